"""Figures of grids (``.png``, ``.svg``, ``.pdf``) through matplotlib.

Uses :func:`meshcore.plot.plot_grid` when the lead's plotting module is
present; otherwise draws the grid lines itself (ξ lines and η lines, borders
thicker, equal aspect), like the paper's figures.  matplotlib is imported
only here, lazily.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ..errors import WriteError
from ._base import GridSet, atomic_path

__all__ = ["write_figure"]


def write_figure(path: Path, gs: GridSet, *, dpi: int = 150, title: str | None = None, **options: Any) -> None:
    """Draw the blocks of ``gs`` to an image file (format from the suffix)."""
    try:
        from matplotlib.figure import Figure
    except ImportError as exc:  # pragma: no cover
        raise WriteError(f"{path}: figures need matplotlib: pip install 'gcmesh[plot]'") from exc
    fmt = Path(path).suffix.lower().lstrip(".")
    fig = Figure(figsize=options.pop("figsize", (7, 6)))
    ax = fig.add_subplot()
    plot_grid = None
    try:
        from ..plot import plot_grid  # type: ignore[attr-defined]
    except ImportError:
        plot_grid = None
    if plot_grid is not None:
        world = [g.replaced(x=gs.world(k)[0], y=gs.world(k)[1]) for k, g in enumerate(gs.blocks)]
        plot_grid(world if len(world) > 1 else world[0], ax=ax, **options)
    else:
        for k in range(len(gs.blocks)):
            X, Y = gs.world(k)
            ax.plot(X, Y, color="0.2", lw=0.5)
            ax.plot(X.T, Y.T, color="0.2", lw=0.5)
            for sl in ((slice(None), 0), (slice(None), -1), (0, slice(None)), (-1, slice(None))):
                ax.plot(X[sl], Y[sl], color="k", lw=1.2)
        ax.set_aspect("equal")
        unit = " [m]" if gs.frame.crs else ""
        ax.set_xlabel(f"x{unit}")
        ax.set_ylabel(f"y{unit}")
    if title:
        ax.set_title(title)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format=fmt, dpi=dpi, bbox_inches="tight")
