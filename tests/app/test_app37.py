"""Session 37 (branch app37): four defects of an app walk — the figure export, the tool after Clear
layout, the cursor read-out after Fit."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from tests.app.test_app33 import _small_lake

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


def _rgb(colour: str) -> tuple[int, int, int]:
    return tuple(int(colour[i : i + 2], 16) for i in (1, 3, 5))  # type: ignore[return-value]


def _image(path) -> np.ndarray:
    """An image file's pixels, (height, width, 3) RGB."""
    from PySide6 import QtGui

    img = QtGui.QImage(str(path)).convertToFormat(QtGui.QImage.Format.Format_RGB888)
    a = np.frombuffer(img.constBits(), np.uint8).reshape(img.height(), img.bytesPerLine())[:, : 3 * img.width()]
    return a.reshape(img.height(), img.width(), 3).copy()


def _pixels(path, rgb, tol: int = 0) -> int:
    """How many pixels of an image file have the colour ``rgb`` (each channel within ``tol``)."""
    return int((np.abs(_image(path).astype(int) - np.array(rgb)) <= tol).all(axis=-1).sum())


def test_an_exported_figure_has_the_grid_without_the_editing_marks(qtbot, win, tmp_path):
    """File ▸ Export figure of a laid-out lake wrote what the canvas showed: block labels, cut lines,
    block corners, the preset's misses and the ring round the worst, the active block's coloured borders.
    Now the figure has the grid, the shore and the axes; the canvas shows its marks again afterwards."""
    from app.lake import compute_layout
    from app.views.canvas import BORDER_COLOURS
    from app.views.lake_items import CUT_COLOUR, SHORE_COLOUR
    from tests.app.waits import wait_for, wait_idle

    lake = _small_lake()
    win.editor.set_lake(lake.replaced(layout=compute_layout(lake)), "Auto layout")
    win.set_tool("layout")
    win.generate()
    wait_for(qtbot, win, lambda: bool(win.doc.grids) and not win.doc.stale and win.doc.multiblock is not None)
    wait_idle(qtbot, win)
    canvas = win.canvas
    canvas.fit()
    (x0, y0, x1, y1) = win.doc.project.bounds()
    canvas.lake_items.set_misses(np.array([[0.5 * (x0 + x1), 0.5 * (y0 + y1), 3.0]]))  # one miss, ringed
    win.show_misses(True)
    qtbot.wait(50)
    shown = tmp_path / "canvas.png"
    assert canvas.grab().save(str(shown))
    labels = [t.toPlainText() for t in canvas.lake_items.labels if t.isVisible()]
    assert labels and canvas.lake_items.miss_marks.worst.isVisible()
    marks = {"cut lines": CUT_COLOUR, "the worst miss's ring": "#d62728"}
    marks |= {f"the {b} border": c for b, c in BORDER_COLOURS.items()}
    rgb = {k: _rgb(c) for k, c in marks.items()}
    shore = _rgb(SHORE_COLOUR)
    for what, c in rgb.items():
        assert _pixels(shown, c) > 0, f"{what} not on the canvas"
    assert win.io.export_figure(tmp_path / "lake.png")
    for what, c in rgb.items():
        assert _pixels(tmp_path / "lake.png", c) == 0, f"{what} in the figure"
    assert _pixels(tmp_path / "lake.png", shore) > 0  # the shore stays
    pen = canvas.grid_curve.opts["pen"].color()  # the grid's lines, faded as the cells are small on screen
    grey = [round(255 * (1 - pen.alphaF()) + v * pen.alphaF()) for v in (pen.red(), pen.green(), pen.blue())]
    assert _pixels(tmp_path / "lake.png", grey, tol=2) > 1000  # and the grid
    assert win.io.export_figure(tmp_path / "lake.svg")
    svg = (tmp_path / "lake.svg").read_text()
    assert SHORE_COLOUR.lower() in svg.lower()
    corners = "#b8860b" if canvas.lake_items.markers_hollow else "#ffd700"  # cells smaller than the squares
    for c in [CUT_COLOUR, corners, "#d62728", *BORDER_COLOURS.values()]:
        assert c.lower() not in svg.lower()
    assert not any(line in svg for text in labels for line in text.split("\n"))  # no block label
    again = tmp_path / "again.png"
    assert canvas.grab().save(str(again))  # the marks are back on the canvas, pixel for pixel
    assert np.array_equal(_image(shown), _image(again))
