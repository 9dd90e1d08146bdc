r"""Orthogonal grids: the smoother that lake models need, over one block or many.

:func:`orthogonalize` takes a multiblock grid (a start grid without folds: algebraic or the
elliptic solution) and the shore it lies on, and iterates

1. a Gauss–Seidel sweep of the Ryskin–Leal weak-constraint update over every free node —
   block interiors, interface nodes (so cut lines move, along and across), corners where 3 or
   5 blocks meet (see :mod:`._kernels`);
2. a sweep that slides every shore node with two cells around it along the shore, to the foot
   of the perpendicular from its inward neighbour.  Nodes with one cell (convex block corners)
   or three (reflex corners, cut lines ending beside a block's side) stay where the layout put
   them; the shore edges on the two sides of such an end are the first cells of two blocks, so
   the nodes next to it keep their edge within ``lo`` of the edge beyond it;
3. optionally (``hold_ends``), where such an end sits at a reflex shore corner (water angle at
   least :data:`FAN_LEAST`), a turn of the grid lines leaving it back towards set angles (a block
   corner there a right angle, the blocks whose side passes it the rest) and out to the length of
   the shore edges there (:func:`._kernels.hold_fans`).  Left alone, the start solve and the
   levels can turn the cut's first edge until the corner block's angle is 150–180° — a polar fan
   whose cells are 10–80 times smaller than those across the cut.  Off by default: it removes
   those fans but, holding only the first edge, makes a kink where the drawn cut bends a few
   cells on, and on 90 generated lakes the two effects cancel (see ``docs/lake-grids-journal.md``);

until the largest move is below ``tol`` × the median edge length.  Where that leaves a cell
thinner than 1 : 100 (aspect ratio over 100, :data:`._kernels.ASPECT_FLOOR`) that was not so thin
at the start, the stage runs again from its start with the guard's thin rule on the nodes round
such cells (:data:`THIN_RUNS`, :func:`_thin_nodes`); every other stage is the same as without it.

The weak constraint accepts any orthogonal grid, also one whose cells grow tenfold from one
to the next (a polar fan into a block corner, a jump across a cut line).  A blend towards
the Laplace weights (``smooth``) damps that everywhere; ``size_ratio = (lo, hi)`` adds more
of it only where two consecutive edges along a grid line differ by more than ``lo``, up to
the full Laplace weights at ``hi`` (default 1.2 and 2: the modellers' limits for consecutive
edges and for cells across an interface) — and where an edge at the node is shorter than
:data:`EDGE_FLOOR` of the level's median edge, however alike the two (a polar fan's cells shrink
towards an obtuse block corner at a steady ratio under ``lo``).  That blend is a state per node, moved
``size_relax`` of the way to its current value each sweep: switched on and off at once, a
node next to a shore node can cycle between the orthogonal and the smooth position for ever.  Every move is guarded: no
cell around a moving node may lose its positive corner Jacobians, so a grid without folds
stays without folds.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from . import _kernels
from .shore import project_to_rings

__all__ = ["STALL_LIMITS", "OrthoResult", "iterate_orthogonalize", "orthogonal_share", "orthogonalize"]

#: The ``|cos|`` limits whose shares of nodes the ``stall`` test watches: Delft3D's 0.02 and the
#: 3° (``sin 3°``) of the lake-grid targets; the sweeps stop only when neither share still rises.
STALL_LIMITS = (0.02, math.sin(math.radians(3.0)))


@dataclass(frozen=True, slots=True, eq=False)
class OrthoResult:
    grids: tuple
    sweeps: int
    converged: bool
    elapsed: float
    history: tuple[float, ...]


def _assemble(grids, m):
    X = np.zeros(m.n_nodes)
    Y = np.zeros(m.n_nodes)
    for g, ids in zip(grids, m.ids, strict=True):
        X[ids] = g.x
        Y[ids] = g.y
    return X, Y


def _node_cells(cells: np.ndarray, n_nodes: int):
    flat = cells.reshape(-1)
    order = np.argsort(flat, kind="stable")
    cnt = np.bincount(flat, minlength=n_nodes)
    ptr = np.concatenate([[0], np.cumsum(cnt)]).astype(np.int64)
    return ptr, cells[order // 4].astype(np.int64), cnt


def _shore_data(X, Y, m, cells, cnt, rings):
    """Arrays describing every shore node: inward neighbour, shore neighbours, ring and s."""
    n = m.n_nodes
    e0 = cells.reshape(-1)
    e1 = np.roll(cells, -1, axis=1).reshape(-1)
    key = np.minimum(e0, e1) * n + np.maximum(e0, e1)
    ukey, ecnt = np.unique(key, return_counts=True)
    a, b = np.divmod(ukey, n)
    bnd_edge = ecnt == 1
    nodes = np.flatnonzero(m.boundary)
    pos = -np.ones(n, dtype=np.int64)
    pos[nodes] = np.arange(len(nodes))
    nbrs = [[] for _ in nodes]
    for u, v in zip(a[bnd_edge], b[bnd_edge], strict=True):
        nbrs[pos[u]].append(int(v))
        nbrs[pos[v]].append(int(u))
    inner = -np.ones(len(nodes), dtype=np.int64)
    # every interior edge from a shore node inwards (or, between two shore nodes, from one with
    # two cells), in edge order; a node's last such edge gives its inward neighbour
    u, v = a[~bnd_edge], b[~bnd_edge]
    bu, bv = m.boundary[u], m.boundary[v]
    both = bu & bv  # an interior edge between two shore nodes
    to_u = (bu & ~bv) | (both & (cnt[u] == 2))
    to_v = (bv & ~bu) | (both & (cnt[v] == 2))
    tgt = np.column_stack([np.where(to_u, u, -1), np.where(to_v, v, -1)]).ravel()
    val = np.column_stack([v, u]).ravel()
    keep = tgt >= 0
    tgt, val = tgt[keep][::-1], val[keep][::-1]
    last = np.unique(tgt, return_index=True)[1]  # the first in reverse: the last in edge order
    inner[pos[tgt[last]]] = val[last]
    # ring and arc length of every shore node (nearest point of the nearest ring)
    if rings:
        ring_of, s_of, _ = project_to_rings(rings, np.column_stack([X[nodes], Y[nodes]]))
        ring_of = ring_of.astype(np.int64)
    else:
        ring_of, s_of = np.zeros(len(nodes), dtype=np.int64), np.zeros(len(nodes))
    prev = -np.ones(len(nodes), dtype=np.int64)
    nxt = -np.ones(len(nodes), dtype=np.int64)
    per = [float(np.hypot(*(np.roll(r, -1, axis=0) - r).T).sum()) for r in rings]
    for i in range(len(nodes)):
        if len(nbrs[i]) != 2 or not rings:
            continue
        total = per[ring_of[i]]
        j0, j1 = pos[nbrs[i][0]], pos[nbrs[i][1]]
        d0 = (s_of[j0] - s_of[i]) % total
        d1 = (s_of[j1] - s_of[i]) % total
        if d0 < d1:
            nxt[i], prev[i] = j0, j1
        else:
            nxt[i], prev[i] = j1, j0
    free = (cnt[nodes] == 2) & (inner >= 0) & (prev >= 0) & bool(rings)
    return nodes, inner, prev, nxt, ring_of, s_of, free


def _end_limits(cells, cell_block, cptr, bn, fidx, lo, end_ratio):
    """Per free shore node, the ratio its two shore edges may reach: ``lo``, or ``end_ratio`` at a
    cut's end on the shore where both blocks have a corner (its two cells in two blocks)."""
    order = np.argsort(cells.reshape(-1), kind="stable") // 4
    p = bn[fidx]
    two = cell_block[order[cptr[p]]] != cell_block[order[cptr[p] + 1]]
    return np.where(two, max(lo, end_ratio), lo).astype(np.float64)


def _across_cut_ends(bn, bprev, bnext, free, cnt) -> np.ndarray:
    """``(len(bn), 2)``: for a free shore node next to a cut line's end on the shore (a fixed
    node with three or more cells), the shore node beyond that end (before it, after it), else -1.

    The shore is one line of edges through such an end although its two sides belong to two
    blocks: the edge before it and the edge after it are the first cells of the blocks on the
    two sides of the cut, whose areas the cross-interface ratio compares."""
    out = -np.ones((len(bn), 2), dtype=np.int64)
    for i in np.flatnonzero(free):
        for col, (nb, beyond) in enumerate(((bprev[i], bprev), (bnext[i], bnext))):
            if nb >= 0 and not free[nb] and cnt[bn[nb]] >= 3 and beyond[nb] >= 0:
                out[i, col] = beyond[nb]
    return out


#: The least water angle (radians) at a cut end on the shore for :func:`._kernels.hold_fans` to
#: act: 225 degrees, halfway between a straight shore (180: a cut ending beside a block's side
#: there turns that side, no corner to keep) and the 270 of a block corner beside a side passing
#: straight.  The fans it stops (a corner block's angle turned to 150-180 degrees by the start
#: solve and the levels, cells 10-80 times smaller than across the cut) were all at reflex
#: corners, 240-300 degrees, on generated lakes (fresh_sweep seeds 499000 ...).
FAN_LEAST = float(np.radians(225.0))
#: How far (times the mean cell angle ``W / cells``) a line at a cut end may stray from its set
#: angle before :func:`._kernels.hold_fans` turns it back.  Measured on 45 generated lakes (fresh
#: seeds 499000, 15 000 cells): 0 (every line held exactly) turned the first edge against the way
#: the drawn cut bends two cells on and made kinks there (lakes with every interface ratio <= 2
#: 14 -> 12); 0.3 kept 14 and cut the worst fans; 0.45 let some come back (net 499004 35 -> 75).
FAN_SLACK = 0.3


def _cut_end_fans(cells, cell_block, boundary, bn, free, cnt):
    """``(ends, fptr, fan, corner)`` for :func:`._kernels.hold_fans`: every fixed shore node with
    three or more cells (a cut line's end), its neighbours in counter-clockwise order round it
    (``fan[fptr[k]:fptr[k + 1]]``), from one shore neighbour through the nodes of the lines into
    the water to the other, and per cell between two of them (``corner[fptr[k] + q]``, the cell
    after ``fan[fptr[k] + q]``) whether it is its block's only cell there; ends whose fan is not of
    that form (a line ending on the shore too) are left out."""
    ends, ptr, fan, corner = [], [0], [], []
    for c in bn[~free & (cnt[bn] >= 3)]:
        rows = np.flatnonzero((cells == c).any(axis=1))
        nxt, blk = {}, {}
        for r in rows:
            k = int(np.flatnonzero(cells[r] == c)[0])
            a = int(cells[r, (k + 1) % 4])
            nxt[a] = int(cells[r, (k + 3) % 4])
            blk[a] = int(cell_block[r])
        first = set(nxt) - set(nxt.values())
        if len(first) != 1:
            continue
        chain = [first.pop()]
        while chain[-1] in nxt and len(chain) <= len(nxt):
            chain.append(nxt[chain[-1]])
        if len(chain) != len(nxt) + 1 or not (boundary[chain[0]] and boundary[chain[-1]]):
            continue
        if boundary[chain[1:-1]].any():
            continue
        blocks = [blk[a] for a in chain[:-1]]
        ends.append(int(c))
        fan.extend(chain)
        corner.extend([blocks.count(b) == 1 for b in blocks] + [False])
        ptr.append(len(fan))
    return (
        np.array(ends, dtype=np.int64),
        np.array(ptr, dtype=np.int64),
        np.array(fan, dtype=np.int64),
        np.array(corner, dtype=np.bool_),
    )


def _pin_features(X, Y, bn, bring, bs, bprev, bnext, free, rings, h: float, angle: float) -> int:
    """Put a shore node on every sharp bend of the shore and keep it there.

    A sliding node would leave a sharp point of the shore (a headland, the end of a bay)
    between two nodes and the grid would cut it off; so each ring vertex that turns by more
    than ``angle`` degrees at the scale ``h`` (the largest turn within ``± h``) takes the free
    node nearest to it along the shore, unless that node's neighbours are closer to another
    feature.  Returns how many nodes were pinned.
    """
    from ..layout.corners import turning

    pinned = 0
    for r, ring in enumerate(rings):
        seg = np.hypot(*(np.roll(ring, -1, axis=0) - ring).T)
        cum = np.concatenate([[0.0], np.cumsum(seg)])
        total = cum[-1]
        t = np.abs(turning(ring, h))
        cand = [int(i) for i in np.argsort(-t) if t[i] > angle]
        on = np.flatnonzero((bring == r) & free)
        if not len(on) or not cand:
            continue
        taken_s: list[float] = []
        for v in cand:
            sv = cum[v]
            if any(min(abs(sv - q), total - abs(sv - q)) < h for q in taken_s):
                continue
            d = np.abs((bs[on] - sv + 0.5 * total) % total - 0.5 * total)
            k = on[int(np.argmin(d))]
            if not free[k]:
                continue
            # only when the vertex lies between the node's two shore neighbours
            sp, sn = bs[bprev[k]], bs[bnext[k]]
            lo = (sv - sp) % total
            hi = (sn - sp) % total
            if not (0 < lo < hi):
                continue
            X[bn[k]], Y[bn[k]] = ring[v]
            bs[k] = sv
            free[k] = False
            taken_s.append(sv)
            pinned += 1
    return pinned


#: How far (times the median edge) the shore between two consecutive shore nodes may stray from
#: the edge between them before the shore sweep stops a node sliding that way (a quarter cell:
#: then the grid follows the shore within half a cell, the issue-12 target, with room to spare).
SHORE_GAP = 0.25


#: How many times a stage runs again from its start with the thin rule (:func:`._kernels._try_move`)
#: round the cells the run before left thinner than :data:`._kernels.ASPECT_FLOOR` allows, and how
#: many rings of cells round them it takes in (:func:`_thin_nodes`).  Only there: the rule
#: everywhere (session 32) changed the sweeps' path on every lake and lost interface ratios on
#: lakes where no cell ended thin (``docs/lake-grids-journal.md``, "thin-cell guard").
THIN_RUNS = 2
THIN_RINGS = 2


#: The size blend (``size_ratio``) starts at this ratio instead of ``size_ratio[0]`` along a grid line
#: that leaves the shore, at its first :data:`SHORE_ROWS` interior nodes (None: ``size_ratio[0]``
#: everywhere).  The edge pairs at those nodes — the first cell off the shore against the next — were
#: the worst of every lake: on held-out g180686 at 10 000 cells 20 % of them above 1.2 (the second row
#: 11 %, block interiors 3 %), a quarter of all the grid's pairs above 1.2, as on the six lakes of
#: session 34 (22–36 %).  Blending there from 1.05 costs little orthogonality, where the same start
#: everywhere (``size_ratio=(1.1, 2.0)``) cost 4–5 points of nodes within 3° for one point of pairs
#: (docs/lake-grids-journal.md, session 40).
SHORE_ROW_LO: float | None = 1.05
SHORE_ROWS = 2


#: Where an edge at a node is shorter than this share of the level's median edge, the size blend
#: rises there too (in full at half of it; :func:`._kernels._short`), along grid lines and along the
#: shore.  At an obtuse block corner (the shore straight or bending outwards there: a tip block's
#: fourth corner, a cut's end at a land tip) the only orthogonal grid is a polar fan whose cells
#: shrink towards the corner by a steady ratio under ``size_ratio[0]``: held-out lakes had edges of
#: 1/100 of the cell size there, an explicit model's time step ÷ 100.  The floor trades a few nodes'
#: angles at such corners for cells of at least ~1/10 (0: off; ``size_ratio=None``: off too).
#: Session 41, held-out sets 25–28 (112 lakes) at 10 000 cells: shortest edge under 0.05 cells on
#: 35 → 11 lakes, hard targets 107 → 107 (docs/lake-grids-journal.md).
EDGE_FLOOR = 0.2


def _row_limits(m, lo: float) -> tuple[np.ndarray, np.ndarray]:
    """Per regular node of node map ``m``, where the size blend starts along its e–w line and along
    its n–s line: ``lo``, or :data:`SHORE_ROW_LO` along a line whose next node (either way) lies
    within :data:`SHORE_ROWS` − 1 rows of the shore (``m.boundary``, row 0; row ``k``: a node with a
    line neighbour in row ``k − 1``).  With 2: the nodes next to the shore along both their lines, the
    second row along the lines that leave the shore."""
    lox = np.full(len(m.nodes), float(lo))
    loy = np.full(len(m.nodes), float(lo))
    if SHORE_ROW_LO is None or not len(m.nodes):
        return lox, loy
    nb = m.nbr
    row = np.asarray(m.boundary, dtype=bool).copy()  # row 0: the shore
    near_x = np.zeros(len(m.nodes), dtype=bool)
    near_y = np.zeros(len(m.nodes), dtype=bool)
    for _ in range(SHORE_ROWS):
        nx = row[nb[:, 0]] | row[nb[:, 1]]  # the e–w line's next node in the rows so far
        ny = row[nb[:, 2]] | row[nb[:, 3]]
        near_x |= nx
        near_y |= ny
        row = row.copy()
        row[m.nodes[nx | ny]] = True  # the next row
    lox[near_x] = min(lo, SHORE_ROW_LO)
    loy[near_y] = min(lo, SHORE_ROW_LO)
    return lox, loy


def _thinness(X, Y, cells) -> np.ndarray:
    """Per cell, the least ratio of the shorter over the longer of the two edges at a corner (one
    over the largest aspect ratio of :mod:`meshcore.quality`, which reads one corner of each cell;
    here every corner: the block's direction is not known)."""
    cx, cy = X[cells], Y[cells]
    e = np.hypot(np.roll(cx, -1, axis=1) - cx, np.roll(cy, -1, axis=1) - cy)
    f = np.roll(e, 1, axis=1)
    return (np.minimum(e, f) / np.maximum(np.maximum(e, f), 1e-300)).min(axis=1)


def _thin_nodes(X, Y, cells, thin0, thin):
    """The node mask for the next run: ``thin`` with the nodes of every cell now thinner than
    :data:`._kernels.ASPECT_FLOOR` (aspect ratio over 100) and thinner than at the stage's start
    (``thin0``),
    and :data:`THIN_RINGS` rings of cells round them; None when every such cell is inside
    ``thin`` already (no run would change)."""
    t = _thinness(X, Y, cells)
    bad = (t < _kernels.ASPECT_FLOOR) & (t < thin0)
    if not bad.any():
        return None
    mark = np.zeros(len(thin), dtype=bool)
    mark[cells[bad]] = True
    if mark[thin == 0].sum() == 0:
        return None
    for _ in range(THIN_RINGS):
        mark[cells[mark[cells].any(axis=1)]] = True
    return (mark | (thin != 0)).astype(np.uint8)


def _interface_pairs(cells, cell_block):
    """The cells of two blocks that share an edge: two arrays of cell indices."""
    e = np.stack([cells, np.roll(cells, -1, axis=1)], axis=2).reshape(-1, 2)
    e.sort(axis=1)
    owner = np.repeat(np.arange(len(cells)), 4)
    order = np.lexsort((e[:, 1], e[:, 0]))
    e, owner = e[order], owner[order]
    same = (e[1:] == e[:-1]).all(axis=1)
    a, b = owner[:-1][same], owner[1:][same]
    cross = cell_block[a] != cell_block[b]
    return a[cross], b[cross]


def quad_areas(X: np.ndarray, Y: np.ndarray, cells: np.ndarray) -> np.ndarray:
    """Signed areas of the quads ``cells`` (corner ids, counter-clockwise: positive), half the
    cross product of their diagonals — the NumPy form of ``_equalize_kernels._quad_area``."""
    x0, x1, x2, x3 = (X[cells[:, k]] for k in range(4))
    y0, y1, y2, y3 = (Y[cells[:, k]] for k in range(4))
    return 0.5 * ((x2 - x0) * (y3 - y1) - (y2 - y0) * (x3 - x1))


def _interface_ratio(X, Y, cells, pairs) -> float:
    """The largest area ratio of two cells across a block interface (the lake grids' metric)."""
    a, b = pairs
    if not len(a):
        return 1.0
    area = np.abs(quad_areas(X, Y, cells))
    lo, hi = np.minimum(area[a], area[b]), np.maximum(area[a], area[b])
    return float(np.max(hi / np.maximum(lo, 1e-300)))


def _ring_tables(rings):
    """Points of all rings in one array (ring k: ``R[roff[k]:roff[k+1]]``) and their cumulative
    arc lengths (ring k: ``S[roff[k]+k : roff[k+1]+k+1]``, from 0 to the perimeter)."""
    parts, off = [], [0]
    for r in rings:
        seg = np.hypot(*(np.roll(r, -1, axis=0) - r).T)
        parts.append(np.concatenate([[0.0], np.cumsum(seg)]))
        off.append(off[-1] + len(r))
    return np.vstack(rings).astype(np.float64), np.concatenate(parts), np.array(off, dtype=np.int64)


def orthogonal_share(X, Y, nodes, nbr, limit: float = 0.02) -> float:
    """Share of the regular nodes ``nodes`` (neighbours ``nbr``: E, W, N, S, …) whose node
    orthogonality ``|cos|`` (central differences, as :mod:`meshcore.quality`) is at most ``limit``."""
    if not len(nodes):
        return 1.0
    ax, ay = X[nbr[:, 0]] - X[nbr[:, 1]], Y[nbr[:, 0]] - Y[nbr[:, 1]]
    bx, by = X[nbr[:, 2]] - X[nbr[:, 3]], Y[nbr[:, 2]] - Y[nbr[:, 3]]
    norm = np.sqrt((ax * ax + ay * ay) * (bx * bx + by * by))
    dot = np.abs(ax * bx + ay * by)
    return float(np.mean(dot <= limit * norm))


def orthogonalize(topology, grids, rings, **options):
    """Orthogonalise ``grids`` (one per block of ``topology``) with shore nodes sliding on ``rings``.

    The options are those of :func:`iterate_orthogonalize`; returns its :class:`OrthoResult`.
    """
    from .._generators import drain

    return drain(iterate_orthogonalize(topology, grids, rings, every=None, **options))


def iterate_orthogonalize(
    topology,
    grids,
    rings,
    *,
    every: int | None = 25,
    tol: float = 1e-4,
    max_sweeps: int = 20_000,
    omega: float = 1.0,
    smooth: float = 0.1,
    pin_angle: float | None = None,
    shore_smooth: float = 0.15,
    guard: bool = True,
    shore_gap: float = SHORE_GAP,
    size_ratio: tuple[float, float] | None = (1.2, 2.0),
    size_relax: float = 0.05,
    hold_ends: bool = False,
    end_ratio: float | None = None,
    stall: float | None = None,
    stall_every: int = 20,
    stall_limits: tuple[float, ...] = STALL_LIMITS,
    callback=None,
):
    """:func:`orthogonalize` as a generator: every ``every`` sweeps it yields
    ``(sweep, change, grids)`` (the change per sweep relative to the median edge, the current
    grids); ``"stop"`` sent to it ends the sweeps.  Returns the :class:`OrthoResult`.

    ``hold_ends``: keep the lines leaving cut ends at reflex shore corners near their angles
    (step 3 of the module docstring).

    ``end_ratio``: a cut's end on the shore where both blocks have a corner (a shore node of two
    cells, one in each block) may slide until its two shore edges differ by this ratio (other shore
    nodes: ``size_ratio[0]``).  No edge pair of the smoothness metric spans such an end; held to
    ``size_ratio[0]`` it hardly slides and the cut keeps the angle the coarse levels left it.  Off
    (None) by default: 2 squares those cuts and raises the share of nodes with ``|cos| ≤ 0.02`` on
    lakes of 50-100 blocks, but the first shore cells either side differ more and a lake here and
    there loses every interface ratio ≤ 2 (``docs/lake-grids-journal.md``, session 25).

    ``stall``: also stop (``converged`` True) when, over ``stall_every`` sweeps, the share of
    regular nodes with ``|cos|`` at most each of ``stall_limits`` (:func:`orthogonal_share`;
    default 0.02 and 3°, :data:`STALL_LIMITS`) rose by less than ``stall`` (e.g. 0.0025: a
    quarter of a percentage point) for every limit.  With 0.02 alone, a fine level whose first
    sweeps after the refinement turned its nodes towards 3° but not yet to 0.02 stopped after
    20 sweeps (``archipelago(701003, n_islands=40)``: the 0.02 share 46.8 → 46.8 %, 3° 64.2 →
    68.9 %; 69.6 % of nodes within 3° at the end, 83.8 % after 400 sweeps).  The largest move per sweep is no measure of
    that: a few nodes held by the fold guard or by the shore keep it near 1e-2 while the
    orthogonality of all the others still improves, or long after it stopped improving.

    ``guard`` also runs the stage again where it left a cell thin (the module docstring;
    ``sweeps`` of the result counts every run's sweeps)."""
    t0 = time.perf_counter()
    lo, hi = size_ratio if size_ratio is not None else (np.inf, np.inf)
    bx, by = np.zeros(len(topology.node_map.nodes)), np.zeros(len(topology.node_map.nodes))
    m = topology.node_map
    X, Y = _assemble(grids, m)
    cells = m.cells.astype(np.int64)
    cptr, ncells, cnt = _node_cells(cells, m.n_nodes)
    # guard floor: a thousandth of the mean area of the cells around each node
    cx, cy = X[cells], Y[cells]
    area = 0.5 * ((cx[:, 0] - cx[:, 2]) * (cy[:, 1] - cy[:, 3]) - (cx[:, 1] - cx[:, 3]) * (cy[:, 0] - cy[:, 2]))
    mean_area = np.bincount(cells.reshape(-1), weights=np.repeat(np.abs(area), 4), minlength=m.n_nodes)
    jmin = 1e-3 * mean_area / np.maximum(cnt, 1) if guard else np.full(m.n_nodes, -np.inf)
    rings = [np.asarray(r, dtype=np.float64) for r in rings]
    bn, binner, bprev, bnext, bring, bs, free = _shore_data(X, Y, m, cells, cnt, rings)
    edge0 = np.hypot(X[cells[:, 1]] - X[cells[:, 0]], Y[cells[:, 1]] - Y[cells[:, 0]])
    if pin_angle is not None:
        _pin_features(X, Y, bn, bring, bs, bprev, bnext, free, rings, float(np.median(edge0)), pin_angle)
    R, S, roff = _ring_tables(rings) if rings else (np.zeros((1, 2)), np.zeros(2), np.zeros(2, dtype=np.int64))
    fidx = np.flatnonzero(free).astype(np.int64)
    across = _across_cut_ends(bn, bprev, bnext, free, cnt)
    blo = _end_limits(cells, m.cell_block, cptr, bn, fidx, lo, lo if end_ratio is None else end_ratio)
    fans = _cut_end_fans(cells, m.cell_block, m.boundary, bn, free, cnt) if hold_ends and rings else None
    bz = np.zeros(len(fidx))
    edge = np.hypot(X[cells[:, 1]] - X[cells[:, 0]], Y[cells[:, 1]] - Y[cells[:, 0]])
    h = float(np.median(edge))
    floor = EDGE_FLOOR * h if EDGE_FLOOR and size_ratio is not None else 0.0  # (part of the size blend)
    hist = []
    it = 0
    converged = False
    thin0 = _thinness(X, Y, cells) if guard else None
    pairs = _interface_pairs(cells, m.cell_block) if guard else None

    def one(nodes, nbr, irr, free, bx, by, bz, blo, smooth, thin):
        """One sweep of the free nodes given (interior, irregular ``irr``, shore ``free``) with
        their states; the largest move over ``h``."""
        d1 = _kernels.sweep(
            X, Y, nodes, nbr, *irr, cptr, ncells, omega, smooth, lox, loy, hi, floor, bx, by, size_relax, jmin, thin
        )
        d2 = _kernels.shore_sweep(
            X,
            Y,
            free,
            bn,
            binner,
            bprev,
            bnext,
            bring,
            bs,
            R,
            S,
            roff,
            cptr,
            ncells,
            1.0,
            shore_smooth,
            shore_gap * h,
            jmin,
            lo,
            hi,
            floor,
            bz,
            size_relax,
            across,
            blo,
            thin,
        )
        d3 = (
            _kernels.hold_fans(X, Y, *fans, cptr, ncells, jmin, FAN_LEAST, FAN_SLACK, lo, thin)
            if fans is not None
            else 0.0
        )
        return max(d1, d2, d3) / h

    irr = (m.irr_nodes, m.irr_ptr, m.irr_ring)
    lox, loy = _row_limits(m, lo)
    thin = np.zeros(m.n_nodes, dtype=np.uint8)  # the thin rule's nodes: none on the first run
    state = (X, Y, bx, by, bs, bz)
    start = tuple(a.copy() for a in state)
    kept = None
    done = 0
    for run in range(THIN_RUNS + 1):
        share = [orthogonal_share(X, Y, m.nodes, m.nbr, q) for q in stall_limits] if stall is not None else []
        stopped = False
        for it in range(1, max_sweeps + 1):
            d = one(m.nodes, m.nbr, irr, fidx, bx, by, bz, blo, smooth, thin)
            hist.append(d)
            if callback is not None and (done + it) % 50 == 0:
                callback(done + it, d)
            if d < tol:
                converged = True
                break
            if stall is not None and it % stall_every == 0:
                now = [orthogonal_share(X, Y, m.nodes, m.nbr, q) for q in stall_limits]
                if all(b - a < stall for a, b in zip(share, now, strict=True)):
                    converged = True
                    break
                share = now
            if every and (done + it) % every == 0:
                snap = tuple(g.replaced(x=X[ids], y=Y[ids]) for g, ids in zip(grids, m.ids, strict=True))
                if (yield (done + it, d, snap)) == "stop":
                    stopped = True
                    break
        done += it
        if stopped or not guard:
            break
        if kept is not None and _interface_ratio(X, Y, cells, pairs) > max(kept[0], hi):
            # the run with the thin rule put two cells across a cut further apart than the
            # modellers' limit and the run before it did: that one kept
            for a, b in zip(state, kept[1], strict=True):
                a[:] = b
            converged = kept[2]
            break
        more = _thin_nodes(X, Y, cells, thin0, thin) if run < THIN_RUNS else None
        if more is None:
            break
        # cells squeezed thin in this run: the run again from the stage's start, with the thin
        # rule round them (and round those of the runs before)
        kept = (_interface_ratio(X, Y, cells, pairs), tuple(a.copy() for a in state), converged)
        thin = more
        for a, b in zip(state, start, strict=True):
            a[:] = b
        converged = False
    it = done
    out = [g.replaced(x=X[ids], y=Y[ids]) for g, ids in zip(grids, m.ids, strict=True)]
    return OrthoResult(tuple(out), it, converged, time.perf_counter() - t0, tuple(hist))
