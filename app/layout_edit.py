"""Editing a lake layout by hand: the handles a user drags and what a move does (no Qt).

A layout is edited in its ``[outline]`` form (:func:`meshcore.layout.outline.outline_parts`:
the shore, the islands, the cut lines, each block's corners and cells).  The handles are

* the **ends** of the cut lines — on the shore (or an island) they stay on it: a dragged end
  slides along it; where cut lines meet inside the water (a junction) they move freely;
* the **interior points** of the cut lines — free;
* the **corners** of the blocks that are not cut ends — they stay on their block's boundary.

A move puts the handle at the new place; the cuts through it bend smoothly to follow (their
far ends stay) and the block corners on them move along (a cut's end and the corners of the
blocks that meet there move together); it keeps the cell counts (so the grid re-solves from
the previous one), and the new layout is made by :func:`meshcore.layout.layout_from_outline`,
whose checks name the block or cut that cannot be four-sided.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

__all__ = ["Handle", "handles", "moved_parts", "nearest_handle", "place"]

#: the order in which coinciding handles are picked
_PRIORITY = {"end": 0, "junction": 0, "corner": 1, "cut": 2}


@dataclass(frozen=True, slots=True)
class Handle:
    """A point of the layout a user can drag: ``kind`` "end", "junction", "cut" or "corner", at ``xy``."""

    kind: str
    xy: tuple[float, float]
    cut: int = -1  # the cut it belongs to ("end", "cut")
    block: int = -1  # the block it is a corner of ("corner")


def _same(a, b, tol: float) -> bool:
    return abs(float(a[0]) - float(b[0])) <= tol and abs(float(a[1]) - float(b[1])) <= tol


def handles(layout: Any) -> list[Handle]:
    """Every handle of ``layout`` (cut ends, interior cut points, block corners), no two at one place."""
    tol = 1e-9 * max(1.0, float(np.sqrt(layout.polygon.area)))
    out: list[Handle] = []

    def add(h: Handle) -> None:
        if not any(_same(h.xy, o.xy, tol) for o in out):
            out.append(h)

    from shapely.geometry import Point

    shore = layout.polygon.boundary
    for k, c in enumerate(layout.cuts):
        c = np.asarray(c, float)
        for p in (c[0], c[-1]):
            on_shore = shore.distance(Point(float(p[0]), float(p[1]))) <= 1e3 * tol
            add(Handle("end" if on_shore else "junction", (float(p[0]), float(p[1])), cut=k))
    for k, b in enumerate(layout.blocks):
        for p in b.corners:
            add(Handle("corner", (float(p[0]), float(p[1])), block=k))
    for k, c in enumerate(layout.cuts):
        for p in np.asarray(c, float)[1:-1]:
            add(Handle("cut", (float(p[0]), float(p[1])), cut=k))
    return out


def nearest_handle(hs: list[Handle], xy: Any, tol: float) -> Handle | None:
    """The handle within ``tol`` of ``xy`` (ends before corners before interior points), or None."""
    x, y = float(xy[0]), float(xy[1])
    near = [(float(np.hypot(h.xy[0] - x, h.xy[1] - y)), _PRIORITY[h.kind], h) for h in hs]
    near = [t for t in near if t[0] <= tol]
    if not near:
        return None
    best = min(d for d, _p, _h in near)
    # among the handles about as near as the nearest one, the most important kind
    return min((t for t in near if t[0] <= best + 0.25 * tol), key=lambda t: (t[1], t[0]))[2]


def _project(rings: list[np.ndarray], xy: Any) -> tuple[float, float]:
    """The point nearest ``xy`` on any of the closed ``rings``."""
    from shapely.geometry import LinearRing, Point

    p = Point(float(xy[0]), float(xy[1]))
    best = None
    for r in rings:
        ring = LinearRing(np.asarray(r, float))
        q = ring.interpolate(ring.project(p))
        d = q.distance(p)
        if best is None or d < best[0]:
            best = (d, (float(q.x), float(q.y)))
    assert best is not None
    return best[1]


def place(layout: Any, handle: Handle, xy: Any, parts: dict | None = None) -> tuple[float, float]:
    """Where ``handle`` goes when dragged to ``xy``: a cut end onto the shore, a corner onto its block.

    A block corner must sit on a vertex of the shore or of a cut: with ``parts`` (the
    ``[outline]`` form the layout is remade from) it goes to the vertex of its block's boundary
    nearest to where it was dragged.
    """
    if handle.kind == "end":
        poly = layout.polygon
        rings = [np.asarray(poly.exterior.coords)[:-1], *(np.asarray(r.coords)[:-1] for r in poly.interiors)]
        return _project(rings, xy)
    if handle.kind == "corner":
        ring = np.asarray(layout.pieces[handle.block].ring, float)
        q = _project([ring], xy)
        if parts is None:
            return q
        return _nearest_vertex_on(ring, parts, q)
    return (float(xy[0]), float(xy[1]))


def _nearest_vertex_on(ring: np.ndarray, parts: dict, q) -> tuple[float, float]:
    """The vertex of the shore, the islands or the cuts on the closed ``ring`` nearest to ``q``."""
    from shapely.geometry import LinearRing, MultiPoint

    pts = np.vstack([np.asarray(parts["outline"], float).reshape(-1, 2)])
    more = [np.asarray(h, float).reshape(-1, 2) for h in parts.get("holes", ())]
    more += [np.asarray(c, float).reshape(-1, 2) for c in parts.get("cuts", ())]
    pts = np.vstack([pts, *more]) if more else pts
    r = LinearRing(ring)
    size = float(np.hypot(*np.ptp(ring, axis=0)))
    d_ring = np.asarray(r.distance(MultiPoint(pts).geoms), float)
    on = pts[d_ring <= 1e-7 * size]
    if not len(on):
        return (float(q[0]), float(q[1]))
    k = int(np.argmin(np.hypot(on[:, 0] - q[0], on[:, 1] - q[1])))
    return (float(on[k, 0]), float(on[k, 1]))


def _weights(c: np.ndarray, k: int) -> np.ndarray:
    """How much each vertex of cut ``c`` follows its vertex ``k``: 1 there, falling linearly
    (by arclength) to 0 at the cut's other end(s) — the cut bends smoothly, its ends stay."""
    s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(c, axis=0).T))])
    total = s[-1]
    w = np.zeros(len(c))
    if total <= 0:
        w[k] = 1.0
        return w
    sk = s[k]
    before = s <= sk
    w[before] = s[before] / sk if sk > 0 else 1.0
    w[~before] = (total - s[~before]) / (total - sk) if total > sk else 1.0
    return w


def moved_parts(parts: dict, old: Any, new: Any, tol: float) -> dict:
    """``parts`` (the ``[outline]`` form) with the handle at ``old`` put at ``new``.

    Every cut through ``old`` bends smoothly to follow it (:func:`_weights`; the cut's far ends
    stay), and every block corner on a moved cut point moves with it; the cells are kept.
    """
    old = np.asarray(old, float)
    d = np.asarray(new, float) - old
    moves: dict[tuple[float, float], tuple[float, float]] = {}
    cuts = []
    for c in parts["cuts"]:
        c = np.asarray(c, float)
        hit = np.flatnonzero(np.all(np.abs(c - old) <= tol, axis=1))
        if len(hit):
            moved = c + _weights(c, int(hit[0]))[:, None] * d
            for a, b in zip(c, moved, strict=True):
                moves[(float(a[0]), float(a[1]))] = (float(b[0]), float(b[1]))
            c = moved
        cuts.append([(float(p[0]), float(p[1])) for p in c])

    def move(p):
        p = (float(p[0]), float(p[1]))
        if _same(p, old, tol):
            return (float(old[0] + d[0]), float(old[1] + d[1]))
        return next((q for a, q in moves.items() if _same(p, a, tol)), p)

    blocks = [dict(b, corners=[move(p) for p in b["corners"]]) for b in parts["blocks"]]
    return dict(parts, cuts=cuts, blocks=blocks)
