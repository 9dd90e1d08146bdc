"""What a solve returns to the window (no Qt): :class:`BlockResult` and the all-blocks index.

Shared by the single-block and multiblock pipeline (:mod:`app.pipeline`) and the lake grid
(:mod:`app.lake_solve`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

__all__ = ["ALL_BLOCKS", "BlockResult"]

#: block index of progress items that concern all blocks at once
ALL_BLOCKS = -1


@dataclass(frozen=True, slots=True)
class BlockResult:
    """What the worker returns: final grids and algebraic grids per block, and the warnings."""

    grids: dict
    initial: dict
    multiblock: object = None  # the meshcore MultiBlockGrid of a multiblock case or a lake (connectivity)
    warnings: tuple[str, ...] = field(default=())
    metrics: object = None  # a lake grid's meshcore LakeMetrics, measured in the worker
