"""What the modeller's second afternoon in the app found (session 18): each as it went wrong, on generated shapes."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6 import QtWidgets

from tests.app.test_modeller import _laid_out

pytestmark = pytest.mark.gui


def _draw(win, points) -> None:
    """Click a loop with the Draw tool and close it (Enter)."""
    from PySide6 import QtCore

    win.set_tool("draw")
    for xy in points:
        win.canvas.tool.click(tuple(xy))
    win.canvas.tool.key(QtCore.Qt.Key.Key_Return)


def _loop(n: int = 12, r: float = 500.0) -> np.ndarray:
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    return np.c_[r * np.cos(t), 0.6 * r * np.sin(t)]


def test_a_drawn_lake_is_titled_in_the_window_and_the_save_name(qtbot, win, tmp_path, monkeypatch):
    """A lake drawn by clicking was "untitled" in the window title and in the name Save offered."""
    from PySide6 import QtWidgets

    from app.commands import DRAWN_TITLE

    _draw(win, _loop())
    assert win.doc.block.closed
    assert win.doc.project.title == DRAWN_TITLE
    assert win.windowTitle().startswith(f"{DRAWN_TITLE} *")
    offered = []

    def dialog(_parent, _caption, directory, _filter):
        offered.append(directory)
        return "", ""

    monkeypatch.setattr(QtWidgets.QFileDialog, "getSaveFileName", dialog)
    win.io.remember_dir(tmp_path / "x")
    win.io.save_as()
    assert offered == [str(tmp_path / f"{DRAWN_TITLE}.toml")]
    win.stack.undo()  # the title goes with the closing of the loop
    assert win.doc.project.title == "" and not win.doc.block.closed


def test_a_lake_traced_on_a_background_image_is_titled_by_the_image(qtbot, win):
    from app.commands import drawn_title
    from app.project import Background

    p = win.doc.project.replaced(background=Background("/maps/Lago di Tovel 1-10000.png", None))
    assert drawn_title(p) == "Lago di Tovel 1-10000"


def test_the_window_of_a_gridded_lake_fits_a_small_screen(qtbot, win, tmp_path):
    """With a lake's verdict in the Quality panel the window could not be less than 779 px tall (the
    verdict table's fixed height over the metrics table, the histogram and the folded-cell list):
    on a 1366×768 screen its status bar was off the screen.  A 1024×600 screen leaves ~530-560 px."""
    _laid_out(qtbot, win, tmp_path, 761811)
    assert win.lake_quality.isVisible() and win.lake_quality.table.rowCount() >= 2
    assert win.minimumSizeHint().height() <= 545
    win.resize(1024, 540)
    qtbot.waitUntil(lambda: win.height() <= 545, timeout=20_000)


def test_the_side_panels_get_their_width_back_when_the_window_grows(qtbot, win):
    """A window made small (snapped to half a 1366 px screen) narrowed the side panels to a quarter
    of it; maximized again they stayed that narrow (~170 px: the Lake and Quality panels cut)."""
    from app.views.docks import MIN_CANVAS_SHARE

    win.resize(1400, 880)
    qtbot.waitUntil(lambda: win.width() == 1400 and win.docks["quality"].width() > 0, timeout=20_000)
    qtbot.wait(300)  # the docks fitted to the new size (fit_docks runs after the resize)
    left, right = win.docks["params"], win.docks["quality"]
    before = left.width(), right.width()
    win.resize(640, 600)
    qtbot.waitUntil(lambda: left.width() <= 0.3 * 640 and right.width() <= 0.3 * 640, timeout=20_000)
    small = left.width(), right.width()
    win.resize(1400, 880)

    def back() -> bool:  # their old widths, or as near as leaves the drawing area its share
        wide = left.width() >= before[0] - 16 and right.width() >= before[1] - 16
        return wide or win.canvas.width() <= MIN_CANVAS_SHARE * win.width() + 8

    qtbot.waitUntil(lambda: win.width() == 1400 and back(), timeout=20_000)
    assert left.width() > small[0] + 40 and right.width() > small[1] + 40


def test_a_failed_limit_double_clicked_zooms_to_its_worst_place(qtbot, win, tmp_path):
    """The worst cell of a failed limit could only be found by scanning the orange dots: a
    double-click (or Enter) on the limit zooms to it, rings it and names it in the status line."""
    _laid_out(qtbot, win, tmp_path, 761811)
    box = win.lake_quality
    row = next(k for k, r in enumerate(box.verdict.results) if r.passed is False)
    worst = box.verdict.results[row].worst[0]
    win.canvas.fit()
    index = box.table.model().index(row, 0)
    box.table.activated.emit(index)
    (x0, x1), (y0, y1) = win.canvas._vb.viewRange()
    assert x0 < worst.x < x1 and y0 < worst.y < y1
    assert x1 - x0 <= 10 * win.doc.project.layout.cell_size  # zoomed in to a few cells
    assert list(win.canvas.highlight_item.data["x"]) == [worst.x]
    assert win._status.text().startswith(f"Worst of {box.verdict.results[row].limit.label}")
    passed = next((k for k, r in enumerate(box.verdict.results) if r.passed), None)
    if passed is not None:
        assert not box.go_to_worst(passed)  # a limit met has no worst place to show


def test_every_toolbar_button_shows_in_a_1024_px_window(qtbot, win):
    """At 1024 px (a small laptop) Pause, Stop, Auto-generate and Fit view were behind the
    toolbar's » (Stop only by its key, Esc): the toolbar says "Open…", "Import…", "Save", the menus
    say it in full."""
    win.resize(1024, 600)
    qtbot.waitUntil(lambda: win.width() == 1024, timeout=20_000)
    tb = win.findChild(QtWidgets.QToolBar, "main-toolbar")
    qtbot.waitUntil(lambda: tb.width() > 0 and tb.width() <= 1024, timeout=20_000)
    hidden = [a.iconText() for a in tb.actions() if not a.isSeparator() and not tb.widgetForAction(a).isVisible()]
    assert hidden == [], (hidden, tb.sizeHint().width())
    assert win.a_open.text() == "&Open project…" and win.a_open.iconText() == "Open…"


def test_a_one_block_lake_exported_as_ddb_is_told_to_write_a_grd_not_to_lay_out_again(qtbot, win, tmp_path):
    """A lake in one block exported as .ddb said "needs at least two blocks; write one block as
    .grd" followed by "… couples no corner where 3 or 5 blocks meet: Lake ▸ Auto layout, regular
    makes a layout it can write" (and offered that layout), which has nothing to couple either."""
    _laid_out(qtbot, win, tmp_path, 761999)
    win.lake_ctl.set_cell_size(4 * win.doc.project.layout.cell_size)  # this lake in one block
    win.a_auto_layout.trigger()
    from tests.app.waits import wait_for, wait_idle

    wait_for(qtbot, win, lambda: not win.lake_ctl.busy)
    wait_idle(qtbot, win)
    assert win.lake_ctl.last_error is None and len(win.doc.project.layout.blocks) == 1
    assert not win.io.export_mesh(tmp_path / "lake.ddb")
    assert ".grd" in win._status.text() and "regular" not in win._status.text()


def test_a_stopped_lake_grid_is_summed_up_as_stopped(qtbot, win, tmp_path):
    """Stop (Esc) during a lake solve on its finest level: the grid as the sweeps left it (without the
    finest level's repair and the interfaces made alike) was summed up as "Lake grid: 16 blocks,
    7,296 cells …", "orthogonal: 60 sweeps, 7.8 s", as a finished grid is."""
    import dataclasses

    _laid_out(qtbot, win, tmp_path, 761811)
    mb = win.doc.multiblock
    assert not win._status.text().startswith("Lake grid, stopped")
    info = dataclasses.replace(mb.info, converged=False, message="stopped")
    win.solve_status._lake_final(dataclasses.replace(mb, info=info))
    assert win._status.text().startswith("Lake grid, stopped before it was finished")
    assert "stopped after" in win.solve_status.label.text()


def _chord_across(piece_ring) -> np.ndarray:
    """A line across a block (the polygon ``piece_ring``) through its middle, the short way."""
    import shapely
    from shapely.geometry import LineString, Polygon

    block = Polygon(piece_ring)
    box = np.asarray(block.minimum_rotated_rectangle.exterior.coords)[:4]
    sides = [box[1] - box[0], box[2] - box[1]]
    short = min(sides, key=lambda v: np.hypot(*v))
    c = np.asarray(block.representative_point().coords[0])
    line = LineString([c - 10 * short, c + 10 * short]).intersection(block.buffer(-1e-6 * block.length))
    parts = getattr(line, "geoms", [line])
    best = min(parts, key=lambda g: g.distance(shapely.Point(c)))
    return np.asarray(best.coords)[[0, -1]]


def test_a_cut_drawn_over_a_lake_layout_parts_the_block_it_crosses_and_auto_layout_is_undoable(qtbot, win, tmp_path):
    """With a layout, the Cut line tool took the modeller's clicks and then said "These blocks are the
    lake's layout: change it in the Lake panel … or Clear layout": a cut across an arm could only be
    drawn after throwing the layout away.  It parts the block it crosses now (one undo step); Auto
    layout after it makes a new layout, and Ctrl+Z brings the hand-made one back."""
    from PySide6 import QtCore

    from tests.app.waits import wait_for, wait_idle

    _laid_out(qtbot, win, tmp_path, 761811)
    lay0 = win.doc.project.layout
    big = max(lay0.pieces, key=lambda p: np.prod(lay0.blocks[lay0.pieces.index(p)].cells))
    a, b = _chord_across(big.ring)
    win.set_tool("cut")
    win.canvas.tool.click(tuple(a))
    win.canvas.tool.click(tuple(b))
    win.canvas.tool.key(QtCore.Qt.Key.Key_Return)
    wait_for(qtbot, win, lambda: win.doc.project.layout is not lay0 and not win.lake_ctl.editing)
    wait_idle(qtbot, win)
    cut = win.doc.project.layout
    assert win.lake_ctl.edit_error is None
    assert len(cut.blocks) == len(lay0.blocks) + 1 and len(cut.cuts) == len(lay0.cuts) + 1
    assert win.stack.undoText() == "Add cut line"

    def corners(lb):
        return frozenset((round(x, 6), round(y, 6)) for x, y in lb.corners)

    kept = {corners(lb) for k, lb in enumerate(lay0.blocks) if lay0.pieces[k] is not big}
    assert kept and kept <= {corners(lb) for lb in cut.blocks}  # the blocks it does not cross keep their corners
    win.a_auto_layout.trigger()
    wait_for(qtbot, win, lambda: not win.lake_ctl.busy)
    wait_idle(qtbot, win)
    assert len(win.doc.project.layout.cuts) == len(lay0.cuts)  # a new layout: the hand-drawn cut is not in it
    win.stack.undo()
    assert win.doc.project.layout is cut
    win.stack.undo()
    assert win.doc.project.layout is lay0


def test_auto_layout_of_a_drawn_lake_brings_the_lake_panel_to_the_front(qtbot, win):
    """A lake drawn and laid out (Ctrl+L) left the Parameters panel in front: the ξ, η and weights of
    one block, which the layout locks ("These blocks are the lake's layout"), over the Lake panel
    with the blocks, their cells and the cell size."""
    from tests.app.waits import wait_for, wait_idle

    win.docks["params"].raise_()
    qtbot.waitUntil(lambda: win.docks["lake"].visibleRegion().isEmpty(), timeout=20_000)
    _draw(win, _loop(r=5000.0))
    win.a_auto_layout.trigger()
    wait_for(qtbot, win, lambda: win.doc.project.layout is not None or bool(win.lake_ctl.last_error))
    assert win.lake_ctl.last_error is None
    qtbot.waitUntil(lambda: not win.docks["lake"].visibleRegion().isEmpty(), timeout=20_000)  # its tab in front
    assert win.docks["params"].visibleRegion().isEmpty()
    wait_idle(qtbot, win)


def test_the_keyboard_help_fits_a_600_px_screen(qtbot, win):
    """Help ▸ Keyboard shortcuts was a message box of one column of 35 rows: ~620 px tall under Xvfb
    (814 offscreen, on a screen of 800), its OK button below a 1024×600 screen.  Two columns, in a
    window that scrolls when the screen is smaller."""
    dlg = win.show_shortcuts()
    qtbot.waitExposed(dlg)
    screen = win.screen().availableGeometry()
    assert dlg.height() <= 0.9 * screen.height() and dlg.width() <= min(1000, screen.width()), (dlg.size(), screen)
    text = dlg.findChild(QtWidgets.QLabel).text()
    assert "verdict row" in text and "Ctrl+L" in text
    dlg.close()


def test_a_limit_on_the_mean_shows_no_misses_beside_its_pass(qtbot, win, tmp_path):
    """With the efdc preset the row "pass (mean 1.67)" had "653" in its miss column: the cells over
    the value, which that limit does not count as misses.  A dash now."""
    _laid_out(qtbot, win, tmp_path, 761811)
    box = win.lake_quality
    box.preset.setCurrentText("efdc")
    rows = [k for k, r in enumerate(box.verdict.results) if r.limit.statistic == "mean"]
    assert rows
    for k in rows:
        assert box.table.item(k, 1).text() == "–"
    each = [k for k, r in enumerate(box.verdict.results) if r.limit.statistic == "each"]
    assert [box.table.item(k, 1).text() for k in each] == [str(box.verdict.results[k].n_failed) for k in each]


def test_about_says_what_the_app_does_for_a_lake_and_where_its_log_is(qtbot, win, monkeypatch):
    """Help ▸ About named the paper's method only: not lakes, nor the log a bug report needs."""
    shown = []
    monkeypatch.setattr(QtWidgets.QMessageBox, "about", lambda _parent, _title, text: shown.append(text))
    win.show_about()
    assert "Auto layout" in shown[0] and "gcmesh.log" in shown[0]


def test_the_layout_offer_after_importing_a_lake_with_islands_is_not_titled_branched(qtbot, win, tmp_path):
    """Importing a round lake with islands offered Auto layout in a box titled "A branched lake" over
    "…: 3 island(s). One block would give a poor grid"."""
    from tests.app.test_modeller import _metres_lake

    assert win.io.import_points(_metres_lake(tmp_path / "lake.csv", 761811))
    box = win.lake_ctl.prompt
    assert box is not None and "island" in box.text()
    assert box.windowTitle() == "Islands in the lake"


def test_side_panels_narrowed_at_their_first_fit_get_their_width_back(qtbot, win):
    """A window first shown a little too narrow for its docks (1200 px: the docks narrowed from 330 to 300
    px at their first fit, no width of before recorded yet) kept them at 300 px when made wider: the Lake
    panel (~317 px) stayed cut behind a scroll bar."""
    from PySide6 import QtCore

    from app.views.docks import MIN_CANVAS_SHARE, NARROWED, WIDE_WIDTH

    win.resize(1400, 880)
    qtbot.waitUntil(lambda: win.width() == 1400 and win.docks["quality"].width() > 0, timeout=20_000)
    left, right = win.docks["params"], win.docks["quality"]
    win.resizeDocks([win.docks["blocks"], right], [330, 330], QtCore.Qt.Orientation.Horizontal)  # the first sizes
    qtbot.waitUntil(lambda: left.width() >= 320 and right.width() >= 320, timeout=20_000)
    qtbot.wait(300)
    before = left.width(), right.width()
    for d in win.docks.values():  # as before the first fit: no width recorded
        d.setProperty(WIDE_WIDTH, None)
        d.setProperty(NARROWED, None)
    narrow = int((before[0] + before[1]) / (1 - MIN_CANVAS_SHARE)) - 60  # the drawing area under its share
    win.resize(narrow, 880)
    qtbot.waitUntil(lambda: win.width() == narrow and left.width() < before[0] - 8, timeout=20_000)
    win.resize(1400, 880)
    qtbot.waitUntil(
        lambda: win.width() == 1400 and left.width() >= before[0] - 16 and right.width() >= before[1] - 16,
        timeout=20_000,
    )
