r"""Nonlinear multigrid (FAS) over a whole multiblock topology (``engine="multigrid"``).

The unknowns are the free nodes of the global node array (see
:class:`~.topology.NodeMap`), the equations ``A(u) = u − T(u) = f`` with ``T``
the point-Jacobi target of :mod:`._kernels` (9-point Winslow stencil in the
local frame of each regular node, ring mean at nodes where 3, 5, … blocks
meet), ``f = 0`` on the finest level.

Hierarchy: a coarse level takes every ``ci``-th / ``cj``-th node of each
block, ``(ci, cj) ∈ {1, 2}²`` (:func:`coarsen`).  Axes glued along an
interface form a class that is coarsened together (:func:`plan`); a class is
not coarsened where its cells are clearly longer than wide (typical aspect >
:data:`SEMI_ASPECT`: semi-coarsening, so the point smoother still smooths) or
where a count or interface range is odd.  The coarse topology has the same
blocks, interfaces and corners.  Coarsening stops when no class can coarsen
or a side would get fewer than :data:`MIN_CELLS` cells.

Full Approximation Scheme, one V(``PRE``, ``POST``) cycle::

    u ← smooth(u, f)                                     (Gauss–Seidel sweeps)
    r = f − A(u)
    v = R̂ u              (injection: the coarse nodes are fine nodes)
    solve approximately  A_H(u_H) = A_H(v) + s · R r     (recursively)
    u ← u + P (u_H − v)
    u ← smooth(u, f)

``P`` is bilinear interpolation inside each block (interface values come from
interface values only, so both blocks agree), ``R = D⁻¹ Pᵀ`` its transpose
normalised by the row sums (full weighting inside a block, consistent across
interfaces and corners of any valence).  ``s``: in index units
``A = −N/(2(α+γ))`` with ``N → (ab)² N``, ``α → b² α``, ``γ → a² γ`` for
coarsening factors ``a, b``, so ``s = (ab)²(α+γ)/(b²α + a²γ)`` (4 for full
coarsening), evaluated on the start grid.  The stopping rule is the shared
one: the finest-level defect with ``f = 0`` is the point-Jacobi displacement.

Transfers are sparse matrices over the global node array (built once per
hierarchy, :func:`_transfers`): one product per transfer, not a Python loop
over tens of blocks (:func:`restrict_reference`, :func:`prolong_reference`
are the blockwise NumPy reference).

Limitation (measured on the Shasta Lake examples and the automatic lake
layouts of ``benchmarks/robust.py``): with strongly varying cell shapes
inside a block the point smoother converges slowly (≈ 0.35 per cycle at
first, 0.5–0.6 later); ``engine="auto"`` then switches to SOR.  Axis classes
that join many blocks rarely all allow coarsening, so the coarsest level of a
lake layout keeps ~40 % of the nodes; and the table kernels cost several
times the single-block smoother per node update.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.sparse as sp

from ..boundary import Borders
from . import _kernels
from .topology import Block, Interface, MultiBlockTopology, Side

__all__ = ["MIN_CELLS", "coarsen", "iterate_fas", "levels"]

#: A block side keeps at least this many cells on the coarsest level.
MIN_CELLS = 2
#: Cells longer than this times their width along an axis: that axis is not coarsened.
SEMI_ASPECT = 1.3
#: Share (node-weighted) of the blocks in an axis class that must want it coarsened
#: (1.0: all of them; a majority vote forced badly stretched blocks to coarsen, measured on
#: the lake: 40 cycles instead of 17).
CLASS_VOTE = 1.0
#: ``engine="auto"`` leaves multigrid for SOR when a cycle reduces the defect by less than
#: this (one cycle costs about as much as 16 single-block SOR sweeps; SOR reduces by ≈ 0.96
#: per sweep on the lake examples, 0.96¹⁶ ≈ 0.5).
AUTO_GIVE_UP_RATE = 0.5
#: Gauss–Seidel sweeps before / after the coarse-grid correction.
PRE, POST = 2, 2
#: Sweeps on the coarsest level: at least COARSEST_SWEEPS, then until the defect fell by
#: COARSEST_REDUCTION, at most COARSEST_MAX_SWEEPS (where the coarsening stops early, e.g. the
#: lake layouts, the coarsest level is large and its SOR does not reach the reduction: 2000
#: sweeps made a cycle cost ~10× more and, on Shasta's automatic layout, diverged; measured).
COARSEST_SWEEPS = 20
COARSEST_REDUCTION = 1e-3
COARSEST_MAX_SWEEPS = 100


_ALONG = {"bottom": 0, "top": 0, "left": 1, "right": 1}


def _factors_ok(topo: MultiBlockTopology, factors: list[tuple[int, int]]) -> bool:
    for b, (ci, cj) in zip(topo.blocks, factors, strict=True):
        ni, nj = b.cells
        if ni % ci or nj % cj or ni // ci < MIN_CELLS or nj // cj < MIN_CELLS:
            return False
    idx = {b.name: k for k, b in enumerate(topo.blocks)}
    for itf in topo.interfaces:
        fa = factors[idx[itf.a.block]][_ALONG[itf.a.border]]
        fb = factors[idx[itf.b.block]][_ALONG[itf.b.border]]
        if fa != fb or any(v % fa for v in (itf.a.start, itf.a.stop, itf.b.start, itf.b.stop)):
            return False
    return True


def coarsen(topo: MultiBlockTopology, factors: list[tuple[int, int]] | None = None) -> MultiBlockTopology | None:
    """Every ``ci``-th / ``cj``-th node of every block (default: every other node), or None.

    ``factors[k] = (ci, cj) ∈ {1, 2}²`` per block; an interface's two sides
    must use the same factor along the shared border, and every count and
    node range must divide.
    """
    if factors is None:
        factors = [(2, 2)] * len(topo.blocks)
    if all(f == (1, 1) for f in factors) or not _factors_ok(topo, factors):
        return None
    blocks = tuple(
        Block(
            b.name,
            Borders(
                bottom=b.borders.bottom[::ci],
                right=b.borders.right[::cj],
                top=b.borders.top[::ci],
                left=b.borders.left[::cj],
            ),
            initial=b.initial,
            weights=b.weights,
            names=b.names,
        )
        for b, (ci, cj) in zip(topo.blocks, factors, strict=True)
    )
    idx = {b.name: k for k, b in enumerate(topo.blocks)}

    def side(sd: Side) -> Side:
        f = factors[idx[sd.block]][_ALONG[sd.border]]
        return Side(sd.block, sd.border, sd.start // f, sd.stop // f)

    itfs = tuple(Interface(side(i.a), side(i.b), i.reversed) for i in topo.interfaces)
    return MultiBlockTopology(blocks, itfs, check_geometry=False)


def _axis_classes(topo: MultiBlockTopology) -> np.ndarray:
    """Class id of each (block, axis): axes glued along an interface must coarsen together."""
    n = len(topo.blocks)
    parent = np.arange(2 * n)

    def find(a: int) -> int:
        while parent[a] != a:
            a = parent[a]
        return int(a)

    idx = {b.name: k for k, b in enumerate(topo.blocks)}
    for itf in topo.interfaces:
        u = find(2 * idx[itf.a.block] + _ALONG[itf.a.border])
        v = find(2 * idx[itf.b.block] + _ALONG[itf.b.border])
        parent[max(u, v)] = min(u, v)
    return np.array([find(k) for k in range(2 * n)])


def plan(topo: MultiBlockTopology, aspect: np.ndarray) -> list[tuple[int, int]] | None:
    """Coarsening factors per block for the next level (semi-coarsening where cells are long).

    ``aspect[k]`` is the typical ``h_ξ / h_η`` of block ``k``.  An axis class is
    coarsened when the cells along it are not clearly longer than across
    (ratio ≤ :data:`SEMI_ASPECT` in every block of the class, see :data:`CLASS_VOTE`) and
    every count and interface range along it is even.
    """
    cls = _axis_classes(topo)
    sizes = np.array([(b.cells[0] + 1) * (b.cells[1] + 1) for b in topo.blocks], dtype=float)
    want = np.zeros(cls.max() + 1)
    total = np.zeros(cls.max() + 1)
    for k in range(len(topo.blocks)):
        for ax in (0, 1):
            r = aspect[k] if ax == 0 else 1.0 / aspect[k]
            total[cls[2 * k + ax]] += sizes[k]
            if r <= SEMI_ASPECT:
                want[cls[2 * k + ax]] += sizes[k]
    chosen = set()
    for c in np.unique(cls):
        if want[c] >= CLASS_VOTE * total[c]:
            trial = [
                (
                    2 if cls[2 * k] == c or cls[2 * k] in chosen else 1,
                    2 if cls[2 * k + 1] == c or cls[2 * k + 1] in chosen else 1,
                )
                for k in range(len(topo.blocks))
            ]
            if _factors_ok(topo, trial):
                chosen.add(int(c))
    factors = [
        (2 if cls[2 * k] in chosen else 1, 2 if cls[2 * k + 1] in chosen else 1) for k in range(len(topo.blocks))
    ]
    if all(f == (1, 1) for f in factors):
        return None
    return factors


@dataclass(slots=True)
class _Level:
    topo: MultiBlockTopology
    args: tuple  # table arguments (nodes, nbr, irr_nodes, irr_ptr, irr_ring)
    n: int
    free: np.ndarray  # bool
    mult: np.ndarray  # in how many blocks each node is
    grids: list  # (x, y) block arrays of the start grid (for metrics)
    factors: list | None = None  # set on the coarse level: (ci, cj) per block from the finer
    inj: np.ndarray | None = None  # coarse node → fine node
    scale: np.ndarray | None = None  # FAS defect scaling per coarse node
    rsum: np.ndarray | None = None  # row sums of Pᵀ (restriction normalisation)
    P: Any = None  # prolongation from this (coarse) level to the finer one (sparse)
    R: Any = None  # restriction D⁻¹ Pᵀ from the finer level to this one (sparse)


def _aspect(grids: list) -> np.ndarray:
    out = []
    for x, y in grids:
        hi = np.hypot(np.diff(x, axis=0), np.diff(y, axis=0))
        hj = np.hypot(np.diff(x, axis=1), np.diff(y, axis=1))
        a = 0.5 * (hi[:, :-1] + hi[:, 1:])
        b = 0.5 * (hj[:-1, :] + hj[1:, :])
        out.append(float(np.median(a / np.maximum(b, 1e-300))))
    return np.array(out)


def _adjoint(F: np.ndarray, ci: int, cj: int) -> np.ndarray:
    """Transpose of the blockwise bilinear prolongation (factors ci, cj)."""
    C = F
    for axis, c in ((0, ci), (1, cj)):
        if c == 2:
            G = np.moveaxis(C, axis, 0)
            H = G[::2].copy()
            H[:-1] += 0.5 * G[1::2]
            H[1:] += 0.5 * G[1::2]
            C = np.moveaxis(H, 0, axis)
    return C


def _interp(E: np.ndarray, ci: int, cj: int) -> np.ndarray:
    """Bilinear prolongation of a coarse block array (factors ci, cj)."""
    F = E
    for axis, c in ((0, ci), (1, cj)):
        if c == 2:
            G = np.moveaxis(F, axis, 0)
            H = np.empty((2 * G.shape[0] - 1, *G.shape[1:]))
            H[::2] = G
            H[1::2] = 0.5 * (G[:-1] + G[1:])
            F = np.moveaxis(H, 0, axis)
    return F


def _interp_1d(n_fine: int, c: int) -> tuple[np.ndarray, np.ndarray]:
    """``(cols, weights)``, each ``(n_fine, 2)``: linear interpolation of every node of a line
    from every ``c``-th node (``c`` = 1: the node itself; a second weight 0)."""
    i = np.arange(n_fine)
    if c == 1:
        return np.stack([i, i], axis=1), np.stack([np.ones(n_fine), np.zeros(n_fine)], axis=1)
    odd = (i % 2).astype(float)
    cols = np.stack([i // 2, np.minimum(i // 2 + 1, (n_fine - 1) // 2)], axis=1)
    return cols, np.stack([1.0 - 0.5 * odd, 0.5 * odd], axis=1)


def _block_interp(shape: tuple[int, int], ci: int, cj: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """COO ``(fine, coarse, weight)`` (local flat indices) of the bilinear interpolation of a block."""
    (ni, nj), ncj = shape, (shape[1] - 1) // cj + 1
    ki, wi = _interp_1d(ni, ci)
    kj, wj = _interp_1d(nj, cj)
    fine = np.broadcast_to(np.arange(ni * nj).reshape(ni, nj, 1, 1), (ni, nj, 2, 2))
    coarse = ki[:, None, :, None] * ncj + kj[None, :, None, :]
    w = wi[:, None, :, None] * wj[None, :, None, :]
    keep = w.ravel() != 0.0
    return fine.ravel()[keep], coarse.ravel()[keep], w.ravel()[keep]


def _transfers(fine: _Level, coarse: _Level) -> tuple[Any, Any, np.ndarray]:
    """``(P, R, rsum)``: blockwise bilinear prolongation and its normalised transpose as sparse
    matrices over the global node arrays (one product per transfer instead of a Python loop over
    the blocks; :func:`_interp` and :func:`_adjoint` are the blockwise reference).

    ``P`` takes a shared fine node's row from the first block that has it (every block that
    has it gives the same row: interface values come from interface values only);
    ``Pᵀ`` sums every block's contribution weighted by ``1/mult`` (a node shared by ``m``
    blocks counts once), ``R = D⁻¹ Pᵀ`` with ``D`` its row sums.
    """
    pr, pc, pv, rr, rc, rv = [], [], [], [], [], []
    seen = np.zeros(fine.n, dtype=bool)
    for gf, gc, (ci, cj) in zip(fine.topo.node_map.ids, coarse.topo.node_map.ids, coarse.factors, strict=True):
        lf, lc, w = _block_interp(gf.shape, ci, cj)
        rows, cols = gf.ravel()[lf], gc.ravel()[lc]
        rr.append(cols)
        rc.append(rows)
        rv.append(w / fine.mult[rows])
        new = ~seen[rows]
        pr.append(rows[new])
        pc.append(cols[new])
        pv.append(w[new])
        seen[gf.ravel()] = True
    P = sp.csr_matrix((np.concatenate(pv), (np.concatenate(pr), np.concatenate(pc))), shape=(fine.n, coarse.n))
    Pt = sp.csr_matrix((np.concatenate(rv), (np.concatenate(rr), np.concatenate(rc))), shape=(coarse.n, fine.n))
    rsum = np.asarray(Pt.sum(axis=1)).ravel()
    R = sp.diags(1.0 / np.where(rsum > 0, rsum, 1.0)) @ Pt
    R = sp.diags(coarse.free.astype(float)) @ R
    P = sp.diags(fine.free.astype(float)) @ P
    return P.tocsr(), R.tocsr(), rsum


def _make_level(t: MultiBlockTopology, grids: list) -> _Level:
    m = t.node_map
    free = np.zeros(m.n_nodes, dtype=bool)
    free[m.nodes] = True
    free[m.irr_nodes] = True
    mult = np.bincount(np.concatenate([g.ravel() for g in m.ids]), minlength=m.n_nodes)
    return _Level(t, (m.nodes, m.nbr, m.irr_nodes, m.irr_ptr, m.irr_ring), m.n_nodes, free, mult.astype(float), grids)


def levels(topo: MultiBlockTopology, max_levels: int = 16, *, semi: bool = True) -> list[_Level]:
    """The multigrid hierarchy (finest first).

    ``semi=True`` chooses per level which axes to coarsen (:func:`plan`);
    ``semi=False`` coarsens both axes of every block while possible.
    """
    from .start import initial_grids

    grids = [(np.asarray(g.x), np.asarray(g.y)) for g in initial_grids(topo)]
    out = [_make_level(topo, grids)]
    aspect = _aspect(grids)
    while len(out) < max_levels:
        t = out[-1].topo
        factors = plan(t, aspect) if semi else [(2, 2)] * len(t.blocks)
        if factors is None:
            break
        tc = coarsen(t, factors)
        if tc is None:
            break
        cgrids = [(x[::ci, ::cj], y[::ci, ::cj]) for (x, y), (ci, cj) in zip(out[-1].grids, factors, strict=True)]
        lv = _make_level(tc, cgrids)
        lv.factors = factors
        out.append(lv)
        aspect = aspect * np.array([ci / cj for ci, cj in factors])
    for fine, coarse in itertools.pairwise(out):
        mf, mc = fine.topo.node_map, coarse.topo.node_map
        inj = np.empty(mc.n_nodes, dtype=np.int64)
        scale = np.zeros(mc.n_nodes)
        for gf, gc, (ci, cj), (x, y) in zip(mf.ids, mc.ids, coarse.factors, fine.grids, strict=True):
            inj[gc.ravel()] = gf[::ci, ::cj].ravel()
            # FAS scaling: A = −N/(2(α+γ)), N ~ (ab)², α → b²α, γ → a²γ
            gx0, gy0 = np.gradient(x, axis=0), np.gradient(y, axis=0)
            gx1, gy1 = np.gradient(x, axis=1), np.gradient(y, axis=1)
            al, ga = gx1**2 + gy1**2, gx0**2 + gy0**2
            a2, b2 = ci * ci, cj * cj
            s = a2 * b2 * (al + ga) / np.maximum(b2 * al + a2 * ga, 1e-300)
            scale[gc.ravel()] = s[::ci, ::cj].ravel()
        coarse.inj = inj
        coarse.scale = scale
        coarse.P, coarse.R, coarse.rsum = _transfers(fine, coarse)
    return out


def restrict_reference(fine: _Level, coarse: _Level, r: np.ndarray) -> np.ndarray:
    """``R r = D⁻¹ Pᵀ r`` block by block (NumPy reference of ``coarse.R``)."""
    acc = np.zeros(coarse.n)
    rsum = np.zeros(coarse.n)
    for gf, gc, (ci, cj) in zip(fine.topo.node_map.ids, coarse.topo.node_map.ids, coarse.factors, strict=True):
        np.add.at(acc, gc.ravel(), _adjoint(r[gf] / fine.mult[gf], ci, cj).ravel())
        np.add.at(rsum, gc.ravel(), _adjoint(1.0 / fine.mult[gf], ci, cj).ravel())
    out = acc / rsum
    out[~coarse.free] = 0.0
    return out


def prolong_reference(fine: _Level, coarse: _Level, e: np.ndarray) -> np.ndarray:
    """Bilinear interpolation of the coarse correction ``e`` block by block (reference of ``coarse.P``)."""
    c = np.zeros(fine.n)
    for gf, gc, (ci, cj) in zip(fine.topo.node_map.ids, coarse.topo.node_map.ids, coarse.factors, strict=True):
        c[gf] = _interp(e[gc], ci, cj)
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
    fcx = -dx + co.scale * (co.R @ rx)
    fcy = -dy + co.scale * (co.R @ ry)
    fcx[~co.free] = 0.0
    fcy[~co.free] = 0.0
    ux, uy = vx.copy(), vy.copy()
    _cycle(lvs, k + 1, ux, uy, fcx, fcy)
    x += co.P @ (ux - vx)
    y += co.P @ (uy - vy)
    for _ in range(POST):
        _kernels.table_sweep_rhs(x, y, fx, fy, *lv.args, 1.0)


def iterate_fas(
    x,
    y,
    topo: MultiBlockTopology,
    tol: float,
    max_cycles: int,
    give_up_rate: float | None = None,
    lvs: list | None = None,
):
    """V-cycles on the global arrays ``x, y`` (in place) until the Jacobi residual ≤ ``tol``.

    A generator: yields ``(cycle, residual)`` after every cycle (send
    ``"stop"`` to stop).  ``give_up_rate``: stop with message ``"slow"`` when,
    from the third cycle on, the defect falls by less than this factor per
    cycle (geometric mean of the last two cycles) — the caller then continues
    with SOR.

    Returns ``(cycles, residual, history, message, n_levels)``.
    """
    lvs = levels(topo) if lvs is None else lvs
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
        if (yield it, r) == "stop":
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
