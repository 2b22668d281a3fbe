import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ddfv.solver import bicgstab


def _system(n=300, seed=0):
    rng = np.random.default_rng(seed)
    A = sp.random(n, n, density=0.02, random_state=seed) * 0.3
    A = (sp.eye(n) * 3 + A - A.T * 0.5).tocsr()   # nonsymmetric, diagonally dominant
    return A, rng.normal(size=(3, n))


def test_bicgstab_solves_a_block_of_right_hand_sides():
    A, b = _system()
    x, info = bicgstab(A, b, np.zeros_like(b), rtol=1e-12)
    assert info.converged and info.iterations > 0
    exact = spla.spsolve(A.tocsc(), b.T).T
    assert np.abs(x - exact).max() < 1e-10
    assert np.linalg.norm(b - np.stack([A @ xi for xi in x])) <= 1e-12 * np.linalg.norm(b) * 1.01
    assert info.residual <= 1e-12


def test_exact_initial_guess_needs_no_iteration():
    A, b = _system()
    exact = spla.spsolve(A.tocsc(), b.T).T
    x, info = bicgstab(A, b, exact, rtol=1e-8)
    assert info.iterations == 0 and info.converged


def test_non_convergence_is_reported():
    A, b = _system()
    x, info = bicgstab(A, b, np.zeros_like(b), rtol=1e-14, maxiter=1)
    assert not info.converged
    assert info.iterations == 1 and info.residual > 1e-14


def test_iteration_count_is_not_undercounted():
    """Each iteration costs at most two products: count them."""
    A, b = _system()
    products = []

    class Counting:
        def __matmul__(self, x):
            products.append(1)
            return A @ x

    x, info = bicgstab(Counting(), b, np.zeros_like(b), rtol=1e-10)
    assert info.converged
    # per block (3 vector products): one for the initial residual, then one
    # (half-step exit) or two per iteration
    blocks = len(products) / 3
    assert 2 * info.iterations - 1 <= blocks - 1 <= 2 * info.iterations
