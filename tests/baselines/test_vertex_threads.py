"""The vertex schemes' compiled passes on two threads (issue 46 item 3): the geometry
(the triangles' terms, then each vertex's sums in triangle order), the vertex normals,
the systems' rows and the checks give the one-thread scatter's numbers bit for bit."""

import numpy as np
import pytest

from baselines.bgn import BGNFlow
from baselines.cotan import CotanFlow
from baselines.laplacian import CotanAssembler
from baselines.mesh import edge_mesh
from mcfbench.geometry.spheres import icosphere
from mcfbench.running.driver import simulate
from mcfbench.running.schemes import get_scheme
from mcfbench.running.solver import Solver


def noisy_sphere(level=2, seed=0):
    V, F = icosphere(level)
    return V + 0.02 * np.random.default_rng(seed).standard_normal(V.shape), F


@pytest.mark.parametrize("mass", ["barycentric", "voronoi"])
def test_the_geometry_on_two_threads_is_the_scatter_s_bit_for_bit(mass):
    V, F = noisy_sphere()
    V[F[5]] = V[F[5, 0]]                    # triangle 5 collapsed to a point: left out
    assembler = CotanAssembler(edge_mesh(F, len(V)), mass)
    one, two = assembler.geometry(V), assembler.geometry(V, threads=2)
    assert (one.degenerate, one.first_degenerate) == (two.degenerate, two.first_degenerate)
    assert one.degenerate >= 1 and one.first_degenerate == 5
    for field in ("L_data", "mass", "area_vectors"):
        np.testing.assert_array_equal(getattr(two, field), getattr(one, field))
    assert np.abs(one.L_data).max() > 1.0 and one.mass.min() >= 0.0     # not all zero
    np.testing.assert_array_equal(assembler.normals(one.area_vectors, threads=2),
                                  assembler.normals(one.area_vectors))
    without = assembler.geometry(V, with_laplacian=False, threads=2)
    assert without.L_data is None and np.array_equal(without.mass, one.mass)


@pytest.mark.parametrize("flow_class", [CotanFlow, BGNFlow])
def test_a_flow_on_two_threads_assembles_and_checks_as_on_one(flow_class):
    V, F = noisy_sphere()
    one, two = flow_class(V, F, 1e-3), flow_class(V, F, 1e-3, threads=2)
    (A1, b1), (A2, b2) = one.system(), two.system()
    np.testing.assert_array_equal(A2.data, A1.data)
    np.testing.assert_array_equal(b2, b1)
    np.testing.assert_array_equal(two._triangle_checks[0], one._triangle_checks[0])
    assert two.defects() == one.defects() == []
    X = np.array(one.state) * 0.9
    X[:, 3] = X[:, 7]                        # collapses a few triangles: "degenerated"
    for flow in (one, two):
        flow.advance(X)
    assert two.defects() == one.defects() != []


def test_bad_thread_counts_are_refused():
    V, F = icosphere(1)
    with pytest.raises(ValueError, match="threads"):
        CotanFlow(V, F, 1e-3, threads=0)


@pytest.mark.parametrize("name", ["cotan", "bgn"])
def test_a_run_whose_passes_take_two_threads_is_the_one_thread_run_bit_for_bit(name):
    """The flow's passes and the driver's checks on two threads, the solve on one (whose
    threaded inner products are summed in another order): every step bitwise."""
    V, F = icosphere(3)
    flows = [get_scheme(name).make(V, F, 1e-3, threads=t) for t in (1, 2)]
    trajectories = [simulate(flow, 4, solver=Solver(), save_every=1) for flow in flows]
    assert all(traj.ok and traj.steps_done == 4 for traj in trajectories)
    assert flows[1].threads == 2
    np.testing.assert_array_equal(trajectories[1].iterations, trajectories[0].iterations)
    np.testing.assert_array_equal(flows[1].X, flows[0].X)
    assert np.abs(flows[0].X - np.asarray(V).T).max() > 1e-3        # the flow moved
