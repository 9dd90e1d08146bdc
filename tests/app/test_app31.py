"""The app as a lake modeller uses it (session 31): a stopped re-solve keeps the grid shown, a large
export written in a child process (the window's thread never waits for the writer)."""

from __future__ import annotations

import pytest

from tests.app.test_appq29 import coarse_then_stopped
from tests.app.waits import wait_for, wait_idle

pytestmark = pytest.mark.gui


def _laid_out_and_solved(qtbot, win, tmp_path):
    """A generated lake with islands imported, laid out and solved; the window's document."""
    from tests.app.test_modeller import _metres_lake

    assert win.io.import_points(_metres_lake(tmp_path / "lake.csv", 761811))
    wait_idle(qtbot, win)
    win.a_auto_layout.trigger()
    wait_for(qtbot, win, lambda: win.doc.project.layout is not None)
    wait_idle(qtbot, win)
    return win.doc


@pytest.mark.slow
def test_a_re_solve_stopped_on_a_coarse_level_keeps_the_finished_grid(qtbot, win, tmp_path, monkeypatch):
    """F5 on a finished lake grid, a cold solve, stopped on its coarse level: the grid the user had stays,
    finished, with its quality, and exports.  Before: the document dropped it ("no grid of this layout",
    the coarse frames greyed, nothing to export): the user lost the grid they saw."""
    import app.solver_controller as sc

    doc = _laid_out_and_solved(qtbot, win, tmp_path)
    grids, mb = dict(doc.grids), doc.multiblock
    assert grids and mb is not None and not doc.stale and doc.lake_metrics is not None
    monkeypatch.setattr(sc, "solve_project", coarse_then_stopped)
    win.generate()
    wait_for(qtbot, win, lambda: win.solver.running and _progressing(win))
    assert all(doc.grids[k] is g for k, g in grids.items())  # the coarse frames never replaced it on screen
    win.a_stop.trigger()
    wait_idle(qtbot, win)
    assert doc.grids == grids and all(doc.grids[k] is g for k, g in grids.items())
    assert doc.multiblock is mb and not doc.stale and not doc.before_grids
    assert doc.quality is not None and doc.lake_metrics is not None  # its quality back in the panel
    assert win.canvas._grid_colour == "#303030"  # drawn as a finished grid, not greyed
    assert "grid of before kept" in win.solve_status.label.text()
    assert "no grid" not in win._status.text() and "stays" in win._status.text()
    assert win.io.export_mesh(tmp_path / "out.vtm") and (tmp_path / "out.vtm").exists()


@pytest.mark.slow
def test_f5_on_a_finished_lake_grid_stopped_after_a_few_sweeps_keeps_the_finished_grid(
    qtbot, win, tmp_path, monkeypatch
):
    """F5 on a finished lake grid (a warm solve of the same layout), Stop after its first sweeps: the
    finished grid comes back, with its quality.  Before: the grid of a few sweeps replaced it, "Lake grid,
    stopped before it was finished (F5 makes it again)" (mean deviation 0.43° -> 0.44° on g180629 under
    Xvfb): the user lost a finished grid by pressing F5 and Stop."""
    import dataclasses

    import app.solver_controller as sc
    from app.lake_solve import LakeProgress
    from app.results import ALL_BLOCKS, BlockResult

    doc = _laid_out_and_solved(qtbot, win, tmp_path)
    grids, mb, initial = dict(doc.grids), doc.multiblock, dict(doc.initial)
    report = doc.lake_metrics

    def warm_then_stopped(project, *, warm, stop_event, smooth, hold, notify=None):
        """A warm solve of the same layout whose Stop lands after its first sweeps (as app.lake_solve ends it)."""
        moved = tuple(g.replaced(x=g.x + 1e-3, y=g.y) for _k, g in sorted(grids.items()))
        progress = LakeProgress(2, 0.1, 1e-5, None, 0.1, "orthogonal", ((2, 0.1),), moved, ((0, "warm start"),))
        while not stop_event.is_set():
            yield ALL_BLOCKS, progress
            stop_event.wait(0.05)
        info = dataclasses.replace(mb.info, converged=False, message="stopped")
        out = dataclasses.replace(mb, grids=moved, info=info)
        return BlockResult(grids=dict(enumerate(moved)), initial=initial, multiblock=out)

    monkeypatch.setattr(sc, "solve_project", warm_then_stopped)
    win.generate()
    wait_for(qtbot, win, lambda: win.solver.running and _progressing(win))
    wait_for(qtbot, win, lambda: doc.grids[0] is not grids[0])  # its sweeps on screen
    win.a_stop.trigger()
    wait_idle(qtbot, win)
    assert all(doc.grids[k] is g for k, g in grids.items()) and doc.multiblock is mb and not doc.stale
    assert doc.lake_metrics is report or doc.lake_metrics is not None
    assert "stopped: the grid of before kept" in win.solve_status.label.text()
    assert "stays" in win._status.text() and "stopped before it was finished" not in win._status.text()
    assert "before" not in win.lake_quality.headline.text()
    assert win.canvas._grid_colour == "#303030"


@pytest.mark.slow
def test_a_re_solve_of_new_cells_stopped_on_a_coarse_level_keeps_the_grid_of_before_greyed(
    qtbot, win, tmp_path, monkeypatch
):
    """A block's cells changed (a cold solve of the new cells), stopped on its coarse level: the grid of
    before the edit, greyed, stays on screen through the coarse level and after the Stop, said so.  Before:
    the coarse frames replaced it on screen and after the Stop it was gone (the greyed grid a coarse one)."""
    import app.solver_controller as sc

    doc = _laid_out_and_solved(qtbot, win, tmp_path)
    grids = dict(doc.grids)
    blk = doc.project.layout.blocks[0]
    monkeypatch.setattr(sc, "solve_project", coarse_then_stopped)
    win.lake_ctl.set_block_cells(0, (blk.cells[0] + 4, blk.cells[1]))
    wait_for(qtbot, win, lambda: doc.project.layout.blocks[0].cells != blk.cells)
    win.generate()
    wait_for(qtbot, win, lambda: win.solver.running and _progressing(win))
    qtbot.wait(200)  # a few coarse frames came
    assert not doc.grids and doc.before_grids == grids  # the grid of before stays drawn, greyed
    win.a_stop.trigger()
    wait_idle(qtbot, win)
    assert not doc.grids and doc.stale and doc.before_grids == grids
    assert all(doc.before_grids[k] is g for k, g in grids.items())
    assert win.canvas._grid_colour == "#b0b0b0" and len(win.canvas.grid_curve.xData) > 0
    assert "coarse level (cells ÷2): no grid" in win.solve_status.label.text()
    assert "greyed grid is of before the last edit" in win._status.text()


def _progressing(win) -> bool:
    from app.results import ALL_BLOCKS

    return ALL_BLOCKS in win.solver._latest


@pytest.fixture
def child_writes(monkeypatch):
    """Every grid counts as large (written in a child process); ``calls`` lists the child commands run."""
    import subprocess

    import app.io_export as ie
    import app.write_process as wp

    calls: list = []
    real = subprocess.run

    def run(cmd, *args, **kw):
        calls.append(list(cmd))
        return real(cmd, *args, **kw)

    monkeypatch.setattr(ie, "EXPORT_ASYNC_CELLS", 1)
    monkeypatch.setattr(wp.subprocess, "run", run)
    return calls


def test_a_large_export_is_written_by_a_child_process_and_reads_back(qtbot, win, tmp_path, child_writes):
    """A large grid's export was written in a worker thread whose writer held the GIL (a 1.75 million-cell
    .vtm stalled the window 1.4 s, EFDC 2 s): now a child process writes it; the file reads back as the
    grid, the status line says it was exported."""
    from meshcore.io import read_grid

    win.io.open_example("bottle-coarse", confirm=False)
    win.generate()
    wait_idle(qtbot, win)
    out = tmp_path / "out.vts"
    assert win.io.export_mesh(out)
    assert win.io.exporting
    wait_for(qtbot, win, lambda: not win.io.exporting)
    assert [c[1:] for c in child_writes] == [["-m", "app.write_process"]]
    (g,) = read_grid(out)
    assert g.shape == win.doc.grid.shape
    assert abs(g.x - win.doc.grid.x).max() < 1e-9 and abs(g.y - win.doc.grid.y).max() < 1e-9
    assert f"Exported 1 block(s) to {out}" in win._status.text()


def test_a_large_export_the_child_cannot_write_says_why_and_writes_nothing(qtbot, win, tmp_path, child_writes):
    """The writer's error in the child (a folder that is a file) comes back as the app's error message."""
    win.io.open_example("bottle-coarse", confirm=False)
    win.generate()
    wait_idle(qtbot, win)
    (tmp_path / "afile").write_text("not a folder")
    out = tmp_path / "afile" / "out.vts"
    assert win.io.export_mesh(out)
    wait_for(qtbot, win, lambda: not win.io.exporting)
    assert child_writes
    assert "Cannot export mesh" in win._status.text() and "out.vts" in win._status.text()
    assert not out.exists() and [p.name for p in tmp_path.iterdir() if p.name.startswith("out")] == []


def test_an_outline_of_many_points_gets_its_markers_only_once_they_are_shown(qtbot, win, tmp_path):
    """Importing a 40 000-point outline built a scatter marker for every point (0.5 s of the window's thread
    under cProfile) though, zoomed out, the markers are hidden (they would touch: the outline is its line).
    Now a hidden marker item of more than MARKERS_AT_ONCE points gets them once it is shown (zoomed in)."""
    import numpy as np

    from app.views.canvas import MARKERS_AT_ONCE

    t = np.linspace(0, 2 * np.pi, 12000, endpoint=False)
    r = 1000 * (1 + 0.3 * np.sin(7 * t))
    csv = tmp_path / "big.csv"
    csv.write_text("x,y\n" + "\n".join(f"{a:.3f},{b:.3f}" for a, b in np.c_[r * np.cos(t), r * np.sin(t)]) + "\n")
    assert win.io.import_points(csv)
    wait_idle(qtbot, win)
    qtbot.wait(50)
    c = win.canvas
    assert len(win.doc.block.points) == 12000 > MARKERS_AT_ONCE
    assert not c.points_item.isVisible() and len(c.points_item.data) == 0  # zoomed out: hidden, not built
    x, y = win.doc.block.points[0]
    c.zoom_to((x - 5, y - 5, x + 5, y + 5))
    wait_for(qtbot, win, lambda: c.points_item.isVisible() and len(c.points_item.data) == 12000)
    small = tmp_path / "small.csv"  # a few points: given at once, hidden or not (as before)
    small.write_text("x,y\n0,0\n10,0\n10,10\n0,10\n")
    assert win.io.import_points(small)
    qtbot.wait(50)
    assert len(c.points_item.data) == 4


@pytest.mark.slow
def test_export_of_the_grid_of_before_a_cut_moved_says_so_before_the_file_dialog(qtbot, win, tmp_path, monkeypatch):
    """A cut end dragged with auto-generate off: the grid on screen (greyed) is of before the edit.  File ▸
    Export opened the file dialog, then said "The lake grid is not finished: generate it (F5)" of a finished
    grid.  Now it says the grid is of before the last edit, before any dialog; after F5 the export writes."""
    from PySide6 import QtWidgets

    from tests.app.waits import drag_a_cut_end

    dialogs: list = []
    monkeypatch.setattr(
        QtWidgets.QFileDialog, "getSaveFileName", lambda *a, **k: dialogs.append(a) or (str(tmp_path / "g.vtm"), "")
    )
    doc = _laid_out_and_solved(qtbot, win, tmp_path)
    assert not win.solver.auto
    drag_a_cut_end(qtbot, win)
    assert doc.stale and doc.grids
    win.io.export_dialog()
    assert not dialogs and "of before the last edit" in win._status.text() and "F5" in win._status.text()
    assert not win.io.export_mesh(tmp_path / "x.vtm") and "not finished" not in win._status.text()
    assert not (tmp_path / "x.vtm").exists()
    win.generate()
    wait_idle(qtbot, win)
    win.io.export_dialog()
    wait_idle(qtbot, win)
    assert len(dialogs) == 1 and (tmp_path / "g.vtm").exists()


def test_colouring_by_deviation_again_keeps_its_colours_the_right_way_up(qtbot, win):
    """Deviation from 90° is coloured light (0°) to dark (10°).  pyqtgraph hands out one cached colour map
    and the canvas reversed it in place: every other colouring (after an undo, a redo, colouring off and on)
    had it upside down, a good grid drawn black (seen walking g181404 under Xvfb)."""
    import pyqtgraph as pg

    from app.document import DEVIATION

    win.io.open_example("bottle-coarse", confirm=False)
    win.generate()
    wait_idle(qtbot, win)
    ends = []
    for _ in range(3):
        win.doc.set_colour_by(DEVIATION)
        wait_idle(qtbot, win)
        cm = win.canvas.colorbar.colorMap()
        ends.append((_rgb(cm, 0.0), _rgb(cm, 1.0)))
        win.doc.set_colour_by("none")
        wait_idle(qtbot, win)
    low, high = ends[0]
    assert sum(low) > sum(high)  # light at 0°, dark at the top of the scale
    assert ends == [ends[0]] * 3
    magma = pg.colormap.get("magma")
    assert sum(_rgb(magma, 0.0)) < sum(_rgb(magma, 1.0))  # the cached map untouched


def _rgb(cm, at: float) -> tuple[int, int, int]:
    """The colour of map ``cm`` at ``at`` (0-1) as integer red, green, blue."""
    r, g, b, _a = (int(c) for c in cm.map(at, mode="byte"))
    return r, g, b
