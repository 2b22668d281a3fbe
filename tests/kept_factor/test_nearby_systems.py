"""A sequence of nearby sparse systems with a kept factorisation (kept_factor/nearby_systems.py).

The systems are ``(I + L_k) x = b_k``, ``L_k`` the cotangent stiffness of an
icosphere moved a little further at every step: solved to ``rtol`` against a
direct solve, with one factorisation while the matrices stay near and a new one
when they jump; the nonsymmetric fallback; the extrapolated start.
"""

import igl
import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from kept_factor import KeptFactorSolver, cholesky_solve, factorise, family_blocks, pinned
from kept_factor.nearby_systems import _preconditioned_cg
from mcfbench.geometry.spheres import icosphere

V, F = icosphere(2)
BUMP = np.random.default_rng(0).standard_normal(V.shape)


def _matrix(k, step=1e-3):
    """``I + L`` of the sphere moved ``k step`` along a fixed random field, (n, n) CSR."""
    L = -igl.cotmatrix(V + k * step * BUMP, F)
    return sp.csr_matrix(sp.eye(len(V)) + L)


def _rhs(k):
    """A right-hand side that moves smoothly with ``k``: ``(n,)``."""
    return np.cos(V[:, 0] + 0.01 * k) + V[:, 2] ** 2


def _solve(solver, A, b, **options):
    return solver.solve(b, A.dot, A, **options)


def test_slowly_moving_sequence_keeps_one_cholesky_factor():
    solver = KeptFactorSolver(rtol=1e-10)
    for k in range(6):
        A, b = _matrix(k), _rhs(k)
        x = _solve(solver, A, b, sequence="x")
        assert np.linalg.norm(b - A @ x) <= 1e-10 * np.linalg.norm(b)
        np.testing.assert_allclose(x, spla.spsolve(A.tocsc(), b), rtol=0, atol=1e-9)
    assert (solver.factorisations, solver.method) == (1, "cg")
    assert 5 <= solver.iterations <= 5 * solver.max_iterations


def test_a_system_without_unknowns_is_solved_without_a_factor():
    """Every vertex fixed (a small open mesh all of whose vertices are on its boundary,
    met in the raw corpus): the empty solution, no factorisation (scipy's norm of an
    empty matrix raised)."""
    solver = KeptFactorSolver(rtol=1e-10)
    x = _solve(solver, sp.csr_matrix((0, 0)), np.zeros(0), sequence="x")
    assert x.shape == (0,) and solver.factorisations == 0


def test_a_jump_of_the_matrix_factorises_again():
    """The matrix of a sphere moved by 0.3 (a third of the radius) is too far from
    the kept one for four CG iterations: a second factorisation, then kept again."""
    solver = KeptFactorSolver(rtol=1e-10)
    for k in (0, 1, 300, 301):
        A, b = _matrix(k), _rhs(k)
        x = _solve(solver, A, b)
        assert np.linalg.norm(b - A @ x) <= 1e-10 * np.linalg.norm(b)
    assert solver.factorisations == 2


def test_nonsymmetric_or_indefinite_matrices_get_lu_and_refinement():
    """A nonsymmetric matrix (an upwind term) and a symmetric negative definite one
    get a sparse LU; the refinement solves the nearby nonsymmetric sequence."""
    A = _matrix(0)
    upwind = (A + sp.diags(0.1 * np.ones(len(V) - 1), 1)).tocsr()
    b = _rhs(0)
    for matrix, method in ((A, "cg"), (upwind, "refinement"),
                           (-A, "refinement")):
        found, solve = factorise(matrix)
        assert found == method
        assert np.linalg.norm(matrix @ solve(b) - b) < 1e-12 * np.linalg.norm(b)
    assert cholesky_solve(-A) is None
    solver = KeptFactorSolver(rtol=1e-10)
    for k in range(4):
        M = (_matrix(k) + sp.diags(0.1 * np.ones(len(V) - 1), 1)).tocsr()
        x = _solve(solver, M, _rhs(k), sequence="x")
        assert np.linalg.norm(_rhs(k) - M @ x) <= 1e-10 * np.linalg.norm(_rhs(k))
    assert (solver.factorisations, solver.method) == (1, "refinement")
    assert solver.iterations >= 3


def test_extrapolated_start():
    """With the matrix kept fixed and ``b_k`` affine in ``k``, ``x_k`` is affine
    in ``k`` too: from the third solve on the extrapolation of the last two is the
    solution, and no iteration is needed; the caller's start overrides it."""
    A = _matrix(0)
    solver = KeptFactorSolver(rtol=1e-9)
    b0, b1 = _rhs(0), V[:, 1]
    for k in range(4):
        _solve(solver, A, b0 + k * b1, sequence="x")
        _solve(solver, A, np.ones(len(V)), sequence="other")   # a second sequence
    assert solver.factorisations == 1
    before = solver.iterations
    x = _solve(solver, A, b0 + 4 * b1, sequence="x")
    assert solver.iterations == before
    np.testing.assert_allclose(x, spla.spsolve(A.tocsc(), b0 + 4 * b1), atol=1e-8)
    _solve(solver, A, b0, start=np.zeros(len(V)))           # a far start: iterations
    assert solver.iterations > before


def test_quadratic_extrapolation():
    """With ``b_k`` quadratic in ``k`` (the matrix fixed) the solutions are too: from
    the fourth solve on, ``extrapolation=2`` starts at the solution (no iteration),
    the linear extrapolation does not; any other degree is refused by name."""
    A = _matrix(0)
    b0, b1, b2 = _rhs(0), V[:, 1], V[:, 0] * V[:, 2]
    counts = {}
    for degree in (1, 2):
        solver = KeptFactorSolver(rtol=1e-9, extrapolation=degree)
        for k in range(3):
            _solve(solver, A, b0 + k * b1 + k * k * b2, sequence="x")
        before = solver.iterations
        x = _solve(solver, A, b0 + 3 * b1 + 9 * b2, sequence="x")
        counts[degree] = solver.iterations - before
        assert np.linalg.norm(b0 + 3 * b1 + 9 * b2 - A @ x) <= 1e-9 * np.linalg.norm(
            b0 + 3 * b1 + 9 * b2)
    assert counts[2] == 0 < counts[1]
    with pytest.raises(ValueError, match="extrapolation must be 1 or 2"):
        KeptFactorSolver(extrapolation=3)



def test_smoothing_of_the_start():
    """``smooth`` acts on the start of the kept factor's iteration, never on the
    caller's array: a smoothing to the exact solution leaves no iteration, one that
    ruins the start (zeroes it) costs iterations but not accuracy; a new factor's
    ``P^{-1} b`` is not smoothed."""
    A, b = _matrix(0), _rhs(0)
    exact = spla.spsolve(A.tocsc(), b)
    calls = []

    def to_exact(x, rhs):
        calls.append(rhs)
        x[:] = exact

    solver = KeptFactorSolver(rtol=1e-10)
    _solve(solver, A, b, smooth=to_exact)          # factorised: not smoothed
    assert calls == [] and solver.factorisations == 1
    start = np.zeros(len(V))
    before = solver.iterations
    x = _solve(solver, A, b, start=start, smooth=to_exact)
    assert solver.iterations == before and len(calls) == 1 and calls[0] is b
    assert not start.any()                          # the caller's start untouched
    np.testing.assert_array_equal(x, exact)
    plain = KeptFactorSolver(rtol=1e-10, max_iterations=50)
    ruined = KeptFactorSolver(rtol=1e-10, max_iterations=50)
    for k in range(4):
        A, b = _matrix(k), _rhs(k)
        y = _solve(plain, A, b, sequence="x")
        z = _solve(ruined, A, b, sequence="x", smooth=lambda x, rhs: x.fill(0.0))
        for w in (y, z):
            assert np.linalg.norm(b - A @ w) <= 1e-10 * np.linalg.norm(b)
    assert ruined.iterations > plain.iterations
    assert ruined.factorisations == plain.factorisations == 1

def test_budget_factorises_once_the_extra_iterations_reach_it():
    """A drifting sequence whose solves take several CG iterations each with the first
    factor: without a budget one factorisation serves them all; with ``budget`` the
    matrix is factorised again at the first solve after the iterations beyond the
    fewest a kept-factor solve has taken (at least one), summed since the last
    factorisation, reach it (a fresh factor's solve counts none), and every solution
    meets the tolerance."""
    plain = KeptFactorSolver(rtol=1e-10, max_iterations=50)
    budgeted = KeptFactorSolver(rtol=1e-10, max_iterations=50, budget=6)
    expected, kept = [], None
    for k in range(16):
        A, b = _matrix(k, step=2e-2), _rhs(k)
        _solve(plain, A, b, sequence="x")
        factorise_now = kept is None or sum(kept) - len(kept) * max(1, min(kept, default=1)) >= 6
        before = budgeted.iterations
        x = _solve(budgeted, A, b, sequence="x")
        assert np.linalg.norm(b - A @ x) <= 1e-10 * np.linalg.norm(b)
        expected.append(factorise_now)
        kept = [] if factorise_now else kept + [budgeted.iterations - before]
    assert plain.factorisations == 1 and plain.iterations >= 2 * 15
    assert budgeted.factorisations == sum(expected) >= 3


def test_budget_counts_iterations_beyond_the_fewest_of_the_kept_factor():
    """A sequence whose solves take two iterations each with the kept factor (a fresh one
    would too) spends no budget: one factorisation for all, where counting beyond one
    a solve factorised every ``budget`` solves; one that grows from two spends the
    growth."""
    solver = KeptFactorSolver(budget=3)
    for counts, factorisations in (([2] * 10, 0), ([2, 3, 3, 3, 2], 1), ([2, 4, 2], 0)):
        solver._kept = list(counts)
        assert (solver._excess() >= solver.budget) == bool(factorisations), counts
    solver._kept = []
    assert solver._excess() == 0


def test_size_change_factorises_again():
    solver = KeptFactorSolver()
    _solve(solver, _matrix(0), _rhs(0), sequence="x")
    A = sp.eye(5, format="csr") * 2.0
    np.testing.assert_allclose(_solve(solver, A, np.ones(5), sequence="x"), 0.5)
    assert solver.factorisations == 2


def test_family_blocks_precondition_cg_to_the_direct_solution():
    """Two families coupled: ``[[I + L, C], [C^T, I + L]]`` with ``C = 0.2 I`` (SPD, the
    blocks' factors not the matrix's): CG with the blocks reaches the tolerance, the
    solution is the direct one to it, one factorisation for the sequence; the blocks
    alone (``C = 0``) are exact (no iteration); a nonsymmetric matrix gets the LU of
    the whole."""
    n = len(V)
    solver = KeptFactorSolver(rtol=1e-10, max_iterations=30, factorise=family_blocks(n))
    for k in range(4):
        block = _matrix(k)
        A = sp.bmat([[block, 0.2 * sp.eye(n)], [0.2 * sp.eye(n), block]]).tocsr()
        b = np.r_[_rhs(k), _rhs(k + 5)]
        x = _solve(solver, A, b, sequence="x")
        assert np.linalg.norm(b - A @ x) <= 1e-10 * np.linalg.norm(b)
        np.testing.assert_allclose(x, spla.spsolve(A.tocsc(), b), rtol=0, atol=1e-8)
    assert (solver.factorisations, solver.method) == (1, "cg")
    assert solver.iterations >= 4                   # the coupling costs iterations
    A = sp.block_diag([_matrix(0), _matrix(1)]).tocsr()
    method, solve = family_blocks(n)(A)
    b = np.r_[_rhs(0), _rhs(1)]
    assert method == "cg"
    np.testing.assert_allclose(solve(b), spla.spsolve(A.tocsc(), b), rtol=0, atol=1e-12)
    A = sp.bmat([[_matrix(0), 0.2 * sp.eye(n)], [None, _matrix(1)]]).tocsr()
    assert family_blocks(n)(A)[0] == "refinement"


def test_pinned_system():
    """``P K P + I - P``: ``apply`` and ``matrix`` agree, and a Laplacian pinned at
    one vertex (kernel: the constants) is symmetric positive definite."""
    K = sp.csr_matrix(-igl.cotmatrix(V, F))
    keep = np.ones(len(V))
    keep[3] = 0.0
    apply, matrix = pinned(K, keep)
    x = np.random.default_rng(1).standard_normal(len(V))
    A = matrix()
    np.testing.assert_allclose(apply(x), A @ x, atol=1e-14)
    np.testing.assert_array_equal(apply(x), keep * (K @ (keep * x)) + (1.0 - keep) * x)
    assert apply(x)[3] == x[3] and x[3] != 0.0
    assert A[3, 3] == 1.0 and A[3].nnz == 1 and A[:, 3].nnz == 1
    assert factorise(A)[0] == "cg"
    with pytest.raises(ValueError, match="keep must hold only 0"):
        pinned(K, np.full(len(V), 0.5))


def test_preconditioned_cg_exact_in_n_steps_and_stops_where_not_positive_definite():
    """Unpreconditioned CG on a 3 x 3 SPD matrix with distinct eigenvalues: the
    solution in exactly 3 iterations (not 2); a start that meets the tolerance: 0
    iterations; an indefinite matrix (``p . A p < 0`` at the first direction):
    stopped, not converged, ``x`` untouched."""
    A = np.array([[4.0, 1.0, 0.0], [1.0, 3.0, 1.0], [0.0, 1.0, 2.0]])
    b = np.array([1.0, 2.0, 3.0])
    exact = np.linalg.solve(A, b)
    x, k, ok = _preconditioned_cg(A.dot, lambda r: r, b, np.zeros(3), 1e-12, 2)
    assert (k, ok) == (2, False) and np.linalg.norm(x - exact) > 1e-6
    x, k, ok = _preconditioned_cg(A.dot, lambda r: r, b, np.zeros(3), 1e-12, 10)
    assert (k, ok) == (3, True)
    np.testing.assert_allclose(x, exact, rtol=1e-12)
    assert _preconditioned_cg(A.dot, lambda r: r, b, exact, 1e-12, 10)[1:] == (0, True)
    D = np.diag([1.0, -1.0])
    x, k, ok = _preconditioned_cg(D.dot, lambda r: r, np.array([0.0, 1.0]), np.zeros(2),
                                  1e-12, 10)
    assert (k, ok) == (1, False) and not x.any()
