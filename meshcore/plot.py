"""Figures of grids like the paper's (matplotlib, imported lazily).

``plot_grid(grid_or_blocks, path=None, ax=None, ...)`` draws ξ- and η-lines
(thin black lines by default; each block in its own colour when there are
several), the boundary thicker, and optionally the input boundary points.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from .grid import StructuredGrid

__all__ = ["line_alpha", "plot_grid"]

_BLOCK_COLOURS = ["#1f4e9c", "#c0392b", "#1e8449", "#8e44ad", "#d35400", "#117a65", "#7d6608"]


def line_alpha(cell_pixels: float, *, full: float = 8.0, faint: float = 2.0, floor: float = 0.12) -> float:
    """Opacity of grid lines for cells ``cell_pixels`` wide on screen (level of detail).

    Opaque for cells of ``full`` pixels or more, fading linearly to ``floor``
    at ``faint`` pixels and below: a zoomed-out fine grid reads as a light
    texture and the cell colouring shows through, instead of a black blob.
    """
    if not math.isfinite(cell_pixels) or cell_pixels >= full:
        return 1.0
    t = (cell_pixels - faint) / (full - faint)
    return float(floor + (1.0 - floor) * min(max(t, 0.0), 1.0))


def _as_blocks(obj: Any) -> list[StructuredGrid]:
    if isinstance(obj, StructuredGrid):
        return [obj]
    blocks = getattr(obj, "blocks", obj)
    return list(blocks)


def plot_grid(
    grids: Any,
    path: str | Path | None = None,
    *,
    ax: Any = None,
    title: str | None = None,
    points: Sequence[np.ndarray] | None = None,
    color: str | None = None,
    linewidth: float = 0.6,
    dpi: int = 150,
    fmt: str | None = None,
    highlight_folded: bool = True,
    figsize: tuple[float, float] | None = None,
) -> Any:
    """Draw one grid or several blocks; save to ``path`` if given; return the Axes."""
    import matplotlib

    if ax is None and path is not None:
        matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt
    from matplotlib.collections import LineCollection

    blocks = _as_blocks(grids)
    own = ax is None
    if own:
        xs = np.concatenate([g.x.ravel() for g in blocks])
        ys = np.concatenate([g.y.ravel() for g in blocks])
        w, h = np.ptp(xs) or 1.0, np.ptp(ys) or 1.0
        if figsize is None:
            scale = 7.0 / max(w, h)
            figsize = (max(3.0, w * scale + 0.8), max(3.0, h * scale + 0.8))
        fig, ax = plt.subplots(figsize=figsize)
    for k, g in enumerate(blocks):
        c = color or ("black" if len(blocks) == 1 else _BLOCK_COLOURS[k % len(_BLOCK_COLOURS)])
        segs = [np.column_stack([g.x[i, :], g.y[i, :]]) for i in range(g.shape[0])]
        segs += [np.column_stack([g.x[:, j], g.y[:, j]]) for j in range(g.shape[1])]
        ax.add_collection(LineCollection(segs, colors=c, linewidths=linewidth))
        edge = [g.border("bottom"), g.border("right"), g.border("top"), g.border("left")]
        ax.add_collection(LineCollection(edge, colors=c, linewidths=linewidth * 2.5))
        if highlight_folded:
            from .quality import cell_quality

            cj = cell_quality(g)["corner_jacobians"]
            bad = np.argwhere((cj <= 0).any(axis=0))
            for i, j in bad:
                ax.fill(
                    [g.x[i, j], g.x[i + 1, j], g.x[i + 1, j + 1], g.x[i, j + 1]],
                    [g.y[i, j], g.y[i + 1, j], g.y[i + 1, j + 1], g.y[i, j + 1]],
                    color="red",
                    alpha=0.6,
                    lw=0,
                )
    if points is not None:
        for pts in points:
            pts = np.asarray(pts)
            ax.plot(pts[:, 0], pts[:, 1], "o", ms=3.5, mfc="white", mec="#d35400", mew=1.0, zorder=5)
    ax.set_aspect("equal")
    ax.autoscale_view()
    ax.margins(0.03)
    if title:
        ax.set_title(title, fontsize=10)
    ax.tick_params(labelsize=8)
    if path is not None:
        fig = ax.figure
        fig.tight_layout()
        fig.savefig(path, dpi=dpi, format=fmt)
        if own:
            plt.close(fig)
    return ax
