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

from .blocks import Piece, block_counts, conform
from .model import Layout, LayoutBlock
from .outline import _size

__all__ = ["layout_from_cuts", "layout_from_outline", "layout_of_outline", "with_cells"]


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


def layout_from_outline(
    outline: Any,
    *,
    cuts: Any,
    blocks: Any,
    holes: Any = (),
    cell_size: float | None = None,
    multiple: int = 1,
):
    """A :class:`~meshcore.layout.Layout` from a shore, islands, cut lines and blocks (corners, cells).

    The inputs are those of :func:`meshcore.multiblock.from_outline`, whose checks name the
    block, cut or island at fault; ``cell_size`` (default: the mean size of the blocks' cells)
    sets how densely the orthogonal smoother samples the shore.
    """
    from ..multiblock.outline import from_outline

    ob = from_outline(outline, holes=holes, cuts=cuts, blocks=blocks, multiple=multiple)
    return layout_of_outline(ob, blocks, cell_size=cell_size, multiple=multiple)


def layout_of_outline(ob: Any, blocks: Any, *, cell_size: float | None = None, multiple: int = 1):
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
    )


def layout_from_cuts(polygon: Any, cuts: Any, *, cell_size: float, multiple: int = 1, corners: Any = None):
    """A layout of hand-drawn cut lines: each region's corners where it turns, cells from ``cell_size``.

    ``corners`` optionally maps a region (given by any point inside it) to its four corner
    points; the other regions get :func:`~.corners.choose_corners`.  Raises
    :class:`~meshcore.errors.TopologyError` naming the place where no integer cell counts
    agree round the blocks or a region is not a simple polygon.
    """
    import shapely
    from shapely.geometry import Point, Polygon

    from .build import _check_pieces
    from .corners import choose_corners
    from .regions import partition

    h = float(cell_size)
    dense = shapely.segmentize(polygon, h)
    rings, all_cuts = partition(dense, [np.asarray(c, dtype=float) for c in cuts])
    given = dict(corners or {})
    corner_pts = []
    for r in rings:
        P = Polygon(r)
        mine = [v for k, v in given.items() if P.contains(Point(k))]
        if mine:
            corner_pts.append([np.asarray(c, dtype=float) for c in mine[0]])
        else:
            c, _ = choose_corners(r, 1.5 * h)
            corner_pts.append([r[i] for i in c])
    names = [f"b{k}" for k in range(len(rings))]
    pieces = _pieces_of_regions(rings, corner_pts, names, _size(polygon))
    _check_pieces(polygon, pieces)
    cells = block_counts(pieces, h, multiple=multiple)
    blocks = tuple(
        LayoutBlock(pc.name, tuple((float(p[0]), float(p[1])) for p in pc.ring[list(pc.corners)]), c)
        for pc, c in zip(pieces, cells, strict=True)
    )
    return Layout(
        polygon=polygon, cell_size=h, cuts=tuple(all_cuts), pieces=tuple(pieces), blocks=blocks, multiple=multiple
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
