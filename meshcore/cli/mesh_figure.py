"""``meshcore mesh --png FIG``: the grid drawn, one colour per block or coloured by deviation from 90°."""

from __future__ import annotations

import io
import math
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["DPI", "figure"]

#: Resolution of the ``--png`` figure (dots per inch).
DPI = 150


def figure(path: Path, mb: Any, poly: Any, frame: Any, colour: str, metrics: Any, left_out: Any = ()) -> None:
    """One colour per block, or cells coloured by the largest deviation from 90° at their nodes."""
    import matplotlib
    from matplotlib.collections import LineCollection
    from matplotlib.figure import Figure

    from ..grid import BORDER_NAMES
    from ..io import atomic_write_bytes
    from ..plot import line_alpha

    xs = np.concatenate([np.ravel(g.x) for g in mb.grids])
    ys = np.concatenate([np.ravel(g.y) for g in mb.grids])
    w, h = float(np.ptp(xs)) or 1.0, float(np.ptp(ys)) or 1.0
    s = 8.0 / max(w, h)
    fig = Figure(figsize=(max(4.0, w * s + 1.5), max(4.0, h * s + 0.8)))
    ax = fig.add_subplot()
    blocks = matplotlib.colormaps["tab10"].colors
    mesh = None
    n_cells = sum(g.cells[0] * g.cells[1] for g in mb.grids)
    # grid lines fade where cells are a few pixels wide (a fine grid or a long river at this size
    # was a black band hiding the blocks' colours and the deviations), as on the app's canvas
    alpha = line_alpha(math.sqrt(poly.area / max(n_cells, 1)) * s * DPI)
    for k, g in enumerate(mb.grids):
        x, y = np.asarray(g.x), np.asarray(g.y)
        if colour == "deviation":
            d = metrics.blocks[k].deviation
            corners = np.stack([d[:-1, :-1], d[1:, :-1], d[1:, 1:], d[:-1, 1:]])
            with np.errstate(all="ignore"):
                c = np.where(np.isnan(corners).all(axis=0), np.nan, np.nanmax(corners, axis=0))
            mesh = ax.pcolormesh(x, y, c, cmap="magma_r", vmin=0.0, vmax=10.0, shading="flat")
            line = "0.35"
        else:
            line = blocks[k % len(blocks)]
        segs = [np.column_stack([x[i], y[i]]) for i in range(x.shape[0])]
        segs += [np.column_stack([x[:, j], y[:, j]]) for j in range(x.shape[1])]
        ax.add_collection(LineCollection(segs, colors=[line], linewidths=0.3, alpha=alpha))
        ax.add_collection(LineCollection([g.border(b) for b in BORDER_NAMES], colors=[line], linewidths=0.9))
    for ring in (r for p in getattr(poly, "geoms", [poly]) for r in (p.exterior, *p.interiors)):
        r = np.asarray(ring.coords)
        ax.plot(r[:, 0], r[:, 1], color="k", lw=0.8)
    for p in left_out:  # parts of the water left out (too small): their shores dashed
        for ring in (p.exterior, *p.interiors):
            r = np.asarray(ring.coords)
            ax.plot(r[:, 0], r[:, 1], color="0.4", lw=0.8, ls="--")
    if mesh is not None:
        fig.colorbar(mesh, ax=ax, extend="max", shrink=0.8, label="deviation from 90° at the cell's nodes [°]")
    ax.set_aspect("equal")
    ax.use_sticky_edges = False  # pcolormesh pins the limits to the cells: no margin
    ax.margins(0.02)  # the shore's extreme points not on the frame (it read as a clipped grid)
    ax.autoscale_view()
    ax.ticklabel_format(useOffset=False, style="plain")
    unit = f" [m, {frame.crs}]" if frame.crs else ""
    ax.set_xlabel(f"x{unit}")
    ax.set_ylabel(f"y{unit}")
    ax.set_title(f"{len(mb.grids)} blocks, {n_cells:,} cells", fontsize=10)
    buf = io.BytesIO()
    fig.savefig(buf, format=path.suffix.lower().lstrip("."), dpi=DPI, bbox_inches="tight")
    atomic_write_bytes(path, buf.getvalue())
