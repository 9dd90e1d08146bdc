r"""numba kernels of the nonlinear multigrid (FAS) solver (functions only).

Operator.  At an interior node the discrete Winslow/TTM equations (eq. 30,
errata applied, Δξ = Δη = 1, see :mod:`._kernels`) are written as

.. math::

    N(u)_P = 2(α + γ)\, φ_P - \big[α(φ_E + φ_W) + γ(φ_N + φ_S)
             - \tfrac{β}{2}(φ_{NE} - φ_{NW} - φ_{SE} + φ_{SW})
             + D^2 (P φ_ξ + Q φ_η)\big] = f_P,\qquad φ ∈ \{x, y\},

``N = −(α φ_ξξ − 2β φ_ξη + γ φ_ηη + D²(P φ_ξ + Q φ_η))``.  The coefficients
α, β, γ, D use central differences that do not involve φ_P, so ``N`` is
*linear in φ_P*: the pointwise nonlinear Gauss–Seidel update is exact,
``φ_P ← (rhs + f_P) / (2(α + γ))``.  On the finest level ``f = 0``; on
coarse levels ``f`` is the FAS right-hand side.  The largest ``|N(u)|/den``
with ``f = 0`` is exactly the shared stopping measure (the point-Jacobi
displacement of :func:`._kernels.jacobi_residual`).

Ordering.  Gauss–Seidel in the **4-colour** (2×2 parity) order of
:func:`._kernels.sweep4`, executed as two passes per sweep: all rows of even
``i`` (in each row first the odd-``j`` then the even-``j`` nodes), then all
rows of odd ``i``.  Rows of one parity never appear in each other's 9-point
stencils, so this is the same arithmetic as the 4-colour sweep and the rows of
a pass are independent: the serial and ``parallel=True`` compilations of each
function give bit-identical results.  Periodic ξ with an odd number of cells
(coarse O-grid levels) makes rows ``0`` and ``ni − 1`` neighbours of the same
parity; row 0 is then updated after the others, in both compilations.

Transfer operators (vertex-centred coarsening, any size).  A coarsened
direction with an even number of uniform intervals keeps every other node;
any other count ``n`` gets ``⌈n/2⌉`` coarse intervals spread uniformly over
the same span, whose nodes fall between fine nodes (see
:func:`coarse_positions`): every level is uniform in the finest index.
``R̂`` samples a fine array at the coarse nodes by linear interpolation
(injection where nested), ``P`` interpolates linearly, and the restriction
is full weighting, the normalised transpose of ``P``, given to the kernels as
index/weight tables per direction (:func:`transfer_tables`), so
non-coarsened directions
(semi-coarsening) and periodic wrap-around need no special code.
"""

from __future__ import annotations

import types

import numpy as np
from numba import njit, prange

#: Rows at least this long use the vectorised (compute-all, store-half) row update.
VECTOR_ROW = 48
#: Band strips at most this wide are relaxed transposed (wider ones: the vectorised
#: kernel's doubled arithmetic eats the gain; measured).
TRANSPOSE_MAX_WIDTH = 4
#: Rows of one colour are split into at most this many chunks (parallel work units).
ROW_CHUNKS = 16

__all__ = [
    "add_operator",
    "add_operator_parallel",
    "defect",
    "defect_parallel",
    "prolong_correct",
    "prolong_correct_parallel",
    "restrict",
    "restrict_parallel",
    "sample",
    "smooth",
    "smooth_parallel",
]


@njit(cache=True, nogil=True)
def _relax_row(x, y, fx, fy, p, q, use_f, use_pq, i, iw, ie, nj1):  # pragma: no cover
    """Gauss–Seidel update of row ``i``: odd ``j`` first, then even ``j`` (stride-2 loops)."""
    for cj in range(2):
        for j in range(1 + cj, nj1 - 1, 2):
            xe = x[ie, j]
            xw = x[iw, j]
            xn = x[i, j + 1]
            xs = x[i, j - 1]
            ye = y[ie, j]
            yw = y[iw, j]
            yn = y[i, j + 1]
            ys = y[i, j - 1]
            xxi = 0.5 * (xe - xw)
            yxi = 0.5 * (ye - yw)
            xet = 0.5 * (xn - xs)
            yet = 0.5 * (yn - ys)
            a = xet * xet + yet * yet
            b = xxi * xet + yxi * yet
            g = xxi * xxi + yxi * yxi
            den = 2.0 * (a + g)
            cx = x[ie, j + 1] - x[iw, j + 1] - x[ie, j - 1] + x[iw, j - 1]
            cy = y[ie, j + 1] - y[iw, j + 1] - y[ie, j - 1] + y[iw, j - 1]
            sx = a * (xe + xw) + g * (xn + xs) - 0.5 * b * cx
            sy = a * (ye + yw) + g * (yn + ys) - 0.5 * b * cy
            if use_pq:
                d = xxi * yet - xet * yxi
                d2 = d * d
                pp = p[i, j]
                qq = q[i, j]
                sx += d2 * (pp * xxi + qq * xet)
                sy += d2 * (pp * yxi + qq * yet)
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
            xe = x[ie, j]
            xw = x[iw, j]
            xn = x[i, j + 1]
            xs = x[i, j - 1]
            ye = y[ie, j]
            yw = y[iw, j]
            yn = y[i, j + 1]
            ys = y[i, j - 1]
            xxi = 0.5 * (xe - xw)
            yxi = 0.5 * (ye - yw)
            xet = 0.5 * (xn - xs)
            yet = 0.5 * (yn - ys)
            a = xet * xet + yet * yet
            b = xxi * xet + yxi * yet
            g = xxi * xxi + yxi * yxi
            den = 2.0 * (a + g)
            cx = x[ie, j + 1] - x[iw, j + 1] - x[ie, j - 1] + x[iw, j - 1]
            cy = y[ie, j + 1] - y[iw, j + 1] - y[ie, j - 1] + y[iw, j - 1]
            sx = a * (xe + xw) + g * (xn + xs) - 0.5 * b * cx
            sy = a * (ye + yw) + g * (yn + ys) - 0.5 * b * cy
            if use_pq:
                d = xxi * yet - xet * yxi
                d2 = d * d
                pp = p[i, j]
                qq = q[i, j]
                sx += d2 * (pp * xxi + qq * xet)
                sy += d2 * (pp * yxi + qq * yet)
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


@njit(cache=True, nogil=True)
def _relax_range(x, y, fx, fy, p, q, use_f, use_pq, i, iw, ie, j0, j1):  # pragma: no cover
    """Gauss–Seidel update of row ``i`` for ``j0 ≤ j < j1`` (odd j first, as in ``_smooth``)."""
    for cj in range(2):
        for j in range(j0 + ((1 + cj - j0) % 2), j1, 2):
            xe = x[ie, j]
            xw = x[iw, j]
            xn = x[i, j + 1]
            xs = x[i, j - 1]
            ye = y[ie, j]
            yw = y[iw, j]
            yn = y[i, j + 1]
            ys = y[i, j - 1]
            xxi = 0.5 * (xe - xw)
            yxi = 0.5 * (ye - yw)
            xet = 0.5 * (xn - xs)
            yet = 0.5 * (yn - ys)
            a = xet * xet + yet * yet
            b = xxi * xet + yxi * yet
            g = xxi * xxi + yxi * yxi
            den = 2.0 * (a + g)
            cx = x[ie, j + 1] - x[iw, j + 1] - x[ie, j - 1] + x[iw, j - 1]
            cy = y[ie, j + 1] - y[iw, j + 1] - y[ie, j - 1] + y[iw, j - 1]
            sx = a * (xe + xw) + g * (xn + xs) - 0.5 * b * cx
            sy = a * (ye + yw) + g * (yn + ys) - 0.5 * b * cy
            if use_pq:
                d = xxi * yet - xet * yxi
                d2 = d * d
                pp = p[i, j]
                qq = q[i, j]
                sx += d2 * (pp * xxi + qq * xet)
                sy += d2 * (pp * yxi + qq * yet)
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


@njit(cache=True, nogil=True)
def _defect_row(
    x, y, fx, fy, p, q, use_f, use_pq, i, iw, nj1, outx, outy, tx, ty, tq, td, measure=True
):  # pragma: no cover - compiled
    """Defect of row ``i`` into ``outx, outy`` (length ``nj1``, 0 at both ends); returns the
    row's largest ``(|f − N|/den)²`` (``inf`` on NaN; 0 without ``measure``).  ``tx … td``
    are scratch rows whose end entries are 0 (fresh, so the unit-stride loop vectorises)."""
    ie = i + 1
    for j in range(1, nj1 - 1):
        xe = x[ie, j]
        xw = x[iw, j]
        xn = x[i, j + 1]
        xs = x[i, j - 1]
        ye = y[ie, j]
        yw = y[iw, j]
        yn = y[i, j + 1]
        ys = y[i, j - 1]
        xxi = 0.5 * (xe - xw)
        yxi = 0.5 * (ye - yw)
        xet = 0.5 * (xn - xs)
        yet = 0.5 * (yn - ys)
        a = xet * xet + yet * yet
        b = xxi * xet + yxi * yet
        g = xxi * xxi + yxi * yxi
        den = 2.0 * (a + g)
        cx = x[ie, j + 1] - x[iw, j + 1] - x[ie, j - 1] + x[iw, j - 1]
        cy = y[ie, j + 1] - y[iw, j + 1] - y[ie, j - 1] + y[iw, j - 1]
        sx = a * (xe + xw) + g * (xn + xs) - 0.5 * b * cx
        sy = a * (ye + yw) + g * (yn + ys) - 0.5 * b * cy
        if use_pq:
            d = xxi * yet - xet * yxi
            d2 = d * d
            pp = p[i, j]
            qq = q[i, j]
            sx += d2 * (pp * xxi + qq * xet)
            sy += d2 * (pp * yxi + qq * yet)
        dx = sx - den * x[i, j]
        dy = sy - den * y[i, j]
        if use_f:
            dx += fx[i, j]
            dy += fy[i, j]
        tx[j] = dx
        ty[j] = dy
        if measure:
            tq[j] = dx * dx + dy * dy
            td[j] = den * den
    m = 0.0
    for j in range(nj1):
        outx[j] = tx[j]
        outy[j] = ty[j]
    if not measure:
        return m
    for j in range(nj1):
        if td[j] > 0.0 and tq[j] > m * td[j]:  # (dx² + dy²)/den² > m, divided only when true
            m = tq[j] / td[j]
    nan = 0
    for j in range(nj1):  # NaN (also from a NaN den) is never a silent pass
        nan += tq[j] != tq[j]
    return m if nan == 0 else np.inf


@njit(cache=True, nogil=True)
def _scratch_rows(nj1):  # pragma: no cover - compiled
    """Four fresh scratch rows for :func:`_defect_row` (end entries 0)."""
    tx = np.empty(nj1)
    ty = np.empty(nj1)
    tq = np.empty(nj1)
    td = np.empty(nj1)
    for e in (0, nj1 - 1):
        tx[e] = 0.0
        ty[e] = 0.0
        tq[e] = 0.0
        td[e] = 0.0
    return tx, ty, tq, td


@njit(cache=True, nogil=True)
def _defect_rows(
    x, y, fx, fy, p, q, use_f, use_pq, i0, ni, nj1, nrows, nchunks, c, rx, ry, row_max
):  # pragma: no cover - compiled
    """Rows of chunk ``c`` of :func:`_defect` (a separate function, so that the
    serial and parallel compilations run the same vectorised machine code)."""
    tx, ty, tq, td = _scratch_rows(nj1)
    for k in range(c * nrows // nchunks, (c + 1) * nrows // nchunks):
        i = i0 + k
        iw = i - 1
        if iw < 0:
            iw = ni - 1
        row_max[i] = _defect_row(x, y, fx, fy, p, q, use_f, use_pq, i, iw, nj1, rx[i], ry[i], tx, ty, tq, td)


def _defect(x, y, fx, fy, p, q, periodic, rx, ry):  # pragma: no cover - compiled
    """``r = f − N(u)`` at interior nodes (0 on the boundary); returns max (|f−N|/den)².

    With ``f = 0`` the square root of the return value is the stopping measure
    (``inf`` if any node gives NaN, as :func:`._kernels.jacobi_residual`).
    Each row is computed into local scratch rows (unit stride, no aliasing:
    the loop vectorises) and then stored; the maximum is a separate loop.
    """
    ni1, nj1 = x.shape
    use_f = fx.size > 0
    use_pq = p.size > 0
    ni = ni1 - 1
    i0 = 0 if periodic else 1
    row_max = np.zeros(ni1)
    for j in range(nj1):
        rx[0, j] = 0.0
        ry[0, j] = 0.0
        rx[ni, j] = 0.0
        ry[ni, j] = 0.0
    nrows = ni - i0
    nchunks = min(nrows, ROW_CHUNKS)
    for c in prange(nchunks):
        _defect_rows(x, y, fx, fy, p, q, use_f, use_pq, i0, ni, nj1, nrows, nchunks, c, rx, ry, row_max)
    if periodic:
        for j in range(nj1):
            rx[ni, j] = rx[0, j]
            ry[ni, j] = ry[0, j]
    return row_max.max()


@njit(cache=True, nogil=True)
def _add_operator_rows(x, y, p, q, use_pq, ni, nj1, fx, fy, lo, hi):  # pragma: no cover
    """Rows ``lo ≤ i < hi`` of :func:`_add_operator`: ``f −= (f = 0 defect)``, which is
    ``f += N(u)`` exactly (IEEE negation)."""
    tx, ty, tq, td = _scratch_rows(nj1)
    ox = np.empty(nj1)
    oy = np.empty(nj1)
    e = np.zeros((0, 0))
    for i in range(lo, hi):
        iw = i - 1
        if iw < 0:
            iw = ni - 1
        _defect_row(x, y, e, e, p, q, False, use_pq, i, iw, nj1, ox, oy, tx, ty, tq, td, False)
        for j in range(1, nj1 - 1):
            fx[i, j] -= ox[j]
            fy[i, j] -= oy[j]


def _add_operator(x, y, p, q, periodic, fx, fy):  # pragma: no cover - compiled
    """``f += N(u)`` at interior nodes (the FAS coarse right-hand side)."""
    ni1, nj1 = x.shape
    use_pq = p.size > 0
    ni = ni1 - 1
    i0 = 0 if periodic else 1
    nrows = ni - i0
    nchunks = min(nrows, ROW_CHUNKS)
    for c in prange(nchunks):
        _add_operator_rows(
            x, y, p, q, use_pq, ni, nj1, fx, fy, i0 + c * nrows // nchunks, i0 + (c + 1) * nrows // nchunks
        )
    if periodic:
        for j in range(nj1):
            fx[ni, j] = fx[0, j]
            fy[ni, j] = fy[0, j]


@njit(cache=True, nogil=True)
def _restrict_rows(rx, ry, ii, wi, jj, wj, scale, fx, fy, lo, hi):  # pragma: no cover
    """Rows ``lo ≤ I < hi`` of :func:`_restrict`."""
    nJ = fx.shape[1]
    if ii.shape[1] == 3 and jj.shape[1] == 3:  # nested both ways: fixed trip counts (unrolled)
        for I in range(lo, hi):
            for J in range(nJ):
                sx = 0.0
                sy = 0.0
                for a in range(3):
                    w_a = wi[I, a]
                    ia = ii[I, a]
                    for b in range(3):
                        w = w_a * wj[J, b]
                        jb = jj[J, b]
                        sx += w * rx[ia, jb]
                        sy += w * ry[ia, jb]
                fx[I, J] = scale * sx
                fy[I, J] = scale * sy
        return
    for I in range(lo, hi):
        for J in range(nJ):
            sx = 0.0
            sy = 0.0
            for a in range(ii.shape[1]):
                w_a = wi[I, a]
                ia = ii[I, a]
                for b in range(jj.shape[1]):
                    w = w_a * wj[J, b]
                    jb = jj[J, b]
                    sx += w * rx[ia, jb]
                    sy += w * ry[ia, jb]
            fx[I, J] = scale * sx
            fy[I, J] = scale * sy


def _restrict(rx, ry, ii, wi, jj, wj, scale, fx, fy):  # pragma: no cover - compiled
    """Full weighting ``f[I, J] = scale · Σ_ab wi[I,a] wj[J,b] r[ii[I,a], jj[J,b]]``.

    ``ii, wi`` are ``(nI, RW)`` index/weight tables (see :func:`transfer_tables`).
    """
    nI = fx.shape[0]
    nchunks = min(nI, ROW_CHUNKS)
    for c in prange(nchunks):
        _restrict_rows(rx, ry, ii, wi, jj, wj, scale, fx, fy, c * nI // nchunks, (c + 1) * nI // nchunks)


@njit(cache=True, nogil=True)
def _prolong_rows(x, y, ex, ey, li, lj, wli, wlj, nj1, lo, hi):  # pragma: no cover
    """Rows ``lo ≤ i < hi`` of the update of :func:`_prolong_correct`."""
    for i in range(lo, hi):
        a = li[i]
        wa = wli[i]
        wb = 1.0 - wa
        for j in range(1, nj1 - 1):
            b = lj[j]
            wc = wlj[j]
            wd = 1.0 - wc
            vx = wa * (wc * ex[a, b] + wd * ex[a, b + 1])
            vx += wb * (wc * ex[a + 1, b] + wd * ex[a + 1, b + 1])
            vy = wa * (wc * ey[a, b] + wd * ey[a, b + 1])
            vy += wb * (wc * ey[a + 1, b] + wd * ey[a + 1, b + 1])
            x[i, j] += vx
            y[i, j] += vy


def _prolong_correct(x, y, xc, yc, ex, ey, si, swi, sj, swj, li, lj, wli, wlj, periodic):  # pragma: no cover - compiled
    """``u += P(u_c − R̂u)`` (``R̂`` = :func:`sample`).

    ``si, swi, sj, swj`` are the sampling tables of ``R̂``; ``li[i]`` is the left coarse
    neighbour of fine ``i`` with weight ``wli[i]`` (the right one is ``li+1``
    with ``1 − wli``; both are always valid indices).
    ``ex, ey`` (coarse shape) receive the coarse correction.  Only unknowns
    change (the correction vanishes on the boundary); with periodic ξ row 0
    is an unknown and row ``ni`` is refreshed from it.
    """
    ni1, nj1 = x.shape
    nI = xc.shape[0]
    bj, wbj, nested = _sample_cols(sj, swj)
    for I in prange(nI):
        _sample_row(x, si[I], swi[I], bj, wbj, nested, ex, I)
        _sample_row(y, si[I], swi[I], bj, wbj, nested, ey, I)
        for J in range(xc.shape[1]):
            ex[I, J] = xc[I, J] - ex[I, J]
            ey[I, J] = yc[I, J] - ey[I, J]
    i0 = 0 if periodic else 1
    nrows = ni1 - 1 - i0
    nchunks = min(nrows, ROW_CHUNKS)
    for c in prange(nchunks):
        _prolong_rows(x, y, ex, ey, li, lj, wli, wlj, nj1, i0 + c * nrows // nchunks, i0 + (c + 1) * nrows // nchunks)
    if periodic:
        for j in range(nj1):
            x[ni1 - 1, j] = x[0, j]
            y[ni1 - 1, j] = y[0, j]


@njit(cache=True, nogil=True)
def _sample_cols(sj, swj):  # pragma: no cover - compiled
    """Column tables of :func:`sample` with weight-0 entries moved to the right neighbour:
    ``(b, wb, nested)`` with ``wb == 1`` exactly at fine nodes; ``nested``: all of them."""
    n = sj.size
    b = np.empty(n, dtype=np.int64)
    wb = np.empty(n)
    nested = True
    for J in range(n):
        b[J] = sj[J]
        wb[J] = swj[J]
        if wb[J] == 0.0:
            b[J] += 1
            wb[J] = 1.0
        elif wb[J] != 1.0:
            nested = False
    return b, wb, nested


@njit(cache=True, nogil=True)
def _sample_row(x, a, wa, bj, wbj, nested, out, I):  # pragma: no cover - compiled
    """Row ``I`` of :func:`sample`: between fine rows ``a, a + 1`` (weight ``wa`` on ``a``)."""
    if wa == 0.0:
        a += 1
        wa = 1.0
    nJ = out.shape[1]
    if wa == 1.0 and nested:  # injection
        for J in range(nJ):
            out[I, J] = x[a, bj[J]]
        return
    for J in range(nJ):
        b = bj[J]
        wb = wbj[J]
        if wa == 1.0:
            v = x[a, b]
            if wb != 1.0:
                v = wb * v + (1.0 - wb) * x[a, b + 1]
        else:
            v = wa * x[a, b] + (1.0 - wa) * x[a + 1, b]
            if wb != 1.0:
                v = wb * v + (1.0 - wb) * (wa * x[a, b + 1] + (1.0 - wa) * x[a + 1, b + 1])
        out[I, J] = v


@njit(cache=True, nogil=True)
def sample(x, si, swi, sj, swj, out):  # pragma: no cover - compiled
    """``out = R̂ x``: ``x`` interpolated (bilinear in the index) at the coarse nodes.

    Coarse node ``(I, J)`` sits between fine nodes ``si[I], si[I] + 1`` with
    weight ``swi[I]`` on the first (likewise in j).  Where a coarse node is a
    fine node the weight is exactly 1 (or 0), so this is injection there.
    """
    bj, wbj, nested = _sample_cols(sj, swj)
    for I in range(out.shape[0]):
        _sample_row(x, si[I], swi[I], bj, wbj, nested, out, I)


#: Fine rows held by a chunk of :func:`_defect_restrict` (a coarse row needs ≤ 4).
RING = 6


@njit(cache=True, nogil=True)
def _defect_restrict_rows(
    x, y, fx, fy, p, q, use_f, use_pq, ii, wi, jj, wj, scale, fxc, fyc, lo, hi
):  # pragma: no cover - compiled
    """Coarse rows ``lo ≤ I < hi`` of :func:`_defect_restrict`; returns the largest
    ``(|f − N|/den)²`` of the fine rows it computed."""
    ni1, nj1 = x.shape
    ni = ni1 - 1
    tx, ty, tq, td = _scratch_rows(nj1)
    ringx = np.empty((RING, nj1))
    ringy = np.empty((RING, nj1))
    held = np.full(RING, -1, dtype=np.int64)
    slot = np.empty(ii.shape[1], dtype=np.int64)
    m = 0.0
    nJ = fxc.shape[1]
    for I in range(lo, hi):
        for a in range(ii.shape[1]):
            i = ii[I, a]
            s = i % RING
            slot[a] = s
            if held[s] != i:
                held[s] = i
                if i == 0 or i == ni:  # boundary rows: no defect
                    for j in range(nj1):
                        ringx[s, j] = 0.0
                        ringy[s, j] = 0.0
                else:
                    mm = _defect_row(
                        x, y, fx, fy, p, q, use_f, use_pq, i, i - 1, nj1, ringx[s], ringy[s], tx, ty, tq, td
                    )
                    if mm > m:
                        m = mm
        # the arithmetic of _restrict_rows, reading the ring instead of r
        if ii.shape[1] == 3 and jj.shape[1] == 3:
            for J in range(nJ):
                sx = 0.0
                sy = 0.0
                for a in range(3):
                    w_a = wi[I, a]
                    sa = slot[a]
                    for b in range(3):
                        w = w_a * wj[J, b]
                        jb = jj[J, b]
                        sx += w * ringx[sa, jb]
                        sy += w * ringy[sa, jb]
                fxc[I, J] = scale * sx
                fyc[I, J] = scale * sy
        else:
            for J in range(nJ):
                sx = 0.0
                sy = 0.0
                for a in range(ii.shape[1]):
                    w_a = wi[I, a]
                    sa = slot[a]
                    for b in range(jj.shape[1]):
                        w = w_a * wj[J, b]
                        jb = jj[J, b]
                        sx += w * ringx[sa, jb]
                        sy += w * ringy[sa, jb]
                fxc[I, J] = scale * sx
                fyc[I, J] = scale * sy
    return m


def _defect_restrict(x, y, fx, fy, p, q, ii, wi, jj, wj, scale, fxc, fyc, chunks):  # pragma: no cover - compiled
    """:func:`_defect` followed by :func:`_restrict`, without the fine defect arrays.

    Each chunk of coarse rows computes the fine defect rows its full-weighting
    stencils need into a small ring buffer (rows shared by two chunks are
    computed by both, with the same result) and restricts them at once: the
    same numbers as ``defect`` + ``restrict`` bit for bit, without writing and
    re-reading two fine arrays (the largest memory stream of a cycle on big
    grids).  Not periodic (the seam's stencil wraps around).  ``chunks``:
    at most this many independent chunks (1 for the serial kernel: one ring,
    no recomputed rows).  Returns the largest ``(|f − N|/den)²`` as
    :func:`_defect`.
    """
    use_f = fx.size > 0
    use_pq = p.size > 0
    nI = fxc.shape[0]
    nchunks = max(1, min(nI, chunks))
    cmax = np.zeros(nchunks)
    for c in prange(nchunks):
        cmax[c] = _defect_restrict_rows(
            x,
            y,
            fx,
            fy,
            p,
            q,
            use_f,
            use_pq,
            ii,
            wi,
            jj,
            wj,
            scale,
            fxc,
            fyc,
            c * nI // nchunks,
            (c + 1) * nI // nchunks,
        )
    return cmax.max()


def _renamed(fn, suffix):
    """A copy of ``fn`` with its own name.

    numba's on-disk cache files a function under its qualified name and line
    and does not tell a ``parallel=True`` compilation from a serial one: the
    two compilations of one Python function would load each other's machine
    code (whichever was compiled first).  Each variant gets its own name.
    """
    out = types.FunctionType(fn.__code__, fn.__globals__, fn.__name__ + suffix, fn.__defaults__, fn.__closure__)
    out.__qualname__ = fn.__qualname__ + suffix
    out.__doc__ = fn.__doc__
    return out


def _serial(fn):
    return njit(cache=True, nogil=True)(_renamed(fn, "_serial"))


def _par(fn):
    return njit(cache=True, nogil=True, parallel=True)(_renamed(fn, "_parallel"))


_smooth_two_pass = _serial(_smooth)
smooth_parallel = _par(_smooth)


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


defect = _serial(_defect)
defect_parallel = _par(_defect)
add_operator = _serial(_add_operator)
add_operator_parallel = _par(_add_operator)
restrict = _serial(_restrict)
restrict_parallel = _par(_restrict)
prolong_correct = _serial(_prolong_correct)
prolong_correct_parallel = _par(_prolong_correct)
defect_restrict = _serial(_defect_restrict)
defect_restrict_parallel = _par(_defect_restrict)


@njit(cache=True, nogil=True)
def cell_stats(x, y, stride):  # pragma: no cover - compiled
    """``(mean log aspect, folded fraction)`` of the cells of a node array.

    Aspect = length of a cell's ξ side / length of its η side (first sides,
    sampled every ``stride`` cells in each direction); a cell is folded when
    the cross product of its diagonals is ≤ 0 (all cells).
    """
    ni1, nj1 = x.shape
    s = 0.0  # sum of log(a²/b²), taken as the log of running products (few logs)
    prod = 1.0
    cnt = 0
    folded = 0
    for i in range(ni1 - 1):
        for j in range(nj1 - 1):
            d1x = x[i + 1, j + 1] - x[i, j]
            d1y = y[i + 1, j + 1] - y[i, j]
            d2x = x[i, j + 1] - x[i + 1, j]
            d2y = y[i, j + 1] - y[i + 1, j]
            if d1x * d2y - d1y * d2x <= 0.0:
                folded += 1
        if i % stride == 0:
            for j in range(0, nj1 - 1, stride):
                a2 = (x[i + 1, j] - x[i, j]) ** 2 + (y[i + 1, j] - y[i, j]) ** 2
                b2 = (x[i, j + 1] - x[i, j]) ** 2 + (y[i, j + 1] - y[i, j]) ** 2
                if a2 > 0.0 and b2 > 0.0:
                    r = a2 / b2
                    cnt += 1
                    if 1e-100 < r < 1e100:
                        prod *= r
                        if not 1e-150 < prod < 1e150:
                            s += np.log(prod)
                            prod = 1.0
                    else:
                        s += np.log(r)
    s += np.log(prod)
    ncell = (ni1 - 1) * (nj1 - 1)
    return (0.5 * s / cnt if cnt else 0.0), folded / max(ncell, 1)


#: Width of the restriction stencils (a coarse node collects from ≤ 4 fine nodes).
RW = 4


def coarse_positions(pos: np.ndarray, coarsen: bool) -> np.ndarray:
    """Positions (finest-level index units) of the coarse nodes of nodes at ``pos``.

    A level with an even number ``n`` of uniform intervals keeps every other
    node (nested).  Otherwise the ``⌈n/2⌉`` coarse intervals are spread
    *uniformly* over the same span and the coarse nodes fall between fine
    nodes: every level stays exactly uniform in the finest index, so the
    coarse equations (uniform spacing, scaled by the coarsening factor) are
    consistent with the fine ones everywhere.  (Keeping a subset of the fine
    nodes with one short interval puts an O(1) inconsistency at that
    interval: measured 0.2–0.4 per cycle instead of ≤ 0.1, and divergence on
    a 125 × 63 grid.)
    """
    pos = np.asarray(pos, dtype=np.float64)
    n = pos.size - 1
    if not coarsen:
        return pos.copy()
    d = np.diff(pos)
    if n % 2 == 0 and np.all(d == d[0]):
        return pos[::2].copy()
    return np.linspace(pos[0], pos[n], (n + 1) // 2 + 1)


def _interp_table(src: np.ndarray, dst: np.ndarray):
    """``(k, w)``: each ``dst`` point between ``src[k]`` (weight ``w``) and ``src[k + 1]``."""
    k = np.clip(np.searchsorted(src, dst, side="right") - 1, 0, src.size - 2).astype(np.int64)
    w = (src[k + 1] - dst) / (src[k + 1] - src[k])
    w[np.abs(w - 1.0) < 1e-12] = 1.0  # a point on a node: exactly that node
    w[np.abs(w) < 1e-12] = 0.0
    return k, w


def transfer_tables(pos: np.ndarray, coarsen: bool, periodic: bool):
    """Index/weight tables of one direction whose nodes sit at positions ``pos``.

    ``pos`` are the nodes' indices on the finest level (so interpolation is
    linear in the finest index), coarse positions from
    :func:`coarse_positions`.  Returns ``(si, swi, r_idx, r_w, left, w_left,
    pos_c)``: ``si, swi`` sample a fine array at the coarse nodes (``R̂``, see
    :func:`sample`); ``r_idx, r_w`` ``(nc+1, 3 or RW)`` full-weighting stencils,
    the normalised transpose of the interpolation (unused entries weigh 0);
    ``left[i], w_left[i]`` the interpolation of node ``i`` from coarse nodes
    ``left[i]`` (weight ``w_left``) and ``left[i] + 1`` (weight ``1 − w_left``);
    ``pos_c`` the coarse positions.  With ``periodic`` the last node repeats
    the first (so does the last coarse node) and the restriction stencil of
    coarse node 0 wraps around.
    """
    pos = np.asarray(pos, dtype=np.float64)
    n = pos.size - 1
    pos_c = coarse_positions(pos, coarsen)
    nc = pos_c.size - 1
    si, swi = _interp_table(pos, pos_c)
    left, w_left = _interp_table(pos_c, pos)
    # restriction: R[I, i] ∝ P[i, I], collected per coarse node in fine-index order
    cols: list[list] = [[] for _ in range(nc + 1)]
    for i in range(n if periodic else n + 1):
        for I, w in ((left[i], w_left[i]), (left[i] + 1, 1.0 - w_left[i])):
            if w > 0.0:
                cols[0 if (periodic and nc == I) else I].append((i, w))
    if periodic:
        cols[0].sort(key=lambda t: t[0] if t[0] <= n // 2 else t[0] - n)  # across the seam
        cols[nc] = cols[0]
    width = max(3, max(len(col) for col in cols))  # 3 (nested) or 4
    r_idx = np.zeros((nc + 1, width), dtype=np.int64)
    r_w = np.zeros((nc + 1, width))
    for I, col in enumerate(cols):
        if len(col) > RW:  # pragma: no cover - spacing ratio < 2 makes this impossible
            raise AssertionError("restriction stencil wider than RW")
        for a, (i, w) in enumerate(col):
            r_idx[I, a] = i
            r_w[I, a] = w
        r_idx[I, len(col) :] = col[0][0]
        r_w[I] /= r_w[I].sum()
    return si, swi, r_idx, r_w, left, w_left, pos_c


# ----------------------------------------------------------- fused coarse V-cycle
#: Columns of the level table of :func:`vcycle` (offsets into the flat buffers).
(
    M_N0,
    M_N1,
    M_X,
    M_Y,
    M_FX,
    M_FY,
    M_P,
    M_Q,
    M_RX,
    M_RY,
    M_PQ,
    M_SI,
    M_SJ,
    M_RI,
    M_RJ,
    M_LI,
    M_LJ,
    M_RWI,
    M_RWJ,
    M_WLI,
    M_WLJ,
    M_SWI,
    M_SWJ,
    M_WI,
    M_WJ,
) = range(25)
META_COLS = 25


@njit(cache=True, nogil=True)
def _v2(buf, off, n0, n1):  # pragma: no cover - compiled
    return buf[off : off + n0 * n1].reshape((n0, n1))


@njit(cache=True, nogil=True)
def vcycle(
    fbuf, ibuf, meta, scale, k0, pre, post, coarsest, band_width, band_sweeps, periodic
):  # pragma: no cover - compiled
    """One FAS V-cycle on levels ``k0 …`` whose arrays live in flat buffers.

    Exactly the operations of :meth:`multigrid._FAS.cycle` (``gamma = 1``,
    serial kernels) in one compiled call, which removes the per-kernel Python
    dispatch that dominates on small levels.  ``meta[k]`` holds the shape
    and the offsets of level k's arrays (``x, y, fx, fy, p, q, rx, ry`` in
    ``fbuf``; transfer tables in ``ibuf``/``fbuf``), see ``M_*``.
    """
    nlev = meta.shape[0]
    e = np.zeros((0, 0))
    for k in range(k0, nlev - 1):
        m = meta[k]
        n0, n1 = m[M_N0], m[M_N1]
        x = _v2(fbuf, m[M_X], n0, n1)
        y = _v2(fbuf, m[M_Y], n0, n1)
        fx = _v2(fbuf, m[M_FX], n0, n1)
        fy = _v2(fbuf, m[M_FY], n0, n1)
        p = _v2(fbuf, m[M_P], n0, n1) if m[M_PQ] else e
        q = _v2(fbuf, m[M_Q], n0, n1) if m[M_PQ] else e
        rx = _v2(fbuf, m[M_RX], n0, n1)
        ry = _v2(fbuf, m[M_RY], n0, n1)
        smooth(x, y, fx, fy, p, q, periodic, pre)
        c = meta[k + 1]
        c0, c1 = c[M_N0], c[M_N1]
        xc = _v2(fbuf, c[M_X], c0, c1)
        yc = _v2(fbuf, c[M_Y], c0, c1)
        fxc = _v2(fbuf, c[M_FX], c0, c1)
        fyc = _v2(fbuf, c[M_FY], c0, c1)
        pc = _v2(fbuf, c[M_P], c0, c1) if c[M_PQ] else e
        qc = _v2(fbuf, c[M_Q], c0, c1) if c[M_PQ] else e
        si = ibuf[m[M_SI] : m[M_SI] + c0]
        sj = ibuf[m[M_SJ] : m[M_SJ] + c1]
        swi = fbuf[m[M_SWI] : m[M_SWI] + c0]
        swj = fbuf[m[M_SWJ] : m[M_SWJ] + c1]
        sample(x, si, swi, sj, swj, xc)
        sample(y, si, swi, sj, swj, yc)
        ri = _v2(ibuf, m[M_RI], c0, m[M_WI])
        rj = _v2(ibuf, m[M_RJ], c1, m[M_WJ])
        rwi = _v2(fbuf, m[M_RWI], c0, m[M_WI])
        rwj = _v2(fbuf, m[M_RWJ], c1, m[M_WJ])
        if periodic:
            defect(x, y, fx, fy, p, q, periodic, rx, ry)
            restrict(rx, ry, ri, rwi, rj, rwj, scale[k], fxc, fyc)
        else:  # the same numbers without the fine defect arrays
            defect_restrict(x, y, fx, fy, p, q, ri, rwi, rj, rwj, scale[k], fxc, fyc, 1)
        add_operator(xc, yc, pc, qc, periodic, fxc, fyc)
    m = meta[nlev - 1]
    n0, n1 = m[M_N0], m[M_N1]
    smooth(
        _v2(fbuf, m[M_X], n0, n1),
        _v2(fbuf, m[M_Y], n0, n1),
        _v2(fbuf, m[M_FX], n0, n1),
        _v2(fbuf, m[M_FY], n0, n1),
        _v2(fbuf, m[M_P], n0, n1) if m[M_PQ] else e,
        _v2(fbuf, m[M_Q], n0, n1) if m[M_PQ] else e,
        periodic,
        coarsest,
    )
    for k in range(nlev - 2, k0 - 1, -1):
        m = meta[k]
        n0, n1 = m[M_N0], m[M_N1]
        x = _v2(fbuf, m[M_X], n0, n1)
        y = _v2(fbuf, m[M_Y], n0, n1)
        fx = _v2(fbuf, m[M_FX], n0, n1)
        fy = _v2(fbuf, m[M_FY], n0, n1)
        p = _v2(fbuf, m[M_P], n0, n1) if m[M_PQ] else e
        q = _v2(fbuf, m[M_Q], n0, n1) if m[M_PQ] else e
        c = meta[k + 1]
        c0, c1 = c[M_N0], c[M_N1]
        si = ibuf[m[M_SI] : m[M_SI] + c0]
        sj = ibuf[m[M_SJ] : m[M_SJ] + c1]
        swi = fbuf[m[M_SWI] : m[M_SWI] + c0]
        swj = fbuf[m[M_SWJ] : m[M_SWJ] + c1]
        li = ibuf[m[M_LI] : m[M_LI] + n0]
        lj = ibuf[m[M_LJ] : m[M_LJ] + n1]
        wli = fbuf[m[M_WLI] : m[M_WLI] + n0]
        wlj = fbuf[m[M_WLJ] : m[M_WLJ] + n1]
        prolong_correct(
            x,
            y,
            _v2(fbuf, c[M_X], c0, c1),
            _v2(fbuf, c[M_Y], c0, c1),
            _v2(fbuf, c[M_RX], c0, c1),
            _v2(fbuf, c[M_RY], c0, c1),
            si,
            swi,
            sj,
            swj,
            li,
            lj,
            wli,
            wlj,
            periodic,
        )
        smooth(x, y, fx, fy, p, q, periodic, post)
        if band_sweeps > 0:
            smooth_band(x, y, fx, fy, p, q, periodic, band_width, band_sweeps)


@njit(cache=True, nogil=True)
def _up(fbuf, ibuf, meta, k, periodic):  # pragma: no cover - compiled
    """``u_k += P(u_{k+1} − R̂ u_k)`` for fused level ``k`` (the up-leg step of :func:`vcycle`)."""
    m = meta[k]
    n0, n1 = m[M_N0], m[M_N1]
    c = meta[k + 1]
    c0, c1 = c[M_N0], c[M_N1]
    prolong_correct(
        _v2(fbuf, m[M_X], n0, n1),
        _v2(fbuf, m[M_Y], n0, n1),
        _v2(fbuf, c[M_X], c0, c1),
        _v2(fbuf, c[M_Y], c0, c1),
        _v2(fbuf, c[M_RX], c0, c1),
        _v2(fbuf, c[M_RY], c0, c1),
        ibuf[m[M_SI] : m[M_SI] + c0],
        fbuf[m[M_SWI] : m[M_SWI] + c0],
        ibuf[m[M_SJ] : m[M_SJ] + c1],
        fbuf[m[M_SWJ] : m[M_SWJ] + c1],
        ibuf[m[M_LI] : m[M_LI] + n0],
        ibuf[m[M_LJ] : m[M_LJ] + n1],
        fbuf[m[M_WLI] : m[M_WLI] + n0],
        fbuf[m[M_WLJ] : m[M_WLJ] + n1],
        periodic,
    )


@njit(cache=True, nogil=True)
def fmg_start(
    fbuf,
    ibuf,
    meta,
    scale,
    pre,
    post,
    coarsest,
    band_width,
    band_sweeps,
    fmg_width,
    fmg_sweeps,
    fmg_min_cells,
    fmg_cycles,
    periodic,
):  # pragma: no cover - compiled
    """The full-multigrid start on all fused levels in one compiled call.

    Solve the coarsest level (``coarsest`` sweeps), then for each finer fused
    level: interpolate the correction up, drop the FAS right-hand side (plain
    coarse discretisation), relax the narrow border band on large levels and
    run ``fmg_cycles`` V-cycles, exactly as the Python driver does level by
    level.  Levels must hold the injected start grid.
    """
    nlev = meta.shape[0]
    e = np.zeros((0, 0))
    m = meta[nlev - 1]
    n0, n1 = m[M_N0], m[M_N1]
    smooth(
        _v2(fbuf, m[M_X], n0, n1),
        _v2(fbuf, m[M_Y], n0, n1),
        _v2(fbuf, m[M_FX], n0, n1),
        _v2(fbuf, m[M_FY], n0, n1),
        _v2(fbuf, m[M_P], n0, n1) if m[M_PQ] else e,
        _v2(fbuf, m[M_Q], n0, n1) if m[M_PQ] else e,
        periodic,
        coarsest,
    )
    for k in range(nlev - 2, -1, -1):
        _up(fbuf, ibuf, meta, k, periodic)
        m = meta[k]
        n0, n1 = m[M_N0], m[M_N1]
        fx = _v2(fbuf, m[M_FX], n0, n1)
        fy = _v2(fbuf, m[M_FY], n0, n1)
        fx[:] = 0.0
        fy[:] = 0.0
        if min(n0, n1) - 1 >= fmg_min_cells:
            smooth_band(
                _v2(fbuf, m[M_X], n0, n1),
                _v2(fbuf, m[M_Y], n0, n1),
                fx,
                fy,
                _v2(fbuf, m[M_P], n0, n1) if m[M_PQ] else e,
                _v2(fbuf, m[M_Q], n0, n1) if m[M_PQ] else e,
                periodic,
                fmg_width,
                fmg_sweeps,
            )
        for _ in range(fmg_cycles):
            vcycle(fbuf, ibuf, meta, scale, k, pre, post, coarsest, band_width, band_sweeps, periodic)
