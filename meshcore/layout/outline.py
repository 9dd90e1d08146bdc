r"""A layout as the ``[outline]`` description: shore, islands, cut lines, blocks with cells.

An automatic layout and a hand-edited one meet here.  :func:`outline_parts` writes a
:class:`~meshcore.layout.Layout` as the inputs of :func:`meshcore.multiblock.from_outline`
(the shore densified to the cell size, the islands, every line between two blocks as a cut,
each block's four corners and cells); :func:`~.edit.layout_from_outline` reads them back.
:meth:`Layout.topology` always goes through :func:`~meshcore.multiblock.from_outline`, so a
layout saved as a case and generated again gives the same grid.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..pointindex import point_keys
from .blocks import Piece

__all__ = ["interior_cuts", "outline_blocks", "outline_parts", "shore_of", "topology_snap"]


def _edge_use(pieces: list[Piece]) -> dict[frozenset, int]:
    """How many pieces use each edge: 1 on the shore, 2 between two blocks."""
    count: dict[frozenset, int] = {}
    for pc in pieces:
        kr = point_keys(pc.ring)
        for a, b in zip(kr, kr[1:] + kr[:1], strict=True):
            e = frozenset((a, b))
            count[e] = count.get(e, 0) + 1
    return count


def interior_cuts(pieces: list[Piece]) -> list[np.ndarray]:
    """Every line between two pieces, as polylines that end where three or more lines meet.

    The edges used by two pieces form a graph; its paths between vertices of degree other
    than two (or where a shore is reached) are the cuts.
    """
    users = _edge_use(pieces)
    inner = [tuple(e) for e, n in users.items() if n >= 2 and len(e) == 2]
    on_shore = {v for e, n in users.items() if n == 1 for v in e}
    adj: dict[tuple, list[tuple]] = {}
    for a, b in inner:
        adj.setdefault(a, []).append(b)
        adj.setdefault(b, []).append(a)
    stop = {v for v, nb in adj.items() if len(nb) != 2 or v in on_shore}
    seen: set[frozenset] = set()
    cuts = []
    for start in sorted(adj):
        if start not in stop:
            continue
        for nxt in adj[start]:
            if frozenset((start, nxt)) in seen:
                continue
            path = [start, nxt]
            seen.add(frozenset((start, nxt)))
            while path[-1] not in stop:
                a, b = path[-2], path[-1]
                c = next(v for v in adj[b] if v != a)
                seen.add(frozenset((b, c)))
                path.append(c)
            cuts.append(np.array(path))
    for a, b in inner:  # closed loops without a stop vertex (a cut round an island touching nothing)
        if frozenset((a, b)) not in seen:
            path = [a, b]
            seen.add(frozenset((a, b)))
            while path[-1] != a:
                c = next(v for v in adj[path[-1]] if frozenset((path[-1], v)) not in seen or v == a)
                seen.add(frozenset((path[-1], c)))
                path.append(c)
            cuts.append(np.array(path))
    return cuts


def shore_of(pieces: list[Piece]) -> tuple[np.ndarray, list[np.ndarray]]:
    """The shore as the pieces have it (every vertex a piece has on it): the edges that only one
    piece uses, joined into rings; the ring of largest area is the outline, the others islands.

    Each ring starts at its lexicographically smallest vertex and the islands come in the order
    of those vertices: the same shore for the same pieces, whichever vertex their rings start at.
    A layout read back from its case has the same pieces with rings that start elsewhere; the
    grid's shore nodes slide along these rings, and a ring's start moved them by 0.03 cells
    (Kyoga: ``meshcore mesh`` and ``meshcore generate`` of its ``--case`` 15 m apart, and each
    save and reopen in the app gave the other of two grids).
    """
    count = _edge_use(pieces)
    nxt: dict[tuple, tuple] = {}
    for pc in pieces:  # walked in each piece's own (counter-clockwise) direction
        kr = point_keys(pc.ring)
        for a, b in zip(kr, kr[1:] + kr[:1], strict=True):
            if count[frozenset((a, b))] == 1:
                nxt[a] = b
    rings = []
    while nxt:
        start, ring = next(iter(nxt)), []
        v = start
        while v in nxt:
            ring.append(v)
            v = nxt.pop(v)
        r = np.array(ring)
        rings.append(np.roll(r, -int(np.lexsort((r[:, 1], r[:, 0]))[0]), axis=0))
    area = [abs(0.5 * float(np.sum(r[:, 0] * np.roll(r[:, 1], -1) - np.roll(r[:, 0], -1) * r[:, 1]))) for r in rings]
    k = int(np.argmax(area))
    return rings[k], sorted((r for i, r in enumerate(rings) if i != k), key=lambda r: (r[0, 0], r[0, 1]))


def outline_parts(layout: Any) -> dict[str, Any]:
    """The :func:`~meshcore.multiblock.from_outline` inputs of a layout.

    Returns ``{"outline", "holes", "cuts", "blocks"}``: the shore ring and the island rings with
    every vertex the blocks have on them, the cut polylines and ``{"name", "corners", "cells"}``
    per block.
    """
    outline, holes = shore_of(list(layout.pieces))
    blocks = [{"name": b.name, "corners": [list(c) for c in b.corners], "cells": list(b.cells)} for b in layout.blocks]
    return {"outline": outline, "holes": holes, "cuts": interior_cuts(list(layout.pieces)), "blocks": blocks}


def outline_blocks(layout: Any):
    """:func:`~meshcore.multiblock.from_outline` of a layout (its topology, regions, cuts)."""
    from ..multiblock.outline import from_outline

    parts = outline_parts(layout)
    return from_outline(
        parts["outline"],
        holes=parts["holes"],
        cuts=parts["cuts"],
        blocks=parts["blocks"],
        multiple=layout.multiple,
        snap=topology_snap(layout.polygon),
        cell_size=layout.cell_size,
        single=layout.single,
    )


def topology_snap(polygon: Any) -> float:
    """The snap distance of a layout's :func:`outline_blocks`: its parts lie on each other up to
    rounding (1e-6 of the water's bounding-box diagonal)."""
    return 1e-6 * _size(polygon)


def _size(polygon: Any) -> float:
    x0, y0, x1, y1 = polygon.bounds
    return math.hypot(x1 - x0, y1 - y0)
