"""The one measuring pass of the driver's checks (mcfbench/geometry/measures.py) against
the separate numpy evaluations of what it measures, on the states the checks exist
for: a folded mesh, a collapsed component, a grown area, a collapsed smallest angle,
non-finite coordinates; and the checks fed one shared measurement against the checks
measuring on their own."""

import numpy as np
import pytest

from mcfbench.geometry.collapse import CollapseCheck
from mcfbench.geometry.invariants import FlowInvariants
from mcfbench.geometry.measures import StateMeasures, vertex_components
from mcfbench.geometry.metrics import min_angle, neighbour_cosines, triangle_areas
from mcfbench.geometry.shapes import flat_patch
from mcfbench.geometry.spheres import icosphere


def two_spheres():
    """Unit sphere around the origin and a sphere of radius 0.3 around (3, 0, 0)."""
    V, F = icosphere(2)
    return np.vstack([V, 0.3 * V + [3.0, 0.0, 0.0]]), np.vstack([F, F + len(V)])


def states():
    """``(name, V0, F, V)``: an initial state and a later one of the same mesh."""
    V, F = two_spheres()
    folded = V.copy()
    i, j = F[0, :2]                               # a vertex moved past its neighbour
    folded[i] = V[j] + 0.5 * (V[j] - V[i])
    shrunk = V.copy()
    shrunk[162:] = 1e-4 * (V[162:] - [3.0, 0, 0]) + [3.0, 0, 0]    # a point
    line = V * [1e-4, 1e-4, 1.0]                   # both components to lines
    grown = 1.01 * V
    P, G = flat_patch(level=1, jitter=0.3, seed=0)
    slid = P.copy()
    slid[G[0, 0]] = 0.999 * P[G[0, 1]] + 0.001 * P[G[0, 0]]       # angle collapses
    bad = V.copy()
    bad[7, 1] = np.nan
    folded0 = folded.copy()                       # folded from step 0, and more later
    i, j = F[300, :2]
    later = 0.98 * folded0
    later[i] = later[j] + 0.5 * (later[j] - later[i])
    return [("folded", V, F, folded), ("shrunk", V, F, shrunk), ("line", V, F, line),
            ("grown", V, F, grown), ("slid", P, G, slid), ("non-finite", V, F, bad),
            ("folded at step 0", folded0, F, later)]


@pytest.mark.parametrize("name, V0, F, V", states(), ids=[s[0] for s in states()])
def test_the_pass_measures_what_numpy_computes_separately(name, V0, F, V):
    measured = StateMeasures(V0, F)(V)
    areas = triangle_areas(V, F)
    count, labels = vertex_components(F, len(V))
    component_area = np.bincount(labels[F[:, 0]], areas, minlength=count)
    box = np.array([[np.nanmin(V[labels == c], axis=0), np.nanmax(V[labels == c], axis=0)]
                    for c in range(count)])
    cosine0, cosine = neighbour_cosines(V0, F), neighbour_cosines(V, F)
    new_folds = int((~(cosine >= 0) & (cosine0 >= 0)).sum())
    if name == "non-finite":      # NaN propagates to the areas of its component only;
        # the box skips it (comparisons with NaN are false)
        assert np.isnan(measured.area) and np.isnan(measured.angle)
        assert np.isnan(measured.component_area[0])
        assert measured.component_area[1] == pytest.approx(component_area[1], rel=1e-14)
        assert measured.diameter == pytest.approx(
            np.linalg.norm(box[:, 1] - box[:, 0], axis=1), rel=1e-14)
        return
    assert measured.area == pytest.approx(areas.sum(), rel=1e-14)
    assert measured.component_area == pytest.approx(component_area, rel=1e-14)
    assert measured.diameter == pytest.approx(np.linalg.norm(box[:, 1] - box[:, 0], axis=1),
                                              rel=1e-14)
    assert measured.angle == pytest.approx(min_angle(V, F), rel=1e-11)
    assert measured.folded == new_folds
    assert (name in ("folded", "folded at step 0")) == (new_folds > 0)


@pytest.mark.parametrize("name, V0, F, V", states(), ids=[s[0] for s in states()])
def test_the_checks_on_one_shared_measurement_say_what_they_say_alone(name, V0, F, V):
    """The driver's way (one measurement for both checks) against each check measuring
    the state itself: the same sentences, the same recorded numbers."""
    shared = StateMeasures(V0, F)
    collapse, invariants = CollapseCheck(V0, F, measures=shared), \
        FlowInvariants(V0, F, measures=shared)
    alone_collapse, alone_invariants = CollapseCheck(V0, F), FlowInvariants(V0, F)
    for step, state in enumerate((0.9999 * V0, V), start=1):
        measured = shared(state)
        assert collapse(state, measured) == alone_collapse(state)
        assert invariants(state, step, measured) == alone_invariants(state, step)
        for key in ("smallest_area", "smallest_area_step", "angle", "collapsed_since"):
            a, b = getattr(invariants, key), getattr(alone_invariants, key)
            assert a == b or (a != a and b != b), key
    expected = {"folded": ["inverted", "area_grew"], "folded at step 0": ["inverted"],
                "grown": ["area_grew"]}      # the moved vertex stretches its triangles
    assert [s for s, _ in alone_invariants(V, 3)] == expected.get(name, [])
    assert (alone_collapse(V) is not None) == (name in ("shrunk", "line", "non-finite"))
    collapsed_angle = name in ("slid", "line", "non-finite")
    assert (alone_invariants.quality_collapse() is not None) == collapsed_angle


def test_a_state_measures_the_same_in_either_layout():
    """The vertex schemes' states are (n, 3) views of (3, n) arrays (Fortran order),
    measured as they are: the same numbers, bitwise, as a C-ordered copy's."""
    V, F = two_spheres()
    state = np.ascontiguousarray((0.9 * V).T)
    view, copy = StateMeasures(V, F)(state.T), StateMeasures(V, F)(state.T.copy())
    assert view[:3] == copy[:3]
    assert np.array_equal(view.component_area, copy.component_area)
    assert np.array_equal(view.diameter, copy.diameter)


def test_components_are_found():
    V, F = two_spheres()
    count, labels = vertex_components(F, len(V))
    assert count == 2 and (labels[:162] == 0).all() and (labels[162:] == 1).all()


def _fin():
    """A non-manifold mesh: a tetrahedron with a fin, a third triangle on edge (0, 1)."""
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0], [0.5, -1, 0.3]])
    F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3], [0, 1, 4]])
    return V, F


@pytest.mark.parametrize("mesh", ["sphere", "patch", "fin"])
def test_the_fold_count_is_the_quality_monitors_on_noisy_states(mesh):
    """Many folds, many near-zero sums (a noise of the size of an edge): the gathered
    sums count exactly the triangles of the scattered ones
    (:func:`mcfbench.geometry.kernels.count_folds`), at a boundary (padded rows) and on
    a non-manifold edge (a wider table) too."""
    from mcfbench.geometry.kernels import count_folds
    from mcfbench.geometry.metrics import edge_neighbours

    V, F = {"sphere": lambda: icosphere(3), "patch": lambda: flat_patch(level=2, seed=1),
            "fin": _fin}[mesh]()
    measures = StateMeasures(V, F)
    assert measures._table.shape[1] == (4 if mesh == "fin" else 3)
    t1, t2 = (np.asarray(t, dtype=np.int64) for t in edge_neighbours(F))
    rng = np.random.default_rng(3)
    counts = []
    for scale in (0.02, 0.1, 0.5):
        W = V + scale * rng.standard_normal(V.shape)
        work = np.empty((3, len(F), 3))
        work[0] = np.cross(W[F[:, 1]] - W[F[:, 0]], W[F[:, 2]] - W[F[:, 0]])
        expected = count_folds(work[0], t1, t2, measures._skip, work[1], work[2])
        assert measures(W).folded == expected
        counts.append(expected)
    assert counts[-1] > 0


@pytest.mark.parametrize("name, V0, F, V", states(), ids=[s[0] for s in states()])
def test_two_threads_measure_a_state_bit_for_bit_as_one(name, V0, F, V):
    """The pass split for threads (state_pass_threads: the triangles' terms apart, their
    sums in triangle order) gives state_pass's numbers, NaN states and folds too."""
    one, two = StateMeasures(V0, F)(V), StateMeasures(V0, F, threads=2)(V)
    assert two.folded == one.folded
    for field in ("area", "angle", "component_area", "diameter"):
        np.testing.assert_array_equal(getattr(two, field), getattr(one, field))
