r"""The layout model: blocks (name, corners, cells) on a water polygon, with their pieces."""

from __future__ import annotations

from dataclasses import dataclass, field, fields
from typing import Any

import numpy as np

from .blocks import Piece

__all__ = ["Layout", "LayoutBlock", "LayoutOptions"]


@dataclass(frozen=True, slots=True)
class LayoutOptions:
    """Layout choices that are off by default, each because it was measured to help one family of
    lakes and hurt another (the numbers are in ``docs/lake-grids-journal.md``).

    thin_arms
        Cuts from reflex corners may leave blocks two cells across (three by default): the
        junctions and reflex bends of arms 2–4 cells wide are split instead of gridded as one
        block round the corner (:data:`.width.THIN_ACROSS`).
    mouths
        At junctions of three or four arms up to seven cells wide, each arm's chord at its mouth,
        through the reflex shore corners between the arms (default: just outside the junction's
        inscribed circle; :func:`~.chords.place_chords`).
    curve
        The shore between the outline's points as a smooth curve through them (corners sharper
        than 60° kept, at most a quarter cell from the straight segments; :mod:`.curve`).
    wedges
        A block ending in a wedge's tip (an arm tapering to a point) gets two corners either side
        of the tip instead of one at it (:func:`~.corners.wedge_corners`).  Not in regular layouts.
    tees
        Regular layouts only: a junction is also offered as a T (:mod:`.tee`: a straight cut
        between two of its reflex corners, a stem from a third reflex corner or the opposite shore
        meeting it at right angles), kept where its pieces, split on, cost less than the greedy
        split's.
    bulges
        Regular layouts only: a piece whose corners bunch on part of a round basin (its bulge, the
        area over the product of the mean lengths of its opposite sides, at least
        :data:`~.fans.FAN_BULGE`) is split as default layouts split every fanning piece
        (:func:`~.fans.unfan`, by the splits regular layouts allow).
    tapers
        Default layouts only: a piece whose two ratios of opposite sides multiply to
        :data:`~.fans.FAN_AREA` or more (a wedge from a neck into a basin: its cells differ in area
        by about the product) is split as a fanning piece whatever its bulge
        (:func:`~.fans.tapers`, :func:`~.fans.unfan`).
    lookahead
        Each region's first split is the one of its :data:`~.split.LOOKAHEAD` cheapest whose pieces,
        split on, cost least (by default the cheapest as it is: the greedy split).  The layout choice
        also draws it where the layout it chose reads far off 90° (:data:`~.choice.WIDE_DEV`).
    islands_apart
        Islands less than three cells apart stay apart (by default they are joined into one, the
        water between given up with a note: :mod:`.islandgaps`); the layout then cuts blocks a
        cell or two across between them.
    """

    thin_arms: bool = False
    mouths: bool = False
    curve: bool = False
    wedges: bool = False
    tees: bool = False
    bulges: bool = False
    tapers: bool = False
    lookahead: bool = False
    islands_apart: bool = False

    def __str__(self) -> str:
        on = [f.name.replace("_", " ") for f in fields(self) if getattr(self, f.name)]
        return ", ".join(on) or "defaults"


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
    the regions with their corners, ``blocks`` their names, corners and cell counts;
    ``single``: the cell counts close every ring of blocks in one index space (``auto_layout(single=True)``);
    ``details``: the notes that one of ``notes`` sums up (each island left out as too narrow, when
    there are many: :func:`~.polygon.summarised_islands`); ``arms``: the dead-end arms narrower than
    two cells left out of the water (shapely Polygons, :func:`~.shore.without_narrow_arms`; None: not
    known, a layout read from a case), which the quality report's shore distance leaves out
    (:class:`~meshcore.multiblock.MultiBlockGrid` ``arms``, :func:`meshcore.quality.lake_metrics`).
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
    single: bool = False
    details: tuple[str, ...] = ()
    arms: tuple[Any, ...] | None = field(default=None, repr=False)
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
