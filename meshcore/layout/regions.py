r"""Regions: the water split by cut lines, each a simple polygon that will become blocks.

:func:`partition` inserts the ends of every cut exactly into the shore rings (and into other
cuts they end on), nodes the line work with shapely and polygonises it.  A region is a
counter-clockwise ring of points; the cut ends are ordinary vertices of it, so neighbouring
regions share their cut lines vertex for vertex.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["partition", "snap_to_rings"]


def _project(poly_pts: np.ndarray, q: np.ndarray, closed: bool):
    a = poly_pts if closed else poly_pts[:-1]
    b = np.roll(poly_pts, -1, axis=0) if closed else poly_pts[1:]
    d = b - a
    L2 = (d * d).sum(axis=1)
    t = np.clip(np.where(L2 > 0, ((q - a) * d).sum(axis=1) / np.where(L2 > 0, L2, 1.0), 0.0), 0.0, 1.0)
    foot = a + t[:, None] * d
    dist = np.hypot(*(foot - q).T)
    k = int(np.argmin(dist))
    return float(dist[k]), k, float(t[k])


def snap_to_rings(rings: list[np.ndarray], cuts: list[np.ndarray], eps: float):
    """Insert every cut end into the nearest ring (or earlier cut) exactly; return new rings, cuts.

    Ends within ``eps`` of an existing vertex snap to it.
    """
    rings = [r.copy() for r in rings]
    cuts = [c.copy() for c in cuts]
    for k in range(len(cuts)):
        for end in (0, -1):
            q = cuts[k][end]
            best = None
            for ri, r in enumerate(rings):
                d, seg, t = _project(r, q, True)
                if best is None or d < best[0]:
                    best = (d, "ring", ri, seg, t)
            for ci in range(len(cuts)):
                if ci == k:
                    continue
                d, seg, t = _project(cuts[ci], q, False)
                if d < best[0]:
                    best = (d, "cut", ci, seg, t)
            _, kind, idx, seg, t = best
            target = rings[idx] if kind == "ring" else cuts[idx]
            closed = kind == "ring"
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
                else:
                    cuts[idx] = target
            cuts[k][end] = p
    return rings, cuts


def partition(poly, cuts: list[np.ndarray]) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """Counter-clockwise rings of the regions that ``cuts`` make of the polygon ``poly``.

    A region that still holds an island gets two more cuts, from the island to the region's
    outer ring at the nearest points on either side (so every region is simply connected);
    returns the rings and the final list of cuts.
    """
    from ..errors import TopologyError

    cuts = list(cuts)
    for _ in range(2 * len(poly.interiors) + 2):  # each round joins an island to another ring
        faces, cuts = _faces(poly, cuts)
        holed = [f for f in faces if f.interiors]
        if not holed:
            break
        new = [c for f in holed for c in _island_cuts(f)]
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
    for f in getattr(faces, "geoms", [faces]):
        if f.area <= 1e-12 * size * size:
            continue
        if not poly.buffer(1e-9 * size).contains(f.representative_point()):
            continue  # an island's interior
        out.append(orient(f, 1.0))
    return out, cuts


def _island_cuts(face) -> list[np.ndarray]:
    """Two straight cuts from each island of ``face`` to another shore (the region's outer ring or
    another island), on opposite sides of the island: the shortest segments that stay in the water.

    Candidates leave the island at 32 points round it and go to the nearest point of every
    other ring; the shortest one that the water covers is the first cut, the shortest one
    leaving from the island's far half (seen from the first) is the second.
    """
    from shapely.geometry import LineString, Point
    from shapely.ops import nearest_points

    rings = [face.exterior, *face.interiors]
    room = face.buffer(1e-9 * math.sqrt(face.area))
    cuts: list[np.ndarray] = []
    for k in range(1, len(rings)):
        hole = rings[k]
        starts = [hole.interpolate(f, normalized=True) for f in np.linspace(0.0, 1.0, 32, endpoint=False)]
        cand = []
        for p in starts:
            for j, other in enumerate(rings):
                if j == k:
                    continue
                _, q = nearest_points(p, other)
                seg = LineString([p.coords[0], q.coords[0]])
                if seg.length > 0 and room.covers(seg) and not any(seg.crosses(LineString(c)) for c in cuts):
                    cand.append((seg.length, np.asarray(seg.coords)))
        if not cand:  # round a bend: the nearest points are not in sight; try the other rings' vertices
            for p in starts:
                for j, other in enumerate(rings):
                    if j == k:
                        continue
                    verts = np.asarray(other.coords)[:-1]
                    for v in verts[:: max(1, len(verts) // 64)]:
                        seg = LineString([p.coords[0], tuple(v)])
                        if seg.length > 0 and room.covers(seg):
                            cand.append((seg.length, np.asarray(seg.coords)))
        if not cand:
            continue
        cand.sort(key=lambda t: t[0])
        first = cand[0][1]
        cuts.append(first)
        c = np.asarray(hole.centroid.coords[0])
        d = first[0] - c
        far = [
            seg
            for _, seg in cand
            if float(np.dot(seg[0] - c, d)) < 0 and not LineString(seg).intersects(Point(first[1]))
        ]
        far = [seg for seg in far if not LineString(seg).crosses(LineString(first))]
        if not far:  # no cut on the far side: any other that leaves the first cut alone
            far = [seg for _, seg in cand if not LineString(seg).intersects(LineString(first))]
        if far:
            cuts.append(far[0])
    return cuts
