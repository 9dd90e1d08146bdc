"""Cut lines → a chain of blocks: the app's "Split into blocks by cut lines".

The user draws cut lines across a closed outline (a lake, a river).  Each
region between the cuts becomes one block whose cut sides are its left/right
borders, so that every block shares its η cell count (``cells_across``) with
its neighbours — a *chain* of blocks, the common river/lake case:

* a region bordered by **one** cut (an arm of the lake) is capped at its far
  tip: its two remaining corners are the outline vertices half a cut length of
  arc on either side of the vertex farthest from the cut;
* a region bordered by **two** cuts takes the four cut ends as corners.

Cut ends are moved onto the outline (and inserted as outline vertices) when
they are within ``snap`` of it.  The result (outline, cuts, blocks) is what
:func:`meshcore.multiblock.from_outline` takes — :func:`meshcore.case.cut_case`
makes it an ``[outline]`` case; shared chains are re-sampled once, so
interface nodes are identical.  Regions bordered by three or more cuts, or
cuts that meet each other, need hand-picked corners (not supported here).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..boundary import signed_area as _signed_area
from ..errors import TopologyError
from ..segments import nearest_on_polyline
from .outline import BlockOutline, _insert

__all__ = ["chain_blocks", "snap_cuts_to_outline"]


def snap_cuts_to_outline(outline: np.ndarray, cuts: list[np.ndarray], snap: float):
    """Move every cut end onto the outline and insert it there as a vertex.

    Returns ``(outline, cuts)``; raises :class:`TopologyError` naming the cut
    whose end is farther than ``snap`` from the outline.
    """
    ring = np.asarray(outline, float).copy()
    out_cuts = []
    for k_cut, c in enumerate(cuts):
        c = np.asarray(c, float).copy()
        if len(c) < 2:
            raise TopologyError(f"cut {k_cut + 1} needs at least two points")
        for end in (0, -1):
            dist, k, t = nearest_on_polyline(ring, c[end], True)
            if dist > snap:
                raise TopologyError(
                    f"cut {k_cut + 1}: its {'first' if end == 0 else 'last'} point is {dist:.3g} from the "
                    f"outline; both ends of a cut must lie on the outline (within {snap:.3g})"
                )
            seg = float(np.hypot(*(ring[(k + 1) % len(ring)] - ring[k])))
            ring, c[end] = _insert(ring, k, t, True, 1e-9 * seg)
        out_cuts.append(c)
    return ring, out_cuts


def _arc(q: np.ndarray, i: int, j: int) -> float:
    n = len(q)
    idx = [(i + s) % n for s in range((j - i) % n + 1)]
    seg = np.diff(q[idx], axis=0)
    return float(np.hypot(seg[:, 0], seg[:, 1]).sum())


def _walk(q: np.ndarray, start: int, step: int, length: float, stop: int) -> int:
    n = len(q)
    arc, k = 0.0, start
    while True:
        nxt = (k + step) % n
        if nxt == stop:
            return k
        arc += float(np.hypot(*(q[nxt] - q[k])))
        k = nxt
        if arc >= length:
            return k


def chain_blocks(
    outline: Any,
    cuts: list[Any],
    *,
    cells_across: int = 12,
    snap: float | None = None,
) -> tuple[np.ndarray, list[np.ndarray], list[BlockOutline]]:
    """A chain of blocks from an outline and cuts: ``(outline, cuts, blocks)`` for :func:`from_outline`.

    ``cells_across`` is the η count shared by all blocks; each block's ξ
    count follows from its length at the same cell size (rounded to even, so
    the multigrid can coarsen).
    """
    from shapely.geometry import LineString
    from shapely.ops import polygonize, unary_union

    ring = np.asarray(outline, float)
    if len(ring) > 3 and np.allclose(ring[0], ring[-1]):
        ring = ring[:-1]
    if _signed_area(ring) < 0:
        ring = ring[::-1].copy()
    size = float(math.hypot(*(ring.max(axis=0) - ring.min(axis=0))))
    snap = 0.02 * size if snap is None else snap
    if not cuts:
        raise TopologyError("draw at least one cut line across the outline first (Cut line tool)")
    ring, cuts = snap_cuts_to_outline(ring, list(cuts), snap)
    lines = [LineString(np.vstack([ring, ring[:1]]))] + [LineString(c) for c in cuts]
    regions = [np.asarray(p.exterior.coords)[:-1] for p in polygonize(unary_union(lines))]
    if len(regions) != len(cuts) + 1:
        raise TopologyError(
            f"{len(cuts)} cut(s) made {len(regions)} region(s); each cut must cross the outline "
            f"from shore to shore without touching another cut"
        )
    ends = [(tuple(c[0]), tuple(c[-1])) for c in cuts]
    h = np.mean([np.hypot(*np.diff(c, axis=0).T).sum() for c in cuts]) / cells_across
    blocks = []
    for r, reg in enumerate(regions):
        q = reg if _signed_area(reg) > 0 else reg[::-1].copy()
        n = len(q)
        key = {tuple(v): i for i, v in enumerate(map(tuple, q))}
        mine = []  # (A, B): ring indices where the cut enters and leaves, in CCW order
        for e0, e1 in ends:
            if e0 in key and e1 in key:
                i0, i1 = key[e0], key[e1]
                # the cut runs along the ring from A to B; the outline from B back to A
                cut_len = float(np.hypot(*(np.asarray(e1) - np.asarray(e0))))
                a, b = (i0, i1) if _arc(q, i0, i1) <= _arc(q, i1, i0) + 1e-12 * size else (i1, i0)
                mine.append((a, b, cut_len))
        if len(mine) == 1:
            a, b, cut_len = mine[0]
            mid = 0.5 * (q[a] + q[b])
            # the tip: the outline vertex (between B and A) farthest from the cut
            cand = [(b + s) % n for s in range(1, (a - b) % n)]
            if len(cand) < 3:
                raise TopologyError(f"region {r + 1}: too few outline points beyond the cut")
            tip = max(cand, key=lambda i: float(np.hypot(*(q[i] - mid))))
            c3 = _walk(q, tip, -1, 0.5 * cut_len, b)  # towards B
            c4 = _walk(q, tip, +1, 0.5 * cut_len, a)  # towards A
            if c3 == c4:
                c4 = (c3 + 1) % n
            corners = [c4, a, b, c3]  # sw, se, ne, nw: right border = the cut
            bottom, top = _arc(q, c4, a), _arc(q, b, c3)
        elif len(mine) == 2:
            (a1, b1, _), (a2, b2, _) = sorted(mine, key=lambda m: m[0])
            # ring: A1 -cut1- B1 … A2 -cut2- B2 …; right = cut1, left = cut2
            if not ((a1 - b2) % n < (b1 - b2) % n < (a2 - b2) % n):
                a1, b1, a2, b2 = a2, b2, a1, b1
            corners = [b2, a1, b1, a2]
            bottom, top = _arc(q, b2, a1), _arc(q, b1, a2)
        else:
            raise TopologyError(
                f"region {r + 1} is bordered by {len(mine)} cuts; only regions with one or two cuts "
                f"(a chain of blocks) can be split automatically"
            )
        ni = max(2, 2 * round(0.5 * (0.5 * (bottom + top)) / h))
        xy = tuple((float(q[c][0]), float(q[c][1])) for c in corners)
        blocks.append(BlockOutline(f"block{r + 1}", xy, (int(ni), int(cells_across))))
    return ring, cuts, blocks
