r"""Automatic block layout: a water polygon (islands included) in, four-sided blocks out.

>>> from meshcore import testing
>>> from meshcore.layout import auto_layout
>>> lay = auto_layout(testing.straight_channel(10.0, 1.0), cell_size=0.25)
>>> len(lay.blocks) >= 1 and all(min(b.cells) >= 3 for b in lay.blocks)
True

How it works (the method, its reasons and its limits are in ``docs/lake-grids.md``):

* :mod:`.skeleton` — the lake's pruned medial axis: its arms, junctions and island rings;
* :mod:`.chords` — cuts across the arms, at right angles to the banks;
* :mod:`.regions` — the regions between shores and cuts, islands cut free;
* :mod:`.split` — regions that are not four-sided split at their reflex corners or by a star;
* :mod:`.corners` — four corners per piece, where the boundary turns at the cells' scale;
* :mod:`.counts` — integer cell counts that agree across every interface (a small MILP);
* :mod:`.blocks` — the pieces as a :class:`~meshcore.multiblock.MultiBlockTopology`;
* :mod:`.build` — the pipeline.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .blocks import Piece, build_topology
from .build import layout_pieces
from .polygon import water_polygon

__all__ = ["Layout", "LayoutBlock", "auto_layout"]


@dataclass(frozen=True, slots=True)
class LayoutBlock:
    """A block of a layout: its name, corners ``(sw, se, ne, nw)`` as points and its cells."""

    name: str
    corners: tuple[tuple[float, float], ...]
    cells: tuple[int, int]


@dataclass(frozen=True, slots=True, eq=False)
class Layout:
    """The result of :func:`auto_layout`.

    ``polygon`` is the water (a shapely Polygon, islands as holes, after cleaning),
    ``cuts`` the cut lines (chords across arms and the splits inside junctions), ``pieces``
    the regions with their corners, ``blocks`` their names, corners and cell counts.
    """

    polygon: Any
    cell_size: float
    cuts: tuple[np.ndarray, ...]
    pieces: tuple[Piece, ...]
    blocks: tuple[LayoutBlock, ...]
    multiple: int = 1
    skeleton: Any = field(default=None, repr=False)
    chords: tuple = field(default=(), repr=False)
    notes: tuple[str, ...] = ()

    @property
    def n_cells(self) -> int:
        return sum(b.cells[0] * b.cells[1] for b in self.blocks)

    def topology(self):
        """The :class:`~meshcore.multiblock.MultiBlockTopology` (re-sampled borders, interfaces)."""
        topo, _ = build_topology(list(self.pieces), self.cell_size, multiple=self.multiple)
        return topo


def auto_layout(
    outline: Any,
    *,
    holes: Any = (),
    cell_size: float | None = None,
    target_cells: int = 10_000,
    multiple: int = 1,
    regular: bool = False,
) -> Layout:
    """Decompose a water polygon into four-sided blocks that follow its channels.

    Parameters
    ----------
    outline : (n, 2) array_like or shapely Polygon
        The shore, in projected units (metres); a Polygon may carry islands as holes.
    holes : sequence of (k, 2) array_like
        Islands (rings inside the outline).
    cell_size : float, optional
        The wanted cell size ``h``; default ``sqrt(area / target_cells)``.
    target_cells : int
        Used for the default cell size.
    multiple : int
        Every cell count along a shared part is a multiple of this (``2**k`` lets the
        solvers coarsen ``k`` times).
    regular : bool
        No node where three or five blocks meet (no star at Y junctions, no butterfly in
        basins): what Delft3D's domain decomposition can couple.

    Returns
    -------
    Layout
        Blocks with corners and integer cell counts that agree across every interface.

    Raises
    ------
    InvalidInputError
        A polygon that crosses itself, islands outside the water, …, naming the place.
    """
    poly, notes = water_polygon(outline, holes=holes)
    h = float(cell_size) if cell_size is not None else float(np.sqrt(poly.area / target_cells))
    poly, more = water_polygon(poly, drop_islands_below=2.0 * h)
    sk, chords, cuts, pieces = layout_pieces(poly, h, regular=regular)
    topo, _ = build_topology(pieces, h, multiple=multiple)
    blocks = tuple(
        LayoutBlock(
            pc.name,
            tuple((float(p[0]), float(p[1])) for p in pc.ring[list(pc.corners)]),
            tuple(int(c) for c in b.cells),
        )
        for pc, b in zip(pieces, topo.blocks, strict=True)
    )
    return Layout(
        polygon=poly,
        cell_size=h,
        cuts=tuple(cuts),
        pieces=tuple(pieces),
        blocks=blocks,
        multiple=multiple,
        skeleton=sk,
        chords=tuple(chords),
        notes=tuple(notes) + tuple(more),
    )
