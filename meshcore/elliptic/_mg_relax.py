r"""Point Gauss–Seidel relaxation of the multigrid (FAS) equations ``N(u) = f`` (numba).

``N(u)_P = 2(α + γ) φ_P − s(φ)`` with ``(s, den)`` from :func:`._stencil.winslow`;
the coefficients do not involve φ_P, so the pointwise update
``φ_P ← (s + f_P) / (2(α + γ))`` solves the equation at P exactly.

Ordering.  Gauss–Seidel in the **4-colour** (2×2 parity) order of
:func:`._kernels.sweep4`, executed as two passes per sweep: all rows of even
``i`` (in each row first the odd-``j`` then the even-``j`` nodes), then all
rows of odd ``i``.  Rows of one parity never appear in each other's 9-point
stencils, so this is the same arithmetic as the 4-colour sweep and the rows of
a pass are independent: the serial and ``parallel=True`` compilations of each
function give bit-identical results.  Periodic ξ with an odd number of cells
(coarse O-grid levels) makes rows ``0`` and ``ni − 1`` neighbours of the same
parity; row 0 is then updated after the others, in both compilations.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from ._compile import ROW_CHUNKS, parallel, serial
from ._stencil import winslow_at, with_sources

__all__ = ["smooth", "smooth_band", "smooth_parallel"]

#: Rows at least this long use the vectorised (compute-all, store-half) row update.
VECTOR_ROW = 48
#: Band strips at most this wide are relaxed transposed (wider ones: the vectorised
#: kernel's doubled arithmetic eats the gain; measured).
TRANSPOSE_MAX_WIDTH = 4


@njit(cache=True, nogil=True)
def _relax_row(x, y, fx, fy, p, q, use_f, use_pq, i, iw, ie, nj1):  # pragma: no cover
    """Gauss–Seidel update of row ``i``: odd ``j`` first, then even ``j`` (stride-2 loops)."""
    for cj in range(2):
        for j in range(1 + cj, nj1 - 1, 2):
            sx, sy, den, xxi, yxi, xet, yet = winslow_at(x, y, i, iw, ie, j)
            if use_pq:
                sx, sy = with_sources(sx, sy, xxi, yxi, xet, yet, p[i, j], q[i, j])
            if use_f:
                sx += fx[i, j]
                sy += fy[i, j]
            if den > 0.0:
                inv = 1.0 / den
                x[i, j] = sx * inv
                y[i, j] = sy * inv


@njit(cache=True, nogil=True)
def _relax_row_vec(x, y, fx, fy, p, q, use_f, use_pq, i, iw, ie, nj1, tx, ty):  # pragma: no cover
    """:func:`_relax_row` for long rows, same arithmetic per node, so identical results.

    Each half computes the targets of the *whole* row into fresh scratch rows
    with unit-stride loops (which vectorise; the stride-2 loop does not; the
    scratch ``tx, ty`` must be freshly allocated by the caller so that LLVM
    knows it does not alias ``x``) and then stores its own half: twice the
    arithmetic, less time.
    """
    for cj in range(2):
        for j in range(1, nj1 - 1):
            sx, sy, den, xxi, yxi, xet, yet = winslow_at(x, y, i, iw, ie, j)
            if use_pq:
                sx, sy = with_sources(sx, sy, xxi, yxi, xet, yet, p[i, j], q[i, j])
            if use_f:
                sx += fx[i, j]
                sy += fy[i, j]
            ok = den > 0.0
            inv = 1.0 / den if ok else 0.0
            tx[j] = sx * inv if ok else x[i, j]
            ty[j] = sy * inv if ok else y[i, j]
        for j in range(1 + cj, nj1 - 1, 2):
            x[i, j] = tx[j]
            y[i, j] = ty[j]


# inline="always": :func:`smooth_band` calls it per row for a band a few nodes wide (the FMG band
# of width 2: 1 node per colour), where the call cost as much as the nodes: 10.6 → 7.9 ns per node
# update there on a 33 × 17 level, the same bits
@njit(cache=True, nogil=True, inline="always")
def _relax_range(x, y, fx, fy, p, q, use_f, use_pq, i, iw, ie, j0, j1):  # pragma: no cover
    """Gauss–Seidel update of row ``i`` for ``j0 ≤ j < j1`` (odd j first, as in ``_smooth``)."""
    for cj in range(2):
        for j in range(j0 + ((1 + cj - j0) % 2), j1, 2):
            sx, sy, den, xxi, yxi, xet, yet = winslow_at(x, y, i, iw, ie, j)
            if use_pq:
                sx, sy = with_sources(sx, sy, xxi, yxi, xet, yet, p[i, j], q[i, j])
            if use_f:
                sx += fx[i, j]
                sy += fy[i, j]
            if den > 0.0:
                inv = 1.0 / den
                x[i, j] = sx * inv
                y[i, j] = sy * inv


@njit(cache=True, nogil=True)
def _strip_in(a, at, j0, periodic):  # pragma: no cover - compiled
    """Columns ``j0 … j0 + at.shape[0] − 1`` of ``a`` as the rows of ``at`` (transposed).

    Periodic ξ gets one extra entry in front (``i = ni − 1`` before ``i = 0``;
    ``i = ni`` ≡ 0 is last), so every node of the ring is inside.
    """
    ni = a.shape[0] - 1
    off = 1 if periodic else 0
    for jj in range(at.shape[0]):
        j = j0 + jj
        if periodic:
            at[jj, 0] = a[ni - 1, j]
        for i in range(ni + 1):
            at[jj, i + off] = a[i, j]


@njit(cache=True, nogil=True)
def _strip_out(at, a, j0, periodic):  # pragma: no cover - compiled
    """Rows ``1 … at.shape[0] − 2`` of ``at`` back into their columns of ``a``."""
    ni = a.shape[0] - 1
    off = 1 if periodic else 0
    for jj in range(1, at.shape[0] - 1):
        j = j0 + jj
        for i in range(1 - off, ni):
            a[i, j] = at[jj, i + off]
        if periodic:
            a[ni, j] = a[0, j]


@njit(cache=True, nogil=True)
def smooth_band(x, y, fx, fy, p, q, periodic, width, sweeps):  # pragma: no cover - compiled
    """Extra Gauss–Seidel sweeps on the nodes within ``width`` of a border.

    Local relaxation where the nonlinearity is strongest (next to curved
    borders): costs O(n·width) per sweep.  Serial only (it is cheap), so it
    is the same in serial and threaded solves.  Each sweep relaxes the rows
    next to the ξ borders (4-colour order, vectorised when long), then the
    strips next to the η borders: long narrow strips are copied transposed
    (the equations are the same with ξ ↔ η and P ↔ Q) and relaxed row by row
    with the vectorised row kernel; others row by row in place.
    """
    ni1, nj1 = x.shape
    use_f = fx.size > 0
    use_pq = p.size > 0
    ni = ni1 - 1
    nj = nj1 - 1
    i0 = 0 if periodic else 1
    late0 = periodic and ni % 2 == 1  # row 0 and ni - 1 share a parity: row 0 goes last
    vec = nj1 >= VECTOR_ROW
    strips = nj > 2 * width + 2
    trans = strips and ni1 >= VECTOR_ROW and width <= TRANSPOSE_MAX_WIDTH
    tx = np.empty(nj1)
    ty = np.empty(nj1)
    # transposed strips (rows 0 and width + 1 are their fixed neighbours)
    L = ni1 + 1 if periodic else ni1
    W = width + 2 if trans else 0
    e = np.zeros((0, 0))
    xs = np.empty((2, W, L))
    ys = np.empty((2, W, L))
    fxs = np.empty((2, W, L)) if (trans and use_f) else np.empty((2, 0, 0))
    fys = np.empty((2, W, L)) if (trans and use_f) else np.empty((2, 0, 0))
    ps = np.empty((2, W, L)) if (trans and use_pq) else np.empty((2, 0, 0))
    qs = np.empty((2, W, L)) if (trans and use_pq) else np.empty((2, 0, 0))
    sx = np.empty(L)
    sy = np.empty(L)
    j0s = (0, nj - width - 1)
    if trans:
        for k in range(2):
            if use_f:
                _strip_in(fx, fxs[k], j0s[k], periodic)
                _strip_in(fy, fys[k], j0s[k], periodic)
            if use_pq:
                _strip_in(q, ps[k], j0s[k], periodic)  # ξ ↔ η: P ↔ Q
                _strip_in(p, qs[k], j0s[k], periodic)
    for _ in range(sweeps):
        for ci in range(2):
            start = i0 + ((ci - i0) % 2)
            if late0 and start == 0:
                start = 2
            last = start + 2 * ((ni - 1 - start) // 2)  # last row of this parity
            lo, hi = start, last  # rows relaxed only in the strips
            if not strips:
                lo, hi = start, start - 2
            elif not periodic:
                while lo <= hi and lo <= width:
                    lo += 2
                while hi >= lo and hi >= ni - width:
                    hi -= 2
            for i in range(start, last + 1, 2):
                if lo <= i <= hi:
                    continue
                iw = i - 1
                if iw < 0:
                    iw = ni - 1
                if vec:
                    _relax_row_vec(x, y, fx, fy, p, q, use_f, use_pq, i, iw, i + 1, nj1, tx, ty)
                else:
                    _relax_range(x, y, fx, fy, p, q, use_f, use_pq, i, iw, i + 1, 1, nj)
            if trans:
                continue
            for i in range(lo, hi + 1, 2):
                iw = i - 1
                if iw < 0:
                    iw = ni - 1
                _relax_range(x, y, fx, fy, p, q, use_f, use_pq, i, iw, i + 1, 1, width + 1)
                _relax_range(x, y, fx, fy, p, q, use_f, use_pq, i, iw, i + 1, nj - width, nj)
            if periodic:
                if ci == 0 and late0:
                    if not strips:
                        _relax_range(x, y, fx, fy, p, q, use_f, use_pq, 0, ni - 1, 1, 1, nj)
                    else:
                        _relax_range(x, y, fx, fy, p, q, use_f, use_pq, 0, ni - 1, 1, 1, width + 1)
                        _relax_range(x, y, fx, fy, p, q, use_f, use_pq, 0, ni - 1, 1, nj - width, nj)
                for j in range(nj1):
                    x[ni, j] = x[0, j]
                    y[ni, j] = y[0, j]
        if trans:
            for k in range(2):
                xt = xs[k]
                yt = ys[k]
                _strip_in(x, xt, j0s[k], periodic)
                _strip_in(y, yt, j0s[k], periodic)
                fxt = fxs[k] if use_f else e
                fyt = fys[k] if use_f else e
                pt = ps[k] if use_pq else e
                qt = qs[k] if use_pq else e
                for jj in range(1, W - 1):
                    _relax_row_vec(xt, yt, fxt, fyt, pt, qt, use_f, use_pq, jj, jj - 1, jj + 1, L, sx, sy)
                _strip_out(xt, x, j0s[k], periodic)
                _strip_out(yt, y, j0s[k], periodic)


def _smooth(x, y, fx, fy, p, q, periodic, sweeps):  # pragma: no cover - compiled
    """``sweeps`` in-place 4-colour Gauss–Seidel sweeps of ``N(u) = f``.

    ``fx, fy`` (or ``p, q``) may be empty ``(0, 0)`` arrays for zero.
    """
    ni1, nj1 = x.shape
    use_f = fx.size > 0
    use_pq = p.size > 0
    ni = ni1 - 1
    i0 = 0 if periodic else 1
    # periodic with odd ni: rows 0 and ni-1 are same-parity neighbours
    late0 = periodic and (ni % 2 == 1)
    vec = nj1 >= VECTOR_ROW
    for _ in range(sweeps):
        for ci in range(2):
            start = i0 + ((ci - i0) % 2)
            if late0 and ci == 0:
                start = 2
            nrows = (ni - 1 - start) // 2 + 1 if start <= ni - 1 else 0
            nchunks = min(nrows, ROW_CHUNKS)
            for c in prange(nchunks):
                tx = np.empty(nj1)
                ty = np.empty(nj1)
                for k in range(c * nrows // nchunks, (c + 1) * nrows // nchunks):
                    i = start + 2 * k
                    iw = i - 1
                    if iw < 0:
                        iw = ni - 1
                    if vec:
                        _relax_row_vec(x, y, fx, fy, p, q, use_f, use_pq, i, iw, i + 1, nj1, tx, ty)
                    else:
                        _relax_row(x, y, fx, fy, p, q, use_f, use_pq, i, iw, i + 1, nj1)
            if periodic:
                if late0 and ci == 0:
                    if vec:
                        _relax_row_vec(
                            x, y, fx, fy, p, q, use_f, use_pq, 0, ni - 1, 1, nj1, np.empty(nj1), np.empty(nj1)
                        )
                    else:
                        _relax_row(x, y, fx, fy, p, q, use_f, use_pq, 0, ni - 1, 1, nj1)
                for j in range(nj1):
                    x[ni, j] = x[0, j]
                    y[ni, j] = y[0, j]


_smooth_two_pass = serial(_smooth)
smooth_parallel = parallel(_smooth)


@njit(cache=True, nogil=True)
def smooth(x, y, fx, fy, p, q, periodic, sweeps):  # pragma: no cover - compiled
    """Serial :func:`_smooth`, in one pass over the rows (a wavefront).

    The two passes of a sweep (even rows, then odd rows) are interleaved:
    odd row ``i − 1`` is relaxed right after even row ``i``, when both its
    neighbour rows are final.  Each row sees exactly the values it sees in
    the two-pass order (odd rows depend only on even rows and themselves),
    so the results are bit-identical to ``smooth_parallel``, with half the
    memory traffic on grids larger than the cache.  Periodic grids use the
    two-pass order.
    """
    if periodic:
        _smooth_two_pass(x, y, fx, fy, p, q, periodic, sweeps)
        return
    ni1, nj1 = x.shape
    use_f = fx.size > 0
    use_pq = p.size > 0
    ni = ni1 - 1
    vec = nj1 >= VECTOR_ROW
    tx = np.empty(nj1)
    ty = np.empty(nj1)
    last_even = ni - 1 if (ni - 1) % 2 == 0 else ni - 2
    for _ in range(sweeps):
        for i in range(2, last_even + 1, 2):
            for r in (i, i - 1):
                if vec:
                    _relax_row_vec(x, y, fx, fy, p, q, use_f, use_pq, r, r - 1, r + 1, nj1, tx, ty)
                else:
                    _relax_row(x, y, fx, fy, p, q, use_f, use_pq, r, r - 1, r + 1, nj1)
        for r in range(max(last_even + 1, 1), ni, 2):
            if vec:
                _relax_row_vec(x, y, fx, fy, p, q, use_f, use_pq, r, r - 1, r + 1, nj1, tx, ty)
            else:
                _relax_row(x, y, fx, fy, p, q, use_f, use_pq, r, r - 1, r + 1, nj1)
