"""Multiblock output beyond the grid files: the human-readable connectivity report.

Grid files (multi-block PLOT3D, VTK ``.vtm``, CGNS …) are written by
:func:`meshcore.io.write`, which takes a :class:`~.solver.MultiBlockGrid`
directly (``write("lake.vtm", mb, crs=mb.frame)``).
``write_report(path, mb)`` writes :meth:`MultiBlockGrid.report` plus the
quality tables as UTF-8 text, atomically.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

__all__ = ["write_report"]


def write_report(path: str | Path, mb: Any) -> Path:
    """Write the connectivity report and the quality tables of a MultiBlockGrid."""
    from ..io import atomic_write_text

    p = Path(path)
    atomic_write_text(p, mb.report() + "\n\n" + mb.quality().table() + "\n")
    return p
