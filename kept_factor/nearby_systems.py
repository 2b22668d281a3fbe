"""``A_k x_k = b_k`` for a sequence of nearby sparse matrices ``A_k``, one factorisation kept.

Along a flow the matrix of a step moves by ``O(tau)`` from the last one's, so
the factorisation ``P`` of an earlier ``A`` is a preconditioner for which
``P^{-1} A`` is within ``O(tau)`` of the identity: started from a good guess,
a few iterations reach the tolerance at the cost of a few triangular solves,
against a new factorisation (tens of solves' worth). The factorisation is
sparse Cholesky (CHOLMOD, through ``cholespy``) where ``A`` is symmetric
positive definite, with conjugate gradients preconditioned by the kept
factor's solve (:func:`_preconditioned_cg`: scipy's loop without its set-up);
else sparse LU (SuperLU, ordering of ``A + A^T``) with iterative refinement
``x <- x + P^{-1} (b - A x)``. The iteration stops at ``|b - A x| <= rtol
|b|`` (CG: its recurrence residual, as scipy's); when it takes more than
``max_iterations``, ``A`` is factorised anew.

GMRES (``scipy.sparse.linalg.gmres``) instead of the refinement was not taken:
it is left-preconditioned and spends one more factor solve per call on
``|P^{-1} b|`` for its inner tolerance, while the refinement of a nearby
factor needs one or two solves (``P^{-1} A`` is within ``O(tau)`` of ``I``).
"""

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

#: relative asymmetry ``|A - A^T|_inf / |A|_inf`` below which ``A`` counts as symmetric
SYMMETRY = 1e-12

#: degree -> weights of the last solutions, newest first, in the extrapolated start
#: (:class:`KeptFactorSolver`): the polynomial through them, evaluated one step on
EXTRAPOLATION = {0: (1.0,), 1: (2.0, -1.0), 2: (3.0, -3.0, 1.0)}


def as_csr(A):
    """``A`` as a scipy CSR matrix: itself when it is one (``scipy.sparse.csr_matrix(A)``
    of a CSR matrix builds a new one and checks its index arrays, an ``O(nnz)`` scan:
    about 0.1 ms at the 276 482 entries of DDFV's step matrix at level 5 of the sphere,
    three times a redistributing step), else converted."""
    return A if sp.issparse(A) and A.format == "csr" else sp.csr_matrix(A)


def cholesky_solve(A):
    """``b -> A^{-1} b`` by the sparse Cholesky factorisation of ``A``, or None.

    CHOLMOD's supernodal factorisation with its own fill-reducing ordering,
    through ``cholespy`` (which ships it: no system library).

    Parameters
    ----------
    A : (n, n) sparse matrix
        Symmetric (one triangle is read).

    Returns
    -------
    callable or None
        ``solve(b, out=None)`` for (n,) ``b`` (into ``out``, a contiguous (n,)
        float64 array, when given); None when ``A`` is not numerically positive
        definite.
    """
    from cholespy import CholeskySolverD, MatrixType

    A = sp.csr_matrix(A, dtype=np.float64)
    A.sum_duplicates()
    try:
        factor = CholeskySolverD(A.shape[0], A.indptr.astype(np.int32),
                                 A.indices.astype(np.int32), A.data, MatrixType.CSR)
    except ValueError:                                   # not positive definite
        return None

    def solve(b, out=None):
        x = np.empty(len(b)) if out is None else out
        factor.solve(np.ascontiguousarray(b, dtype=np.float64), x)
        return x
    return solve


def factorise(A):
    """``(method, solve)``: the factorisation of ``A`` (n, n) sparse and its iteration.

    Returns
    -------
    method : {"cg", "refinement"}
        ``"cg"``: sparse Cholesky (:func:`cholesky_solve`), where ``A`` is
        symmetric (to :data:`SYMMETRY`, infinity norm) and positive definite,
        kept with conjugate gradients; ``"refinement"``: else sparse LU (SuperLU,
        minimum degree ordering of ``A + A^T``), kept with iterative refinement.
    solve : callable (n,) -> (n,)
        ``b -> A^{-1} b``.
    """
    A = sp.csr_matrix(A)
    if spla.norm(A - A.T, np.inf) <= SYMMETRY * spla.norm(A, np.inf):
        solve = cholesky_solve(A)
        if solve is not None:
            return "cg", solve
    return "refinement", spla.splu(A.tocsc(), permc_spec="MMD_AT_PLUS_A").solve


def family_blocks(split):
    """A ``factorise`` (:func:`factorise`'s contract) for a matrix of two families of
    unknowns, ``[0, split)`` and ``[split, n)``: where ``A`` is symmetric, the sparse
    Cholesky factorisations of its two diagonal blocks, ``P = diag(A_11, A_22)``, kept
    with conjugate gradients; else (or where a block is not positive definite)
    :func:`factorise` of the whole matrix.

    ``P`` is symmetric positive definite where ``A`` is (its diagonal blocks are), so
    CG preconditioned by it converges to the same solution; it costs one more
    iteration where the coupling of the families is strong, and much less fill than
    the factor of ``A`` where the coupling makes the graph denser (DDFV: a diamond
    couples its two F- and two T-vertices, 16 entries; its F-F and T-T blocks are
    the graphs of the primal and dual meshes).

    Parameters
    ----------
    split : int
        The first unknown of the second family.

    Returns
    -------
    callable
        ``A -> (method, solve)``.
    """
    def factorise_blocks(A):
        A = sp.csr_matrix(A)
        if spla.norm(A - A.T, np.inf) <= SYMMETRY * spla.norm(A, np.inf):
            first = cholesky_solve(A[:split, :split])
            second = cholesky_solve(A[split:, split:])
            if first is not None and second is not None:
                def solve(b):
                    x = np.empty(len(b))        # each block's solve written in place
                    first(b[:split], x[:split])
                    second(b[split:], x[split:])
                    return x
                return "cg", solve
        return factorise(A)
    return factorise_blocks


def pinned(K, keep):
    """The pinned system ``A = P K P + I - P``, ``P = diag(keep)``, as ``(apply, matrix)``.

    ``K`` with the rows and columns of the pinned entries (``keep`` 0 there, 1
    elsewhere) replaced by those of the identity: symmetric when ``K`` is, and
    positive definite when ``K`` is positive semi-definite with a kernel that
    no vector vanishing at the pinned entries meets (a Laplacian pinned once
    per kernel constant).

    Parameters
    ----------
    K : (n, n) sparse matrix
    keep : (n,) float array

    Returns
    -------
    apply : callable (n,) -> (n,)
        ``x -> A x`` without forming ``A``.
    matrix : callable () -> (n, n) scipy.sparse.csr_matrix
        ``A``.
    """
    K = as_csr(K)
    keep = np.asarray(keep, dtype=float)
    if not np.all((keep == 0.0) | (keep == 1.0)):
        raise ValueError("keep must hold only 0 (pinned) and 1 (kept)")
    pins = np.flatnonzero(keep == 0.0)

    def apply(x):          # keep * (K @ (keep * x)) + (1 - keep) * x, two fewer passes
        kept = np.array(x, dtype=float)
        kept[pins] = 0.0
        y = K @ kept
        y[pins] = x[pins]
        return y

    def matrix():
        P = sp.diags(keep)
        return (P @ K @ P + sp.diags(1.0 - keep)).tocsr()
    return apply, matrix


class KeptFactorSolver:
    """Solver of a sequence of nearby sparse systems ``A_k x = b_k`` with a kept factor.

    Each system is solved with the factorisation ``P`` of an earlier matrix of
    the sequence (``factorise``, default :func:`factorise`), iterated from a
    start until ``|b - A x| <= rtol |b|``: the caller's start, else, for a named
    sequence of solutions, the polynomial extrapolation of its last solutions
    (:data:`EXTRAPOLATION`: ``2 x_{k-1} - x_{k-2}`` from two, ``3 x_{k-1} - 3
    x_{k-2} + x_{k-3}`` from three with ``extrapolation=2``; the last one alone
    after one), else ``P^{-1} b``. When that takes more than ``max_iterations``
    (or the size changed), ``A`` is factorised and the iteration runs from
    ``P^{-1} b`` of the new factor (for an exact factorisation one residual
    check). With a ``budget``, ``A`` is also factorised before a solve once the
    iterations beyond ``max(1, fewest)`` a solve (``fewest``: the fewest any solve
    with the kept factor has taken, the estimate of what a fresh factor takes),
    summed over the solves since the last factorisation, reach it: a
    factorisation that costs about ``budget`` iterations is bought when the stale
    factor has cost that much more than a fresh one would (the rule of renting
    until the rent paid equals the price), so that a factor that ages slowly is
    neither kept at a growing cost nor given up at the first hard step. (Counted
    beyond one, a sequence that takes two iterations with a fresh factor, as the
    tangential motion's at its tolerance, paid one factorisation every
    ``budget`` solves for no iteration saved.)

    Parameters
    ----------
    rtol : float
        Relative residual of every solve.
    max_iterations : int
        Iterations with a kept factor before factorising anew.
    factorise : callable
        ``A -> (method, solve)``, default :func:`factorise`; ``solve`` may be an
        approximate inverse (a preconditioner), symmetric positive definite for
        ``"cg"``.
    budget : int, optional
        Iterations beyond ``max(1, fewest)`` a solve, summed since the last
        factorisation, after which the next solve factorises anew; default None
        (only when a solve takes more than ``max_iterations``).
    extrapolation : {1, 2}
        Degree of the polynomial extrapolation of a sequence's start.

    Attributes
    ----------
    factorisations, iterations : int
        Factorisations and iterations so far.
    method : {"cg", "refinement"} or None
        The iteration of the kept factor (None before the first).
    """

    def __init__(self, rtol=1e-7, max_iterations=4, factorise=factorise, budget=None,
                 extrapolation=1):
        if extrapolation not in (1, 2):
            raise ValueError(f"extrapolation must be 1 or 2, not {extrapolation!r}")
        self.rtol, self.max_iterations = rtol, max_iterations
        self._factorise = factorise
        self.budget, self.extrapolation = budget, extrapolation
        self.factorisations = self.iterations = 0
        self._kept = []                 # iterations of each solve with the kept factor
        self.method = self._factor = None
        self._history = {}                              # sequence -> its last two solutions

    def solve(self, b, apply, matrix, start=None, sequence=None, smooth=None):
        """``x`` (n,) with ``|b - A x| <= rtol |b|``.

        Parameters
        ----------
        b : (n,) float array
        apply : callable (n,) -> (n,)
            ``x -> A x``.
        matrix : (n, n) sparse matrix or callable () -> (n, n) sparse matrix
            ``A`` itself, asked for only when it is factorised.
        start : (n,) float array, optional
            The first iterate with a kept factor; default the extrapolation of
            ``sequence``.
        sequence : hashable, optional
            Name of the sequence of solutions ``x`` belongs to (its last two are
            kept for the next start).
        smooth : callable, optional
            ``smooth(x, b)``: improves a start ``x`` (n,) in place before the kept
            factor's iteration (e.g. a relaxation sweep over the rows where the
            start's residual is known to gather); the iteration then checks the
            residual of the smoothed start as of any other, so a poor smoothing costs
            iterations, never accuracy. Not applied to a new factor's ``P^{-1} b``.

        Returns
        -------
        (n,) float array
        """
        b = np.asarray(b, dtype=float)
        if not len(b):              # no unknown (every vertex fixed): nothing to factorise
            return b.copy()
        history = [x for x in self._history.get(sequence, []) if len(x) == len(b)]
        converged = False
        if (self._factor is not None and self._factor[1] == len(b)
                and (self.budget is None or self._excess() < self.budget)):
            if start is None and history:                # a new array
                weights = EXTRAPOLATION[min(len(history) - 1, self.extrapolation)]
                start = sum(w * x for w, x in zip(weights, reversed(history)))
            elif start is not None and smooth is not None:
                start = np.array(start, dtype=float)     # the caller's start stays as it is
            if smooth is not None and start is not None:
                smooth(start, b)
            before = self.iterations
            x, converged = self._iterate(apply, b, start)
            self._kept.append(self.iterations - before)
        if not converged:
            self.method, solve = self._factorise(matrix() if callable(matrix) else matrix)
            self._factor = solve, len(b)
            self.factorisations += 1
            self._kept = []
            x, _ = self._iterate(apply, b, None)
            history = []
        if sequence is not None:
            self._history[sequence] = history[-self.extrapolation:] + [x]
        return x

    def _excess(self):
        """Iterations beyond ``max(1, fewest)`` a solve since the last factorisation."""
        return sum(self._kept) - len(self._kept) * max(1, min(self._kept, default=1))

    def _iterate(self, apply, b, start):
        """``(x, converged)`` from ``start`` (None: ``P^{-1} b``) with the kept factor
        ``P``: CG preconditioned by ``P`` or iterative refinement, at most
        ``max_iterations``."""
        solve, _ = self._factor
        x = solve(b) if start is None else np.array(start, dtype=float)
        tol = self.rtol * np.linalg.norm(b)
        if self.method == "cg":
            x, k, converged = _preconditioned_cg(apply, solve, b, x, tol, self.max_iterations)
            self.iterations += k
            return x, converged
        for k in range(self.max_iterations + 1):         # refinement
            r = b - apply(x)
            if np.linalg.norm(r) <= tol:
                self.iterations += k
                return x, True
            if k < self.max_iterations:
                x = x + solve(r)
        self.iterations += self.max_iterations
        return x, False


def _preconditioned_cg(apply, precondition, b, x, tol, max_iterations):
    """Conjugate gradients preconditioned by ``precondition`` (Hestenes-Stiefel), from
    ``x`` until the recurrence residual ``|r| <= tol`` or ``max_iterations``.

    The loop of ``scipy.sparse.linalg.cg`` without its set-up, which at one
    iteration (the usual count with a kept factor) cost about a third of the
    solve: here one product for the start's residual, then one product and one
    preconditioner solve per iteration (scipy: 0.81 ms per solve of the cotangent
    potential at level 5 of the sphere, this loop 0.64 ms, a factor solve 0.44 ms).
    A start that meets the tolerance costs one product. Stops, not converged, where
    ``p . A p <= 0`` (a matrix or preconditioner not positive definite).

    Returns
    -------
    x : (n,) float array
    iterations : int
    converged : bool
    """
    r = b - apply(x)
    if np.linalg.norm(r) <= tol:
        return x, 0, True
    z = precondition(r)
    p, rz = z, np.dot(r, z)
    for k in range(1, max_iterations + 1):
        q = apply(p)
        pq = np.dot(p, q)
        if not pq > 0.0:
            return x, k, False
        alpha = rz / pq
        x = x + alpha * p
        r = r - alpha * q
        if np.linalg.norm(r) <= tol:
            return x, k, True
        if k < max_iterations:
            z = precondition(r)
            rz, rz_old = np.dot(r, z), rz
            p = z + (rz / rz_old) * p
    return x, max_iterations, False
