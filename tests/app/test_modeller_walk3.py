"""What a third modeller's afternoon in the app (session 19, held-out GSHHG lakes under Xvfb) found,
each as it went wrong, on generated shapes."""

from __future__ import annotations

import pytest

from tests.app.test_modeller import _metres_lake
from tests.app.waits import answer_questions

pytestmark = pytest.mark.gui


def test_a_lake_imported_over_a_saved_project_is_not_saved_over_its_file(qtbot, win, tmp_path, monkeypatch):
    """Open (or save) lake A's project, import lake B over it (B replaces A, one undo step), Ctrl+S:
    the title bar still named A's file and Save wrote lake B into it without a word; A's project
    was gone.  Save now asks for a file, offering B's name, and A's file is left as it was."""
    from PySide6 import QtWidgets

    assert win.io.import_points(_metres_lake(tmp_path / "Tarn.csv", 761901))
    first = tmp_path / "Tarn.toml"
    assert win.io.save_to(first)
    saved = first.read_text()
    assert win.io.import_points(_metres_lake(tmp_path / "Mere.csv", 761902))
    asked = []

    def dialog(_parent, _caption, directory, _filter):
        asked.append(directory)
        return "", ""

    monkeypatch.setattr(QtWidgets.QFileDialog, "getSaveFileName", dialog)
    assert not win.io.save()  # the dialog was cancelled
    assert first.read_text() == saved
    assert asked == [str(tmp_path / "Mere.toml")]
    assert "Tarn.toml" not in win.windowTitle()


def test_an_imported_lake_file_is_in_open_recent(qtbot, win, tmp_path):
    """File ▸ Open recent listed saved projects only: the lake file a modeller imported an hour ago
    had to be found again in the file dialog.  It is listed, and opening it imports it."""
    src = _metres_lake(tmp_path / "Tarn.csv", 761903)
    assert win.io.import_points(src)
    assert win.io.recent()[0] == str(src)
    texts = [a.text() for a in win.io.recent_menu.actions()]
    assert str(src) in texts


def test_a_file_that_cannot_be_imported_prints_no_traceback_in_the_terminal(qtbot, win, tmp_path, monkeypatch, capsys):
    """A CSV that is no point file: the dialog said why, and the terminal got the same at INFO level
    with a full traceback (the "app" logger's INFO records reached the terminal's handler).  The
    terminal gets warnings and errors only; the log file keeps the traceback."""
    import logging

    from PySide6 import QtCore

    import app.__main__ as entry

    root = logging.getLogger()
    monkeypatch.setattr(root, "handlers", [])  # as in a new process (pytest's own are put back after)
    monkeypatch.setattr(root, "level", root.level)
    monkeypatch.setattr(logging.getLogger("app"), "level", logging.getLogger("app").level)
    monkeypatch.setattr(QtCore.QStandardPaths, "writableLocation", lambda _loc: str(tmp_path / "data"))
    entry._logging()
    added = list(root.handlers)
    try:
        bad = tmp_path / "notes.csv"
        bad.write_text("hello,world\nfoo\n")
        assert not win.io.import_points(bad)
        for h in added:
            h.flush()
        err = capsys.readouterr().err
        assert "Traceback" not in err and "notes.csv" not in err
        assert "Traceback" in (tmp_path / "data" / "gcmesh.log").read_text()
        logging.getLogger("app.test").warning("a warning still shows")
        assert "a warning still shows" in capsys.readouterr().err
    finally:
        for h in added:
            h.close()


def test_undo_and_redo_bring_back_the_grids_made_for_each_layout(qtbot, win, tmp_path):
    """Auto layout (gridded), drag a cut end, F5 (gridded again), add a cut line, F5: three grids
    made.  Ctrl+Z went back through the layouts and showed none of them (a blank lake, "F5 if it
    is not being made"): each had to be solved again, also after Ctrl+Y to the last one.  Each
    layout's grid comes back with it, current (not greyed), its verdict with it."""
    from app.layout_edit import with_cut
    from tests.app.test_modeller import _laid_out
    from tests.app.waits import drag_a_cut_end, wait_for, wait_idle

    first = _laid_out(qtbot, win, tmp_path, 761904)
    made = [(first, dict(win.doc.grids))]
    drag_a_cut_end(qtbot, win)
    win.generate()
    wait_idle(qtbot, win)
    made.append((win.doc.project, dict(win.doc.grids)))
    lay = win.doc.project.layout
    x0, y0, x1, y1 = lay.polygon.bounds
    cut = [[x0 - 1.0, (y0 + y1) / 2], [x1 + 1.0, (y0 + y1) / 2]]
    before = win.doc.project
    win.lake_ctl.edit_layout(lambda: with_cut(lay, cut), "Add cut line")
    wait_for(qtbot, win, lambda: win.doc.project is not before and not win.lake_ctl.editing)
    win.generate()
    wait_idle(qtbot, win)
    made.append((win.doc.project, dict(win.doc.grids)))
    assert len({len(g) for _p, g in made}) > 1  # the cut added blocks
    for project, grids in reversed(made[:-1]):
        win.stack.undo()
        assert win.doc.project is project
        assert win.doc.grids == grids and not win.doc.stale
        assert win.doc.lake_metrics is not None and "F5" not in win.lake_quality.headline.text()
        assert win.canvas.grid_curve.opts["pen"].color().name() == "#303030"  # drawn as current, not greyed
    for project, grids in made[1:]:
        win.stack.redo()
        assert win.doc.project is project
        assert win.doc.grids == grids and not win.doc.stale
    assert win.io.export_mesh(tmp_path / "last.vtm")


def test_a_laid_out_case_opened_first_thing_says_f5_not_auto_layout(qtbot, win, tmp_path):
    """The app started, File ▸ Open recent of a saved lake layout: the Quality panel's verdict box
    said "No lake grid yet (Auto layout, then it generates)" — an Auto layout would throw away the
    layout edited by hand.  It says that F5 makes the grid of this layout."""
    import shapely

    from app import io_adapter as fio
    from app.lake import with_layout
    from meshcore.layout import auto_layout

    assert win.io.import_points(_metres_lake(tmp_path / "Tarn.csv", 761905))
    lake = win.doc.project.lake
    laid = with_layout(win.doc.project, lake.replaced(layout=auto_layout(shapely.Polygon(lake.outline, lake.holes))))
    case = tmp_path / "Tarn.toml"
    fio.save_project(laid, case)
    from PySide6 import QtCore

    from app.main_window import MainWindow
    from app.window_frame import LIVE

    settings = QtCore.QSettings(str(tmp_path / "fresh.ini"), QtCore.QSettings.Format.IniFormat)
    settings.setValue(LIVE["lake"][0], False)  # no grid made on opening (Live is on for lakes by default)
    fresh = MainWindow(settings=settings, recovery=tmp_path / "fresh.gcmesh")
    fresh.quiet = True
    qtbot.addWidget(fresh)
    fresh.show()
    assert fresh.io.open_path(case)
    assert fresh.doc.project.layout is not None and not fresh.doc.grids
    text = fresh.lake_quality.headline.text()
    assert "Auto layout" not in text and "F5" in text


def test_a_failed_limit_never_reads_100_percent_ok(qtbot, monkeypatch):
    """The huge lake (12 islands, 14 736 cells) had 4 folded cells: the verdict table read
    "FAIL (100.0 % ok) | 4 | folded or non-convex cells" — a share of 0.99973 rounded up."""
    import sys
    from types import SimpleNamespace

    from app.document import Document
    from app.views.lake_panel import LakeQualityBox
    from meshcore.quality.presets import Limit, LimitResult

    doc = Document()
    box = LakeQualityBox(doc)
    qtbot.addWidget(box)
    folded = LimitResult(Limit("folded", 0.5), 14736, 4, 1 - 4 / 14736, False, ())
    smooth = LimitResult(Limit("smoothness", 1.2, share=0.95), 40000, 1000, 0.975, True, ())
    metrics = SimpleNamespace(samples={})  # no places to mark
    preset = SimpleNamespace(name="delft3d")
    verdict = SimpleNamespace(preset=preset, results=(folded, smooth), passed=False, failed=(folded,), metrics=metrics)
    summary = {"cells": 14736, "mean_deviation_deg": 4.88, "folded_cells": 4}
    monkeypatch.setattr(sys.modules["meshcore.quality"], "check", lambda _m, _preset: verdict)
    doc.lake_metrics = SimpleNamespace(summary=lambda: summary)
    box.refresh()
    assert box.table.item(0, 0).text() == "FAIL (99.9 % ok)"
    assert box.table.item(1, 0).text() == "pass (97.5 % ok)"


def test_the_export_dialog_offers_the_lake_file_name(qtbot, win, tmp_path, monkeypatch):
    """Save offered "<lake>.toml", Export an empty name: every export of every lake was typed.  It
    offers the lake's name with the suffix of the format it offers first (.ddb for a lake layout)."""
    from PySide6 import QtWidgets

    from tests.app.test_modeller import _laid_out

    _laid_out(qtbot, win, tmp_path, 761906)
    offered = []

    def dialog(_parent, _caption, directory, _filter, _first):
        offered.append(directory)
        return "", ""

    monkeypatch.setattr(QtWidgets.QFileDialog, "getSaveFileName", dialog)
    win.io.remember_dir(tmp_path / "out" / "x")
    win.io.export_dialog()
    assert offered == [str(tmp_path / "out" / "lake761906.ddb")]


def test_the_block_quality_names_its_block_on_a_lake_of_several(qtbot, win, tmp_path):
    """On the 12-island lake the verdict said "4 folded" and, under it, the block report "Folded /
    non-convex cells: none" and "cells 4 × 8": of the active block b0, which nothing said.  The
    report names its block (and follows the block picked)."""
    from tests.app.test_modeller import _laid_out

    _laid_out(qtbot, win, tmp_path, 761907)
    blocks = win.doc.project.blocks
    assert len(blocks) > 1
    panel = win.quality_panel
    for k in (0, 1):
        win.doc.set_active(k)
        assert f" in {blocks[k].name}" in panel.folded_label.text()
        assert (panel.table.item(0, 0).text(), panel.table.item(0, 1).text()) == ("block", blocks[k].name)


def test_the_solver_label_forgets_the_last_lake_when_another_is_imported(qtbot, win, tmp_path):
    """A lake gridded, another imported over it (no grid yet): the status bar's solver label kept
    "orthogonal: 590 sweeps, 8.1 s" of the first lake beside the second's outline."""
    from tests.app.test_modeller import _laid_out

    _laid_out(qtbot, win, tmp_path, 761908)
    assert "sweeps" in win.solve_status.label.text()
    assert win.io.import_points(_metres_lake(tmp_path / "Mere.csv", 761909))
    assert not win.doc.grids and win.solve_status.label.text() == "idle"


def test_a_stray_click_before_the_import_leaves_no_block_behind(qtbot, win, tmp_path):
    """A click on the empty canvas (the Draw tool is on at start) made an open block of one point;
    the lake imported next became a second block and the first stayed in the Blocks panel as
    "block · 1 points, open" until an Auto layout.  The lake takes its place (undo brings it back)."""
    win.editor.add_point((0.0, 0.0))
    clicked = win.doc.project
    assert win.io.import_points(_metres_lake(tmp_path / "Tarn.csv", 761910))
    assert len(win.doc.project.blocks) == 1 and win.doc.project.blocks[0].name == "Tarn"
    win.stack.undo()
    assert win.doc.project is clicked


def test_the_lon_lat_question_names_the_utm_zone(qtbot, win, tmp_path, monkeypatch):
    """ "g180810.kml holds longitude/latitude degrees. Project them to metres (the UTM zone of the
    outline, …)?" — which zone showed only on the axes after the answer.  The question names it."""

    from tests.app.test_modeller import _lonlat_lake

    asked = answer_questions(monkeypatch)
    monkeypatch.setattr(win, "quiet", False)
    monkeypatch.setattr(win.lake_ctl, "offer", lambda *_a: None)  # the Auto layout offer: not asked here
    assert win.io.import_points(_lonlat_lake(tmp_path / "Alp.geojson", 761911, lon=9.0, lat=47.0))
    assert "EPSG:32632, WGS 84 / UTM zone 32N" in asked[0]
    assert win.doc.project.crs == "EPSG:32632"


def _drop(win, path) -> None:
    from PySide6 import QtCore, QtGui

    mime = QtCore.QMimeData()
    mime.setUrls([QtCore.QUrl.fromLocalFile(str(path))])
    buttons, keys = QtCore.Qt.MouseButton.NoButton, QtCore.Qt.KeyboardModifier.NoModifier
    win.dropEvent(QtGui.QDropEvent(QtCore.QPointF(200, 200), QtCore.Qt.DropAction.CopyAction, mime, buttons, keys))


def test_a_project_dropped_on_the_window_asks_about_unsaved_work(qtbot, win, tmp_path, monkeypatch):
    """File ▸ Open and Open recent ask about unsaved changes; a .toml dropped on the window replaced
    the work at once, undo history included (a lake laid out and edited for an hour, gone)."""
    from PySide6 import QtWidgets

    from app import io_adapter as fio

    other = tmp_path / "Other.toml"
    assert win.io.import_points(_metres_lake(tmp_path / "Other.csv", 761912))
    fio.save_project(win.doc.project, other)
    assert win.io.import_points(_metres_lake(tmp_path / "Tarn.csv", 761913))
    work = win.doc.project
    asked = []

    def question(_parent, title, _text, *_a):
        asked.append(title)
        return QtWidgets.QMessageBox.StandardButton.Cancel

    monkeypatch.setattr(QtWidgets.QMessageBox, "question", question)
    monkeypatch.setattr(win, "quiet", False)
    _drop(win, other)
    assert asked == ["Unsaved changes"] and win.doc.project is work and win.stack.canUndo()


def test_the_worst_folded_cell_is_named_as_a_cell(qtbot, win):
    """Double-click on the failed folded-cells limit of the 12-island lake: the status line read
    "Worst of folded or non-convex cells: none: 1 at b8(1,50) (-5275.8308, 110017.66)"."""
    from meshcore.quality.lake import Location

    win.show_worst(Location(1.0, "b8", 1, 50, -5275.8308, 110017.66), "folded or non-convex cells: none")
    assert win._status.text() == "Worst of folded or non-convex cells: a cell at b8(1,50) (-5275.8308, 110017.66)"
    win.show_worst(Location(0.31, "b2", 4, 5, 10.0, 20.0), "node orthogonality |cos| ≤ 0.02")
    assert win._status.text() == "Worst of node orthogonality |cos| ≤ 0.02: 0.31 at b2(4,5) (10, 20)"
