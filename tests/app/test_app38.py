"""Session 38 (branch app38): defects of a lake modeller's walk under Xvfb on held-out lakes."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from tests.app.test_app33 import _small_lake

pytestmark = pytest.mark.gui

DATA = Path(__file__).resolve().parents[1] / "data"


def _laid_out(win):
    from app.lake import compute_layout

    lake = _small_lake()
    win.editor.set_lake(lake.replaced(layout=compute_layout(lake)), "Auto layout")
    return win.doc.project


def test_a_lake_imported_while_the_last_one_solves_gets_none_of_its_grid(qtbot, win, tmp_path):
    """F5 on a lake's layout, then File ▸ Import of another lake before the solve ended: the solve of the
    first lake went on and its grid became the new project's — the Quality dock measured the first lake's
    block b0 ("cells 28 × 48") under the new lake's name, the Messages said "g181044: orthogonal grid on
    3 levels" of a grid never made of it, and Export mesh wrote the first lake's block in the second's
    frame.  Now a new lake (or an opened project) drops the solve of the one before: no grid, nothing
    measured, nothing to export until F5."""
    from tests.app.waits import wait_for, wait_idle

    _laid_out(win)
    win.generate()
    assert win.solver.running
    win.solver.pause()  # the solve of the first lake is on (paused: it cannot end before the import)
    assert win.io.import_points(DATA / "lake_zurich_sparse.geojson", project_lonlat=True)
    assert win.doc.project.lake is not None and win.doc.project.layout is None
    win.solver.resume()
    wait_for(qtbot, win, lambda: not win.solver.running)
    wait_idle(qtbot, win)
    assert win.doc.grids == {} and win.doc.multiblock is None
    assert win.doc.quality is None and win.doc.lake_metrics is None
    assert not win.io.export_mesh(tmp_path / "zurich.vts")
    assert not (tmp_path / "zurich.vts").exists()


def test_an_example_opened_while_another_solves_gets_none_of_its_grid(qtbot, win):
    """The same for File ▸ Open and the Examples menu: the solve of the project before was stopped, not
    dropped, and the grid it returned was set as the opened project's block 0 (greyed, measured in the
    Quality dock: the bottle's quality under the two circles' name)."""
    from tests.app.waits import wait_for, wait_idle

    assert win.io.open_example("bottle-fine", confirm=False)
    win.generate()
    assert win.solver.running
    win.solver.pause()
    assert win.io.open_example("two-circles-coarse", confirm=False)
    win.solver.resume()
    wait_for(qtbot, win, lambda: not win.solver.running)
    wait_idle(qtbot, win)
    assert win.doc.grids == {} and win.doc.quality is None
    win.generate()  # F5 makes the example's own grid, as before
    wait_for(qtbot, win, lambda: bool(win.doc.grids) and not win.doc.stale and not win.solver.running)
    assert win.doc.grids[0].cells == tuple(win.doc.project.blocks[0].cells)


def _h_layout(win):
    """A 3000 × 1000 m lake split by two cuts across it and one between them (an H): four blocks; the
    middle cut runs from one junction to the other, straight: no end on the shore, no point of its own."""
    from app.lake import Lake, compute_layout

    out = np.array([(0, 0), (3000, 0), (3000, 1000), (0, 1000)], float)
    cuts = (
        np.array([(1000, 0), (1000, 1000)], float),
        np.array([(2000, 0), (2000, 1000)], float),
        np.array([(1000, 500), (2000, 500)], float),
    )
    lake = Lake(outline=out, cell_size=100.0)
    win.editor.set_lake(lake.replaced(layout=compute_layout(lake, cuts)), "Split into 4 blocks by cut lines")
    win.set_tool("layout")
    return win.doc.project.layout


def test_del_deletes_a_cut_line_pointed_at_along_its_line(qtbot, win):
    """Layout tool, the cursor on a cut line, Del: "Delete a cut line: point at its end or one of its points
    (ringed)".  A cut from one junction to another, straight, has neither (4 of 96 cuts of a held-out lake's
    layout, g180752): it could not be deleted at all.  Now the cut under the cursor goes (one undo step);
    at a junction, where several cuts are as near, nothing goes and the status says how."""
    from tests.app.waits import wait_for, wait_idle

    lay = _h_layout(win)
    assert len(lay.blocks) == 4
    tool = win.canvas.tool
    tool.hover((1000.0, 500.0))  # the junction: three cuts meet there
    win.a_delete.trigger()
    assert not win.lake_ctl.editing and win.doc.project.layout is lay
    assert "point at" in win._status.text()
    tool.hover((1400.0, 500.0 + 0.5 * tool.tol()))  # on the middle cut, between its junctions
    win.a_delete.trigger()
    assert win.lake_ctl.editing  # the layout without it is being made
    wait_for(qtbot, win, lambda: win.doc.project.layout is not lay and not win.lake_ctl.editing)
    wait_idle(qtbot, win)
    new = win.doc.project.layout
    assert len(new.blocks) == 3 and len(new.cuts) == 2
    assert not any(np.allclose(np.asarray(c)[:, 1], 500.0) for c in new.cuts)  # the middle cut went
    assert win.stack.undoText() == "Delete cut line"
    win.stack.undo()
    assert win.doc.project.layout is lay


def test_the_cursor_reads_out_the_deviation_of_every_coloured_block(qtbot, win):
    """Colour cells by deviation from 90° colours every block of a lake grid; the status bar read out the
    cell under the cursor of the active block alone: over the dark cells of another block (where a
    modeller looks) it said nothing.  Now it names the block and the cell of any block, with its value."""
    from app.document import DEVIATION
    from tests.app.waits import wait_for, wait_idle

    p = _laid_out(win)
    win.generate()
    wait_for(qtbot, win, lambda: bool(win.doc.grids) and not win.doc.stale and win.doc.lake_metrics is not None)
    wait_idle(qtbot, win)
    win.quality_panel.metric.setCurrentText(DEVIATION)
    assert len(win.doc.colour_layers()) == len(p.blocks) > 1  # every block coloured
    win.doc.set_active(0)
    k = 1  # a block that is not the active one, its worst cell
    g, dev = win.doc.multiblock.grids[k], win.doc.lake_metrics.blocks[k].deviation
    values = np.fmax(np.fmax(dev[:-1, :-1], dev[1:, :-1]), np.fmax(dev[1:, 1:], dev[:-1, 1:]))  # a cell's nodes' worst
    i, j = np.unravel_index(int(np.nanargmax(values)), values.shape)
    cx, cy = g.x[i : i + 2, j : j + 2].mean(), g.y[i : i + 2, j : j + 2].mean()
    said = win._cell_readout(cx, cy)
    assert said == f"{p.blocks[k].name} cell ({i}, {j}): {DEVIATION} {float(values[i, j]):.4g}"
    win.quality_panel.metric.setCurrentText("skewness")  # a metric of the active block only: no block named
    g0 = win.doc.quality_grid
    assert win._cell_readout(g0.x[0:2, 0:2].mean(), g0.y[0:2, 0:2].mean()).startswith("cell (0, 0): skewness")
    assert win._cell_readout(cx, cy) == ""  # over another block: not coloured, nothing read out


def test_a_file_not_opened_for_a_restored_autosave_is_said_where_it_stays(qtbot, win, tmp_path, monkeypatch):
    """gcmesh started on g180663.csv after a crash offered the autosaved lake; Yes restored it and, Live on,
    solved it: the status line's "g180663.csv was not opened" was the restored grid's line a second later
    and the question had not said the file would not open.  Now the question says what Yes and No do with
    the file, and the Messages keep the note."""
    from PySide6 import QtWidgets

    from app.__main__ import open_at_start
    from app.main_window import MainWindow
    from tests.app.waits import wait_for, wait_idle

    _laid_out(win)
    win.io.autosave()  # the session that crashes
    w = MainWindow(settings=win.settings, recovery=win.io.recovery_path)
    w.quiet = True
    qtbot.addWidget(w)
    asked, reported = [], []
    w.doc.reported.connect(lambda level, text: reported.append(text))

    def question(_parent, _title, text, *_a):
        asked.append(text)
        return QtWidgets.QMessageBox.StandardButton.Yes

    monkeypatch.setattr(QtWidgets.QMessageBox, "question", question)
    assert open_at_start(w, file=str(tmp_path / "g180663.csv"))
    assert len(asked) == 1 and "g180663.csv is not opened" in asked[0]
    w.generate()  # the restored lake's grid: its line replaces the status line's note
    wait_for(qtbot, w, lambda: bool(w.doc.grids) and not w.doc.stale and not w.solver.running)
    wait_idle(qtbot, w)
    assert "g180663.csv was not opened" not in w._status.text()
    assert any("g180663.csv was not opened" in t for t in reported)  # kept in the Messages
    assert w.solver.shutdown(msecs=120_000)
    w.stack.setClean()


def test_an_undo_while_a_layout_edit_is_made_is_not_undone_by_the_edit(qtbot, win):
    """Lake panel: a block's cells set, Ctrl+Z at once (the new layout still being made off the GUI
    thread): the undo took Auto layout away, then the edit landed on the lake without a layout — the
    layout was back, with the cells, and Redo (Auto layout) was gone from the history.  Now an edit of a
    layout that an undo (or anything else) replaced before it was made is not set, and said so."""
    from app.lake import compute_layout
    from tests.app.waits import wait_for, wait_idle

    lake = _small_lake()
    win.editor.set_lake(lake, "Import lake.geojson")  # the lake imported, then laid out
    lay = compute_layout(lake)
    win.editor.set_lake(lake.replaced(layout=lay), "Auto layout")
    c = lay.blocks[0].cells
    win.lake_ctl.set_block_cells(0, (c[0] + 4, c[1]))
    assert win.lake_ctl.editing
    win.stack.undo()  # Ctrl+Z before the edit is made: Auto layout is undone
    assert win.doc.project.layout is None
    wait_for(qtbot, win, lambda: not win.lake_ctl.editing)
    wait_idle(qtbot, win)
    assert win.doc.project.layout is None  # not set again by the edit
    assert win.stack.redoText() == "Auto layout" and win.stack.index() == win.stack.count() - 1
    assert "not made" in win._status.text()
    win.stack.redo()
    assert win.doc.project.layout is lay  # the layout as it was, its cells unchanged
    win.lake_ctl.set_block_cells(0, (c[0] + 4, c[1]))  # an edit with nothing in between lands as before
    wait_for(qtbot, win, lambda: not win.lake_ctl.editing)
    assert win.doc.project.layout.blocks[0].cells == (c[0] + 4, c[1])
    assert win.stack.undoText().startswith("Cells of")


def test_a_layout_made_while_another_lake_was_imported_is_not_set_on_it(qtbot, win, monkeypatch):
    """Auto layout of Bolsena (it takes seconds on a real lake), File ▸ Import of Zurich meanwhile: when
    Bolsena's layout was done it was set on the project — Bolsena's outline and blocks in Zurich's frame
    under Zurich's name.  Now a layout of water the project no longer holds is not set, and said so."""
    import threading

    from app import lake_controller
    from tests.app.waits import wait_for, wait_idle

    imported = threading.Event()
    made = lake_controller.compute_layout

    def slow(*a, **k):  # the layout is done only after the second import (as on a lake of 20 s)
        imported.wait(60)
        return made(*a, **k)

    monkeypatch.setattr(lake_controller, "compute_layout", slow)
    assert win.io.import_points(DATA / "lake_bolsena_sparse.geojson", project_lonlat=True)
    assert win.lake_ctl.auto_layout() and win.lake_ctl.busy
    assert win.io.import_points(DATA / "lake_zurich_sparse.geojson", project_lonlat=True)
    zurich = win.doc.project
    imported.set()
    wait_for(qtbot, win, lambda: not win.lake_ctl.busy)
    wait_idle(qtbot, win)
    assert win.doc.project is zurich and zurich.layout is None  # Zurich as imported
    assert "not set" in win._status.text()
    assert win.stack.undoText() == "Import lake_zurich_sparse.geojson"
    win.stack.undo()  # back to Bolsena: Auto layout lays it out as before
    assert win.lake_ctl.auto_layout()
    wait_for(qtbot, win, lambda: not win.lake_ctl.busy)
    assert win.doc.project.layout is not None and win.doc.project.title == "lake_bolsena_sparse"


def test_an_import_undone_while_its_lake_solves_leaves_none_of_its_grid(qtbot, win):
    """The same through Ctrl+Z: a lake laid out (not solved yet), another imported and F5 on its one
    block, Ctrl+Z (the import undone) while that solves: its grid became the first lake's block b0 grid
    (greyed, measured in the Quality dock)."""
    from tests.app.waits import wait_for, wait_idle

    first = _laid_out(win)
    assert win.io.import_points(DATA / "lake_zurich_sparse.geojson", project_lonlat=True)
    win.generate()  # the one block of the second lake
    assert win.solver.running
    win.solver.pause()
    win.stack.undo()  # the import undone: the first lake, its layout, no grid yet
    assert win.doc.project.layout is first.layout
    win.solver.resume()
    wait_for(qtbot, win, lambda: not win.solver.running)
    wait_idle(qtbot, win)
    assert win.doc.grids == {} and win.doc.quality is None and win.doc.lake_metrics is None


def test_a_click_again_on_a_failed_limit_goes_to_its_next_worst_place(qtbot, win, tmp_path):
    """Quality dock, a failed limit clicked: the view went to its worst place, and a click again went there
    again — the second, third worst (which ``meshcore quality`` prints as "next worst") could be found only
    among hundreds of orange dots.  Now each click again goes to the next of the worst places the verdict
    keeps (round again after the last), the status line says which; Enter shows the same place again."""
    from PySide6 import QtCore

    from tests.app.test_modeller import _laid_out as laid_out_coarse

    laid_out_coarse(qtbot, win, tmp_path, 850_021)  # coarse: it misses delft3d's limits in many places
    box = win.lake_quality
    row = next(k for k, r in enumerate(box.verdict.results) if r.passed is False and len(r.worst) >= 3)
    worst, label = box.verdict.results[row].worst, box.verdict.results[row].limit.label
    rect = box.table.visualRect(box.table.model().index(row, 2))

    def click():
        qtbot.mouseClick(box.table.viewport(), QtCore.Qt.MouseButton.LeftButton, pos=rect.center())
        return win.canvas.highlight_item.data["x"][0], win._status.text()

    def at(w, shown) -> bool:
        return shown[0] == w.x

    first = click()
    assert at(worst[0], first) and first[1].startswith(f"Worst of {label}: {worst[0]}")
    second = click()
    assert at(worst[1], second) and second[1].startswith(f"2nd worst of {label}: {worst[1]}")
    assert f"(2 of the {len(worst)} worst" in second[1]
    box.table.activated.emit(box.table.model().index(row, 0))  # Enter: the same place again
    assert win.canvas.highlight_item.data["x"][0] == worst[1].x
    for _ in range(len(worst) - 1):
        last = click()
    assert at(worst[0], last)  # round again: the worst


def test_block_tools_on_a_laid_out_lake_say_what_to_do_with_a_layout(qtbot, win):
    """On an imported lake laid out by Auto layout: A (Auto corners) said "Auto corners needs a closed loop
    of at least 4 points", a click with the Corners tool "Corners need a closed loop of points: draw or import
    one first", Ctrl+K "Split needs a closed loop of points (draw or import one)" — of a lake just imported.
    Now they say how a layout is edited (and that a cut drawn over it splits at once), and change nothing."""
    from app.commands import LAYOUT_HINT

    p = _laid_out(win)
    win.a_auto_corners.trigger()
    assert win._status.text() == LAYOUT_HINT
    win.set_tool("corners")
    win.canvas.tool.click((0.0, 0.0))
    assert win._status.text() == LAYOUT_HINT
    win.a_split.trigger()
    assert "splits the blocks it crosses at once" in win._status.text() and LAYOUT_HINT in win._status.text()
    assert win.doc.project is p and not win.lake_ctl.busy
