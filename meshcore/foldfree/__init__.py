"""Fold-free structured grids: the corner-triangle barrier (Winslow–Ivanenko) method.

:func:`repair` fixes a grid's folded and non-convex cells by local barrier
minimisation (untangling first); :func:`smooth` minimises over the whole
block.  :func:`meshcore.generate_block` calls :func:`repair` automatically
(``repair="auto"``) and :func:`smooth` for ``method="foldfree"``.
"""

from __future__ import annotations

from .driver import (
    BoundaryCorner,
    FoldFreeResult,
    block_corner_problems,
    invalid_cells,
    repair,
    smooth,
)

__all__ = [
    "BoundaryCorner",
    "FoldFreeResult",
    "block_corner_problems",
    "invalid_cells",
    "repair",
    "smooth",
]
