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


def drag_shore_end_round(qtbot, win, lay0, degrees: float = 40.0, steps: int = 9) -> None:
    """With the layout tool, drag the cut end farthest from the origin (on the shore of a round lake
    centred there) ``degrees`` round the centre in ``steps`` moves, and wait for the edit to end."""
    from app.layout_edit import handles
    from tests.app.waits import wait_for, wait_idle

    win.set_tool("layout")
    tool = win.canvas.tool
    end = max((h for h in handles(lay0) if h.kind == "end"), key=lambda h: np.hypot(*h.xy))
    a0, r = np.arctan2(end.xy[1], end.xy[0]), np.hypot(*end.xy)
    path = [(r * np.cos(a0 + t), r * np.sin(a0 + t)) for t in np.radians(np.linspace(0, degrees, steps))]
    assert tool.drag("start", path[0], end.xy)
    for p in path[1:]:
        tool.drag("move", p, end.xy)
        qtbot.wait(20)
    tool.drag("finish", path[-1], end.xy)
    wait_for(qtbot, win, lambda: not win.lake_ctl.editing and win.doc.project.layout is not lay0)
    wait_idle(qtbot, win)
