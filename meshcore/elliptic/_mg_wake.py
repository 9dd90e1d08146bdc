r"""The C-grid wake cut in the multigrid: its nodes are unknowns on every level.

A C-grid's bottom border runs out along the lower side of the wake, round the
body and back along the upper side: bottom nodes ``i = 1 … n − 1`` coincide
with ``ni − i`` (``n`` = ``control.wake`` cells, see :mod:`meshcore.control`).
Those nodes are interior nodes of the physical grid: node ``(i, 0)`` has the
neighbours

.. math::

    E = (i+1, 0),\ W = (i-1, 0),\ N = (i, 1),\ S = (m, 1),\
    NE = (i+1, 1),\ NW = (i-1, 1),\ SE = (m-1, 1),\ SW = (m+1, 1),\qquad m = n_i - i,

(the η lines run straight through the cut) and the Winslow equations of
:mod:`._stencil` with ``P = Q = 0``.  Treated as fixed border nodes, moved once
per cycle by the control updater, the cut and the thin cells along it form a
strongly coupled block that only creeps (a residual plateau: the multigrid
handed over to SOR, 27 000 sweeps).  Here every level relaxes its cut nodes
with the interior (:func:`relax_cut` after each sweep), their defects go into
the convergence measure and are restricted with the mirrored full-weighting
stencil (:func:`restrict_cut`), and the coarse-grid correction is interpolated
along the cut (:func:`prolong_cut`).  Coarse levels keep the cut nested: ξ is
coarsened only while ``ni`` and ``n`` are even and the coarse cut keeps at
least :data:`MIN_CUT_CELLS` cells (:func:`coarsen_xi_ok`).

The two kernels have NumPy references (:func:`cut_defect_reference`,
:func:`relax_cut_reference`), the test oracles.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ._stencil import winslow

__all__ = [
    "MIN_CUT_CELLS",
    "add_cut_operator",
    "coarsen_xi_ok",
    "cut_defect",
    "cut_defect_reference",
    "prolong_cut",
    "relax_cut",
    "relax_cut_reference",
    "restrict_cut",
]

#: A coarse level keeps at least this many wake-cut cells (else ξ is not coarsened further).
MIN_CUT_CELLS = 2


def coarsen_xi_ok(ni: int, wake: int) -> bool:
    """Whether ξ of a level with ``ni`` cells and a ``wake``-cell cut may be coarsened (nested)."""
    return ni % 2 == 0 and wake % 2 == 0 and wake // 2 >= MIN_CUT_CELLS


def _cut_neighbours(a, i, m):
    """E, W, N, S, NE, NW, SE, SW of cut node ``(i, 0)`` (``m`` its mirror index) in ``a``."""
    return a[i + 1, 0], a[i - 1, 0], a[i, 1], a[m, 1], a[i + 1, 1], a[i - 1, 1], a[m - 1, 1], a[m + 1, 1]


_cut_neighbours_jit = njit(cache=True, nogil=True, inline="always")(_cut_neighbours)


def _cut_stencil(x, y, i, m):
    """NumPy references: ``(den, sx, sy)`` of the Winslow stencil at cut node ``(i, 0)``, so that
    ``N(u) = (sx, sy) - den * (x, y)`` there (``i`` an index or an array of them)."""
    xe, xw, xn, xs, xne, xnw, xse, xsw = _cut_neighbours(x, i, m)
    ye, yw, yn, ys, yne, ynw, yse, ysw = _cut_neighbours(y, i, m)
    xxi, yxi = 0.5 * (xe - xw), 0.5 * (ye - yw)
    xet, yet = 0.5 * (xn - xs), 0.5 * (yn - ys)
    a = xet * xet + yet * yet
    b = xxi * xet + yxi * yet
    g = xxi * xxi + yxi * yxi
    den = 2.0 * (a + g)
    sx = a * (xe + xw) + g * (xn + xs) - 0.5 * b * (xne - xnw - xse + xsw)
    sy = a * (ye + yw) + g * (yn + ys) - 0.5 * b * (yne - ynw - yse + ysw)
    return den, sx, sy


def cut_defect_reference(x, y, fx, fy, wake: int):
    """NumPy reference of :func:`cut_defect`: ``(rx, ry, den)`` at cut nodes ``1 … wake − 1``."""
    ni = x.shape[0] - 1
    i = np.arange(1, wake)
    m = ni - i
    den, sx, sy = _cut_stencil(x, y, i, m)
    rx = sx - den * x[i, 0]
    ry = sy - den * y[i, 0]
    if fx.size:
        rx = rx + fx[i, 0]
        ry = ry + fy[i, 0]
    return rx, ry, den


@njit(cache=True, nogil=True)
def cut_defect(x, y, fx, fy, wake, rcx, rcy):  # pragma: no cover - compiled
    """Defect ``f − N(u)`` at the cut nodes into ``rcx[i], rcy[i]`` (``i = 1 … wake − 1``; the
    other entries 0); returns the largest ``(|f − N|/den)²`` (``inf`` on NaN).

    ``fx, fy``: the right-hand side, read at ``(i, 0)`` (empty arrays for 0).
    """
    ni = x.shape[0] - 1
    use_f = fx.size > 0
    rcx[:] = 0.0
    rcy[:] = 0.0
    worst = 0.0
    for i in range(1, wake):
        m = ni - i
        xe, xw, xn, xs, xne, xnw, xse, xsw = _cut_neighbours_jit(x, i, m)
        ye, yw, yn, ys, yne, ynw, yse, ysw = _cut_neighbours_jit(y, i, m)
        sx, sy, den, _a, _b, _c, _d = winslow(xe, xw, xn, xs, xne, xnw, xse, xsw, ye, yw, yn, ys, yne, ynw, yse, ysw)
        dx = sx - den * x[i, 0]
        dy = sy - den * y[i, 0]
        if use_f:
            dx += fx[i, 0]
            dy += fy[i, 0]
        rcx[i] = dx
        rcy[i] = dy
        q = dx * dx + dy * dy
        if q != q:
            worst = np.inf
        elif den > 0.0 and q > worst * den * den:
            worst = q / (den * den)
    return worst


def relax_cut_reference(x, y, fx, fy, wake: int, sweeps: int) -> None:
    """NumPy reference of :func:`relax_cut` (node by node, the same order)."""
    ni = x.shape[0] - 1
    for _ in range(sweeps):
        for i in range(1, wake):
            m = ni - i
            den, sx, sy = _cut_stencil(x, y, i, m)
            if fx.size:
                sx += fx[i, 0]
                sy += fy[i, 0]
            if den > 0.0:
                x[i, 0] = x[m, 0] = sx / den
                y[i, 0] = y[m, 0] = sy / den


@njit(cache=True, nogil=True)
def relax_cut(x, y, fx, fy, wake, sweeps):  # pragma: no cover - compiled
    """``sweeps`` Gauss–Seidel sweeps along the cut (``i = 1 … wake − 1``, in order) of
    ``N(u) = f``; each update is written to both sides of the cut."""
    ni = x.shape[0] - 1
    use_f = fx.size > 0
    for _ in range(sweeps):
        for i in range(1, wake):
            m = ni - i
            xe, xw, xn, xs, xne, xnw, xse, xsw = _cut_neighbours_jit(x, i, m)
            ye, yw, yn, ys, yne, ynw, yse, ysw = _cut_neighbours_jit(y, i, m)
            sx, sy, den, _a, _b, _c, _d = winslow(
                xe, xw, xn, xs, xne, xnw, xse, xsw, ye, yw, yn, ys, yne, ynw, yse, ysw
            )
            if use_f:
                sx += fx[i, 0]
                sy += fy[i, 0]
            if den > 0.0:
                inv = 1.0 / den
                x[i, 0] = sx * inv
                y[i, 0] = sy * inv
                x[m, 0] = x[i, 0]
                y[m, 0] = y[i, 0]


def add_cut_operator(x, y, wake: int, fx, fy, scratch_x, scratch_y) -> None:
    """``f += N(u)`` at the cut nodes (the FAS coarse right-hand side there)."""
    empty = np.zeros((0, 0))
    cut_defect(x, y, empty, empty, wake, scratch_x, scratch_y)
    fx[1:wake, 0] -= scratch_x[1:wake]
    fy[1:wake, 0] -= scratch_y[1:wake]


def restrict_cut(rcx, rcy, rx, ry, ri, rwi, eta_coarsened: bool, scale: float, wake_c: int, fxc, fyc) -> None:
    """Full weighting of the fine defects to the coarse cut nodes ``1 … wake_c − 1``.

    ``rcx, rcy``: the fine cut defects (0 off the cut), ``rx, ry``: the fine
    interior defects; ``ri, rwi``: the ξ restriction table.  Across the cut the
    stencil is mirrored: weights ½ on the cut row and ¼ on row 1 of either side
    when η is coarsened (1 on the cut row when not).
    """
    ni = rx.shape[0] - 1
    for I in range(1, wake_c):
        sx = sy = 0.0
        for a in range(ri.shape[1]):
            i, w = int(ri[I, a]), float(rwi[I, a])
            if w == 0.0:
                continue
            if eta_coarsened:
                vx = 0.5 * rcx[i] + 0.25 * (rx[i, 1] + rx[ni - i, 1])
                vy = 0.5 * rcy[i] + 0.25 * (ry[i, 1] + ry[ni - i, 1])
            else:
                vx, vy = rcx[i], rcy[i]
            sx += w * vx
            sy += w * vy
        fxc[I, 0] = scale * sx
        fyc[I, 0] = scale * sy


def prolong_cut(x, y, ex, ey, li, wli, wake: int) -> None:
    """``u += P e`` at the fine cut nodes: the coarse correction ``e`` (row 0 of the coarse
    scratch, 0 at the fixed ends) interpolated along the cut, written to both sides."""
    ni = x.shape[0] - 1
    i = np.arange(1, wake)
    a = li[i]
    w = wli[i]
    x[i, 0] += w * ex[a, 0] + (1.0 - w) * ex[a + 1, 0]
    y[i, 0] += w * ey[a, 0] + (1.0 - w) * ey[a + 1, 0]
    x[ni - i, 0] = x[i, 0]
    y[ni - i, 0] = y[i, 0]
