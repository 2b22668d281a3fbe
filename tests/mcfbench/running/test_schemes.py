"""The scheme registry (mcfbench/running/schemes.py): every entry is a working flow."""

import numpy as np
import pytest

from mcfbench.geometry.spheres import icosphere, random_bumpy_sphere
from mcfbench.running.driver import simulate
from mcfbench.running.flow import SchemeFlow
from mcfbench.running.integrators import Euler
from mcfbench.running.schemes import SCHEMES, Scheme, get_scheme, parse_name
from mcfbench.running.solver import ROBUST


@pytest.mark.parametrize("name", sorted(SCHEMES))
def test_every_scheme_follows_the_contract_and_runs(name):
    scheme = get_scheme(name)
    V, F = random_bumpy_sphere(2)
    flow = scheme.make(V, F, 0.001)
    assert isinstance(flow, SchemeFlow)
    assert flow.n == 0 and flow.tau == 0.001 and flow.defects() == []
    assert flow.X.shape[0] == 3 and not flow.X.flags.writeable
    assert flow.vertices.shape == V.shape and np.array_equal(flow.faces, F)
    area = 0.5 * np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]),
                                axis=1).sum()
    # the vertex schemes' lumped mass tiles the triangles; DDFV's covolumes tile the
    # diamond mesh, whose T-vertices lie off the triangles' planes (1.3 % more here)
    rel = 0.02 if scheme.extra_points else 1e-10
    assert flow.l2_weights.sum() == pytest.approx(area, rel=rel)
    traj = simulate(flow, 3, save_every=1)
    assert traj.status == "ok" and traj.steps.tolist() == [0, 1, 2, 3]
    expected = {"vertices", "extra_points"} if scheme.extra_points else {"vertices"}
    assert set(traj.frames) == expected
    assert scheme.label and scheme.description and {"color", "marker"} <= set(scheme.style)


# conformalized MCF keeps the initial stiffness: another rate (tests/baselines/test_cmcf.py)
@pytest.mark.parametrize("name", sorted(set(SCHEMES) - {"cmcf"}))
def test_every_scheme_shrinks_the_sphere_at_the_exact_rate(name):
    """r(t) = sqrt(1 - 4t) on the level-3 icosphere to 1 % at t = 0.05 (r = 0.894)."""
    V, F = icosphere(3)
    traj = simulate(get_scheme(name).make(V, F, 0.0025), 20, save_every=0)
    points = traj.frames["vertices"][-1]
    assert np.linalg.norm(points, axis=1).mean() == pytest.approx(np.sqrt(0.8), rel=0.01)


def test_options_override_the_entry():
    flow = get_scheme("ddfv-chord").make(*icosphere(1), 0.01, tangential="eliminate")
    assert flow.dual_length == "chord" and flow.tangential == "eliminate"


def test_unknown_scheme_lists_the_known_ones():
    with pytest.raises(ValueError, match="unknown scheme 'x'; choose one of ddfv, ddfv-chord"):
        get_scheme("x")


def _second_matrix(scheme, V, F):
    """The matrix of a scheme's second step (the first may start from a special state)."""
    from mcfbench.running.solver import Solver

    flow, seen, solver = scheme.make(V, F, 0.01), [], Solver("direct")

    def solve(A, b, x0):
        seen.append(A)
        return solver(A, b, x0)

    stepper = Euler()
    stepper.step(flow, solve)
    stepper.step(flow, solve)
    return seen[-1]


def _symmetrizing_residual(A):
    """How far ``A`` is from ``diag(d) S`` with ``S`` symmetric: the least-squares misfit of
    ``log d_i - log d_j = log(A_ji / A_ij)`` over the off-diagonal pairs (0: exactly)."""
    import scipy.sparse as sp
    import scipy.sparse.linalg as sla

    A = A.tocsr() if hasattr(A, "substitute") else sp.csr_matrix(A)   # KLL's blocks
    C = sp.triu(A, k=1).tocoo()
    r, c, v = C.row, C.col, C.data
    keep = v != 0
    r, c, v = r[keep], c[keep], v[keep]
    vt = np.asarray(A[c, r]).ravel()
    if not (vt != 0).all():        # not structurally symmetric (KLL's block triangle)
        return np.inf, A
    assert (np.sign(vt) == np.sign(v)).all()          # structurally symmetric, signs alike
    q = np.log(vt / v)
    rows = np.arange(len(q))
    G = sp.csr_matrix((np.r_[np.ones(len(q)), -np.ones(len(q))],
                       (np.r_[rows, rows], np.r_[r, c])), shape=(len(q), A.shape[0]))
    d = sla.lsqr(G, q, atol=1e-15, btol=1e-15)[0]
    return float(np.abs(G @ d - q).max()), A


@pytest.mark.parametrize("name", sorted(SCHEMES))
def test_matrix_kind_of_every_scheme_is_what_the_registry_says(name):
    """``Scheme.matrix``: ``scaled-spd`` is a row scaling of an SPD matrix (misfit at
    round-off, real positive eigenvalues), ``nonsymmetric`` is not (misfit 1e-2 for the
    paper's broken-line DDFV)."""
    scheme = get_scheme(name)
    misfit, A = _symmetrizing_residual(_second_matrix(scheme, *random_bumpy_sphere(1)))
    if scheme.matrix == "scaled-spd":
        assert misfit < 1e-10
        eig = np.linalg.eigvals(A.toarray())
        assert np.abs(eig.imag).max() < 1e-8 and eig.real.min() > 0
    else:
        assert misfit > 1e-4
    assert scheme.robust_solver == ROBUST and scheme.suited_solver


def test_unknown_matrix_kind_is_refused():
    from mcfbench.running.schemes import Scheme

    with pytest.raises(ValueError, match="unknown matrix kind 'spd'"):
        Scheme("x", "x", "baselines.cotan:CotanFlow", matrix="spd")


def test_tangential_strategy_is_declared_once_per_entry():
    """DDFV's strategy is its ``tangential`` option (declared in ddfv.variants, not
    again in the registry); another integrator keeps the entry's; an unknown one is
    refused."""
    from mcfbench.running.schemes import TANGENTIAL, Scheme

    for name, scheme in SCHEMES.items():
        assert scheme.tangential in TANGENTIAL
        if scheme.family == "ddfv":
            assert scheme.tangential == scheme.options.get("tangential", "none")
    assert [SCHEMES[n].tangential for n in ("cotan", "cotan-redistribute", "bgn",
                                            "ddfv-chord-bgn-carried", "mdr", "deturck")] \
        == ["none", "redistribute", "bgn", "bgn", "mdr", "deturck"]
    assert get_scheme("ddfv-chord-mdr-carried@bdf2").tangential == "mdr"
    with pytest.raises(ValueError, match="unknown tangential strategy 'sideways'"):
        Scheme("x", "x", "baselines.cotan:CotanFlow", tangential="sideways")


@pytest.mark.parametrize("name, parts", [("cotan", ("cotan", "euler")),
                                         ("cotan@bdf2", ("cotan", "bdf2")),
                                         ("ddfv-chord@bdf3", ("ddfv-chord", "bdf3"))])
def test_scheme_names_split_and_join_back(name, parts):
    from mcfbench.running.schemes import joined_name, split_name

    assert split_name(name) == parts
    assert joined_name(*parts) == name
    assert get_scheme(name).integrator == parts[1]


@pytest.mark.parametrize("name, parts", [("cotan", ("cotan", "euler", "none")),
                                         ("cotan+surgery", ("cotan", "euler", "surgery")),
                                         ("bgn@bdf2+surgery", ("bgn", "bdf2", "surgery"))])
def test_the_surgery_is_a_mesh_strategy_parsed_off_the_name(name, parts):
    """NAME+surgery is parsed as NAME+remesh is (one parser, parse_name)."""
    assert parse_name(name) == parts
    with pytest.raises(ValueError, match="unknown mesh strategy 'sideways'"):
        parse_name("cotan+sideways")


def test_name_plus_surgery_is_the_entry_with_the_surgery():
    entry, cut = get_scheme("ddfv-chord-carried"), get_scheme("ddfv-chord-carried+surgery")
    assert cut.mesh_strategy == "surgery" and entry.mesh_strategy == "none"
    assert (cut.flow, cut.options, cut.integrator, cut.tangential) == \
        (entry.flow, entry.options, entry.integrator, entry.tangential)
    assert cut.name == "ddfv-chord-carried+surgery" and cut.label.endswith(", surgery")
    both = get_scheme("bgn@bdf2+surgery")
    assert (both.integrator, both.mesh_strategy) == ("bdf2", "surgery")
    with pytest.raises(ValueError, match="scheme 'cotan\\+sideways': unknown mesh strategy"):
        get_scheme("cotan+sideways")
    with pytest.raises(ValueError, match="'\\+' a mesh strategy"):
        Scheme("x", "x", "baselines.cotan:CotanFlow", mesh_strategy="glue")
