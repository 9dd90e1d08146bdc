"""The nearest point of a segment, written once.

Projection onto polylines is everywhere in a lake pipeline: cut ends snapped to the shore,
nodes pulled back onto it, coarse samplings measured against it.  Every caller asks the same
question — for a point ``q`` and segments ``a[k] → b[k]``, where is the foot of ``q`` on each
segment and how far is it — and answers it here.  (A module of its own, below the layout, the
multiblock outline and the orthogonal smoother, which may not import each other.)
"""

from __future__ import annotations

import numpy as np

__all__ = ["feet", "nearest_on_polyline"]


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
