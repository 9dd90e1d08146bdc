r"""The regions of hand-drawn cut lines made blocks (:func:`meshcore.layout.edit.layout_from_cuts`).

Cut ends on the shore noded into its rings, a region of three points given a fourth corner,
another choice of one region's corners where no cell counts agree round the blocks, and the
messages that name the place where none do.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .blocks import Piece, block_counts, conform


def _pieces_of_regions(rings: list[np.ndarray], corner_points: list[list], names: list[str], size: float):
    """Conforming pieces of region rings with their corners given as points (inserted if need be)."""
    rings = conform([np.asarray(r, dtype=float) for r in rings], 1e-9 * size)
    pieces = []
    for r, cs, name in zip(rings, corner_points, names, strict=True):
        named = [int(np.argmin(np.hypot(*(r - np.asarray(c)).T))) for c in cs]
        idx = sorted(named)  # counter-clockwise along the ring, from the first corner given (sw):
        idx = idx[idx.index(named[0]) :] + idx[: idx.index(named[0])]  # the piece's sides are the block's
        pieces.append(Piece(r, (idx[0], idx[1], idx[2], idx[3]), name))
    return pieces


def _countable(
    rings: list, corner_pts: list, chosen: list[int], names: list[str], h: float, multiple: int, size: float
) -> list[Piece] | None:
    """Where no cell counts agree round the pieces of ``rings`` cornered at ``corner_pts``: the
    first pieces round which some do with one region's corners chosen again (of those in
    ``chosen``, whose corners were not given: its junctions, the vertices three regions share,
    made corners, or its corners read at another scale), or None.  A cut drawn onto a cut's end
    next to an island cut it crosses: 4 of 5 such cuts that had no counts (session 20)."""
    from ..errors import TopologyError
    from .corners import choose_corners

    if len(rings) > 60:  # a count per region and try: not for a large layout
        return None
    from collections import Counter

    seen = Counter(tuple(np.round(p, 9)) for r in rings for p in r)
    shared = {q for q, n in seen.items() if n >= 3}
    for k in chosen:
        r = rings[k]
        nodes = [i for i, p in enumerate(r) if tuple(np.round(p, 9)) in shared]
        tries = [choose_corners(r, 1.5 * h, forced=nodes)[0]] if 0 < len(nodes) <= 4 else []
        tries += [choose_corners(r, f * h)[0] for f in (0.75, 3.0)]
        for c in tries:
            if c is None:
                continue
            pts = list(corner_pts)
            pts[k] = [r[i] for i in c]
            again = _pieces_of_regions(rings, pts, names, size)
            try:
                block_counts(again, h, multiple=multiple, best=False)
            except TopologyError:
                continue
            return again
    return None


def _where_counts_fail(polygon: Any, cuts: list, pieces: list[Piece], h: float, multiple: int) -> str:
    """Where no integer cell counts agree: the blocks without any one of which some do (at most
    three, the smallest first), and the points of the shore where two of ``cuts`` end on their
    rings; for the message of :func:`layout_from_cuts`."""
    from shapely.geometry import Polygon

    from ..errors import TopologyError

    if len(pieces) > 60:  # a count per block left out: not for a large layout
        return ""
    culprits = []
    for k in range(len(pieces)):
        try:
            block_counts(pieces[:k] + pieces[k + 1 :], h, multiple=multiple, best=False)
        except TopologyError:
            continue
        culprits.append(pieces[k])
    if not culprits:
        return ""
    culprits.sort(key=lambda pc: Polygon(pc.ring).area)
    where = ", ".join(
        f"({p.x:.6g}, {p.y:.6g})" for p in (Polygon(pc.ring).representative_point() for pc in culprits[:3])
    )
    at = ""
    shared = _shared_shore_ends(polygon, cuts, h)
    shared = [p for p in shared if any(np.min(np.hypot(*(pc.ring - p).T)) <= 1e-6 * h for pc in culprits)]
    if shared:
        pts = ", ".join(f"({x:.6g}, {y:.6g})" for x, y in shared[:2])
        at = f"; two cuts end at one shore point there, {pts}: end one 3 or more cells from it, or across the other"
    return f": no cell counts agree round the block{'s' * (len(culprits) > 1)} near {where}{at}"


def _shared_shore_ends(polygon: Any, cuts: list, h: float) -> list[np.ndarray]:
    """The points on the shore (or an island) where two or more of ``cuts`` end."""
    from shapely.geometry import Point

    ends = [np.asarray(c, float)[e] for c in cuts for e in (0, -1)]
    shore = polygon.boundary
    out: list[np.ndarray] = []
    for p in ends:
        if any(np.hypot(*(p - q)) <= 1e-6 * h for q in out) or shore.distance(Point(p)) > 1e-6 * h:
            continue
        if sum(np.hypot(*(p - q)) <= 1e-6 * h for q in ends) >= 2:
            out.append(p)
    return out


def _shore_ends_in_rings(poly: Any, cuts: list) -> tuple[Any, list]:
    """``poly`` with every cut end on its shore (within 1e-9 of its size) a vertex of its ring, and
    the cuts whose ends are (a float's width) apart from one such vertex put exactly on it.

    Two cuts ending at one shore point (a cut drawn onto an auto cut's end) otherwise end on each
    other: :func:`~.regions.snap_to_rings` puts an end on the nearest line, the other cut, whose
    end is nearer than the shore by 1e-13; the shore is not noded there, and the region beside it
    touches itself (session 20: the 'not a simple polygon' errors of such cuts)."""
    from shapely.geometry import Polygon

    from ..segments import feet

    size = math.sqrt(poly.area)
    eps = 1e-9 * size
    rings = [np.asarray(poly.exterior.coords)[:-1], *(np.asarray(r.coords)[:-1] for r in poly.interiors)]
    cuts = [np.array(c, float) for c in cuts]
    for c in cuts:
        if len(c) < 2:
            continue
        for e in (0, -1):
            q = c[e]
            for k, r in enumerate(rings):
                dist, _ = feet(r, np.roll(r, -1, axis=0), q)
                j = int(np.argmin(dist))
                if dist[j] > eps:
                    continue
                near = np.hypot(*(r - q).T)
                i = int(np.argmin(near))
                if near[i] <= eps:
                    c[e] = r[i]  # onto the vertex there (an earlier cut's end, or the shore's)
                else:
                    rings[k] = np.insert(r, j + 1, q, axis=0)
                break
    return Polygon(rings[0], rings[1:]), cuts


def _four_vertices(ring: np.ndarray, h: float) -> np.ndarray:
    """A region of three vertices (straight cuts crossing, or a cut and the shore's vertices) with a
    fourth at the middle of its longest side, a block corner there (:func:`~.corners.choose_corners`
    takes four of a ring's vertices); the neighbour across that side gets the point as a T
    (:func:`~.blocks.conform`).  Raises :class:`~meshcore.errors.TopologyError` naming the place when
    the region is under a cell: a sliver where two cuts cross just before they end (a cut end
    drawn near another one on the shore, not onto it)."""
    from ..errors import TopologyError

    if len(ring) >= 4:
        return ring
    (ax, ay), (bx, by) = ring[1] - ring[0], ring[-1] - ring[0]
    area = 0.5 * abs(float(ax * by - ay * bx)) if len(ring) == 3 else 0.0
    c = ring.mean(axis=0)
    if area < h * h:
        raise TopologyError(
            f"the cut lines leave a three-sided sliver of {area / (h * h):.2g} cells near ({c[0]:.6g}, {c[1]:.6g}) "
            f"(two cuts crossing just before they end: a cut end drawn near another one, not onto it); "
            f"put the two ends onto one point or farther apart"
        )
    side = np.hypot(*(np.roll(ring, -1, axis=0) - ring).T)
    k = int(np.argmax(side))
    return np.insert(ring, k + 1, 0.5 * (ring[k] + ring[(k + 1) % 3]), axis=0)
