r"""The layout model: blocks (name, corners, cells) on a water polygon, with their pieces."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .blocks import Piece

__all__ = ["Layout", "LayoutBlock"]


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
    _topology: Any = field(default=None, init=False, repr=False, compare=False)  # made once

    @property
    def n_cells(self) -> int:
        return sum(b.cells[0] * b.cells[1] for b in self.blocks)

    def topology(self):
        """The :class:`~meshcore.multiblock.MultiBlockTopology` (re-sampled borders, interfaces).

        Made by :func:`meshcore.multiblock.from_outline` from :func:`.outline.outline_parts`,
        as a case file of this layout is: the same layout gives the same grid either way.
        """
        from .outline import outline_blocks

        if self._topology is None:
            object.__setattr__(self, "_topology", outline_blocks(self).topology)
        return self._topology
