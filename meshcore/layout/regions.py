r"""Regions: the water split by cut lines, each a simple polygon that will become blocks.

:func:`partition` inserts the ends of every cut exactly into the shore rings (and into other
cuts they end on), nodes the line work with shapely and polygonises it.  A region is a
counter-clockwise ring of points; the cut ends are ordinary vertices of it, so neighbouring
regions share their cut lines vertex for vertex.
"""

from __future__ import annotations

import math

import numpy as np

from ..segments import feet

__all__ = ["partition", "snap_to_rings"]

#: The narrowest angle (degrees, read at the corners' scale) an island cut may make with a
#: shore: a cut that meets a ring at a grazing angle leaves a wedge, a block corner of a few
#: degrees whose cells cannot be orthogonal (nor, on the coarse levels, convex).
MIN_CORNER_ANGLE = 30.0


def snap_to_rings(rings: list[np.ndarray], cuts: list[np.ndarray], eps: float):
    """Insert every cut end into the nearest ring (or earlier cut) exactly; return new rings, cuts.

    Ends within ``eps`` of an existing vertex snap to it.  The nearest segment is the first at
    the least distance, the rings before the cuts, in order: one :func:`~meshcore.segments.feet`
    per end over the segments of every cut and of the ring segments near the end (a call per
    ring and per other cut made this quadratic in the cuts: 0.5 CPU-s of the layout of a
    100-block lake; a scan of every ring segment per end, in the shore points: 2 CPU-s of a lake
    of 8 000 points and 250 blocks).  The ring segments near the end come from a spatial index of
    the rings as given (:class:`_RingSegments`): a segment split by an inserted end lies on the
    segment it was split from.
    """
    rings = [r.copy() for r in rings]
    cuts = [c.copy() for c in cuts]
    near = _RingSegments(rings)
    for k in range(len(cuts)):
        for end in (0, -1):
            q = cuts[k][end]
            ring_segs = near.candidates(rings, q)  # (ring, segment) pairs, in the scan's order
            others = [(c, ci) for ci, c in enumerate(cuts) if ci != k]
            a = np.vstack([rings[ri][si] for ri, si in ring_segs] + [c[:-1] for c, _ in others])
            b = np.vstack([rings[ri][(si + 1) % len(rings[ri])] for ri, si in ring_segs] + [c[1:] for c, _ in others])
            dist, ts = feet(a.reshape(-1, 2), b.reshape(-1, 2), q)
            j = int(np.argmin(dist))
            t = float(ts[j])
            if j < len(ring_segs):
                kind, (idx, seg) = "ring", ring_segs[j]
                target, closed = rings[idx], True
            else:
                first = np.cumsum([len(ring_segs)] + [len(c) - 1 for c, _ in others])
                which = int(np.searchsorted(first, j, side="right")) - 1
                (target, idx), seg, kind, closed = others[which], j - int(first[which]), "cut", False
            n = len(target)
            a = target[seg]
            b = target[(seg + 1) % n] if closed else target[seg + 1]
            p = a + t * (b - a)
            if math.hypot(*(p - a)) <= eps:
                p = a.copy()
            elif math.hypot(*(p - b)) <= eps:
                p = b.copy()
            else:
                target = np.insert(target, seg + 1, p, axis=0)
                if kind == "ring":
                    rings[idx] = target
                    near.inserted(idx, seg)
                else:
                    cuts[idx] = target
            cuts[k][end] = p
    return rings, cuts


class _RingSegments:
    """The segments of the rings as first given, in an STR-tree, and for every segment of each
    ring now the given segment it lies on (``parent``, non-decreasing round the ring)."""

    def __init__(self, rings: list[np.ndarray]) -> None:
        import shapely

        a = np.vstack(rings)
        b = np.vstack([np.roll(r, -1, axis=0) for r in rings])
        self.ring = np.repeat(np.arange(len(rings)), [len(r) for r in rings])
        self.seg = np.concatenate([np.arange(len(r)) for r in rings])
        self.tree = shapely.STRtree(shapely.linestrings(np.stack([a, b], axis=1)))
        self.parent = [np.arange(len(r)) for r in rings]
        self.slack = 1e-12 * (1.0 + float(np.abs(a).max()))

    def inserted(self, ring: int, seg: int) -> None:
        """A point was inserted after vertex ``seg`` of ``ring``: its segment is now two."""
        self.parent[ring] = np.insert(self.parent[ring], seg + 1, self.parent[ring][seg])

    def candidates(self, rings: list[np.ndarray], q: np.ndarray) -> list[tuple[int, int]]:
        """(ring, segment) of every segment of ``rings`` that may be the nearest to ``q``, in order."""
        import shapely

        pt = shapely.Point(float(q[0]), float(q[1]))
        _, d = self.tree.query_nearest(pt, return_distance=True, all_matches=False)
        reach = float(d[0]) * (1 + 1e-9) + 4 * self.slack
        out = []
        for g in np.sort(self.tree.query(pt, predicate="dwithin", distance=reach)):
            r, s = int(self.ring[g]), int(self.seg[g])
            par = self.parent[r]
            lo, hi = np.searchsorted(par, s, side="left"), np.searchsorted(par, s, side="right")
            out += [(r, int(i)) for i in range(lo, hi)]
        return sorted(out)


def partition(poly, cuts: list[np.ndarray], sigma: float | None = None) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """Counter-clockwise rings of the regions that ``cuts`` make of the polygon ``poly``.

    A region that still holds an island gets two more cuts, from the island to the region's
    outer ring at the nearest points on either side (so every region is simply connected);
    returns the rings and the final list of cuts.  ``sigma`` (the corners' scale): island
    cuts that meet a ring at less than :data:`MIN_CORNER_ANGLE` there (a wedge) are
    taken only when there is no other.
    """
    from ..errors import TopologyError

    cuts = list(cuts)
    for _ in range(2 * len(poly.interiors) + 2):  # each round joins an island to another ring
        faces, cuts = _faces(poly, cuts)
        holed = [f for f in faces if f.interiors]
        if not holed:
            break
        new = [c for f in holed for c in _island_cuts(f, sigma, cuts)]
        if not new:
            break
        cuts += new
    if holed:
        c = holed[0].interiors[0].centroid
        raise TopologyError(
            f"automatic layout: no cut from the island near ({c.x:.6g}, {c.y:.6g}) to the shore stays in "
            f"the water; add cut lines there by hand (a [outline] case) or try another cell size"
        )
    return [np.asarray(f.exterior.coords)[:-1] for f in faces], cuts


def _faces(poly, cuts):
    import shapely
    from shapely.geometry import LineString
    from shapely.geometry.polygon import orient

    rings = [np.asarray(poly.exterior.coords)[:-1], *(np.asarray(h.coords)[:-1] for h in poly.interiors)]
    size = math.hypot(*np.subtract(*np.reshape(poly.bounds, (2, 2))[::-1]))
    rings, cuts = snap_to_rings(rings, cuts, 1e-9 * size)
    lines = [LineString(np.vstack([r, r[:1]])) for r in rings] + [LineString(c) for c in cuts]
    noded = shapely.union_all(lines)
    faces = shapely.polygonize(list(getattr(noded, "geoms", [noded])))
    out = []
    water = poly.buffer(1e-9 * size)  # once, not per face
    shapely.prepare(water)
    for f in getattr(faces, "geoms", [faces]):
        if f.area <= 1e-12 * size * size:
            continue
        if not water.contains(f.representative_point()):
            continue  # an island's interior
        out.append(orient(f, 1.0))
    return out, cuts


def _meets_at(ring, end: np.ndarray, other: np.ndarray, sigma: float) -> float:
    """The narrower of the two angles (degrees) between a cut from ``end`` to ``other`` and the
    ring ``ring`` (a shapely LinearRing through ``end``), the ring read ``sigma`` either side."""
    s = ring.project(_point(end))
    d = other - end
    worst = 180.0
    for ds in (-sigma, sigma):
        q = np.asarray(ring.interpolate((s + ds) % ring.length).coords[0]) - end
        den = math.hypot(*q) * math.hypot(*d)
        if den > 0:
            worst = min(worst, math.degrees(math.acos(max(-1.0, min(1.0, float(q @ d) / den)))))
    return worst


def _point(p):
    from shapely.geometry import Point

    return Point(float(p[0]), float(p[1]))


def _island_cuts(face, sigma: float | None = None, existing=()) -> list[np.ndarray]:
    """Two straight cuts from each island of ``face`` to another shore (the region's outer ring or
    another island), on opposite sides of the island: the shortest segments that stay in the water.

    Candidates leave the island at 32 points round it and go to the nearest point of every
    other ring; the shortest one that the water covers is the first cut, the shortest one
    leaving from the island's far half (seen from the first) is the second (:func:`_second_cut`:
    not alongside the first nor a chord near the island).
    """

    rings = [face.exterior, *face.interiors]
    room = face.buffer(1e-9 * math.sqrt(face.area))
    cuts: list[np.ndarray] = []
    for k in range(1, len(rings)):
        hole = rings[k]
        starts = [hole.interpolate(f, normalized=True) for f in np.linspace(0.0, 1.0, 32, endpoint=False)]

        def to_vertices(starts=starts, k=k) -> list:  # the cuts as they are when called
            return [t for p in starts for t in _sights(p, k, rings, room, cuts, 64)]

        cand = [s for p in starts for s in _sights(p, k, rings, room, cuts)]
        if not cand:  # round a bend: the nearest points are not in sight; try the other rings' vertices
            cand = to_vertices()
        if not cand:
            continue
        cand.sort(key=lambda t: t[0])
        if sigma is not None:
            cand = _without_wedges(cand, hole, rings, sigma) or cand
            cand = _apart(cand, [*existing, *cuts], 2 * sigma) or cand
        first = cand[0][1]
        cuts.append(first)
        second = _second_cut(first, hole, rings, cand, to_vertices, [*existing, *cuts], sigma)
        if second is not None:
            cuts.append(second)
    return cuts


def _second_cut(first, hole, rings, cand, to_vertices, earlier, sigma):
    """The second cut that frees an island, ``first`` being the first: the shortest of ``cand``
    leaving from the island's far half (seen from ``first``) that keeps ``2 sigma`` from
    ``first`` and from the ``earlier`` cuts near the island (chords, the cuts of other islands):
    not alongside one, where the strip between would be a sliver block.  Where no
    nearest-point candidate does (an island near one side of a wide region sees only that
    side), the candidates to the rings' vertices (``to_vertices()``);
    then, as before, any that keeps the gap, any on the far half, any other."""
    from shapely.geometry import LineString, Point

    c = np.asarray(hole.centroid.coords[0])
    d = first[0] - c
    line = LineString(first)

    def away(seg) -> bool:
        return float(np.dot(seg[0] - c, d)) < 0 and not LineString(seg).intersects(Point(first[1]))

    others = [seg for _, seg in cand if not LineString(seg).intersects(line)]
    far = [seg for seg in others if away(seg)]
    if sigma is None:
        return (far or others or [None])[0]
    reach = max((L for L, _ in cand), default=0.0) + 2 * sigma  # the cuts a candidate can lie beside
    beside = [first, *(e for e in earlier if hole.distance(LineString(e)) < reach)]
    apart = [seg for _, seg in _apart([(0.0, seg) for seg in others], beside, 2 * sigma)]
    good = [seg for seg in far if any(seg is a for a in apart)]
    if others and not apart:  # every nearest-point cut lies beside one: the rings' vertices
        more = sorted(to_vertices(), key=lambda t: t[0])
        more = [(L, seg) for L, seg in more if not LineString(seg).intersects(line)]
        pick = _first_apart(more, hole, rings, sigma, beside, away)
        if pick is not None:
            return pick
    far = good or apart or far or others
    return far[0] if far else None


def _first_apart(more: list, hole, rings, sigma: float, beside, away):
    """What ``good or apart`` of :func:`_second_cut`'s fallback begins with — the first of ``more``
    (those without a wedge, :func:`_without_wedges`, if any) that keeps ``2 sigma`` from ``beside``
    and leaves from the far half (``away``), else the first that keeps the gap — or None; each
    candidate's angles and gaps read only until that one (the whole list was read before)."""
    for wedges in (True, False):
        first = None
        kept = False  # some candidate without a wedge
        for cand in more:
            if wedges and not _without_wedges([cand], hole, rings, sigma):
                continue
            kept = True
            if _apart([cand], beside, 2 * sigma):
                if away(cand[1]):
                    return cand[1]
                first = first if first is not None else cand[1]
        if kept or not wedges:
            return first
    return None


def _sights(p, k: int, rings, room, cuts, step: int | None = None) -> list:
    """(length, segment) from the point ``p`` of ring ``k`` to the other rings, the segments that
    ``room`` covers and that cross none of ``cuts``: to the nearest point of each ring (``step``
    None), or to every ``len / step``-th vertex of each (round a bend, where the nearest points
    are out of sight)."""
    import shapely
    from shapely.geometry import LineString
    from shapely.ops import nearest_points

    out = []
    lines = np.array([LineString(c) for c in cuts], dtype=object) if len(cuts) else None  # once, not per segment
    for j, other in enumerate(rings):
        if j == k:
            continue
        if step is None:
            ends = [nearest_points(p, other)[1].coords[0]]
        else:
            verts = np.asarray(other.coords)[:-1]
            ends = [tuple(v) for v in verts[:: max(1, len(verts) // step)]]
        for q in ends:
            seg = LineString([p.coords[0], q])
            if seg.length > 0 and room.covers(seg) and not (lines is not None and shapely.crosses(seg, lines).any()):
                out.append((seg.length, np.asarray(seg.coords)))
    return out


def _without_wedges(cand: list, hole, rings, sigma: float) -> list:
    """The candidate island cuts that meet both of their rings at no less than
    :data:`MIN_CORNER_ANGLE` (read at scale ``sigma``)."""
    out = []
    for length, seg in cand:
        far = min(rings, key=lambda r: r.distance(_point(seg[1])))
        if min(_meets_at(hole, seg[0], seg[1], sigma), _meets_at(far, seg[1], seg[0], sigma)) >= MIN_CORNER_ANGLE:
            out.append((length, seg))
    return out


def _apart(cand: list, cuts, gap: float) -> list:
    """The candidate cuts that keep ``gap`` from every one of ``cuts``: neither end within
    ``gap`` of an end of one (the short stretch of shore between the two ends would be a
    wedge's tip or a block side a cell long; ending on a cut, a T, is fine), not alongside one
    (Hausdorff distance: a strip between two cuts that close would be a sliver; a cut from an
    island beside a chord that already joins it to the next island, for one)."""
    from shapely.geometry import LineString, Point

    lines = [LineString(c) for c in cuts]
    tips = [Point(p) for c in cuts for p in (c[0], c[-1])]

    def ok(seg) -> bool:
        ends = (Point(seg[0]), Point(seg[-1]))
        ls = LineString(seg)
        return all(e.distance(t) >= gap for e in ends for t in tips) and all(
            ls.hausdorff_distance(o) >= gap for o in lines
        )

    return [(L, seg) for L, seg in cand if ok(seg)]
