"""The shared linear solver (mcfbench.running.solver): methods, failures, invariances.

The oracle is a literal copy of the former numpy BiCGStab (ddfv/solver.py at
6cc720c): the compiled kernel must reproduce its iteration counts and its
iterates up to round-off.
"""

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from mcfbench.running.solver import (
    METHODS,
    ROBUST,
    SolveInfo,
    Solver,
    SolverFailure,
    apply_block,
    solve,
)

pytestmark = pytest.mark.filterwarnings("error")   # no arithmetic warning may escape


def oracle_bicgstab(A, b, x0, rtol, maxiter):
    """The former ddfv.solver.bicgstab (stopping test |r| <= rtol |b|)."""
    dot = lambda x, y: float(np.vdot(x, y))          # noqa: E731
    norm = lambda x: float(np.sqrt(np.vdot(x, x)))   # noqa: E731
    bnorm = norm(b)
    tol = rtol * bnorm
    x = np.array(x0, dtype=float, copy=True)
    r = b - np.stack([A @ xi for xi in x])
    if norm(r) <= tol:
        return x, 0
    r_hat, p = r.copy(), r.copy()
    rho = dot(r_hat, r)
    for it in range(1, maxiter + 1):
        v = np.stack([A @ pi for pi in p])
        alpha = rho / dot(r_hat, v)
        s = r - v * alpha
        x += p * alpha
        if norm(s) <= tol:
            return x, it
        t = np.stack([A @ si for si in s])
        omega = dot(t, s) / dot(t, t)
        x += s * omega
        r = s - t * omega
        if norm(r) <= tol:
            return x, it
        rho_new = dot(r_hat, r)
        beta = (rho_new / rho) * (alpha / omega)
        rho = rho_new
        p = (p - v * omega) * beta + r
    return x, maxiter


def nonsymmetric(n=300, seed=0):
    A = sp.random(n, n, density=0.02, random_state=seed) * 0.3
    A = (sp.eye(n) * 3 + A - A.T * 0.5).tocsr()          # diagonally dominant
    return A, np.random.default_rng(seed).normal(size=(3, n))


def spd(n=200, seed=1):
    B = sp.random(n, n, density=0.03, random_state=seed)
    A = (B @ B.T + sp.eye(n)).tocsr()
    return A, np.random.default_rng(seed).normal(size=(3, n))


def ring_system(n=400, tau=0.3, seed=2):
    """Like a DDFV/cotangent step: ``I + tau diag(1/m) L`` (row sums one,
    nonsymmetric) on a ring with chords, ``b`` smooth positions off the origin."""
    rng = np.random.default_rng(seed)
    i = np.arange(n)
    rows = np.r_[i, i, i]
    cols = np.r_[(i + 1) % n, (i + 7) % n, (i + 31) % n]
    W = sp.coo_matrix((rng.uniform(0.5, 2.0, rows.size), (rows, cols)), shape=(n, n))
    W = (W + W.T).tocsr()
    L = sp.diags(np.asarray(W.sum(axis=1)).ravel()) - W
    m = rng.uniform(0.5, 2.0, n)
    A = (sp.eye(n) + tau * sp.diags(1.0 / m) @ L).tocsr()
    theta = 2 * np.pi * i / n
    b = np.stack([np.cos(theta), np.sin(theta), 0.3 * np.sin(3 * theta)]) + 0.01 * rng.normal(
        size=(3, n))
    return A, b


def residual(A, b, x):
    return np.linalg.norm(b - np.stack([A @ xi for xi in x]))


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("system", [spd, nonsymmetric])
def test_methods_solve_against_spsolve(method, system):
    A, b = system()
    x, info = Solver(method, rtol=1e-12)(A, b, np.zeros_like(b))
    exact = spla.spsolve(A.tocsc(), b.T).T
    assert info.converged and info.status == "converged" and info.method == method
    assert info.detail == ""
    assert np.abs(x - exact).max() < 1e-9 * np.abs(exact).max()
    assert info.residual <= 1e-12
    assert residual(A, b, x) <= 1.01e-12 * np.linalg.norm(b)   # c = 0 here: |b - A c| = |b|
    if method == "direct":
        assert info.iterations == 0
    elif "ilu" in method:
        assert 1 <= info.iterations <= 5
    else:
        assert 5 <= info.iterations <= 60


@pytest.mark.parametrize("method", METHODS)
def test_shared_and_coupled_matrices_agree(method):
    """(n, n) shared by the rows == block-diagonal (3n, 3n) on b.ravel()."""
    A, b = ring_system(tau=1.0)
    x0 = b + 0.01
    xs, infos = Solver(method, rtol=1e-11)(A, b, x0)
    xc, infoc = Solver(method, rtol=1e-11)(sp.block_diag([A, A, A], format="csr"), b, x0)
    assert xc.shape == b.shape
    assert np.abs(xs - xc).max() < 1e-10 * np.abs(xs).max()
    assert infos.converged and infoc.converged
    if "ilu" not in method and method != "coupled-jacobi-bicgstab":  # spilu's ordering;
        assert infos.iterations == infoc.iterations                   # Jacobi if coupled
        assert infos.residual == pytest.approx(infoc.residual, rel=1e-3)


class _Triangular:
    """``[[I, diag(d)], [0, S]]`` on a (2, n) block: the solver's block triangular form
    (module docstring, "Systems"; KLL's (KL6) has three rows above four)."""

    rows = 1

    def __init__(self, S, d):
        self.shared, self.d, self.shape = S, d, (2 * S.shape[0],) * 2

    def substitute(self, y, b):
        return b[:1] - self.d * y


@pytest.mark.parametrize("method", METHODS)
def test_block_triangular_system_is_solved_by_its_blocks(method):
    """The shared block, then the substitution: the whole matrix's solution to 1e-10,
    the shared system's iterations; shapes that do not fit are refused."""
    A, b = ring_system(tau=1.0)
    n = A.shape[0]
    d = np.linspace(0.5, 2.0, n)
    T, rhs = _Triangular(A, d), b[:2]
    whole = sp.bmat([[sp.identity(n), sp.diags(d)], [None, A]], format="csc")
    expected = spla.spsolve(whole, rhs.ravel()).reshape(rhs.shape)
    x, info = Solver(method, rtol=1e-12)(T, rhs, rhs + 0.01)
    _, shared = Solver(method, rtol=1e-12)(A, rhs[1:], rhs[1:] + 0.01)
    assert np.abs(x - expected).max() < 1e-10 * np.abs(expected).max()
    assert info.converged and info.iterations == shared.iterations
    with pytest.raises(ValueError, match="block triangular of shape .* b has shape"):
        Solver(method)(T, b, None)
    with pytest.raises(ValueError, match="x0 has shape"):
        Solver(method)(T, rhs, b)


def test_block_triangular_system_keeps_its_preconditioner_for_plain_bicgstab():
    """A block triangular system carrying an incomplete LU of its shared matrix (as KLL's
    (KL6) on a spread diagonal): plain ``bicgstab`` runs as ``ilu-bicgstab`` with it, the
    same solution to the tolerance in fewer iterations; another method ignores it."""
    A, b = ring_system(tau=1.0)
    n = A.shape[0]
    d = np.linspace(0.5, 2.0, n)
    T, rhs = _Triangular(A, d), b[:2]
    T.preconditioner = spla.spilu(A.tocsc(), drop_tol=1e-3, fill_factor=1.5,
                                  permc_spec="NATURAL", diag_pivot_thresh=0.0)
    whole = sp.bmat([[sp.identity(n), sp.diags(d)], [None, A]], format="csc")
    expected = spla.spsolve(whole, rhs.ravel()).reshape(rhs.shape)
    x, info = Solver(rtol=1e-12)(T, rhs, rhs + 0.01)
    _, plain = Solver(rtol=1e-12)(A, rhs[1:], rhs[1:] + 0.01)
    _, jacobi = Solver("jacobi-bicgstab", rtol=1e-12)(T, rhs, rhs + 0.01)
    assert np.abs(x - expected).max() < 1e-10 * np.abs(expected).max()
    assert info.method == "ilu-bicgstab" and info.residual <= 1e-12
    assert info.iterations < plain.iterations and jacobi.method == "jacobi-bicgstab"


def test_coupled_matrix_acts_on_the_raveled_block():
    rng = np.random.default_rng(3)
    n = 50
    A = (sp.random(3 * n, 3 * n, density=0.05, random_state=3) + 4 * sp.eye(3 * n)).tocsr()
    b = rng.normal(size=(3, n))
    x, info = Solver(rtol=1e-12)(A, b, np.zeros_like(b))
    assert np.abs(A @ x.ravel() - b.ravel()).max() < 1e-10
    assert np.array_equal(apply_block(A, x).ravel(), A @ x.ravel())


def test_block_product_is_bitwise_scipy():
    A, b = ring_system()
    assert np.array_equal(apply_block(A, b), np.stack([A @ row for row in b]))
    out = np.empty_like(b)
    assert apply_block(A, b, out=out) is out


@pytest.mark.parametrize("rtol", [1e-6, 1e-9, 1e-12])
@pytest.mark.parametrize("system", [ring_system, nonsymmetric])
def test_bicgstab_reproduces_the_former_iterations(system, rtol):
    """Same iteration count (half-step exits included) and iterates as the numpy
    oracle; b is centred so that |b - A c| = |b| up to round-off."""
    A, b = system()
    b = b - b.mean(axis=1, keepdims=True)
    x0 = b + 1e-3 * np.sin(np.arange(b.size)).reshape(b.shape)
    x0 -= x0.mean(axis=1, keepdims=True)
    x_ref, it_ref = oracle_bicgstab(A, b, x0, rtol, 1000)
    x, info = Solver(rtol=rtol)(A, b, x0)
    assert info.iterations == it_ref > 0
    assert np.abs(x - x_ref).max() <= 1e-10 * np.abs(x_ref).max()


def test_iteration_count_conventions():
    A, b = nonsymmetric()
    exact = spla.spsolve(A.tocsc(), b.T).T
    assert Solver()(A, b, exact)[1].iterations == 0              # converged at x0
    # a half-step exit counts one: the oracle's count matches at every tolerance
    for rtol in np.logspace(-2, -12, 11):
        assert Solver(rtol=rtol)(A, b, np.zeros_like(b))[1].iterations == \
            oracle_bicgstab(A, b, np.zeros_like(b), rtol, 1000)[1]


def test_translation_invariance():
    """Row sums one: shifting b and x0 by a constant shifts the solution and
    leaves iterations and relative residual unchanged (|b - A c| is shift-free)."""
    A, b = ring_system()
    x0 = b.copy()
    x, info = Solver(rtol=1e-10)(A, b, x0)
    shift = np.array([[1e3], [-250.0], [40.0]])
    xs, infos = Solver(rtol=1e-10)(A, b + shift, x0 + shift)
    assert infos.iterations == info.iterations > 0
    assert infos.residual == pytest.approx(info.residual, rel=1e-3)
    assert np.abs(xs - shift - x).max() < 1e-9


@pytest.mark.parametrize("scale", [1e-6, 7.0, 1e8])
def test_scale_invariance(scale):
    A, b = ring_system()
    x0 = b.copy()
    x, info = Solver(rtol=1e-10)(A, b, x0)
    xs, infos = Solver(rtol=1e-10)(A, scale * b, scale * x0)
    assert infos.iterations == info.iterations > 0
    assert infos.residual == pytest.approx(info.residual, rel=1e-6)
    assert np.abs(xs / scale - x).max() < 1e-12


def test_constant_right_hand_side_is_solved_at_once():
    """b = A c exactly (c the mean of x0): c is the solution, nothing to iterate."""
    A, _ = ring_system()
    b = np.ones((3, A.shape[0])) * np.array([[1.0], [2.0], [3.0]])
    x, info = Solver()(A, b, b.copy())
    assert info.iterations == 0 and info.residual == 0.0
    assert np.array_equal(x, b)


def test_breakdown_r_hat_v():
    """A rotation: v = A r0 is orthogonal to r_hat = r0 at the first iteration."""
    R = sp.csr_matrix(np.array([[0.0, 1.0], [-1.0, 0.0]]))
    with pytest.raises(SolverFailure) as err:
        Solver()(R, np.array([[1.0, 0.0], [0.0, 2.0], [3.0, 0.0]]), None)
    assert err.value.status == "solver_breakdown"
    assert err.value.info.status == "breakdown" and not err.value.info.converged
    assert err.value.info.iterations == 1
    assert "(r_hat, v) = 0" in str(err.value) and "bicgstab" in str(err.value)


def test_breakdown_rho():
    """r_1 is orthogonal to r_hat = r_0 (exactly, in floating point)."""
    A = sp.csr_matrix(np.array([[1.0, 1, 1], [1, 2, 0], [-1, 0, 3]]))
    x, info = solve(A, np.array([[1.0, 0, 0]]), None)
    assert info.status == "breakdown" and info.iterations == 1
    assert "rho" in info.detail
    assert info.residual == pytest.approx(np.sqrt(13) / 13)    # |r_1| = |(0, -3, -2)| / 13
    with pytest.raises(SolverFailure, match="rho = "):
        Solver()(A, np.array([[1.0, 0, 0]]), None)


def test_breakdown_omega():
    """(t, s) = 0 with t != 0: omega = 0."""
    A = sp.csr_matrix(np.array([[1.0, -1, 0], [1, 1, -1], [2, 0, 1]]))
    with pytest.raises(SolverFailure, match=r"omega = 0") as err:
        Solver()(A, np.array([[1.0, 1, 0]]), None)
    assert err.value.status == "solver_breakdown"


def test_iteration_limit():
    A, b = nonsymmetric()
    with pytest.raises(SolverFailure) as err:
        Solver(maxiter=1)(A, b, np.zeros_like(b))
    assert err.value.status == "solver_failed"
    assert err.value.info.status == "max_iterations" and err.value.info.iterations == 1
    message = str(err.value)
    assert "iteration limit 1 reached" in message and "rtol 1.0e-09" in message
    assert "after 1 iterations" in message and "\n" not in message
    assert 1e-3 < err.value.info.residual < 1   # one iteration reduces, does not converge
    # without raising, the last iterate comes back
    x, info = solve(A, b, np.zeros_like(b), maxiter=1)
    assert not info.converged and residual(A, b, x) < np.linalg.norm(b)


def test_stagnation_below_round_off():
    """rtol = 1e-18 is below what double precision can attain (~1e-16)."""
    A, b = nonsymmetric()
    with pytest.raises(SolverFailure) as err:
        Solver(rtol=1e-18)(A, b, np.zeros_like(b))
    info = err.value.info
    assert err.value.status == "solver_stagnated" and info.status == "stagnated"
    assert 1e-17 < info.residual < 1e-14
    assert info.iterations < 40          # detected, not run to maxiter
    assert "stagnation" in str(err.value)


def test_tight_but_attainable_tolerance_converges():
    A, b = nonsymmetric()
    x, info = Solver(rtol=1e-15)(A, b, np.zeros_like(b))
    assert residual(A, b, x) <= 1e-15 * np.linalg.norm(b)   # the true residual


@pytest.mark.parametrize("where", ["b", "x0", "A"])
@pytest.mark.parametrize("method", METHODS)
def test_non_finite_input_fails_clearly(where, method):
    A, b = ring_system(n=50)
    x0 = b.copy()
    if where == "b":
        b[1, 3] = np.nan
    elif where == "x0":
        x0[2, 7] = np.inf
    else:
        A = A.copy()
        A.data[5] = np.nan
    with pytest.raises(SolverFailure) as err:
        Solver(method)(A, b, x0)
    assert err.value.status == "solver_breakdown"
    assert f"NaN/inf in {'the matrix A' if where == 'A' else where}" in str(err.value)


def test_direct_singular_matrix_fails_clearly():
    S = sp.csr_matrix(np.array([[1.0, 1.0, 0.0], [1.0, 1.0, 0.0], [0.0, 0.0, 2.0]]))
    with pytest.raises(SolverFailure) as err:
        Solver("direct")(S, np.array([[1.0, 2.0, 3.0]]), None)
    assert err.value.status == "solver_breakdown"
    assert "singular" in str(err.value) and str(err.value).startswith("direct")
    with pytest.raises(SolverFailure, match="singular"):
        Solver("ilu-bicgstab")(S, np.array([[1.0, 2.0, 3.0]]), None)


def test_direct_tries_symmetric_mode_then_partial_pivoting(monkeypatch):
    """``direct`` factorises with SuperLU's symmetric mode first and, when that
    fails, with COLAMD and partial pivoting (:data:`LU_ORDERINGS`): the answer is
    the second's; with every ordering failing, the last failure is named."""
    import mcfbench.running.solver as solver

    factorize, seen = solver.factorize, []

    def first_fails(A, ilu, *args, ordering=None, **kwargs):
        seen.append(ordering)
        if ordering is solver.LU_ORDERINGS[0]:
            return None, "LU factorization failed: the first ordering"
        return factorize(A, ilu, *args, ordering=ordering, **kwargs)

    monkeypatch.setattr(solver, "factorize", first_fails)
    P = sp.csr_matrix(np.array([[0.0, 2.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 3.0]]))
    x, info = Solver("direct")(P, np.array([[4.0, 1.0, 6.0]]), None)
    np.testing.assert_allclose(x, [[1.0, 2.0, 2.0]], rtol=1e-15)
    assert info.converged and seen == list(solver.LU_ORDERINGS)
    assert solver.LU_ORDERINGS[0]["options"] == {"SymmetricMode": True}
    assert solver.LU_ORDERINGS[-1] == {"permc_spec": "COLAMD"}
    monkeypatch.setattr(solver, "LU_ORDERINGS", solver.LU_ORDERINGS[:1])
    with pytest.raises(SolverFailure, match="the first ordering"):
        Solver("direct")(P, np.array([[4.0, 1.0, 6.0]]), None)


def test_direct_ill_conditioned_matrix_fails_clearly():
    """Hilbert matrix of order 14 (condition ~1e17): LU plus refinement
    cannot reach 1e-9."""
    i = np.arange(14)
    H = sp.csr_matrix(1.0 / (i[:, None] + i[None, :] + 1))
    with pytest.raises(SolverFailure) as err:
        Solver("direct")(H, np.ones((1, 14)), None)
    assert err.value.status == "solver_stagnated"
    assert "ill-conditioned" in str(err.value)
    assert 1e-9 < err.value.info.residual < 1e-3 and err.value.info.iterations == 0


def test_krylov_methods_report_a_singular_system():
    """A s = 0 along the way, or no convergence: never an exception or a NaN."""
    S = sp.csr_matrix(np.array([[1.0, 1.0], [1.0, 1.0]]))
    for method in ("bicgstab", "jacobi-bicgstab"):
        x, info = solve(S, np.array([[1.0, 2.0]]), None, method=method)
        assert not info.converged and info.status == "breakdown"
        assert np.isfinite(x).all()


def test_preconditioners_help_on_an_ill_conditioned_system():
    """Rows scaled over six decades (tiny covolumes) and a large tau: plain
    BiCGStab does not converge in 1000 iterations, the preconditioned ones do."""
    A, b = ring_system(tau=1e4)
    A = (sp.diags(np.geomspace(1e-3, 1e3, A.shape[0])) @ A).tocsr()
    b = np.stack([A @ row for row in b])
    its = {m: solve(A, b, np.zeros_like(b), method=m, rtol=1e-9)[1] for m in METHODS}
    assert its["bicgstab"].status == "max_iterations"
    assert its["jacobi-bicgstab"].converged and its["jacobi-bicgstab"].iterations < 100
    assert its["ilu-bicgstab"].converged and its["ilu-bicgstab"].iterations < 30
    assert its["direct"].converged and its["direct"].residual < 1e-12


@pytest.mark.parametrize("coupled", [False, True])
def test_robust_method_is_jacobi_then_the_sparse_lu(coupled):
    """``jacobi-direct`` (the robust method): Jacobi-BiCGStab's iterate where it converges,
    bitwise; where it does not (maxiter 3 here), the sparse LU's solution from the same
    x0, bitwise, with Jacobi's iterations counted; where both fail, the LU's verdict."""
    A, b = ring_system(tau=1e4)
    A = (sp.diags(np.geomspace(1e-3, 1e3, A.shape[0])) @ A).tocsr()
    b = np.stack([A @ row for row in b])
    A = sp.block_diag([A, A, A], format="csr") if coupled else A
    x0 = np.zeros_like(b)
    kept = x0.copy()
    assert ROBUST == "jacobi-direct"
    x_jacobi, jacobi = solve(A, b, x0, method="jacobi-bicgstab")
    x, info = solve(A, b, x0, method=ROBUST)
    assert jacobi.converged and np.array_equal(x, x_jacobi)
    assert info == SolveInfo(jacobi.iterations, jacobi.residual, True, method=ROBUST)
    assert not solve(A, b, x0, method="jacobi-bicgstab", maxiter=3)[1].converged
    x_lu, lu = solve(A, b, x0, method="direct")
    x, info = solve(A, b, x0, method=ROBUST, maxiter=3)
    assert np.array_equal(x, x_lu) and x.shape == b.shape and np.array_equal(x0, kept)
    assert info == SolveInfo(3, lu.residual, True, method=ROBUST) and lu.residual < 1e-12
    S = sp.csr_matrix(np.array([[1.0, 1.0], [1.0, 1.0]]))
    x, info = solve(S, np.array([[1.0, 2.0]]), np.array([[0.5, 0.25]]), method=ROBUST)
    assert (info.status, info.method) == ("breakdown", ROBUST) and "singular" in info.detail
    assert np.array_equal(x, [[0.5, 0.25]])


@pytest.mark.parametrize("field, value", [("method", "cg"), ("rtol", 0.0), ("rtol", 1.5),
                                          ("maxiter", 0), ("maxiter", 2.5),
                                          ("stagnation_window", 0), ("ilu_drop_tol", -1.0),
                                          ("ilu_fill_factor", 0.5)])
def test_solver_validates_its_fields(field, value):
    with pytest.raises(ValueError, match=field.replace("_", ".") if field != "method"
                       else "method"):
        Solver(**{field: value})


@pytest.mark.parametrize("method", ["bicgstab", "kept-ilu-bicgstab"])
def test_shapes_are_checked(method):
    A, b = ring_system(n=20)
    with pytest.raises(ValueError, match="shape"):
        Solver(method)(A, b[:, :10], None)
    with pytest.raises(ValueError, match=r"b must be a \(k, n\) block, got shape \(20,\)"):
        Solver(method)(A, b[0], None)
    with pytest.raises(ValueError, match="x0"):
        Solver(method)(A, b, b[:2])


def test_solve_info_api():
    info = SolveInfo(3, 1e-10, True, "converged", "bicgstab")
    assert info.detail == ""
    with pytest.raises(AttributeError):
        info.iterations = 4


def test_overwrite_x0_iterates_in_the_callers_buffer():
    """overwrite_x0: no copy of a suitable x0, the same solution as with the copy."""
    rng = np.random.default_rng(7)
    n = 40
    A = sp.csr_matrix(sp.eye(n) * 4.0 + sp.random(n, n, density=0.1, random_state=3))
    b = rng.standard_normal((3, n))
    x0 = rng.standard_normal((3, n))
    kept = x0.copy()
    x_copy, info_copy = solve(A, b, x0)
    assert np.array_equal(x0, kept)                          # default: x0 untouched
    x_own, info_own = solve(A, b, x0, overwrite_x0=True)
    assert x_own is x0 and np.array_equal(x_own, x_copy)
    assert info_own == info_copy
    x1, _ = Solver()(A, b, kept.copy(), overwrite_x0=True)
    assert np.array_equal(x1, x_copy) and Solver.can_overwrite_x0
    view = kept.copy()[:, ::1].T.copy().T                    # not C-contiguous: copied
    x2, _ = solve(A, b, view, overwrite_x0=True)
    assert x2 is not view and np.array_equal(x2, x_copy)


@pytest.mark.parametrize("system", [ring_system, nonsymmetric])
def test_two_threads_give_the_same_solution_to_round_off(system):
    A, b = system()
    x1, info1 = solve(A, b, None, rtol=1e-10)
    x2, info2 = solve(A, b, None, rtol=1e-10, threads=2)
    assert info1.converged and info2.converged
    assert abs(info2.iterations - info1.iterations) <= 1
    np.testing.assert_allclose(x2, x1, atol=1e-8 * np.abs(x1).max())
    assert residual(A, b, x2) <= 1e-10 * np.linalg.norm(b)


@pytest.mark.parametrize("threads", [0, 2.5, True, 10**6])
def test_bad_thread_counts_are_refused(threads):
    with pytest.raises(ValueError, match="threads"):
        Solver(threads=threads)


def test_one_solver_of_either_settings_shape():
    """Table 3.1's flat settings, the matrix's nested ones and the gallery's flat ones
    with a method give the solvers their jobs ran with."""
    flat = Solver.of_settings({"rtol": 1e-11, "threads": 2, "tau": 0.01})
    assert (flat.method, flat.rtol, flat.maxiter, flat.threads) == ("bicgstab", 1e-11, 1000, 2)
    nested = Solver.of_settings({"solver": {"method": "direct", "rtol": 1e-8, "maxiter": 7}})
    assert (nested.method, nested.rtol, nested.maxiter) == ("direct", 1e-8, 7)
    gallery = Solver.of_settings({"solver": "direct", "rtol": 1e-9, "maxiter": 1000, "C": 0.1})
    assert (gallery.method, gallery.rtol, gallery.maxiter) == ("direct", 1e-9, 1000)
    with pytest.raises(ValueError, match="unknown solver method 'lu'"):
        Solver.of_settings({"solver": "lu", "rtol": 1e-9})


def _floor(A, b, c):
    """The round-off bound of ``b - A c`` by its definition, for a shared A:
    ``(nnz_row + 1) eps | |b| + |A| |c| |``."""
    width = np.diff(A.indptr).max()
    f = abs(b) + np.outer(abs(c), abs(A).sum(axis=1).A1)
    return (width + 1) * np.finfo(float).eps * np.linalg.norm(f)


@pytest.mark.parametrize("offset", [0.0, 1e-15, 1e-3])
def test_residual_round_off_bound(offset):
    """The shared three-row pass returns the bound itself when ``|b - A c|`` is near
    it (c nearly the solution) and otherwise an upper bound that ``|b - A c|``
    exceeds, so the test ``|b - A c| <= bound`` decides as with the bound."""
    from mcfbench.running import krylov
    from mcfbench.running.solver import _csr

    A, _ = ring_system()
    c = np.array([1.0, -2.0, 3.0])
    b = A @ np.outer(np.ones(A.shape[0]), c)
    b = np.ascontiguousarray(b.T) + offset * np.sin(np.arange(b.size)).reshape(3, -1)
    r = np.empty_like(b)
    rr, ref2, bb, xx, norm_a, code, bound = krylov.residual(
        *_csr(A), b, np.ascontiguousarray(b), c, np.empty((3, 0)), r)
    exact = _floor(A, b, c)
    assert code == 0 and norm_a == pytest.approx(abs(A).sum(axis=1).max(), rel=1e-14)
    assert ref2 == pytest.approx(np.sum((b - c[:, None] * A.sum(axis=1).A1) ** 2), rel=1e-10)
    if offset < 1e-14:
        assert np.sqrt(ref2) <= bound == pytest.approx(exact, rel=1e-12)
    else:
        assert bound >= exact and np.sqrt(ref2) > bound


def test_four_row_passes_are_the_general_ones_bitwise():
    """The product and the residual of a shared matrix and four rows (kll's block solve)
    keep their sums in registers: the numbers of the general path, which a fifth row of
    zeros takes (it adds +0.0 to every sum)."""
    from mcfbench.running import krylov
    from mcfbench.running.solver import _csr

    A, b3 = ring_system()
    rng = np.random.default_rng(4)
    b = np.vstack([b3, rng.normal(size=(1, A.shape[0]))])
    x, R = b + 0.01 * rng.normal(size=b.shape), rng.normal(size=b.shape)
    five = [np.vstack([z, np.zeros((1, A.shape[0]))]) for z in (b, x, R)]
    Y, Y5 = np.empty_like(b), np.empty_like(five[0])
    assert krylov.spmv(*_csr(A), x, Y, R) == krylov.spmv(*_csr(A), five[1], Y5, five[2])
    assert np.array_equal(Y, Y5[:4]) and np.array_equal(Y, (A @ x.T).T)
    c = np.array([0.5, -1.0, 2.0, 0.25])
    r, r5 = np.empty_like(b), np.empty_like(five[0])
    sums = krylov.residual(*_csr(A), b, x, c, np.empty((4, 0)), r)
    assert sums == krylov.residual(*_csr(A), five[0], five[1], np.r_[c, 0.0],
                                   np.empty((5, 0)), r5)
    assert np.array_equal(r, r5[:4]) and sums[0] > 0.0


@pytest.mark.parametrize("where", ["b", "x0", "A"])
def test_overflowing_but_finite_input_is_not_called_non_finite(where):
    """A sum of squares overflows with entries of 1e200: the pass checks the
    entries before naming NaN/inf in the input (code 0), and names them when one is."""
    from mcfbench.running import krylov
    from mcfbench.running.solver import _csr

    A, b = ring_system(n=50)
    x0 = b.copy()
    A = A.copy()
    target = {"b": b, "x0": x0, "A": A.data}[where]
    target.flat[3] = 1e200
    args = (b, x0, np.zeros(3), np.empty((3, 0)), np.empty_like(b))
    assert krylov.residual(*_csr(A), *args)[5] == 0
    target.flat[4] = np.inf
    assert krylov.residual(*_csr(A), *args)[5] == {"b": 8, "x0": 9, "A": 10}[where]


def test_kept_ilu_factor_is_kept_renewed_and_retried(monkeypatch):
    """``kept-ilu-bicgstab``: one factor for nearby matrices; renewed after a solve of
    more than ``ilu_refresh`` iterations, and, when the kept one fails, at once (the solve
    repeated from ``x0``, iterations summed); every solution to the tolerance."""
    from mcfbench.running import solver as solver_module

    far, b = ring_system(tau=100.0, seed=5)
    far = (sp.diags(np.geomspace(1e-3, 1e3, far.shape[0])) @ far).tocsr()
    far_b, x0 = b, np.zeros_like(b)
    fresh = solve(far, far_b, x0, method="ilu-bicgstab", rtol=1e-8, maxiter=30)[1]
    assert not solve(far, far_b, x0, method="kept-ilu-bicgstab", rtol=1e-8, maxiter=30,
                     factor=solver_module.ilu_factor(ring_system(tau=10.0)[0])[0])[1].converged
    factored = []

    def counted(A, *args):
        factored.append(A.copy())
        return ilu_factor(A, *args)

    ilu_factor = solver_module.ilu_factor
    monkeypatch.setattr(solver_module, "ilu_factor", counted)
    kept = Solver("kept-ilu-bicgstab", rtol=1e-8, maxiter=30, ilu_refresh=10)
    for tau in (1.0, 1.01, 1.02):                        # nearby: one factor, 1-2 iterations
        A, b = ring_system(tau=tau)
        x, info = kept(A, b, None)
        assert residual(A, b, x) <= 1e-8 * np.linalg.norm(b) and info.iterations <= 10
    assert len(factored) == 1
    A, b = ring_system(tau=50.0)                         # further: 12 iterations
    x, older = kept(A, b, None)
    assert older.converged and older.iterations > 10 and len(factored) == 1
    assert residual(A, b, x) <= 1e-8 * np.linalg.norm(b)
    x, info = kept(A, b, None)                           # renewed before this solve
    assert len(factored) == 2 and (factored[1] != A).nnz == 0
    assert info.iterations < older.iterations
    x, info = kept(far, far_b, x0, overwrite_x0=True)   # the kept factor fails: renewed
    assert len(factored) == 3 and info.converged and info.iterations == 30 + fresh.iterations
    assert residual(far, far_b, x) <= 1e-8 * np.linalg.norm(far_b)


def test_ilu_preconditioner_is_superlus_solve_for_every_row():
    """The compiled ILU preconditioner (``krylov.precondition``) is ``M^{-1} y`` of
    SuperLU's factor, ``M = D Pr^T L U Pc^T``, for a (3, n) block, its three rows in one
    pass bitwise those of the one-row path (the same sums in the same order)."""
    from mcfbench.running import krylov
    from mcfbench.running.factorizations import ILU_ORDERING, ilu_factor

    A, _ = nonsymmetric(n=400, seed=3)
    y = np.random.default_rng(3).normal(size=(3, 400))
    (dinv, arrays), _ = ilu_factor(A, drop_tol=1e-2)
    z = np.empty_like(y)
    krylov.precondition(2, y, z, dinv, *arrays, np.empty_like(y))
    rows = np.empty_like(y)
    for q in range(3):
        krylov.precondition(2, y[q:q + 1], rows[q:q + 1], dinv, *arrays, np.empty((1, 400)))
    assert np.array_equal(z, rows)
    lu = spla.spilu(sp.csc_matrix(sp.diags(dinv) @ A), drop_tol=1e-2, **ILU_ORDERING)
    assert np.abs(z - lu.solve((dinv * y).T).T).max() <= 1e-13 * np.abs(z).max()
    assert np.abs(z - spla.spsolve(A.tocsc(), y.T).T).max() > 1e-8 * np.abs(z).max()


@pytest.mark.parametrize("scheme", ["ddfv-chord", "cotan", "bgn", "mdr", "deturck"])
def test_kept_ilu_runs_the_anisotropic_sphere_as_bicgstab_does(scheme):
    """The anisotropic sphere (level 2: 1 922 vertices, 8 steps): the kept ILU
    factor's run equals BiCGStab's to the solver's tolerance, in a tenth of the
    iterations or fewer (level 4: 2-4 a step against 100-300); for the coupled
    systems of bgn, mdr and deturck that of their isotropic part (96, 82, 62
    iterations against 1 532, 1 150, 899)."""
    from mcfbench.running.run import run

    plain, _ = run(scheme, "anisotropic_sphere", 2, solver=Solver())
    kept, _ = run(scheme, "anisotropic_sphere", 2, solver=Solver("kept-ilu-bicgstab"))
    assert plain.status == kept.status == "ok" and kept.solver == "kept-ilu-bicgstab"
    for name, value in plain.metrics.items():
        assert kept.metrics[name] == pytest.approx(value, rel=1e-6), name
    assert 10 * kept.iterations <= plain.iterations


@pytest.mark.parametrize("scheme", ["cotan", "bgn", "mdr", "deturck"])
def test_coupled_jacobi_runs_the_remeshed_sphere_as_bicgstab_does(scheme):
    """The remeshed sphere (level 2, 8 steps), ``coupled-jacobi-bicgstab``: BGN's, MDR's
    and DeTurck's runs equal BiCGStab's to the solver's tolerance in fewer iterations
    (450, 488, 345 against 993, 971, 465), the shared systems' (cotan) are BiCGStab's,
    bit for bit."""
    from mcfbench.running.run import run

    plain, _ = run(scheme, "remeshed_sphere", 2, solver=Solver())
    jacobi, _ = run(scheme, "remeshed_sphere", 2, solver=Solver("coupled-jacobi-bicgstab"))
    assert plain.status == jacobi.status == "ok"
    if scheme == "cotan":
        assert jacobi.metrics == plain.metrics and jacobi.iterations == plain.iterations
        return
    for name, value in plain.metrics.items():
        assert jacobi.metrics[name] == pytest.approx(value, rel=1e-6), name
    assert jacobi.iterations < 0.8 * plain.iterations


def bgn_like(n=400, tau=0.3, seed=2):
    """A coupled (3n, 3n) system like BGN's (B4) row-scaled (``baselines/bgn.py``):
    ``K (x) I_3`` plus ``omega_k omega_k^T`` at every vertex, ``omega_k`` random unit
    vectors, ``K = tau diag(1/m) L`` of :func:`ring_system`; unknowns by components.
    Returns the matrix, a (3, n) ``b`` and ``S = K + I / 3``, the mean of its diagonal
    blocks."""
    A, b = ring_system(n, tau, seed)
    K = A - sp.eye(n)
    omega = np.random.default_rng(seed).normal(size=(n, 3))
    omega /= np.linalg.norm(omega, axis=1)[:, None]
    coupled = sp.block_diag([K, K, K]) + sp.bmat(
        [[sp.diags(omega[:, c] * omega[:, d]) for d in range(3)] for c in range(3)])
    return coupled.tocsr(), b, (K + sp.eye(n) / 3).tocsc()


def test_coupled_jacobi_is_jacobi_on_a_coupled_system_and_bicgstab_on_a_shared_one():
    """``coupled-jacobi-bicgstab``: the iterates of ``jacobi-bicgstab`` for a coupled
    (3n, 3n) system, of the unpreconditioned ``bicgstab`` for a shared (n, n) one, bit
    for bit (and the two differ on the coupled one)."""
    coupled, b, _ = bgn_like()
    shared, bs = ring_system()
    iterations = []
    for A, rhs, same in ((coupled, b, "jacobi-bicgstab"), (shared, bs, "bicgstab")):
        x, info = Solver("coupled-jacobi-bicgstab")(A, rhs, rhs + 0.01)
        y, expected = Solver(same)(A, rhs, rhs + 0.01)
        assert np.array_equal(x, y) and info.iterations == expected.iterations
        iterations.append(info.iterations)
    assert Solver()(coupled, b, b + 0.01)[1].iterations != iterations[0]


def test_coupled_ilu_is_the_inverse_of_the_isotropic_part_on_each_component():
    """The ILU methods' factor of a coupled system (:func:`isotropic_ilu_factor`) without
    dropping applies ``S^{-1}`` to each component, ``S`` the mean of the diagonal blocks
    (here ``K + I / 3``: ``|omega_k| = 1``)."""
    from mcfbench.running import krylov
    from mcfbench.running.factorizations import isotropic_ilu_factor

    A, _, S = bgn_like(n=60)
    dinv, arrays = isotropic_ilu_factor(A, 3, drop_tol=0.0)[0]
    y = np.random.default_rng(1).normal(size=(1, 180))
    z, w = np.empty_like(y), np.empty_like(y)
    krylov.precondition(2, y, z, dinv, *arrays, w)
    expected = np.concatenate([spla.spsolve(S, part) for part in y.reshape(3, 60)])
    np.testing.assert_allclose(z[0], expected, rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("method", ["ilu-bicgstab", "kept-ilu-bicgstab"])
def test_coupled_ilu_solves_as_bicgstab_in_fewer_iterations(method):
    """A coupled system under the ILU methods: plain BiCGStab's solution to the
    tolerance, in a third of its iterations or fewer."""
    A, b, _ = bgn_like(tau=3.0)
    x0 = np.zeros_like(b)
    exact = spla.spsolve(A.tocsc(), b.ravel()).reshape(b.shape)
    x_plain, plain = solve(A, b, x0, rtol=1e-10)
    x, info = Solver(method, rtol=1e-10)(A, b, x0)
    assert plain.converged and info.converged and info.method == method
    assert 3 * info.iterations <= plain.iterations, (info.iterations, plain.iterations)
    for solution in (x, x_plain):
        assert np.linalg.norm(b.ravel() - A @ solution.ravel()) <= 1e-10 * np.linalg.norm(b)
        assert np.abs(solution - exact).max() <= 1e-8 * np.abs(exact).max()


def test_kept_coupled_factor_is_renewed_when_its_iterations_grow(monkeypatch):
    """``kept-ilu-bicgstab`` on coupled systems: a factor whose solves take more than
    ``ilu_refresh`` iterations, as many as a new one's (12 here), is kept; it is renewed
    after a solve of more than ``ilu_refresh`` above the fewest it took (37 > 12 + 5)."""
    from mcfbench.running import solver as solver_module

    factored = []
    isotropic = solver_module.isotropic_ilu_factor
    monkeypatch.setattr(solver_module, "isotropic_ilu_factor",
                        lambda A, *args: factored.append(A.shape) or isotropic(A, *args))
    kept = Solver("kept-ilu-bicgstab", rtol=1e-10, ilu_refresh=5)
    for tau in (0.3, 0.303, 0.306, 0.03):
        A, b, _ = bgn_like(tau=tau)
        x, info = kept(A, b, None)
        assert np.linalg.norm(b.ravel() - A @ x.ravel()) <= 1e-10 * np.linalg.norm(b)
        assert info.iterations > 5 and factored == [(1200, 1200)]
    assert info.iterations > 12 + 5
    x, again = kept(A, b, None)
    assert len(factored) == 2 and again.iterations < info.iterations
