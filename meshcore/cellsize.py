"""The default cell size of a lake grid, written once: ``sqrt(area / DEFAULT_CELLS)``.

``meshcore mesh``, ``meshcore import``, :func:`meshcore.layout.auto_layout`,
:func:`meshcore.io.outline.guess_cells` and the app all take it from here, so one outline gets
cells of one size everywhere.  (A module of its own: the layout and the lake pipeline both use
it, and neither may import the other at module level.)
"""

from __future__ import annotations

import math

__all__ = [
    "DEFAULT_CELLS",
    "MANY_BLOCKS",
    "SMALL_BLOCKS",
    "default_cell_size",
    "finer_for_small_blocks",
    "small_blocks_reason",
]

#: Cells of a lake's default grid: ``cell size = sqrt(water area / DEFAULT_CELLS)`` (a grid a
#: hydrodynamic model runs in minutes, fine enough to resolve the arms of a lake tens of km long).
DEFAULT_CELLS = 10_000


def default_cell_size(area: float, cells: int | None = None) -> float:
    """``sqrt(area / cells)`` (default :data:`DEFAULT_CELLS`): the side of ``cells`` square cells
    covering ``area``."""
    return math.sqrt(float(area) / float(cells or DEFAULT_CELLS))


#: Blocks of fewer cells than this on average, in a layout of :data:`MANY_BLOCKS` or more (a lake of
#: many arms at the cells asked): ``meshcore mesh`` and the app name the cells (and cell size) that
#: would give them this many.  On dev sets 13 and 14 at 10 000 cells the share of edge pairs ≤ 1.2
#: fell with the blocks: ≤ 20 blocks 98–100 %, 51–58 blocks ~95 %, 88–94 blocks 88–91 %; the same
#: lakes at 1.5× the cells met the target (journal, session 29).  Advice only: the cells are the
#: user's (their model's run time); a coarse grid of a few blocks is a choice, not a lake of arms.
SMALL_BLOCKS = 256
MANY_BLOCKS = 20


def finer_for_small_blocks(blocks: int, cells: int, cell_size: float) -> tuple[int, float] | None:
    """``(cells, cell size)`` that would give a layout of ``blocks`` blocks and ``cells`` cells at
    ``cell_size`` about :data:`SMALL_BLOCKS` cells a block (the cells rounded up to a thousand),
    when it has :data:`MANY_BLOCKS` or more blocks of fewer; else None.

    >>> finer_for_small_blocks(94, 11696, 100.0)
    (25000, 68.4)
    >>> finer_for_small_blocks(6, 600, 100.0) is None
    True
    """
    if blocks < MANY_BLOCKS or cells >= SMALL_BLOCKS * blocks:
        return None
    more = -(-SMALL_BLOCKS * blocks // 1000) * 1000
    return more, float(f"{cell_size * math.sqrt(cells / more):.3g}")


def small_blocks_reason(blocks: int, cells: int) -> str:
    """Why a layout of ``blocks`` blocks and ``cells`` cells that :func:`finer_for_small_blocks`
    flags grids less smoothly (the words ``meshcore mesh`` and the app share)."""
    return (
        f"{blocks} blocks of {cells // blocks} cells on average: arms only a few cells across grid less "
        "smoothly (edge pairs, angles)"
    )
