r"""Grid sequencing: solve on a coarse copy of the layout, refine, solve again.

The orthogonal smoother is a Gauss–Seidel iteration: it removes local errors in a few sweeps
but needs thousands to move nodes along a 30-km shore.  Those slow, smooth errors are
resolved cheaply on a coarse grid — the same blocks with half (or a quarter of) the cells —
and carried to the fine grid by :func:`refine`, where a few sweeps remove what the
interpolation left.  Cell counts must be multiples of ``2**levels`` (the layout's integer
program arranges that).
"""

from __future__ import annotations

import numpy as np

from ..multiblock.topology import Block, Interface, MultiBlockTopology, Side
from .shore import arc_lengths, project_to_rings, ring_point

__all__ = ["coarsen_topology", "fit_bends", "fit_ends", "refine", "refine_shore"]


def _refine_grid(x: np.ndarray) -> np.ndarray:
    """Bilinear refinement in index space: ``(n+1, m+1)`` nodes → ``(2n+1, 2m+1)``."""
    n, m = x.shape
    out = np.empty((2 * n - 1, 2 * m - 1))
    out[::2, ::2] = x
    out[1::2, ::2] = 0.5 * (x[:-1] + x[1:])
    out[::2, 1::2] = 0.5 * (x[:, :-1] + x[:, 1:])
    out[1::2, 1::2] = 0.25 * (x[:-1, :-1] + x[1:, :-1] + x[:-1, 1:] + x[1:, 1:])
    return out


def refine(grids) -> list:
    """Every block grid refined twice in each direction (interface nodes stay shared:
    the midpoint of a shared edge is computed the same way from either side)."""
    return [g.replaced(x=_refine_grid(g.x), y=_refine_grid(g.y)) for g in grids]


def coarsen_topology(topology: MultiBlockTopology, factor: int) -> MultiBlockTopology:
    """The topology with every block's borders sub-sampled by ``factor`` (cells divisible by it)."""
    blocks = []
    for b in topology.blocks:
        ni, nj = b.cells
        if ni % factor or nj % factor:
            raise ValueError(f"block {b.name!r}: cells {ni}×{nj} are not multiples of {factor}")
        bd = b.borders
        sub = type(bd)(
            bottom=bd.bottom[::factor].copy(),
            right=bd.right[::factor].copy(),
            top=bd.top[::factor].copy(),
            left=bd.left[::factor].copy(),
        )
        blocks.append(Block(b.name, sub, initial=b.initial, weights=b.weights, names=dict(b.names)))
    itfs = []
    for itf in topology.interfaces:
        sides = []
        for s in (itf.a, itf.b):
            if s.start % factor or s.stop % factor:
                raise ValueError(f"interface side {s.label} is not a multiple of {factor}")
            sides.append(Side(s.block, s.border, s.start // factor, s.stop // factor))
        itfs.append(Interface(sides[0], sides[1], itf.reversed))
    return MultiBlockTopology(tuple(blocks), tuple(itfs), check_geometry=False)


def refine_shore(grids, topology: MultiBlockTopology, rings: list[np.ndarray]) -> list:
    """After :func:`refine`, put every new shore node on the shore, halfway along it between
    its two neighbours (the straight midpoint would cut across every bay the coarse edge
    spanned, and the nearest shore point would be at its mouth); where that alone would make a
    cell non-convex, with the new nodes inwards of it carried along (:func:`_carried_to`)."""
    if not rings:
        return list(grids)
    m = topology.node_map
    per = [float(np.hypot(*(np.roll(r, -1, axis=0) - r).T).sum()) for r in rings]
    xs = [np.array(g.x) for g in grids]
    ys = [np.array(g.y) for g in grids]
    where, ends = [], []  # (block, index of the new node, its column inwards), its two neighbours
    for b, ids in enumerate(m.ids):
        n1, m1 = ids.shape
        for fixed_i, fixed_j in ((None, 0), (None, m1 - 1), (0, None), (n1 - 1, None)):
            side = (slice(None), fixed_j) if fixed_i is None else (fixed_i, slice(None))
            on = m.boundary[ids[side]]
            ks = np.arange(1, len(on) - 1, 2)
            ks = ks[on[ks - 1] & on[ks] & on[ks + 1]]  # the new node and both neighbours on the shore
            for k in ks.tolist():
                ij = (k, fixed_j) if fixed_i is None else (fixed_i, k)
                where.append((b, ij, _column(ids.shape, ij, fixed_i, fixed_j)))
            sx, sy = xs[b][side], ys[b][side]
            ends.append(np.column_stack([sx[ks - 1], sy[ks - 1], sx[ks + 1], sy[ks + 1]]))
    if not where:
        return list(grids)
    ends_a = np.concatenate(ends)
    n = len(ends_a)
    r12, s12, _ = project_to_rings(rings, np.vstack([ends_a[:, :2], ends_a[:, 2:]]))  # one tree for both ends
    ra, sa, rb, sb = r12[:n], s12[:n], r12[n:], s12[n:]
    # halfway along the shore, else elsewhere on the shore between the two (a sharp bend of the
    # shore between them can leave no convex cell at halfway), each with the new nodes inwards
    # of it carried along, else towards halfway: every candidate point of one ring at once
    fractions = np.array([0.5, 0.35, 0.65, 0.2, 0.8, 0.1, 0.9])
    cands = np.full((n, len(fractions), 2), np.nan)
    for r in np.unique(ra):
        sel = np.flatnonzero((ra == r) & (rb == r))
        if not len(sel):
            continue
        total = per[r]
        d = (sb[sel] - sa[sel]) % total
        d = np.where(d > total / 2, d - total, d)  # the short way round
        cands[sel] = ring_point(
            rings[r], (sa[sel, None] + d[:, None] * fractions).ravel(), arc_lengths(rings[r])
        ).reshape(len(sel), len(fractions), 2)
    for (b, ij, col), r1, r2, at in zip(where, ra, rb, cands, strict=True):
        if r1 != r2:
            continue
        if not any(_moved_to(xs[b], ys[b], ij, p) for p in at) and not any(
            _carried_to(xs[b], ys[b], ij, col, p) for p in at
        ):
            _move_if_valid(xs[b], ys[b], ij, at[0])
    return [g.replaced(x=x, y=y) for g, x, y in zip(grids, xs, ys, strict=True)]


def _convex_around(x: np.ndarray, y: np.ndarray, ij) -> bool:
    """True when every cell of the block that has node ``ij`` as a corner is convex."""
    i, j = ij
    n1, m1 = x.shape
    for ci in (i - 1, i):
        for cj in (j - 1, j):
            if not (0 <= ci < n1 - 1 and 0 <= cj < m1 - 1):
                continue
            px = [x[ci, cj], x[ci + 1, cj], x[ci + 1, cj + 1], x[ci, cj + 1]]
            py = [y[ci, cj], y[ci + 1, cj], y[ci + 1, cj + 1], y[ci, cj + 1]]
            for k in range(4):
                ax, ay = px[(k + 1) % 4] - px[k], py[(k + 1) % 4] - py[k]
                bx, by = px[(k + 3) % 4] - px[k], py[(k + 3) % 4] - py[k]
                if ax * by - ay * bx <= 0.0:
                    return False
    return True


def _moved_to(x: np.ndarray, y: np.ndarray, ij, p: np.ndarray) -> bool:
    """Move node ``ij`` to ``p`` if its cells stay convex there; True if it moved."""
    ox, oy = x[ij], y[ij]
    x[ij], y[ij] = p[0], p[1]
    if _convex_around(x, y, ij):
        return True
    x[ij], y[ij] = ox, oy
    return False


#: New nodes inwards of a new shore node that :func:`_carried_to` moves with it: the new
#: nodes of the coarse cell whose edge cut across the shore and of the next one (measured only
#: at this value, on generated lakes with islands: ``tests/meshcore/test_shore_fit.py``).
CARRY = 3


def _column(shape: tuple[int, int], ij, fixed_i, fixed_j) -> list[tuple[int, int]]:
    """Up to :data:`CARRY` nodes inwards of the new shore node ``ij`` along its grid line, short of
    the block's other borders (the line of a new node holds new nodes only: they were interpolated,
    not solved, and no other block shares them)."""
    n1, m1 = shape
    i, j = ij
    if fixed_i is None:
        step = 1 if fixed_j == 0 else -1
        return [(i, j + step * t) for t in range(1, CARRY + 1) if 0 < j + step * t < m1 - 1]
    step = 1 if fixed_i == 0 else -1
    return [(i + step * t, j) for t in range(1, CARRY + 1) if 0 < i + step * t < n1 - 1]


def _carried_to(x: np.ndarray, y: np.ndarray, ij, col: list, p: np.ndarray) -> bool:
    """Move node ``ij`` to ``p`` and the ``k`` nodes ``col`` inwards of it by a share of the same
    move that falls off along the line (``1 - t / (k + 1)`` for the ``t``-th); True if every
    cell around them stays convex, else nothing moves.  Where the coarse edge cut across a bulge of the shore the row
    inside is closer to the shore than the move, and moving the shore node alone folds a cell."""
    ox, oy = x[ij], y[ij]
    dx, dy = p[0] - ox, p[1] - oy
    nodes = [ij, *col]
    old = [(x[n], y[n]) for n in nodes]
    for t, n in enumerate(nodes):
        w = 1.0 - t / len(nodes)
        x[n], y[n] = old[t][0] + w * dx, old[t][1] + w * dy
    if all(_convex_around(x, y, n) for n in nodes):
        return True
    for n, (a, c) in zip(nodes, old, strict=True):
        x[n], y[n] = a, c
    return False


#: Radii (index steps) of the patches of a block's interior nodes that :func:`_patched_to` moves with
#: a shore node, smallest first.
PATCH_RADII = (2, 3, 5, 8)


def _patch(shape: tuple[int, int], ij, r: int):
    """``(i, j, w)``: the block's interior nodes within an index distance ``r`` of ``ij`` and the
    share ``1 - d / (r + 1)`` of a move of ``ij`` each takes along."""
    n1, m1 = shape
    i, j = ij
    ii, jj = np.meshgrid(
        np.arange(max(1, i - r), min(n1 - 1, i + r + 1)),
        np.arange(max(1, j - r), min(m1 - 1, j + r + 1)),
        indexing="ij",
    )
    d = np.hypot(ii - i, jj - j)
    keep = d < r + 1
    return ii[keep], jj[keep], 1.0 - d[keep] / (r + 1)


def _patched_to(x: np.ndarray, y: np.ndarray, ij, p: np.ndarray) -> bool:
    """Move node ``ij`` (on a block side) to ``p`` with the patch of :func:`_patch` of the smallest
    radius of :data:`PATCH_RADII` that leaves every cell around them convex; True if it moved, else
    nothing moves.  Where the node must go a cell or more out to a sharp tip of land its own grid
    line points at, the nodes of that line alone (:func:`_carried_to`) cross their neighbours: the
    patch takes the cells beside them along."""
    ox, oy = x[ij], y[ij]
    dx, dy = p[0] - ox, p[1] - oy
    for r in PATCH_RADII:
        ii, jj, w = _patch(x.shape, ij, r)
        old_x, old_y = x[ii, jj].copy(), y[ii, jj].copy()
        x[ii, jj] += w * dx
        y[ii, jj] += w * dy
        x[ij], y[ij] = p[0], p[1]
        if all(_convex_around(x, y, n) for n in [ij, *zip(ii.tolist(), jj.tolist(), strict=True)]):
            return True
        x[ii, jj], y[ii, jj] = old_x, old_y
        x[ij], y[ij] = ox, oy
    return False


#: Radii of the patches :func:`_repaired_to` tries, smallest first: the largest of
#: :data:`PATCH_RADII`, then half as far again each time.  Where the solve laid several rows of a
#: block side over a land tip, squeezed to a few hundredths of a cell, the rows that must move
#: with the node run eight or more cells along the side (``channel_network(158204, …,
#: roughness=0.15)`` at 15 000 cells: the patch of radius 8 leaves cells folded, 12 none).
REPAIR_RADII = (PATCH_RADII[-1], 12, 18)


def _repaired_to(x: np.ndarray, y: np.ndarray, ij, p: np.ndarray) -> bool:
    """Move node ``ij`` (on a block side) to ``p`` with a patch of :func:`_patch` of a radius of
    :data:`REPAIR_RADII`, then let the fold-free repair (:func:`meshcore.foldfree.repair`) move the
    interior nodes of that patch's window (its edges fixed: the repair of the whole block, whose
    patches grow until they are the block, reshaped blocks far from the tip; ``headlands(763605)``:
    65 -> 44 % of nodes within 3°) round the cells the move leaves non-convex; True for the first
    radius after which no cell of the block is non-convex that was not before, else nothing moves.
    Along a side that passes a sharp tip the solve squeezes the rows next to the shore to a sliver:
    even the patch leaves the row inwards of the node short of the tip
    (``channel_network(263005)``: the grid's edge 1.0 cells from it)."""
    return any(_repaired_once(x, y, ij, p, r) for r in REPAIR_RADII)


def _repaired_once(x: np.ndarray, y: np.ndarray, ij, p: np.ndarray, radius: int) -> bool:
    """:func:`_repaired_to` with the patch of one ``radius``."""
    from ..foldfree import invalid_cells, repair
    from ..grid import StructuredGrid

    before = invalid_cells(x, y)
    ox, oy = x.copy(), y.copy()
    ii, jj, w = _patch(x.shape, ij, radius)
    x[ii, jj] += w * (p[0] - ox[ij])
    y[ii, jj] += w * (p[1] - oy[ij])
    x[ij], y[ij] = p[0], p[1]
    if invalid_cells(x, y).any():  # repaired within the patch's window only, its edges fixed
        r = radius + 1
        win = (slice(max(0, ij[0] - r), ij[0] + r + 1), slice(max(0, ij[1] - r), ij[1] + r + 1))
        res = repair(StructuredGrid(x[win].copy(), y[win].copy()), strict=False)
        x[win], y[win] = res.grid.x, res.grid.y
    if not (invalid_cells(x, y) & ~before).any():
        return True
    x[...], y[...] = ox, oy
    return False


def _move_if_valid(x: np.ndarray, y: np.ndarray, ij, p: np.ndarray) -> None:
    """Move node ``ij`` to ``p``, or as far towards it as keeps its cells convex."""
    ox, oy = x[ij], y[ij]
    for f in (1.0, 0.5, 0.25):
        x[ij], y[ij] = ox + f * (p[0] - ox), oy + f * (p[1] - oy)
        if _convex_around(x, y, ij):
            return
    x[ij], y[ij] = ox, oy


def _arc(cum: np.ndarray, s1: float, d: float) -> np.ndarray:
    """Indices of the ring's vertices strictly inside the arc from ``s1`` over ``d`` (either
    sign) of a ring with :func:`~.shore.arc_lengths` ``cum``, in order along it."""
    total, v = cum[-1], cum[:-1]
    a = (s1 if d >= 0 else s1 + d) % total
    b = a + abs(d)
    i0 = int(np.searchsorted(v, a, side="right"))
    if b <= total:
        idx = np.arange(i0, int(np.searchsorted(v, b, side="left")))
    else:
        idx = np.concatenate([np.arange(i0, len(v)), np.arange(int(np.searchsorted(v, b - total, side="left")))])
    return idx if d >= 0 else idx[::-1]


def _chord_gaps(pts: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance of each row of ``pts`` from the segment ``a``–``b``."""
    ab = b - a
    L2 = float(ab @ ab)
    t = np.clip((pts - a) @ ab / L2, 0.0, 1.0) if L2 > 0 else np.zeros(len(pts))
    return np.hypot(*(pts - a - t[:, None] * ab).T)


def _best_on_arc(ring: np.ndarray, cum: np.ndarray, sp: float, d: float, p: np.ndarray, q: np.ndarray):
    """``(best, s, point)`` for a shore node between shore neighbours ``p`` (at arc length ``sp``)
    and ``q`` (``d`` further along): over the ring's vertices on that arc as places for the node,
    the least of the largest distances of the shore from the node's two edges (``best``), with
    that vertex's arc length and point; ``(inf, None, None)`` when the arc holds no vertex."""
    idx = _arc(cum, sp, d)
    if len(idx) < 1:
        return np.inf, None, None
    pts = ring[idx]
    n = len(idx)
    g1 = np.zeros(n)
    g2 = np.zeros(n)
    for j in range(n):  # the node at vertex j: the vertices before it against edge p-j, after against j-q
        g1[j] = _chord_gaps(pts[:j], p, pts[j]).max() if j else 0.0
        g2[j] = _chord_gaps(pts[j + 1 :], pts[j], q).max() if j < n - 1 else 0.0
    worst = np.maximum(g1, g2)
    j = int(np.argmin(worst))
    return float(worst[j]), float(cum[idx[j]]), pts[j]


def _better(ring: np.ndarray, cum: np.ndarray, s3: np.ndarray, trio: np.ndarray, limit: float):
    """``(point, s)``: where on the shore to put the middle one of three consecutive shore nodes
    (``trio``, at arc lengths ``s3`` of ``ring``) whose two edges leave the shore between the
    outer two more than ``limit`` away, if a vertex of the ring there is better: its edges within
    ``limit`` of the shore, or at least half as far as now; else ``(None, None)``."""
    total = cum[-1]
    d = (s3[2] - s3[0]) % total
    if d > total / 2:  # the short way round
        d -= total
    inside = _arc(cum, s3[0], d)
    t = (cum[inside] - s3[0]) % total if d >= 0 else (s3[0] - cum[inside]) % total
    t1 = (s3[1] - s3[0]) % total if d >= 0 else (s3[0] - s3[1]) % total
    if not 0.0 < t1 < abs(d):  # the short way between the outer two does not pass the middle one
        return None, None
    side1, side2 = ring[inside[t < t1]], ring[inside[t > t1]]
    now = max(
        _chord_gaps(side1, trio[0], trio[1]).max() if len(side1) else 0.0,
        _chord_gaps(side2, trio[1], trio[2]).max() if len(side2) else 0.0,
    )
    if now <= limit:
        return None, None
    best, sb, at = _best_on_arc(ring, cum, s3[0], d, trio[0], trio[2])
    if at is None or not (best < limit or best <= 0.5 * now):
        return None, None
    return at, sb


def fit_bends(grids, topology: MultiBlockTopology, rings: list[np.ndarray], limit: float) -> tuple[list, int]:
    """``(grids, moved)``: every free shore node (on a block's side, in one block only) whose two
    shore edges leave the shore between its neighbours more than ``limit`` away — the grid cuts off
    a headland, an island's tip or the bend next to a cut end — moved to the ring vertex between its
    neighbours where the larger of the two distances is least, if that is below ``limit`` or at most
    half the distance now, and the cells around it stay convex (alone, or with the nodes inwards of it
    carried along as :func:`refine_shore` does).

    The orthogonal smoother's shore sweep lets a node slide only where its edges stay within its
    ``shore_gap`` of the shore, or come no further from it: it keeps a shore it follows, but does not
    reach for a bend its edges already cut across (the start grid's coarse edges, the midpoints the
    refinement put on the arc between two nodes, a cut end the layout put short of a tip)."""
    if not rings:
        return list(grids), 0
    m = topology.node_map
    cums = [arc_lengths(r) for r in rings]
    xs = [np.array(g.x) for g in grids]
    ys = [np.array(g.y) for g in grids]
    moved = 0
    sides = []  # (block, its side's nodes, which of them are on the shore, where they start in pts)
    pts: list[np.ndarray] = []
    at0 = 0
    for b, ids in enumerate(m.ids):
        n1, m1 = ids.shape
        for fixed_i, fixed_j in ((None, 0), (None, m1 - 1), (0, None), (n1 - 1, None)):
            side = (slice(None), fixed_j) if fixed_i is None else (fixed_i, slice(None))
            on = m.boundary[ids[side]]
            if on.sum() >= 3:
                count = len(on)
                sides.append((b, fixed_i, fixed_j, count, on, at0))
                pts.append(np.column_stack([xs[b][side], ys[b][side]]))
                at0 += count
    if not sides:
        return list(grids), 0
    pts_a = np.concatenate(pts)
    ring_all, s_all, _ = project_to_rings(rings, pts_a)  # one tree for every side
    per = np.array([c[-1] for c in cums])
    for b, fixed_i, fixed_j, count, on, at0 in sides:
        ids = m.ids[b]
        r_of, s_of = ring_all[at0 : at0 + count], s_all[at0 : at0 + count]
        # a shore arc of length L between two points c apart strays at most sqrt(L² - c²) / 2
        # from their chord: only edges that could stray more than ``limit`` are looked at
        total = per[r_of[:-1]]
        arc = np.abs((s_of[1:] - s_of[:-1] + 0.5 * total) % total - 0.5 * total)
        chord = np.hypot(*np.diff(pts_a[at0 : at0 + count], axis=0).T)
        far = 0.5 * np.sqrt(np.maximum(arc**2 - chord**2, 0.0)) > limit
        line = [(t, fixed_j) if fixed_i is None else (fixed_i, t) for t in range(count)]
        for k in range(1, count - 1):
            if not (far[k - 1] or far[k]):
                continue
            ij = line[k]
            r = int(r_of[k])
            if not (on[k - 1] and on[k] and on[k + 1]) or m.shared[ids[ij]] or r_of[k - 1] != r or r_of[k + 1] != r:
                continue
            trio = np.array([[xs[b][line[t]], ys[b][line[t]]] for t in (k - 1, k, k + 1)])
            at, sb = _better(rings[r], cums[r], s_of[k - 1 : k + 2], trio, limit)
            if at is None:
                continue
            col = _column(ids.shape, ij, fixed_i, fixed_j)
            if (
                _moved_to(xs[b], ys[b], ij, at)
                or _carried_to(xs[b], ys[b], ij, col, at)
                or _patched_to(xs[b], ys[b], ij, at)
                or _repaired_to(xs[b], ys[b], ij, at)
            ):
                s_of[k] = sb
                moved += 1
    return [g.replaced(x=x, y=y) for g, x, y in zip(grids, xs, ys, strict=True)], moved


#: The least turning (degrees) of the shore within half a finest cell of the place a block corner
#: with both sides on the shore (one cell there) is moved to by :func:`fit_ends`: on a straighter
#: place its finest corner cell is a triangle (``estuary(8)`` at 4 000 cells: a corner beside a
#: notch went past it onto a straight edge).  Summed over the ring's vertices there, for a ring
#: densified finer than a cell turns only at its own vertices.
CORNER_TURN = 20.0


def _turning_near(ring: np.ndarray, cum: np.ndarray, at: np.ndarray, reach: float) -> float:
    """The turning (degrees) of closed ``ring`` summed over its vertices within ``reach`` (arc
    length) of its vertex nearest ``at``; ``cum`` its :func:`arc_lengths`."""
    from ..layout.corners import raw_turning

    j = int(np.argmin(np.hypot(*(ring - at).T)))
    d = np.abs(cum[:-1] - cum[j])
    near = np.minimum(d, cum[-1] - d) <= reach
    return float(raw_turning(ring)[near].sum())


def fit_ends(
    grids, topology: MultiBlockTopology, rings: list[np.ndarray], limit: float, fine: float | None = None
) -> tuple[list, int]:
    """``(grids, moved)``: :func:`fit_bends` for the shore nodes the smoother holds fixed — block
    corners and cut lines' ends on the shore (one, three or more cells) — moved, with every block
    around them, to the ring vertex between their two shore neighbours where their two edges leave
    the shore least, where that helps as :func:`fit_bends` requires and every cell around stays
    convex.  A cut the layout ended a few tenths of a cell short of an island's or a headland's
    tip leaves it outside the grid, and no free node can reach it: the block whose side passes the
    end would need a reflex cell to go round it."""
    from .driver import _assemble
    from .untangle import _Mesh, _score

    if not rings:
        return list(grids), 0
    m = topology.node_map
    X, Y = _assemble(grids, m)
    cells = m.cells.astype(np.int64)
    cnt = np.bincount(cells.reshape(-1), minlength=m.n_nodes)
    e0, e1 = cells.reshape(-1), np.roll(cells, -1, axis=1).reshape(-1)
    key, ce = np.unique(np.minimum(e0, e1) * np.int64(m.n_nodes) + np.maximum(e0, e1), return_counts=True)
    shore_nbrs: dict[int, list[int]] = {}
    for a, b in zip(*np.divmod(key[ce == 1], np.int64(m.n_nodes)), strict=True):
        shore_nbrs.setdefault(int(a), []).append(int(b))
        shore_nbrs.setdefault(int(b), []).append(int(a))
    ends = [n for n, nb in shore_nbrs.items() if len(nb) == 2 and cnt[n] != 2]
    if not ends:
        return list(grids), 0
    cums = [arc_lengths(r) for r in rings]
    trios = np.array([[shore_nbrs[n][0], n, shore_nbrs[n][1]] for n in ends])
    r_all, s_all, _ = project_to_rings(rings, np.column_stack([X[trios.ravel()], Y[trios.ravel()]]))
    todo = []
    for k, n in enumerate(ends):
        r = int(r_all[3 * k + 1])
        if r_all[3 * k] != r or r_all[3 * k + 2] != r:
            continue
        trio = np.column_stack([X[trios[k]], Y[trios[k]]])
        at, _ = _better(rings[r], cums[r], s_all[3 * k : 3 * k + 3], trio, limit)
        if at is None:
            continue
        if fine is not None and cnt[n] == 1 and abs(_turning_near(rings[r], cums[r], at, 0.5 * fine)) < CORNER_TURN:
            continue  # a block corner onto a straight piece of shore: its finest cell a triangle
        todo.append((n, trio[1], at))
    if not todo:
        return list(grids), 0
    mesh = _Mesh(topology, grids)  # the incidence tables, only where an end moves
    X, Y = mesh.X, mesh.Y
    moved = 0
    for n, here, at in todo:
        # alone, else with the first nodes of the cut line leaving it carried along
        line = _cut_line(mesh, n)
        for k in (0, len(line)):
            nodes = [n, *line[:k]]
            old = [(X[v], Y[v]) for v in nodes]
            around = np.unique(np.concatenate([mesh.around(v) for v in nodes]))
            before = _score(X, Y, cells, around)
            bad = _bad_corners(X, Y, cells[around])
            for t, v in enumerate(nodes):
                w = 1.0 - t / len(nodes)
                X[v], Y[v] = old[t][0] + w * (at[0] - here[0]), old[t][1] + w * (at[1] - here[1])
            # no cell around made non-convex, nor more corners of a cell that was already
            if _score(X, Y, cells, around)[0] >= before[0] and _bad_corners(X, Y, cells[around]) <= bad:
                moved += 1
                break
            for v, (px, py) in zip(nodes, old, strict=True):
                X[v], Y[v] = px, py
    return mesh.grids(grids), moved


def _bad_corners(X, Y, cells) -> int:
    """How many corners of ``cells`` are not convex (corner Jacobian ``≤ 0``).  A move that keeps the
    count of bad cells can still add bad corners to a cell that was bad already: Saimaa's block b114
    (a block corner with both sides on the shore, non-convex on the coarsest level, 2 × 2 cells) had
    its corner put on a land tip where the water turns beyond 180°, and no free node could make
    that cell convex again on any level (the per-block repair keeps the shore fixed): it went out
    folded.  A corner straight up to rounding (sine ``≤`` :data:`~meshcore.quality.cells.STRAIGHT_SINE`)
    is bad too: a block corner moved onto a straight piece of shore makes its corner cell a
    triangle (the lake's quality reports such cells)."""
    from ..quality.cells import STRAIGHT_SINE
    from .untangle import _NEXT, _PREV, _corner_jacobians

    px, py = X[cells], Y[cells]
    den = np.hypot(px[:, _NEXT] - px, py[:, _NEXT] - py) * np.hypot(px[:, _PREV] - px, py[:, _PREV] - py)
    return int((_corner_jacobians(X, Y, cells) <= STRAIGHT_SINE * den).sum())


def _cut_line(mesh, n: int) -> list[int]:
    """Up to :data:`CARRY` nodes along the one cut line (shared nodes off the shore) leaving the
    shore node ``n``, nearest first; none where no single line leaves it."""
    m = mesh.m
    out: list[int] = []
    prev, at = -1, n
    for _ in range(CARRY):
        nxt = [v for v in mesh.nbrs(at) if v != prev and m.shared[v] and not m.boundary[v]]
        if len(nxt) != 1:
            break
        prev, at = at, nxt[0]
        out.append(at)
    return out
