"""What the cut-line tests draw: a 20 × 10 km box lake and cut lines clicked with the Cut line tool."""

from __future__ import annotations

from pathlib import Path

import numpy as np


def box_csv(path: Path) -> Path:
    """A CSV of the 20 × 10 km rectangle (metres), written to ``path``."""
    ring = [(0.0, 0.0), (20000.0, 0.0), (20000.0, 10000.0), (0.0, 10000.0)]
    path.write_text("x,y\n" + "\n".join(f"{x:.3f},{y:.3f}" for x, y in ring) + "\n")
    return path


def draw_cut(win, pts) -> None:
    """Click ``pts`` (world coordinates) with the Cut line tool and press Return."""
    from PySide6 import QtCore

    win.set_tool("cut")
    for xy in pts:
        win.canvas.tool.click(np.asarray(xy, float))
    win.canvas.tool.key(QtCore.Qt.Key.Key_Return)
