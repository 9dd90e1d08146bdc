r"""Index frames that close up: the corners a regular layout needs round every island.

Delft3D's domain decomposition couples an M grid line only to an M line (see
:mod:`meshcore.io.delft3d_dd`).  Each block's index directions ``(i, j)`` are a frame; across
an interface the writer may turn a block by quarter turns so that the frames agree.  That is
possible for every block at once only when, walking round any loop of blocks, the frame comes
back unturned: its **holonomy** is zero (mod four quarter turns).

The holonomy is read off the block corners.  At a vertex ``v`` let ``m`` be the number of
blocks that have it on their boundary and ``c`` how many of them have a corner there; each
block spans a quarter turn of the frame at its corner and a half turn elsewhere, so the blocks
round ``v`` span ``q = 2m − c`` quarter turns:

* a vertex inside the water needs ``q = 4`` (four corners, a T-junction's ``2 + 1 + 1``, or a
  cut's ``2 + 2``); a node where three or five blocks meet (``q = 3`` or ``5``) turns the
  frame by a quarter;
* going round an island the frame turns by ``Σ (2 − q)`` quarter turns over its vertices
  (a straight shore spans a half turn: ``q = 2``), i.e. by ``C − 2 E`` with ``C`` the block
  corners on the island and ``E = Σ (m − 1)`` the cut ends there.  A ring of blocks closes
  up when that is ``≡ 0 (mod 4)``.  Round the outer shore it then closes by itself (the
  turns of all loops add up to that of the whole outline).

A ring of blocks round an island is left turned by a quarter when, say, a cut leaves the
island continuing one of its sides (one block has a corner there, its neighbour none:
``q = 3``), or a block takes a corner on a rounded tip of the island.

:func:`frame_defects` finds the islands and nodes that do not close.  :func:`close_frames`
re-chooses corners where they do not: every piece at an island or a defect may move one of its
corners to another of its vertices where a cut ends, blocks meet or the shore bends; a small
integer program (HiGHS) picks the moves that close every island and node at the least corner
cost (:func:`~.corners.set_cost`).  Layouts that close already are left as they are.
"""

from __future__ import annotations

import itertools
from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np

from ..pointindex import PointIndex
from .blocks import Piece
from .corners import OWN_TURN, SHARP, _arclength_closed, raw_turning, set_cost, turning

__all__ = ["FrameDefect", "close_frames", "corner_flaws", "frame_defects", "straight_corners"]


@dataclass(frozen=True, slots=True)
class FrameDefect:
    """A loop of blocks whose index frame comes back turned by ``turn`` quarter turns:
    round an island (``kind == "island"``, ``where`` a point of its shore; ``"ring"``: with
    ``single``, a ring round an island that does not turn exactly once) or round a node
    inside the water where blocks do not meet four corners to four (``kind == "node"``)."""

    kind: str
    where: tuple[float, float]
    turn: int

    def note(self) -> str:
        x, y = self.where
        if self.kind == "ring":
            return (
                f"the ring of blocks round the island near ({x:.8g}, {y:.8g}) cannot close in one index space: "
                f"it does not turn exactly once round it (a block with a corner alone on the island, a cut "
                f"ending on it without a block corner, or the block corners on it minus twice the cut ends "
                f"there not {ONE_TURN})"
            )
        if self.kind == "island":
            return (
                f"the blocks round the island near ({x:.8g}, {y:.8g}) come back turned by {self.turn} quarter "
                f"turn{'s' if self.turn > 1 else ''} (their corners on it minus twice the cut ends there "
                f"is not a multiple of 4)"
            )
        return (
            f"the blocks at ({x:.8g}, {y:.8g}) do not meet four corners to four: their index directions come "
            f"back turned by {self.turn} quarter turn{'s' if self.turn > 1 else ''} round it"
        )


@dataclass(frozen=True, slots=True, eq=False)
class _Vertices:
    """The pieces' vertices numbered: ``m`` blocks and ``c`` corners at each, which boundary
    loop each lies on (``-1``: inside the water; ``0``: the outer shore)."""

    index: PointIndex
    m: np.ndarray
    c: np.ndarray
    loop: np.ndarray


def _vertices(pieces: list[Piece]) -> _Vertices:
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    ix = PointIndex([pc.ring for pc in pieces])
    n = len(ix)
    m = np.zeros(n, dtype=int)
    c = np.zeros(n, dtype=int)
    edges = []
    for ids, pc in zip(ix.ids, pieces, strict=True):
        m[np.unique(ids)] += 1
        c[np.unique(ids[list(pc.corners)])] += 1
        e = np.sort(np.column_stack([ids, np.roll(ids, -1)]), axis=1)
        edges.append(e[e[:, 0] != e[:, 1]])
    e, used = np.unique(np.vstack(edges), axis=0, return_counts=True)
    bnd = e[used == 1]  # an edge of one piece only: on a shore
    loop = np.full(n, -1)
    if len(bnd):
        g = coo_matrix((np.ones(len(bnd)), (bnd[:, 0], bnd[:, 1])), shape=(n, n))
        _, lab = connected_components(g, directed=False)
        on = np.unique(bnd)
        # the lexicographically last point (largest x) is on the outer shore: its loop is 0
        outer = lab[on[-1]]
        labels = {outer: 0}
        for v in on:
            labels.setdefault(lab[v], len(labels))
            loop[v] = labels[lab[v]]
    return _Vertices(ix, m, c, loop)


def _island_turns(v: _Vertices, single: bool = False) -> dict[int, int]:
    """Quarter turns (mod 4) of the frame round every island loop; ``single``: how far ``C − 2E``
    is from :data:`ONE_TURN` (not mod 4)."""
    out: dict[int, int] = {}
    for k in range(1, int(v.loop.max(initial=0)) + 1):
        on = v.loop == k
        each = v.c[on] - 2 * (v.m[on] - 1)  # what every vertex adds
        turns = int(each.sum())
        odd = int(((each != 0) & (each != -1)).sum())  # a lone corner (+1), a cut end passed by both (-2)
        out[k] = abs(turns - ONE_TURN) + odd if single else turns % 4
    return out


#: ``C − 2E`` round an island whose ring of blocks closes in one ``(I, J)`` index space: the ring
#: turns once round the island there (the eight blocks of a 3 × 3 lattice round its middle cell:
#: 12 corners and 8 cut ends on the hole).  0 (≡ 0 mod 4, enough for Delft3D's domain
#: decomposition) is a ring of blocks that runs straight in index space and never comes back
#: (an O-grid's), −8 one that winds twice.  Every vertex adds ``c − 2(m − 1)``: −1 where the
#: island's hole in index space has a corner, +1 where one block alone has a corner on the island
#: (the hole turns back there), −2 where a cut ends on the island and neither block has a corner
#: (the hole folds back on itself).  With ``single`` every vertex adds 0 or −1: the hole is then a
#: rectangle whose sides are whole chains; with a +1 or a −2 the counts that close the ring could
#: give the hole no width (seen: a block wrapped round an island's end, the block across it placed
#: on top of it in index space: "reach index node at two places").
ONE_TURN = -4


def frame_defects(pieces: list[Piece], *, single: bool = False) -> list[FrameDefect]:
    """The islands and inner nodes round which the blocks' index frames do not close up
    (``single``: islands whose ring does not turn once, :data:`ONE_TURN`, as one index space needs)."""
    v = _vertices(pieces)
    out = []
    for k, turn in _island_turns(v, single).items():
        if turn:
            p = v.index.points[np.flatnonzero(v.loop == k)[0]]
            out.append(FrameDefect("ring" if single else "island", (float(p[0]), float(p[1])), turn))
    q = 2 * v.m - v.c
    for i in np.flatnonzero((v.loop < 0) & (q != 4)):
        p = v.index.points[i]
        out.append(FrameDefect("node", (float(p[0]), float(p[1])), int((4 - q[i]) % 4)))
    return out


def straight_corners(pieces: list[Piece]) -> list[tuple[float, float]]:
    """The block corners at a vertex of a straight shore: on the shore (of one block only), both
    its ring neighbours on the shore too, turning by less than :data:`~.corners.OWN_TURN`; the
    corner cell there has an angle of 180° (:data:`~meshcore.quality.cells.STRAIGHT_SINE`)."""
    v = _vertices(pieces)
    out = []
    for ids, pc in zip(v.index.ids, pieces, strict=True):
        raw = raw_turning(pc.ring)
        n = len(ids)
        for i in pc.corners:
            near = ids[[i - 1, i, (i + 1) % n]]
            if (v.loop[near] >= 0).all() and v.m[ids[i]] == 1 and raw[i] < OWN_TURN:
                out.append((float(pc.ring[i][0]), float(pc.ring[i][1])))
    return out


def corner_flaws(pieces: list[Piece], sigma: float) -> tuple[int, int, int]:
    """How many block corners of ``pieces`` are at a vertex of a straight shore
    (:func:`straight_corners`), how many borrow the turn of a sharper bend beside them (a shore
    vertex within ``sigma / 2`` of arc length turning more than :data:`_BESIDE` beyond it, or
    beyond :data:`~.corners.SHARP`), and how many blocks have two sides shorter than ``sigma``
    (``testing.lake_with_islands(28)`` at 15 000 cells folded 51 cells in such a block)."""
    straight = len(straight_corners(pieces))
    borrowed = short = 0
    for pc in pieces:
        s, total = _arclength_closed(pc.ring)
        cs = sorted(pc.corners)
        borrowed += int((~_bends(pc.ring, np.asarray(cs), s, total, sigma, 2, own=False)).sum())
        pos = s[cs]
        short += int((np.diff(np.r_[pos, pos[0] + total]) < sigma).sum() >= 2)
    return straight, borrowed, short


#: At most this many shore bends per piece are tried as new corners (the sharpest, one per
#: corner window): a corner moved off an island goes where the shore turns most.
_BENDS = 6

#: The least turning (degrees, at the corners' scale) of a vertex that becomes a corner: a
#: corner on a straight line is a cell of 180°.  Half of :data:`~.corners.SHARP`: on 20 lakes
#: with islands (``testing.lake_with_islands(0..19)``, 2000 cells) 19 closed with it, 17 with
#: ``SHARP`` itself, 16 with no limit (a corner at a T on a straight side can also make the
#: cells uncountable, and the next choice is then tried).
_LEAST_TURN = SHARP / 2

#: Corners one piece may move (two: a block between two islands, or an island and a node, may
#: have to give one corner to each).
_MOVES = 2

#: Added to the cost of every piece whose corners change (the corner cost of one corner 10°
#: off a right angle, in squared degrees): of equally good choices, the fewest changed blocks.
_CHANGE = 100.0

#: Added to the cost of a choice for every side shorter than ``sigma`` that it gives a piece:
#: more than four corners on straight lines (``4 × 3 × 90²``), so such a choice is taken only
#: when none without closes the frames.  Two corners a fraction of a cell apart (one vertex off
#: a cut's end or an island's tip, where the turning at ``sigma`` is borrowed) make a side of
#: at least four cells a fraction of a cell long; costed only as a corner on a straight line,
#: ``testing.lake_with_islands(28)`` at 15 000 cells (regular) got a 4 × 92 block with two
#: such sides at an island's tip and 51 folded cells there (0 with this).
_SHORT = 1.0e5


def _own_turning(ring: np.ndarray, sigma: float, t: np.ndarray, s: np.ndarray, total: float) -> np.ndarray:
    """The turning a corner's cell would see at every vertex of a piece: ``t`` (the turning at
    the corners' scale ``sigma``), but no more than the turning at the scale of the corner cell
    (``sigma / 3``: half a cell each way) and, where a vertex within ``sigma / 2`` of arc
    length bends more by itself, no more than the vertex's own bend.

    Read at ``sigma`` alone, the vertices beside a sharp bend (a cut's end, an island's tip, a
    point repeated a hair away) borrow its turn (62–83°); a corner moved there sits a fraction
    of a cell from the bend, with a straight or reflex angle of its own, and its cells fold.
    Seen on generated lakes with islands (``testing.lake_with_islands(4)`` and ``(5)``,
    2000 cells, regular): each of their folds sat at such a corner (own turning −9 to 2°, one
    vertex from a cut end turning 101–119°).  Costed by what they are, they are taken only when
    no other move closes the frames (excluded, 11 of 62 generated island lakes no longer
    closed, against 1).
    """
    raw = raw_turning(ring)
    seen = np.where(t > 0, np.minimum(t, np.maximum(turning(ring, sigma / 3), 0.0)), t)
    for i in np.flatnonzero(seen > 0):
        d = np.abs(s - s[i])
        if raw[np.minimum(d, total - d) <= 0.5 * sigma].max() > raw[i]:
            seen[i] = min(seen[i], max(raw[i], 0.0))
    return seen


#: A shore vertex beside one that turns more than this (degrees) beyond its own turning (or
#: :data:`~.corners.SHARP`), within ``sigma / 2`` of arc length, borrows that bend's turn at the
#: corners' scale (:func:`_bends`).
_BESIDE = 30.0


def _bends(
    ring: np.ndarray, at: np.ndarray, s: np.ndarray, total: float, sigma: float, level: int, own: bool = True
) -> np.ndarray:
    """Which shore vertices ``at`` of closed ``ring`` may take a corner moved there: ``level`` 0
    all; 1 those that turn by :data:`~.corners.OWN_TURN` or more themselves (at a vertex of a
    straight edge the corner cell has an angle of 180°, a triangle:
    :data:`~meshcore.quality.cells.STRAIGHT_SINE`); 2 of those, the bends of their own: no vertex
    within ``sigma / 2`` of arc length turns more than :data:`_BESIDE` beyond it (a corner a
    fraction of a cell from a sharper bend, whose turn it borrows at ``sigma``; with ``own``
    False, only that).

    Regular layouts of generated lakes with islands closed their frames with corners on straight
    island shores beside a cut's end or a bend (``testing.lake_with_islands(5)`` at 2000 cells:
    0.82 cells from a cut end turning 106°, a straight cell; with level 1 there, a corner 0.04
    cells beside a bend of 83°, turning 2° itself); the bends themselves stay candidates.  Level
    2 closes fewer frames (``lake_with_islands(0)``, ``(5)``, ``(8)`` at 10 000 cells: not at all),
    so :func:`~.build._closed` tries the levels in turn.
    """
    if level <= 0:
        return np.ones(len(at), dtype=bool)
    raw = raw_turning(ring)
    out = raw[at] >= OWN_TURN if own else np.ones(len(at), dtype=bool)
    if level >= 2:
        for k, i in enumerate(np.asarray(at, dtype=int).tolist()):
            d = np.abs(s - s[i])
            out[k] &= raw[np.minimum(d, total - d) <= 0.5 * sigma].max() <= max(raw[i], SHARP) + _BESIDE
    return out


def _candidates(
    pc: Piece, ids: np.ndarray, v: _Vertices, sigma: float, own: bool = True, level: int = 0, least: float = _LEAST_TURN
) -> list[tuple[tuple[int, ...], float]]:
    """``(corners, cost)`` of the piece's current corners (0) and of every move of one or two
    corners to other vertices where blocks meet (a cut end, a T) or the shore bends (the rise
    of :func:`~.corners.set_cost`, plus :data:`_CHANGE` per corner).

    A new corner turns by at least ``least`` (:data:`_LEAST_TURN`); shore bends (of ``level``,
    :func:`_bends`) are taken one per ``sigma`` of arc
    length, the sharpest first; the costs are read with the turning the corner cells
    see (:func:`_own_turning`; with ``own`` False, the turning at ``sigma``); a choice that
    makes a side shorter than ``sigma`` costs :data:`_SHORT` more.
    """
    ring = pc.ring
    meet = np.flatnonzero(v.m[ids] >= np.where(v.loop[ids] < 0, 3, 2))
    s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(ring, axis=0).T))])
    total = s[-1] + float(np.hypot(*(ring[0] - ring[-1])))
    t = turning(ring, sigma)
    seen = _own_turning(ring, sigma, t, s, total) if own else t

    def apart(i: int, others) -> bool:
        return all(min(abs(s[i] - s[j]), total - abs(s[i] - s[j])) > sigma for j in others)

    shore = np.flatnonzero((v.loop[ids] >= 0) & (v.m[ids] == 1) & (t >= least))
    shore = shore[_bends(ring, shore, s, total, sigma, level)]
    bends: list[int] = []
    for i in shore[np.argsort(-t[shore])]:
        if apart(int(i), bends):
            bends.append(int(i))
        if len(bends) >= _BENDS:
            break
    here = tuple(sorted(pc.corners))
    now = set_cost(ring, sigma, here, t=seen)

    def short(cs: tuple[int, ...]) -> int:
        pos = s[list(cs)]
        return int((np.diff(np.r_[pos, pos[0] + total]) < sigma).sum())

    had = short(here)
    options = {here: 0.0}
    to = sorted(({int(i) for i in meet if t[i] >= least} | set(bends)) - set(here))
    for k in range(1, _MOVES + 1):
        for a in itertools.combinations(here, k):
            for b in itertools.combinations(to, k):
                new = tuple(sorted({*here} - {*a} | {*b}))
                if new not in options:  # what the move costs; one that lowers the cost is no reason to move
                    rise = max(set_cost(ring, sigma, new, t=seen) - now, 0.0)
                    options[new] = rise + k * _CHANGE + _SHORT * max(short(new) - had, 0)
    return list(options.items())


def close_frames(
    pieces: list[Piece],
    sigma: float,
    *,
    tries: int = 3,
    own: bool = True,
    single: bool = False,
    bends: int = 0,
    least: float = _LEAST_TURN,
) -> Iterator[list[Piece]]:
    """The pieces with corners re-chosen so that every island and inner node closes up
    (:func:`frame_defects` empty): up to ``tries`` choices, the one of least corner cost first
    (a caller that cannot count the cells of one takes the next).  Yields nothing when the
    pieces close already or when no moves of one corner per piece make them close.  ``own``:
    corners cost the turning their cells see (:func:`_own_turning`); False: the turning at
    ``sigma`` (a fallback: its choices close some layouts whose ``own`` ones cannot be counted);
    ``single``: every island's ``C − 2E`` is :data:`ONE_TURN` (one index space), not any multiple of 4;
    ``bends``: which shore vertices a corner may move to (:func:`_bends`: 0 every bend at ``sigma``,
    1 those that turn themselves, 2 bends of their own); ``least``: the least turning of a new
    corner (:data:`_LEAST_TURN`; lower: a fallback for rings that close in no other way)."""
    from scipy.optimize import Bounds, LinearConstraint, milp

    defects = frame_defects(pieces, single=single)
    if not defects:
        return
    v = _vertices(pieces)
    bad = {i for d in defects if d.kind == "node" for i in v.index.find([d.where]).tolist()}
    movable = [k for k, ids in enumerate(v.index.ids) if (v.loop[ids] > 0).any() or bool(bad & set(ids.tolist()))]
    cand = {k: _candidates(pieces[k], v.index.ids[k], v, sigma, own, bends, least) for k in movable}
    cols = [(k, cs, cost) for k in movable for cs, cost in cand[k]]
    islands = sorted(_island_turns(v))
    nx, nz = len(cols), len(islands)
    # the corners every vertex gets: fixed pieces' as they are, movable ones' by their choice
    fixed_c = v.c.copy()
    for k in movable:
        fixed_c[v.index.ids[k][list(pieces[k].corners)]] -= 1
    touched: dict[int, list[int]] = {}
    for j, (k, cs, _) in enumerate(cols):
        for i in v.index.ids[k][list(cs)].tolist():
            touched.setdefault(i, []).append(j)
    rows, want = [], []

    def equal(cols_of: list[int], value: float, z: int | None = None) -> None:
        r = np.zeros(nx + nz)
        np.add.at(r, cols_of, 1.0)
        if z is not None:
            r[nx + z] = -4.0
        rows.append(r)
        want.append(value)

    for k in movable:  # one choice per piece
        equal([j for j, col in enumerate(cols) if col[0] == k], 1.0)
    for i in sorted({i for i in touched if v.loop[i] < 0} | bad):  # q = 2m − c = 4 inside the water
        equal(touched.get(i, []), float(2 * v.m[i] - 4 - fixed_c[i]))
    for z, k in enumerate(islands):  # C − 2E = 4 z round every island
        on = v.loop == k
        equal(
            [j for i in np.flatnonzero(on).tolist() for j in touched.get(i, [])],
            float(2 * (v.m[on] - 1).sum() - fixed_c[on].sum()),
            z,
        )
    cuts: list[np.ndarray] = []
    lo: list[float] = []
    hi: list[float] = []
    if single:  # every island vertex adds 0 or -1 (see ONE_TURN): c in [2(m - 1) - 1, 2(m - 1)]
        for i in np.flatnonzero(v.loop > 0).tolist():
            r = np.zeros(nx + nz)
            np.add.at(r, touched.get(i, []), 1.0)
            cuts.append(r)
            lo.append(float(2 * (v.m[i] - 1) - 1 - fixed_c[i]))
            hi.append(float(2 * (v.m[i] - 1) - fixed_c[i]))
    cost = np.concatenate([[col[2] for col in cols], np.zeros(nz)])
    big = 4.0 * len(v.m)
    lb = np.concatenate([np.zeros(nx), np.full(nz, ONE_TURN / 4 if single else -big)])
    ub = np.concatenate([np.ones(nx), np.full(nz, ONE_TURN / 4 if single else big)])
    for _ in range(tries):
        low = np.array(want + lo + [-np.inf] * (len(cuts) - len(lo)), dtype=float)
        res = milp(
            cost,
            constraints=LinearConstraint(np.array(rows + cuts), low, np.array(want + hi, dtype=float)),
            integrality=np.ones(nx + nz),
            bounds=Bounds(lb, ub),
            options={"time_limit": 60.0},
        )
        if res.x is None or res.status not in (0, 1):
            return
        chosen = np.flatnonzero(np.rint(res.x[:nx]) == 1)
        out = list(pieces)
        for j in chosen.tolist():
            k, cs, _ = cols[j]
            out[k] = Piece(pieces[k].ring, (cs[0], cs[1], cs[2], cs[3]), pieces[k].name)
        yield out
        r = np.zeros(nx + nz)  # the next choice differs from this one in at least one piece
        r[chosen] = 1.0
        cuts.append(r)
        hi.append(float(len(chosen) - 1))
