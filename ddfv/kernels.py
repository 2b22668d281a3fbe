"""Compiled (numba) kernels of the per-step hot path.

One loop over the diamonds (or triangles, or CSR rows) per kernel; the
formulas are those of :mod:`ddfv.geometry` and :mod:`ddfv.assembly`, whose
public functions call these kernels and document the results. With
:mod:`ddfv.tangential_kernels` (the tangential motions' passes, in its
conventions) the only module of ``ddfv`` that compiles with numba (loading its
kernels from numba's cache takes about 0.1 s: a run that does not step DDFV
never imports it); :mod:`ddfv.geometry` and :mod:`ddfv.assembly` import it on
first use, so ``import ddfv`` does not pay for it. Their threaded copies are made by
:mod:`kept_factor.threads`.

Conventions
-----------
- Every kernel has one explicit signature whose arrays have layout ``A``
  (any strides), so views of the flow state (``Flow.F`` is a strided
  ``(n_f, 3)`` view) need no copy and no second compilation.
- Index arrays are unsigned views of the topology's int64 arrays
  (``uint64``) or ``uint32`` CSR slots: no negative-index wraparound code.
  The missing ``t2 = -1`` of a boundary diamond is :data:`NO_T`
  (``2**64 - 1``). Every gathered index is checked against its array
  (``IndexError``); the check is one predictable compare per index.
- ``error_model="numpy"``: a division by zero gives inf/nan as in numpy.
- ``cache=True``: compiled once into numba's cache (``NUMBA_CACHE_DIR``, by
  default ``__pycache__`` next to this file) and loaded from it afterwards.
- Loops over independent elements are ``prange`` loops: plain loops in
  these kernels, split over numba's threads in their
  :func:`kept_factor.threads.threaded` copies (``threads > 1``).
"""

import numba
import numpy as np

#: ``t2`` of a boundary diamond (the int64 ``-1`` seen as uint64)
NO_T = np.uint64(2**64 - 1)

_OPTIONS = dict(cache=True, nogil=True, error_model="numpy", boundscheck=False)

#: rows of the buffer filled by :func:`diamond_geometry_kernel`
ROW_U, ROW_V, ROW_E = 0, 3, 6
ROW_LEN_U, ROW_LEN_V, ROW_J, ROW_UV, ROW_GAMMA_T, ROW_GAMMA_F = 9, 10, 11, 12, 13, 14
ROW_QUARTERS = 15
GEOMETRY_ROWS = 19

#: columns of the per-diamond CSR slot table of :func:`system_kernel`:
#: entry (row, column) of K, ``a, b`` F-rows/columns, ``t1, t2`` T-rows/columns
(SLOT_AB, SLOT_BA, SLOT_AA, SLOT_BB, SLOT_A_T1, SLOT_B_T1, SLOT_A_T2, SLOT_B_T2,
 SLOT_T1_A, SLOT_T1_B, SLOT_T2_A, SLOT_T2_B, SLOT_T1_T2, SLOT_T2_T1, SLOT_T1_T1,
 SLOT_T2_T2) = range(16)
N_SLOTS = 16
#: flag bit of a slot in :func:`system_kernel`'s table: the first write into its
#: entry (:meth:`ddfv.assembly.Assembler._first_touch`); the other bits are the position
FIRST_TOUCH = np.uint32(2**31)
POSITION = np.uint32(2**31 - 1)


def unsigned(indices):
    """An int index array as the kernels' uint64 indices (a view when it is int64 already,
    any strides): a negative index becomes one out of range, which the kernels' check
    reports (``t2 = -1`` becomes :data:`NO_T`)."""
    return np.asarray(indices).astype(np.int64, copy=False).view(np.uint64)


def padded_length(n):
    """Row length ``>= n`` for buffers of many rows of ``n`` float64.

    The byte stride of the rows is 192 modulo 4096, so any two of up to 21
    rows written together by one loop start at least 192 bytes apart modulo
    4 KiB. Rows whose stride is a multiple of 4 KiB alias in the store
    buffer ("4K aliasing"): at level 5, ``n_d = 30720 = 60 * 512``, that
    made :func:`diamond_geometry_kernel` about 3 times slower.
    """
    return n + (24 - n) % 512


@numba.njit(**_OPTIONS, inline="always")
def _diamond(diamonds, d, n_f, n_t):
    """``a, b, t1, t2`` of diamond ``d``, whether it is inner (``t2 != NO_T``) and
    whether its indices are below ``n_f``, ``n_t`` (uint64: a comparison of
    uint64 with int64 would go through float64)."""
    a, b, t1, t2 = diamonds[0, d], diamonds[1, d], diamonds[2, d], diamonds[3, d]
    inner = t2 != NO_T
    valid = a < n_f and b < n_f and t1 < n_t and (not inner or t2 < n_t)
    return a, b, t1, t2, inner, valid


@numba.njit(**_OPTIONS, inline="always")
def _add_quarters(chi_f, chi_t, a, b, t1, t2, inner, q_a1, q_a2, q_b1, q_b2):
    """Add the quarters ``(F_a, T_t1, S)``, ``(F_a, S, T_t2)``, ``(F_b, T_t1, S)``,
    ``(F_b, S, T_t2)`` of one diamond to its covolumes (Section 2.2.4)."""
    chi_f[a] += q_a1 + q_a2
    chi_f[b] += q_b1 + q_b2
    chi_t[t1] += q_a1 + q_b1
    if inner:
        chi_t[t2] += q_a2 + q_b2


@numba.njit(**_OPTIONS, inline="always")
def _geometry_block(F, T, diamonds, order, lo, hi, broken, vectors, scatter, chi_f, chi_t,
                    out):
    """The diamonds ``order[lo:hi]`` of :func:`diamond_geometry_kernel`; returns how
    many had an index out of range (skipped)."""
    n_f, n_t = np.uint64(F.shape[0]), np.uint64(T.shape[0])
    bad = 0
    for j in range(lo, hi):
        d = order[j]
        a, b, t1, t2, inner, valid = _diamond(diamonds, d, n_f, n_t)
        if not valid:
            bad += 1
            continue
        uu = vv = ee = uv = ue = ve = 0.0
        for k in range(3):
            fa, fb, p = F[a, k], F[b, k], T[t1, k]
            # T_t2 = F_a + F_b - T_t1 on a boundary diamond (Section 2.2.5)
            q = T[t2, k] if inner else (fa + fb) - p
            u, v = fb - fa, q - p                          # diagonals (2.3)
            e = (((fa + fb) - p) - q) * 0.25               # F_a - S = e - u/2 etc.
            if vectors:
                out[ROW_U + k, d] = u
                out[ROW_V + k, d] = v
                out[ROW_E + k, d] = e
            uu += u * u
            vv += v * v
            ee += e * e
            uv += u * v
            ue += u * e
            ve += v * e
        # squared lengths of F_a - S, F_b - S, T_t1 - S, T_t2 - S
        base_f, base_t = 0.25 * uu + ee, 0.25 * vv + ee
        ra2, rb2, p2, q2 = base_f - ue, base_f + ue, base_t + ve, base_t - ve
        # (F_a - S).(T_t1 - S) etc. for the four quarter triangles at S (Section 2.2.4)
        c_minus, c_plus = 0.25 * uv - ee, 0.25 * uv + ee
        d_minus, d_plus = 0.5 * (ue - ve), 0.5 * (ue + ve)
        ra_p, rb_q = c_minus + d_minus, c_minus - d_minus
        ra_q, rb_p = d_plus - c_plus, d_plus + c_plus      # rb_p up to its sign
        # area = |x| |y| sin / 2 = sqrt(|x|^2 |y|^2 - (x.y)^2) / 2
        q_a1 = 0.5 * np.sqrt(max(ra2 * p2 - ra_p * ra_p, 0.0))
        q_b1 = 0.5 * np.sqrt(max(rb2 * p2 - rb_p * rb_p, 0.0))
        q_a2 = q_b2 = 0.0          # a boundary diamond: only the side of T_t1
        if inner:
            q_a2 = 0.5 * np.sqrt(max(ra2 * q2 - ra_q * ra_q, 0.0))
            q_b2 = 0.5 * np.sqrt(max(rb2 * q2 - rb_q * rb_q, 0.0))
        if scatter:                # the covolumes, as covolume_kernel
            _add_quarters(chi_f, chi_t, a, b, t1, t2, inner, q_a1, q_a2, q_b1, q_b2)
        else:
            out[ROW_QUARTERS, d] = q_a1
            out[ROW_QUARTERS + 1, d] = q_a2
            out[ROW_QUARTERS + 2, d] = q_b1
            out[ROW_QUARTERS + 3, d] = q_b2
        out[ROW_LEN_U, d] = np.sqrt(uu)
        out[ROW_LEN_V, d] = np.sqrt(vv)                    # d^T (2.8)
        out[ROW_J, d] = np.sqrt(max(0.0, uu * vv - uv * uv))   # |u x v| = 2 chi(V^D) (2.8)
        out[ROW_UV, d] = uv
        if broken:
            out[ROW_GAMMA_T, d] = np.sqrt(p2) + np.sqrt(q2)    # (2.5)
            out[ROW_GAMMA_F, d] = np.sqrt(ra2) + np.sqrt(rb2)  # (2.15), Section 2.2.5
    return bad


@numba.njit("void(float64[:, :], float64[:, :], uint64[:, :], uint64[::1], uint64[::1], "
            "boolean, boolean, boolean, float64[::1], float64[::1], float64[:, ::1])",
            **_OPTIONS)
def diamond_geometry_kernel(F, T, diamonds, order, starts, broken, vectors, scatter, chi_f,
                            chi_t, out):
    """Per-diamond geometry in one pass, see :func:`ddfv.geometry.diamond_geometry`.

    The blocks of :meth:`ddfv.topology.DiamondMesh.diamond_blocks` one per
    thread, then the diamonds across blocks.

    Parameters
    ----------
    F : (n_f, 3) float64 array
    T : (n_t, 3) float64 array
    diamonds : (4, n_d) uint64 array
        Rows ``a, b, t1, t2``; ``t2 = NO_T`` on boundary diamonds.
    order, starts : uint64 arrays
        The diamond blocks.
    broken : bool
        Write ``|gamma^T|``, ``|gamma^F|`` as broken lines (2.5), (2.15);
        otherwise the rows ``ROW_GAMMA_T``, ``ROW_GAMMA_F`` are left alone
        (the chord is ``|v|``, ``|u|``).
    vectors : bool
        Write the rows ``u``, ``v``, ``e``; otherwise they are left alone.
    scatter : bool
        Add the quarters into the covolumes ``chi_f``, ``chi_t`` (as
        :func:`covolume_kernel`) instead of writing their rows.
    chi_f : (n_f,) float64 array, output (any length when not ``scatter``)
    chi_t : (n_t,) float64 array, output (any length when not ``scatter``)
    out : (GEOMETRY_ROWS, >= n_d) float64 array
        Rows ``u`` (3), ``v`` (3), ``e`` (3), ``|u|``, ``|v|``, ``J``,
        ``u.v``, ``|gamma^T|``, ``|gamma^F|``, the four quarters. On large
        meshes the pass is bound by its writes: the rows not asked for are
        left alone.
    """
    if scatter:
        if chi_f.shape[0] != F.shape[0] or chi_t.shape[0] != T.shape[0]:
            raise ValueError("covolume arrays do not fit F and T")
        chi_f[:] = 0.0
        chi_t[:] = 0.0
    parts = starts.shape[0] - 2
    bad = np.zeros(parts + 1, dtype=np.int64)       # per block (no reduction across blocks)
    for k in numba.prange(parts):
        bad[k] = _geometry_block(F, T, diamonds, order, starts[k], starts[k + 1], broken,
                                 vectors, scatter, chi_f, chi_t, out)
    bad[parts] = _geometry_block(F, T, diamonds, order, starts[parts], starts[parts + 1],
                                 broken, vectors, scatter, chi_f, chi_t, out)
    if bad.any():
        raise IndexError("diamond index out of range")


@numba.njit(**_OPTIONS, inline="always")
def _scatter_quarters(diamonds, quarters, order, lo, hi, chi_f, chi_t):
    """The diamonds ``order[lo:hi]`` of :func:`covolume_kernel`; returns how many
    had an index out of range (skipped)."""
    n_f, n_t = np.uint64(chi_f.shape[0]), np.uint64(chi_t.shape[0])
    bad = 0
    for j in range(lo, hi):
        d = order[j]
        a, b, t1, t2, inner, valid = _diamond(diamonds, d, n_f, n_t)
        if not valid:
            bad += 1
            continue
        _add_quarters(chi_f, chi_t, a, b, t1, t2, inner,
                      quarters[0, d], quarters[1, d], quarters[2, d], quarters[3, d])
    return bad


@numba.njit("void(uint64[:, :], float64[:, :], uint64[::1], uint64[::1], float64[::1], "
            "float64[::1])", **_OPTIONS)
def covolume_kernel(diamonds, quarters, order, starts, chi_f, chi_t):
    """Scatter the quarters of each diamond into ``chi(V^F)``, ``chi(V^T)`` (Section 2.2.4).

    The blocks of :meth:`ddfv.topology.DiamondMesh.diamond_blocks` one per
    thread, then the diamonds across blocks.

    Parameters
    ----------
    diamonds : (4, n_d) uint64 array
    quarters : (4, n_d) float64 array
        Areas of ``(F_a, T_t1, S)``, ``(F_a, S, T_t2)``, ``(F_b, T_t1, S)``,
        ``(F_b, S, T_t2)``.
    order, starts : uint64 arrays
        The diamond blocks.
    chi_f : (n_f,) float64 array, output
    chi_t : (n_t,) float64 array, output
    """
    chi_f[:] = 0.0
    chi_t[:] = 0.0
    parts = starts.shape[0] - 2
    bad = np.zeros(parts + 1, dtype=np.int64)       # per block (no reduction across blocks)
    for k in numba.prange(parts):
        bad[k] = _scatter_quarters(diamonds, quarters, order, starts[k], starts[k + 1],
                                   chi_f, chi_t)
    bad[parts] = _scatter_quarters(diamonds, quarters, order, starts[parts],
                                   starts[parts + 1], chi_f, chi_t)
    if bad.any():
        raise IndexError("diamond index out of range")


@numba.njit("void(uint64[:, :], float64[:, :], float64[:, :], int64, float64[:, ::1])",
            **_OPTIONS)
def vertex_normals_kernel(diamonds, u, v, n_f, out):
    """Unit normals at F- and T-vertices: normalised sums of ``u x v`` (3.6).

    Parameters
    ----------
    diamonds : (4, n_d) uint64 array
    u, v : (3, n_d) float64 arrays
    n_f : int
    out : (3, n_f + n_t) float64 array, output
    """
    n_t = np.uint64(out.shape[1] - n_f)
    nf = np.uint64(n_f)    # uint64 + int64 would be float64 in numba
    out[:, :] = 0.0
    for d in range(diamonds.shape[1]):
        a, b, t1, t2, inner, valid = _diamond(diamonds, d, nf, n_t)
        if not valid:
            raise IndexError("diamond index out of range")
        # u x v = 2 chi(V^D) N^D
        c0 = u[1, d] * v[2, d] - u[2, d] * v[1, d]
        c1 = u[2, d] * v[0, d] - u[0, d] * v[2, d]
        c2 = u[0, d] * v[1, d] - u[1, d] * v[0, d]
        for k in range(3):
            i = a if k == 0 else (b if k == 1 else nf + t1)
            out[0, i] += c0
            out[1, i] += c1
            out[2, i] += c2
        if inner:
            out[0, nf + t2] += c0
            out[1, nf + t2] += c1
            out[2, nf + t2] += c2
    for i in range(out.shape[1]):
        norm = np.sqrt(out[0, i] * out[0, i] + out[1, i] * out[1, i] + out[2, i] * out[2, i])
        out[0, i] /= norm
        out[1, i] /= norm
        out[2, i] /= norm


@numba.njit("UniTuple(float64, 4)(float64, float64, float64, float64, float64, float64)",
            **_OPTIONS, inline="always")
def flux_coefficients_kernel(gamma_t, gamma_f, J, len_u, len_v, uv):
    """``alpha, beta, alpha_hat, beta_hat`` of one diamond (2.12), (2.15).

    The Python function (``.py_func``) also evaluates arrays elementwise:
    :func:`ddfv.assembly.flux_coefficients` uses it, so the formulas exist
    once.
    """
    gt_J = gamma_t / J
    gf_J = gamma_f / J
    return (gt_J * len_v,              # alpha = q^F / 2              (2.12)
            gt_J * uv / len_v,         # beta = |g^T|/d^T cot(omega)  (2.12)
            gf_J * len_u,              # alpha_hat = q_hat^T / 2      (2.15)
            gf_J * uv / len_u)         # beta_hat = q_hat^F           (2.15)


@numba.njit(**_OPTIONS, inline="always")
def _accumulate(data, slot, init, value):
    """``data[i] += value``, ``i`` the position of ``slot``; at a slot flagged
    :data:`FIRST_TOUCH` ``data[i] = init + value`` instead (``init`` the value
    the entry would have been set to before any diamond: bitwise the same)."""
    i = slot & POSITION
    old = data[i]          # read either way: a select, not a branch
    data[i] = (init if slot >= FIRST_TOUCH else old) + value


@numba.njit(**_OPTIONS, inline="always")
def _scatter_entries(inner, gamma_t, gamma_f, J, len_u, len_v, uv, slots, rows, scale, shift,
                     order, lo, hi, data):
    """The diamonds ``order[lo:hi]`` of :func:`system_kernel`. A subtraction
    ``x - y`` is added as ``x + (-y)`` (IEEE: the same)."""
    for j in range(lo, hi):
        d = order[j]
        alpha, beta, alpha_hat, beta_hat = flux_coefficients_kernel(
            gamma_t[d], gamma_f[d], J[d], len_u[d], len_v[d], uv[d])
        s = slots[d]
        r = rows[d]
        s_a, s_b, s_t1 = scale[r[0]], scale[r[1]], scale[r[2]]
        # F-rows: flux_a = alpha (f_b - f_a) - beta (f_t2 - f_t1) = -flux_b
        data[s[SLOT_AB]] = -(alpha * s_a)           # entries of one diamond only
        data[s[SLOT_BA]] = -(alpha * s_b)
        _accumulate(data, s[SLOT_AA], shift, alpha * s_a)
        _accumulate(data, s[SLOT_BB], shift, alpha * s_b)
        _accumulate(data, s[SLOT_A_T1], 0.0, -(beta * s_a))
        _accumulate(data, s[SLOT_B_T1], 0.0, beta * s_b)
        if inner[d]:
            s_t2 = scale[r[3]]
            _accumulate(data, s[SLOT_A_T2], 0.0, beta * s_a)
            _accumulate(data, s[SLOT_B_T2], 0.0, -(beta * s_b))
            # T-rows: flux_t1 = alpha_hat (f_t2 - f_t1) - beta_hat (f_b - f_a) = -flux_t2
            _accumulate(data, s[SLOT_T1_A], 0.0, -(beta_hat * s_t1))
            _accumulate(data, s[SLOT_T1_B], 0.0, beta_hat * s_t1)
            _accumulate(data, s[SLOT_T2_A], 0.0, beta_hat * s_t2)
            _accumulate(data, s[SLOT_T2_B], 0.0, -(beta_hat * s_t2))
            data[s[SLOT_T1_T2]] = -(alpha_hat * s_t1)
            data[s[SLOT_T2_T1]] = -(alpha_hat * s_t2)
            _accumulate(data, s[SLOT_T1_T1], shift, alpha_hat * s_t1)
            _accumulate(data, s[SLOT_T2_T2], shift, alpha_hat * s_t2)
        else:
            # f_t2 = f_a + f_b - f_t1 in the T-equation (Section 2.2.5)
            _accumulate(data, s[SLOT_T1_A], 0.0, -((beta_hat + alpha_hat) * s_t1))
            _accumulate(data, s[SLOT_T1_B], 0.0, (beta_hat - alpha_hat) * s_t1)
            _accumulate(data, s[SLOT_T1_T1], shift, (2.0 * alpha_hat) * s_t1)


@numba.njit("void(boolean[::1], float64[:], float64[:], float64[:], float64[:], float64[:], "
            "float64[:], uint32[:, ::1], uint32[:, ::1], uint64[::1], uint64[::1], "
            "uint32[::1], float64[::1], float64, float64[::1])", **_OPTIONS)
def system_kernel(inner, gamma_t, gamma_f, J, len_u, len_v, uv, slots, rows, order, starts,
                  untouched, scale, shift, data):
    """Values of ``diag(scale) K + shift I`` in a fixed CSR pattern (2.10)-(2.15).

    Each diamond adds its entries of ``K`` (minus its fluxes, see
    :mod:`ddfv.assembly`), each times the ``scale`` of its row, into their CSR
    slots, the blocks of :meth:`ddfv.topology.DiamondMesh.diamond_blocks` one
    per thread, then the diamonds across blocks. No pass sets the values
    first: the first write into each entry, flagged in its slot
    (:data:`FIRST_TOUCH`), starts from ``shift`` (diagonal) or 0, the value
    the entry would have had, so the sums are bitwise those of a zeroed
    array; the diagonal entries no diamond writes (``untouched``: rows of
    vertices in no triangle) are set to ``shift``. The slots, ``rows`` and
    ``untouched`` come from :class:`ddfv.assembly.Assembler` (positions in
    its CSR pattern and rows, all in range by construction) and are not
    checked here.

    Parameters
    ----------
    inner : (n_d,) bool array
        False on boundary diamonds (``t2 = -1``).
    gamma_t, gamma_f, J, len_u, len_v, uv : (n_d,) float64 arrays
        The geometric factors of :class:`ddfv.geometry.DiamondGeometry`.
    slots : (n_d, N_SLOTS) uint32 array
        CSR position of each entry of the diamond (``SLOT_*``), flagged
        :data:`FIRST_TOUCH` at the first write into the entry in the order
        of ``order``; the ``t2`` slots of boundary diamonds are unused.
    rows : (n_d, 4) uint32 array
        The rows ``a, b, n_f + t1, n_f + t2`` of each diamond (the last unused
        on boundary diamonds).
    order, starts : uint64 arrays
        The diamond blocks.
    untouched : uint32 array
        CSR positions of the diagonal entries no diamond writes.
    scale : (n,) float64 array
    shift : float
    data : (nnz,) float64 array, output
    """
    for i in range(untouched.shape[0]):
        data[untouched[i]] = shift
    parts = starts.shape[0] - 2
    for k in numba.prange(parts):
        _scatter_entries(inner, gamma_t, gamma_f, J, len_u, len_v, uv, slots, rows, scale,
                         shift, order, starts[k], starts[k + 1], data)
    _scatter_entries(inner, gamma_t, gamma_f, J, len_u, len_v, uv, slots, rows, scale, shift,
                     order, starts[parts], starts[parts + 1], data)


@numba.njit("void(uint32[:, ::1], boolean[::1], uint64[::1], boolean[::1], boolean[::1], "
            "boolean[::1], uint32[:, ::1])", **_OPTIONS)
def first_touch_kernel(slots, inner, order, boundary_used, accumulated, seen, flagged):
    """The slot table of :func:`system_kernel` with the first write into each entry
    flagged (:meth:`ddfv.assembly.Assembler._first_touch`).

    Parameters
    ----------
    slots : (n_d, N_SLOTS) uint32 array
        CSR position of each entry of each diamond (in range by construction).
    inner : (n_d,) bool array
    order : (n_d,) uint64 array
        The diamonds in the order :func:`system_kernel` writes them.
    boundary_used : (N_SLOTS,) bool array
        The slots a boundary diamond writes.
    accumulated : (N_SLOTS,) bool array
        The slots :func:`system_kernel` adds into (the others it assigns).
    seen : (nnz,) bool array, output
        Whether a diamond writes the entry.
    flagged : (n_d, N_SLOTS) uint32 array, output
        ``slots``, :data:`FIRST_TOUCH` set on the accumulated slots of first writes.
    """
    seen[:] = False
    for j in range(order.shape[0]):
        d = order[j]
        for c in range(N_SLOTS):
            s = slots[d, c]
            flagged[d, c] = s
            if (inner[d] or boundary_used[c]) and not seen[s]:
                seen[s] = True
                if accumulated[c]:
                    flagged[d, c] = s | FIRST_TOUCH


@numba.njit("float64(float64)", **_OPTIONS, inline="always")
def _bernoulli(x):
    """``x / (e^x - 1)``, 1 at 0 (the Bernoulli function of the drift
    weights, ``ddfv/README.md``; its numpy reference is ``tests/reference.py``); for ``|x| < 0.1``
    (every weight under the default Peclet limit) its Taylor series ``sum B_k x^k / k!``
    to ``x^8``: the next term is below 2.1e-18, so the value is that of ``expm1`` to
    rounding (measured: 2.2e-16 relative), at a third of its cost."""
    if abs(x) < 0.1:
        x2 = x * x
        return 1.0 - 0.5 * x + x2 * (1.0 / 12.0 + x2 * (-1.0 / 720.0 + x2 * (
            1.0 / 30240.0 - x2 / 1209600.0)))
    return x / np.expm1(x)


@numba.njit("void(boolean[::1], float64[:], float64[:], float64[:], float64[:], float64[:], "
            "float64[:], uint32[:, ::1], uint64[:, :], float64[::1], float64[::1], "
            "float64, float64[:, ::1], int64, float64[::1], float64[:, ::1])", **_OPTIONS)
def drift_kernel(inner, gamma_t, gamma_f, J, len_u, len_v, uv, slots, diamonds, psi, scale,
                 peclet, X, n_f, data, DX):
    """Adds ``diag(scale) D`` of the drift (R7) into ``data`` (the CSR values of
    :class:`ddfv.assembly.Assembler`'s pattern; :func:`ddfv.redistribution.drift_system`)
    and writes ``diag(scale) D X`` into ``DX`` in the same pass.

    Each inner diamond ``(a, b, t1, t2)`` multiplies the F-row part of its
    fluxes (``(K f)_a = alpha (f_a - f_b) + beta (f_t2 - f_t1) = -(K f)_b``,
    :func:`system_kernel`) by ``B(-d) - 1`` in the row of ``a`` and ``B(d) - 1``
    in the row of ``b``, ``d = psi_b - psi_a`` clipped to ``[-peclet,
    peclet]``, ``B`` the Bernoulli function; each row is scaled by
    ``scale`` (``dt / chi``, zero at Dirichlet rows). One sequential pass
    (the rows of neighbouring diamonds share entries).

    Parameters
    ----------
    inner : (n_d,) bool array
    gamma_t, gamma_f, J, len_u, len_v, uv : (n_d,) float64 arrays
    slots : (n_d, N_SLOTS) uint32 array
    diamonds : (4, n_d) uint64 array
        ``a, b, t1, t2`` (:func:`ddfv.geometry._diamond_indices`).
    psi : (n,) float64 array
    scale : (n,) float64 array
    peclet : float
    X : (3, n) float64 array
        Positions ``[F; T]`` (own numbering).
    n_f : int
    data : (nnz,) float64 array, updated
    DX : (3, n) float64 array, output
        ``diag(scale) D X``; zero in the T-rows.
    """
    DX[:] = 0.0
    for d in range(len(inner)):
        if not inner[d]:
            continue
        alpha, beta, _, _ = flux_coefficients_kernel(
            gamma_t[d], gamma_f[d], J[d], len_u[d], len_v[d], uv[d])
        a, b = diamonds[0, d], diamonds[1, d]
        t1, t2 = n_f + np.int64(diamonds[2, d]), n_f + np.int64(diamonds[3, d])
        x = min(max(psi[b] - psi[a], -peclet), peclet)
        ca = (_bernoulli(-x) - 1.0) * scale[a]
        cb = (_bernoulli(x) - 1.0) * scale[b]
        s = slots[d]
        data[s[SLOT_AA]] += ca * alpha
        data[s[SLOT_AB]] -= ca * alpha
        data[s[SLOT_A_T2]] += ca * beta
        data[s[SLOT_A_T1]] -= ca * beta
        data[s[SLOT_BA]] -= cb * alpha
        data[s[SLOT_BB]] += cb * alpha
        data[s[SLOT_B_T2]] -= cb * beta
        data[s[SLOT_B_T1]] += cb * beta
        for k in range(3):       # (K f)_a of the flux times the weights, f = X_k
            flux = alpha * (X[k, a] - X[k, b]) + beta * (X[k, t2] - X[k, t1])
            DX[k, a] += ca * flux
            DX[k, b] -= cb * flux


@numba.njit("float64(float64[:, :], float64[:, :], uint64[:, :], float64[:, ::1])", **_OPTIONS)
def t_barycentric_kernel(F, T, faces, out):
    """Barycentric coordinates of the projection of ``T_i`` into triangle ``i``.

    Returns the smallest coordinate (the T monitor), NaN when one is NaN
    (as ``out.min()``).

    Parameters
    ----------
    F : (n_f, 3) float64 array
    T : (n_t, 3) float64 array
    faces : (n_t, 3) uint64 array
    out : (n_t, 3) float64 array, output
    """
    n_f = np.uint64(F.shape[0])
    low = np.inf
    nans = 0
    bad = 0
    for t in numba.prange(faces.shape[0]):
        i0, i1, i2 = faces[t, 0], faces[t, 1], faces[t, 2]
        if i0 >= n_f or i1 >= n_f or i2 >= n_f:
            bad += 1            # raised after the loop (a raise would keep it serial)
            continue
        g11 = g12 = g22 = r1 = r2 = 0.0
        for k in range(3):
            p0 = F[i0, k]
            e1, e2, dk = F[i1, k] - p0, F[i2, k] - p0, T[t, k] - p0
            g11 += e1 * e1
            g12 += e1 * e2
            g22 += e2 * e2
            r1 += e1 * dk
            r2 += e2 * dk
        # normal equations of the projection onto the plane of the triangle
        det = g11 * g22 - g12 * g12
        l1 = (g22 * r1 - g12 * r2) / det
        l2 = (g11 * r2 - g12 * r1) / det
        l0 = 1.0 - l1 - l2
        out[t, 0] = l0
        out[t, 1] = l1
        out[t, 2] = l2
        if l0 == l0 and l1 == l1 and l2 == l2:
            low = min(low, min(l0, l1, l2))
        else:
            nans += 1
    if bad > 0:
        raise IndexError("face index out of range")
    return np.nan if nans > 0 else low
