r"""Grid transfers of the multigrid solver and the tables that define them.

Vertex-centred coarsening, any size.  A coarsened direction with an even
number of uniform intervals keeps every other node; any other count ``n`` gets
``⌈n/2⌉`` coarse intervals spread uniformly over the same span, whose nodes
fall between fine nodes (see :func:`coarse_positions`): every level is uniform
in the finest index.  ``R̂`` (:func:`sample`) samples a fine array at the
coarse nodes by linear interpolation (injection where nested), ``P``
(:func:`prolong_correct`) interpolates linearly, and the restriction
(:func:`restrict`) is full weighting, the normalised transpose of ``P``, given
to the kernels as index/weight tables per direction (:func:`transfer_tables`),
so non-coarsened directions (semi-coarsening) and periodic wrap-around need no
special code.  :func:`cell_stats` measures a level for the coarsening plan.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from ._compile import ROW_CHUNKS, parallel, serial

__all__ = [
    "cell_stats",
    "coarse_positions",
    "far_fraction",
    "prolong_correct",
    "prolong_correct_parallel",
    "restrict",
    "restrict_parallel",
    "sample",
    "transfer_tables",
]


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


restrict = serial(_restrict)
restrict_parallel = parallel(_restrict)
prolong_correct = serial(_prolong_correct)
prolong_correct_parallel = parallel(_prolong_correct)


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


@njit(cache=True, nogil=True)
def far_fraction(x, y, stride, lim2):  # pragma: no cover - compiled
    """The fraction of the cells sampled every ``stride`` cells in each direction whose first ξ
    side is longer than ``sqrt(lim2)`` times their first η side or the other way round (the
    sides of :func:`cell_stats`; 0 when there is no cell)."""
    ni1, nj1 = x.shape
    far = 0
    cnt = 0
    for i in range(0, ni1 - 1, stride):
        for j in range(0, nj1 - 1, stride):
            a2 = (x[i + 1, j] - x[i, j]) ** 2 + (y[i + 1, j] - y[i, j]) ** 2
            b2 = (x[i, j + 1] - x[i, j]) ** 2 + (y[i, j + 1] - y[i, j]) ** 2
            cnt += 1
            if a2 > lim2 * b2 or b2 > lim2 * a2:
                far += 1
    return far / cnt if cnt else 0.0


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
