r"""Whole coarse V-cycles and the full-multigrid start in one compiled call (numba).

The serial coarse levels of a solve live in flat buffers (``fbuf`` floats,
``ibuf`` indices) described by a level table (``meta``, columns ``M_*``);
:func:`vcycle` and :func:`fmg_start` run exactly the operations of the Python
driver (:meth:`.multigrid._FAS.cycle`) on them, without the per-kernel Python
dispatch that dominates on small levels.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ._mg_defect import add_operator, defect, defect_restrict
from ._mg_relax import smooth, smooth_band
from ._mg_transfer import prolong_correct, restrict, sample

__all__ = ["META_COLS", "fmg_start", "vcycle"]

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
