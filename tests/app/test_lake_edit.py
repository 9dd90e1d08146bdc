"""Editing a lake layout in the app: drag cut ends and corners, set a block's cells; the grid follows."""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import pytest
import shapely

from app import io_controller
from tests.app.waits import drag_a_cut_end, wait_for, wait_idle

pytestmark = pytest.mark.gui

LAKES = Path(__file__).resolve().parents[2] / "benchmarks" / "lakes"
ISEO = LAKES / "lake_iseo_sparse.geojson"


@pytest.fixture
def laid(qtbot, win):
    """Iseo laid out at 300 m and gridded, the Layout tool active, auto-generate on."""
    assert win.io.import_points(ISEO, project_lonlat=True)
    win.lake_ctl.set_cell_size(300.0)
    win.a_auto_layout.trigger()
    wait_for(qtbot, win, lambda: win.doc.project.layout is not None)
    wait_idle(qtbot, win)
    assert win.canvas.tool is win.tools["layout"]  # Auto layout leads on to editing it
    win.a_auto.trigger()
    assert win.solver.auto
    return win


def _is_start(grid, algebraic) -> bool:
    return algebraic is not None and grid.shape == algebraic.shape and np.array_equal(grid.x, algebraic.x)


def test_drag_a_cut_end_along_the_shore_and_the_grid_follows(qtbot, laid):
    from app.layout_edit import handles

    win = laid
    lay0 = win.doc.project.layout
    grids0 = dict(win.doc.grids)
    shown_start = []
    win.solver.redrawn.connect(
        lambda: shown_start.extend(k for k, g in win.doc.grids.items() if _is_start(g, win.doc.initial.get(k)))
    )
    end = next(h for h in handles(lay0) if h.kind == "end")
    tool = win.canvas.tool
    n = win.stack.count()
    h = lay0.cell_size
    path = [np.add(end.xy, (f * h, f * h)) for f in np.linspace(0, 1.5, 6)]
    assert tool.drag("start", tuple(path[0]), end.xy)
    assert win.solver.live  # while the hand drags, a solve stops after its live frames
    for p in path[1:]:
        tool.drag("move", tuple(p), end.xy)
        qtbot.wait(30)
    tool.drag("finish", tuple(path[-1]), end.xy)
    wait_idle(qtbot, win)
    assert not win.solver.live
    lay1 = win.doc.project.layout
    assert lay1 is not lay0 and win.lake_ctl.edit_error is None
    assert win.stack.count() == n + 1 and win.stack.undoText().startswith("Move cut end")  # one undo step
    assert [b.cells for b in lay1.blocks] == [b.cells for b in lay0.blocks]  # cells kept
    ends0 = {tuple(np.round(c[k], 6)) for c in lay0.cuts for k in (0, -1)}
    ends1 = {tuple(np.round(c[k], 6)) for c in lay1.cuts for k in (0, -1)}
    moved = ends1 - ends0
    assert len(moved) == 1
    q = np.array(next(iter(moved)))
    assert lay1.polygon.boundary.distance(shapely.Point(q)) < 1e-6 * h  # on the shore
    # the grid re-solved from the previous one: same shapes, new nodes, never the start grid on screen
    assert sorted(win.doc.grids) == sorted(grids0)
    assert all(win.doc.grids[k].shape == g.shape for k, g in grids0.items())
    assert any(not np.array_equal(win.doc.grids[k].x, g.x) for k, g in grids0.items())
    assert shown_start == []
    assert win.doc.lake_metrics is not None and win.doc.lake_metrics.summary()["folded_cells"] == 0
    # the final grid of the edit is the one meshcore makes of the new layout (coarse to fine), not
    # the warm start's: the same grid as `meshcore generate` of the saved layout, loaded fresh
    from meshcore.case import case_layout, dumps_case, layout_case, loads_case
    from meshcore.lakegrid import mesh_layout

    fresh = case_layout(loads_case(dumps_case(layout_case(lay1))))
    for a, b in zip(lay1.topology().blocks, fresh.topology().blocks, strict=True):
        assert a.name == b.name
        for side in ("bottom", "right", "top", "left"):
            np.testing.assert_array_equal(getattr(a.borders, side), getattr(b.borders, side))
    ref = mesh_layout(lay1)
    for k, g in enumerate(ref.grids):
        np.testing.assert_array_equal(win.doc.grids[k].x, g.x)
        np.testing.assert_array_equal(win.doc.grids[k].y, g.y)
    # (to rounding: the case's shore ring starts at another vertex, the sliding shore nodes see it)
    for g, f in zip(ref.grids, mesh_layout(fresh).grids, strict=True):
        np.testing.assert_allclose(f.x, g.x, rtol=1e-12, atol=1e-9 * h)
        np.testing.assert_allclose(f.y, g.y, rtol=1e-12, atol=1e-9 * h)
    assert [lv for _k, lv in win.conv_panel.levels] == ["warm start", "cells ÷4", "÷2", "full"]
    win.stack.undo()
    assert win.doc.project.layout is lay0


def test_set_one_blocks_cells_and_its_neighbours_follow(qtbot, laid):
    win = laid
    lay0 = win.doc.project.layout
    win.lake_panel.table.item(0, 0).setSelected(True)
    win.doc.set_active(0)
    b0 = lay0.blocks[0]
    m = lay0.multiple
    assert win.lake_panel.ni.value() == b0.cells[0] and win.lake_panel.ni.singleStep() == m
    win.lake_panel.ni.setValue(b0.cells[0] + 2 * m)
    win.lake_panel.set_cells.click()
    wait_idle(qtbot, win)
    lay1 = win.doc.project.layout
    assert lay1.blocks[0].cells == (b0.cells[0] + 2 * m, b0.cells[1])
    assert win.stack.undoText().startswith(f"Cells of {b0.name}")
    # the grid was made again with the new counts (auto-generate), every block as its layout says
    assert [win.doc.grids[k].cells for k in range(len(lay1.blocks))] == [tuple(b.cells) for b in lay1.blocks]
    assert win.lake_panel.table.item(0, 1).text() == f"{b0.cells[0] + 2 * m} × {b0.cells[1]}"


def test_enter_in_a_blocks_cells_sets_them_and_the_keyboard_goes_back_to_the_canvas(qtbot, laid):
    """Typing a count in the Lake panel and pressing Enter sets it (issue 13: Enter did nothing, the
    count was lost unless Set was clicked, and the tool keys went on into the spin box)."""
    from PySide6 import QtCore, QtWidgets

    win = laid
    lay0 = win.doc.project.layout
    win.doc.set_active(0)
    b0, m = lay0.blocks[0], lay0.multiple
    box = win.lake_panel.nj
    box.setFocus()
    box.selectAll()
    qtbot.keyClicks(box, str(b0.cells[1] + m))
    qtbot.keyClick(box, QtCore.Qt.Key.Key_Return)
    wait_for(qtbot, win, lambda: win.doc.project.layout is not lay0 or bool(win.lake_ctl.edit_error))
    wait_idle(qtbot, win)
    assert win.lake_ctl.edit_error is None
    assert win.doc.project.layout.blocks[0].cells == (b0.cells[0], b0.cells[1] + m)
    assert QtWidgets.QApplication.focusWidget() is win.canvas
    qtbot.keyClick(win.canvas, QtCore.Qt.Key.Key_E)  # a tool key reaches the canvas, not the box
    assert win.canvas.tool is win.tools["edit"]


def test_an_impossible_layout_is_a_message_and_nothing_changes(qtbot, laid):
    from app.layout_edit import handles

    win = laid
    lay0 = win.doc.project.layout
    inner = next(h for h in handles(lay0) if h.kind == "cut")
    x0, y0, x1, y1 = lay0.polygon.bounds
    outside = (x1 + (x1 - x0), y1 + (y1 - y0))  # a cut point dragged far out of the water
    tool = win.canvas.tool
    assert tool.drag("start", inner.xy, inner.xy)
    tool.drag("finish", outside, inner.xy)
    wait_idle(qtbot, win)
    assert win.doc.project.layout is lay0
    assert win.lake_ctl.edit_error and "Cannot change the layout" in win._status.text()
    assert win.docks["messages"].isVisible()


def test_a_drag_ending_where_it_began_gives_the_layout_back(qtbot, laid):
    """Out and back to the very point it started from: the layout before the drag, not the last step's."""
    from app.layout_edit import handles

    win = laid
    lay0 = win.doc.project.layout
    end = next(h for h in handles(lay0) if h.kind == "end")
    h = lay0.cell_size
    tool = win.canvas.tool
    assert tool.drag("start", end.xy, end.xy)
    for f in (0.5, 1.0, 0.5):
        tool.drag("move", (end.xy[0] + f * h, end.xy[1] + f * h), end.xy)
        qtbot.wait(30)
    tool.drag("finish", end.xy, end.xy)
    wait_idle(qtbot, win)
    assert win.doc.project.layout is lay0 and win.lake_ctl.edit_error is None


def test_a_drag_refused_at_its_end_keeps_its_last_good_layout_as_a_case_gives_it(qtbot, laid, monkeypatch):
    """Steps that kept the chains' cells, then a refused end: the last good step stays, made fresh
    (the program's cells), with the refusal in a message."""
    from app.layout_edit import handles
    from meshcore.case import case_layout, dumps_case, layout_case, loads_case

    win = laid
    lay0 = win.doc.project.layout
    end = next(h for h in handles(lay0) if h.kind == "end")
    h = lay0.cell_size
    x0, _y0, x1, y1 = lay0.polygon.bounds
    tool = win.canvas.tool
    assert tool.drag("start", end.xy, end.xy)
    for f in (0.3, 0.6):
        tool.drag("move", (end.xy[0] + f * h, end.xy[1] + f * h), end.xy)
        wait_for(qtbot, win, lambda: not win.lake_ctl.editing)
    assert tool._steps.kept  # the second step kept the first one's cells
    monkeypatch.setattr("app.layout_edit.place", lambda *a, **k: (x1 + (x1 - x0), y1))  # then far off the shore
    tool.drag("finish", (x1 + (x1 - x0), y1), end.xy)
    wait_idle(qtbot, win)
    lay1 = win.doc.project.layout
    assert lay1 is not lay0 and "from the shore" in win.lake_ctl.edit_error and win.docks["messages"].isVisible()
    fresh = case_layout(loads_case(dumps_case(layout_case(lay1))))
    for a, b in zip(lay1.topology().blocks, fresh.topology().blocks, strict=True):
        np.testing.assert_array_equal(a.borders.bottom, b.borders.bottom)
        np.testing.assert_array_equal(a.borders.left, b.borders.left)


def test_drag_a_block_corner_to_another_vertex_of_its_block(qtbot, laid):
    from app.layout_edit import handles

    win = laid
    lay0 = win.doc.project.layout
    corner = next(h for h in handles(lay0) if h.kind == "corner")
    b = lay0.blocks[corner.block]
    h = lay0.cell_size
    target = (corner.xy[0] + 2 * h, corner.xy[1] + 2 * h)
    tool = win.canvas.tool
    assert tool.drag("start", corner.xy, corner.xy)
    tool.drag("finish", target, corner.xy)
    wait_idle(qtbot, win)
    lay1 = win.doc.project.layout
    assert win.lake_ctl.edit_error is None, win.lake_ctl.edit_error
    assert lay1 is not lay0 and win.stack.undoText().startswith("Move block corner")
    new = next(x for x in lay1.blocks if x.name == b.name).corners
    assert corner.xy not in new  # the corner left its place …
    ring = shapely.LinearRing(lay0.pieces[corner.block].ring)
    moved = [p for p in new if p not in b.corners]
    assert moved and all(ring.distance(shapely.Point(p)) < 1e-6 * h for p in moved)  # … along its block
    assert [x.cells for x in lay1.blocks] == [x.cells for x in lay0.blocks]


def test_drag_a_shore_point_and_the_layout_and_grid_follow(qtbot, laid):
    from app.layout_edit import handles

    win = laid
    lay0 = win.doc.project.layout
    outline0 = win.doc.project.lake.outline.copy()
    grids0 = dict(win.doc.grids)
    h = lay0.cell_size
    shore = [x for x in handles(lay0) if x.kind == "shore"]
    assert shore  # the shore's own points can be taken
    # one well inside a block's shore: pushed out of the water by half a cell (the lake grows)
    far = max(shore, key=lambda x: min(np.hypot(*np.subtract(x.xy, c[k])) for c in lay0.cuts for k in (0, -1)))
    c = np.asarray(lay0.polygon.centroid.coords[0])
    out = np.asarray(far.xy) + 0.5 * h * (np.asarray(far.xy) - c) / np.hypot(*(np.asarray(far.xy) - c))
    tool = win.canvas.tool
    tool.hover(far.xy)  # the handle a drag would take is ringed
    assert win.canvas.lake_items.drag_point.data["x"].tolist() == [far.xy[0]]
    n = win.stack.count()
    assert tool.drag("start", far.xy, far.xy)
    tool.drag("finish", tuple(out), far.xy)
    wait_idle(qtbot, win)
    lay1 = win.doc.project.layout
    assert win.lake_ctl.edit_error is None, win.lake_ctl.edit_error
    assert win.stack.count() == n + 1 and win.stack.undoText() == "Move shore point"
    assert lay1.polygon.area > lay0.polygon.area
    assert lay1.polygon.boundary.distance(shapely.Point(out)) < 1e-6 * h  # the point is where it was dropped
    assert [(b.name, b.cells) for b in lay1.blocks] == [(b.name, b.cells) for b in lay0.blocks]
    # the lake's shore is the layout's: Clear layout keeps the edit
    assert any(np.allclose(p, out) for p in win.doc.project.lake.outline)
    # the grid re-solved from the previous one (same shapes, new nodes), measured on the new shore
    assert all(win.doc.grids[k].shape == g.shape for k, g in grids0.items())
    assert any(not np.array_equal(win.doc.grids[k].x, g.x) for k, g in grids0.items())
    assert win.solver.last_result.metrics is win.doc.lake_metrics
    assert win.doc.lake_metrics.summary()["folded_cells"] == 0
    win.stack.undo()
    assert win.doc.project.layout is lay0 and np.array_equal(win.doc.project.lake.outline, outline0)


def test_cells_of_a_block_after_a_drag_keep_the_layout_consistent(qtbot, laid):
    from app.layout_edit import handles

    win = laid
    lay0 = win.doc.project.layout
    inner = next(x for x in handles(lay0) if x.kind == "cut")
    tool = win.canvas.tool
    assert tool.drag("start", inner.xy, inner.xy)
    tool.drag("finish", (inner.xy[0] + 0.3 * lay0.cell_size, inner.xy[1]), inner.xy)
    wait_idle(qtbot, win)
    lay1 = win.doc.project.layout
    assert lay1 is not lay0 and win.lake_ctl.edit_error is None
    m = lay1.multiple
    for k, b in enumerate(lay1.blocks):  # every block: its cells set, the neighbours follow
        win.lake_ctl.set_block_cells(k, (b.cells[0] + m, b.cells[1]))
        wait_idle(qtbot, win)
        assert win.lake_ctl.edit_error is None, win.lake_ctl.edit_error
        lay = win.doc.project.layout
        assert lay.blocks[k].cells == (b.cells[0] + m, b.cells[1])
        lay.topology()
        win.stack.undo()
        wait_idle(qtbot, win)
        assert win.doc.project.layout is lay1


def test_the_autosave_waits_for_the_end_of_a_drag(qtbot, laid, monkeypatch):
    from app import recovery
    from app.layout_edit import handles

    win = laid
    writes = []
    monkeypatch.setattr(recovery, "write", lambda *a, **k: writes.append(time.monotonic()))
    lay0 = win.doc.project.layout
    end = next(x for x in handles(lay0) if x.kind == "end")
    tool = win.canvas.tool
    h = lay0.cell_size
    assert tool.drag("start", end.xy, end.xy)
    t_end = time.monotonic() + 1.5 * io_controller.MAX_DELAY_S  # longer than the autosave's longest wait
    k = 0
    while time.monotonic() < t_end:
        k += 1
        tool.drag("move", (end.xy[0] + 0.1 * h * (k % 5), end.xy[1]), end.xy)
        qtbot.wait(50)
    assert writes == []  # nothing written while the drag lasts
    tool.drag("finish", (end.xy[0] + 0.2 * h, end.xy[1]), end.xy)
    wait_idle(qtbot, win)
    wait_for(qtbot, win, lambda: len(writes) == 1)


def test_what_would_slow_a_drags_redraws_is_off_the_canvas(qtbot, laid):
    win = laid
    c = win.canvas
    # the coordinate grid behind the canvas is off under a grid (its axes repaint with every frame)
    assert win.doc.grids and c.getPlotItem().getAxis("left").grid is False
    assert c.selected_item.boundingRect().isEmpty()  # an empty scatter takes no part in a repaint
    x_loops = c.loop_curve.getData()[0]
    assert x_loops is None or len(x_loops) == 0  # no dashed copy of the blocks' loops (shore and cuts)
    # the places missing a preset belong to the last grid: hidden while a new one is made
    misses = c.lake_items.misses
    grids, initial, mb = dict(win.doc.grids), dict(win.doc.initial), win.doc.multiblock
    win.doc.set_solving(True)
    assert not misses.isVisible()
    win.doc.set_solving(False)
    win.doc.set_grids(grids, initial, multiblock=mb)  # as the solver ends
    assert misses.isVisible()
    win.doc.clear_grids()
    assert c.getPlotItem().getAxis("left").grid  # back behind an outline


def _y_lake_csv(path: Path) -> Path:
    """A Y-shaped lake (three 6-km arms, 1 km wide, meeting at the origin) as an x,y CSV in metres."""
    from shapely import affinity

    from meshcore.testing import y_junction

    poly = affinity.scale(y_junction(6.0, 1.0), 1000.0, 1000.0, origin=(0.0, 0.0))
    ring = np.asarray(poly.exterior.coords)[:-1]
    path.write_text("x,y\n" + "\n".join(f"{x:.3f},{y:.3f}" for x, y in ring) + "\n")
    return path


# cut lines clicked roughly by hand on the Y lake (metres): a T (the second cut ends on the first)
# and three cuts meeting at the junction (the three-cut case of the issue)
HAND_CUTS = {
    "T": [[(-520.0, 290.0), (520.0, 290.0)], [(10.0, -600.0), (0.0, 0.0), (20.0, 270.0)]],
    "meeting at a point": [[(0.0, 0.0), (-510.0, 300.0)], [(0.0, 0.0), (0.0, -600.0)], [(0.0, 0.0), (510.0, 280.0)]],
}


@pytest.mark.parametrize("kind", sorted(HAND_CUTS))
def test_cut_lines_drawn_by_hand_in_any_topology_split_a_lake(qtbot, win, tmp_path, kind):
    """Item 1 of the issue: a branched lake split by hand. Cuts drawn with the Cut line tool that
    end on another cut (T) or meet at a point give blocks (Block ▸ Split, Ctrl+K) whose cells
    agree across every cut, an orthogonal grid without folds, and one undo step back to the cuts."""
    from PySide6 import QtCore

    assert win.io.import_points(_y_lake_csv(tmp_path / "y.csv"))
    assert win.doc.project.lake is not None and win.doc.project.crs == ""
    win.lake_ctl.set_cell_size(100.0)
    win.set_tool("cut")
    tool = win.canvas.tool
    for cut in HAND_CUTS[kind]:
        for xy in cut:
            tool.click(xy)
        tool.key(QtCore.Qt.Key.Key_Return)
    before = win.doc.project
    assert len(before.cut_lines) == len(HAND_CUTS[kind])
    win.a_split.trigger()
    wait_for(qtbot, win, lambda: win.doc.project.layout is not None or bool(win.lake_ctl.last_error))
    assert win.lake_ctl.last_error is None
    wait_idle(qtbot, win)
    p = win.doc.project
    lay = p.layout
    assert len(lay.blocks) == 3 and p.cut_lines == ()  # the drawn lines are the layout's cuts now
    topo = lay.topology()  # every interface's cells agree (raises otherwise)
    assert len(topo.interfaces) >= 2
    # one cut end inside the water: the T's foot, on the first cut; or the junction, where three cuts end
    ends = np.round([c[k] for c in lay.cuts for k in (0, -1)], 6)
    nodes, counts = np.unique(
        [e for e in ends if lay.polygon.boundary.distance(shapely.Point(e)) > 100.0], axis=0, return_counts=True
    )
    assert len(nodes) == 1
    if kind == "T":
        on = [c for c in lay.cuts if shapely.LineString(c).distance(shapely.Point(nodes[0])) < 1e-6]
        assert counts.tolist() == [1] and len(on) == 2 and abs(nodes[0][1] - 290.0) < 25.0
    else:
        assert counts.tolist() == [3] and np.hypot(*nodes[0]) < 25.0
    assert [win.doc.grids[k].cells for k in range(3)] == [tuple(b.cells) for b in lay.blocks]
    assert win.doc.lake_metrics is not None and win.doc.lake_metrics.summary()["folded_cells"] == 0
    assert win.stack.undoText() == "Split into 3 blocks by cut lines"
    win.stack.undo()
    assert win.doc.project.layout is None and len(win.doc.project.cut_lines) == len(HAND_CUTS[kind])


def test_with_auto_generate_off_a_drag_greys_the_grid_of_before_until_f5(qtbot, win):
    """Auto-generate is off by default: a dragged cut end moves the layout, not the grid. The grid
    on screen (and its verdict) was shown as current, its block borders off the new cut lines."""

    assert win.io.import_points(ISEO, project_lonlat=True)
    win.lake_ctl.set_cell_size(300.0)
    win.a_auto_layout.trigger()
    wait_for(qtbot, win, lambda: win.doc.project.layout is not None)
    wait_idle(qtbot, win)
    assert not win.solver.auto
    pen = lambda: win.canvas.grid_curve.opts["pen"].color().name()  # noqa: E731
    assert pen() == "#303030" and "before" not in win.lake_quality.headline.text()
    grids0 = dict(win.doc.grids)
    drag_a_cut_end(qtbot, win, reach=1.5)
    assert all(win.doc.grids[k] is g for k, g in grids0.items())  # no solve: the grid of before
    assert pen() == "#b0b0b0"
    assert "before the last edit" in win.lake_quality.headline.text()
    assert "F5" in win.solve_status.label.text()
    win.generate()
    wait_idle(qtbot, win)
    assert any(not np.array_equal(win.doc.grids[k].x, g.x) for k, g in grids0.items())
    assert pen() == "#303030" and "before" not in win.lake_quality.headline.text()
