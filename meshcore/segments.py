"""The nearest point of a segment, written once.

Projection onto polylines is everywhere in a lake pipeline: cut ends snapped to the shore,
nodes pulled back onto it, coarse samplings measured against it.  Every caller asks the same
question — for a point ``q`` and segments ``a[k] → b[k]``, where is the foot of ``q`` on each
segment and how far is it — and answers it here.  (A module of its own, below the layout, the
multiblock outline and the orthogonal smoother, which may not import each other.)
"""

from __future__ import annotations

import numpy as np

__all__ = ["SegmentIndex", "feet", "nearest_on_polyline"]


def feet(a: np.ndarray, b: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Distance from ``q`` to each segment ``a[k] → b[k]`` and the parameter ``t ∈ [0, 1]`` of the
    foot ``a[k] + t (b[k] - a[k])``.

    ``q`` is one point or one point per segment; a segment of zero length has its foot at ``a``.
    """
    a = np.asarray(a, dtype=float)
    d = np.asarray(b, dtype=float) - a
    L2 = (d * d).sum(axis=1)
    t = np.where(L2 > 0, ((q - a) * d).sum(axis=1) / np.where(L2 > 0, L2, 1.0), 0.0)
    t = np.clip(t, 0.0, 1.0)
    foot = a + t[:, None] * d
    return np.hypot(*(foot - q).T), t


def nearest_on_polyline(poly: np.ndarray, q: np.ndarray, closed: bool) -> tuple[float, int, float]:
    """(distance, segment index, parameter t) of the point of ``poly`` nearest to ``q`` (the first
    segment at the least distance); ``closed``: the last point joins the first."""
    poly = np.asarray(poly, dtype=float)
    b = np.roll(poly, -1, axis=0) if closed else poly[1:]
    dist, t = feet(poly if closed else poly[:-1], b, q)
    k = int(np.argmin(dist))
    return float(dist[k]), k, float(t[k])


class SegmentIndex:
    """The segments of closed rings in a spatial index: the answers of a scan over all of them, at
    the cost of a few.

    :meth:`nearest` is :func:`nearest_on_polyline` over the rings in turn (the first ring, then
    the first segment, at the least distance), :meth:`near` is ``shapely.distance(points,
    rings) < eps``
    (or ``<= eps``); both compute the distances of the segments near the point as the full scan
    does, so they give the same numbers (a scan per point was quadratic on lakes with thousands
    of shore points and hundreds of blocks).
    """

    __slots__ = ("_a", "_b", "_first", "_lines", "_tree")

    def __init__(self, rings) -> None:
        import shapely

        rings = [np.asarray(r, dtype=float) for r in rings]
        self._a = np.vstack(rings)
        self._b = np.vstack([np.roll(r, -1, axis=0) for r in rings])
        self._first = np.cumsum([0] + [len(r) for r in rings])
        self._lines = shapely.linestrings(np.stack([self._a, self._b], axis=1))
        self._tree = shapely.STRtree(self._lines)

    def nearest(self, q) -> tuple[float, int, int, float]:
        """(distance, ring, segment of that ring, parameter t) of the point of the rings nearest to ``q``."""
        import shapely

        q = np.asarray(q, dtype=float)
        _, d = self._tree.query_nearest(shapely.Point(q), return_distance=True, all_matches=False)
        # every segment as near as the nearest (up to rounding) is a candidate; the scan's rule on them
        reach = float(d[0]) * (1 + 1e-9) + 1e-12 * (1.0 + float(np.abs(q).max()))
        cand = np.sort(self._tree.query(shapely.Point(q), predicate="dwithin", distance=reach))
        dist, t = feet(self._a[cand], self._b[cand], q)
        j = int(np.argmin(dist))
        g = int(cand[j])
        k = int(np.searchsorted(self._first, g, side="right")) - 1
        return float(dist[j]), k, g - int(self._first[k]), float(t[j])

    def near(self, points, eps: float, *, within: bool = False) -> np.ndarray:
        """Whether each of ``points`` is closer than ``eps`` to the rings (``within``: at most ``eps``)."""
        import shapely

        pts = shapely.points(np.asarray(points, dtype=float).reshape(-1, 2))
        out = np.zeros(len(pts), dtype=bool)
        if not len(pts):
            return out
        i, j = self._tree.query(pts, predicate="dwithin", distance=2 * eps)
        d = shapely.distance(pts[i], self._lines[j])
        hit = d <= eps if within else d < eps
        out[i[hit]] = True
        return out
