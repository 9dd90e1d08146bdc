r"""A whole multiblock V-cycle in one compiled call (numba; functions only).

The Python driver (:func:`.multigrid._cycle_reference`) calls one kernel per
smoothing step, defect and transfer; on the small coarse levels of a lake
layout the dispatch (and scipy's sparse products) cost as much as the
arithmetic.  Here every level of a hierarchy lives in two flat buffers
(``ib`` indices, ``fb`` floats), described by a level table ``meta`` (one row
per level, columns ``C_*``: offsets into the buffers and sizes), built once per
hierarchy by :func:`.multigrid.pack` (``ib`` in int32 when the ids fit: half the bytes the
sweeps stream through).  :func:`vcycle` runs exactly the
operations of the Python driver in the same order (the same table kernels of
:mod:`._kernels`, the transfers as CSR products summed in the same order), so
both give the same iterates (the test oracle compares them).  Gathered ids are read as unsigned
indices (:func:`._kernels._u`).

Level ``k`` holds its node values ``x, y, f_x, f_y, r_x, r_y, v_x, v_y``
(``v``: the injected finer values a coarse level started from), its table
(``nodes, nbr``, irregular nodes, the block lines along ξ then along η, their rows gathered), and on
a coarse level the injection, the FAS scaling, the free-node mask and the
transfers: ``P`` (finer × this level) and ``R`` (this level × finer), CSR.
"""

from __future__ import annotations

import math

from numba import njit

from ._kernels import _u, line_sweep_rhs, table_defect, table_sweep_rhs

__all__ = ["META_COLS", "vcycle"]

#: Columns of the level table (sizes, then offsets into ``ib`` / ``fb``).
(
    C_N,  # nodes of the level
    C_NREG,  # regular free nodes (table rows)
    C_NINT,  # of which block-interior (the rest lie on block borders)
    C_NIRR,  # irregular free nodes
    C_NRING,  # entries of their rings
    C_NROWS,  # table rows on lines
    C_NL0,  # lines along ξ
    C_NL,  # all lines (ξ then η)
    C_PNZ,  # nonzeros of P (coarse levels)
    C_RNZ,  # nonzeros of R (coarse levels)
    C_NBAND,  # regular nodes near the fixed boundary
    C_NODES,  # ib offsets from here on
    C_NBR,
    C_IRRN,
    C_IRRP,
    C_RING,
    C_LNODES,  # the line tables (nodes, neighbour rows in line order; ξ then η)
    C_LNBR,
    C_LPTR,
    C_LAXIS,
    C_INJ,
    C_FREE,
    C_PPTR,
    C_PIDX,
    C_RPTR,
    C_RIDX,
    C_BNODES,
    C_BNBR,
    C_X,  # fb offsets from here on
    C_Y,
    C_FX,
    C_FY,
    C_RX,
    C_RY,
    C_VX,
    C_VY,
    C_SCALE,
    C_PVAL,
    C_RVAL,
) = range(39)
META_COLS = 39


@njit(cache=True, nogil=True)
def _f(fb, m, col):  # pragma: no cover - compiled
    """The node-value array ``col`` of level ``m`` (a view into ``fb``)."""
    return fb[m[col] : m[col] + m[C_N]]


@njit(cache=True, nogil=True)
def _rhs(fb, m, use_f):  # pragma: no cover - compiled
    """The level's ``f`` (x and y), or empty views when it is zero and not to be read (the table
    kernels then leave it out)."""
    fx, fy = _f(fb, m, C_FX), _f(fb, m, C_FY)
    if use_f:
        return fx, fy
    return fx[:0], fy[:0]


@njit(cache=True, nogil=True)
def _smooth(fb, ib, m, steps, border_sweeps, band_sweeps, line_omega, use_f=True):  # pragma: no cover
    """``steps`` smoothing steps on one level: point sweep, lines along ξ (even steps) or along η
    (odd steps; damped by ``line_omega``), border sweeps, sweeps over the band next to the fixed
    boundary (``use_f`` false: the level's ``f`` is zero and not read)."""
    x, y = _f(fb, m, C_X), _f(fb, m, C_Y)
    fx, fy = _rhs(fb, m, use_f)
    nodes = ib[m[C_NODES] : m[C_NODES] + m[C_NREG]]
    nbr = ib[m[C_NBR] : m[C_NBR] + 8 * m[C_NREG]].reshape((m[C_NREG], 8))
    irr_n = ib[m[C_IRRN] : m[C_IRRN] + m[C_NIRR]]
    irr_p = ib[m[C_IRRP] : m[C_IRRP] + m[C_NIRR] + 1]
    ring = ib[m[C_RING] : m[C_RING] + m[C_NRING]]
    lnodes = ib[m[C_LNODES] : m[C_LNODES] + m[C_NROWS]]
    lnbr = ib[m[C_LNBR] : m[C_LNBR] + 8 * m[C_NROWS]].reshape((m[C_NROWS], 8))
    lptr = ib[m[C_LPTR] : m[C_LPTR] + m[C_NL] + 1]
    axis = ib[m[C_LAXIS] : m[C_LAXIS] + m[C_NL]]
    nl0, nint = m[C_NL0], m[C_NINT]
    band = ib[m[C_BNODES] : m[C_BNODES] + m[C_NBAND]]
    band_nbr = ib[m[C_BNBR] : m[C_BNBR] + 8 * m[C_NBAND]].reshape((m[C_NBAND], 8))
    no_irr = irr_p[:1]
    for step in range(steps):
        table_sweep_rhs(x, y, fx, fy, nodes, nbr, irr_n, irr_p, ring, 1.0)
        if step % 2 == 0:
            line_sweep_rhs(x, y, fx, fy, lnodes, lnbr, lptr[: nl0 + 1], axis[:nl0], line_omega)
        else:
            line_sweep_rhs(x, y, fx, fy, lnodes, lnbr, lptr[nl0:], axis[nl0:], line_omega)
        for _ in range(border_sweeps):
            table_sweep_rhs(x, y, fx, fy, nodes[nint:], nbr[nint:], irr_n, irr_p, ring, 1.0)
        for _ in range(band_sweeps):
            table_sweep_rhs(x, y, fx, fy, band, band_nbr, irr_n[:0], no_irr, ring[:0], 1.0)


@njit(cache=True, nogil=True)
def _defect(fb, ib, m, x, y, fx, fy, rx, ry):  # pragma: no cover - compiled
    """:func:`._kernels.table_defect` with the table of level ``m``."""
    nodes = ib[m[C_NODES] : m[C_NODES] + m[C_NREG]]
    nbr = ib[m[C_NBR] : m[C_NBR] + 8 * m[C_NREG]].reshape((m[C_NREG], 8))
    irr_n = ib[m[C_IRRN] : m[C_IRRN] + m[C_NIRR]]
    irr_p = ib[m[C_IRRP] : m[C_IRRP] + m[C_NIRR] + 1]
    ring = ib[m[C_RING] : m[C_RING] + m[C_NRING]]
    return table_defect(x, y, fx, fy, nodes, nbr, irr_n, irr_p, ring, rx, ry)


@njit(cache=True, nogil=True)
def _coarsest(fb, ib, m, min_sweeps, reduction, max_sweeps):  # pragma: no cover - compiled
    """SOR on the coarsest level until the defect fell by ``reduction`` (checked every 10 sweeps
    from ``min_sweeps`` on), at most ``max_sweeps`` sweeps."""
    x, y, fx, fy = _f(fb, m, C_X), _f(fb, m, C_Y), _f(fb, m, C_FX), _f(fb, m, C_FY)
    rx, ry = _f(fb, m, C_RX), _f(fb, m, C_RY)
    nodes = ib[m[C_NODES] : m[C_NODES] + m[C_NREG]]
    nbr = ib[m[C_NBR] : m[C_NBR] + 8 * m[C_NREG]].reshape((m[C_NREG], 8))
    irr_n = ib[m[C_IRRN] : m[C_IRRN] + m[C_NIRR]]
    irr_p = ib[m[C_IRRP] : m[C_IRRP] + m[C_NIRR] + 1]
    ring = ib[m[C_RING] : m[C_RING] + m[C_NRING]]
    omega = 2.0 / (1.0 + math.sin(math.pi / max(math.sqrt(2.0 * m[C_N]), 2.0)))
    rx[:] = 0.0
    ry[:] = 0.0
    r0 = table_defect(x, y, fx, fy, nodes, nbr, irr_n, irr_p, ring, rx, ry)
    for sweep in range(1, max_sweeps + 1):
        table_sweep_rhs(x, y, fx, fy, nodes, nbr, irr_n, irr_p, ring, omega)
        if sweep % 10 == 0 and sweep >= min_sweeps:
            r = table_defect(x, y, fx, fy, nodes, nbr, irr_n, irr_p, ring, rx, ry)
            if r <= reduction * r0:
                break


@njit(cache=True, nogil=True)
def _restrict_to(fb, ib, fine, co):  # pragma: no cover - compiled
    """Inject the finer level's values into ``co`` (``x = v``) and set its FAS right-hand side
    ``f = −A_H(v) + s · R r`` (0 at fixed nodes); the finer level's defect is in its ``r``."""
    xf, yf = _f(fb, fine, C_X), _f(fb, fine, C_Y)
    rxf, ryf = _f(fb, fine, C_RX), _f(fb, fine, C_RY)
    x, y, fx, fy = _f(fb, co, C_X), _f(fb, co, C_Y), _f(fb, co, C_FX), _f(fb, co, C_FY)
    vx, vy, dx, dy = _f(fb, co, C_VX), _f(fb, co, C_VY), _f(fb, co, C_RX), _f(fb, co, C_RY)
    scale = _f(fb, co, C_SCALE)
    inj = ib[co[C_INJ] : co[C_INJ] + co[C_N]]
    free = ib[co[C_FREE] : co[C_FREE] + co[C_N]]
    rptr = ib[co[C_RPTR] : co[C_RPTR] + co[C_N] + 1]
    ridx = ib[co[C_RIDX] : co[C_RIDX] + co[C_RNZ]]
    rval = fb[co[C_RVAL] : co[C_RVAL] + co[C_RNZ]]
    n = co[C_N]
    for i in range(n):
        vx[i] = xf[_u(inj[i])]
        vy[i] = yf[_u(inj[i])]
        dx[i] = 0.0
        dy[i] = 0.0
        fx[i] = 0.0
        fy[i] = 0.0
    _defect(fb, ib, co, vx, vy, fx, fy, dx, dy)  # d = T(v) − v = −A_H(v)
    for i in range(n):
        x[i] = vx[i]
        y[i] = vy[i]
        if free[i] == 0:
            continue
        sx = 0.0
        sy = 0.0
        for q in range(rptr[i], rptr[i + 1]):
            sx += rval[q] * rxf[_u(ridx[q])]
            sy += rval[q] * ryf[_u(ridx[q])]
        fx[i] = -dx[i] + scale[i] * sx
        fy[i] = -dy[i] + scale[i] * sy


@njit(cache=True, nogil=True)
def _correct(fb, ib, fine, co):  # pragma: no cover - compiled
    """``u_h ← u_h + P (u_H − v)`` on the finer level."""
    xf, yf = _f(fb, fine, C_X), _f(fb, fine, C_Y)
    x, y, vx, vy = _f(fb, co, C_X), _f(fb, co, C_Y), _f(fb, co, C_VX), _f(fb, co, C_VY)
    ex, ey = _f(fb, co, C_RX), _f(fb, co, C_RY)  # scratch: the coarse correction
    for i in range(co[C_N]):
        ex[i] = x[i] - vx[i]
        ey[i] = y[i] - vy[i]
    pptr = ib[co[C_PPTR] : co[C_PPTR] + fine[C_N] + 1]
    pidx = ib[co[C_PIDX] : co[C_PIDX] + co[C_PNZ]]
    pval = fb[co[C_PVAL] : co[C_PVAL] + co[C_PNZ]]
    for i in range(fine[C_N]):
        if pptr[i + 1] == pptr[i]:
            continue
        sx = 0.0
        sy = 0.0
        for q in range(pptr[i], pptr[i + 1]):
            sx += pval[q] * ex[_u(pidx[q])]
            sy += pval[q] * ey[_u(pidx[q])]
        xf[i] += sx
        yf[i] += sy


@njit(cache=True, nogil=True)
def vcycle(
    fb, ib, meta, k0, pre, post, border_sweeps, band_sweeps, c_min, c_reduction, c_max, line_omega, f0=True
):  # pragma: no cover
    """One FAS V(``pre``, ``post``) cycle from level ``k0`` (its ``x, y, f`` set in ``fb``); the line
    sweeps damped by ``line_omega`` (1: undamped).  ``f0`` false: level ``k0``'s ``f`` is zero (the
    solver's cycles and full-multigrid start) and its sweeps and defect do not read it."""
    last = meta.shape[0] - 1
    for k in range(k0, last):
        m = meta[k]
        use_f = f0 or k > k0
        _smooth(fb, ib, m, pre, border_sweeps, band_sweeps, line_omega, use_f)
        rx, ry = _f(fb, m, C_RX), _f(fb, m, C_RY)
        rx[:] = 0.0
        ry[:] = 0.0
        fx, fy = _rhs(fb, m, use_f)
        _defect(fb, ib, m, _f(fb, m, C_X), _f(fb, m, C_Y), fx, fy, rx, ry)
        _restrict_to(fb, ib, m, meta[k + 1])
    _coarsest(fb, ib, meta[last], c_min, c_reduction, c_max)
    for k in range(last - 1, k0 - 1, -1):
        _correct(fb, ib, meta[k], meta[k + 1])
        _smooth(fb, ib, meta[k], post, border_sweeps, band_sweeps, line_omega, f0 or k > k0)
