"""Editing a lake layout by hand: the handles a user drags and what a move does (no Qt).

A layout is edited in its ``[outline]`` form (:func:`meshcore.layout.outline.outline_parts`:
the shore, the islands, the cut lines, each block's corners and cells).  The handles are

* the **ends** of the cut lines — on the shore (or an island) they stay on it: a dragged end
  slides along it; where cut lines meet inside the water (a junction) they move freely;
* the **interior points** of the cut lines — free;
* the **corners** of the blocks that are not cut ends — they stay on their block's boundary;
* the **shore points** (the vertices of the shore and the islands) — free: the shore between
  the point and its neighbouring vertices follows, with the cut ends and corners on it.

A move puts the handle at the new place; the cuts through it bend smoothly to follow (their
far ends stay) and the block corners on them move along (a cut's end and the corners of the
blocks that meet there move together); it keeps the cell counts (so the grid re-solves from
the previous one), and the new layout is made by :func:`moved_layout` (one
:func:`meshcore.multiblock.from_outline` for the layout and its topology, whose checks name the
block or cut that cannot be four-sided); a move that would change the blocks (a cut dragged
across another) is refused.  :func:`without_cut` removes a cut line: the two blocks it parted
become one.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from meshcore.errors import TopologyError

__all__ = [
    "KIND_NAMES",
    "DragSteps",
    "Handle",
    "MoveRefused",
    "handles",
    "moved_layout",
    "moved_parts",
    "nearest_handle",
    "place",
    "settled_layout",
    "shore_points",
    "snapped_cut",
    "with_cut",
    "with_drawn_cut",
    "without_cut",
]

#: the order in which coinciding handles are picked
_PRIORITY = {"end": 0, "junction": 0, "corner": 1, "cut": 2, "shore": 3}
#: what a handle is called in messages and undo texts
KIND_NAMES = {
    "end": "cut end",
    "junction": "junction",
    "cut": "cut point",
    "corner": "block corner",
    "shore": "shore point",
}


@dataclass(frozen=True, slots=True)
class Handle:
    """A point of the layout a user can drag: ``kind`` "end", "junction", "cut", "corner" or "shore", at ``xy``."""

    kind: str
    xy: tuple[float, float]
    cut: int = -1  # the cut it belongs to ("end", "cut")
    block: int = -1  # the block it is a corner of ("corner")


def _same(a, b, tol: float) -> bool:
    return abs(float(a[0]) - float(b[0])) <= tol and abs(float(a[1]) - float(b[1])) <= tol


def handles(layout: Any) -> list[Handle]:
    """Every handle of ``layout`` (cut ends, interior cut points, block corners, shore points), no two at one place."""
    tol = 1e-9 * max(1.0, float(np.sqrt(layout.polygon.area)))
    out: list[Handle] = []
    # the handles so far by a grid of tol-sized cells: one within tol of a new one is in one of
    # the 3 × 3 cells round it (a scan of all of them was quadratic: 42 -> 8 ms CPU for 591 handles)
    cells: dict[tuple[int, int], list[tuple[float, float]]] = {}

    def add(h: Handle) -> None:
        i, j = math.floor(h.xy[0] / tol), math.floor(h.xy[1] / tol)
        near = (cells.get((i + a, j + b), ()) for a in (-1, 0, 1) for b in (-1, 0, 1))
        if not any(_same(h.xy, q, tol) for cell in near for q in cell):
            cells.setdefault((i, j), []).append(h.xy)
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
    for p in shore_points(layout):
        add(Handle("shore", (float(p[0]), float(p[1]))))
    return out


def shore_points(layout: Any) -> np.ndarray:
    """The vertices of the shore and the islands of ``layout`` (its water polygon), ``(n, 2)``."""
    poly = layout.polygon
    rings = [np.asarray(poly.exterior.coords)[:-1], *(np.asarray(r.coords)[:-1] for r in poly.interiors)]
    return np.vstack(rings) if rings else np.zeros((0, 2))


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
    if handle.kind == "shore":
        return (float(xy[0]), float(xy[1]))
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


def moved_parts(parts: dict, old: Any, new: Any, tol: float, shore: Any = None) -> dict:
    """``parts`` (the ``[outline]`` form) with the handle at ``old`` put at ``new``.

    Every cut through ``old`` bends smoothly to follow it (:func:`_weights`; the cut's far ends
    stay), and every block corner on a moved cut point moves with it; the cells are kept.
    ``shore`` (a shore point is dragged): the shore's vertices, ``(n, 2)``; the shore's sampling
    points between ``old`` and its neighbouring vertices follow it (:func:`_moved_ring`), with
    the cut ends and corners on them.
    """
    old = np.asarray(old, float)
    d = np.asarray(new, float) - old
    moves: dict[tuple[float, float], tuple[float, float]] = {}
    rings: dict = {}
    ring_moves: list = []
    if shore is not None:
        stops = np.asarray(shore, float).reshape(-1, 2)
        outline, ring_moves = _moved_ring(np.asarray(parts["outline"], float), old, d, stops, tol)
        holes = []
        for hole in parts.get("holes", ()):
            hole, more = _moved_ring(np.asarray(hole, float), old, d, stops, tol)
            holes.append(hole)
            ring_moves += more
        rings = {"outline": outline, "holes": holes}
    cuts = []
    for c in parts["cuts"]:
        c = np.asarray(c, float)
        hit = np.flatnonzero(np.all(np.abs(c - old) <= tol, axis=1))
        if len(hit):
            moved = c + _weights(c, int(hit[0]))[:, None] * d
        else:  # a cut whose end sits on a moved piece of shore bends with it
            moved = c.copy()
            for a, b in ring_moves:
                for k in (0, len(c) - 1):
                    if _same(c[k], a, tol):
                        moved = moved + _weights(c, k)[:, None] * (np.asarray(b) - np.asarray(a))
        if len(hit) or not np.array_equal(moved, c):
            for a, b in zip(c, moved, strict=True):
                moves[(float(a[0]), float(a[1]))] = (float(b[0]), float(b[1]))
            c = moved
        cuts.append([(float(p[0]), float(p[1])) for p in c])
    for a, b in ring_moves:
        moves.setdefault((float(a[0]), float(a[1])), (float(b[0]), float(b[1])))

    src = np.array(list(moves), float).reshape(-1, 2)
    dst = list(moves.values())

    def move(p):
        p = (float(p[0]), float(p[1]))
        if _same(p, old, tol):
            return (float(old[0] + d[0]), float(old[1] + d[1]))
        hit = np.flatnonzero(np.all(np.abs(src - p) <= tol, axis=1))
        return dst[int(hit[0])] if len(hit) else p

    blocks = [dict(b, corners=[move(p) for p in b["corners"]]) for b in parts["blocks"]]
    return dict(parts, **rings, cuts=cuts, blocks=blocks)


def _moved_ring(ring: np.ndarray, old: np.ndarray, d: np.ndarray, stops: np.ndarray, tol: float):
    """``ring`` with its vertex at ``old`` moved by ``d``; the points between it and the next of the
    ``stops`` (the shore's own vertices) or turn on either side (the sampling points the layout
    put on the shore's straight edges) follow linearly.

    Returns the new ring and the ``(old point, new point)`` pairs of every point that moved.
    """
    hit = np.flatnonzero(np.all(np.abs(ring - old) <= tol, axis=1))
    if not len(hit) or not np.any(d):
        return ring, []
    n, i = len(ring), int(hit[0])
    out = ring.copy()
    out[i] = ring[i] + d
    moved = [(ring[i], out[i])]
    for step in (1, -1):
        run = []  # the points on the straight edge from vertex i to the next turn
        k = (i + step) % n
        while k != i and len(run) < n - 2 and _straight(ring[(k - 1) % n], ring[k], ring[(k + 1) % n], tol):
            if np.any(np.all(np.abs(stops - ring[k]) <= tol, axis=1)):
                break
            run.append(k)
            k = (k + step) % n
        pts = [i, *run, k]  # k: the turn that stays
        s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(ring[pts], axis=0).T))])
        for j, sj in zip(run, s[1:-1], strict=True):
            out[j] = ring[j] + (1.0 - sj / s[-1]) * d
            moved.append((ring[j], out[j]))
    return out, moved


def _straight(a, b, c, tol: float) -> bool:
    """True when ``b`` lies on the segment from ``a`` to ``c`` (a sampling point, not a turn)."""
    ab, ac = np.asarray(b) - np.asarray(a), np.asarray(c) - np.asarray(a)
    cross = abs(float(ab[0] * ac[1] - ab[1] * ac[0]))
    return cross <= 1e-9 * float(np.dot(ac, ac)) + tol * tol


class DragSteps:
    """What the steps of one drag share (the layout worker runs them one after another).

    ``cells``: the cells of the chains of every block side (``OutlineBlocks.side_cells``) of the
    drag's first layout: later steps keep them while they fit (a cut end moved along the shore
    keeps them), without the integer program that shares a side's cells among its parts (on
    Como 12 of the 55 ms of a step).  The program's shares can differ a little from the kept
    ones, so the drag's last layout is made without them (:func:`settled_layout`).  ``good``:
    the parts of the last step that gave a layout, ``kept``: whether it kept cells.
    """

    def __init__(self) -> None:
        self.cells: Any = None
        self.good: dict | None = None
        self.kept = False


class MoveRefused(TopologyError):
    """The last step of a drag gives no layout: ``layout`` is the one that stays (the drag's last
    good step, made as :func:`moved_layout` without kept cells makes it)."""

    def __init__(self, message: str, layout: Any) -> None:
        super().__init__(message)
        self.layout = layout


def moved_layout(base: Any, parts: dict, steps: DragSteps | None = None) -> Any:
    """The layout of ``parts`` (a move of :func:`moved_parts` on ``base``), with ``base``'s blocks.

    One :func:`~meshcore.multiblock.from_outline` of ``parts`` makes both the layout and its
    topology (kept on it): without ``steps``, the one a case of the layout gives, as
    :meth:`Layout.topology <meshcore.layout.Layout.topology>` would make it by a second call
    (the same shore, cuts and blocks, at its snap distance and cell size).  ``steps`` (a step
    of a drag): the chains' cells of the drag's first layout are kept while they fit.

    Raises :class:`~meshcore.errors.TopologyError` naming the problem when the parts give no
    layout, or when they give other blocks (a cut dragged across another cut or an island):
    a drag keeps the blocks and their cells, so that the grid re-solves from the previous one.
    """
    from meshcore.layout.edit import layout_of_outline
    from meshcore.layout.outline import shore_of, topology_snap
    from meshcore.multiblock.outline import from_outline

    keep = None if steps is None else steps.cells
    ob = from_outline(
        parts["outline"],
        holes=parts["holes"],
        cuts=parts["cuts"],
        blocks=parts["blocks"],
        multiple=base.multiple,
        snap=topology_snap(base.polygon),
        cell_size=base.cell_size,
        keep_cells=keep,
        single=base.single,
    )
    lay = layout_of_outline(ob, parts["blocks"], cell_size=base.cell_size, multiple=base.multiple, single=base.single)
    before = [(b.name, tuple(b.cells)) for b in base.blocks]
    after = [(b.name, tuple(b.cells)) for b in lay.blocks]
    if len(after) != len(before):
        raise TopologyError(
            f"the move would make {len(after)} blocks of the {len(before)} (a cut line crossing another "
            f"or the shore); drag it back, or use Auto layout for a new one"
        )
    if after != before:
        changed = next(f"{a[0]} ({a[1][0]}×{a[1][1]})" for a, b in zip(after, before, strict=True) if a != b)
        raise TopologyError(f"the move would change block {changed}; a drag keeps every block and its cells")
    _, islands = shore_of(list(lay.pieces))  # the shore a case of the layout writes: one ring and the islands
    if len(islands) != len(lay.polygon.interiors):
        raise TopologyError(
            "the move would leave the blocks' shore in pieces (a case of it would not read back as one "
            "shore and its islands); drag it back"
        )
    object.__setattr__(lay, "_topology", ob.topology)  # made, checked: the layout's own (Layout.topology)
    if steps is not None:
        steps.cells = ob.side_cells if keep is None else keep
        steps.good, steps.kept = parts, keep is not None
    return lay


def settled_layout(base: Any, parts: dict, steps: DragSteps | None = None) -> Any:
    """The last layout of a drag: :func:`moved_layout` of ``parts`` without kept cells (what a
    case of it gives).  When they give none while the layout on screen kept cells, raises
    :class:`MoveRefused` with that layout made so."""
    try:
        return moved_layout(base, parts)
    except TopologyError as exc:
        if steps is None or steps.good is None or not steps.kept:
            raise
        raise MoveRefused(str(exc), moved_layout(base, steps.good)) from exc


def without_cut(layout: Any, k: int) -> Any:
    """``layout`` without its cut line ``k``: the blocks it parted are one block, cornered where it
    turns (:func:`meshcore.layout.edit.layout_from_cuts`); every other block keeps its corners, and
    the cells follow from the layout's cell size."""
    from shapely.geometry import LineString

    mid = LineString(np.asarray(layout.cuts[k], float)).interpolate(0.5, normalized=True)
    tol = 1e-6 * layout.cell_size
    cuts = [c for j, c in enumerate(layout.cuts) if j != k]
    # a block the cut bounds joins its neighbour
    return _recut(layout, cuts, lambda ring: ring.boundary.distance(mid) <= tol)


def with_cut(layout: Any, cut: Any) -> Any:
    """``layout`` with a cut line drawn by hand (its ends snap to the shore, an island or a cut): the
    blocks it crosses are parted and cornered where their parts turn
    (:func:`meshcore.layout.edit.layout_from_cuts`); every other block keeps its corners, and the
    cells follow from the layout's cell size."""
    from shapely.geometry import LineString

    line = LineString(np.asarray(cut, float))
    tol = 1e-6 * layout.cell_size
    cuts = [*layout.cuts, np.asarray(cut, float)]
    return _recut(layout, cuts, lambda ring: ring.intersection(line).length > tol)


def snapped_cut(layout: Any, cut: Any, cells: float | None = None) -> tuple[np.ndarray, list[str]]:
    """A cut drawn by hand over ``layout`` with each end that lands within ``cells`` cells
    (default :data:`meshcore.layout.edit.SNAP_CELLS`) of a cut end, block corner or shore tip put on
    it (:func:`meshcore.layout.edit.snap_cut`; an end a few cells off makes a thin wedge block),
    and a message per snapped end (none: the ends stay where drawn)."""
    from meshcore.layout.edit import SNAP_CELLS, snap_cut, snap_note, snap_targets

    h = float(layout.cell_size)
    d = (SNAP_CELLS if cells is None else float(cells)) * h
    corners = [p for b in layout.blocks for p in b.corners]
    targets = snap_targets(layout.polygon, layout.cuts, corners)
    out, snaps = snap_cut(layout.polygon, cut, targets, d, layout.cuts)
    if not snaps:
        return np.asarray(cut, float), []
    return out, [snap_note("Cut line", s, h) for s in snaps]


def with_drawn_cut(layout: Any, cut: Any, report: Callable[[str, str], None] | None = None) -> Any:
    """:func:`with_cut` of a cut drawn by hand, its ends snapped (:func:`snapped_cut`); ``report(level,
    text)`` gets a message per snapped end.  When the snapped cut gives no layout (a cut put along
    another one) the cut is taken as drawn, and its error is the one it gives unsnapped."""
    snapped, notes = snapped_cut(layout, cut)
    if not notes:
        return with_cut(layout, cut)
    try:
        out = with_cut(layout, snapped)
    except TopologyError as exc:
        out = with_cut(layout, cut)
        if report is not None:
            report("info", f"Cut line: its ends stay where drawn (snapped, it gives no layout: {exc})")
        return out
    for note in notes:
        if report is not None:
            report("info", note)
    return out


def _recut(layout: Any, cuts: list, changed: Callable[[Any], bool]) -> Any:
    """The layout of ``cuts`` in ``layout``'s water, every block but those ``changed`` (a test on
    its polygon) keeping its corners."""
    from shapely.geometry import Polygon

    from meshcore.layout.edit import layout_from_cuts

    corners = {}
    for piece in layout.pieces:
        ring = Polygon(piece.ring)
        if changed(ring):
            continue
        q = ring.representative_point()
        corners[(q.x, q.y)] = [piece.ring[i] for i in piece.corners]
    return layout_from_cuts(layout.polygon, cuts, cell_size=layout.cell_size, multiple=layout.multiple, corners=corners)
