r"""The levels of the multiblock multigrid (:mod:`.multigrid`): which nodes each level keeps,
its solver tables and the transfers between levels.

A coarse level keeps a subset of the finer level's nodes: in every block the
nodes at the kept *line positions* ``si`` (along ξ) × ``sj`` (along η).  A line
position of one block is glued to positions of other blocks wherever a shared
border node lies on it (the grid line continues across the interface), so the
positions form classes (connected components, :func:`_positions`), and a
class is kept or dropped as a whole: the blocks of a coarse level still meet
node to node.  Kept are the ends of every block line (block corners and
T-junctions) and every position of a line with fewer than ``2 · MIN_CELLS``
cells; then, greedily, every class none of whose neighbours along a line is
dropped (:func:`select`).  A coarse cell therefore spans one or two fine cells
per direction, whatever the cell counts: odd counts and interface ranges
coarsen as well, and the hierarchy goes down to 150–600 nodes, until a level
would keep more than :data:`MAX_KEEP` of the finer one's (the earlier factor-2
coarsening kept ~40 % of the nodes of a lake layout on its coarsest level).
Both directions are coarsened everywhere; stretched cells are the smoother's
business (line relaxation, :mod:`.multigrid`).

Transfers: ``P`` is linear interpolation (in index space) along each block
line, tensor product in a block; a shared node's row comes from interface
nodes only, so every block that holds it gives the same row.  ``R = D⁻¹ Pᵀ``
(each block's contribution weighted by ``1/mult``, normalised by the row
sums).  Both are sparse matrices over the global node arrays;
:func:`restrict_reference` and :func:`prolong_reference` are the blockwise
NumPy reference (dense interpolation matrices from ``np.interp``).

FAS scaling of the restricted defect: in index units ``A = −N/(2(α+γ))`` with
``N → (ab)² N``, ``α → b² α``, ``γ → a² γ`` for local coarsening factors
``a, b`` (the mean length of the two coarse cells at a node, in fine cells:
1, 1.5 or 2), so ``s = (ab)²(α+γ)/(b²α + a²γ)``, evaluated on the start grid.
"""

from __future__ import annotations

import hashlib
import itertools
import threading
from collections import OrderedDict
from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from . import _hier_kernels as _typed_hk
from . import _kernels as _typed_mk
from .nodemap import flat_ids, solver_tables
from .topology import MultiBlockTopology

#: The numba kernels (``Any``: mypy's numba stubs reject some calls).
_hk: Any = _typed_hk
_mk: Any = _typed_mk

__all__ = ["MIN_CELLS", "Level", "hot_rows", "levels", "near_rows", "prolong_reference", "restrict_reference", "select"]

#: A block line keeps at least this many cells (lines with fewer than twice this do not coarsen).
MIN_CELLS = 2
#: Stop coarsening when a level would keep more than this share of the finer level's nodes.
#: The last levels of a lake layout keep 60–80 % (their block lines have few cells left, and
#: the forced block ends and short lines dominate): each cost as much set-up as a level of
#: several thousand nodes (4–6 ms of numpy calls per level) and changed no cycle count.  0.8 → 0.5
#: dropped 1–2 levels on 11 automatic layouts (7 of them generated shapes of
#: :mod:`meshcore.testing`: channel networks, lakes with islands, a spiral, jagged shores) with
#: the same cycle counts (52 → 51 in all), the coarsest level then 150–600 nodes (measured).
MAX_KEEP = 0.5
#: ... or when a level has at most this many nodes (its SOR solve is cheap).
COARSEST_NODES = 150
#: The smoother's extra point sweeps cover the nodes this many stencil steps from the fixed boundary.
BAND_WIDTH = 2

#: Hierarchies kept for re-solves of the same block structure (:func:`levels`).
CACHED = 4
_CACHE: OrderedDict = OrderedDict()
_LOCK = threading.Lock()


@dataclass(slots=True)
class Level:
    """One level: the blocks' global ids, solver tables and (coarse levels) the transfers."""

    ids: tuple[np.ndarray, ...]  # per block, global ids of this level's nodes
    args: tuple  # table arguments (nodes, nbr, irr_nodes, irr_ptr, irr_ring)
    n: int
    free: np.ndarray  # bool
    mult: np.ndarray  # in how many blocks each node is
    lines: tuple  # ((nodes, nbr, ptr, axis) along ξ, along η): block lines, interface ends too (:func:`_line_tables`)
    border: tuple  # table arguments of the free border nodes only
    band: tuple  # table arguments of the regular nodes near the fixed boundary (:func:`_band`)
    sel: tuple = ()  # coarse level: per block (si, sj), the finer block indices kept
    inj: np.ndarray | None = None  # coarse node → fine node
    scale: np.ndarray | None = None  # FAS defect scaling per coarse node
    rsum: np.ndarray | None = None  # row sums of Pᵀ (restriction normalisation)
    P: Any = None  # prolongation from this (coarse) level to the finer one (sparse)
    R: Any = None  # restriction D⁻¹ Pᵀ from the finer level to this one (sparse)
    packed: Any = None  # finest level: {depth: the first depth levels in the flat buffers of the fused cycle}
    flat: tuple = ()  # :func:`.nodemap.flat_ids` of ``ids`` (the kernels' form, built once per level)
    sel_flat: tuple = ()  # coarse level: :func:`_sel_flat` of ``sel``
    reverse: tuple = ()  # (pos, ptr, rows) of :func:`hot_rows`, built at its first call

    @property
    def shapes(self) -> list[tuple[int, int]]:
        """Node counts ``(ni + 1, nj + 1)`` of every block on this level."""
        return [g.shape for g in self.ids]


def _colour_order(ids: tuple[np.ndarray, ...], args: tuple, n_interior: int) -> tuple:
    """The table ``args`` with every block's interior rows in 4-colour order (one compiled call,
    :func:`._hier_kernels.colour_perm`; see :func:`colour_order_reference`)."""
    shape = np.array([g.shape for g in ids], dtype=np.int64).reshape(-1, 2)
    order = _hk.colour_perm(shape, len(args[0]))
    return (np.ascontiguousarray(args[0][order]), np.ascontiguousarray(args[1][order]), *args[2:])


def colour_order_reference(ids: tuple[np.ndarray, ...], args: tuple, n_interior: int) -> tuple:
    """The table ``args`` with every block's interior rows in 4-colour order (the parity of
    ``(i, j)``: even ``i`` before odd, in each row parity odd ``j`` before even, then
    lexicographic), the border rows unchanged.  No two nodes of one colour are in each other's
    9-point stencil, so consecutive updates of a point sweep do not wait for each other (a
    lexicographic sweep is one long chain of dependent divisions: 1.5× slower, measured).
    NumPy reference of :func:`_colour_order`."""
    perm, off = [], 0
    for g in ids:
        if g.shape[0] < 3 or g.shape[1] < 3:
            continue
        idx = off + np.arange((g.shape[0] - 2) * (g.shape[1] - 2)).reshape(g.shape[0] - 2, g.shape[1] - 2)
        off += idx.size  # idx[ii, jj]: node (i, j) = (1 + ii, 1 + jj); even i first, then odd j first
        perm += [idx[1::2, 0::2].ravel(), idx[1::2, 1::2].ravel(), idx[0::2, 0::2].ravel(), idx[0::2, 1::2].ravel()]
    perm.append(np.arange(n_interior, len(args[0])))
    order = np.concatenate(perm)
    return (np.ascontiguousarray(args[0][order]), np.ascontiguousarray(args[1][order]), *args[2:])


def _level(ids: tuple[np.ndarray, ...], n: int, args: tuple, n_interior: int, flat: tuple | None = None) -> Level:
    flat = flat_ids(ids) if flat is None else flat
    args = _colour_order(ids, args, n_interior)
    free = np.zeros(n, dtype=bool)
    free[args[0]] = True
    free[args[2]] = True
    mult = np.bincount(flat[0], minlength=n).astype(float)
    border = (args[0][n_interior:], args[1][n_interior:], *args[2:])
    return Level(ids, args, n, free, mult, _line_tables(ids, args, n), border, _band(args, free), flat=flat)


def _band(args: tuple, free: np.ndarray) -> tuple:
    """Table arguments of the regular nodes at most :data:`BAND_WIDTH` nodes (of the 8-point
    stencil) from a fixed node.  The error that a cycle leaves is largest there (measured on the
    lake layouts: next to shore points where the cells are most distorted), and extra point
    sweeps over this band took the lakes from 8 to 5-6 cycles."""
    return near_rows(args, ~free, BAND_WIDTH)


def near_rows(args: tuple, seed: np.ndarray, width: int) -> tuple:
    """Table arguments (regular rows only, in table order) of the nodes at most ``width`` steps of
    the 8-point stencil from a node where the boolean array ``seed`` holds."""
    nodes, nbr = args[0], args[1]
    sel = _hk.grow_near(nodes, nbr, seed, width)[nodes]
    e = np.zeros(0, dtype=np.int64)
    return (np.ascontiguousarray(nodes[sel]), np.ascontiguousarray(nbr[sel]), e, np.zeros(1, dtype=np.int64), e)


def hot_rows(lv: Level, seeds: np.ndarray, width: int) -> tuple:
    """:func:`near_rows` of the seed nodes ``seeds`` (ids) on level ``lv``, grown outward from them
    (:func:`._kernels.grow_rows`; the reverse table is built at the first call and kept with the
    level): the same rows, for the few nodes round the hot spots of a cycle without a scan of
    the whole table per step (0.41 → 0.05 ms per cycle on a 46 000-node lake, measured)."""
    nodes, nbr = lv.args[0], lv.args[1]
    if not lv.reverse:
        pos = np.full(lv.n, -1, dtype=np.int64)
        pos[nodes] = np.arange(len(nodes))
        lv.reverse = (pos, *_mk.reverse_table(nodes, nbr, lv.n))
    r = _mk.grow_rows(nodes, *lv.reverse, np.asarray(seeds, dtype=np.int64), width)
    e = np.zeros(0, dtype=np.int64)
    return (nodes[r], nbr[r], e, np.zeros(1, dtype=np.int64), e)


def near_reference(args: tuple, seed: np.ndarray, width: int) -> np.ndarray:
    """The nodes :func:`near_rows` grows (boolean over all nodes; NumPy reference of
    :func:`._hier_kernels.grow_near`)."""
    nodes, nbr = args[0], args[1]
    near = seed
    for _ in range(width):
        grown = near.copy()
        grown[nodes[near[nbr].any(axis=1)]] = True
        near = grown
    return near


def _lines(ids: tuple[np.ndarray, ...], nodes: np.ndarray, nbr: np.ndarray, n: int) -> tuple[tuple, tuple]:
    """``(along ξ, along η)``, each ``(rows, lnbr, ptr, axis)``: every interior line of every block
    as table rows, with its end nodes on interfaces, and the rows' stencils in the block's frame,
    one compiled call per direction (:func:`._hier_kernels.block_lines`; see :func:`lines_reference`)."""
    pos = np.full(n, -1, dtype=np.int64)
    pos[nodes] = np.arange(len(nodes))
    flat, off, shape = flat_ids(ids)
    out = []
    for ax in (0, 1):
        rows, lnbr, ptr = _hk.block_lines(flat, off, shape, pos, nbr, ax)
        out.append((rows, lnbr, ptr, np.full(len(ptr) - 1, ax, dtype=np.int64)))
    return out[0], out[1]


def _line_tables(ids: tuple[np.ndarray, ...], args: tuple, n: int) -> tuple[tuple, tuple]:
    """``(along ξ, along η)``, each ``(nodes, nbr, ptr, axis)``: the rows of :func:`_lines`
    gathered in line order, the form :func:`._kernels.line_sweep_rhs` reads in sequence."""
    nodes, nbr = args[0], args[1]
    return tuple(  # type: ignore[return-value]
        (np.ascontiguousarray(nodes[rows]), lnbr, ptr, axis) for rows, lnbr, ptr, axis in _lines(ids, nodes, nbr, n)
    )


def lines_reference(ids: tuple[np.ndarray, ...], nodes: np.ndarray, nbr: np.ndarray, n: int) -> tuple[tuple, tuple]:
    """``(along ξ, along η)``, each ``(rows, lnbr, ptr, axis)``: every line of every block through
    its interior nodes, extended by its two end nodes on the block border when they are free regular
    nodes (on an interface: the node is then relaxed with the line instead of by point sweeps only),
    as table rows, and each row's stencil in the block's frame (``E`` = +i, ``N`` = +j): an interior
    row as the table has it, a border node's row (whose frame the ring of cells gave) turned or
    mirrored so that its neighbours along the block's +i and +j come first.  Python reference of
    :func:`_lines`."""
    pos = np.full(n, -1, dtype=np.int64)
    pos[nodes] = np.arange(len(nodes))
    dirs = [(1, 0), (-1, 0), (0, 1), (0, -1), (1, 1), (-1, 1), (1, -1), (-1, -1)]
    out = []
    for ax in (0, 1):
        rows, lnbr, ptr = [], [], [0]
        for g in ids:
            if g.shape[0] < 3 or g.shape[1] < 3:
                continue
            ni, nj = g.shape
            for s in range(1, (nj if ax == 0 else ni) - 1):
                for t in range(ni if ax == 0 else nj):
                    i, j = (t, s) if ax == 0 else (s, t)
                    r = int(pos[g[i, j]])
                    if r < 0:
                        continue
                    row = [int(v) for v in nbr[r]]
                    if 0 < i < ni - 1 and 0 < j < nj - 1:
                        rows.append(r)
                        lnbr.append(row)
                        continue
                    frame = []  # the row's directions of the block's +i and +j
                    for di, dj in ((1, 0), (0, 1)):
                        ahead = (i + di, j + dj)
                        back = (i - di, j - dj)
                        if ahead[0] < ni and ahead[1] < nj and int(g[ahead]) in row[:4]:
                            frame.append(dirs[row.index(int(g[ahead]))])
                        elif back[0] >= 0 and back[1] >= 0 and int(g[back]) in row[:4]:
                            d = dirs[row.index(int(g[back]))]
                            frame.append((-d[0], -d[1]))
                    if len(frame) < 2 or frame[0][0] * frame[1][0] + frame[0][1] * frame[1][1] != 0:
                        continue
                    (ei, ej), (ni_, nj_) = frame
                    turned = [row[dirs.index((a * ei + b * ni_, a * ej + b * nj_))] for a, b in dirs]
                    rows.append(r)
                    lnbr.append(turned)
                ptr.append(len(rows))
        out.append(
            (
                np.array(rows, dtype=np.int64),
                np.array(lnbr, dtype=np.int64).reshape(-1, 8),
                np.array(ptr, dtype=np.int64),
                np.full(len(ptr) - 1, ax, dtype=np.int64),
            )
        )
    return out[0], out[1]


def _positions(ids: tuple[np.ndarray, ...]) -> tuple[list[np.ndarray], np.ndarray]:
    """``(lines, comp)``: the position elements of every block line (block ``k``: ``lines[2k]``
    along ξ, ``lines[2k + 1]`` along η) and the class of every element (positions holding a
    common border node are one class)."""
    lines, gid, el = [], [], []
    total = 0
    for g in ids:
        ni, nj = g.shape
        ei, ej = total + np.arange(ni), total + ni + np.arange(nj)
        total += ni + nj
        lines += [ei, ej]
        gid += [g[:, 0], g[:, -1], g[0, :], g[-1, :]]
        el += [ei, ei, ej, ej]
    gid_a, el_a = np.concatenate(gid).astype(np.int64), np.concatenate(el).astype(np.int64)
    return lines, _hk.position_classes(el_a, gid_a, total, int(gid_a.max()) + 1)


def positions_reference(ids: tuple[np.ndarray, ...]) -> np.ndarray:
    """The classes of :func:`_positions` as connected components of a graph (reference; the
    numbering may differ)."""
    gid, el = [], []
    total = 0
    for g in ids:
        ni, nj = g.shape
        ei, ej = total + np.arange(ni), total + ni + np.arange(nj)
        total += ni + nj
        gid += [g[:, 0], g[:, -1], g[0, :], g[-1, :]]
        el += [ei, ei, ej, ej]
    gid_a, el_a = np.concatenate(gid), np.concatenate(el)
    n = total + int(gid_a.max()) + 1
    graph = sp.coo_matrix((np.ones(len(el_a), dtype=np.int8), (el_a, total + gid_a)), shape=(n, n))
    return connected_components(graph, directed=False)[1][:total]


def select(ids: tuple[np.ndarray, ...], flat: tuple | None = None) -> list | None:
    """The kept positions ``[(si, sj), ...]`` of every block for the next coarser level, or None
    (see the module docstring; compiled: :func:`._hier_kernels.keep_classes`, reference
    :func:`select_reference`); ``flat``: :func:`.nodemap.flat_ids` of ``ids`` when known."""
    fl, off, shape = flat_ids(ids) if flat is None else flat
    el, gid, line_ptr = _hk.line_elements(fl, off, shape)
    comp = _hk.position_classes(el, gid, int(line_ptr[-1]), int(gid.max()) + 1)
    state = _hk.keep_classes(comp, line_ptr, int(comp.max()) + 1, MIN_CELLS)
    if (state != 2).all():
        return None
    idx = np.flatnonzero(state[comp] != 2)  # kept elements; line L holds line_ptr[L]:line_ptr[L + 1]
    local = idx - line_ptr[np.searchsorted(line_ptr, idx, side="right") - 1]
    cut = np.searchsorted(idx, line_ptr).tolist()
    spans = [local[a:b] for a, b in itertools.pairwise(cut)]
    return list(zip(spans[0::2], spans[1::2], strict=True))


def select_reference(ids: tuple[np.ndarray, ...]) -> list | None:
    """:func:`select` with the classes' neighbours in a scipy matrix (reference of
    :func:`._hier_kernels.keep_classes`)."""
    lines, comp = _positions(ids)
    nc = int(comp.max()) + 1
    forced = np.zeros(nc, dtype=bool)
    cl = [comp[e] for e in lines]
    for c in cl:
        forced[c[[0, -1]]] = True
        if len(c) - 1 < 2 * MIN_CELLS:
            forced[c] = True
        forced[c[1:][c[1:] == c[:-1]]] = True  # a class twice in a row on one line
    a = np.concatenate([c[:-1] for c in cl])
    b = np.concatenate([c[1:] for c in cl])
    adj = sp.csr_matrix((np.ones(2 * len(a)), (np.r_[a, b], np.r_[b, a])), shape=(nc, nc))
    state = np.where(forced, 1, 0).astype(np.int64)  # 0 undecided, 1 kept, 2 dropped
    line_ptr = np.concatenate([[0], np.cumsum([len(c) for c in cl])]).astype(np.int64)
    _hk.greedy_drop(np.concatenate(cl).astype(np.int64), line_ptr, adj.indptr.astype(np.int64),
                    adj.indices.astype(np.int64), state)  # fmt: skip
    kept = state != 2
    if kept.all():
        return None
    return [(np.flatnonzero(kept[cl[2 * k]]), np.flatnonzero(kept[cl[2 * k + 1]])) for k in range(len(ids))]


def greedy_reference(cl: list[np.ndarray], adj: Any, state: np.ndarray) -> None:
    """The greedy choice of :func:`select` in Python (reference of :func:`._hier_kernels.greedy_drop`)."""
    ptr, nbr = adj.indptr.tolist(), adj.indices.tolist()
    for c in cl:
        for q in c[1:-1].tolist():
            if state[q] == 0:
                state[q] = 1 if any(state[v] == 2 for v in nbr[ptr[q] : ptr[q + 1]]) else 2


def _interp_1d(n_fine: int, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(cols, weights)``, each ``(n_fine, 2)``: linear interpolation of every position of a line
    from the kept positions ``s`` (a kept position: itself with weight 1, a second weight 0)."""
    i = np.arange(n_fine)
    k = np.searchsorted(s, i, side="right") - 1
    k1 = np.minimum(k + 1, len(s) - 1)
    span = np.maximum(s[k1] - s[k], 1)
    t = np.where(s[k] == i, 0.0, (i - s[k]) / span)
    return np.stack([k, k1], axis=1), np.stack([1.0 - t, t], axis=1)


def _block_interp(shape: tuple[int, int], si: np.ndarray, sj: np.ndarray) -> tuple:
    """COO ``(fine, coarse, weight)`` (local flat indices) of the interpolation of a block."""
    ni, nj = shape
    ki, wi = _interp_1d(ni, si)
    kj, wj = _interp_1d(nj, sj)
    fine = np.broadcast_to(np.arange(ni * nj).reshape(ni, nj, 1, 1), (ni, nj, 2, 2))
    coarse = ki[:, None, :, None] * len(sj) + kj[None, :, None, :]
    w = wi[:, None, :, None] * wj[None, :, None, :]
    keep = w.ravel() != 0.0
    return fine.ravel()[keep], coarse.ravel()[keep], w.ravel()[keep]


def _offsets(parts: list) -> np.ndarray:
    """``[0, len(parts[0]), len(parts[0]) + len(parts[1]), …]`` (int64)."""
    off = np.zeros(len(parts) + 1, dtype=np.int64)
    np.cumsum([len(p) for p in parts], out=off[1:])
    return off


def _sel_flat(sel: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``(si, si_off, sj, sj_off)``: the kept positions of every block in one array per direction
    (block ``b``'s at ``si[si_off[b]:si_off[b + 1]]``), as the kernels take them."""
    si, sj = [s[0] for s in sel], [s[1] for s in sel]
    return np.concatenate(si).astype(np.int64), _offsets(si), np.concatenate(sj).astype(np.int64), _offsets(sj)


def _interp_coo(fine: Level, coarse: Level) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """COO ``(rows, cols, vals)`` of the prolongation, every block's entries weighted by ``1/mult``
    (:func:`._hier_kernels.interp_coo`)."""
    sel = coarse.sel_flat or _sel_flat(coarse.sel)
    return _hk.interp_coo(*fine.flat, coarse.flat[0], coarse.flat[1], *sel, fine.mult)


def _transfers(fine: Level, coarse: Level) -> tuple[Any, Any, np.ndarray]:
    """``(P, R, rsum)`` over the global node arrays (see the module docstring).

    Every block that holds a shared fine node gives it the same row (interface values come from
    interface values only), so summing each block's rows weighted by ``1/mult`` gives that row
    once: ``P``; the restriction is its transpose normalised by the row sums.  The sparse
    matrices are assembled in one compiled call (:func:`._hier_kernels.transfer_csr`; reference
    :func:`transfers_reference`).
    """
    r, c, v = _interp_coo(fine, coarse)
    pp, pi, pv, rp, ri, rv, rsum = _hk.transfer_csr(r, c, v, fine.n, coarse.n, fine.free, coarse.free)
    P = sp.csr_matrix((pv, pi, pp), shape=(fine.n, coarse.n))
    R = sp.csr_matrix((rv, ri, rp), shape=(coarse.n, fine.n))
    return P, R, rsum


def transfers_reference(fine: Level, coarse: Level) -> tuple[Any, Any, np.ndarray]:
    """:func:`_transfers` with scipy's sparse conversions (reference of
    :func:`._hier_kernels.transfer_csr`).

    Every block that holds a shared fine node gives it the same row (interface values come from
    interface values only), so summing each block's rows weighted by ``1/mult`` gives that row
    once: ``P``; the restriction is its transpose normalised by the row sums.
    """
    r, c, v = _interp_coo(fine, coarse)
    P = sp.csr_matrix((v, (r, c)), shape=(fine.n, coarse.n))
    Pt = P.T.tocsr()
    rsum = np.asarray(Pt.sum(axis=1)).ravel()
    Pt.data *= np.repeat(coarse.free / np.where(rsum > 0, rsum, 1.0), np.diff(Pt.indptr))
    P.data *= np.repeat(fine.free.astype(float), np.diff(P.indptr))
    Pt.eliminate_zeros()
    P.eliminate_zeros()
    return P, Pt, rsum


def _scale(coarse: Level) -> np.ndarray:
    """FAS scaling of the restricted defect per coarse node (module docstring; α = γ), one
    compiled call (:func:`._hier_kernels.fas_scale`; reference :func:`scale_reference`)."""
    return _hk.fas_scale(coarse.flat[0], coarse.flat[1], *(coarse.sel_flat or _sel_flat(coarse.sel)), coarse.n)


def scale_reference(coarse: Level) -> np.ndarray:
    """FAS scaling of the restricted defect per coarse node, block by block (reference of :func:`_scale`)."""
    scale = np.zeros(coarse.n)
    for gc, (si, sj) in zip(coarse.ids, coarse.sel, strict=True):
        a2 = _gradient(si)[:, None] ** 2
        b2 = _gradient(sj)[None, :] ** 2
        scale[gc] = 2.0 * a2 * b2 / (a2 + b2)
    return scale


def _gradient(s: np.ndarray) -> np.ndarray:
    """``np.gradient`` of the kept positions ``s`` (one-sided at the ends; 1 for a single one)."""
    s = s.astype(float)
    if len(s) < 2:
        return np.ones(len(s))
    g = np.empty(len(s))
    g[1:-1] = (s[2:] - s[:-2]) / 2.0
    g[0] = s[1] - s[0]
    g[-1] = s[-1] - s[-2]
    return g


def _coarser(lv: Level) -> Level | None:
    """The next coarser level of ``lv``, or None when it would not pay."""
    sel = select(lv.ids, lv.flat)
    if sel is None:
        return None
    si, sj = [s[0] for s in sel], [s[1] for s in sel]
    sel_flat = _sel_flat(sel)
    si_off, sj_off = sel_flat[1], sel_flat[3]
    kept = _hk.gather_kept(*lv.flat, *sel_flat)
    inj, inv = np.unique(kept, return_inverse=True)  # kept: g[np.ix_(si, sj)] of every block
    if len(inj) > MAX_KEEP * lv.n:
        return None
    inv = inv.astype(np.int64, copy=False)
    cut = np.concatenate([[0], np.cumsum(np.diff(si_off) * np.diff(sj_off))])
    ids = tuple(inv[a:b].reshape(len(i), len(j)) for a, b, i, j in zip(cut[:-1], cut[1:], si, sj, strict=True))
    flat = flat_ids(ids)
    args, n_interior = solver_tables(ids, len(inj), flat)
    co = _level(ids, len(inj), args, n_interior, flat)
    co.sel, co.sel_flat, co.inj = tuple(sel), sel_flat, inj.astype(np.int64)
    co.scale = _scale(co)
    co.P, co.R, co.rsum = _transfers(lv, co)
    return co


def levels(topo: MultiBlockTopology, max_levels: int = 16) -> list[Level]:
    """The multigrid hierarchy of ``topo`` (finest first).

    It depends on the block structure only (node counts and interfaces, not on
    coordinates), so it is kept for the last :data:`CACHED` structures: a re-solve
    after a corner drag or a changed shore reuses it.
    """
    m = topo.node_map
    h = hashlib.blake2b(digest_size=16)
    for a in m.ids:  # the node map's tables are a function of the blocks' global ids
        h.update(np.ascontiguousarray(a).tobytes())
        h.update(repr(a.shape).encode())
    key = (h.hexdigest(), max_levels)
    with _LOCK:
        hit = _CACHE.get(key)
        if hit is not None:
            _CACHE.move_to_end(key)
            return list(hit)
    args = (m.nodes, m.nbr, m.irr_nodes, m.irr_ptr, m.irr_ring)
    out = [_level(m.ids, m.n_nodes, args, m.n_interior)]
    while len(out) < max_levels and out[-1].n > COARSEST_NODES:
        co = _coarser(out[-1])
        if co is None:
            break
        out.append(co)
    with _LOCK:
        _CACHE[key] = tuple(out)
        while len(_CACHE) > CACHED:
            _CACHE.popitem(last=False)
    return out


def _interp_matrix(n: int, s: np.ndarray) -> np.ndarray:
    """Dense ``(n, len(s))`` linear interpolation from the kept positions ``s`` (reference)."""
    return np.column_stack([np.interp(np.arange(n), s, np.eye(len(s))[c]) for c in range(len(s))])


def restrict_reference(fine: Level, coarse: Level, r: np.ndarray) -> np.ndarray:
    """``R r = D⁻¹ Pᵀ r`` block by block (NumPy reference of ``coarse.R``)."""
    acc = np.zeros(coarse.n)
    rsum = np.zeros(coarse.n)
    for gf, gc, (si, sj) in zip(fine.ids, coarse.ids, coarse.sel, strict=True):
        wi, wj = _interp_matrix(gf.shape[0], si), _interp_matrix(gf.shape[1], sj)
        np.add.at(acc, gc.ravel(), (wi.T @ (r[gf] / fine.mult[gf]) @ wj).ravel())
        np.add.at(rsum, gc.ravel(), (wi.T @ (1.0 / fine.mult[gf]) @ wj).ravel())
    out = acc / rsum
    out[~coarse.free] = 0.0
    return out


def prolong_reference(fine: Level, coarse: Level, e: np.ndarray) -> np.ndarray:
    """Interpolation of the coarse correction ``e`` block by block (reference of ``coarse.P``)."""
    c = np.zeros(fine.n)
    for gf, gc, (si, sj) in zip(fine.ids, coarse.ids, coarse.sel, strict=True):
        wi, wj = _interp_matrix(gf.shape[0], si), _interp_matrix(gf.shape[1], sj)
        c[gf] = wi @ e[gc] @ wj.T
    c[~fine.free] = 0.0
    return c
