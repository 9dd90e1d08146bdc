r"""Zebra η-line Gauss–Seidel relaxation of the multigrid (FAS) equations ``N(u) = f`` (numba).

Why.  A C-grid's wake is meshed with cells that are far longer in ξ than in η:
the ξ spacing grows downstream of the trailing edge while the η spacing stays
the wall spacing (on the NACA 0012 example the 99th percentile of the cell
aspect is ≈ 360, while the cells round the body are near 1 and the far-field
cells longer in η).  With coefficients ``α ≪ γ`` a node is coupled to its η
neighbours only: point Gauss–Seidel then leaves errors that are smooth along η
and oscillate along ξ, and no global choice of (semi-)coarsening fits such a
mix of aspects.  Measured on that example (sources following the grid): the
point-smoothed cycle stalls at a defect of 1.8·10⁻⁴ (also with the sources
frozen), with the largest defects in the wake rows.  Relaxing every
``i = const`` line (an η line) at once smooths those errors whatever the
aspect.

What.  Each η line ``(i, 1 … nj − 1)`` is solved for its nodes with the
coefficients of :func:`._stencil.winslow` frozen at the current values, the
ξ neighbours and the cross term taken as known: with ``s = s_x`` of the
stencil (sources and ``f`` included; the same for ``y``)

.. math::

    2(α + γ)\, x_j − c_N x_{j+1} − c_S x_{j−1} = s − c_N x_{j+1} − c_S x_{j−1},\qquad
    c_{N,S} = γ ± \tfrac12 D^2 \bar Q,

a tridiagonal system (Thomas algorithm).  ``Q̄`` is ``Q`` clipped to
``|½ D² Q̄| ≤ γ``: that keeps the matrix diagonally dominant (``2(α + γ) ≥
|c_N| + |c_S|``) whatever the control sources; the rest of the source term
stays on the right-hand side, so a converged line solves ``N(u) = f`` exactly
as the point update does (same fixed point, same discrete equations).
Lines of one parity of ``i`` never meet in each other's 9-point stencils: all
odd lines are relaxed, then all even lines (zebra), and the lines of a pass are
independent, so the serial and ``parallel=True`` compilations give
bit-identical results.  Non-periodic grids only: the C-grids, and grids whose cells are
long one way in places and the other way elsewhere (branched lakes as one block), which
:func:`.multigrid._alt_lines` relaxes by η lines and then by ξ lines (the η lines of the
transposed level).

The cut.  The η lines run straight through a C-grid's wake cut (see
:mod:`._mg_wake`): column ``m = ni − i`` from the far field down to the cut,
the cut node ``(i, 0)``, column ``i`` out again.  Solved as one line
(:func:`_cut_line`, first in each sweep, serially) the cut node moves with the
columns it is strongly coupled to; relaxed on its own between line sweeps it
held them back (measured: 0.98 per cycle at the far end of the wake, against
≈ 0.5–0.6 per cycle joined, with the sources frozen).

:func:`smooth_lines_reference` is the NumPy reference (the test oracle).
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from ._compile import ROW_CHUNKS, parallel, renamed, serial
from ._mg_wake import _cut_neighbours_jit as _cut_neighbours
from ._stencil import winslow, winslow_at, with_sources

__all__ = ["alt_lines", "smooth_lines", "smooth_lines_parallel", "smooth_lines_reference"]


def _node(x, y, fx, fy, p, q, use_f, use_pq, i, j):  # pragma: no cover - compiled
    """``(den, c_N, c_S, r_x, r_y)`` at node ``(i, j)``: the stencil with its N and S terms
    taken out of ``s`` (``r = s − c_N φ_N − c_S φ_S``)."""
    sx, sy, den, xxi, yxi, xet, yet = winslow_at(x, y, i, i - 1, i + 1, j)
    g = xxi * xxi + yxi * yxi
    cq = 0.0
    if use_pq:
        sx, sy = with_sources(sx, sy, xxi, yxi, xet, yet, p[i, j], q[i, j])
        d = xxi * yet - xet * yxi
        cq = min(max(0.5 * d * d * q[i, j], -g), g)
    if use_f:
        sx += fx[i, j]
        sy += fy[i, j]
    cn = g + cq
    cs = g - cq
    return den, cn, cs, sx - cn * x[i, j + 1] - cs * x[i, j - 1], sy - cn * y[i, j + 1] - cs * y[i, j - 1]


# inline="always": called once per node with six arrays; left to LLVM the call with sources
# (``use_pq``) stayed a call: 87 → 61 ns per node of a line sweep inlined (257 × 65, the same bits)
_node_jit = njit(cache=True, nogil=True, inline="always")(renamed(_node, "_serial"))


def _thomas(lo, dg, up, rx, ry, n):  # pragma: no cover - compiled
    """Solve the tridiagonal system ``(lo, dg, up)`` for ``rx`` and ``ry`` in place (False: a
    zero pivot, the line is left alone)."""
    for k in range(1, n):
        if not dg[k - 1] > 0.0:
            return False
        m = lo[k] / dg[k - 1]
        dg[k] -= m * up[k - 1]
        rx[k] -= m * rx[k - 1]
        ry[k] -= m * ry[k - 1]
    if not dg[n - 1] > 0.0:
        return False
    rx[n - 1] /= dg[n - 1]
    ry[n - 1] /= dg[n - 1]
    for k in range(n - 2, -1, -1):
        rx[k] = (rx[k] - up[k] * rx[k + 1]) / dg[k]
        ry[k] = (ry[k] - up[k] * ry[k + 1]) / dg[k]
    return True


_thomas_jit = serial(_thomas)


def _line(x, y, fx, fy, p, q, use_f, use_pq, i, lo, dg, up, rx, ry):  # pragma: no cover - compiled
    """Solve η line ``i`` (nodes ``j = 1 … nj − 1``) with frozen coefficients, in place."""
    nj1 = x.shape[1]
    n = nj1 - 2
    # the flags as constants in each loop: the branches fold away and the loop vectorises
    # (with the flags as variables the line sweep took 3× as long, measured)
    if use_pq:
        for k in range(n):
            dg[k], cn, cs, rx[k], ry[k] = _node_jit(x, y, fx, fy, p, q, use_f, True, i, k + 1)
            lo[k] = -cs
            up[k] = -cn
    elif use_f:
        for k in range(n):
            dg[k], cn, cs, rx[k], ry[k] = _node_jit(x, y, fx, fy, p, q, True, False, i, k + 1)
            lo[k] = -cs
            up[k] = -cn
    else:
        for k in range(n):
            dg[k], cn, cs, rx[k], ry[k] = _node_jit(x, y, fx, fy, p, q, False, False, i, k + 1)
            lo[k] = -cs
            up[k] = -cn
    rx[0] -= lo[0] * x[i, 0]  # the border nodes stay on the right-hand side
    ry[0] -= lo[0] * y[i, 0]
    rx[n - 1] -= up[n - 1] * x[i, nj1 - 1]
    ry[n - 1] -= up[n - 1] * y[i, nj1 - 1]
    if _thomas_jit(lo, dg, up, rx, ry, n):
        for k in range(n):
            x[i, k + 1] = rx[k]
            y[i, k + 1] = ry[k]


_line_jit = serial(_line)


def _cut_line(x, y, fx, fy, p, q, use_f, use_pq, i, lo, dg, up, rx, ry):  # pragma: no cover - compiled
    """Solve the η line through wake-cut node ``(i, 0)``: column ``m = ni − i`` from the far
    field down to the cut, the cut node (neighbours N = ``(i, 1)``, S = ``(m, 1)``, P = Q = 0,
    see :mod:`._mg_wake`) and column ``i`` out to the far field."""
    ni1, nj1 = x.shape
    m = ni1 - 1 - i
    n = nj1 - 2
    for k in range(n):  # column m, from j = nj − 1 down to 1: its N neighbour comes first
        dg[k], cn, cs, rx[k], ry[k] = _node_jit(x, y, fx, fy, p, q, use_f, use_pq, m, n - k)
        lo[k] = -cn
        up[k] = -cs
    xe, xw, xn, xs, xne, xnw, xse, xsw = _cut_neighbours(x, i, m)
    ye, yw, yn, ys, yne, ynw, yse, ysw = _cut_neighbours(y, i, m)
    sx, sy, den, xxi, yxi, _xet, _yet = winslow(xe, xw, xn, xs, xne, xnw, xse, xsw, ye, yw, yn, ys, yne, ynw, yse, ysw)
    g = xxi * xxi + yxi * yxi
    if use_f:
        sx += fx[i, 0]
        sy += fy[i, 0]
    dg[n] = den
    lo[n] = -g
    up[n] = -g
    rx[n] = sx - g * (xn + xs)
    ry[n] = sy - g * (yn + ys)
    for k in range(n + 1, 2 * n + 1):  # column i, from j = 1 out
        dg[k], cn, cs, rx[k], ry[k] = _node_jit(x, y, fx, fy, p, q, use_f, use_pq, i, k - n)
        lo[k] = -cs
        up[k] = -cn
    last = 2 * n
    rx[0] -= lo[0] * x[m, nj1 - 1]  # the far-field nodes stay on the right-hand side
    ry[0] -= lo[0] * y[m, nj1 - 1]
    rx[last] -= up[last] * x[i, nj1 - 1]
    ry[last] -= up[last] * y[i, nj1 - 1]
    if _thomas_jit(lo, dg, up, rx, ry, last + 1):
        for k in range(n):
            x[m, n - k] = rx[k]
            y[m, n - k] = ry[k]
        x[i, 0] = x[m, 0] = rx[n]
        y[i, 0] = y[m, 0] = ry[n]
        for k in range(n + 1, last + 1):
            x[i, k - n] = rx[k]
            y[i, k - n] = ry[k]


_cut_line_jit = serial(_cut_line)


def _smooth_lines(x, y, fx, fy, p, q, wake, sweeps):  # pragma: no cover - compiled
    """``sweeps`` zebra η-line sweeps of ``N(u) = f`` (``fx, fy`` or ``p, q`` may be empty);
    with a ``wake``-cell C-grid cut each sweep first solves the lines through the cut
    (:func:`_cut_line`, in order of ``i``), then the other lines."""
    ni1, nj1 = x.shape
    ni = ni1 - 1
    if nj1 < 3:
        return
    use_f = fx.size > 0
    use_pq = p.size > 0
    for _ in range(sweeps):
        if wake > 1:
            lo = np.empty(2 * nj1)
            dg = np.empty(2 * nj1)
            up = np.empty(2 * nj1)
            rx = np.empty(2 * nj1)
            ry = np.empty(2 * nj1)
            for i in range(1, wake):
                _cut_line_jit(x, y, fx, fy, p, q, use_f, use_pq, i, lo, dg, up, rx, ry)
        for par in range(2):
            start = 1 + par
            nlines = (ni - 1 - start) // 2 + 1 if start <= ni - 1 else 0
            nchunks = min(nlines, ROW_CHUNKS)
            for c in prange(nchunks):
                lo = np.empty(nj1)
                dg = np.empty(nj1)
                up = np.empty(nj1)
                rx = np.empty(nj1)
                ry = np.empty(nj1)
                for k in range(c * nlines // nchunks, (c + 1) * nlines // nchunks):
                    i = start + 2 * k
                    if wake > 1 and (i < wake or i > ni - wake):
                        continue  # on a line through the cut
                    _line_jit(x, y, fx, fy, p, q, use_f, use_pq, i, lo, dg, up, rx, ry)


smooth_lines = serial(_smooth_lines)
smooth_lines_parallel = parallel(_smooth_lines)


def _damped_t(x, y, x0, y0, w, xt, yt):  # pragma: no cover - compiled
    """``xt, yt`` = the damped pass ``x0 + w (x − x0)`` (and ``y``'s), transposed."""
    for i in range(x.shape[0]):
        for j in range(x.shape[1]):
            xt[j, i] = x0[i, j] + w * (x[i, j] - x0[i, j])
            yt[j, i] = y0[i, j] + w * (y[i, j] - y0[i, j])


_damped_t_jit = serial(_damped_t)


def _alt_lines(x, y, fx, fy, p, q, w, sweeps):  # pragma: no cover - compiled
    """``sweeps`` alternating sweeps of :func:`.multigrid._alt_lines`, each every η line then every ξ
    line (the η lines of the transposed level, ``P ↔ Q``), each pass damped by ``w``: the same
    operations in the same order as the NumPy steps there (bit for bit), without a Python call and
    eight array copies per sweep (on a coarse level most of a sweep's time)."""
    ni1, nj1 = x.shape
    x0 = np.empty_like(x)
    y0 = np.empty_like(y)
    xt = np.empty((nj1, ni1))
    yt = np.empty((nj1, ni1))
    xt0 = np.empty((nj1, ni1))
    yt0 = np.empty((nj1, ni1))
    fxt, fyt = np.ascontiguousarray(fx.T), np.ascontiguousarray(fy.T)
    pt, qt = np.ascontiguousarray(q.T), np.ascontiguousarray(p.T)
    for _ in range(sweeps):
        x0[...] = x
        y0[...] = y
        smooth_lines(x, y, fx, fy, p, q, 0, 1)
        _damped_t_jit(x, y, x0, y0, w, xt, yt)
        xt0[...] = xt
        yt0[...] = yt
        smooth_lines(xt, yt, fxt, fyt, pt, qt, 0, 1)
        _damped_t_jit(xt, yt, xt0, yt0, w, x, y)


alt_lines = serial(_alt_lines)


def _rows_reference(x, y, fx, fy, p, q, i, j):
    """NumPy reference: ``(den, c_N, c_S, r_x, r_y)`` at nodes ``(i, j)`` (arrays), as :func:`_node`."""
    xe, xw, xn, xs = x[i + 1, j], x[i - 1, j], x[i, j + 1], x[i, j - 1]
    ye, yw, yn, ys = y[i + 1, j], y[i - 1, j], y[i, j + 1], y[i, j - 1]
    xxi, yxi, xet, yet = 0.5 * (xe - xw), 0.5 * (ye - yw), 0.5 * (xn - xs), 0.5 * (yn - ys)
    a = xet**2 + yet**2
    b = xxi * xet + yxi * yet
    g = xxi**2 + yxi**2
    cx = x[i + 1, j + 1] - x[i - 1, j + 1] - x[i + 1, j - 1] + x[i - 1, j - 1]
    cy = y[i + 1, j + 1] - y[i - 1, j + 1] - y[i + 1, j - 1] + y[i - 1, j - 1]
    rx = a * (xe + xw) - 0.5 * b * cx  # all but the line neighbours' γ and Q terms
    ry = a * (ye + yw) - 0.5 * b * cy
    cq = np.zeros_like(g)
    if p.size:
        d2 = (xxi * yet - xet * yxi) ** 2
        full = 0.5 * d2 * q[i, j]
        cq = np.clip(full, -g, g)
        rx = rx + d2 * p[i, j] * xxi + (full - cq) * (xn - xs)  # the explicit rest of the Q term
        ry = ry + d2 * p[i, j] * yxi + (full - cq) * (yn - ys)
    if fx.size:
        rx = rx + fx[i, j]
        ry = ry + fy[i, j]
    return 2.0 * (a + g), g + cq, g - cq, rx, ry


def _solve_reference(x, y, nodes, den, lower, upper, rx, ry, ends) -> None:
    """Dense solve of one line: ``nodes`` (list of ``(i, j)``) in line order, ``lower[k]``,
    ``upper[k]`` the coefficients of nodes ``k − 1``, ``k + 1``; ``ends``: the border nodes
    before the first and after the last."""
    A = np.diag(den) - np.diag(upper[:-1], 1) - np.diag(lower[1:], -1)
    rx, ry = rx.copy(), ry.copy()
    (i0, j0), (i1, j1) = ends
    rx[0] += lower[0] * x[i0, j0]
    ry[0] += lower[0] * y[i0, j0]
    rx[-1] += upper[-1] * x[i1, j1]
    ry[-1] += upper[-1] * y[i1, j1]
    sx, sy = np.linalg.solve(A, rx), np.linalg.solve(A, ry)
    for (i, j), vx, vy in zip(nodes, sx, sy, strict=True):
        x[i, j], y[i, j] = vx, vy


def smooth_lines_reference(x, y, fx, fy, p, q, wake: int, sweeps: int) -> None:
    """NumPy reference of :func:`smooth_lines`: each line a dense solve, the same order."""
    ni1, nj1 = x.shape
    ni, n = ni1 - 1, nj1 - 2
    if n < 1:
        return
    j = np.arange(1, nj1 - 1)
    for _ in range(sweeps):
        for i in range(1, wake if wake > 1 else 1):
            m = ni - i
            dm, nm, sm, xm, ym = (a[::-1] for a in _rows_reference(x, y, fx, fy, p, q, np.full(n, m), j))
            di, ni_, si, xi, yi = _rows_reference(x, y, fx, fy, p, q, np.full(n, i), j)
            # the cut node: neighbours N = (i, 1), S = (m, 1); P = Q = 0
            xxi, yxi = 0.5 * (x[i + 1, 0] - x[i - 1, 0]), 0.5 * (y[i + 1, 0] - y[i - 1, 0])
            xet, yet = 0.5 * (x[i, 1] - x[m, 1]), 0.5 * (y[i, 1] - y[m, 1])
            a, b, g = xet**2 + yet**2, xxi * xet + yxi * yet, xxi**2 + yxi**2
            cx = x[i + 1, 1] - x[i - 1, 1] - x[m - 1, 1] + x[m + 1, 1]
            cy = y[i + 1, 1] - y[i - 1, 1] - y[m - 1, 1] + y[m + 1, 1]
            cxr = a * (x[i + 1, 0] + x[i - 1, 0]) - 0.5 * b * cx + (fx[i, 0] if fx.size else 0.0)
            cyr = a * (y[i + 1, 0] + y[i - 1, 0]) - 0.5 * b * cy + (fy[i, 0] if fy.size else 0.0)
            nodes = [(m, jj) for jj in j[::-1]] + [(i, 0)] + [(i, jj) for jj in j]
            _solve_reference(
                x,
                y,
                nodes,
                np.concatenate([dm, [2.0 * (a + g)], di]),
                np.concatenate([nm, [g], si]),  # column m runs against η: N comes first
                np.concatenate([sm, [g], ni_]),
                np.concatenate([xm, [cxr], xi]),
                np.concatenate([ym, [cyr], yi]),
                ((m, nj1 - 1), (i, nj1 - 1)),
            )
            x[m, 0], y[m, 0] = x[i, 0], y[i, 0]
        for start in (1, 2):
            for i in range(start, ni, 2):
                if wake > 1 and (i < wake or i > ni - wake):
                    continue
                den, cn, cs, rx, ry = _rows_reference(x, y, fx, fy, p, q, np.full(n, i), j)
                _solve_reference(x, y, [(i, jj) for jj in j], den, cs, cn, rx, ry, ((i, 0), (i, nj1 - 1)))
