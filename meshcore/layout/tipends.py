r"""Cut ends slid onto island tips: no block side made of a cut and a short piece of shore.

Where a cut ends at an island's tip (the water round it spans at least :data:`TIP_WATER`) and
continues one of the island's shore lines there, the block on that side passes the tip: its side
runs along the cut, past the tip and on along the island to the block's corner ``P``.  When
``P`` is only a few cells from the tip and another cut ends there, that side is two chains, the
cut and the short piece of shore, and the cell counts can give the short piece what the side's
opposite asks for and the cut what a ring of other blocks fixes: on generated lakes with islands
the start grid's border edges at such tips were 12–118× apart, the block's grid lines fanning
into the tip (journal: *Fans into island tips*, *Crowded shore pieces*).

Where the counts do crowd such a side (its cells per length jump by :data:`TIP_JUMP` or more at
the tip; :func:`counted_without_tip_fans`, after the layout is counted), the other cut's end is
slid from ``P`` to the tip (a straight cut from its other end ``Q``):
the block that passed the tip gets its corner there (between the two cuts), the block across
the slid cut takes the piece of shore into its side along the island, with its corner at the tip
too.  Done only when the layout stays sound: ``P`` on a straight piece of shore (it becomes a
point of that side), both corners at the tip and both angles at ``Q`` neither flat nor
needle-thin, both blocks valid polygons.  A layout without the pattern is left as it is.
Not reached: held-out g180782's end, where ``P`` is a land tip as well (the block across would
get a reflex vertex there).

OFF by default (:data:`SLIDE`): the fans it targets go, but the counts of the slid layout move
cells elsewhere, and on the grids the gains and losses are mixed (journal: *Cut ends slid onto
island tips*).
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from ..pointindex import PointIndex
from .blocks import Piece
from .corners import SHARP, raw_turning

__all__ = ["counted_without_tip_fans", "slide_tip_ends"]

#: Slide cut ends onto crowded island tips (:func:`counted_without_tip_fans`).  OFF: measured
#: mixed (session 23, journal *Cut ends slid onto island tips*).
SLIDE = False

#: The water angle (degrees) round a cut's end from which it is a land tip (*Cut ends on the shore*'s *point*).
TIP_WATER = 250.0

#: The longest piece of shore (cells) between the tip and the passing block's corner that is slid
#: away; it must also be shorter than the cut it follows in the side.
TIP_PIECE = 8.0

#: The spacing jump (the cells along one chain of a block side against the next one's, per length)
#: at a tip from which the side counts as crowded there (session 15's measure of a layout's jumps).
TIP_JUMP = 4.0

#: The least and largest angle (degrees) of a block at its new corner on the tip, and the least
#: angle of either block at the slid cut's other end.
CORNER_ANGLES = (45.0, 150.0)
LEAST_ANGLE = 20.0


def _angles(ring: np.ndarray) -> np.ndarray:
    """Interior angle (degrees) of a counter-clockwise ring at every vertex."""
    return 180.0 - raw_turning(ring)


def _step(n: int, i: int, d: int) -> int:
    return (i + d) % n


def counted_without_tip_fans(pieces: list[Piece], h: float, hl: float, *, multiple: int = 1):
    """``(pieces, cells)``: the cells of every piece (:func:`~.blocks.block_counts`), and where a
    block side's cells jump by :data:`TIP_JUMP` or more at an island's tip, the cut ends slid
    onto those tips (:func:`slide_tip_ends`; ``h`` the cell size, ``hl`` the layout's) and the
    pieces counted again.  The pieces as they are when there is no such tip, or when the slid
    ones have no counts that agree; only with :data:`SLIDE` (else just the cells)."""
    from ..errors import TopologyError
    from .blocks import block_counts

    if not SLIDE:
        return pieces, block_counts(pieces, h, multiple=multiple)
    cells, crowded = _jumps(pieces, h, multiple)
    if not crowded:
        return pieces, cells
    slid = slide_tip_ends(pieces, hl, at=crowded)
    if slid is pieces:
        return pieces, cells
    try:
        return slid, block_counts(slid, h, multiple=multiple)
    except TopologyError:
        return pieces, cells


def cut_beside_shore(pieces: list[Piece], h: float, multiple: int):
    """The cells of every piece and, for every place where a block side passes from a cut to a
    piece of shore (consecutive chains of the side, one shared, one not), ``(piece, cut, shore)``:
    each chain as ``(length, spacing of its cells, meeting point keys)`` (the side's counts as
    :func:`~.blocks.block_counts` gives them).  Shared by :func:`_jumps` and
    :func:`.tipsplit.crowded`."""
    from ..pointindex import point_key
    from .blocks import BORDERS, _chains_of, _counts, _line_work

    work = _line_work(pieces)
    cells, counts = _counts(work, pieces, h, 3, multiple, None, True)
    sides, chain_pts, users = _chains_of(pieces, work)
    keys = list(chain_pts)
    index = {k: i for i, k in enumerate(keys)}
    length = np.array([float(np.hypot(*np.diff(chain_pts[k], axis=0).T).sum()) for k in keys])
    spacing = length / np.maximum(np.asarray(counts, dtype=float), 1.0)

    def ends(c: int) -> set:
        p = chain_pts[keys[c]]
        return {point_key(p[0]), point_key(p[-1])}

    places = []
    for pi in range(len(pieces)):
        for side in BORDERS:
            chain = [index[k] for k in sides[(pi, side)]]
            for c1, c2 in itertools.pairwise(chain):
                shore1, shore2 = len(users[keys[c1]]) == 1, len(users[keys[c2]]) == 1
                if shore1 == shore2:
                    continue  # not a cut beside a piece of shore
                cut, shore = (c2, c1) if shore1 else (c1, c2)
                at = ends(c1) & ends(c2)  # the point where they meet
                places.append((pi, (length[cut], spacing[cut], at), (length[shore], spacing[shore], at)))
    return cells, places


def _jumps(pieces: list[Piece], h: float, multiple: int):
    """The cells of every piece and the points where a block side's cells jump by :data:`TIP_JUMP`
    or more between a cut and a piece of shore (point keys)."""
    cells, places = cut_beside_shore(pieces, h, multiple)
    crowded: set = set()
    for _pi, (_, s_cut, at), (_, s_shore, _) in places:
        if max(s_cut / s_shore, s_shore / s_cut) >= TIP_JUMP:
            crowded |= at
    return cells, crowded


def slide_tip_ends(pieces: list[Piece], h: float, *, at=None) -> list[Piece]:
    """``pieces`` with every cut end slid onto an island tip where a block side would otherwise
    hold that tip's cut and a short piece of shore (see the module; ``at``: only at these tips,
    :func:`~meshcore.pointindex.point_key`); the same list when none."""
    out = pieces
    for _ in range(len(pieces)):
        got = _slide_one(out, h, at)
        if got is None:
            break
        out = got
    return out


def _slide_one(pieces: list[Piece], h: float, at=None) -> list[Piece] | None:
    from shapely.geometry import Polygon

    from ..pointindex import point_key

    ix = PointIndex([pc.ring for pc in pieces])
    n_pts = len(ix)
    m = np.zeros(n_pts, dtype=int)
    where: dict[int, list[tuple[int, int]]] = {}  # point → (piece, vertex) of every piece holding it
    angle = np.zeros(n_pts)
    edges: dict[tuple[int, int], int] = {}
    for k, (ids, pc) in enumerate(zip(ix.ids, pieces, strict=True)):
        m[ids] += 1
        np.add.at(angle, ids, _angles(pc.ring))
        for j, p in enumerate(ids.tolist()):
            where.setdefault(p, []).append((k, j))
        for a, b in zip(ids.tolist(), np.roll(ids, -1).tolist(), strict=True):
            e = (min(a, b), max(a, b))
            edges[e] = edges.get(e, 0) + 1
    loop = _island_points(ix, edges)
    for x, (ids, pc) in enumerate(zip(ix.ids, pieces, strict=True)):
        ring, n = pc.ring, len(pc.ring)
        corners = set(pc.corners)

        def on_shore(i: int, j: int, ids=ids) -> bool:
            a, b = int(ids[i]), int(ids[j])
            return edges[(min(a, b), max(a, b))] == 1

        for a in range(n):
            pa = int(ids[a])
            if a in corners or m[pa] != 2 or pa not in loop or angle[pa] < TIP_WATER:
                continue
            if at is not None and point_key(ring[a]) not in at:
                continue
            fwd, back = on_shore(a, _step(n, a, 1)), on_shore(_step(n, a, -1), a)
            if fwd == back:
                continue
            d = 1 if fwd else -1
            # the shore from the tip to the block's corner P, where another cut ends
            s, p, length = a, _step(n, a, d), 0.0
            length += float(np.hypot(*(ring[p] - ring[s])))
            while p not in corners and m[int(ids[p])] == 1 and on_shore(p, _step(n, p, d)) and length <= TIP_PIECE * h:
                s, p = p, _step(n, p, d)
                length += float(np.hypot(*(ring[p] - ring[s])))
            pp = int(ids[p])
            if p not in corners or m[pp] != 2 or length > TIP_PIECE * h or abs(angle[pp] - 180.0) > SHARP:
                continue
            # the cut the tip ends (C1) must be the longer part of the side
            c1, j = 0.0, a
            while True:
                i = _step(n, j, -d)
                if on_shore(i, j) or i == a:
                    break
                c1 += float(np.hypot(*(ring[i] - ring[j])))
                j = i
                if m[int(ids[j])] != 2 or j in corners:
                    break
            if c1 <= length:
                continue
            ((y, yp),) = [(k, j) for k, j in where[pp] if k != x]
            ypc = pieces[y]
            if yp not in set(ypc.corners):
                continue
            # the other cut (C2): from P on, the edges X shares with Y, to its other end Q
            yset = set(ix.ids[y].tolist())
            q = p
            while True:
                nq = _step(n, q, d)
                if int(ids[nq]) not in yset or on_shore(q, nq):
                    break
                q = nq
                if m[int(ids[q])] != 2 or q in corners:
                    break
            if q in (p, a):
                continue
            got = _slid(pieces, ix, x, y, a, p, q, d, h)
            if got is None:
                continue
            new_x, new_y = got
            if not (Polygon(new_x.ring).is_valid and Polygon(new_y.ring).is_valid):
                continue
            out = list(pieces)
            out[x], out[y] = new_x, new_y
            return out
    return None


def _island_points(ix: PointIndex, edges: dict[tuple[int, int], int]) -> set[int]:
    """The points on island shores (the loops of shore edges other than the outer one)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    bnd = np.array([e for e, used in edges.items() if used == 1])
    if not len(bnd):
        return set()
    n = len(ix)
    g = coo_matrix((np.ones(len(bnd)), (bnd[:, 0], bnd[:, 1])), shape=(n, n))
    _, lab = connected_components(g, directed=False)
    on = np.unique(bnd)
    outer = lab[on[-1]]  # the lexicographically last point (largest x) is on the outer shore
    return {int(v) for v in on if lab[v] != outer}


def _path(n: int, i: int, j: int, d: int) -> list[int]:
    """Indices strictly between ``i`` and ``j`` walking in direction ``d``."""
    out, k = [], _step(n, i, d)
    while k != j:
        out.append(k)
        k = _step(n, k, d)
    return out


def _replace(ring: np.ndarray, i: int, j: int, pts: np.ndarray) -> np.ndarray:
    """``ring`` with the vertices strictly between ``i`` and ``j`` (forward) replaced by ``pts``."""
    rest = _path(len(ring), j, i, 1)  # from j round to i
    return np.vstack([ring[i : i + 1], pts.reshape(-1, 2), ring[[j, *rest]]])


def _slid(pieces, ix, x, y, a, p, q, d, h):
    """Pieces ``x`` and ``y`` with the cut from ``q`` to ``p`` slid to end at the tip ``a``."""
    X, Y = pieces[x], pieces[y]
    rx, ry = X.ring, Y.ring
    A, P, Q = rx[a], rx[p], rx[q]
    k = max(math.ceil(float(np.hypot(*(A - Q))) / h), 1)
    t = np.arange(1, k)[:, None] / k
    cut = Q + t * (A - Q)  # Q → A, inner points
    shore = rx[_path(len(rx), a, p, d)]  # A → P, inner points (X's order when d = 1)
    iy = {int(v): j for j, v in enumerate(ix.ids[y].tolist())}
    yq, yp = iy[int(ix.ids[x][q])], iy[int(ix.ids[x][p])]
    if d == 1:  # X: A, shore, P, C2, Q;  Y: Q, C2, P (forward)
        new_rx = _replace(rx, a, q, cut[::-1])
        new_ry = _replace(ry, yq, yp, np.vstack([cut, A[None], shore]))
    else:  # X: Q, C2, P, shore, A;  Y: P, C2, Q
        new_rx = _replace(rx, q, a, cut)
        new_ry = _replace(ry, yp, yq, np.vstack([shore[::-1], A[None], cut[::-1]]))
    cx = [A if np.array_equal(rx[c], P) else rx[c] for c in X.corners]
    cy = [A if np.array_equal(ry[c], P) else ry[c] for c in Y.corners]
    out = []
    for r, cs, pc in ((new_rx, cx, X), (new_ry, cy, Y)):
        idx = [int(np.flatnonzero((r == c).all(axis=1))[0]) for c in cs]
        if len(set(idx)) != 4:
            return None
        ang = _angles(r)
        ia = int(np.flatnonzero((r == A).all(axis=1))[0])
        iq = int(np.flatnonzero((r == Q).all(axis=1))[0])
        if not CORNER_ANGLES[0] <= ang[ia] <= CORNER_ANGLES[1] or ang[iq] < LEAST_ANGLE:
            return None
        out.append(Piece(r, tuple(sorted(idx)), pc.name))
    return out[0], out[1]
