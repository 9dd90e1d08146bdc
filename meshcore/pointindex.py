r"""Exact points as keys: one vertex shared by several rings, cuts and chains is one key.

The layout (:mod:`meshcore.layout`) and the outline blocks (:mod:`meshcore.multiblock.outline`)
find the vertices that rings and cut lines share by their exact coordinates: a vertex inserted
into two rings is the same pair of floats in both (:func:`meshcore.layout.blocks.conform` and
``weld`` make sure of that).  :func:`point_key` is that key; :func:`point_keys` the keys of a
whole array at once (``tolist`` then ``tuple``: the same Python floats, ~10× faster than a key
per row); :class:`PointIndex` numbers the distinct points of several arrays, for set
operations in NumPy instead of dictionaries.

>>> import numpy as np
>>> a = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]])
>>> b = np.array([[1.0, 1.0], [1.0, 0.0], [2.0, 0.5]])
>>> point_keys(a)[1] == point_key(b[1])
True
>>> ix = PointIndex([a, b])
>>> ix.ids[1].tolist()   # b's points as ids of ix.points
[2, 1, 3]
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

__all__ = ["PointIndex", "point_key", "point_keys"]

PointKey = tuple[float, float]


def point_key(p: Any) -> PointKey:
    """The key of one point: its two coordinates as Python floats."""
    return (float(p[0]), float(p[1]))


def point_keys(points: Any) -> list[PointKey]:
    """The keys of every row of an ``(n, 2)`` array (the values :func:`point_key` gives)."""
    a = np.asarray(points, dtype=float)
    return list(map(tuple, a.reshape(-1, 2).tolist()))


class PointIndex:
    """The distinct points of several ``(n_k, 2)`` arrays, numbered.

    ``points`` holds each distinct point once, sorted lexicographically (x, then y);
    ``ids[k]`` gives the number of every row of array ``k``.  Points are equal when their
    coordinates are equal (``-0.0 == 0.0``), as for :func:`point_key`.
    """

    __slots__ = ("ids", "points")

    def __init__(self, arrays: Sequence[Any]) -> None:
        arrs = [np.asarray(a, dtype=float).reshape(-1, 2) for a in arrays]
        allv = np.vstack(arrs) if arrs else np.zeros((0, 2))
        allv = allv + 0.0  # -0.0 → 0.0, so equal points have equal bytes
        self.points, inv = np.unique(allv, axis=0, return_inverse=True)
        inv = np.asarray(inv).reshape(-1)
        bounds = np.cumsum([0] + [len(a) for a in arrs])
        self.ids = [inv[bounds[k] : bounds[k + 1]] for k in range(len(arrs))]

    def __len__(self) -> int:
        return len(self.points)

    def find(self, points: Any) -> np.ndarray:
        """The number of each row of ``points`` in :attr:`points`, ``-1`` where it is not there."""
        q = np.asarray(points, dtype=float).reshape(-1, 2) + 0.0
        if not len(self.points):
            return np.full(len(q), -1)
        px, py = self.points[:, 0], self.points[:, 1]
        lo = np.searchsorted(px, q[:, 0], side="left")
        hi = np.searchsorted(px, q[:, 0], side="right")
        out = np.full(len(q), -1)
        for i in np.flatnonzero(hi > lo):  # the rows with this x: their y are sorted
            k = lo[i] + int(np.searchsorted(py[lo[i] : hi[i]], q[i, 1]))
            if k < hi[i] and py[k] == q[i, 1]:
                out[i] = k
        return out
