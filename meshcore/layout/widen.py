r"""Blocks starved by a chain of counts: a band along one side, the rest its own block.

Integer cell counts must agree across every interface, so the count across a row of blocks
is one number from end to end.  Where the row widens — the water round an island beside a
narrow passage (one C-shaped block from one side of the passage round to the other), a wide
basin between narrow arms — the wide block gets the narrow ends' count across: cells many
times the asked size, far fewer cells than the area asks for (``round_lake(1021, "blob")``
at 3000 cells: a quarter).

The cure here, when the layout's cells fall below :data:`STARVED` × its area / h²: a block
whose count across does not suit its width or one of its ends is split into a **band** along
one of its long sides, as wide as one of its ends (so that end's count across suits it), and
the **rest**, farther than that from the side.  The band keeps the block's corners on it; the
rest meets the band along a cut line (the edge of the band's buffer) whose ends lie on the
block's boundary, and those ends become corners of the rest where it turns there, and
T-junctions on the band's side where the band runs straight on: the rest's counts no longer
follow the chain.  As wide as both ends, the rest meets neither (the water round an island);
as wide as the narrower, it meets the wider end (a basin opening from an arm).  Each round
tries both widths and both long sides of the most starved blocks and keeps the split that
brings the blocks' cells nearest their areas (:func:`_miss`), while a block stays starved or
overfull and a split helps.  Regular layouts (:func:`~meshcore.layout.auto_layout`'s
``regular``) are not split: Delft3D's domain decomposition couples whole block sides.
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from ..errors import TopologyError
from ..pointindex import point_keys
from ..segments import nearest_on_polyline
from .blocks import Piece, _line_work, block_counts, conform, weld

__all__ = ["STARVED", "widen_starved"]

#: A block whose cells are below this share of its own area / h² is starved (issue 12's lower
#: bound of the total cells; a block at half the cells has cells ~1.4 × the asked size each way).
STARVED = 0.5
#: The rest must hold at least this share of the block's area: a smaller one is not worth a
#: block and its corners (it would not change the counts much).
MIN_REST = 0.2
#: A cut end where either new block's angle is below this (degrees) makes a sliver, not a
#: corner: the cut leaves the boundary almost along it.  The rest of ``round_lake(1021)``'s
#: C-shaped block has its corners at 33° and 36° and gets a grid without folds, 96 % of its
#: nodes within 3°; 20° leaves room below that, and the grids of every split the generated
#: lakes made are measured in ``docs/lake-grids-journal.md``.
MIN_TIP = 20.0
#: A cut end where a ring's angle is above this (degrees; it turns by less than 45°) is a point
#: on one of its sides, not a corner: the band's side bends there.  45° is where
#: :func:`~.corners.choose_corners` starts reading a turn as a corner.
STRAIGHT = 135.0
#: ... and a ring with four corners already must not turn by more than 70° at a cut end (an
#: angle below this): a side that bends that much at one point is a corner in all but name,
#: its grid lines would kink there.
KINK = 110.0
#: A cut end closer than this many cell sizes to a chain end (a corner, a T-junction) is moved
#: onto it (``lake_with_islands(5, n_islands=1)``: a cut ending 0.1 cells beside a corner made
#: a chain of one cell between two of 25, a cross-interface area ratio of 111).
SNAP = 1.0
#: Blocks tried per round: the split that brings the blocks' cells nearest their areas wins.
CANDIDATES = 8
#: Rounds of splits (each splits one block): a layout has few starved blocks.
ROUNDS = 4


def _sides(pc: Piece) -> list[np.ndarray]:
    r, c = pc.ring, list(pc.corners)
    n = len(r)
    return [np.array([r[(c[k] + t) % n] for t in range((c[(k + 1) % 4] - c[k]) % n + 1)]) for k in range(4)]


def _length(line: np.ndarray) -> float:
    return float(np.hypot(*np.diff(line, axis=0).T).sum())


def _split(pc: Piece, cells: tuple[int, int], h: float, size: float, breaks: np.ndarray):
    """The band-and-rest splits of a starved piece (both widths, either long side), as
    ``(band ring, its forced corner points, rest ring, its forced corner points)``; ``breaks``:
    the points where chains end (block corners, T-junctions, cut ends on the shore)."""
    from shapely.geometry import LineString, Polygon

    sides = _sides(pc)
    P = Polygon(pc.ring)
    lengths = [_length(s) for s in sides]
    eps = 1e-9 * size
    corners = pc.ring[list(pc.corners)]
    out = []
    for d_ends, count in ((0, cells[0]), (1, cells[1])):  # ends: sides d, d+2 (count across them)
        ends = (d_ends, d_ends + 2)
        longs = ((d_ends + 1) % 4, (d_ends + 3) % 4)
        width = P.area / max(0.5 * (lengths[longs[0]] + lengths[longs[1]]), 1e-300)
        if 0.5 * width <= count * h <= 2.0 * min(lengths[e] for e in ends):
            continue  # the count across suits the block's width and both its ends
        # as wide as both ends (the rest meets neither: a C round an island), or as the narrower
        # (the rest meets the wider end: a basin widening from an arm)
        widths = {1.02 * lengths[e] for e in ends}
        for d, s in itertools.product(sorted(widths), longs):
            cut = _cut_line(P, LineString(sides[s]).buffer(d, quad_segs=16), eps)
            if cut is None:
                continue
            cut = _snapped(cut, breaks, SNAP * h)
            res = _rings(pc.ring, sides[s][[0, -1]], cut, eps)
            if res is None:
                continue
            band, rest = res
            B, R = Polygon(band), Polygon(rest)
            if not (B.is_valid and R.is_valid) or R.area < MIN_REST * P.area:
                continue
            if abs(B.area + R.area - P.area) > 1e-6 * P.area:
                continue
            forced = [_forced(ring, corners, cut, h) for ring in (band, rest)]
            if forced[0] is not None and forced[1] is not None:
                out.append((band, forced[0], rest, forced[1]))
    return out


def _forced(ring: np.ndarray, corners: np.ndarray, cut: np.ndarray, h: float):
    """The corners a new ring must have: the block's corners on it and the cut's ends where the
    ring turns (not a T on its side; one next to a block corner is that corner's turn, read at
    the cell size), the sharper first while it has fewer than four; None when a cut end makes
    a sliver (:data:`MIN_TIP`) or a kink in a side (:data:`KINK`)."""
    keys = {tuple(q) for q in ring}
    mine = [q for q in corners if tuple(q) in keys]
    ends = sorted((_angle_at(ring, _index(ring, q), h), i) for i, q in enumerate((cut[0], cut[-1])))
    if ends[0][0] < MIN_TIP:
        return None
    for a, i in ends:
        q = cut[0] if i == 0 else cut[-1]
        if a >= STRAIGHT or min((np.hypot(*(q - c)) for c in mine), default=np.inf) <= 1.5 * h:
            continue
        if len(mine) < 4:
            mine.append(q)
        elif a < KINK:
            return None
    return mine


def _index(ring: np.ndarray, q: np.ndarray) -> int:
    return int(np.argmin(np.hypot(*(ring - q).T)))


def _snapped(cut: np.ndarray, breaks: np.ndarray, tol: float) -> np.ndarray:
    """The cut with each end moved onto the nearest chain end within ``tol``: a cut ending a
    hair beside another block's corner would make a chain a fraction of a cell long."""
    cut = cut.copy()
    if len(breaks):
        for e in (0, -1):
            dist = np.hypot(*(breaks - cut[e]).T)
            k = int(np.argmin(dist))
            if dist[k] <= tol:
                cut[e] = breaks[k]
    return cut


def _cut_line(P, zone, eps: float):
    """The one line of the zone's boundary inside ``P``, as points, or None."""
    import shapely

    inside = shapely.line_merge(P.intersection(zone.boundary))
    parts = [g for g in getattr(inside, "geoms", [inside]) if g.geom_type == "LineString" and g.length > eps]
    parts = [g for g in parts if P.exterior.distance(g.interpolate(0.5, normalized=True)) > eps]
    if len(parts) != 1 or parts[0].is_ring:
        return None
    return np.asarray(parts[0].coords)


def _insert(ring: np.ndarray, q: np.ndarray, eps: float) -> tuple[np.ndarray, int]:
    """``ring`` with the point ``q`` (on one of its edges) inserted, and its index."""
    k = nearest_on_polyline(ring, q, closed=True)[1]
    if np.hypot(*(ring[k] - q)) <= eps:
        return ring, k
    if np.hypot(*(ring[(k + 1) % len(ring)] - q)) <= eps:
        return ring, (k + 1) % len(ring)
    return np.insert(ring, k + 1, q, axis=0), k + 1


def _rings(ring: np.ndarray, keep: np.ndarray, cut: np.ndarray, eps: float):
    """The two rings a cut line from one boundary point of ``ring`` to another makes: the one
    that holds the points ``keep`` (the band: the ends of its side) and the other (the rest),
    or None when the cut separates them."""
    r, _ = _insert(ring, cut[0], eps)
    r, j = _insert(r, cut[-1], eps)
    _, i = _insert(r, cut[0], eps)  # its index after the second insertion
    n = len(r)
    inner = cut[1:-1]
    walk_ij = r[[(i + t) % n for t in range((j - i) % n + 1)]]  # along the ring from cut[0] to cut[-1]
    walk_ji = r[[(j + t) % n for t in range((i - j) % n + 1)]]
    first = np.vstack([walk_ij, inner[::-1]])  # closes back along the cut
    second = np.vstack([walk_ji, inner])
    keys = {tuple(q) for q in keep}
    n_ij = sum(tuple(q) in keys for q in walk_ij[1:-1])
    n_ji = sum(tuple(q) in keys for q in walk_ji[1:-1])
    if max(n_ij, n_ji) != len(keys):
        return None
    return (first, second) if n_ij == len(keys) else (second, first)


def _angle_at(ring: np.ndarray, i: int, h: float) -> float:
    """The ring's interior angle at vertex ``i``, in degrees, between the points one cell size
    along the ring on either side (a cut line that leaves the shore almost along it makes a
    sliver, not a corner)."""
    n = len(ring)
    ahead = np.roll(ring, -i, axis=0)
    out = []
    for seq in (np.vstack([ahead, ahead[:1]]), np.vstack([ahead[:1], ahead[::-1]])):
        s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(seq, axis=0).T))])
        k = min(int(np.searchsorted(s, min(h, 0.25 * s[-1]))), n)
        out.append(seq[k] - seq[0])
    a, b = out
    ang = math.degrees(math.atan2(a[0] * b[1] - a[1] * b[0], a @ b))
    return ang % 360.0


def _pieces(rings: list[np.ndarray], corner_pts: list, size: float) -> list[Piece] | None:
    rings = weld(rings, 1e-9 * size)
    if len(rings) != len(corner_pts):
        return None
    rings = conform(rings, 1e-9 * size)
    if not _clean(rings):
        return None
    out: list[Piece] = []
    for r, cs in zip(rings, corner_pts, strict=True):
        a, b, c, d = sorted(int(np.argmin(np.hypot(*(r - q).T))) for q in cs)
        if len({a, b, c, d}) != 4:
            return None
        out.append(Piece(r, (a, b, c, d), f"b{len(out)}"))
    return out


def _clean(rings: list[np.ndarray]) -> bool:
    """Every ring a valid polygon and every edge used by at most two rings (no sliver between a
    cut line and the side it grazes)."""
    from shapely.geometry import Polygon

    from .outline import _edge_use

    if not all(Polygon(r).is_valid for r in rings):
        return False
    return max(_edge_use([Piece(r, (0, 1, 2, 3)) for r in rings]).values()) <= 2


def _total(pieces: list[Piece], cells, h: float) -> float:
    """The layout's cells over its area / h²."""
    from shapely.geometry import Polygon

    area = sum(Polygon(p.ring).area for p in pieces)
    return sum(a * b for a, b in cells) * h * h / area


def _shares(pieces: list[Piece], cells, h: float) -> tuple[np.ndarray, np.ndarray]:
    """Every block's cells over its own area / h², and its area."""
    from shapely.geometry import Polygon

    area = np.array([Polygon(p.ring).area for p in pieces])
    return np.array([a * b for a, b in cells]) * h * h / area, area


def _miss(pieces: list[Piece], cells, h: float) -> float:
    """How far the blocks' cells lie from their areas / h²: the area-weighted mean of
    ``|log share|`` (a split that feeds a starved block by overfilling a narrow neighbour —
    the count along a chain moves both — pays for both)."""
    share, area = _shares(pieces, cells, h)
    return float(np.sum(area * np.abs(np.log(np.maximum(share, 1e-300)))) / area.sum())


def _corners(ring: np.ndarray, pts: list, h: float):
    """Four corner points of ``ring`` that include ``pts`` (:func:`~.corners.choose_corners`), or None."""
    from .corners import choose_corners
    from .split import forced_indices

    forced = forced_indices(ring, pts)
    rc, _cost = choose_corners(ring, 1.5 * h, forced=forced)
    if rc is None or not set(forced) <= set(rc):
        return None
    return [ring[i] for i in rc]


def widen_starved(pieces: list[Piece], cells: list[tuple[int, int]], h: float, *, multiple: int = 1):
    """The pieces and their counts with starved blocks split into a band and the rest (see the
    module's doc); the pieces as they are when no split brings the cells nearer the asked ones."""
    xy = np.vstack([p.ring for p in pieces])
    size = math.hypot(*(xy.max(axis=0) - xy.min(axis=0)))
    if _total(pieces, cells, h) >= STARVED:
        return pieces, cells
    for _ in range(ROUNDS):
        share, _area = _shares(pieces, cells, h)
        if share.min() >= STARVED and share.max() <= 1.0 / STARVED:
            break
        miss = _miss(pieces, cells, h)
        ends = _line_work(pieces)[3]  # where chains end
        best = None
        # the starved blocks, and others below their share of cells (a block fed by the first
        # split whose chain overfills a narrow neighbour), the most starved first
        for k in np.argsort(share)[:CANDIDATES]:
            if share[k] >= 1.0:
                break
            ring = pieces[k].ring
            breaks = ring[[i for i, q in enumerate(point_keys(ring)) if q in ends]]
            for band_ring, band_forced, rest_ring, rest_forced in _split(pieces[k], cells[k], h, size, breaks):
                picked = [_corners(ring, pts, h) for ring, pts in ((band_ring, band_forced), (rest_ring, rest_forced))]
                if picked[0] is None or picked[1] is None:
                    continue
                others = [p for i, p in enumerate(pieces) if i != k]
                new = _pieces(
                    [p.ring for p in others] + [band_ring, rest_ring],
                    [[p.ring[c] for c in p.corners] for p in others] + picked,
                    size,
                )
                if new is None:
                    continue
                try:
                    new_cells = block_counts(new, h, multiple=multiple)
                except TopologyError:
                    continue
                m = _miss(new, new_cells, h)
                if m < miss and (best is None or m < best[0]):
                    best = (m, new, new_cells)
        if best is None:
            break
        _, pieces, cells = best
    return pieces, cells
