"""What the session-26 walk through the app found (a lake with islands from a KML, edited,
exported, saved, reopened, broken files): each as it went wrong, on generated shapes."""

from __future__ import annotations

import json

import numpy as np
import pytest

from tests.app.test_modeller import _laid_out
from tests.app.waits import wait_idle

pytestmark = pytest.mark.gui


def _eight(path):
    """A figure-eight outline in metres (it touches itself at its middle): a lake meshcore mesh refuses."""
    t = np.linspace(0, 2 * np.pi, 40, endpoint=False)
    xy = np.c_[3000 * np.sin(t), 2000 * np.sin(2 * t)]
    path.write_text("x,y\n" + "\n".join(f"{x:.2f},{y:.2f}" for x, y in xy) + "\n")
    return path


def test_undo_back_to_a_gridded_lake_after_a_failed_solve_shows_its_grid_as_current(qtbot, win, tmp_path):
    """A gridded lake, auto-generate on; an outline that crosses itself imported over it (its solve
    fails: "Cannot generate"), then undone: the lake, its layout and its grid came back, but the
    grid stayed greyed and its verdict "Grid of before the last edit (F5 makes the new one)",
    although it was the grid of that very layout (the failed solve's error held the summary back)."""
    solved = _laid_out(qtbot, win, tmp_path, 862601)
    grids = dict(win.doc.grids)
    win.a_auto.trigger()
    assert win.solver.auto
    assert win.io.import_points(_eight(tmp_path / "eight.csv"))
    wait_idle(qtbot, win)
    assert win.solver.last_error  # the eight cannot be gridded: where, its points counted from 1
    assert "the edge from point" in win.solver.last_error and "segment" not in win.solver.last_error
    win.stack.undo()
    wait_idle(qtbot, win)
    assert win.doc.project is solved and win.doc.grids == grids and not win.doc.stale
    assert win.canvas.grid_curve.opts["pen"].color().name() == "#303030"  # not greyed
    assert "before the last edit" not in win.lake_quality.headline.text()


def test_an_outline_that_crosses_itself_is_not_offered_auto_layout(qtbot, win, tmp_path):
    """A lon/lat outline that crosses itself: the import said in Messages that meshcore mesh refuses
    it (fix it first), and at once offered Auto layout ("lays the lake out in blocks"), whose
    button then failed with the same crossing.  Now no offer; the status line says why."""
    t = np.linspace(0, 2 * np.pi, 40, endpoint=False)
    ring = np.c_[10 + 0.05 * np.sin(t), 60 + 0.03 * np.sin(2 * t)].tolist()
    path = tmp_path / "eight.geojson"
    path.write_text(json.dumps({"type": "Polygon", "coordinates": [[*ring, ring[0]]]}))
    assert win.io.import_points(path, project_lonlat=True)
    assert win.doc.project.lake is not None  # imported, to be fixed by hand
    assert win.lake_ctl.prompt is None
    status = win._status.text()
    assert "crosses itself" in status and "Auto layout" in status
    # both edges by their two points (the second was "the edge from point 20")
    assert "the edge from point 1 to 2 meets the edge from point 20 to 21" in status


def test_undo_of_an_import_shows_the_lake_again(qtbot, win, tmp_path):
    """An outline imported over a lake fits the view to it; Ctrl+Z brought the lake back but the
    view stayed on the other outline, far away: an empty canvas, the lake looked lost."""
    _laid_out(qtbot, win, tmp_path, 862602)
    lake = win.doc.project.bounds()
    far = tmp_path / "far.csv"
    t = np.linspace(0, 2 * np.pi, 30, endpoint=False)
    far.write_text("x,y\n" + "\n".join(f"{5e6 + 800 * np.cos(a):.2f},{800 * np.sin(a):.2f}" for a in t) + "\n")
    assert win.io.import_points(far)
    assert not win.canvas.shows_any_of(lake)
    win.stack.undo()
    assert win.canvas.shows_any_of(lake)
    win.stack.redo()
    assert win.canvas.shows_any_of(win.doc.project.bounds())


def test_undo_of_an_import_in_another_frame_fits_the_lake_back(qtbot, win, tmp_path):
    """The walk's case: Lake g180632 (UTM 35N) and a small outline imported over it (UTM 32N, its
    local origin elsewhere); undo left the view on the small outline's few kilometres round the
    local origin, inside the lake's bounding box but showing none of it."""
    import shapely

    _laid_out(qtbot, win, tmp_path, 862608)
    lake = win.doc.project.bounds()
    t = np.linspace(0, 2 * np.pi, 30, endpoint=False)
    small = tmp_path / "small.geojson"
    ring = [[10 + 0.002 * np.cos(a), 60 + 0.001 * np.sin(a)] for a in t]
    small.write_text(json.dumps({"type": "Polygon", "coordinates": [[*ring, ring[0]]]}))
    assert win.io.import_points(small, project_lonlat=True)
    (x0, x1), (y0, y1) = win.canvas._vb.viewRange()
    win.stack.undo()
    (u0, u1), (v0, v1) = win.canvas._vb.viewRange()
    assert (u0, u1, v0, v1) != (x0, x1, y0, y1)
    view = shapely.box(u0, v0, u1, v1)
    assert view.contains(shapely.box(*lake))  # fitted: the whole lake in sight


def test_a_laid_out_lake_says_which_tool_edits_it(qtbot, win, tmp_path):
    """A saved lake layout reopened in the Edit tool: a click said "use Block ▸ Convert to loop to
    edit points", which then refused ("These blocks are the lake's layout ..."); Select all and
    Delete did nothing and said nothing.  The Layout tool (Y) drags its points: each says so, and
    the project reopens in it."""
    from app.commands import LAYOUT_HINT

    _laid_out(qtbot, win, tmp_path, 862603)
    win.set_tool("edit")
    x0, y0, x1, y1 = win.doc.project.bounds()
    win.canvas.tool.click(((x0 + x1) / 2, (y0 + y1) / 2))
    assert win._status.text() == LAYOUT_HINT and "Layout tool" in LAYOUT_HINT
    win.message("")
    win.a_select_all.trigger()
    assert win._status.text() == LAYOUT_HINT
    win.message("")
    win.a_delete.trigger()
    assert win._status.text() == LAYOUT_HINT
    win.message("")
    win.convert_to_loop()
    assert win._status.text() == LAYOUT_HINT
    assert win.io.save_to(tmp_path / "lake.toml")
    assert win.io.open_path(tmp_path / "lake.toml")
    assert win.canvas.tool.name == "layout"


def test_the_worst_place_of_a_failed_limit_is_ringed_in_a_block_not_active(qtbot, win, tmp_path):
    """A click on a failed limit zoomed to its worst place and made its block the active one; the
    active block's quality, drawn anew, cleared the ring: a fan of thin cells on screen and no way
    to tell which node was the worst."""
    _laid_out(qtbot, win, tmp_path, 862604)
    box = win.lake_quality
    names = [b.name for b in win.doc.project.blocks]
    rows = [k for k, r in enumerate(box.verdict.results) if r.passed is False and r.worst]
    assert rows
    for row in rows:
        worst = box.verdict.results[row].worst[0]
        win.doc.set_active(next(k for k, n in enumerate(names) if n != worst.block))
        box.table.activated.emit(box.table.model().index(row, 0))
        assert names[win.doc.active] == worst.block
        assert list(win.canvas.highlight_item.data["x"]) == [worst.x]
        assert list(win.canvas.highlight_item.data["y"]) == [worst.y]


def test_the_active_block_is_in_sight_in_the_blocks_panel(qtbot, win, tmp_path):
    """A worst place (or a click on the canvas) made b20 of a 76-block lake active: the Blocks
    panel showed b0 … b14, the active block expanded out of sight below."""
    from app.views.panels import BlocksPanel

    _laid_out(qtbot, win, tmp_path, 862605)
    tree = BlocksPanel(win.doc)
    qtbot.addWidget(tree)
    tree.setFixedSize(300, 70)  # room for a few rows only
    tree.show()
    qtbot.waitExposed(tree)
    n = len(win.doc.project.blocks)
    assert n >= 4
    for k in (n - 1, 0, n - 2):
        win.doc.set_active(k)
        assert tree.viewport().rect().intersects(tree.visualItemRect(tree.topLevelItem(k)))
        # the Lake panel's table selects its row (it went on showing b0 selected under "b18: 24 44 Set")
        assert win.lake_panel.table.currentRow() == k


def test_a_project_opened_with_auto_generate_on_does_not_say_press_f5(qtbot, win, tmp_path):
    """Auto-generate on (remembered): a saved lake opened, its grid being made, and the status line
    said "Opened lake.toml: press F5 to generate"."""
    _laid_out(qtbot, win, tmp_path, 862606)
    assert win.io.save_to(tmp_path / "lake.toml")
    win.a_auto.trigger()
    assert win.io.open_path(tmp_path / "lake.toml")
    assert "F5" not in win._status.text() and "generating" in win._status.text()
    wait_idle(qtbot, win)
    assert not win.doc.stale and win.doc.grids
    win.a_auto.trigger()  # off: F5 makes the grid
    assert win.io.open_path(tmp_path / "lake.toml")
    assert "press F5" in win._status.text()


def test_a_bad_point_in_a_kml_or_geojson_is_counted_from_1(qtbot, win, tmp_path):
    """Messages count points from 1 (CSV lines, crossing edges): a KML's bad second tuple was
    "coordinate tuple 1", a GeoJSON's bad third position "feature 0 (feature 1) ring 0: position 2"."""
    ring = [(10.0, 60.0), (10.1, 60.0), (10.1, 60.1), (10.0, 60.1), (10.0, 60.0)]
    coords = " ".join(f"{x},{y},0" for x, y in ring).replace("10.1,60.0,0", "10.1,,0")
    kml = tmp_path / "bad.kml"
    kml.write_text(
        '<kml xmlns="http://www.opengis.net/kml/2.2"><Document><Placemark><name>shore</name><Polygon>'
        f"<outerBoundaryIs><LinearRing><coordinates>{coords}</coordinates></LinearRing></outerBoundaryIs>"
        "</Polygon></Placemark></Document></kml>"
    )
    assert not win.io.import_points(kml, project_lonlat=True)
    assert "placemark 1 (shore) outerBoundaryIs: coordinate tuple 2 '10.1,,0'" in win._status.text()
    good = {"type": "Feature", "properties": {}, "geometry": {"type": "Polygon", "coordinates": [ring]}}
    bad = {"type": "Feature", "properties": {}, "geometry": {"type": "Polygon", "coordinates": [[*ring]]}}
    bad["geometry"]["coordinates"][0][2] = ["x", 60.1]
    gj = tmp_path / "bad.geojson"
    gj.write_text(json.dumps({"type": "FeatureCollection", "features": [good, bad]}))
    assert not win.io.import_points(gj, project_lonlat=True)
    assert "feature 2 (feature 2) ring 1: position 3 is not a list of numbers" in win._status.text()


def test_export_after_an_edit_says_the_grid_on_screen_is_of_before_it(qtbot, win, tmp_path):
    """Auto-generate off, a block given other cells (or a drag that stretched one): the grid of
    before stays on screen, greyed; File ▸ Export mesh said "Nothing to export yet: generate a grid
    first (F5)" over it."""
    _laid_out(qtbot, win, tmp_path, 862607)
    assert not win.solver.auto
    ni, nj = win.doc.project.layout.blocks[0].cells
    win.lake_ctl.set_block_cells(0, (ni + 4, nj))
    wait_idle(qtbot, win)
    assert win.doc.before_grids and not win.doc.grids  # the greyed grid of before the edit
    win.io.export_dialog()
    text = win._status.text()
    assert "Nothing to export" not in text and "before the last edit" in text and "F5" in text
    assert not win.io.export_mesh(tmp_path / "lake.vtm")
    assert "before the last edit" in win._status.text() and not (tmp_path / "lake.vtm").exists()


def test_a_file_of_two_points_is_one_error(qtbot, win, tmp_path):
    """A CSV of two points: a warning that it was "not read as a lake ...; its largest line is
    imported as one block", then the error that it needs 4 points — and nothing imported."""
    said = []
    win.doc.reported.connect(lambda level, text: said.append((level, text)))
    f = tmp_path / "two.csv"
    f.write_text("x,y\n0,0\n1,1\n")
    assert not win.io.import_points(f)
    assert len(said) == 1 and said[0][0] == "error" and "needs at least 3 points, found 2" in said[0][1]


def test_a_file_opened_after_a_crash_does_not_lose_the_autosaved_work(qtbot, win, tmp_path, monkeypatch):
    """The app crashed with unsaved edits (autosaved); started again on a file (a double-click,
    ``gcmesh lake.toml``) it opened the file without offering the autosave, and the first edit
    autosaved over it: the lost session's work was gone for good.  Now the autosave is offered first."""
    from PySide6 import QtWidgets

    from app.__main__ import open_at_start
    from app.main_window import MainWindow

    assert win.io.open_example("bottle-coarse", confirm=False)
    assert win.io.save_to(tmp_path / "bottle.toml")
    win.editor.set_block_options(weights=(0.3, 0.7))  # the unsaved edit of the session that crashed
    win.io.autosave()
    crashed = win.doc.project

    def started(answer):  # a window started after the crash, as main() starts it on a file
        w = MainWindow(settings=win.settings, recovery=win.io.recovery_path)
        w.quiet = True
        qtbot.addWidget(w)
        asked = []

        def question(*a, **k):
            asked.append(a[1])
            return answer

        monkeypatch.setattr(QtWidgets.QMessageBox, "question", question)
        assert open_at_start(w, file=str(tmp_path / "bottle.toml"))
        return w, asked

    w, asked = started(QtWidgets.QMessageBox.StandardButton.Yes)
    assert asked == ["Recover project"] and w.doc.project == crashed and not w.stack.isClean()
    assert "bottle.toml was not opened" in w._status.text()
    w.io.autosave()  # still the crashed work in the autosave
    w.stack.setClean()  # (a clean close: the autosave goes)
    win.io.autosave()
    w, asked = started(QtWidgets.QMessageBox.StandardButton.No)  # declined: the file opens
    assert asked == ["Recover project"] and w.doc.path == tmp_path / "bottle.toml"
    assert w.doc.project != crashed


def test_a_restored_lake_layout_is_in_the_layout_tool(qtbot, win, tmp_path, monkeypatch):
    """A laid-out lake restored after a crash came back in the Draw tool (the window's first)."""
    from PySide6 import QtWidgets

    from app.main_window import MainWindow

    _laid_out(qtbot, win, tmp_path, 862609)
    win.io.autosave()
    w = MainWindow(settings=win.settings, recovery=win.io.recovery_path)
    w.quiet = True
    qtbot.addWidget(w)
    monkeypatch.setattr(QtWidgets.QMessageBox, "question", lambda *a, **k: QtWidgets.QMessageBox.StandardButton.Yes)
    assert w.io.offer_recovery() and w.doc.project.layout is not None
    assert w.canvas.tool.name == "layout"
    w.stack.setClean()


def test_the_verdict_of_a_stopped_lake_grid_says_it_was_stopped(qtbot, win, tmp_path):
    """Stop (Esc) on a lake grid: the status line said "stopped before it was finished" once (the
    Stop button's tip replaced it at once); the Quality panel's verdict read as of a finished grid."""
    import copy
    import dataclasses

    _laid_out(qtbot, win, tmp_path, 862610)
    mb = win.doc.multiblock
    assert "stopped" not in win.lake_quality.headline.text()
    info = dataclasses.replace(mb.info, converged=False, message="stopped")
    stopped = dataclasses.replace(mb, info=info)
    win.doc.set_grids({k: copy.copy(g) for k, g in win.doc.grids.items()}, multiblock=stopped)  # as a solve sets them
    assert "stopped before it was finished" in win.lake_quality.headline.text()


def test_a_lake_offered_auto_layout_is_not_gridded_as_one_block_by_auto_generate(qtbot, win, tmp_path):
    """Auto-generate on, a lake with an island imported: beside the offer ("One block would give a
    poor grid; Auto layout splits the lake into blocks") the one block was solved at once — its grid
    drawn across the island, "351 non-convex cells (88 folded); repaired ..." in Messages."""
    from tests.app.test_modeller import _metres_lake

    win.a_auto.trigger()
    assert win.solver.auto
    assert win.io.import_points(_metres_lake(tmp_path / "lake.csv", 862611))
    assert win.lake_ctl.prompt is not None and win.doc.project.lake.holes
    wait_idle(qtbot, win)
    assert not win.doc.grids and not win.solver.running
    win.generate()  # F5 still makes it
    wait_idle(qtbot, win)
    assert win.doc.grids


def test_the_auto_layout_offer_goes_with_its_lake(qtbot, win, tmp_path):
    """The offer is a window of its own (non-modal): after another import (one not offered), an
    undo of the import or File ▸ New it stayed open, and its button laid out the lake there then."""
    from tests.app.test_modeller import _metres_lake

    assert win.io.import_points(_metres_lake(tmp_path / "lake.csv", 862612))
    assert win.lake_ctl.prompt is not None
    win.stack.undo()
    assert win.lake_ctl.prompt is None
    win.stack.redo()  # (no offer again: the redo is not an import)
    assert win.io.import_points(_metres_lake(tmp_path / "lake2.csv", 862613))
    assert win.lake_ctl.prompt is not None
    assert win.io.import_points(_eight(tmp_path / "eight.csv"))  # crosses itself: not offered
    assert win.lake_ctl.prompt is None
    assert win.io.import_points(_metres_lake(tmp_path / "lake3.csv", 862614))
    assert win.lake_ctl.prompt is not None
    win.lake_ctl.set_cell_size(123.0)  # the same lake: the offer stays
    assert win.lake_ctl.prompt is not None
    win.stack.setClean()
    win.io.new_project()
    assert win.lake_ctl.prompt is None


def test_the_limit_clicked_stays_chosen_when_its_worst_place_is_in_another_block(qtbot, win, tmp_path):
    """A click on the second failed limit: the view went to its worst place and made that block
    active; the block's quality, drawn anew, selected the first failed limit again, and the canvas
    showed that limit's misses under the status line of the one clicked."""
    from app.views.lake_panel import miss_points

    _laid_out(qtbot, win, tmp_path, 862604)
    box = win.lake_quality
    box.preset.setCurrentText("delft3d")
    failed = [k for k, r in enumerate(box.verdict.results) if r.passed is False and r.worst]
    assert len(failed) >= 2
    row = failed[1]
    shown = []
    box.misses.connect(lambda pts: shown.append(pts))
    names = [b.name for b in win.doc.project.blocks]
    worst = box.verdict.results[row].worst[0]
    win.doc.set_active(next(k for k, n in enumerate(names) if n != worst.block))
    box.table.selectRow(row)
    box.table.clicked.emit(box.table.model().index(row, 0))
    assert names[win.doc.active] == worst.block
    assert [r.row() for r in box.table.selectionModel().selectedRows()] == [row]
    assert shown and np.array_equal(shown[-1], miss_points(box.verdict, row))
