"""What a user saw in the app in session 28: a ring the file holds twice, the Export dialog's folder,
Redo of Auto layout, the Auto layout offer over the lake, Stop on a huge solve."""

from __future__ import annotations

import json

import numpy as np
import pytest

from tests.app.waits import wait_idle

pytestmark = pytest.mark.gui

T = np.linspace(0, 2 * np.pi, 60, endpoint=False)
SHORE = np.column_stack([1000 * np.cos(T), 600 * np.sin(T)])
ISLE = np.column_stack([200 + 100 * np.cos(T[::3]), 80 * np.sin(T[::3])])


def _geojson(path, rings):
    lonlat = [[[8 + x / 1e5, 47 + y / 1e5] for x, y in [*r.tolist(), r[0].tolist()]] for r in rings]
    geometry = {"type": "Polygon", "coordinates": lonlat}
    feature = {"type": "Feature", "properties": {"name": "lake"}, "geometry": geometry}
    path.write_text(json.dumps({"type": "FeatureCollection", "features": [feature]}))
    return path


@pytest.mark.parametrize(("holes", "islands"), [((ISLE[::-1], ISLE[::-1]), 1), ((SHORE[::-1],), 0)])
def test_an_outline_with_a_ring_twice_imports_the_lake_once_with_a_note(qtbot, win, tmp_path, holes, islands):
    """A duplicated hole was "a pond on an island" (two islands in the lake), a hole the same as the
    shore was "not read as a lake" (one block of the shore, the layout refused)."""
    said: list[str] = []
    win.doc.reported.connect(lambda _level, text: said.append(text))
    f = _geojson(tmp_path / "lake.geojson", [SHORE, *holes])
    assert win.io.import_points(f, project_lonlat=True)
    wait_idle(qtbot, win)
    lake = win.doc.project.lake
    assert lake is not None and len(lake.holes) == islands
    (note,) = [t for t in said if "same ring" in t]
    assert note.startswith("lake.geojson: 'lake hole ") and "read once" in note
    assert not any("pond" in t or "not read as a lake" in t for t in said), said


def test_the_export_dialog_opens_in_the_last_export_folder_else_the_projects_else_the_imports(
    qtbot, win, tmp_path, monkeypatch
):
    """It opened in the folder the outline was imported from (or the case file's), also after the
    user had exported elsewhere: now the last export's folder (remembered in the settings), else the
    project file's, else the import folder."""
    from PySide6 import QtWidgets

    from tests.app.test_modeller import _laid_out, _metres_lake

    src, proj, out = (tmp_path / d for d in ("src", "proj", "out"))
    for d in (src, proj, out):
        d.mkdir()
    offered: list[str] = []

    def dialog(_parent, _caption, directory, *_filters):
        offered.append(directory)
        return "", ""

    monkeypatch.setattr(QtWidgets.QFileDialog, "getSaveFileName", dialog)
    _laid_out(qtbot, win, src, 761906)
    win.io.export_dialog()
    assert offered.pop() == str(src / "lake761906.ddb")  # the import folder: nothing else yet
    assert win.io.save_to(proj / "case.toml")
    win.io.export_dialog()
    assert offered.pop() == str(proj / "case.ddb")  # the project file's folder
    assert win.io.export_mesh(out / "case.vtm")
    win.io.export_dialog()
    assert offered.pop() == str(out / "case.ddb")  # the last export's (was: the project file's)
    win.io.figure_dialog()
    assert offered.pop() == str(out)
    assert win.io.import_points(_metres_lake(src / "second.csv", 761907))  # another lake, from src again
    assert win.doc.path is None and win.io.last_dir() == str(src)
    win.lake_ctl.set_cell_size(win.doc.project.lake.cell_size or 200.0)
    win.a_auto_layout.trigger()
    wait_idle(qtbot, win)
    win.io.export_dialog()
    assert offered.pop() == str(out / "second.ddb")  # remembered in the settings (was: src, the import's)
    out.rename(tmp_path / "gone")  # a folder no longer there: the next in the order
    win.io.export_dialog()
    assert offered.pop() == str(src / "second.ddb")


@pytest.mark.parametrize("how", ["auto-generate", "F5"])
def test_redo_of_auto_layout_brings_its_grid_back_without_a_new_solve(qtbot, win, tmp_path, how):
    """Undo of Auto layout starts the one block's solve (auto-generate on, or F5); a Redo while it ran
    solved the layout again from scratch (the document skipped its kept grid while a solve ran).  Now
    the redo shows the layout's grid as it was, current, and the one block's solve is dropped."""
    from tests.app.waits import wait_for

    t = np.linspace(0, 2 * np.pi, 80, endpoint=False)
    ring = np.column_stack([3000 * np.cos(t) + 400 * np.cos(3 * t), 1500 * np.sin(t)])
    assert win.io.import_points(_geojson(tmp_path / "lake.geojson", [ring]), project_lonlat=True)
    wait_idle(qtbot, win)
    win.a_auto_layout.trigger()
    wait_for(qtbot, win, lambda: win.doc.project.layout is not None)
    wait_idle(qtbot, win)
    laid, grids = win.doc.project, {k: g.x.copy() for k, g in win.doc.grids.items()}
    assert len(grids) == len(laid.blocks) > 1 and not win.doc.stale
    starts: list[object] = []
    win.solver.state_changed.connect(lambda s: starts.append(win.doc.project) if s == "running" else None)
    win.solver.set_auto(how == "auto-generate")
    win.io.stack.undo()
    if how == "F5":
        win.generate()
    wait_for(qtbot, win, lambda: win.doc.solving)  # the one block's solve runs
    assert win.doc.project.layout is None and len(starts) == 1
    win.io.stack.redo()
    assert win.doc.project is laid and not win.doc.stale  # at once, while the one block's solve stops
    wait_idle(qtbot, win)
    assert len(starts) == 1, "the redo started a solve"
    assert win.doc.project is laid and not win.doc.stale and win.doc.multiblock is not None
    assert set(win.doc.grids) == set(grids)
    for k, x in grids.items():
        assert np.array_equal(win.doc.grids[k].x, x)
    assert "orthogonal" in win.solve_status.label.text()  # the lake grid's summary, not "stopped"


def test_the_auto_layout_offer_is_a_bar_above_the_canvas_clear_of_the_lake(qtbot, win, tmp_path):
    """The offer was a message box in the middle of the window, over the lake and its islands.  It is a
    strip above the canvas now: the canvas below it shows the whole lake; Esc declines it, Enter takes
    it (the Auto layout button has the focus)."""
    from PySide6 import QtCore, QtWidgets

    from tests.app.test_modeller import _metres_lake

    win.quiet = False  # the offer is shown (quiet: made, not shown)
    win.activateWindow()
    try:
        assert win.io.import_points(_metres_lake(tmp_path / "lake.csv", 761811))
    finally:
        win.quiet = True  # (closing the window would ask to save)
    bar = win.lake_ctl.prompt
    assert bar is not None and "island" in bar.text()
    qtbot.waitUntil(bar.isVisible)
    top_left = bar.mapTo(win, QtCore.QPoint(0, 0))
    on_window = QtCore.QRect(top_left, bar.size())
    canvas = QtCore.QRect(win.canvas.mapTo(win, QtCore.QPoint(0, 0)), win.canvas.size())
    assert not on_window.intersects(canvas) and on_window.bottom() < canvas.top()
    (vx0, vx1), (vy0, vy1) = win.canvas._vb.viewRange()
    shore = win.doc.project.lake.outline
    assert vx0 <= shore[:, 0].min() and shore[:, 0].max() <= vx1
    assert vy0 <= shore[:, 1].min() and shore[:, 1].max() <= vy1
    go, later = bar.buttons()
    assert go.text() == "Auto layout" and later.text() == "Not now"
    qtbot.waitUntil(lambda: QtWidgets.QApplication.focusWidget() is go)
    qtbot.keyClick(go, QtCore.Qt.Key.Key_Escape)  # declined: no layout, the keys go back to the canvas
    assert win.lake_ctl.prompt is None and not win.lake_ctl.busy and win.doc.project.layout is None
    assert QtWidgets.QApplication.focusWidget() is win.canvas
    win.quiet = False
    try:
        assert win.io.import_points(_metres_lake(tmp_path / "again.csv", 761812))
    finally:
        win.quiet = True
    go = win.lake_ctl.prompt.buttons()[0]
    qtbot.waitUntil(lambda: QtWidgets.QApplication.focusWidget() is go)
    win.lake_ctl.set_cell_size(np.sqrt(abs(_area(win.doc.project.lake.outline))) / 20)  # a quick grid
    qtbot.keyClick(go, QtCore.Qt.Key.Key_Return)  # taken: Auto layout runs
    assert win.lake_ctl.busy or win.doc.project.layout is not None
    wait_idle(qtbot, win)
    assert win.doc.project.layout is not None and win.lake_ctl.prompt is None


def _area(ring):
    x, y = np.asarray(ring, float).T
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def test_the_apps_grid_stopped_half_way_is_measured_without_its_coverage():
    """The coverage (the union of every block's cells) was most of what a Stop waited for after the
    sweeps had stopped (8 s of 10 on a lake of 380 000 cells)."""
    import threading

    from app.lake_solve import _cold
    from meshcore import testing
    from meshcore._generators import drain
    from meshcore.layout import auto_layout

    ev = threading.Event()
    ev.set()
    one = auto_layout(testing.lake_with_islands(1), target_cells=3000, multiple=1)  # the full level at once
    stopped = drain(_cold(one, ev))
    assert stopped.multiblock.info.message == "stopped" and stopped.metrics is not None
    assert stopped.metrics.coverage is None
    done = drain(_cold(one, None))
    assert done.metrics.coverage is not None


def test_stop_during_a_lake_solve_ends_it_and_leaves_a_consistent_document(qtbot, win, tmp_path):
    """Stop pressed while the lake grid's start is solved: the solve ends (on 1.7 million cells it went
    on for minutes: the start solve, repairs and untangling did not look at Stop), the status line says
    so, and the document holds either the stopped grid of the layout or none; F5 then makes the grid."""
    from tests.app.test_modeller import _metres_lake
    from tests.app.waits import wait_for

    assert win.io.import_points(_metres_lake(tmp_path / "lake.csv", 761811))
    wait_idle(qtbot, win)
    win.a_auto_layout.trigger()
    wait_for(qtbot, win, lambda: win.doc.project.layout is not None and win.solver.running)
    laid = win.doc.project
    win.a_stop.trigger()
    wait_idle(qtbot, win)
    assert not win.solver.running and not win.doc.solving and win.doc.project is laid
    grids = win.doc.grids
    if grids:  # stopped on the full level: the grid as it stood, said to be stopped
        assert len(grids) == len(laid.blocks) and win.doc.multiblock is not None
        assert win.doc.multiblock.info.message == "stopped" and "stopped" in win.solve_status.label.text()
    else:  # stopped on a coarse level: no grid (the coarse ones are never a result), F5 makes it
        assert win.doc.multiblock is None and win.doc.quality is None
    win.generate()
    wait_idle(qtbot, win)
    assert len(win.doc.grids) == len(laid.blocks) and not win.doc.stale
    assert win.doc.multiblock.info.converged and win.doc.lake_metrics is not None
