"""What a redraw of the canvas costs in kind: a new grid updates the same items in place, and a repaint
for something else over the grid (the ring that follows the mouse in a drag) does not draw its cells again."""

from __future__ import annotations

import numpy as np
import pyqtgraph as pg
import pytest

from meshcore import StructuredGrid

pytestmark = pytest.mark.gui


def _grid(k: int, n: int = 60) -> StructuredGrid:
    """An annular sector of ``n`` × ``n`` nodes, its rings bent by ``k`` (a grid that moves between frames)."""
    s, t = np.meshgrid(np.linspace(0, 1, n), np.linspace(0, 1, n), indexing="ij")
    r = 1.0 + t + 0.05 * k * np.sin(np.pi * s)
    a = 0.5 * np.pi * s
    return StructuredGrid(r * np.cos(a), r * np.sin(a))


@pytest.fixture
def painted(qtbot, win, monkeypatch):
    """The window with a grid on its canvas; ``painted[0]``: how often the grid's curve drew its cells."""
    c = win.canvas
    count = [0]
    paint = pg.PlotCurveItem.paint

    def counting(self, *args):
        if self is c.grid_curve:
            count[0] += 1
        return paint(self, *args)

    monkeypatch.setattr(pg.PlotCurveItem, "paint", counting)
    qtbot.waitExposed(win)
    c.set_grids({0: _grid(0)})
    c.zoom_to((0.0, 0.0, 2.2, 2.2))
    c.viewport().repaint()
    return count


def test_a_new_grid_updates_the_canvas_items_in_place(qtbot, win, painted):
    c = win.canvas
    items = list(c.scene().items())
    curve = c.grid_curve
    for k in range(1, 4):
        c.set_grids({0: _grid(k)})
        c.viewport().repaint()
    assert c.grid_curve is curve and list(c.scene().items()) == items  # no item made or dropped
    x, _y = curve.getData()
    assert np.isclose(x.max(), _grid(3).x.max())  # the last grid is what the curve holds


def test_the_drag_ring_moving_over_the_grid_does_not_draw_its_cells_again(qtbot, win, painted):
    c = win.canvas
    assert painted[0] >= 1  # the grid was drawn
    painted[0] = 0
    for f in np.linspace(0.0, 1.0, 5):
        c.lake_items.set_drag_point((1.2 + 0.3 * f, 0.6))
        c.viewport().repaint()
    assert c.lake_items.drag_point.isVisible() and len(c.lake_items.drag_point.data) == 1
    assert painted[0] == 0  # the ring moved five times over the grid: its cells were not drawn again
    c.set_grids({0: _grid(1)})
    c.viewport().repaint()
    assert painted[0] >= 1  # a new grid is drawn


def test_an_edit_that_keeps_the_crs_does_not_make_the_axes_again(qtbot, win, painted):
    c = win.canvas
    p = win.doc.project.replaced(crs="EPSG:32632", origin=(520000.0, 5090000.0))
    win.doc.set_project(p)
    c.viewport().repaint()
    bottom = c.getPlotItem().getAxis("bottom")
    assert bottom.labelText == "x = E − 520000 m (EPSG:32632)"
    picture = bottom.picture
    assert picture is not None
    win.doc.set_project(p.replaced(title="an edit"))  # as each step of a drag: a new project, the same CRS
    c.viewport().repaint()
    assert bottom.picture is picture  # its ticks and labels were not made again
    win.doc.set_project(p.replaced(origin=(0.0, 0.0)))
    assert bottom.labelText == "x = E − 0 m (EPSG:32632)"


def test_the_solver_label_ends_on_the_latest_progress_of_a_burst(qtbot, win):
    """The label is set at most a few times a second during a multiblock solve, but it never stays on an
    old snapshot: a solve that holds after a burst of frames (a drag) shows the last one."""
    from app.lake_solve import LakeProgress
    from app.pipeline import ALL_BLOCKS

    status = win.solve_status
    win.solver._set_state("running")
    try:
        for it in (1, 2, 3):
            win.solver.progress.emit(ALL_BLOCKS, LakeProgress(it, 0.1 / it, 1e-5, None, 0.0, "orthogonal", (), ()))
        qtbot.waitUntil(lambda: "iteration 3," in status.label.text(), timeout=5000)
    finally:
        win.solver._set_state("idle")
    win.solver.progress.emit(ALL_BLOCKS, LakeProgress(4, 0.01, 1e-5, None, 0.0, "orthogonal", (), ()))
    qtbot.wait(400)
    assert "iteration 4," not in status.label.text()  # not over what an idle solver shows
