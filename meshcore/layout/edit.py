r"""Layouts made or changed by hand: from a shore, islands and cut lines; one block's cells set.

:func:`layout_from_outline` takes what a case's ``[outline]`` holds (cuts, blocks with corners
and cells); :func:`layout_from_cuts` only cut lines (each region's corners where it turns,
cells from the cell size); :func:`with_cells` sets one block's cells and lets its neighbours
follow.  The checks of :func:`meshcore.multiblock.from_outline` name the block, cut or island
at fault.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .blocks import block_counts
from .handcut import _countable, _four_vertices, _pieces_of_regions, _shore_ends_in_rings, _where_counts_fail
from .model import Layout, LayoutBlock
from .outline import _size

__all__ = [
    "SNAP_CELLS",
    "layout_from_cuts",
    "layout_from_outline",
    "layout_of_outline",
    "snap_cut",
    "snap_note",
    "snap_targets",
    "with_cells",
]


def layout_from_outline(
    outline: Any,
    *,
    cuts: Any,
    blocks: Any,
    holes: Any = (),
    cell_size: float | None = None,
    multiple: int = 1,
    single: bool = False,
):
    """A :class:`~meshcore.layout.Layout` from a shore, islands, cut lines and blocks (corners, cells).

    The inputs are those of :func:`meshcore.multiblock.from_outline`, whose checks name the
    block, cut or island at fault; ``cell_size`` (default: the mean size of the blocks' cells)
    sets how densely the orthogonal smoother samples the shore; ``single``: a layout for one index
    space (its rings' counts closed, :mod:`meshcore.multiblock.closure`).
    """
    from ..multiblock.outline import from_outline

    ob = from_outline(outline, holes=holes, cuts=cuts, blocks=blocks, multiple=multiple, single=single)
    return layout_of_outline(ob, blocks, cell_size=cell_size, multiple=multiple, single=single)


def layout_of_outline(ob: Any, blocks: Any, *, cell_size: float | None = None, multiple: int = 1, single: bool = False):
    """The :class:`~meshcore.layout.Layout` of ``ob`` (a :func:`meshcore.multiblock.from_outline`
    of ``blocks``): its regions become the pieces, in the order of ``blocks``."""
    from ..multiblock.outline import BlockOutline
    from .polygon import water_polygon

    specs = [BlockOutline.coerce(b) for b in blocks]
    poly, notes = water_polygon(ob.outline, holes=list(ob.islands))
    h = float(cell_size) if cell_size else math.sqrt(poly.area / sum(s.cells[0] * s.cells[1] for s in specs))
    regions = list(ob.regions)
    topo = ob.topology
    # every region is one block's (from_outline checks it): the block of each region, in the regions' order
    block_of = {fi: topo.blocks[k] for k, fi in enumerate(ob.block_regions)}
    names, corners = [], []
    for fi in range(len(regions)):
        b = block_of[fi]
        names.append(b.name)
        corners.append([b.borders.bottom[0], b.borders.bottom[-1], b.borders.top[-1], b.borders.top[0]])
    pieces = _pieces_of_regions(regions, corners, names, _size(poly))
    lblocks = tuple(
        LayoutBlock(n, tuple((float(p[0]), float(p[1])) for p in cs), (int(b.cells[0]), int(b.cells[1])))
        for n, cs, b in zip(names, corners, (block_of[fi] for fi in range(len(regions))), strict=True)
    )
    order = {s.name: k for k, s in enumerate(specs)}
    perm = sorted(range(len(pieces)), key=lambda k: order[names[k]])
    return Layout(
        polygon=poly,
        cell_size=h,
        cuts=tuple(np.asarray(c) for c in ob.cuts),
        pieces=tuple(pieces[k] for k in perm),
        blocks=tuple(lblocks[k] for k in perm),
        multiple=multiple,
        notes=tuple(notes),
        single=single,
    )


#: how near (in cells) a hand-drawn cut's end must land to a cut end, block corner or shore tip to
#: be put on it (:func:`snap_cut`); measured in session 19 (docs/lake-grids.md, *Editing a layout*)
SNAP_CELLS = 2.5
#: a shore vertex is a tip a cut end snaps to where the shore turns by at least this (degrees)
_TIP_TURN = 30.0


def snap_targets(polygon: Any, cuts: Any = (), corners: Any = ()) -> list[tuple[tuple[float, float], str]]:
    """The places a hand-drawn cut's end snaps to: the ends of ``cuts`` (where they meet the shore or
    another cut), the ``corners`` (points) and the shore's and islands' vertices where they turn by
    at least 30° (tips), each with its kind."""
    from shapely.geometry import LineString, MultiLineString

    out: list[tuple[tuple[float, float], str]] = []
    cuts = [np.asarray(c, float) for c in cuts]
    shore = [list(polygon.exterior.coords), *(list(r.coords) for r in polygon.interiors)]
    for i, c in enumerate(cuts):  # where each cut meets the shore or another cut (drawn past it or not)
        walls = MultiLineString(shore + [k.tolist() for j, k in enumerate(cuts) if j != i])
        for e in (0, -1):
            p = _landing(LineString(c), walls, e)[1]
            out.append(((float(p.x), float(p.y)), "cut end"))
    out += [((float(p[0]), float(p[1])), "block corner") for p in corners]
    rings = [np.asarray(polygon.exterior.coords)[:-1], *(np.asarray(r.coords)[:-1] for r in polygon.interiors)]
    for r in rings:
        a, b = r - np.roll(r, 1, axis=0), np.roll(r, -1, axis=0) - r
        turn = np.degrees(np.abs(np.arctan2(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0], np.sum(a * b, axis=1))))
        out += [((float(p[0]), float(p[1])), "shore tip") for p in r[turn >= _TIP_TURN]]
    return out


def _landing(line: Any, walls: Any, end: int) -> tuple[float, Any]:
    """Where end ``end`` (0 or -1) of the drawn ``line`` lands: its crossing of ``walls`` (the shore
    and the cuts) nearest that end (the water's regions end there: a piece drawn past it dangles),
    or the end itself when it crosses none, or only once nearer the other end (that one's: a cut
    drawn from past the shore to short of a cut, session 20; before, both ends went to that
    crossing and the cut to a point); returned as (distance along ``line``, point)."""
    from shapely.geometry import Point

    hits = line.intersection(walls)
    pts = [Point(xy) for g in getattr(hits, "geoms", [hits]) if not g.is_empty for xy in g.coords]
    own = (0.0 if end == 0 else line.length), Point(line.coords[end])
    if not pts:
        return own
    s = [line.project(q) for q in pts]
    lo, hi = int(np.argmin(s)), int(np.argmax(s))
    if s[hi] - s[lo] <= 1e-9 * line.length:  # one crossing: the nearer end's (the other is in the water)
        mine = s[lo] <= 0.5 * line.length if end == 0 else s[lo] > 0.5 * line.length
        return (s[lo], pts[lo]) if mine else own
    k = lo if end == 0 else hi
    return s[k], pts[k]


def snap_cut(polygon: Any, cut: Any, targets: Any, distance: float, cuts: Any = ()) -> tuple[np.ndarray, list]:
    """A hand-drawn ``cut`` with each end that lands within ``distance`` of one of ``targets``
    (:func:`snap_targets`) put on the nearest one (cut ends before corners before shore tips; a
    corner or tip within ``distance`` of a cut end, or a tip of a corner, is none).

    An end lands where the drawn line first meets the shore or one of ``cuts`` (or where it
    stops, inside the water); the cut returned ends there (what is drawn past it dangles) or, when
    snapped, on the target.  An end is not put on a target from which the new piece of cut would
    leave the water or leave at under 30° to a cut through it (:func:`_sliver`).  Returns the cut
    and, per snapped end, ``(end, landed, target, kind)`` (``end`` 0 or -1, points ``(x, y)``).
    """
    from shapely.geometry import LineString, MultiLineString

    c = np.asarray(cut, float)
    if len(c) < 2 or distance <= 0 or not len(targets):
        return c, []
    line = LineString(c)
    walls = MultiLineString(
        [list(polygon.exterior.coords), *(list(r.coords) for r in polygon.interiors)]
        + [np.asarray(k, float).tolist() for k in cuts]
    )
    pts = np.array([t[0] for t in targets], float)
    rank = np.array([{"cut end": 0, "block corner": 1}.get(t[1], 2) for t in targets], int)
    # a corner or tip within the distance of a cut end (or a tip of a corner) is no target: an end
    # put on it would make the wedge it is snapped to avoid
    gap = np.hypot(pts[:, None, 0] - pts[None, :, 0], pts[:, None, 1] - pts[None, :, 1])
    shadow = (rank[None, :] < rank[:, None]) & (gap > 1e-9 * distance) & (gap <= distance)
    keep = ~np.any(shadow, axis=1)
    pts, rank, targets = pts[keep], rank[keep], [t for t, k in zip(targets, keep, strict=True) if k]
    water = polygon.buffer(1e-7 * math.sqrt(polygon.area))
    land = [_landing(line, walls, e) for e in (0, -1)]
    s_v = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(c, axis=0).T))])
    inner = c[(s_v > land[0][0]) & (s_v < land[1][0])]
    out = [np.array(land[0][1].coords), np.array(land[1][1].coords)]  # drawn past the shore or a cut: trimmed
    snaps = []
    for k, end in enumerate((0, -1)):
        q = land[k][1]
        towards = inner[0 if end == 0 else -1] if len(inner) else np.array(land[1 - k][1].coords[0])
        d = np.hypot(pts[:, 0] - q.x, pts[:, 1] - q.y)
        if np.any(d <= 1e-9 * distance):
            continue  # on a cut end, corner or tip already
        near = np.flatnonzero(d <= distance)
        for j in near[np.lexsort((d[near], rank[near]))]:
            if water.contains(LineString([pts[j], towards])) and not _sliver(pts[j], towards, cuts, distance):
                out[k] = pts[j][None, :]
                snaps.append((end, (float(q.x), float(q.y)), (float(pts[j, 0]), float(pts[j, 1])), targets[j][1]))
                break
    return np.vstack([out[0], inner, out[1]]), snaps


#: a snapped end makes no angle under this (degrees) with a cut through its new place
_MIN_SNAP_ANGLE = 30.0


def _sliver(p: np.ndarray, towards: np.ndarray, cuts: Any, distance: float) -> bool:
    """True when the cut from ``p`` towards ``towards`` leaves ``p`` at less than 30° to one of the
    ``cuts`` through ``p``: a near-parallel cut drawn a few cells beside another, one end snapped
    onto the other's end, would close a sliver block between them."""
    from shapely.geometry import LineString, Point

    u = np.asarray(towards, float) - p
    u = u / (np.hypot(*u) or 1.0)
    for c in cuts:
        line = LineString(np.asarray(c, float))
        if line.distance(Point(p)) > 1e-9 * distance:
            continue
        s = line.project(Point(p))
        for t in (s - 0.5 * distance, s + 0.5 * distance):
            if 0.0 <= t <= line.length:
                v = np.asarray(line.interpolate(t).coords[0]) - p
                cos = float(np.dot(u, v)) / (np.hypot(*v) or 1.0)
                if cos > math.cos(math.radians(_MIN_SNAP_ANGLE)):
                    return True
    return False


def layout_from_cuts(
    polygon: Any, cuts: Any, *, cell_size: float, multiple: int = 1, corners: Any = None, snap: float = 0.0
):
    """A layout of hand-drawn cut lines: each region's corners where it turns, cells from ``cell_size``.

    ``corners`` optionally maps a region (given by any point inside it) to its four corner
    points; the other regions get :func:`~.corners.choose_corners`.  Raises
    :class:`~meshcore.errors.TopologyError` naming the place where no integer cell counts
    agree round the blocks or a region is not a simple polygon.

    ``snap`` (cells; :data:`SNAP_CELLS` for cuts drawn by hand, default 0: off): each cut's end
    that lands within ``snap`` cells of an earlier cut's end, a given corner or a shore tip goes
    onto it (:func:`snap_cut`; an end a few cells off makes a thin wedge block); the layout's
    ``notes`` say which ends moved and where.
    """
    import shapely
    from shapely.geometry import Point, Polygon

    from ..errors import TopologyError
    from .build import _check_pieces
    from .corners import choose_corners
    from .regions import partition

    h = float(cell_size)
    given = dict(corners or {})
    cuts, notes = _snapped_cuts(polygon, cuts, [p for cs in given.values() for p in cs], h, snap)
    dense, cuts = _shore_ends_in_rings(shapely.segmentize(polygon, h), cuts)
    rings, all_cuts = partition(dense, cuts)
    rings = [_four_vertices(r, h) for r in rings]
    corner_pts, chosen = [], []
    for k, r in enumerate(rings):
        P = Polygon(r)
        mine = [v for q, v in given.items() if P.contains(Point(q))]
        if mine:
            corner_pts.append([np.asarray(c, dtype=float) for c in mine[0]])
        else:
            c, _ = choose_corners(r, 1.5 * h)
            corner_pts.append([r[i] for i in c])
            chosen.append(k)
    names = [f"b{k}" for k in range(len(rings))]
    pieces = _pieces_of_regions(rings, corner_pts, names, _size(polygon))
    try:
        _check_pieces(polygon, pieces)
    except TopologyError as exc:  # its words are the automatic layout's
        msg = str(exc).replace("automatic layout: a block", "the cut lines make a block")
        raise TopologyError(msg.replace("came out self-intersecting", "that is not a simple polygon")) from None
    try:
        cells = block_counts(pieces, h, multiple=multiple)
    except TopologyError as exc:
        again = _countable(rings, corner_pts, chosen, names, h, multiple, _size(polygon))
        if again is None:
            raise TopologyError(f"{exc}{_where_counts_fail(polygon, all_cuts, pieces, h, multiple)}") from None
        pieces = again
        _check_pieces(polygon, pieces)
        cells = block_counts(pieces, h, multiple=multiple)
    blocks = tuple(
        LayoutBlock(pc.name, tuple((float(p[0]), float(p[1])) for p in pc.ring[list(pc.corners)]), c)
        for pc, c in zip(pieces, cells, strict=True)
    )
    return Layout(
        polygon=polygon,
        cell_size=h,
        cuts=tuple(all_cuts),
        pieces=tuple(pieces),
        blocks=blocks,
        multiple=multiple,
        notes=tuple(notes),
    )


def _snapped_cuts(polygon: Any, cuts: Any, corners: list, h: float, snap_cells: float) -> tuple[list, list[str]]:
    """``cuts`` with their ends snapped (:func:`snap_cut`) onto the earlier cuts' ends, ``corners``
    and the shore tips within ``snap_cells`` cells of size ``h``, and a note per snapped end."""
    distance = snap_cells * h
    out: list[np.ndarray] = []
    notes: list[str] = []
    tips = snap_targets(polygon, (), corners) if distance > 0 else []
    for i, c in enumerate(cuts):
        c = _in_water(polygon, np.asarray(c, dtype=float))
        if distance > 0:
            c, snaps = snap_cut(polygon, c, snap_targets(polygon, out)[: 2 * len(out)] + tips, distance, out)
            notes += [snap_note(f"cut {i + 1}", s, h) for s in snaps]
        out.append(c)
    return out, notes


def _in_water(polygon: Any, cut: np.ndarray) -> np.ndarray:
    """``cut`` with each end drawn past the shore (or into an island) cut where the line enters the
    water, the vertices beyond dropped.  Put onto the shore point nearest it instead, the end of a
    slanted cut moved along the shore: drawn onto another cut's end (a three-cut junction on the
    shore), a sliver region between the two (session 20: 65 of 96 such cuts gave none)."""
    from shapely.geometry import LineString, MultiLineString, Point

    if len(cut) < 2:
        return cut
    tol = 1e-9 * math.sqrt(polygon.area)
    ends = [Point(cut[0]), Point(cut[-1])]
    outside = [polygon.distance(p) > tol for p in ends]
    if not any(outside):
        return cut
    line = LineString(cut)
    walls = MultiLineString([list(polygon.exterior.coords), *(list(r.coords) for r in polygon.interiors)])
    land = [
        _landing(line, walls, e) if out else (0.0 if e == 0 else line.length, ends[k])
        for k, (e, out) in enumerate(zip((0, -1), outside, strict=True))
    ]
    if land[1][0] <= land[0][0]:
        return cut  # crosses the shore once or never: not a cut through the water
    s_v = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(cut, axis=0).T))])
    inner = cut[(s_v > land[0][0]) & (s_v < land[1][0])]
    return np.vstack([np.array(land[0][1].coords), inner, np.array(land[1][1].coords)])


def snap_note(what: str, s: tuple, cell_size: float) -> str:
    """What a snap of :func:`snap_cut` did (``s``), for messages: ``what`` names the cut."""
    end, a, b, kind = s
    d = math.hypot(b[0] - a[0], b[1] - a[1]) / cell_size
    return (
        f"{what}: its {'first' if end == 0 else 'last'} end snapped {d:.2g} cells from ({a[0]:.6g}, {a[1]:.6g}) "
        f"onto the {kind} at ({b[0]:.6g}, {b[1]:.6g})"
    )


def with_cells(layout: Layout, name: str, cells: tuple[int, int]) -> Layout:
    """The layout with block ``name`` at ``cells = (ni, nj)``; its neighbours (and theirs) follow.

    The other blocks keep the counts closest to the cell size that agree with the new one.
    Raises :class:`~meshcore.errors.TopologyError` when no counts agree (naming the block).
    """
    from ..errors import TopologyError

    names = [b.name for b in layout.blocks]
    if name not in names:
        raise TopologyError(f"no block {name!r} in the layout (blocks: {', '.join(names)})")
    ni, nj = (int(c) for c in cells)
    m = layout.multiple
    if min(ni, nj) < 1 or ni % m or nj % m:
        raise TopologyError(f"block {name!r}: cells ({ni}, {nj}) must be positive multiples of {m}")
    k = names.index(name)
    try:
        counts = block_counts(list(layout.pieces), layout.cell_size, min_cells=1, multiple=m, block_cells={k: (ni, nj)})
    except TopologyError:
        raise TopologyError(
            f"block {name!r} cannot have ({ni}, {nj}) cells: no cell counts of its neighbours agree with "
            f"them (at a T-junction a side needs room for each of its parts)"
        ) from None
    blocks = tuple(LayoutBlock(b.name, b.corners, c) for b, c in zip(layout.blocks, counts, strict=True))
    import dataclasses

    return dataclasses.replace(layout, blocks=blocks)
