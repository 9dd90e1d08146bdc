"""Session 37 (branch app37): four defects of an app walk — the figure export, the tool after Clear
layout, the cursor read-out after Fit."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytestmark = pytest.mark.gui

LAKES = Path(__file__).resolve().parents[2] / "benchmarks" / "lakes"


def _readout(win) -> str:
    return win._coords.text()


def _said(x: float, y: float) -> str:
    return f"x = {x:.6g}   y = {y:.6g}"


def test_the_cursor_readout_follows_a_fit_under_a_still_mouse(qtbot, win):
    """Zoomed in on a corner of a block, the mouse still, F (Fit): the status bar kept the coordinates of
    the point the mouse was over before the fit until the mouse moved.  Now it names the point under the
    mouse after the fit; with the mouse off the canvas (a click on Fit in the toolbar) it is cleared."""
    from PySide6 import QtCore

    for p in [(0.0, 0.0), (10.0, 0.0), (10.0, 5.0), (0.0, 5.0)]:
        win.editor.add_point(p)
    canvas = win.canvas
    canvas.zoom_to((0.0, 0.0, 1.0, 1.0))  # zoomed in on a corner
    r = canvas._vb.sceneBoundingRect()
    pos = QtCore.QPointF(r.center().x() + 0.2 * r.width(), r.center().y() - 0.2 * r.height())
    canvas.scene().sigMouseMoved.emit(pos)  # the mouse rests there
    before = canvas.to_model(pos)
    assert _said(*before) in _readout(win)
    canvas.fit()  # F: the whole block in view, the mouse not moved
    after = canvas.to_model(pos)
    assert abs(after[0] - before[0]) > 1.0  # the point under the mouse is another one now
    assert _said(*after) in _readout(win) and _said(*before) not in _readout(win)
    # the mouse leaves the canvas (for the toolbar's Fit button), the view changes: no coordinates shown
    QtCore.QCoreApplication.sendEvent(canvas, QtCore.QEvent(QtCore.QEvent.Type.Leave))
    canvas.zoom_to((0.0, 0.0, 1.0, 1.0))
    assert _readout(win) == ""
    canvas.scene().sigMouseMoved.emit(pos)  # back over the canvas: read out again
    assert _said(*canvas.to_model(pos)) in _readout(win)


def _small_lake():
    from app.lake import Lake
    from meshcore import testing

    poly = testing.round_lake(850_031, kind="ring", radius=2000.0)
    return Lake(
        outline=np.asarray(poly.exterior.coords)[:-1],
        holes=tuple(np.asarray(r.coords)[:-1] for r in poly.interiors),
        target_cells=1500,
    )


def test_clear_layout_leaves_the_layout_tool_for_the_tool_of_a_lake_without_one(qtbot, win):
    """Lake ▸ Clear layout left the Layout tool chosen, with no layout to act on (a click did nothing).
    Now the tool falls back to Edit, the tool an imported lake starts in; Ctrl+Z brings the layout back
    and with it the Layout tool, Ctrl+Y clears it again."""
    from app.lake import compute_layout

    lake = _small_lake()
    win.editor.set_lake(lake.replaced(layout=compute_layout(lake)), "Auto layout")
    win.set_tool("layout")  # as Auto layout leaves it
    layout = win.doc.project.layout
    assert layout is not None
    win.a_clear_layout.trigger()
    assert win.doc.project.layout is None
    assert win.canvas.tool is win.tools["edit"] and win.tool_actions["edit"].isChecked()
    win.stack.undo()  # an undoable edit: the layout back, and its tool
    assert win.doc.project.layout == layout
    assert win.canvas.tool is win.tools["layout"] and win.tool_actions["layout"].isChecked()
    win.stack.redo()
    assert win.doc.project.layout is None and win.canvas.tool is win.tools["edit"]
