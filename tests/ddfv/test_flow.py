"""The DDFV flow (ddfv/flow.py): stepping (2.1), boundary (1.2), elimination (3.6), defects."""

import numpy as np
import pytest
from conftest import cylinder

from ddfv import Flow
from ddfv.geometry import covolume_areas, diamond_geometry
from ddfv.topology import diamond_mesh
from mcfbench.geometry import surfaces
from mcfbench.geometry.metrics import catenoid_parameter
from mcfbench.geometry.shapes import hemisphere
from mcfbench.geometry.spheres import icosphere
from mcfbench.running.driver import simulate as drive
from mcfbench.running.integrators import Euler
from mcfbench.running.solver import Solver

TIGHT = dict(rtol=1e-13, t_init="paper")


def simulate(V, F, tau, steps, *, save_every=1, rtol=1e-9, maxiter=1000, collapse=True,
             **options):
    """The DDFV flow driven by the harness; frames as ``traj.F``, ``traj.T``."""
    traj = drive(Flow(V, F, tau, **options), steps, save_every=save_every,
                 solver=Solver(rtol=rtol, maxiter=maxiter), collapse=collapse)
    traj.F, traj.T = traj.frames["vertices"], traj.frames["extra_points"]
    return traj


def _rotation(seed=0):
    q, _ = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))
    return q * np.sign(np.linalg.det(q))


def _run(V, F, tau=0.002, steps=6, **options):
    return simulate(V, F, tau, steps, **{**TIGHT, **options})


def test_trajectory_invariant_under_rigid_motion(bumpy):
    V, F = bumpy
    Q, shift = _rotation(), np.array([0.3, -2.0, 1.5])
    ref, moved = _run(V, F), _run(V @ Q.T + shift, F)
    np.testing.assert_allclose(moved.F, ref.F @ Q.T + shift, atol=1e-11)
    np.testing.assert_allclose(moved.T, ref.T @ Q.T + shift, atol=1e-11)


def test_trajectory_invariant_under_scaling_with_tau_times_s2(bumpy):
    V, F = bumpy
    s = 3.0
    ref, scaled = _run(V, F), _run(s * V, F, tau=0.002 * s**2)
    np.testing.assert_allclose(scaled.F, s * ref.F, atol=1e-10 * s)
    np.testing.assert_allclose(scaled.T, s * ref.T, atol=1e-10 * s)


def test_public_arrays_are_in_the_callers_numbering(bumpy):
    V, F = bumpy
    T0 = V[F].mean(axis=1) + 1e-3 * np.arange(len(F))[:, None]
    flow = Flow(V, F, 0.01, T0=T0)
    np.testing.assert_array_equal(flow.F, V)
    np.testing.assert_array_equal(flow.T, T0)
    np.testing.assert_array_equal(flow.X, np.concatenate([V, T0]).T)
    np.testing.assert_array_equal(flow.faces, F)
    assert not flow.X.flags.writeable
    frame = flow.frame()
    np.testing.assert_array_equal(frame["vertices"], V)
    mesh = diamond_mesh(F, len(V))
    chi_f, chi_t = covolume_areas(mesh, diamond_geometry(mesh, V, T0))
    np.testing.assert_allclose(flow.covolumes, np.r_[chi_f, chi_t], rtol=1e-13)


def test_public_arrays_are_copies_of_the_current_state(bumpy):
    """Writing into the arrays that F and T return leaves the flow's state alone; after
    a step F, T and X are those of the new state."""
    V, F = bumpy
    flow = Flow(V, F, 0.01)
    T0 = flow.T.copy()
    F1, T1 = flow.F, flow.T
    F1[:] = 0.0
    T1[:] = 0.0
    np.testing.assert_array_equal(flow.F, V)
    np.testing.assert_array_equal(flow.T, T0)
    flow.advance(2.0 * flow.state)
    X = flow.X
    np.testing.assert_array_equal(flow.F, 2.0 * V)
    np.testing.assert_array_equal(X[:, :len(V)].T, flow.F)
    np.testing.assert_array_equal(X[:, len(V):].T, flow.T)


def test_the_mesh_vertices_are_gathered_once_per_state(bumpy):
    """``vertices`` (what the driver's checks and the observers read every step) is one
    read-only array per state, the state's F-vertices, gathered anew after a step."""
    V, F = bumpy
    flow = Flow(V, F, 0.01)
    first = flow.vertices
    assert flow.vertices is first and not first.flags.writeable
    np.testing.assert_array_equal(first, V)
    flow.advance(2.0 * flow.state)
    assert flow.vertices is not first
    np.testing.assert_array_equal(flow.vertices, 2.0 * V)
    np.testing.assert_array_equal(first, V)


def test_trajectory_invariant_under_relabelling(bumpy):
    V, F = bumpy
    rng = np.random.default_rng(5)
    pv, pt = rng.permutation(len(V)), rng.permutation(len(F))
    new_index = np.empty_like(pv)
    new_index[pv] = np.arange(len(V))           # old vertex pv[k] becomes k
    F2 = np.roll(new_index[F[pt]], 1, axis=1)   # renumbered, reordered, rotated
    ref, relabelled = _run(V, F), _run(V[pv], F2)
    np.testing.assert_allclose(relabelled.F, ref.F[:, pv], atol=1e-11)
    np.testing.assert_allclose(relabelled.T, ref.T[:, pt], atol=1e-11)


@pytest.mark.parametrize("radius", [0.5, 2.0])
def test_sphere_radius_follows_exact_solution(radius):
    V, F = icosphere(3, radius)
    tau = 0.0025 * radius**2
    steps = 40                                        # t = 0.1 R^2: r = 0.775 R
    traj = simulate(V, F, tau, steps, save_every=10)
    exact = np.sqrt(radius**2 - 4 * traj.t)
    r_f = np.linalg.norm(traj.F, axis=2).mean(axis=1)
    r_t = np.linalg.norm(traj.T, axis=2).mean(axis=1)
    # level 3: the error grows to 0.30 % at t = 0.1 R^2 (the radius shrinks 22 %)
    np.testing.assert_allclose(r_f, exact, rtol=5e-3)
    np.testing.assert_allclose(r_t, exact, rtol=5e-3)
    assert traj.status == "ok" and len(traj.t) == 5


def test_frames_follow_save_every(bumpy):
    V, F = bumpy
    traj = simulate(V, F, 0.001, 7, save_every=3)
    np.testing.assert_array_equal(traj.steps, [0, 3, 6, 7])
    np.testing.assert_allclose(traj.t, traj.steps * 0.001)
    assert traj.F.shape == (4, len(V), 3) and traj.T.shape == (4, len(F), 3)
    assert len(traj.iterations) == 7
    np.testing.assert_array_equal(traj.F[0], V)


def test_solver_failure_is_reported_and_keeps_frames(bumpy):
    V, F = bumpy
    traj = simulate(V, F, 0.01, 5, rtol=1e-15, maxiter=1)
    assert traj.status == "solver_failed" and traj.failed_step == 1
    assert traj.message.startswith("solver_failed at step 1 (t = 0.01): ")
    assert "relative residual" in traj.message and "iteration limit 1" in traj.message
    assert len(traj.t) == 1 and np.array_equal(traj.F[0], V)


def test_collapse_to_a_point_is_detected():
    """DDFV's own check of its diamonds (the driver's check of the components, which
    fires first, turned off)."""
    V, F = icosphere(2, 0.3)                 # extinction at t = 0.0225
    traj = simulate(V, F, 0.005, 20, collapse=False)
    assert traj.status == "degenerated"
    assert traj.message.startswith(f"degenerated at step {traj.failed_step}")
    assert "diamond cell(s) collapsed" in traj.message
    assert 5 <= traj.failed_step < 20
    assert traj.steps[-1] == traj.failed_step and len(traj.t) == traj.failed_step + 1


def test_t_vertex_escape_is_named_with_step_triangle_and_coordinate():
    """The cylinder of Fig. 3.6: without (3.6) a T-vertex leaves its triangle at n = 592."""
    from mcfbench.geometry.surfaces import make_surface
    from mcfbench.studies.figures.experiments import EXPERIMENTS

    run = EXPERIMENTS["fig_3_6"].runs[0]
    V, F = make_surface(run.shape, **run.params)
    traj = simulate(V, F, 0.0025, 640, save_every=0)
    assert traj.status == "t_escaped" and traj.failed_step == 592
    assert traj.message.startswith("t_escaped at step 592 (t = 1.48): the T-vertex of triangle ")
    assert "barycentric coordinate -" in traj.message
    recorded = drive(Flow(V, F, 0.0025), 640, save_every=0, on_defect="record")
    assert recorded.status == "t_escaped" and recorded.steps_done == 640
    assert recorded.defects[0]["step"] == 592


def test_boundary_vertices_stay_fixed():
    V, F = cylinder(16, 6)
    traj = simulate(V, F, 0.002, 10, save_every=5)
    fixed = diamond_mesh(F).boundary_vertices
    assert traj.status == "ok"
    np.testing.assert_array_equal(traj.F[-1][fixed], V[fixed])
    assert np.abs(traj.F[-1][~fixed] - V[~fixed]).max() > 1e-3


def test_elimination_keeps_t_vertices_inside_their_triangles():
    """Section 3.3: the cylinder's T-vertices drift without (3.6), not with it."""
    V, F = cylinder(24, 8)
    monitor = []
    flow = Flow(V, F, 0.0025, tangential="eliminate")
    eliminated = drive(flow, 800, save_every=0,
                       observers=[lambda f: monitor.append(f.t_min_barycentric())])
    assert eliminated.status == "ok" and min(monitor) > 0.25
    assert simulate(V, F, 0.0025, 800, save_every=0).status == "t_escaped"


@pytest.mark.parametrize("dual_length", ["broken", "chord"])
@pytest.mark.parametrize("surface", ["bumpy", "hemisphere"])
def test_elimination_right_hand_side_is_numpys_bitwise(surface, dual_length, request):
    """(3.6) in one compiled pass (Flow._eliminated): numpy's ``h = (X* - A X*) / dt``,
    ``B - dt (h - (h.N) N)`` bit for bit, at a state, base and step of their own (as
    BDF2 asks) and with Dirichlet rows (the hemisphere's equator)."""
    from ddfv.geometry import vertex_normals

    V, F = request.getfixturevalue("bumpy") if surface == "bumpy" else hemisphere(rings=4)
    flow = Flow(V, F, 0.002, tangential="eliminate", dual_length=dual_length)
    rng = np.random.default_rng(3)
    at = flow.state + 0.01 * rng.standard_normal(flow.state.shape)
    base, dt = flow.state + 0.01 * rng.standard_normal(flow.state.shape), 0.0013
    A, rhs = flow.system(at, base, dt)
    h = (at - (A @ at.T).T) / dt
    N = vertex_normals(flow._mesh, flow._geometry_at(at)[0])
    assert np.array_equal(rhs, base - dt * (h - (h * N).sum(axis=0) * N))
    assert not np.array_equal(rhs, base)


@pytest.mark.parametrize("surface", ["bumpy", "hemisphere"])
def test_squared_normal_speed_is_numpys(surface, request):
    """The redistribution's ``h.V = (h.N)^2`` (R3) in one compiled pass
    (``squared_normal_speed_kernel``): numpy's ``h = (X* - A X*) / dt`` and ``((h * N)
    .sum(axis=0))^2`` bit for bit (the components summed in order), zero on the
    Dirichlet rows (the hemisphere's equator)."""
    from ddfv.geometry import vertex_normals
    from ddfv.tangential_kernels import squared_normal_speed_kernel

    V, F = request.getfixturevalue("bumpy") if surface == "bumpy" else hemisphere(rings=4)
    flow = Flow(V, F, 0.002, tangential="eliminate", dual_length="chord")  # keeps u, v
    at = flow.state + 0.01 * np.random.default_rng(5).standard_normal(flow.state.shape)
    A, _ = flow.system(at, at, 0.0013)
    N = vertex_normals(flow._mesh, flow._geometry_at(at)[0])
    out = np.empty(A.shape[0])
    squared_normal_speed_kernel(A.indptr, A.indices, A.data, flow._assembler._diag, at, N,
                                0.0013, np.empty(0), out, np.empty(0))
    h = (at - (A @ at.T).T) / 0.0013
    assert np.array_equal(out, ((h[0] * N[0] + h[1] * N[1]) + h[2] * N[2]) ** 2)
    fixed = flow._mesh.boundary_vertices
    assert (surface == "hemisphere") == fixed.any() and not out[:flow._mesh.n_f][fixed].any()
    assert out[:flow._mesh.n_f][~fixed].min() > 0.0


@pytest.mark.parametrize("options, message", [
    (dict(tau=0.0), "tau must be a positive number"),
    (dict(tau=float("nan")), "tau must be a positive number"),
    (dict(t_init="middle"), "unknown T-vertex initialisation"),
    (dict(tangential="some"), "unknown tangential"),
    (dict(T0=np.zeros((3, 3))), "T0 must have shape"),
])
def test_bad_settings_are_named(bumpy, options, message):
    V, F = bumpy
    with pytest.raises(ValueError, match=message):
        Flow(V, F, **{"tau": 0.01, **options})


def test_degenerate_initial_t_vertices_are_a_defect_at_step_0(bumpy):
    V, F = bumpy
    mesh = diamond_mesh(F)
    a, b, t1, t2 = mesh.diamonds[0]
    T0 = V[F].mean(axis=1)
    T0[t1] = T0[t2] = (V[a] + V[b]) / 2          # v = 0: the diamond collapses
    assert Flow(V, F, 0.01, T0=T0).defects() == [
        ("degenerated", f"1 diamond cell(s) collapsed, e.g. diamond cell of edge "
                        f"({min(a, b)}, {max(a, b)})")]
    traj = simulate(V, F, 0.01, 3, T0=T0)
    assert traj.status == "degenerated" and traj.failed_step == 0 and traj.steps_done == 0


def test_paper_initialisation_keeps_t_vertices_in_their_triangles():
    """On a coarse sharp mesh (a cube split twice) the osculating-sphere recipe would
    put T-vertices outside their triangles; those keep the barycentre."""
    from mcfbench.geometry.spheres import subdivide

    V = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)
    F = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                  [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])
    for _ in range(2):
        V, F = subdivide(V, F)
    flow = Flow(V, F, 0.001)
    assert flow.t_min_barycentric() >= 0.0
    assert flow.defects() == []


# -- open surfaces against their exact steady states (Dirichlet boundary (1.2)) --


def twisted_cylinder(segments=24, bands=8, radius=1.0, half_height=0.55):
    """The cylinder of Figs. 3.5-3.7: rings turned by half a segment."""
    return surfaces.cylinder(segments, bands, radius, half_height, diagonals="twisted")


@pytest.mark.parametrize("segments, bands, radius, half_height", [(32, 12, 1.0, 0.5),
                                                                  (32, 12, 1.5, 0.9)])
def test_cylinder_converges_to_the_catenoid(segments, bands, radius, half_height):
    """h/R < 0.66: the steady state is r(z) = a cosh(z/a), a cosh(h/a) = R."""
    V, F = twisted_cylinder(segments, bands, radius, half_height)
    tau = 0.005 * radius**2
    traj = simulate(V, F, tau, 240, save_every=0, tangential="eliminate")
    assert traj.status == "ok", traj.message
    a = catenoid_parameter(radius, half_height)
    X = traj.F[-1]
    r, z = np.hypot(X[:, 0], X[:, 1]), X[:, 2]
    neck = r[np.abs(z) < 1e-9 * radius]
    assert len(neck) == segments
    np.testing.assert_allclose(neck, a, rtol=0.01)
    np.testing.assert_allclose(r, a * np.cosh(z / a), atol=0.01 * radius)


def test_catenoid_error_decreases_under_refinement():
    errors = []
    for segments, bands in ((16, 6), (32, 12)):
        traj = simulate(*twisted_cylinder(segments, bands, 1.0, 0.5), 0.005, 240,
                        save_every=0, tangential="eliminate")
        X = traj.F[-1]
        errors.append(abs(np.hypot(X[:, 0], X[:, 1])[np.abs(X[:, 2]) < 1e-9].mean()
                          - catenoid_parameter(1.0, 0.5)))
    assert errors[1] < 0.5 * errors[0]


def test_hemisphere_with_fixed_equator_converges_to_the_disk():
    V, F = hemisphere(rings=6)
    boundary = diamond_mesh(F, len(V)).boundary_vertices
    traj = simulate(V, F, 0.005, 400, save_every=0, tangential="eliminate")
    assert traj.status == "ok", traj.message
    X, T = traj.F[-1], traj.T[-1]
    np.testing.assert_array_equal(X[boundary], V[boundary])
    assert np.abs(X[:, 2]).max() < 1e-3 and np.abs(T[:, 2]).max() < 1e-3
    assert np.hypot(X[:, 0], X[:, 1]).max() <= 1.0 + 1e-12


def test_boundary_vertices_stay_fixed_without_elimination():
    V, F = twisted_cylinder()
    boundary = diamond_mesh(F, len(V)).boundary_vertices
    traj = simulate(V, F, 0.0025, 40, save_every=20)
    for X in traj.F:
        np.testing.assert_array_equal(X[boundary], V[boundary])


def test_t_monitor_and_state_checks_reuse_the_kernels_minimum():
    """t_min_barycentric is barycentric.min() (taken in the kernel's pass), and the
    warm start with the solver iterating in its own buffer keeps the states."""
    V, F = icosphere(2)
    flow, stepper = Flow(V, F, 0.001), Euler()
    for _ in range(3):
        stepper.step(flow, Solver())
        assert flow.defects() == []
        assert flow.t_min_barycentric() == float(flow.barycentric.min())
    other, stepper = Flow(V, F, 0.001), Euler()
    for _ in range(3):
        stepper.step(other, lambda A, b, x0: Solver()(A, b, x0))   # a plain callable: copies
    np.testing.assert_array_equal(flow.X, other.X)


def test_threaded_passes_agree_with_one_thread(bumpy):
    """threads=2: the per-diamond and per-triangle passes are the same
    arithmetic; the scatters add the diamonds across blocks last (round-off)."""
    V, F = bumpy
    one, two = Flow(V, F, 0.002), Flow(V, F, 0.002, threads=2)
    for name in ("J", "uv", "len_u", "gamma_t"):
        np.testing.assert_array_equal(getattr(two._geometry, name),
                                      getattr(one._geometry, name))
    np.testing.assert_allclose(two.covolumes, one.covolumes, rtol=1e-14)
    np.testing.assert_array_equal(two.barycentric, one.barycentric)
    assert two.t_min_barycentric() == one.t_min_barycentric()
    A1 = one._assembler.system(one._geometry, one._chi, one.tau)
    A2 = two._assembler.system(two._geometry, two._chi, two.tau, threads=2)
    np.testing.assert_allclose(A2.toarray(), A1.toarray(), rtol=1e-13, atol=1e-15)
    solve, step_one, step_two = Solver(), Euler(), Euler()
    for _ in range(5):
        step_one.step(one, solve)
        step_two.step(two, solve)
    np.testing.assert_allclose(two.X, one.X, atol=1e-12)


@pytest.mark.parametrize("threads", [0, 1.5, True, 10**6])
def test_bad_thread_counts_are_refused(bumpy, threads):
    with pytest.raises(ValueError, match="threads"):
        Flow(*bumpy, 0.01, threads=threads)
