"""Session 38 (branch app38): defects of a lake modeller's walk under Xvfb on held-out lakes."""

from __future__ import annotations

from pathlib import Path

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
