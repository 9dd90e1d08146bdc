"""Cells that follow a drag of the layout (no Qt).

While a cut end, corner or shore point is dragged every block keeps its cells, so that each step's
grid re-solves from the one before (:func:`app.layout_edit.moved_layout`).  A long drag then left a
block's cells stretched or squeezed: a cut end dragged a fifth of the way round a ring lake made one
block's cells 1.6 times as long as the cell size and the other's 0.8 times, with the counts as they
were and nothing said.  :func:`cells_followed` gives the drag's last layout the cells of the cell
size for each block whose cells the drag made more than :data:`STRETCH` longer or shorter (the other
blocks keep theirs, a block's count set by hand too) and says which changed, or why they could not;
a total that changes by more than :data:`CELLS_WARN` is a warning with both counts.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from typing import Any

import numpy as np

__all__ = ["CELLS_WARN", "STRETCH", "cell_lengths", "cells_followed"]

#: a block's cells follow the cell size when the drag made them this much longer or shorter (a share)
STRETCH = 0.2

#: the total cells changing by more than this share at a drag's end is a warning (the solve's time,
#: the model's time step and the output files follow the count; it was an info line among others)
CELLS_WARN = 0.2


def _along(ring: np.ndarray, a: int, b: int) -> float:
    """The length of ``ring`` (closed, not repeated) from vertex ``a`` to vertex ``b`` going forward."""
    n = len(ring)
    idx = [(a + k) % n for k in range((b - a) % n + 1)]
    p = ring[idx]
    return float(np.hypot(*np.diff(p, axis=0).T).sum())


def cell_lengths(layout: Any) -> np.ndarray:
    """Per block the mean cell length along ξ (bottom and top) and η (left and right), ``(n, 2)``."""
    out = []
    for pc, b in zip(layout.pieces, layout.blocks, strict=True):
        ring = np.asarray(pc.ring, float)
        sw, se, ne, nw = pc.corners
        xi = 0.5 * (_along(ring, sw, se) + _along(ring, ne, nw))
        eta = 0.5 * (_along(ring, se, ne) + _along(ring, nw, sw))
        out.append((xi / b.cells[0], eta / b.cells[1]))
    return np.asarray(out, float).reshape(-1, 2)


def cells_followed(base: Any, layout: Any, report: Callable[[str, str], None] | None = None) -> Any:
    """``layout`` (the last of a drag that began on ``base``, the same blocks and cells) with the
    cells of the cell size for the blocks whose cells the drag stretched or squeezed by more than
    :data:`STRETCH`; ``report(level, text)`` gets what changed, or why nothing could."""
    from meshcore.errors import TopologyError
    from meshcore.layout.blocks import block_counts

    if [b.name for b in base.blocks] != [b.name for b in layout.blocks]:
        return layout
    ratio = cell_lengths(layout) / cell_lengths(base)
    off = np.flatnonzero(np.any(np.abs(np.log(ratio)) > np.log1p(STRETCH), axis=1))
    if not len(off):
        return layout
    fixed = {k: tuple(b.cells) for k, b in enumerate(layout.blocks) if k not in set(off.tolist())}
    names = ", ".join(layout.blocks[k].name for k in off)
    try:
        counts = block_counts(
            list(layout.pieces), layout.cell_size, min_cells=1, multiple=layout.multiple, block_cells=fixed
        )
    except TopologyError:
        if report is not None:
            worst = float(np.max(np.abs(np.log(ratio[off]))))
            report(
                "info",
                f"The drag stretched the cells of {names} (up to {np.exp(worst):.2g}×); they keep their counts: "
                "none that follow the cell size agree with the other blocks' (set them in the Lake panel)",
            )
        return layout
    blocks = tuple(dataclasses.replace(b, cells=tuple(c)) for b, c in zip(layout.blocks, counts, strict=True))
    out = dataclasses.replace(layout, blocks=blocks)
    if report is not None:
        changed = [
            f"{b.name} {b.cells[0]}×{b.cells[1]} → {c[0]}×{c[1]}"
            for b, c in zip(layout.blocks, counts, strict=True)
            if tuple(c) != tuple(b.cells)
        ]
        if changed:
            report("info", f"Cells follow the drag (its blocks' cells had stretched): {', '.join(changed)}")
        n0, n1 = layout.n_cells, out.n_cells
        if n0 and abs(n1 / n0 - 1.0) > CELLS_WARN:
            report(
                "warning",
                f"The drag changes the grid from {n0:,} to {n1:,} cells ({100 * (n1 / n0 - 1):+.0f} %): the cells "
                f"of {names} follow the cell size (Ctrl+Z undoes the drag; the Lake panel sets a block's cells)",
            )
    return out
