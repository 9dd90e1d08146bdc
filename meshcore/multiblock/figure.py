"""Figures of multiblock grids: each block in its own colour (matplotlib, imported lazily)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["plot_multiblock"]


def plot_multiblock(
    mb: Any,
    path: str | Path | None = None,
    *,
    ax: Any = None,
    outline: np.ndarray | None = None,
    scale: float = 1.0,
    unit: str = "",
    title: str | None = None,
    labels: bool = True,
    linewidth: float = 0.45,
    window: tuple[float, float, float, float] | None = None,
    dpi: int = 150,
) -> Any:
    """Draw a :class:`~.solver.MultiBlockGrid` with one colour per block.

    Parameters
    ----------
    mb : MultiBlockGrid
    path : path, optional
        Save the figure there (format from the suffix).
    outline : (n, 2) array, optional
        A closed outline drawn in black (e.g. the shoreline).
    scale : float
        Coordinates are multiplied by ``scale`` (e.g. ``1e-3`` for km).
    window : (xmin, ymin, xmax, ymax), optional
        Zoom (in scaled units).
    """
    import matplotlib

    if ax is None and path is not None:
        matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt
    from matplotlib.collections import LineCollection

    own = ax is None
    if own:
        fig, ax = plt.subplots(figsize=(11, 8))
    else:
        fig = ax.figure
    colors = plt.get_cmap("tab10").colors
    for k, (name, g) in enumerate(zip(mb.names, mb.grids, strict=True)):
        c = colors[k % len(colors)]
        x, y = g.x * scale, g.y * scale
        segs = [np.column_stack([x[i], y[i]]) for i in range(x.shape[0])]
        segs += [np.column_stack([x[:, j], y[:, j]]) for j in range(x.shape[1])]
        ax.add_collection(LineCollection(segs, colors=[c], linewidths=linewidth))
        if labels:
            i, j = x.shape[0] // 2, x.shape[1] // 2
            ax.text(
                x[i, j],
                y[i, j],
                name,
                color="k",
                fontsize=8,
                ha="center",
                va="center",
                clip_on=True,
                bbox={"boxstyle": "round,pad=0.2", "fc": "white", "ec": c, "alpha": 0.85},
            )
    for itf in mb.interfaces:
        p = mb[itf.a.block].border(itf.a.border)[itf.a.start : itf.a.stop + 1] * scale
        ax.plot(p[:, 0], p[:, 1], color="k", lw=1.2, ls="--", zorder=3)
    if outline is not None:
        o = np.vstack([outline, outline[:1]]) * scale
        ax.plot(o[:, 0], o[:, 1], color="k", lw=0.9, zorder=4)
    ax.set_aspect("equal")
    ax.autoscale_view()
    if window is not None:
        ax.set_xlim(window[0], window[2])
        ax.set_ylim(window[1], window[3])
    if unit:
        ax.set_xlabel(f"x [{unit}]")
        ax.set_ylabel(f"y [{unit}]")
    if title:
        ax.set_title(title, fontsize=10)
    if path is not None:
        fig.savefig(path, dpi=dpi, bbox_inches="tight")
        if own:
            plt.close(fig)
    return ax
