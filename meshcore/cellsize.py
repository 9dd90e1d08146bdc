"""The default cell size of a lake grid, written once: ``sqrt(area / DEFAULT_CELLS)``.

``meshcore mesh``, ``meshcore import``, :func:`meshcore.layout.auto_layout`,
:func:`meshcore.io.outline.guess_cells` and the app all take it from here, so one outline gets
cells of one size everywhere.  (A module of its own: the layout and the lake pipeline both use
it, and neither may import the other at module level.)
"""

from __future__ import annotations

import math

__all__ = ["DEFAULT_CELLS", "default_cell_size"]

#: Cells of a lake's default grid: ``cell size = sqrt(water area / DEFAULT_CELLS)`` (a grid a
#: hydrodynamic model runs in minutes, fine enough to resolve the arms of a lake tens of km long).
DEFAULT_CELLS = 10_000


def default_cell_size(area: float, cells: int | None = None) -> float:
    """``sqrt(area / cells)`` (default :data:`DEFAULT_CELLS`): the side of ``cells`` square cells
    covering ``area``."""
    return math.sqrt(float(area) / float(cells or DEFAULT_CELLS))
