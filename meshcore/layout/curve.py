r"""The shore between an outline's vertices as a smooth curve.

An outline from Google Earth, GSHHG or a digitised map is a polygon whose vertices are a
few cells apart (the GSHHG lakes at 10 000 cells: a vertex every 1.5–12 cells, turning by
10° at the median and 20–65° at the 90th percentile), and a dense outline simplified at
the grid's scale (:func:`~.shore.without_dense_vertices`) becomes one.  Its straight
segments are not the shore: they are chords between points measured on it.  A grid that
follows them has a kink at every vertex, and an orthogonal grid cannot be orthogonal on both
sides of a kink: its lines wave where the vertices are 1.5–3 cells apart.

So every segment longer than half a cell is replaced by a cubic (Hermite) curve between its
two vertices, sampled every ``STEP`` cells.  The curve passes through every vertex with a
direction there that is the mean of the two segments' directions weighted by their squared
lengths: the bisector where the points are evenly spaced (the usual case), the direction of a
long straight segment beside short ones (a channel's straight side beside its round end stays
straight: the shore turns where it was sampled densely);

* a vertex that turns by more than ``CORNER`` degrees is a corner (a dam, a headland's tip,
  the reflex corner of a junction): the curve meets it along the straight segments either
  side, so the corner stays sharp;
* the curve stays within ``BULGE`` cells of its segment's chord (where the spline would
  bulge more — a long segment between short ones — its offsets from the chord are scaled
  down), so the grid's shore stays within half a cell of the outline as given;
* segments shorter than half a cell are at the grid's scale already and stay straight.

Off by default (``auto_layout(..., options=LayoutOptions(curve=True))``,
``meshcore mesh --layout-option curve``): measured mixed (session 18, docs/lake-grids-journal.md
*Outlines with a point every few cells*).  Grids get
more orthogonal (GSHHG lakes held out in session 17, 10 000 cells: mean share within 3°
94.4 → 95.5 %, the worst lake 75.9 → 87.6 %; generated lakes at 15 000 cells: ≥ 90 % within 3°
in 43 → 45, 42 → 44 and 20 → 23 of 45, 45, 27), but fewer keep every interface ratio ≤ 2
(21 → 19, 20 → 14, 5 → 4; held-out 9 → 7) and one generated network's short stub arm folded
(42 cells).  Measured again in session 35 (held-out set 21, stress34, generated shapes): hard
targets 28 → 28, 26 → 28, 26 → 27 on set 21 but 28 → 27, 26 → 25 on stress34, CPU +17–34 %;
still off.  The layout drawn on the curve is another layout (:func:`onto_curves`: the layout of
the straight segments with its blocks' shore on the curve, tried, ``CURVE_ON_STRAIGHT``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

__all__ = ["Curves", "curve_ring", "curved_shore", "curved_shores", "onto_curves"]

#: A vertex turning by more than this (degrees) is a corner the curve keeps.
CORNER = 60.0
#: Largest distance (cells) of the curve from the chord of its segment.
BULGE = 0.25
#: Segments shorter than this (cells) stay straight.
SHORT = 0.5
#: The curve is sampled every this many cells.
STEP = 0.5
#: A point of a segment this near a sample (in steps between samples) is moved onto it.
SNAP = 1e-6


def _turning(p: np.ndarray) -> np.ndarray:
    """The turning angle (degrees, unsigned) at every vertex of the closed ring ``p``."""
    e = np.roll(p, -1, axis=0) - p
    f = np.roll(e, 1, axis=0)  # the segment into each vertex
    cross = f[:, 0] * e[:, 1] - f[:, 1] * e[:, 0]
    return np.degrees(np.abs(np.arctan2(cross, (f * e).sum(axis=1))))


def curve_ring(ring: Any, h: float) -> np.ndarray:
    """The closed ring ``ring`` ((n, 2), not repeating its first point) with every segment
    longer than ``SHORT`` cells replaced by its spline (see the module), as an (m, 2) array
    that holds every vertex of ``ring`` in order.  ``ring`` itself (as an array) when no
    segment is that long."""
    return _curve(ring, h)[0]


def _curve(ring: Any, h: float) -> tuple[np.ndarray, np.ndarray]:
    """:func:`curve_ring` and the number of its samples on each segment of ``ring`` (the first
    at the segment's first vertex, the others at equal steps of the segment's parameter)."""
    p = np.asarray(ring, dtype=float)
    n = len(p)
    nxt = np.roll(p, -1, axis=0)
    length = np.hypot(*(nxt - p).T)
    if n < 3 or not np.any(length > SHORT * h):
        return p, np.ones(n, dtype=int)
    d = (nxt - p) / np.maximum(length, 1e-300)[:, None]  # each segment's direction
    # the curve's direction at a vertex: the mean of the two segments' directions weighted by
    # their squared lengths — a long straight segment beside short ones stays straight (the
    # shore turns where it is sampled densely), evenly spaced points get the bisector
    w_in, w_out = np.roll(length, 1)[:, None] ** 2, length[:, None] ** 2
    m = w_in * np.roll(d, 1, axis=0) + w_out * d
    m /= np.maximum(np.hypot(*m.T), 1e-300)[:, None]
    sharp = _turning(p) > CORNER
    i2 = (np.arange(n) + 1) % n
    # at a corner the curve leaves (and reaches) it along the segment itself
    m1 = np.where(sharp[:, None], d, m)
    m2 = np.where(sharp[i2, None], d, m[i2])
    k = np.where(length > SHORT * h, np.maximum(1, np.ceil(length / (STEP * h))).astype(int), 1)
    seg = np.repeat(np.arange(n), k)
    # the parameter of each sample within its segment, 0 ≤ u < 1
    u = (np.arange(len(seg)) - np.repeat(np.cumsum(k) - k, k)) / np.repeat(k, k)
    q = _hermite(p[seg], nxt[seg], length[seg, None] * m1[seg], length[seg, None] * m2[seg], u)
    q = _within_bulge(q, p, nxt, length, seg, h)
    q[u == 0] = p  # the vertices themselves, exactly
    return q, k


def _hermite(p1, p2, t1, t2, u) -> np.ndarray:
    """Points of the cubic Hermite segments from ``p1`` (tangent ``t1``) to ``p2`` (``t2``) at
    ``u`` ∈ [0, 1)."""
    u = u[:, None]
    u2, u3 = u * u, u * u * u
    return (2 * u3 - 3 * u2 + 1) * p1 + (u3 - 2 * u2 + u) * t1 + (3 * u2 - 2 * u3) * p2 + (u3 - u2) * t2


def _within_bulge(q, p, nxt, length, seg, h) -> np.ndarray:
    """``q`` with each segment's offsets from its chord scaled down to at most ``BULGE`` cells."""
    d = (nxt - p) / np.maximum(length, 1e-300)[:, None]
    normal = np.column_stack([-d[:, 1], d[:, 0]])[seg]
    off = ((q - p[seg]) * normal).sum(axis=1)
    worst = np.zeros(len(p))
    np.maximum.at(worst, seg, np.abs(off))
    scale = np.where(worst > BULGE * h, BULGE * h / np.maximum(worst, 1e-300), 1.0)[seg]
    return q - (off * (1.0 - scale))[:, None] * normal


def curved_shore(poly: Any, h: float) -> tuple[Any, list[str]]:
    """The water polygon ``poly`` with every ring drawn as its curve (:func:`curve_ring`),
    and a note.  Where the curves would make the polygon invalid (rings that touch or cross,
    an island lost), the islands keep their segments, then every ring does."""
    new, _, notes = curved_shores(poly, h)
    return new, notes


@dataclass(frozen=True, slots=True, eq=False)
class Curves:
    """The rings of a water polygon (``rings``: outline, then islands, as ``polygon.exterior`` and
    ``interiors`` give them) and their curves (``samples``; a ring kept straight is its own
    curve); ``count[k][i]``: the samples of ring ``k``'s curve on its segment ``i``, from
    ``first[k][i]``."""

    rings: list[np.ndarray]
    samples: list[np.ndarray]
    count: list[np.ndarray]
    first: list[np.ndarray]

    def at(self, k: int, i: int, u: float) -> np.ndarray:
        """The point of ring ``k``'s curve at parameter ``u`` (0 ≤ u ≤ 1) of its segment ``i``,
        on the polyline of the samples (a sample itself within ``SNAP`` of its parameter)."""
        q, c = self.samples[k], int(self.count[k][i])
        t = u * c
        m = min(int(np.floor(t)), c - 1)
        a = int(self.first[k][i]) + m
        f = t - m
        if f <= SNAP:
            return q[a].copy()
        if f >= 1 - SNAP:
            return q[(a + 1) % len(q)].copy()
        return q[a] + f * (q[(a + 1) % len(q)] - q[a])


def curved_shores(poly: Any, h: float) -> tuple[Any, Curves | None, list[str]]:
    """:func:`curved_shore`, and the :class:`Curves` that map a point of ``poly``'s shore onto
    the new one (:func:`onto_curves`; None when nothing is curved)."""
    from shapely.geometry import Polygon
    from shapely.geometry.polygon import orient

    given, poly = poly, orient(poly, 1.0)
    rings = [np.asarray(poly.exterior.coords)[:-1], *(np.asarray(r.coords)[:-1] for r in poly.interiors)]
    drawn = [_curve(r, h) for r in rings]
    curved = [c for c, _ in drawn]
    if all(len(c) == len(r) for c, r in zip(curved, rings, strict=True)):
        return given, None, []
    for candidate in (curved, curved[:1] + rings[1:]):
        if all(len(c) == len(r) for c, r in zip(candidate, rings, strict=True)):
            break  # nothing of it curved
        new = Polygon(candidate[0], candidate[1:])
        if new.is_valid and len(new.interiors) == len(poly.interiors):
            long = sum(int(np.sum(np.hypot(*(np.roll(r, -1, 0) - r).T) > SHORT * h)) for r in rings)
            total = sum(len(r) for r in rings)
            islands = (
                "" if candidate is curved or len(rings) == 1 else " (the islands kept as given: curved, they touched)"
            )
            note = (
                f"shore drawn as a smooth curve through the outline's points ({long} of its {total} segments are "
                f"longer than half a cell; turns sharper than {CORNER:g}° kept as corners), at most {BULGE:g} cells "
                f"from its straight segments{islands}"
            )
            counts = [k if c is curved[j] else np.ones(len(rings[j]), dtype=int) for j, (c, k) in enumerate(drawn)]
            if candidate is not curved:
                counts = counts[:1] + [np.ones(len(r), dtype=int) for r in rings[1:]]
            firsts = [np.cumsum(c) - c for c in counts]
            # orient keeps the order of a ring that runs the right way round (``poly`` was oriented)
            return orient(new, 1.0), Curves(rings, candidate, counts, firsts), [note]
    return given, None, []


def onto_curves(pieces: list, curves: Curves, grid: Any) -> list | None:
    """The pieces of a layout drawn on the straight segments (``curves.rings``) with their shore
    on the curves: every piece vertex on a segment moves to the same parameter of the segment's
    curve, and between two piece vertices on one segment the curve's samples are put in.  The
    layout, its corners and cut lines stay those of the straight shore; a cut's end moves by at
    most ``BULGE`` cells.  None when a moved piece is not a valid polygon or the pieces do not
    cover ``grid`` (the curved water) exactly."""
    import math

    import shapely
    from shapely.geometry import Polygon

    from ..segments import SegmentIndex
    from .blocks import Piece

    x0, y0, x1, y1 = grid.bounds
    eps = 1e-7 * math.hypot(x1 - x0, y1 - y0)
    index = SegmentIndex(curves.rings)
    vertex = {(float(p[0]), float(p[1])): (k, i) for k, r in enumerate(curves.rings) for i, p in enumerate(r)}

    def where(p) -> tuple[int, int, float] | None:
        hit = vertex.get((float(p[0]), float(p[1])))
        if hit is not None:
            return hit[0], hit[1], 0.0
        if not index.near(p[None], eps, within=True)[0]:
            return None
        _, k, i, u = index.nearest(p)
        return k, i, float(min(max(u, 0.0), 1.0))

    def options(w) -> list[tuple[int, float]]:
        k, i, u = w
        n = len(curves.rings[k])
        out = [(i, u)]
        if u <= 1e-12:
            out.append(((i - 1) % n, 1.0))
        if u >= 1 - 1e-12:
            out.append(((i + 1) % n, 0.0))
        return out

    out = []
    for pc in pieces:
        ring = np.asarray(pc.ring, dtype=float)
        on = [where(p) for p in ring]
        new: list[np.ndarray] = []
        at: list[int] = []
        for j, p in enumerate(ring):
            at.append(len(new))
            w = on[j]
            new.append(p.copy() if w is None else curves.at(*w))
            v = on[(j + 1) % len(ring)]
            if w is None or v is None or w[0] != v[0]:
                continue
            k = w[0]
            shared = [(s, ua, ub) for s, ua in options(w) for t, ub in options(v) if s == t and ua != ub]
            if not shared:
                continue
            s, ua, ub = shared[0]
            c, f = int(curves.count[k][s]), int(curves.first[k][s])
            lo, hi = sorted((ua * c, ub * c))
            ms = [m for m in range(1, c) if lo + SNAP < m < hi - SNAP]
            q = curves.samples[k]
            new.extend(q[(f + m) % len(q)].copy() for m in (ms if ua < ub else ms[::-1]))
        # a point moved onto a sample is that sample once
        slot = np.zeros(len(new), dtype=int)  # each point's place in the ring without repeats
        keep = [0]
        for j in range(1, len(new)):
            if not np.array_equal(new[j], new[keep[-1]]):
                keep.append(j)
            slot[j] = len(keep) - 1
        while len(keep) > 1 and np.array_equal(new[keep[-1]], new[0]):
            slot[slot == len(keep) - 1] = 0
            keep.pop()
        sw, se, ne, nw = (int(slot[at[c]]) for c in pc.corners)
        corners = (sw, se, ne, nw)
        if len(keep) < 3 or len(set(corners)) < 4:
            return None
        out.append(Piece(np.array([new[j] for j in keep]), corners, pc.name))
    polys = [Polygon(p.ring) for p in out]
    if not all(p.is_valid for p in polys):
        return None
    area = grid.area
    if abs(sum(p.area for p in polys) - area) > 1e-6 * area:
        return None
    if shapely.union_all(polys).symmetric_difference(grid).area > 1e-6 * area:
        return None
    return out
