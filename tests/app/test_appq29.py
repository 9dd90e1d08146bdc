"""Large grids in the app without freezes (session 29): the quality of a large grid is measured in a
worker thread, and its result is taken only while it is of the grid shown."""

from __future__ import annotations

import threading

import numpy as np
import pytest

from tests.app.waits import wait_for, wait_idle

pytestmark = pytest.mark.gui


@pytest.fixture
def measured(monkeypatch):
    """Every grid counts as large (measured in the worker); ``threads`` lists the threads the quality
    reports were made in; the measures whose numbers (from 0) are in ``hold`` wait for ``gate``."""
    import app.document as document

    real = document.quality
    seen = {"threads": [], "gate": threading.Event(), "hold": set(), "started": threading.Event(), "made": {}}

    def quality(g):
        n = len(seen["threads"])
        seen["threads"].append(threading.current_thread())
        if n in seen["hold"]:
            seen["started"].set()
            assert seen["gate"].wait(60), "the test never let the measure go on"
        report = real(g)
        seen["made"][id(report)] = g
        return report

    monkeypatch.setattr(document, "ASYNC_CELLS", 1)
    monkeypatch.setattr(document, "quality", quality)
    return seen


def test_a_large_grids_quality_is_measured_in_a_worker_and_fills_the_panel_in(qtbot, win, measured):
    """The quality report of a grid of 1.75 million cells took 5-7 s of the window's thread after the solve;
    now a worker measures it: the panel says so meanwhile, then shows the report, and the status line
    gets its summary."""
    win.io.open_example("bottle-coarse", confirm=False)
    measured["hold"].add(len(measured["threads"]))
    win.generate()
    wait_for(qtbot, win, lambda: not win.solver.running and measured["started"].is_set())
    assert win.doc.measuring and win.doc.quality is None and win.doc.grid is not None
    assert win.quality_panel.table.rowCount() == 0
    assert "Measuring" in win.quality_panel.folded_label.text()
    assert "measuring its quality" in win._status.text()
    measured["gate"].set()
    wait_idle(qtbot, win)
    assert not win.doc.measuring and win.doc.quality is not None and win.doc.quality_grid is win.doc.grid
    assert win.quality_panel.table.rowCount() > 5
    assert "measuring" not in win._status.text() and "Grid" in win._status.text()
    assert measured["threads"] and threading.main_thread() not in measured["threads"]


@pytest.mark.parametrize("then", ["re-solve", "open another"])
def test_a_measure_of_an_older_grid_never_replaces_the_newer_one(qtbot, win, measured, then):
    """The user solves again (or opens another case) while the last grid is measured: when that measure
    ends, its report is thrown away; the document shows the new grid's report (or none)."""
    win.io.open_example("bottle-coarse", confirm=False)
    win.generate()
    wait_idle(qtbot, win)
    first = win.doc.grid
    assert win.doc.quality is not None and win.doc.quality_grid is first
    measured["hold"].add(len(measured["threads"]))  # the next measure waits
    win.generate()  # a warm start: a new grid of the same shape
    wait_for(qtbot, win, lambda: not win.solver.running and measured["started"].is_set())
    held = win.doc.quality_grid
    assert held is not None and held is not first and win.doc.measuring
    if then == "re-solve":
        win.generate()
        wait_for(qtbot, win, lambda: not win.solver.running)
    else:
        win.io.open_example("annulus-sector", confirm=False)
    newer = win.doc.quality_grid
    assert newer is not held
    shown = []  # the reports the document showed from here on: the grids they were made of
    win.doc.quality_changed.connect(lambda: shown.append(measured["made"].get(id(win.doc.quality))))
    measured["gate"].set()
    wait_idle(qtbot, win)
    assert win.doc.quality_grid is newer and not win.doc.measuring
    assert all(g is newer for g in shown)  # never the held one (the grids may be equal: "is")
    assert bool(shown) == (then == "re-solve")
    if then == "re-solve":
        assert newer is win.doc.grid and win.doc.quality is not None and win.doc.quality.cells == newer.cells
        assert win.measurer.runs >= 3  # the held measure ran to its end (thrown away), the newer one after it
        assert win.quality_panel.table.rowCount() > 5
    else:
        assert newer is None and win.doc.quality is None and not win.doc.grids
        assert win.quality_panel.table.rowCount() == 0


def coarse_then_stopped(project, *, warm, stop_event, smooth, hold, notify=None):
    """A lake solve whose Stop lands on the level of half the cells (as app.lake_solve ends it)."""
    from app.lake_solve import LakeProgress
    from app.results import ALL_BLOCKS, BlockResult
    from meshcore import StructuredGrid
    from meshcore.multiblock import initial_grids

    full = initial_grids(project.layout.topology())
    half = tuple(StructuredGrid(x=g.x[::2, ::2], y=g.y[::2, ::2]) for g in full)
    progress = LakeProgress(5, 0.1, 1e-5, None, 0.1, "orthogonal", ((5, 0.1),), half, ((0, "cells ÷2"),))
    while not stop_event.is_set():  # a live frame every 0.05 s until Stop
        yield ALL_BLOCKS, progress
        stop_event.wait(0.05)
    return BlockResult(grids={}, initial={})


def test_stop_on_a_coarse_level_leaves_no_grid_and_the_coarse_one_greyed(qtbot, win, tmp_path, monkeypatch):
    """Stop while a lake grid is on a coarse level: the solve returns no grid (the coarse ones are never a
    result).  The frames of that level were kept as the final grids ("Grid 8×12 cells: converged" of a block
    of 16×24, its quality measured, exported so, not stale).  Now: no grid of the layout (nothing measured or
    exported, the project stale), the last coarse frames drawn greyed, the status line says so; F5 makes it."""
    import app.solver_controller as sc
    from tests.app.test_modeller import _metres_lake

    real = sc.solve_project

    assert win.io.import_points(_metres_lake(tmp_path / "lake.csv", 761811))
    wait_idle(qtbot, win)
    monkeypatch.setattr(sc, "solve_project", coarse_then_stopped)
    win.a_auto_layout.trigger()
    wait_for(qtbot, win, lambda: win.doc.project.layout is not None and win.solver.running and bool(win.doc.grids))
    laid = win.doc.project
    cells = [tuple(b.cells) for b in laid.layout.blocks]
    assert [g.cells for g in win.doc.grids.values()] == [(a // 2, b // 2) for a, b in cells]  # a coarse frame
    superseded: list = []  # no grid was made: the messages of before it are not greyed as of an older grid
    win.doc.superseded.connect(lambda: superseded.append(1))
    win.a_stop.trigger()
    wait_idle(qtbot, win)
    assert not superseded
    doc = win.doc
    assert doc.project is laid and not doc.grids and doc.stale and doc.quality is None and doc.multiblock is None
    assert len(doc.before_grids) == len(cells)  # drawn greyed
    assert win.canvas._grid_colour == "#b0b0b0" and len(win.canvas.grid_curve.xData) > 0
    assert "coarse level (cells ÷2): no grid" in win.solve_status.label.text()
    assert "no grid of this layout" in win._status.text() and "F5" in win._status.text()
    assert not win.io.export_mesh(tmp_path / "out.vtm") and not (tmp_path / "out.vtm").exists()
    monkeypatch.setattr(sc, "solve_project", real)
    win.generate()
    wait_idle(qtbot, win)
    assert [g.cells for _k, g in sorted(doc.grids.items())] == cells and not doc.stale and not doc.before_grids
    assert win.canvas._grid_colour == "#303030" and doc.lake_metrics is not None


def _drawn_edges(canvas) -> set:
    """The segments the canvas draws, as pairs of rounded end points."""
    x, y = canvas.grid_curve.xData, canvas.grid_curve.yData
    p = np.round(np.column_stack([x, y]), 6)
    return {(tuple(a), tuple(b)) for a, b in zip(p[0::2], p[1::2], strict=True)}


def test_a_grid_of_many_cells_is_drawn_in_part_and_every_cell_where_zoomed_in(qtbot, win):
    """Every cell edge of a grid of 1.75 million cells was drawn every frame (2-4 s of the window's thread,
    the first frame 3-10 s).  Now a grid of more than MAX_DRAWN_CELLS cells is drawn every few lines (its
    borders always); zoomed in on a part of few enough cells, every edge there is drawn; a small grid is
    drawn whole.  The document keeps the whole grid."""
    from app.views import canvas as cv
    from meshcore import StructuredGrid

    def grid(n):
        i, j = np.meshgrid(np.arange(n + 1.0), np.arange(n + 1.0), indexing="ij")
        return StructuredGrid(x=i + 0.1 * np.sin(j / 7), y=j)

    c = win.canvas
    small = grid(100)
    win.doc.set_grids({0: small})
    assert len(c.grid_curve.xData) == 2 * (2 * 100 * 101)  # every edge: two ends each
    n = 600
    big = grid(n)
    assert n * n > cv.MAX_DRAWN_CELLS
    win.doc.set_grids({0: big})
    c.fit()
    qtbot.wait(2 * cv.WINDOW_DELAY_MS)
    edges = _drawn_edges(c)
    assert len(edges) <= 2 * (cv.MAX_DRAWN_CELLS + 2 * n)  # about the budget, not the 721 200 edges of the grid
    x, y = np.round(big.x, 6), np.round(big.y, 6)
    ends = {p for e in edges for p in e}
    border = [(x[i, j], y[i, j]) for i, j in ((0, 0), (0, n), (n, 0), (n, n), (n, n // 2 + 1), (n // 2 + 1, 0))]
    assert all(p in ends for p in border)  # the four borders are drawn lines (an odd index: not every other)
    inner = ((x[301, 151], y[301, 151]), (x[302, 151], y[302, 151]))  # off the drawn lines (odd i, odd j)
    assert inner not in edges
    c.zoom_to((290.0, 140.0, 320.0, 170.0), margin=0.0)  # 30 x 30 cells in view
    qtbot.waitUntil(lambda: inner in _drawn_edges(c), timeout=10_000)
    assert win.doc.grids[0] is big
    c.fit()
    qtbot.waitUntil(lambda: inner not in _drawn_edges(c), timeout=10_000)


def test_the_colouring_of_a_grid_of_many_cells_merges_cells_and_keeps_the_worst(qtbot, win):
    """Coloured by a quality measure, a grid of 1.75 million cells froze the window for about a minute
    (pyqtgraph paints each cell as a polygon from Python).  Now more than MAX_COLOURED_CELLS cells are
    merged for the colouring, each merged cell showing the worst value of its cells (the largest; the
    smallest of the Jacobian ratio); zoomed in on few enough cells, those are coloured one by one."""
    from app.views import canvas as cv
    from meshcore import StructuredGrid

    n = 400
    i, j = np.meshgrid(np.arange(n + 1.0), np.arange(n + 1.0), indexing="ij")
    x = i + 0.2 * np.sin(j / 5) * np.exp(-(((i - 123) / 3) ** 2 + ((j - 77) / 3) ** 2))  # one skewed spot
    big = StructuredGrid(x=x, y=j)
    win.doc.set_grids({0: big})
    wait_for(qtbot, win, lambda: win.doc.quality is not None)
    win.doc.set_colour_by("skewness")
    z = win.canvas.quality_item.z
    assert z.size <= cv.MAX_COLOURED_CELLS < n * n
    worst = np.nanmax(win.doc.quality.arrays["skewness"])
    assert np.nanmax(z) == pytest.approx(worst)  # the skewed spot is seen
    c = win.canvas
    c.zoom_to((0.0, 0.0, float(n), float(n)))  # the whole grid in view (a margin round it): merged only
    qtbot.waitUntil(lambda: not c.quality_window_items, timeout=10_000)
    c.zoom_to((110.0, 65.0, 135.0, 90.0), margin=0.0)  # the spot, ~25 x 25 cells: coloured one by one
    qtbot.waitUntil(lambda: bool(c.quality_window_items), timeout=10_000)
    fine = c.quality_window_items[0].z
    assert fine.size < cv.MAX_COLOURED_CELLS and np.nanmax(fine) == pytest.approx(worst)
    skew = win.doc.quality.arrays["skewness"]
    assert np.isin(np.round(fine, 9), np.round(skew, 9)).all()  # the cells' own values, not merged ones
    c.zoom_to((0.0, 0.0, float(n), float(n)))
    qtbot.waitUntil(lambda: not c.quality_window_items, timeout=10_000)
    win.doc.set_colour_by("Jacobian ratio")  # its worst cells are its smallest values
    z = win.canvas.quality_item.z
    assert np.nanmin(z) == pytest.approx(np.nanmin(win.doc.quality.arrays["jacobian_ratio"]))
    win.doc.set_colour_by("none")
    assert win.canvas.quality_item is None


def test_a_large_grid_is_exported_in_a_worker_and_said_when_written(qtbot, win, tmp_path, monkeypatch):
    """Writing a grid of 1.75 million cells held the window (a .vtm 26 s, EFDC files 128 s at load 20).
    Now a grid of EXPORT_ASYNC_CELLS or more is written in a worker: the status says it is being written,
    then that it was (or why not); a second export meanwhile is refused, not lost."""
    import app.io_export as ie
    import app.write_process as wp
    from meshcore import StructuredGrid
    from meshcore.io import read

    real, threads, gate = wp.write_in_process, [], threading.Event()

    def write_in_process(*args):  # waited for in the worker (session 31: it runs a child process that writes)
        threads.append(threading.current_thread())
        assert gate.wait(60)
        return real(*args)

    monkeypatch.setattr(wp, "write_in_process", write_in_process)
    monkeypatch.setattr(ie, "EXPORT_ASYNC_CELLS", 1000)
    i, j = np.meshgrid(np.arange(41.0), np.arange(31.0), indexing="ij")
    win.doc.set_grids({0: StructuredGrid(x=i + 0.1 * np.sin(j), y=j)})
    out = tmp_path / "big.vts"
    assert win.io.export_mesh(out)
    assert win.io.exporting and "Exporting 1,200 cells" in win._status.text()
    assert not win.io.export_mesh(tmp_path / "again.vts") and "being written" in win._status.text()
    gate.set()
    wait_idle(qtbot, win)
    assert out.exists() and read(out).cells == (40, 30) and not (tmp_path / "again.vts").exists()
    assert win._status.text().startswith("Exported 1 block(s)")
    assert threads and threading.main_thread() not in threads
    assert win.io.export_mesh(tmp_path / "no" / "such" / "x.vts")  # started; it fails in the worker
    wait_idle(qtbot, win)
    assert win._status.text().startswith("Cannot export mesh") and not win.io.exporting
