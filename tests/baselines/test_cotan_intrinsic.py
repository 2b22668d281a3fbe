"""The cotangent scheme on the intrinsic Delaunay triangulation (baselines/cotan_intrinsic.py)."""

import numpy as np
import pytest
from conftest import cylinder, table_3_1_error, twin_sphere

from baselines.cotan import CotanFlow
from baselines.laplacian import cotangent_laplacian, lumped_mass
from baselines.cotan_intrinsic import FLIP_BELOW, IntrinsicCotanFlow, intrinsic_operators
from mcfbench.geometry.exact import eoc
from mcfbench.geometry.spheres import icosphere
from mcfbench.running.driver import simulate
from mcfbench.running.problems import get_problem
from mcfbench.running.run import problem_mesh
from mcfbench.running.solver import Solver, solve

EXACT = Solver(method="direct", rtol=1e-12)


def flipped_icosphere(level=2):
    """An icosphere with one edge flipped: the two new triangles fold across the old
    edge, whose opposite angles (each about 60 degrees) become the new edge's
    neighbours, so the new edge's opposite angles sum to about 240 degrees (not
    Delaunay: a negative cotangent weight)."""
    V, F = icosphere(level)
    F = F.copy()
    a, b, c = F[0]                                  # triangle (a, b, c), edge (a, b)
    k = next(i for i in range(1, len(F)) if {a, b} <= set(F[i]))
    d = next(v for v in F[k] if v not in (a, b))    # triangle (b, a, d)
    F[0], F[k] = (c, d, b), (d, c, a)               # edge (c, d), orientation kept
    return V, F


def assert_intrinsic_delaunay(L, mass, area):
    """Every edge weight ``(cot alpha + cot beta) / 2 = -L_ij`` of the triangulation is
    above the package's threshold (intrinsic Delaunay), ``L`` symmetric with zero row
    sums, the mass positive and summing to the surface's area."""
    off = L.tocoo()
    assert -off.data[off.row != off.col].max() >= FLIP_BELOW
    assert abs(L - L.T).max() < 1e-15 and np.abs(np.asarray(L.sum(axis=1))).max() < 1e-13
    assert mass.min() > 0 and mass.sum() == pytest.approx(area, rel=1e-13)


def mesh_area(V, F):
    return 0.5 * np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]),
                                axis=1).sum()


def assert_the_packages_operators(flow, F, atol):
    """The flow's operators at its state are the package's (stiffness to ``atol`` of its
    largest entry, mass to 1e-14) and intrinsic Delaunay."""
    L, mass = flow.operators()
    L_package, mass_package = intrinsic_operators(flow.X.T, F)
    np.testing.assert_allclose(L.toarray(), L_package.toarray(), rtol=0,
                               atol=atol * abs(L_package).max())
    np.testing.assert_allclose(mass, mass_package, rtol=1e-14)
    assert_intrinsic_delaunay(L, mass, mesh_area(flow.X.T, F))


def test_on_a_delaunay_mesh_the_operators_are_the_cotangent_ones():
    """Icosphere: ``L`` = the mesh's cotangent stiffness, the mass = its barycentric
    lumped mass (not the Voronoi one: they differ by 2e-3 at level 3)."""
    V, F = icosphere(3)
    L, mass = intrinsic_operators(V, F)
    np.testing.assert_allclose(L.toarray(), cotangent_laplacian(V, F).toarray(), rtol=0,
                               atol=1e-14)
    np.testing.assert_allclose(mass, lumped_mass(V, F), rtol=1e-14)
    assert np.abs(mass - lumped_mass(V, F, "voronoi")).max() > 1e-3


def test_on_a_delaunay_mesh_the_flow_is_cotan_with_barycentric_mass():
    V, F = icosphere(2)
    runs = [simulate(cls(V, F, 0.01), 8, solver=EXACT, save_every=0).frames["vertices"][-1]
            for cls in (IntrinsicCotanFlow, CotanFlow)]
    np.testing.assert_allclose(runs[0], runs[1], rtol=0, atol=1e-13)
    voronoi = simulate(CotanFlow(V, F, 0.01, mass="voronoi"), 8, solver=EXACT,
                       save_every=0).frames["vertices"][-1]
    assert np.abs(runs[0] - voronoi).max() > 1e-4


def test_on_a_non_delaunay_mesh_every_edge_weight_is_nonnegative():
    V, F = flipped_icosphere()
    L_mesh = cotangent_laplacian(V, F)
    assert L_mesh.tocoo().data.max() > 0.1             # a negative weight -L_ij < 0
    L, mass = intrinsic_operators(V, F)
    off = L.tocoo()
    assert off.data[off.row != off.col].max() <= 0.0
    assert_intrinsic_delaunay(L, mass, mesh_area(V, F))
    traj = simulate(IntrinsicCotanFlow(V, F, 0.001), 10, solver=EXACT, save_every=0)
    assert traj.status == "ok", traj.message


def test_order_2_on_the_sphere():
    """Table 3.1 setting, levels 1-3: L2 1.4464e-2, 3.3985e-3, 8.2796e-4 (EOC 2.09,
    2.04), cotan's values."""
    errors = [table_3_1_error(IntrinsicCotanFlow, level, EXACT)[0] for level in (1, 2, 3)]
    np.testing.assert_allclose(errors, [1.4464e-2, 3.3985e-3, 8.2796e-4], rtol=1e-4)
    orders = eoc(np.array(errors))[1:]
    assert np.all((orders > 2.0) & (orders < 2.15)), orders


def test_open_cylinder_keeps_its_boundary_and_follows_cotan_to_the_catenoid():
    """The 24 x 8 cylinder is Delaunay (its tufted Laplacian is the mesh's cotangent
    one to 4e-15), so the flow is cotan's, whose approach to the catenoid
    tests/baselines/test_cotan.py checks; the boundary stays exactly fixed."""
    V, F = cylinder(24, 8)
    flow = IntrinsicCotanFlow(V, F, 0.005)
    traj = simulate(flow, 200, solver=EXACT, save_every=50)
    cotan = simulate(CotanFlow(V, F, 0.005), 200, solver=EXACT, save_every=50)
    assert traj.status == "ok", traj.message
    for frame in traj.frames["vertices"]:
        np.testing.assert_array_equal(frame[flow.fixed], V[flow.fixed])
    np.testing.assert_allclose(traj.frames["vertices"], cotan.frames["vertices"], rtol=0, atol=1e-12)


def test_twin_point_sphere_completes_where_cotan_inverts():
    """The sliver-rich twin-point sphere, n = 162, tau = 0.01 towards t = 0.24
    (extinction 0.25), sparse LU at rtol 1e-9: cotan inverts at step 22, the intrinsic Laplacian
    completes the 24 steps (mean radius 0.296; the exact sphere's 0.2)."""
    V, F = twin_sphere()
    runs = [simulate(cls(V, F, 0.01), 24, solver=Solver("direct"), save_every=0)
            for cls in (CotanFlow, IntrinsicCotanFlow)]
    assert (runs[0].status, runs[0].steps_done) == ("inverted", 22)
    assert (runs[1].status, runs[1].steps_done) == ("ok", 24)
    assert np.linalg.norm(runs[1].frames["vertices"][-1], axis=1).mean() == pytest.approx(0.296,
                                                                                  abs=1e-3)


@pytest.mark.parametrize("mollify", [-1.0, np.nan, np.inf])
def test_bad_mollify_is_named(mollify):
    with pytest.raises(ValueError, match="mollify must be a finite number >= 0"):
        IntrinsicCotanFlow(*icosphere(1), 0.01, mollify=mollify)


def planar_quad(weight):
    """Two triangles on the edge (0, 1) from (-1, 0) to (1, 0), apexes (0, +-c): the edge's
    weight ``(cot alpha + cot beta) / 2 = (c^2 - 1) / (2 c)`` set to ``weight``."""
    c = weight + np.sqrt(weight ** 2 + 1.0)
    V = np.array([[-1.0, 0, 0], [1, 0, 0], [0, c, 0], [0, -c, 0]])
    return V, np.array([[0, 1, 2], [1, 0, 3]])


@pytest.mark.parametrize("weight, flips", [(0.3, 0), (-2e-7, 0), (-8e-7, 0), (-3e-6, 1),
                                           (-0.3, 1)])
def test_the_mesh_operators_flip_exactly_where_the_package_does(weight, flips):
    """The package keeps an edge of weight above ``FLIP_BELOW`` = -1e-6 (-8e-7: kept) and
    flips one below (-3e-6: the other diagonal gets the weight ``3e-6``); so do the
    mesh's operators (:meth:`FlipPattern.flip`, a flip next to the boundary, whose edges
    count twice in the tufted cover), and they are the package's to round-off."""
    V, F = planar_quad(weight)
    flow = IntrinsicCotanFlow(V, F, 0.01)
    L, mass = intrinsic_operators(V, F)
    kept = L[0, 1] == pytest.approx(-weight, rel=1e-6)         # L_ab = -weight
    assert kept == (weight > FLIP_BELOW)
    assert kept or L[2, 3] == pytest.approx(weight, rel=1e-6)
    flip, _, _ = flow.flips.flip(V)
    assert len(flip) == flips
    L_flow, mass_flow = flow.operators()
    np.testing.assert_allclose(L_flow.toarray(), L.toarray(), rtol=0, atol=1e-15)
    np.testing.assert_allclose(mass_flow, mass, rtol=1e-15)


def test_a_sliver_within_the_mollification_margin_is_mollified_as_the_package_does():
    """A vertex of the level-2 icosphere moved next to the midpoint of its triangle's
    opposite side (a fraction ``s`` of its height left): at ``s = 1e-3`` the triangle is
    within the margin (1e-5 x the mean edge length), every length grows by ``epsilon``
    = 2.68e-6 (the package's ``mollifyIntrinsic``), at ``s = 0.1`` it is not (0); both
    times the operators are the package's to round-off, one edge flipped."""
    V, F = icosphere(2)
    p, q, r = F[0]
    for s, epsilon in [(1e-3, 2.685e-6), (0.1, 0.0)]:
        W = V.copy()
        W[p] = (1 - s) * (V[q] + V[r]) / 2 + s * V[p]
        flow = IntrinsicCotanFlow(W, F, 0.01)
        L, mass = flow.operators()
        assert (flow.flips.flip_count, flow.flips.epsilon) == (1, pytest.approx(epsilon,
                                                                              rel=1e-3, abs=0))
        L_package, mass_package = intrinsic_operators(W, F)
        np.testing.assert_allclose(L.toarray(), L_package.toarray(), rtol=0,
                                   atol=1e-13 * abs(L_package).max())
        np.testing.assert_allclose(mass, mass_package, rtol=1e-14)


def test_one_flip_back_to_the_icosphere_is_the_packages_triangulation():
    """The icosphere with one edge flipped (weight about -0.6): that edge is the one to
    flip, and the operators of the flipped mesh (the edge's new length that of the
    two triangles unfolded, not the chord of the icosphere) are the package's to
    round-off; so are the flow's states, step by step."""
    V, F = flipped_icosphere()
    flow = IntrinsicCotanFlow(V, F, 0.001)
    flip, _, _ = flow.flips.flip(V)
    assert len(flip) == 1 and set(flow.mesh.edges[flip[0]]) == set(F[0][:2])
    L, mass = flow.operators()
    L_package, mass_package = intrinsic_operators(V, F)
    np.testing.assert_allclose(L.toarray(), L_package.toarray(), rtol=0, atol=1e-14)
    np.testing.assert_allclose(mass, mass_package, rtol=1e-14)
    traj = simulate(flow, 10, solver=EXACT, save_every=1)
    assert flow.flipped_steps == 10
    package = IntrinsicCotanFlow(V, F, 0.001)
    package._mesh_operators = lambda at: None
    reference = simulate(package, 10, solver=EXACT, save_every=1)
    np.testing.assert_allclose(traj.frames["vertices"], reference.frames["vertices"], rtol=0,
                               atol=1e-14)


def test_along_the_catenoid_flow_every_step_takes_the_mesh_operators():
    """The open 24 x 8 cylinder stays Delaunay along its flow to the catenoid: all 200
    systems from the mesh, the trajectory the package's to round-off (a run that calls
    the package at every step: its test of the mesh made to refuse)."""
    V, F = cylinder(24, 8)
    fast = IntrinsicCotanFlow(V, F, 0.005)
    traj = simulate(fast, 200, solver=EXACT, save_every=50)
    assert fast.delaunay_steps == 200
    slow = IntrinsicCotanFlow(V, F, 0.005)
    slow._mesh_operators = lambda at: None
    reference = simulate(slow, 200, solver=EXACT, save_every=50)
    assert slow.delaunay_steps == 0
    np.testing.assert_allclose(traj.frames["vertices"], reference.frames["vertices"], rtol=0,
                               atol=1e-13)


def test_the_catenoids_flips_are_the_packages_intrinsic_delaunay_triangulation():
    """Along the registry's catenoid at level 1 (216 vertices, 60 steps) the mesh's
    rectangles' diagonals (weight 0 at ``t = 0``) turn non-Delaunay, all 192 of them every
    other step at first: the compiled flips (:func:`flip_to_delaunay`) give the
    systems of 42 steps, each of its states' operators is intrinsic Delaunay and the
    package's to round-off, and the trajectory is that of a run that calls the package
    at every step to 1e-12."""
    catenoid = get_problem("catenoid")
    V, F = problem_mesh(catenoid, 1)
    tau = catenoid.tau(1, (V, F))
    fast = IntrinsicCotanFlow(V, F, tau)
    flips = []
    for _ in range(60):
        flip, _, _ = fast.flips.flip(fast.X.T)
        flips.append(len(flip))
        assert_the_packages_operators(fast, F, 4e-15)
        A, b = fast.system()
        fast.advance(solve(A, b, b, method="direct", rtol=1e-12)[0])
    assert (fast.delaunay_steps, fast.flipped_steps) == (18, 42)
    assert flips[:4] == [0, 192, 0, 192] and max(flips) == 192     # every rectangle's
    slow = IntrinsicCotanFlow(V, F, tau)
    slow._mesh_operators = lambda at: None
    reference = simulate(slow, 60, solver=EXACT, save_every=0)
    np.testing.assert_allclose(fast.X.T, reference.frames["vertices"][-1], rtol=0, atol=1e-12)


def planar_fan():
    """Triangle (0, 1, 2) between (1, 0, 3) and (2, 1, 4) in the plane, both of its
    interior edges non-Delaunay (opposite angles 112 + 157 and 23 + 172 degrees)."""
    V = np.array([[0.0, 0, 0], [1, 0, 0], [0.7, 0.3, 0], [0.5, -0.1, 0], [0.87, 0.17, 0]])
    return V, np.array([[0, 1, 2], [1, 0, 3], [2, 1, 4]])


def flat_tetrahedron():
    """A tetrahedron whose edge (0, 1) has opposite angles of 145 degrees each: its flip
    makes a second edge (2, 3) beside the one it already has."""
    V = np.array([[-1.0, 0, 0], [1, 0, 0], [0, 0.3, 0.1], [0, -0.3, 0.1]])
    return V, np.array([[0, 1, 2], [1, 0, 3], [0, 2, 3], [1, 3, 2]])


def test_a_flip_onto_an_existing_edge_is_the_packages():
    """The flat tetrahedron's flip gives the vertices 2 and 3 two edges, whose weights
    the entry (2, 3) sums, as the package's: its operators to round-off."""
    V, F = flat_tetrahedron()
    flow = IntrinsicCotanFlow(V, F, 0.01)
    flip, _, _ = flow.flips.flip(V)
    assert flow.mesh.edges[flip].tolist() == [[0, 1]] and flow.flips.flip_count == 1
    L, mass = flow.operators()
    L_package, mass_package = intrinsic_operators(V, F)
    assert L_package[2, 3] == pytest.approx(-2.9487, abs=1e-4)
    np.testing.assert_allclose(L.toarray(), L_package.toarray(), rtol=0, atol=1e-15)
    np.testing.assert_allclose(mass, mass_package, rtol=1e-15)


def test_a_boundary_edge_to_flip_is_left_to_the_package():
    """The fan's flips leave a boundary edge below the threshold, which the tufted cover
    flips: no compiled operators (None), the flow takes the package's, every weight
    >= the threshold."""
    V, F = planar_fan()
    flow = IntrinsicCotanFlow(V, F, 0.01)
    weights = -flow.geometry.L_data[flow.assembler.pattern.edge_slots[:, 0]]
    assert np.sum(weights < FLIP_BELOW) == 2
    assert flow.flips.flip(V) is None
    L, mass = flow.operators()
    L_package, mass_package = intrinsic_operators(V, F)
    np.testing.assert_array_equal(L.toarray(), L_package.toarray())
    np.testing.assert_array_equal(mass, mass_package)
    off = L.tocoo()
    assert -off.data[off.row != off.col].min() >= FLIP_BELOW
    flow.system()
    assert (flow.delaunay_steps, flow.flipped_steps) == (0, 0)


def test_along_a_real_meshs_flow_the_compiled_flips_are_the_packages():
    """The noisy sphere at level 0 (482 vertices): at ``t = 0`` 107 edges to flip, 14
    triangles with two of them, 118 flips (some edges flip again); along 12 steps every
    system comes from the compiled flips, each state's operators are intrinsic Delaunay
    and the package's to round-off, and the trajectory is that of a run that calls the
    package at every step to 1e-12."""
    problem = get_problem("real_noisy_sphere")
    V, F = problem_mesh(problem, 0)
    tau = problem.tau(0, (V, F))
    fast = IntrinsicCotanFlow(V, F, tau)
    weights = -fast.geometry.L_data[fast.assembler.pattern.edge_slots[:, 0]]
    sides = fast.mesh.edge_faces[weights < FLIP_BELOW].ravel()
    assert len(sides) // 2 == 107 and np.sum(np.bincount(sides) == 2) == 14
    for step in range(12):
        assert_the_packages_operators(fast, F, 5e-14)
        assert step or fast.flips.flip_count == 118
        A, b = fast.system()
        fast.advance(solve(A, b, b, method="direct", rtol=1e-12)[0])
    assert (fast.delaunay_steps, fast.flipped_steps) == (0, 12)
    slow = IntrinsicCotanFlow(V, F, tau)
    slow._mesh_operators = lambda at: None
    reference = simulate(slow, 12, solver=EXACT, save_every=0)
    np.testing.assert_allclose(fast.X.T, reference.frames["vertices"][-1], rtol=0, atol=1e-12)
