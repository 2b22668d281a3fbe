"""BGN with BDF-k on predictor surfaces (baselines/bgn_bdf.py)."""

import numpy as np
import pytest

from baselines.bgn import BGNFlow
from baselines.bgn_bdf import VANISHED, BGNBDFFlow, bdf_base
from baselines.bgn_equilibrium import tangential_increment
from mcfbench.geometry.committed_meshes import read_committed_mesh
from mcfbench.geometry.exact import eoc
from mcfbench.geometry.metrics import area, volume
from mcfbench.geometry.spheres import icosphere
from mcfbench.running.driver import simulate
from mcfbench.running.integrators import BDF2, Euler
from mcfbench.running.solver import Solver

EXACT = Solver(method="direct", rtol=1e-12)


def counting(solver, counts):
    """``solver`` that appends 1 to ``counts[-1]`` per solve."""
    def solve(A, b, x0):
        counts[-1] += 1
        return solver(A, b, x0)
    return solve


def shrinking(flow, steps):
    """Run ``flow`` ``steps`` steps (sparse LU); assert the run ends ``ok`` and the
    area falls at every step (the driver's own check allows 1e-3)."""
    areas = []
    traj = simulate(flow, steps, solver=EXACT, save_every=0,
                    observers=[lambda f: areas.append(area(f.vertices, f.faces))])
    assert traj.status == "ok", traj.message
    assert np.diff(areas).max() < 0.0, np.diff(areas).max()


def mean_radius(flow):
    return np.average(np.linalg.norm(flow.vertices, axis=1), weights=flow.mass)


@pytest.mark.parametrize("order, start, low, high", [
    (2, "bgn", 1.7, 2.3),             # measured EOCs 1.92, 1.97, 2.00
    (3, "richardson", 2.7, 3.3),      # 3.07, 3.02, 3.01: an O(tau^3) start
    (3, "bgn", 1.7, 2.3),             # 2.04, 2.00, 2.01: BGN's start is O(tau^2)
])
def test_time_order_on_the_sphere(order, start, low, high):
    """The level-1 sphere (no tangential motion: its symmetry) to t = 0.04, the
    area-weighted mean radius against a tau / 8 reference; every run's area decreases
    at every step."""
    V, F = icosphere(1)
    taus = [0.01, 0.005, 0.0025, 0.00125]

    def final(tau):
        flow = BGNBDFFlow(V, F, tau, order=order, start=start)
        shrinking(flow, round(0.04 / tau))
        return mean_radius(flow)

    reference = final(taus[-1] / 8)
    errors = np.array([abs(final(tau) - reference) for tau in taus])
    orders = eoc(errors)[1:]
    assert np.all((orders > low) & (orders < high)), (errors, orders)


def test_third_order_from_bgn_s_tangential_equilibrium():
    """The level-2 icosphere, which BGN moves along the surface (the level-1 one it does
    not), to t = 0.04, the volume against a tau / 8 reference: from ``X^0`` (Richardson's
    O(tau^3) start) the order falls to about 1 (measured volume EOCs -0.85, 0.64, 1.01
    from tau 0.005), from BGN's tangential equilibrium it is 3 (3.08, 3.32); every run's
    area decreases at every step."""
    V, F = icosphere(2)
    taus = [0.005, 0.0025, 0.00125]

    def final(tau):
        flow = BGNBDFFlow(V, F, tau, order=3, start="equilibrium")
        shrinking(flow, round(0.04 / tau))
        assert flow.equilibrated
        return volume(flow.vertices, F)

    reference = final(taus[-1] / 8)
    errors = np.array([abs(final(tau) - reference) for tau in taus])
    orders = eoc(errors)[1:]
    assert np.all((orders > 2.7) & (orders < 3.6)), (errors, orders)


def test_the_equilibrium_start_relaxes_x0_along_the_surface_and_then_extrapolates():
    """``start="equilibrium"``: ``X^0`` moved along the surface to (E2) (the next
    iteration (E3) moves no vertex by 1e-10 of the edge scale; the area not grown),
    ``X^1`` Richardson's ``2 Z - W`` from there, which is the history of step 2; a mesh at
    the equilibrium already (the level-1 icosphere, by symmetry) starts as
    ``"richardson"``, bitwise."""
    V, F = icosphere(2)
    flow = BGNBDFFlow(V, F, 0.001, order=3, start="equilibrium")
    Euler().step(flow, EXACT)
    assert flow.equilibrated
    X0 = flow._past[0]
    moved = X0 - V.T
    assert 1e-3 < np.abs(moved).max() < 0.05
    nu = V / np.linalg.norm(V, axis=1, keepdims=True)
    # along the surface: the radial part is of second order in the moves (measured
    # 2.7e-4 for moves of up to 0.017, each iterate's tangential to its own normals)
    radial = np.abs(np.einsum("kc,ck->k", nu, moved))
    assert radial.max() < 0.05 * np.abs(moved).max()
    g = flow.geometry_at(X0)
    D = tangential_increment(flow.assembler.laplacian(g.L_data), flow._normals(g), X0,
                             ~flow.fixed)
    assert np.abs(D).max() < 1e-10 * np.sqrt(area(X0.T, F) / len(V))
    assert area(X0.T, F) <= area(V, F)
    W = BGNBDFFlow(X0.T, F, 0.001, order=3, start="richardson")
    Euler().step(W, EXACT)
    np.testing.assert_allclose(flow.state, W.state, rtol=0, atol=1e-13)
    V1, F1 = icosphere(1)
    a = BGNBDFFlow(V1, F1, 0.01, order=3, start="equilibrium")
    b = BGNBDFFlow(V1, F1, 0.01, order=3, start="richardson")
    for _ in range(3):
        Euler().step(a, EXACT)
        Euler().step(b, EXACT)
    assert a.equilibrated
    np.testing.assert_array_equal(a.state, b.state)


def test_the_equilibrium_start_falls_back_to_bgn_where_it_diverges():
    """The committed nut: BGN's tangential motion without normal motion (E3) does not
    converge (its iterates move vertices by more than a unit); the run starts as
    ``"bgn"`` from ``X^0``, bitwise, and says so (``equilibrated`` False)."""
    V, F = read_committed_mesh("nut")
    h = np.linalg.norm(V[F[:, 1]] - V[F[:, 0]], axis=1).mean()
    a = BGNBDFFlow(V, F, 0.1 * h * h, order=3, start="equilibrium")
    b = BGNBDFFlow(V, F, 0.1 * h * h, order=3, start="bgn")
    for _ in range(2):
        Euler().step(a, EXACT)
        Euler().step(b, EXACT)
    assert a.equilibrated is False
    np.testing.assert_array_equal(a.state, b.state)


@pytest.mark.parametrize("order", [2, 3])
def test_the_area_never_grows_where_bgn_moves_vertices_tangentially(noisy_sphere, order):
    """The noisy level-2 sphere (BGN's first steps move its vertices along the
    surface by an amount that does not vanish with tau), tau 0.001 and 0.0002:
    the area decreases at every step."""
    V, F = noisy_sphere
    for tau in (0.001, 0.0002):
        shrinking(BGNBDFFlow(V, F, tau, order=order), 40)


def test_the_start_and_the_solves_per_step(noisy_sphere):
    """X^1 is BGN's step, X^2 of k = 3 is BGN/BDF2's, bitwise; k solves a step once
    the history has k levels (1, 2, 3, 3)."""
    V, F = noisy_sphere
    bgn = BGNFlow(V, F, 0.01)
    Euler().step(bgn, EXACT)
    flows, counts = {}, {}
    for k in (2, 3):
        flow, counts[k] = BGNBDFFlow(V, F, 0.01, order=k), []
        for _ in range(4):
            counts[k].append(0)
            Euler().step(flow, counting(EXACT, counts[k]))
            flows[k, flow.n] = flow.state.copy()
    assert counts == {2: [1, 2, 2, 2], 3: [1, 2, 3, 3]}
    np.testing.assert_array_equal(flows[2, 1], bgn.state)
    np.testing.assert_array_equal(flows[3, 1], bgn.state)
    np.testing.assert_array_equal(flows[3, 2], flows[2, 2])
    assert np.abs(flows[3, 3] - flows[2, 3]).max() > 1e-6        # then BDF3 differs


def test_bdf_bases_are_exact_for_polynomials_and_keep_fixed_points():
    """delta_k X / tau = alpha_0 (X^{m+1} - B_k) / tau (J1) is exact for polynomials
    of degree k in t; a point equal at every level keeps its coordinates exactly."""
    rng = np.random.default_rng(5)
    tau = 0.1
    for k in (1, 2, 3):
        c = rng.standard_normal((k + 1, 3, 4))
        X = [sum(c[j] * (i * tau) ** j for j in range(k + 1)) for i in range(k + 1)]
        derivative = sum(j * c[j] * (k * tau) ** (j - 1) for j in range(1, k + 1))
        base, dt = bdf_base(k, X[k - 1], tuple(X[k - 2::-1]) if k > 1 else (), tau)
        np.testing.assert_allclose((X[k] - base) / dt, derivative, rtol=1e-12, atol=1e-12)
        still = np.full((3, 4), 0.3)
        np.testing.assert_array_equal(bdf_base(k, still, (still,) * (k - 1), tau)[0], still)


def test_steps_are_invariant_under_rigid_motions(noisy_sphere):
    V, F = noisy_sphere
    Q, _ = np.linalg.qr(np.random.default_rng(3).standard_normal((3, 3)))
    shift = np.array([0.3, -1.2, 2.0])
    for k in (2, 3):
        a = BGNBDFFlow(V, F, 0.01, order=k)
        b = BGNBDFFlow(V @ Q.T + shift, F, 0.01, order=k)
        for _ in range(4):
            Euler().step(a, EXACT)
            Euler().step(b, EXACT)
        np.testing.assert_allclose(b.vertices, a.vertices @ Q.T + shift, rtol=0, atol=1e-10)


def test_only_the_euler_integrator_steps_it_and_bad_orders():
    V, F = icosphere(1)
    with pytest.raises(ValueError, match="integrates in time itself"):
        BDF2().step(BGNBDFFlow(V, F, 0.01), EXACT)
    for order in (1, 4):
        with pytest.raises(ValueError, match="BGN/BDF-k is implemented for k in"):
            BGNBDFFlow(V, F, 0.01, order=order)
    with pytest.raises(ValueError, match="unknown start 'euler'"):
        BGNBDFFlow(V, F, 0.01, order=3, start="euler")


def test_registry_entries():
    from mcfbench.running.schemes import get_scheme

    V, F = icosphere(1)
    for k in (2, 3):
        entry = get_scheme(f"bgn-bdf{k}")
        flow = entry.make(V, F, 0.01)
        assert isinstance(flow, BGNBDFFlow) and flow.order == k and flow.scaling == "mass"
        assert flow.start == {2: "bgn", 3: "equilibrium"}[k]
        assert entry.integrates_itself and entry.integrator == "euler"
        with pytest.raises(ValueError, match="integrates in time itself"):
            get_scheme(f"bgn-bdf{k}@bdf2")
    assert not get_scheme("bgn").integrates_itself


@pytest.mark.parametrize("order", [2, 3])
def test_a_step_ends_at_a_predictor_that_vanished(order):
    """Radius 0.1 (extinction at t = 0.0025), tau 0.003: step 3's BGN predictor keeps
    1e-5 of the area (measured 1.80e-4 -> 9.4e-10): the step ends there, one solve,
    and that predictor is the state the harness reports as shrunk to a point; steps 1
    and 2 solve as always (1, 2)."""
    V, F = icosphere(1)
    flow, counts, areas = BGNBDFFlow(0.1 * V, F, 0.003, order=order), [], []
    for _ in range(3):
        counts.append(0)
        Euler().step(flow, counting(EXACT, counts))
        areas.append(area(flow.vertices, F))
    assert counts == [1, 2, 1]
    assert areas[2] < VANISHED * areas[1]
