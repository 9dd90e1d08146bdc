"""The app as a lake modeller found it (issue 13): one test per problem fixed."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from PySide6 import QtCore, QtWidgets
from PySide6.QtTest import QTest

from app import geometry as geo
from tests.app.waits import wait_for, wait_idle

pytestmark = pytest.mark.gui


def solved(qtbot, win, name="bottle-coarse"):
    win.io.open_example(name, confirm=False)
    win.generate()
    wait_idle(qtbot, win)
    return win.doc.grid


def _labels(colorbar):
    return [
        colorbar.getAxis(k).labelText
        for k in ("left", "right", "top", "bottom")
        if colorbar.getAxis(k).label.isVisible() and colorbar.getAxis(k).labelText
    ]


# ------------------------------------------------------------------ display
def test_one_colour_bar_label_after_a_re_solve(qtbot, win):
    solved(qtbot, win)
    win.quality_panel.metric.setCurrentText("skewness")
    win.generate()
    wait_idle(qtbot, win)
    win.quality_panel.metric.setCurrentText("aspect ratio")
    assert _labels(win.canvas.colorbar) == ["aspect ratio"]


def test_no_stale_ring_after_new_open_or_in_figures(qtbot, win, tmp_path):
    x, y = np.meshgrid(np.arange(6.0), np.arange(5.0), indexing="ij")
    x[2, 2], y[2, 2] = 3.6, 2.9
    from meshcore import StructuredGrid

    win.doc.set_grids({0: StructuredGrid(x, y)})
    win.quality_panel._folded_clicked(win.quality_panel.folded.item(0))
    ring = win.canvas.highlight_item
    assert len(ring.data) == 1
    seen = []
    real = win.canvas.grab

    def grab(*a):
        seen.append(ring.isVisible())
        return real(*a)

    win.canvas.grab = grab
    assert win.io.export_figure(tmp_path / "f.png")
    assert seen == [False] and ring.isVisible()  # not in the figure, still on screen
    win.io.new_project()
    assert len(ring.data) == 0


def test_quality_table_is_cleared_while_a_new_solve_runs(qtbot, win):
    solved(qtbot, win, "bottle-fine")
    assert win.quality_panel.table.rowCount() > 0
    win.editor.set_block_options(cells=(200, 200))
    win.editor.set_solver(method="sor", tolerance=1e-300, max_iterations=10_000_000)
    win.generate()
    wait_for(qtbot, win, lambda: win.solver.state == "running")
    assert win.quality_panel.table.rowCount() == 0 and win.doc.quality is None
    win.solver.stop()
    wait_idle(qtbot, win)


def test_grid_lines_fade_when_cells_are_a_few_pixels(qtbot, win):
    assert geo.line_alpha(20.0) == 1.0 and geo.line_alpha(1.0) == pytest.approx(0.12)
    a = [geo.line_alpha(px) for px in np.linspace(0.5, 12, 30)]
    assert all(p <= q for p, q in itertools.pairwise(a))  # more pixels, more ink
    from app.pipeline import block_initial_grid

    win.io.open_example("bottle-coarse", confirm=False)
    win.editor.set_block_options(cells=(300, 300))
    # the test is about drawing: any grid of small cells will do, the algebraic one (no solve)
    win.doc.set_grids({0: block_initial_grid(win.doc.block)})

    def alpha():
        return win.canvas.grid_curve.opts["pen"].color().alphaF()

    win.canvas.fit()  # the view settles through the event loop: wait for it, however busy the machine
    wait_for(qtbot, win, lambda: alpha() < 0.5)
    g = win.doc.grid
    win.canvas.zoom_to((g.x[150, 150], g.y[150, 150], g.x[153, 153], g.y[153, 153]), margin=0)
    wait_for(qtbot, win, lambda: alpha() == 1.0)


def test_markers_and_grid_lines_can_be_hidden(qtbot, win):
    solved(qtbot, win)
    c = win.canvas
    assert c.points_item.isVisible() and c.corner_item.isVisible()
    win.a_markers.trigger()
    assert not c.points_item.isVisible() and not c.corner_item.isVisible()
    assert not any(a.isVisible() for a in c.border_arrows.values())
    win.editor.set_block_options(weights=(0.4, 0.6))  # a redraw does not bring them back
    assert not any(a.isVisible() for a in c.border_arrows.values())
    win.a_grid_lines.trigger()
    assert not c.grid_curve.isVisible()
    win.a_markers.trigger()
    win.a_grid_lines.trigger()
    assert c.points_item.isVisible() and c.grid_curve.isVisible()


def test_the_window_fits_its_screen_and_remembers_its_size(qtbot, tmp_path):
    from app.main_window import MainWindow

    settings = QtCore.QSettings(str(tmp_path / "s.ini"), QtCore.QSettings.Format.IniFormat)
    w = MainWindow(settings=settings, recovery=tmp_path / "r.toml")
    qtbot.addWidget(w)
    w.show()
    wait_for(qtbot, w, lambda: w._shown)
    qtbot.wait(20)
    avail = w.screen().availableGeometry()
    assert avail.contains(w.frameGeometry()), (avail, w.frameGeometry())
    assert w.minimumSizeHint().width() <= 1066 and w.minimumSizeHint().height() <= 666  # 1600×1000 at 150 %
    w.resize(700, 600)
    w.close()
    w2 = MainWindow(settings=settings, recovery=tmp_path / "r.toml")
    qtbot.addWidget(w2)
    assert (w2.width(), w2.height()) == (700, 600)


def test_auto_generate_is_remembered_between_sessions(qtbot, tmp_path):
    """Generate ▸ Auto-generate on edit (the grid follows every drag) went back to off in every new
    window: a modeller who works with it on had to find it again each session."""
    from app.main_window import MainWindow

    settings = QtCore.QSettings(str(tmp_path / "s.ini"), QtCore.QSettings.Format.IniFormat)
    w = MainWindow(settings=settings, recovery=tmp_path / "r.toml")
    qtbot.addWidget(w)
    assert not w.solver.auto and not w.a_auto.isChecked()  # off the first time
    w.a_auto.trigger()
    assert w.solver.auto
    w.close()
    w2 = MainWindow(settings=settings, recovery=tmp_path / "r.toml")
    qtbot.addWidget(w2)
    assert w2.solver.auto and w2.a_auto.isChecked()
    w2.a_auto.trigger()  # and off again when it was left off
    w2.close()
    w3 = MainWindow(settings=settings, recovery=tmp_path / "r.toml")
    qtbot.addWidget(w3)
    assert not w3.solver.auto and not w3.a_auto.isChecked()


# --------------------------------------------------------------- keyboard
def test_focus_returns_to_the_canvas_after_an_edit(qtbot, win):
    win.io.open_example("bottle-coarse", confirm=False)
    assert win.focusWidget() is win.canvas  # opening a project does not focus ξ
    pp = win.params_panel
    pp.ni.setFocus()
    pp.ni.lineEdit().selectAll()
    QTest.keyClicks(pp.ni, "9")
    QTest.keyClick(pp.ni, QtCore.Qt.Key.Key_Return)
    wait_for(qtbot, win, lambda: win.focusWidget() is win.canvas)
    assert win.doc.block.cells[0] == 9
    # moving on with Tab keeps the keyboard in the panel
    pp.ni.setFocus()
    pp.ni.lineEdit().selectAll()
    QTest.keyClicks(pp.ni, "11")
    QTest.keyClick(pp.ni, QtCore.Qt.Key.Key_Tab)
    qtbot.wait(20)
    assert win.doc.block.cells[0] == 11 and win.focusWidget() is not win.canvas
    # a pick from a list gives the keyboard back too
    pp.initial.setFocus()
    pp.initial.setCurrentText("tfi")
    pp.initial.activated.emit(pp.initial.currentIndex())
    wait_for(qtbot, win, lambda: win.focusWidget() is win.canvas)


# -------------------------------------------------------------- messages
def test_wrong_cell_counts_are_refused_visibly(qtbot, win):
    win.io.open_example("bottle-coarse", confirm=False)
    pp = win.params_panel
    before = win.doc.block.cells
    for typed in ("0", "-5"):
        pp.nj.setFocus()
        pp.nj.lineEdit().selectAll()
        QTest.keyClicks(pp.nj, typed)
        QTest.keyClick(pp.nj, QtCore.Qt.Key.Key_Return)
        assert win.doc.block.cells == before
        assert pp.nj.value() == int(typed) and pp.nj.property("refused")  # still shown, in red
        assert pp.nj.palette().color(pp.nj.palette().ColorRole.Base).name() == "#ffd6d6"
        assert "at least 1" in pp.block_msg.text() and typed in pp.block_msg.text()
        assert any("at least 1" in t for _lv, t in win.messages_panel.messages())
    assert win.focusWidget() is not win.canvas  # the keyboard stays there to fix it


def test_a_tolerance_error_is_in_view_and_in_the_message_panel(qtbot, win):
    win.io.open_example("bottle-coarse", confirm=False)
    pp = win.params_panel
    pp.resize(pp.width(), 200)  # a short dock: the solver group is below the fold
    pp.verticalScrollBar().setValue(0)
    pp.tol.setText("-1")
    pp.tol.editingFinished.emit()
    qtbot.wait(20)
    assert not pp.solver_msg.visibleRegion().isEmpty()
    assert win.doc.project.solver.tolerance is None
    assert ("warning", pp.solver_msg.text()) in win.messages_panel.messages()
    assert win.docks["messages"].isVisible()


def test_long_messages_are_kept_whole(qtbot, win):
    text = "Cannot generate: " + "a very long explanation " * 40
    win.message(text, error=True)
    assert win._status.text() == text  # the full text (and tooltip) ...
    assert QtWidgets.QLabel.text(win._status).endswith("…")  # ... shown shortened to fit
    assert win.statusBar().width() <= win.width()
    assert ("error", text) in win.messages_panel.messages()


def test_repairs_and_corner_advice_reach_the_message_panel(qtbot, win):
    solved(qtbot, win, "windermere")
    notes = " ".join(t for _lv, t in win.messages_panel.messages())
    assert "repaired" in notes  # Windermere's south arm: the fold-free repair says what it did
    # a corner on a reflex vertex: which point (counted from 1) and where to move it
    ring = np.array([[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2.0]])  # an L: point 4 is reflex
    for xy in ring:
        win.editor.add_point(tuple(xy))
    win.editor.close_loop()
    win.editor.set_corners((0, 1, 3, 5))
    advice = [t for lv, t in win.messages_panel.messages() if lv == "warning" and "reflex" in t]
    assert advice and "point 4" in advice[0] and "corner NE" in advice[0]


def test_corner_tool_counts_points_from_one(qtbot, win):
    for xy in [(0, 0), (1, 0), (1, 1), (0, 1)]:
        win.editor.add_point(xy)
    win.editor.close_loop()
    win.set_tool("corners")
    win.canvas.zoom_to((0, 0, 1, 1))
    qtbot.wait(20)
    win.canvas.tool.click((0.0, 0.0))
    assert "= point 1;" in win._status.text()


def test_a_point_clicked_twice_is_named_from_one_and_is_no_reflex_corner(qtbot, win):
    """The duplicate is the 4th point drawn: messages say "point 4" as the app counts (they said
    "index 3"), and the true 90° corner beside it is not called reflex (it was: 180°)."""
    for xy in [(0, 0), (2, 0), (4, 0), (4, 0), (4, 2), (2, 2), (0, 2), (0, 1)]:
        win.editor.add_point(xy)
    win.editor.close_loop()
    win.editor.set_corners((0, 2, 4, 6))  # SE on the first of the two (4, 0)
    win.generate()
    wait_idle(qtbot, win)
    notes = [t for lv, t in win.messages_panel.messages() if lv == "warning"]
    dup = [t for t in notes if "duplicate" in t]
    assert len(dup) == 1 and "point 4 (index 3)" in dup[0], notes
    assert not dup[0].startswith("block: block:")  # the block named once
    assert not any("reflex" in t for t in notes), notes
    assert win.doc.grid is not None and win.doc.grid.converged


# ------------------------------------------------------------- background
def _image(tmp_path, w=40, h=20):
    from PySide6 import QtGui

    img = QtGui.QImage(w, h, QtGui.QImage.Format.Format_RGB32)
    img.fill(QtGui.QColor("steelblue"))
    path = tmp_path / "bg.png"
    assert img.save(str(path))
    return path


def _in_view(win, box):
    (x0, x1), (y0, y1) = win.canvas.getPlotItem().getViewBox().viewRange()
    return x0 <= box[0] and box[2] <= x1 and y0 <= box[1] and box[3] <= y1


def test_a_background_is_in_view_after_loading_fitting_and_calibrating(qtbot, win, tmp_path):
    win.background.load(str(_image(tmp_path)))
    assert _in_view(win, (0, 0, 40, 20))  # no outline yet: one unit per pixel, and shown
    win.canvas.zoom_to((500, 500, 510, 510))
    win.canvas.fit()
    assert _in_view(win, (0, 0, 40, 20))  # Fit view counts the image
    win.background.calibrate([(0.0, 0.0), (40.0, 0.0)], [(1000.0, 5000.0), (1400.0, 5000.0)])
    assert _in_view(win, (1000, 5000, 1400, 5200))  # the view follows it to its true place


def test_a_background_loaded_over_an_outline_is_all_in_view(qtbot, win, tmp_path):
    """The image covers the outline's box and reaches past it on one side (a wide image over a
    tall outline): that side was out of view until Fit view."""
    for xy in [(0, 0), (10, 0), (10, 100), (0, 100.0)]:
        win.editor.add_point(xy)
    win.editor.close_loop()
    win.canvas.zoom_to((0, 0, 10, 100))
    win.background.load(str(_image(tmp_path, w=40, h=20)))
    a, _b, tx, ty = win.doc.project.background.transform
    assert (tx, ty) == (0.0, 0.0) and a * 40 > 100  # over the outline, 200 wide
    assert _in_view(win, geo.image_bounds(40, 20, win.doc.project.background.transform))


@pytest.mark.parametrize("with_crs", [True, False])
def test_calibration_by_longitude_and_latitude(qtbot, win, tmp_path, with_crs):
    from pyproj import Transformer

    from app.project import Project

    if with_crs:
        win.io.set_project(Project(crs="EPSG:32632", origin=(700000.0, 4700000.0), source_crs="EPSG:4326"))
    win.background.load(str(_image(tmp_path)))
    lonlat = [(11.90, 42.55), (11.99, 42.62)]
    a, b, tx, ty = win.doc.project.background.transform
    shown = [(tx, ty), (a * 40 + tx, b * 40 + ty)]  # pixels (0, 0) and (40, 0) as drawn now
    win.background.calibrate(shown, lonlat, lonlat=True)
    p = win.doc.project
    assert p.crs == "EPSG:32632"  # the project's, or the UTM zone of the points
    tr = Transformer.from_crs("EPSG:4326", p.crs, always_xy=True)
    a, b, tx, ty = p.background.transform
    for (u, v), (lon, lat) in zip([(0, 0), (40, 0)], lonlat, strict=True):
        e, n = tr.transform(lon, lat)
        z = complex(a, b) * complex(u, v) + complex(tx, ty)
        assert (z.real + p.origin[0], z.imag + p.origin[1]) == pytest.approx((e, n), abs=1e-6)
    win.stack.undo()  # one step: the image and the frame it brought
    assert win.doc.project.crs == ("EPSG:32632" if with_crs else "")


def test_calibration_by_projected_eastings_and_northings(qtbot, win, tmp_path):
    """A lake project in UTM keeps a local origin: a map's grid gives world metres (E, N), which
    calibrate the image where it belongs (they were taken as local x, y: 700 km away)."""
    from app.background import _TrueCoordinatesDialog
    from app.project import Project

    win.io.set_project(Project(crs="EPSG:32632", origin=(700000.0, 4700000.0), source_crs="EPSG:4326"))
    win.background.load(str(_image(tmp_path)))
    a, b, tx, ty = win.doc.project.background.transform
    shown = [(tx, ty), (a * 40 + tx, b * 40 + ty)]  # pixels (0, 0) and (40, 0) as drawn now
    dialog = _TrueCoordinatesDialog(win, shown, "EPSG:32632", (700000.0, 4700000.0))
    kinds = [dialog.kind.itemData(k) for k in range(dialog.kind.count())]
    assert kinds == ["model", "world", "lonlat"]
    dialog.kind.setCurrentIndex(1)  # the picked points shown as eastings and northings
    pair, kind = dialog.answer()
    assert kind == "world" and pair[0] == pytest.approx((tx + 700000.0, ty + 4700000.0))
    for e, v in zip(dialog.edits, ("701000", "4705000", "701400", "4705000"), strict=True):
        e.setText(v)
    pair, kind = dialog.answer()
    win.background.calibrate(shown, pair, world=True)
    a, b, tx, ty = win.doc.project.background.transform
    assert (tx, ty) == pytest.approx((1000.0, 5000.0)) and complex(a, b) * 40 == pytest.approx(400.0)
    assert _in_view(win, (1000, 5000, 1400, 5200))
    assert [_TrueCoordinatesDialog(win, shown, "").kind.itemData(k) for k in range(2)] == ["model", "lonlat"]


# ------------------------------------------------------------------ flicker
def test_a_drag_with_auto_generate_never_shows_the_start_grid(qtbot, win):
    from app.bench import _is_start

    win.io.open_example("annulus-sector", confirm=False)
    win.a_auto.trigger()
    wait_idle(qtbot, win)
    assert win.doc.grid is not None
    frames = []
    win.doc.grids_changed.connect(lambda: frames.append(_is_start(win.doc.grids.get(0), win.doc.initial.get(0))))
    k = int(win.doc.block.corners[2])
    p = np.array(win.doc.block.points[k])
    drag = win.editor.new_drag_id()
    for t in np.linspace(0, 1, 8)[1:]:
        win.doc.initial.pop(0, None)  # as when the warm start is refused: each solve starts cold
        win.editor.set_points([k], [p + t * np.array([0.2, 0.1])], drag_id=drag)
        qtbot.wait(30)
    wait_idle(qtbot, win)
    assert frames and not any(frames)  # redraws happened, none of them the algebraic grid
    assert win.doc.grid.converged


def test_typed_cells_survive_setting_corners(qtbot, win):
    square = [(0, 0), (4, 0), (8, 0), (8, 2), (4, 2), (0, 2.0)]
    for xy in square:
        win.editor.add_point(xy)
    win.editor.close_loop()
    win.params_panel.ni.setValue(20)
    win.params_panel.nj.setValue(6)
    win.editor.set_corners((0, 2, 3, 5))
    assert win.doc.block.cells == (20, 6)  # what the user typed
    # a block nobody typed counts for gets counts in proportion to its borders, and is told so
    win.editor.add_block()
    for xy in square:
        win.editor.add_point(xy)
    win.editor.close_loop()
    before = win.doc.block.cells
    win.editor.set_corners((0, 2, 3, 5))
    ni, nj = win.doc.block.cells
    assert (ni, nj) != before and ni > nj  # 8 long, 2 wide
    assert f"Cells {ni}×{nj}" in win._status.text()
