r"""Nonlinear multigrid (FAS) over a whole multiblock topology (``engine="multigrid"``).

The unknowns are the free nodes of the global node array (see
:class:`~.topology.NodeMap`), the equations ``A(u) = u − T(u) = f`` with ``T``
the point-Jacobi target of :mod:`._kernels` (9-point Winslow stencil in the
local frame of each regular node, ring mean at nodes where 3, 5, … blocks
meet), ``f = 0`` on the finest level.

Hierarchy: a level is coarsened by taking every other node of every block,
which needs even cell counts in every block and even node ranges in every
interface; the coarse topology has the same blocks, interfaces and corners
(:func:`coarsen`).  Coarsening stops when that fails or a block side would
get fewer than :data:`MIN_CELLS` cells.

Full Approximation Scheme, one V(``PRE``, ``POST``) cycle::

    u ← smooth(u, f)                                     (Gauss–Seidel sweeps)
    r = f − A(u)
    v = R̂ u              (injection: the coarse nodes are fine nodes)
    solve approximately  A_H(u_H) = A_H(v) + 4 R r       (recursively)
    u ← u + P (u_H − v)
    u ← smooth(u, f)

``R`` is full weighting over the local 3 × 3 frame of each coarse node (the
ring mean plus the node itself at irregular nodes), ``P`` bilinear
interpolation inside each block (interface values come from interface values
only, so both blocks agree).  The factor 4: in index units ``A = −N/(2(α+γ))``
scales like ``h²`` (``N`` like ``h⁴``, α, γ like ``h²``).  The stopping rule is
the shared one: the finest-level defect with ``f = 0`` is the point-Jacobi
displacement.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np

from ..boundary import Borders
from . import _kernels
from .topology import Block, Interface, MultiBlockTopology, Side

__all__ = ["MIN_CELLS", "coarsen", "levels", "solve_fas"]

#: A block side keeps at least this many cells on the coarsest level.
MIN_CELLS = 2
#: ``engine="auto"`` leaves multigrid for SOR when a cycle reduces the defect by less than
#: this (one cycle costs about as much as 16 single-block SOR sweeps; SOR reduces by ≈ 0.96
#: per sweep on the lake examples, 0.96¹⁶ ≈ 0.5).
AUTO_GIVE_UP_RATE = 0.5
#: Gauss–Seidel sweeps before / after the coarse-grid correction.
PRE, POST = 2, 2
#: Sweeps on the coarsest level: at least COARSEST_SWEEPS, then until the defect fell by
#: COARSEST_REDUCTION, at most COARSEST_MAX_SWEEPS.
COARSEST_SWEEPS = 20
COARSEST_REDUCTION = 1e-3
COARSEST_MAX_SWEEPS = 2000


def coarsen(topo: MultiBlockTopology) -> MultiBlockTopology | None:
    """The topology with every other node of every block, or None if not possible."""
    for b in topo.blocks:
        ni, nj = b.cells
        if ni % 2 or nj % 2 or ni // 2 < MIN_CELLS or nj // 2 < MIN_CELLS:
            return None
    for itf in topo.interfaces:
        if any(v % 2 for v in (itf.a.start, itf.a.stop, itf.b.start, itf.b.stop)):
            return None
    blocks = tuple(
        Block(
            b.name,
            Borders(
                bottom=b.borders.bottom[::2], right=b.borders.right[::2],
                top=b.borders.top[::2], left=b.borders.left[::2],
            ),
            initial=b.initial, weights=b.weights, names=b.names,
        )
        for b in topo.blocks
    )
    itfs = tuple(
        Interface(
            Side(i.a.block, i.a.border, i.a.start // 2, i.a.stop // 2),
            Side(i.b.block, i.b.border, i.b.start // 2, i.b.stop // 2),
            i.reversed,
        )
        for i in topo.interfaces
    )
    return MultiBlockTopology(blocks, itfs, check_geometry=False)


@dataclass(slots=True)
class _Level:
    topo: MultiBlockTopology
    args: tuple  # table arguments (nodes, nbr, irr_nodes, irr_ptr, irr_ring)
    n: int
    free: np.ndarray  # bool
    inj: np.ndarray | None = None  # coarse node → fine node (set on the coarse level)
    fw_nodes: np.ndarray | None = None  # coarse regular-in-fine free nodes …
    fw_nbr: np.ndarray | None = None  # … and the 8 fine neighbours of their fine node
    ri_nodes: np.ndarray | None = None  # coarse nodes whose fine node is irregular
    ri_fine: np.ndarray | None = None
    ri_ptr: np.ndarray | None = None
    ri_ring: np.ndarray | None = None


def levels(topo: MultiBlockTopology, max_levels: int = 12) -> list[_Level]:
    """The multigrid hierarchy (finest first)."""
    out = []
    t: MultiBlockTopology | None = topo
    while t is not None and len(out) < max_levels:
        m = t.node_map
        free = np.zeros(m.n_nodes, dtype=bool)
        free[m.nodes] = True
        free[m.irr_nodes] = True
        out.append(_Level(t, (m.nodes, m.nbr, m.irr_nodes, m.irr_ptr, m.irr_ring), m.n_nodes, free))
        t = coarsen(t)
    for fine, coarse in itertools.pairwise(out):
        mf, mc = fine.topo.node_map, coarse.topo.node_map
        inj = np.empty(mc.n_nodes, dtype=np.int64)
        for gf, gc in zip(mf.ids, mc.ids, strict=True):
            inj[gc.ravel()] = gf[::2, ::2].ravel()
        coarse.inj = inj
        row = np.full(mf.n_nodes, -1, dtype=np.int64)
        row[mf.nodes] = np.arange(len(mf.nodes))
        irow = np.full(mf.n_nodes, -1, dtype=np.int64)
        irow[mf.irr_nodes] = np.arange(len(mf.irr_nodes))
        cfree = np.flatnonzero(coarse.free)
        p = inj[cfree]
        reg = row[p] >= 0
        coarse.fw_nodes = cfree[reg]
        coarse.fw_nbr = mf.nbr[row[p[reg]]]
        irr = irow[p] >= 0
        coarse.ri_nodes = cfree[irr]
        coarse.ri_fine = p[irr]
        k = irow[p[irr]]
        coarse.ri_ptr = mf.irr_ptr
        coarse.ri_ring = (k, mf.irr_ring)
    return out


def _restrict(lv: _Level, r: np.ndarray) -> np.ndarray:
    """Full weighting of the fine defect ``r`` onto the coarse free nodes of ``lv``."""
    out = np.zeros(lv.n)
    nb = lv.fw_nbr
    out[lv.fw_nodes] = (
        4.0 * r[lv.inj[lv.fw_nodes]] + 2.0 * r[nb[:, :4]].sum(axis=1) + r[nb[:, 4:]].sum(axis=1)
    ) / 16.0
    ks, ring = lv.ri_ring
    for c, p, k in zip(lv.ri_nodes.tolist(), lv.ri_fine.tolist(), ks.tolist(), strict=True):
        nbrs = ring[lv.ri_ptr[k] : lv.ri_ptr[k + 1]]
        out[c] = 0.5 * r[p] + 0.5 * r[nbrs].mean()
    return out


def _prolong(fine: _Level, coarse: _Level, e: np.ndarray) -> np.ndarray:
    """Bilinear interpolation of the coarse correction ``e`` block by block."""
    c = np.zeros(fine.n)
    for gf, gc in zip(fine.topo.node_map.ids, coarse.topo.node_map.ids, strict=True):
        E = e[gc]
        F = np.empty(gf.shape)
        F[::2, ::2] = E
        F[1::2, ::2] = 0.5 * (E[:-1] + E[1:])
        F[::2, 1::2] = 0.5 * (E[:, :-1] + E[:, 1:])
        F[1::2, 1::2] = 0.25 * (E[:-1, :-1] + E[1:, :-1] + E[:-1, 1:] + E[1:, 1:])
        c[gf] = F
    c[~fine.free] = 0.0
    return c


def _cycle(lvs: list[_Level], k: int, x, y, fx, fy) -> None:
    lv = lvs[k]
    if k == len(lvs) - 1:
        # SOR until the defect dropped by COARSEST_REDUCTION (checked every 10 sweeps)
        omega = 2.0 / (1.0 + math.sin(math.pi / max(math.sqrt(2.0 * lv.n), 2.0)))
        rx, ry = np.zeros(lv.n), np.zeros(lv.n)
        r0 = _kernels.table_defect(x, y, fx, fy, *lv.args, rx, ry)
        for sweep in range(1, COARSEST_MAX_SWEEPS + 1):
            _kernels.table_sweep_rhs(x, y, fx, fy, *lv.args, omega)
            if sweep % 10 == 0 and sweep >= COARSEST_SWEEPS:
                r = _kernels.table_defect(x, y, fx, fy, *lv.args, rx, ry)
                if r <= COARSEST_REDUCTION * r0:
                    break
        return
    for _ in range(PRE):
        _kernels.table_sweep_rhs(x, y, fx, fy, *lv.args, 1.0)
    rx, ry = np.zeros(lv.n), np.zeros(lv.n)
    _kernels.table_defect(x, y, fx, fy, *lv.args, rx, ry)
    co = lvs[k + 1]
    vx, vy = x[co.inj].copy(), y[co.inj].copy()
    zero = np.zeros(co.n)
    dx, dy = np.zeros(co.n), np.zeros(co.n)
    _kernels.table_defect(vx, vy, zero, zero, *co.args, dx, dy)  # d = T(v) − v = −A_H(v)
    fcx = -dx + 4.0 * _restrict(co, rx)
    fcy = -dy + 4.0 * _restrict(co, ry)
    fcx[~co.free] = 0.0
    fcy[~co.free] = 0.0
    ux, uy = vx.copy(), vy.copy()
    _cycle(lvs, k + 1, ux, uy, fcx, fcy)
    x += _prolong(lv, co, ux - vx)
    y += _prolong(lv, co, uy - vy)
    for _ in range(POST):
        _kernels.table_sweep_rhs(x, y, fx, fy, *lv.args, 1.0)


def solve_fas(x, y, topo: MultiBlockTopology, tol: float, max_cycles: int, callback=None,
              give_up_rate: float | None = None):
    """V-cycles on the global arrays ``x, y`` (in place) until the Jacobi residual ≤ ``tol``.

    ``give_up_rate``: stop with message ``"slow"`` when, from the third cycle
    on, the defect falls by less than this factor per cycle (geometric mean of
    the last two cycles) — the caller then continues with SOR.

    Returns ``(cycles, residual, history, message, n_levels)``.
    """
    lvs = levels(topo)
    lv = lvs[0]
    zero = np.zeros(lv.n)
    rx, ry = np.zeros(lv.n), np.zeros(lv.n)
    r = float(_kernels.table_defect(x, y, zero, zero, *lv.args, rx, ry))
    history = [(0, r)]
    best, saved = r, (x.copy(), y.copy())
    for it in range(1, max_cycles + 1):
        if r <= tol:
            return it - 1, r, history, "", len(lvs)
        _cycle(lvs, 0, x, y, zero, zero)
        r = float(_kernels.table_defect(x, y, zero, zero, *lv.args, rx, ry))
        history.append((it, r))
        if callback is not None and callback(it, r) == "stop":
            return it, r, history, "stopped", len(lvs)
        if not math.isfinite(r) or r > 1e3 * best:
            x[...] = saved[0]
            y[...] = saved[1]
            return it, history[0][1], history, "diverged", len(lvs)
        if r < best:
            best = r
            saved = (x.copy(), y.copy())
        if give_up_rate is not None and it >= 3 and r > tol:
            rate = math.sqrt(r / history[-3][1]) if history[-3][1] > 0 else 0.0
            if rate > give_up_rate:
                return it, r, history, "slow", len(lvs)
    return max_cycles, r, history, "", len(lvs)
