"""The live frames of a solve started by Generate: paced by their cost, the history always complete.

Behaviour only (which frames are drawn, what the convergence plot ends on), never how fast.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import app.solver_controller as controller
from app.views.panels import step_ranges
from tests.app.waits import wait_for, wait_idle

pytestmark = pytest.mark.gui

LAKES = Path(__file__).resolve().parents[2] / "benchmarks" / "lakes"
ISEO = LAKES / "lake_iseo_sparse.geojson"  # one island


def _no_live_frames(win, monkeypatch) -> list:
    """Make every live frame of a Generate solve wait for ever; the list gets one entry per frame drawn."""
    monkeypatch.setattr(controller, "MAX_FRAME_GAP", 1e9)
    win.solver.frame_cost = 1e9  # as if a frame cost more than any solve: the first one never comes
    frames: list = []
    win.solver.redrawn.connect(lambda: frames.append(1))
    return frames


def test_a_lake_solve_without_live_frames_ends_on_every_level_of_its_history(qtbot, win, monkeypatch):
    """A solve shorter than its first frame's budget draws only its final grid, yet the convergence plot
    gets the progress of its last snapshot: every level is marked (the first-frame delay tried in session
    9 lost the 'full' mark with the last snapshot)."""
    frames = _no_live_frames(win, monkeypatch)
    assert win.io.import_points(ISEO, project_lonlat=True)
    win.lake_panel.cell_size.setValue(600.0)
    win.lake_panel.cell_size.editingFinished.emit()
    win.a_auto_layout.trigger()  # lays out, then Generate
    wait_for(qtbot, win, lambda: win.doc.project.layout is not None or bool(win.lake_ctl.last_error))
    assert win.lake_ctl.last_error is None
    wait_idle(qtbot, win)
    mb = win.doc.multiblock
    assert mb is not None and len(mb.grids) == len(win.doc.project.layout.blocks)
    assert frames == []  # no live frame: the final grid only
    assert [name for _k, name in win.conv_panel.levels] == ["cells ÷4", "÷2", "full"]
    x, _y = win.conv_panel.curve.getData()
    assert len(x) and x[-1] > win.conv_panel.levels[-1][0]  # the history goes on into the full level


def test_a_long_generate_solve_draws_live_frames_of_its_iterates(qtbot, win):
    """The view stays live: a solve that runs on draws frame after frame, each a newer iterate."""
    win.io.open_example("bottle-fine", confirm=False)
    win.editor.set_block_options(cells=(200, 200))
    win.editor.set_solver(method="sor", tolerance=1e-300, max_iterations=10_000_000)
    shown: list = []
    win.solver.redrawn.connect(lambda: shown.append(win.doc.grid))
    win.generate()
    wait_for(qtbot, win, lambda: len(shown) >= 3)
    assert win.solver.running
    win.solver.stop()
    wait_idle(qtbot, win)
    live = [g for g in shown[:3] if g is not None]
    assert len(live) == 3 and all(g.cells == (200, 200) for g in live)
    assert not np.array_equal(live[0].x, live[2].x)  # the iterates move between frames


def test_the_convergence_plot_ranges_change_in_steps():
    """The axes of the convergence plot are drawn again only when the history passes a step of its
    ranges: the iteration axis ends on 1, 1.5, 2, 3, 4, 5, 6, 8 × 10^k, the residual axis on decades."""
    h = np.array([[1, 0.5], [7, 3e-3], [12, 2e-4]])
    assert step_ranges(h) == ((0.0, 15.0), (-4.0, 0.0))
    assert step_ranges(h[:2]) == ((0.0, 8.0), (-3.0, 0.0))
    assert step_ranges(h, tolerance=1e-6) == ((0.0, 15.0), (-6.0, 0.0))
    assert step_ranges(np.array([[100.0, 1.0]])) == ((0.0, 100.0), (0.0, 1.0))
    assert step_ranges(np.array([[101.0, 1.0]]))[0] == (0.0, 150.0)
    assert step_ranges(np.zeros((0, 2))) is None
    assert step_ranges(np.array([[3.0, np.inf]])) is None


def test_a_new_point_within_the_ranges_does_not_draw_the_axes_again(qtbot):
    """A live frame that adds points within the shown ranges keeps the axes' ticks and labels (made again,
    with the grid lines over the whole plot, they were most of a frame's cost); a step passed makes them."""
    from app.views.panels import ConvergencePanel

    conv = ConvergencePanel()
    qtbot.addWidget(conv)
    conv.resize(400, 250)
    conv.show()
    qtbot.waitExposed(conv)
    h = [(k, 10.0 ** (-k / 10)) for k in range(1, 40)]
    axes = conv.getAxis("left"), conv.getAxis("bottom")

    def drawn():  # the axes' pictures once they were painted
        qtbot.waitUntil(lambda: all(a.picture is not None for a in axes))
        return tuple(a.picture for a in axes)

    conv.set_history(h[:11], 1e-6)  # iterations to 11: the axis ends on 15
    before = drawn()
    for _ in range(20):  # the window settled (a late resize draws the axes again)
        qtbot.wait(100)
        conv.viewport().repaint()
        now = drawn()
        if all(p is q for p, q in zip(now, before, strict=True)):
            break
        before = now
    conv.set_history(h[:14], 1e-6)
    qtbot.wait(50)
    conv.viewport().repaint()
    assert all(p is q for p, q in zip(drawn(), before, strict=True))  # the same pictures: not made again
    conv.set_history(h[:16], 1e-6)  # past 15: the iteration axis ends on 20
    qtbot.wait(50)
    assert drawn()[1] is not before[1]


def test_an_empty_convergence_plot_shows_decades(qtbot):
    """Before any solve, and after its history is cleared, the residual axis spans whole decades
    (1e-6 … 1): pyqtgraph's default, one decade, labelled its minor ticks 2 … 9 in a crowd."""
    from app.views.panels import EMPTY_RANGES, ConvergencePanel

    panel = ConvergencePanel()
    qtbot.addWidget(panel)

    def decades() -> float:
        y0, y1 = panel.viewRange()[1]
        return y1 - y0

    assert decades() >= EMPTY_RANGES[1][1] - EMPTY_RANGES[1][0] == 6.0
    panel.set_history([(1, 0.5), (2, 0.4)], 0.3)  # less than a decade: the history's own range
    assert decades() < 3.0
    panel.clear_history()
    assert decades() >= 6.0
