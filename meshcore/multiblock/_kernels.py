r"""numba kernels for the multiblock ``smooth`` mode (functions only, no state).

All blocks are assembled into one node array ``x, y`` (each shared node stored
once).  A free *regular* node ``n = nodes[k]`` has exactly four cells around
it; ``nbr[k] = (E, W, N, S, NE, NW, SE, SW)`` are its eight neighbours in a
local frame taken from its ring of cells (see :mod:`.topology`).  Its update is
the single-block Winslow stencil (:func:`meshcore.elliptic._stencil.winslow`) with
P = Q = 0:

.. math::

    2(α + γ) φ_P^* = α(φ_E + φ_W) + γ(φ_N + φ_S) − \tfrac{β}{2}(φ_{NE} − φ_{NW} − φ_{SE} + φ_{SW}).

The discrete equation is invariant under the eight symmetries of the square
(rotating or mirroring the local frame maps α ↔ γ, β → ±β), so any frame
taken from the ring of cells gives the same equation as the owning block's.

A free *irregular* node (a corner where 3, 5, … blocks meet: ``k ≠ 4`` cells
around it) has no 9-point stencil.  It is moved to the mean of its ``k`` edge
neighbours (a Laplacian update over its ring, ``irr_ring[irr_ptr[k]:irr_ptr[k+1]]``),
which for a symmetric star of ``k`` equal cells is the symmetric position.

Sweeps are Gauss–Seidel/SOR in table order (block by block, lexicographic),
serial.  Each function returns the largest displacement (a length), ``inf`` if a
node is NaN (a NaN grid must never pass the stopping test).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ..elliptic._stencil import winslow

__all__ = [
    "grow_rows",
    "line_sweep_rhs",
    "reverse_table",
    "table_defect",
    "table_residual",
    "table_sweep",
    "table_sweep_rhs",
]


@njit(cache=True, nogil=True, inline="always")
def _u(i):  # pragma: no cover - compiled
    """The node id ``i`` as an unsigned index: numba then does not test it for a negative value
    (wrap-around), one compare and select less per load (ids are never negative here).  The same
    loads, the same arithmetic; the sweeps 10–28 % faster (measured on the Shasta examples and
    lake layouts, every level)."""
    return np.uint64(i)


@njit(cache=True, nogil=True)
def _update(x, y, nb):  # pragma: no cover - compiled
    """:func:`~meshcore.elliptic._stencil.winslow` at a regular node with neighbours ``nb``."""
    e, w, n, s = _u(nb[0]), _u(nb[1]), _u(nb[2]), _u(nb[3])
    ne, nw, se, sw = _u(nb[4]), _u(nb[5]), _u(nb[6]), _u(nb[7])
    sx, sy, den, _, _, _, _ = winslow(
        x[e], x[w], x[n], x[s], x[ne], x[nw], x[se], x[sw],
        y[e], y[w], y[n], y[s], y[ne], y[nw], y[se], y[sw],
    )  # fmt: skip
    return sx, sy, den


@njit(cache=True, nogil=True)
def table_sweep(x, y, nodes, nbr, irr_nodes, irr_ptr, irr_ring, omega):  # pragma: no cover
    """One SOR sweep over the regular nodes, then the irregular ones (:func:`table_sweep_rhs`
    with ``f = 0``)."""
    e = np.zeros(0)
    return table_sweep_rhs(x, y, e, e, nodes, nbr, irr_nodes, irr_ptr, irr_ring, omega)


@njit(cache=True, nogil=True)
def table_residual(x, y, nodes, nbr, irr_nodes, irr_ptr, irr_ring):  # pragma: no cover
    """Largest point-Jacobi displacement (the shared stopping measure)."""
    dmax = 0.0
    for k in range(nodes.shape[0]):
        p = _u(nodes[k])
        rx, ry, den = _update(x, y, nbr[k])
        if den <= 0.0:
            continue
        dx = rx / den - x[p]
        dy = ry / den - y[p]
        m = dx * dx + dy * dy
        if not m <= dmax:  # a NaN makes the measure inf (never 'converged')
            dmax = m if m == m else np.inf
    for k in range(irr_nodes.shape[0]):
        p = _u(irr_nodes[k])
        sx = 0.0
        sy = 0.0
        for r in range(irr_ptr[k], irr_ptr[k + 1]):
            sx += x[_u(irr_ring[r])]
            sy += y[_u(irr_ring[r])]
        c = 1.0 / (irr_ptr[k + 1] - irr_ptr[k])
        dx = sx * c - x[p]
        dy = sy * c - y[p]
        m = dx * dx + dy * dy
        if not m <= dmax:  # a NaN makes the measure inf (never 'converged')
            dmax = m if m == m else np.inf
    return np.sqrt(dmax)


# ---------------------------------------------------------------- multigrid
# FAS form of the equations: A(u) = u − T(u) = f, with T the Jacobi target above
# (9-point stencil or ring mean).  f = 0 on the finest level.


@njit(cache=True, nogil=True)
def table_sweep_rhs(x, y, fx, fy, nodes, nbr, irr_nodes, irr_ptr, irr_ring, omega):  # pragma: no cover
    """One nonlinear Gauss–Seidel/SOR sweep of ``u − T(u) = f``: ``u_p ← u_p + ω (T_p + f_p − u_p)``
    (``fx, fy`` empty: ``f = 0``)."""
    use_f = fx.size > 0
    dmax = 0.0
    for k in range(nodes.shape[0]):
        p = _u(nodes[k])
        rx, ry, den = _update(x, y, nbr[k])
        if den <= 0.0:
            continue
        if use_f:
            dx = omega * (rx / den + fx[p] - x[p])
            dy = omega * (ry / den + fy[p] - y[p])
        else:
            dx = omega * (rx / den - x[p])
            dy = omega * (ry / den - y[p])
        x[p] += dx
        y[p] += dy
        m = dx * dx + dy * dy
        if not m <= dmax:  # a NaN makes the measure inf (never 'converged')
            dmax = m if m == m else np.inf
    for k in range(irr_nodes.shape[0]):
        p = _u(irr_nodes[k])
        sx = 0.0
        sy = 0.0
        for r in range(irr_ptr[k], irr_ptr[k + 1]):
            sx += x[_u(irr_ring[r])]
            sy += y[_u(irr_ring[r])]
        c = 1.0 / (irr_ptr[k + 1] - irr_ptr[k])
        if use_f:
            dx = omega * (sx * c + fx[p] - x[p])
            dy = omega * (sy * c + fy[p] - y[p])
        else:
            dx = omega * (sx * c - x[p])
            dy = omega * (sy * c - y[p])
        x[p] += dx
        y[p] += dy
        m = dx * dx + dy * dy
        if not m <= dmax:  # a NaN makes the measure inf (never 'converged')
            dmax = m if m == m else np.inf
    return np.sqrt(dmax)


@njit(cache=True, nogil=True)
def table_defect(x, y, fx, fy, nodes, nbr, irr_nodes, irr_ptr, irr_ring, rx_out, ry_out):  # pragma: no cover
    """Defect ``r = f − (u − T(u))`` at every free node (other entries untouched); returns max |r|
    (``fx, fy`` empty: ``f = 0``, not read)."""
    use_f = fx.size > 0
    dmax = 0.0
    for k in range(nodes.shape[0]):
        p = _u(nodes[k])
        rx, ry, den = _update(x, y, nbr[k])
        if den <= 0.0:
            rx_out[p] = 0.0
            ry_out[p] = 0.0
            continue
        if use_f:
            dx = rx / den + fx[p] - x[p]
            dy = ry / den + fy[p] - y[p]
        else:
            dx = rx / den - x[p]
            dy = ry / den - y[p]
        rx_out[p] = dx
        ry_out[p] = dy
        m = dx * dx + dy * dy
        if not m <= dmax:  # a NaN makes the measure inf (never 'converged')
            dmax = m if m == m else np.inf
    for k in range(irr_nodes.shape[0]):
        p = _u(irr_nodes[k])
        sx = 0.0
        sy = 0.0
        for r in range(irr_ptr[k], irr_ptr[k + 1]):
            sx += x[_u(irr_ring[r])]
            sy += y[_u(irr_ring[r])]
        c = 1.0 / (irr_ptr[k + 1] - irr_ptr[k])
        if use_f:
            dx = sx * c + fx[p] - x[p]
            dy = sy * c + fy[p] - y[p]
        else:
            dx = sx * c - x[p]
            dy = sy * c - y[p]
        rx_out[p] = dx
        ry_out[p] = dy
        m = dx * dx + dy * dy
        if not m <= dmax:  # a NaN makes the measure inf (never 'converged')
            dmax = m if m == m else np.inf
    return np.sqrt(dmax)


@njit(cache=True, nogil=True)
def line_sweep_rhs(x, y, fx, fy, lnodes, lnbr, ptr, axis, omega=1.0):  # pragma: no cover - compiled
    """Line Gauss–Seidel sweep of ``u − T(u) = f`` over block lines (``fx, fy`` empty: ``f = 0``).

    Line ``L`` is the nodes ``lnodes[ptr[L]:ptr[L + 1]]`` in order along its block axis
    ``axis[L]`` (0: W → E, 1: S → N), ``lnbr`` their neighbour rows in the block's frame (the table
    rows gathered in line order, those of interface nodes at the line's ends turned into the
    block's frame, :func:`.hierarchy.lines_reference`; read in sequence, where the table's colour
    order made a line along ξ jump through it, 4× slower on a 46 000-node lake, measured); its end
    neighbours stay fixed.  The coefficients α, β, γ
    are frozen at the current values and the tridiagonal system
    ``u_t − c_t (u_{t−1} + u_{t+1}) = f_t + T_t − c_t (u_{t−1} + u_{t+1})|current``
    (``c = α/den`` along ξ, ``γ/den`` along η) is solved exactly (Thomas algorithm), for x and y.
    With ``omega`` ≠ 1 every line moves ``omega`` of the way to its solution (damped: a line
    solved with frozen coefficients overshoots where cells are nearly folded; the retry of
    :func:`.solver._smooth`).  Returns the largest displacement (``inf`` if a node is NaN).
    """
    use_f = fx.size > 0
    m_max = 0
    for L in range(ptr.shape[0] - 1):
        m_max = max(m_max, ptr[L + 1] - ptr[L])
    cp = np.empty(m_max)
    bx = np.empty(m_max)
    by = np.empty(m_max)
    pp = np.empty(m_max, dtype=np.uint64)
    dmax = 0.0
    for L in range(ptr.shape[0] - 1):
        along_xi = axis[L] == 0
        lo_k, hi_k = (1, 0) if along_xi else (3, 2)
        m = ptr[L + 1] - ptr[L]
        # one pass: the frozen coefficients at t and the forward elimination (rows (−c_t, 1, −c_t))
        for t in range(m):
            p = _u(lnodes[ptr[L] + t])
            pp[t] = p
            nb = lnbr[ptr[L] + t]
            q0, q1, q2, q3 = _u(nb[0]), _u(nb[1]), _u(nb[2]), _u(nb[3])
            q4, q5, q6, q7 = _u(nb[4]), _u(nb[5]), _u(nb[6]), _u(nb[7])
            sx, sy, den, xxi, yxi, xet, yet = winslow(
                x[q0], x[q1], x[q2], x[q3], x[q4], x[q5], x[q6], x[q7],
                y[q0], y[q1], y[q2], y[q3], y[q4], y[q5], y[q6], y[q7],
            )  # fmt: skip
            if den <= 0.0:
                ct = 0.0
                b_x = x[p]
                b_y = y[p]
            else:
                lo, hi = _u(nb[lo_k]), _u(nb[hi_k])
                w = (xet * xet + yet * yet) if along_xi else (xxi * xxi + yxi * yxi)
                inv_den = 1.0 / den
                ct = w * inv_den
                b_x = sx * inv_den - ct * (x[lo] + x[hi])
                b_y = sy * inv_den - ct * (y[lo] + y[hi])
                if use_f:
                    b_x += fx[p]
                    b_y += fy[p]
                if t == 0:
                    b_x += ct * x[lo]
                    b_y += ct * y[lo]
                if t == m - 1:
                    b_x += ct * x[hi]
                    b_y += ct * y[hi]
            if t == 0:
                cp[t] = ct
                bx[t] = b_x
                by[t] = b_y
            else:
                inv = 1.0 / (1.0 - ct * cp[t - 1])
                cp[t] = ct * inv
                bx[t] = (b_x + ct * bx[t - 1]) * inv
                by[t] = (b_y + ct * by[t - 1]) * inv
        # back substitution, written back as it goes
        for t in range(m - 1, -1, -1):
            if t < m - 1:
                bx[t] += cp[t] * bx[t + 1]
                by[t] += cp[t] * by[t + 1]
            p = pp[t]
            dx = bx[t] - x[p]
            dy = by[t] - y[p]
            if omega == 1.0:
                x[p] = bx[t]
                y[p] = by[t]
            else:
                dx *= omega
                dy *= omega
                x[p] += dx
                y[p] += dy
            d = dx * dx + dy * dy
            if not d <= dmax:  # a NaN makes the measure inf (never 'converged')
                dmax = d if d == d else np.inf
    return np.sqrt(dmax)


# ---------------------------------------------------------------- hot spots
# The nodes round a few seeds (the largest defects after a cycle, :func:`.multigrid._hot_sweeps`)
# grown outward from the seeds: :func:`.hierarchy.near_rows` scans the whole table once per step.


@njit(cache=True, nogil=True)
def reverse_table(nodes, nbr, n):  # pragma: no cover - compiled
    """``(ptr, rows)``: for every node ``q`` of ``n`` the table rows whose stencil holds it,
    ``rows[ptr[q]:ptr[q + 1]]`` (ascending, a row once per stencil entry)."""
    ptr = np.zeros(n + 1, dtype=np.int64)
    for k in range(nodes.shape[0]):
        for c in range(8):
            ptr[nbr[k, c] + 1] += 1
    for q in range(n):
        ptr[q + 1] += ptr[q]
    fill = ptr[:-1].copy()
    rows = np.empty(ptr[n], dtype=np.int64)
    for k in range(nodes.shape[0]):
        for c in range(8):
            q = nbr[k, c]
            rows[fill[q]] = k
            fill[q] += 1
    return ptr, rows


@njit(cache=True, nogil=True)
def grow_rows(nodes, pos, ptr, rows, seeds, width):  # pragma: no cover - compiled
    """The table rows (ascending) of the nodes at most ``width`` steps of the 8-point stencil from
    a node of ``seeds``: the rows :func:`.hierarchy.near_rows` selects for the seed mask, grown
    from the seeds through :func:`reverse_table` ``(ptr, rows)`` (``pos``: node → its table row or
    −1).  Step ``s`` marks the rows whose stencil holds a node marked in step ``s − 1`` (the seeds
    in step 1), which are the rows :func:`._hier_kernels.grow_near` marks in its ``s``-th scan."""
    mark = np.zeros(pos.shape[0], dtype=np.bool_)
    marked = np.empty(pos.shape[0], dtype=np.int64)
    m = 0
    for s in seeds:
        if not mark[s]:
            mark[s] = True
            marked[m] = s
            m += 1
    lo = 0
    for _ in range(width):
        hi = m
        for t in range(lo, hi):
            q = marked[t]
            for u in range(ptr[q], ptr[q + 1]):
                p = nodes[rows[u]]
                if not mark[p]:
                    mark[p] = True
                    marked[m] = p
                    m += 1
        lo = hi
    out = np.empty(m, dtype=np.int64)
    c = 0
    for t in range(m):
        r = pos[marked[t]]
        if r >= 0:
            out[c] = r
            c += 1
    return np.sort(out[:c])
