"""Points on the shore: nearest-point projection onto the shore rings, and back.

The shore is a list of closed rings (outline and islands, densified).  A shore node is kept
as ``(ring, s)``: which ring and the arc length along it.
"""

from __future__ import annotations

import threading

import numpy as np

from ..segments import feet

__all__ = ["arc_lengths", "project_to_rings", "ring_point"]


def _segments(rings: list[np.ndarray]):
    a = np.vstack(rings)
    b = np.vstack([np.roll(r, -1, axis=0) for r in rings])
    ring = np.concatenate([np.full(len(r), k) for k, r in enumerate(rings)])
    L = np.hypot(*(b - a).T)
    start = np.concatenate(
        [np.concatenate([[0.0], np.cumsum(np.hypot(*(np.roll(r, -1, axis=0) - r).T))[:-1]]) for r in rings]
    )
    return a, b, ring, L, start


#: The segments and STR-trees of the last few sets of rings, keyed by their bytes: a lake's
#: shore rings stay the same through every level of the solve, and :func:`project_to_rings` is
#: asked about them 10-20 times a lake (shore data, fits, refinement, equalize patches).
_TREES: dict[bytes, tuple] = {}
_TREES_KEPT = 4
#: guards :data:`_TREES`: solves in two threads (the app's lake grid and the coarse readings of a layout
#: counted or laid out beside it) evicted the same oldest entry (KeyError) or iterated it while the other
#: added one (RuntimeError: dictionary changed size during iteration)
_TREES_LOCK = threading.Lock()


def _tree(rings: list[np.ndarray]):
    """``(tree, a, b, ring, L, start)`` of ``rings`` (:func:`_segments` and its STR-tree), made once."""
    import shapely

    rs = [np.ascontiguousarray(r, dtype=float) for r in rings]
    key = np.array([r.shape for r in rs], dtype=np.int64).tobytes() + b"".join(r.tobytes() for r in rs)
    with _TREES_LOCK:
        hit = _TREES.pop(key, None)
    if hit is None:  # (made outside the lock: two threads may both make it, the same tree)
        a, b, ring, L, start = _segments(rs)
        hit = (shapely.STRtree(shapely.linestrings(np.stack([a, b], axis=1))), a, b, ring, L, start)
    with _TREES_LOCK:
        _TREES[key] = hit  # the most recent last
        while len(_TREES) > _TREES_KEPT:
            del _TREES[next(iter(_TREES))]
    return hit


def project_to_rings(rings: list[np.ndarray], pts: np.ndarray):
    """For every point: the index of the nearest ring, the arc length of its nearest point on
    that ring, and the distance (an STR-tree nearest-segment query, then the exact foot)."""
    import shapely

    pts = np.asarray(pts, dtype=float).reshape(-1, 2)
    tree, a, b, ring, L, start = _tree(rings)
    seg = tree.query_nearest(shapely.points(pts), return_distance=False, all_matches=False)[1]
    dist, t = feet(a[seg], b[seg], pts)
    return ring[seg], start[seg] + t * L[seg], dist


def arc_lengths(ring: np.ndarray) -> np.ndarray:
    """The arc length at each vertex of a closed ring, and at its return to the first (the perimeter)."""
    closed = np.vstack([ring, ring[:1]])
    return np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(closed, axis=0).T))])


def ring_point(ring: np.ndarray, s: np.ndarray, cum: np.ndarray | None = None) -> np.ndarray:
    """Points at arc lengths ``s`` (any real: the ring is closed) of one ring.

    ``cum``: the ring's :func:`arc_lengths`, when the caller asks for points of one ring many times.
    """
    closed = np.vstack([ring, ring[:1]])
    cum = arc_lengths(ring) if cum is None else cum
    s = np.mod(s, cum[-1])
    return np.column_stack([np.interp(s, cum, closed[:, 0]), np.interp(s, cum, closed[:, 1])])
