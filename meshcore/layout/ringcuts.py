r"""More cuts from an island, for one index space: at least four cut ends on every island.

A single-domain grid (``auto_layout(single=True)``) needs every island's ring of blocks to turn
exactly once (:data:`~.frames.ONE_TURN`): ``C − 2E = −4`` with every vertex on the island adding
``c − 2(m − 1)`` of 0 or −1.  A vertex where one block alone touches the island (``m = 1``) adds
0 only without a corner; −1 comes only from a cut end (``m = 2``) where one of its two blocks has
a corner and the other passes straight on (or a node of three blocks with three corners).  An
island needs four such vertices — the corners of its hole in index space — and so **at least
four cut ends**.  The layout frees an island with two cuts (:func:`~.regions.partition`), and
chords and splits may add more; where they leave two or three, no choice of corners
(:func:`~.frames.close_frames`) can turn the ring once, and the lake was refused (one island
included: a lobed lake whose single island sits in its middle).

:func:`ring_cuts` adds straight cuts from such an island to the nearest other shore until it has
four ends, each leaving the island where it is farthest (along the island) from the ends it has:
the blocks round the island become a frame whose sides turn once round it.  It is a fallback
(:func:`~meshcore.layout.auto_layout` draws with it only when no layout without it fits), so the
layouts that fit without it stay as they are.
"""

from __future__ import annotations

import math

import numpy as np

from .regions import _apart, _sights, _without_wedges

__all__ = ["RING_ENDS", "ring_cuts"]

#: Cut ends an island needs for its ring of blocks to turn once (the four corners of its hole).
RING_ENDS = 4

#: Points round the island a new cut may leave from.
_STARTS = 64

#: A new cut leaves the island at least this fraction as far (along it) from the ends it has as
#: the farthest start does: the four ends spread round it (at one half, the shortest cut of
#: ``round_lake(0, n_islands=1)``, an island near the shore, left near the three it had).
_FAR = 0.75


def ring_cuts(poly, cuts: list[np.ndarray], sigma: float, least: int = RING_ENDS, ends=None) -> list[np.ndarray]:
    """Straight cuts (each a (2, 2) array) from every island of ``poly`` with fewer than ``least``
    cut ends on it (``ends``: the points where blocks meet on the islands; default the ends of
    ``cuts``) to the nearest point of another shore (the outer shore or another
    island) or along the island's normal to the first shore or cut (a T), until it has ``least``.

    Each new cut is the shortest that stays in the water, crosses no cut, meets both shores at no
    less than :data:`~.regions.MIN_CORNER_ANGLE` and keeps ``2 sigma`` from every other cut's
    ends, among those leaving the island at least :data:`_FAR` as far (along it) from its ends as
    the farthest one does; the conditions are dropped in turn (angles and gap first) when none meets
    them.  An island with no cut at all in sight keeps what it has.

    Examples
    --------
    >>> from shapely.geometry import Point
    >>> lake = Point(0, 0).buffer(10.0).difference(Point(0, 0).buffer(3.0))
    >>> first = np.array([[3.0, 0.0], [10.0, 0.0]])
    >>> second = np.array([[-3.0, 0.0], [-10.0, 0.0]])
    >>> more = ring_cuts(lake, [first, second], sigma=0.5)
    >>> len(more)
    2
    >>> sorted(int(np.sign(c[0, 1])) for c in more)  # from the island's top and bottom
    [-1, 1]
    >>> [bool(abs(c[0, 0]) < 1.0) for c in more]
    [True, True]
    """
    from shapely.geometry import Point

    rings = [poly.exterior, *poly.interiors]
    size = math.sqrt(poly.area)
    room = poly.buffer(1e-9 * size)
    eps = 1e-7 * size
    new: list[np.ndarray] = []
    for k in range(1, len(rings)):
        hole = rings[k]
        total = hole.length

        def along(p, hole=hole) -> float:
            return float(hole.project(Point(float(p[0]), float(p[1]))))

        pts = [p for c in cuts for p in (c[0], c[-1])] if ends is None else list(ends)
        have = [along(p) for p in pts if hole.distance(Point(float(p[0]), float(p[1]))) <= eps]
        while len(have) < least:
            cut = _next_cut(hole, k, rings, room, [*cuts, *new], have, total, sigma)
            if cut is None:
                break
            new.append(cut)
            have.append(along(cut[0]))
    return new


def _normal_ray(hole, s: float, room, lines, reach: float):
    """The segment from the point ``s`` (arc length) of ``hole`` along its normal into the water to
    the first shore or cut it meets (ending on a cut: a T), or None."""
    from shapely.geometry import LineString, Point

    d = 1e-3 * hole.length
    a = np.asarray(hole.interpolate((s - d) % hole.length).coords[0])
    b = np.asarray(hole.interpolate((s + d) % hole.length).coords[0])
    p = np.asarray(hole.interpolate(s).coords[0])
    t = b - a
    if not np.hypot(*t):
        return None
    n = np.array([-t[1], t[0]]) / np.hypot(*t)
    if not room.contains(Point(*(p + d * n))):
        n = -n
        if not room.contains(Point(*(p + d * n))):
            return None
    hit = LineString([p + 1e-9 * reach * n, p + reach * n]).intersection(lines)
    pts = np.asarray(shapely_points(hit))
    if not len(pts):
        return None
    q = pts[np.argmin(np.hypot(*(pts - p).T))]
    seg = np.array([p, q])
    return seg if room.covers(LineString(seg)) else None


def shapely_points(geom) -> list:
    """The points of a shapely intersection (points, lines: their ends)."""
    out: list = []
    for g in getattr(geom, "geoms", [geom]):
        if g.is_empty:
            continue
        out += list(g.coords) if g.geom_type in ("Point", "LineString") else []
    return out


def _next_cut(hole, k: int, rings, room, cuts: list[np.ndarray], ends: list[float], total: float, sigma: float):
    """The next cut from ring ``k`` (``hole``; ``ends``: where cuts end on it, by arc length)."""

    def gap(s: float) -> float:
        return min((min(abs(s - e), total - abs(s - e)) for e in ends), default=total)

    import shapely
    from shapely.geometry import LineString

    lines = shapely.union_all([LineString(r.coords) for r in rings] + [LineString(c) for c in cuts])
    reach = 2.0 * math.hypot(*np.subtract(*np.reshape(rings[0].bounds, (2, 2))[::-1]))
    cand = []
    for s in np.linspace(0.0, total, _STARTS, endpoint=False):
        g = gap(float(s))
        p = hole.interpolate(float(s))
        for length, seg in _sights(p, k, rings, room, cuts):
            cand.append((g, length, seg))
        ray = _normal_ray(hole, float(s), room, lines, reach)
        if ray is not None:
            cand.append((g, float(np.hypot(*(ray[1] - ray[0]))), ray))
    if not cand:
        return None
    far = max(g for g, _, _ in cand)
    kept = sorted(((length, seg) for g, length, seg in cand if g >= _FAR * far and g > 0), key=lambda t: t[0])
    if not kept:
        return None
    good = _without_wedges(kept, hole, rings, sigma) or kept
    good = _apart(good, cuts, 2 * sigma) or good
    return good[0][1]
