"""Session 39 (branch app39): what a lake modeller's walk left — the Lake panel's cell count of a cell size
set, the cut line Del deletes, Ctrl+Z in the middle of a drag."""

from __future__ import annotations

import numpy as np
import pytest

from tests.app.test_app38 import _h_layout

pytestmark = pytest.mark.gui


def _y_lake():
    """A Y junction of arms 1 km wide (a lake whose blocks are a few cells across at a coarse size)."""
    import shapely.affinity

    from app.lake import Lake
    from meshcore import testing

    poly = shapely.affinity.scale(testing.y_junction(), 1000.0, 1000.0, origin=(0, 0))
    return Lake(outline=np.asarray(poly.exterior.coords)[:-1]), poly.area


def test_the_lake_panel_gives_the_cells_of_the_layout_a_cell_size_makes(qtbot, win):
    """A cell size typed in the Lake panel over a laid-out lake: the panel said "Auto layout (Ctrl+L) makes
    them at 419.1 m (about 100 cells)" — the water's area over the cell size squared — and Auto layout
    made 256 (blocks of a few cells across: each side's count is a multiple of 4; on 50 lake/size pairs
    area ÷ h² was 0.26-1.49 × the layout's cells).  Now the layout is made in a worker when the size is set
    and the panel gives its cells and blocks; Auto layout then sets that layout at once."""
    from app.lake import compute_layout, expected_cells
    from tests.app.waits import wait_for, wait_idle

    lake, area = _y_lake()
    win.editor.set_lake(lake.replaced(layout=compute_layout(lake)), "Auto layout")
    h = float(np.sqrt(area / 100))
    want = compute_layout(lake.replaced(cell_size=h))
    rough = expected_cells(lake.replaced(cell_size=h))
    assert want.n_cells > 1.5 * rough  # what area / h² missed
    win.lake_ctl.set_cell_size(h)
    text = win.lake_panel.summary.text()
    assert f"about {rough:,} cells by area" in text and "counting" in text  # said to be rough while counted
    wait_for(qtbot, win, lambda: win.lake_ctl.layout_count(win.lake_ctl.lake()) is not None)
    n = len(want.blocks)
    assert f"makes them at {h:.4g} m: {want.n_cells:,} cells in {n} blocks" in win.lake_panel.summary.text()
    win.a_auto_layout.trigger()  # the layout counted is the one set, at once
    assert not win.lake_ctl.busy
    lay = win.doc.project.layout
    assert lay.n_cells == want.n_cells and [b.cells for b in lay.blocks] == [b.cells for b in want.blocks]
    wait_idle(qtbot, win)
    win.stack.undo()  # the layout before; a size typed before any layout is counted too
    win.editor.set_lake(lake, "Import")
    win.lake_ctl.set_cell_size(h)
    wait_for(qtbot, win, lambda: win.lake_ctl.layout_count(win.lake_ctl.lake()) is not None)
    assert f"(at {h:.4g} m: {want.n_cells:,} cells in {n} blocks)" in win.lake_panel.summary.text()


def _line(item) -> np.ndarray:
    x, y = item.xData, item.yData
    if x is None or len(x) == 0:
        return np.zeros((0, 2))
    a = np.column_stack([x, y])
    return a[np.isfinite(a).all(axis=1)]


def test_the_cut_line_del_would_delete_is_highlighted(qtbot, win):
    """Layout tool: Del deletes "the cut line pointed at", but nothing on the canvas said which one (near a
    junction: which of three, or none).  Now the cut Del would delete is drawn in a red band while the
    cursor is on it — its line, or its end ringed — none at a junction, none in a drag; the cut deleted
    is the one marked, and the mark goes with it."""
    from tests.app.waits import wait_for, wait_idle

    lay = _h_layout(win)
    tool, items = win.canvas.tool, win.canvas.lake_items
    mark = items.del_cut
    tool.hover((1400.0, 500.0 + 0.5 * tool.tol()))  # on the middle cut, between its junctions
    assert np.allclose(_line(mark), lay.cuts[2])
    assert mark.isVisible() and mark in items.editing_items()  # (left out of an exported figure)
    tool.hover((1000.0, 500.0))  # the junction: Del deletes nothing, nothing is marked
    assert len(_line(mark)) == 0
    tool.hover((1000.0 + 0.3 * tool.tol(), 0.0))  # the first cut's end on the shore, ringed
    assert np.allclose(_line(mark), lay.cuts[0])
    tool.hover((2500.0, 700.0))  # inside a block, away from every cut
    assert len(_line(mark)) == 0
    assert tool.drag("start", (1000.0, 0.0), (1000.0, 0.0))  # a drag marks nothing
    assert len(_line(mark)) == 0
    tool.hover((1000.0, 100.0))
    assert len(_line(mark)) == 0
    tool.drag("finish", (1000.0, 0.0), (1000.0, 0.0))  # back where it began
    wait_idle(qtbot, win)
    lay = win.doc.project.layout
    tool.hover((1400.0, 500.0 + 0.5 * tool.tol()))
    marked = _line(mark).copy()
    assert np.allclose(marked, lay.cuts[2])
    win.a_delete.trigger()
    assert len(_line(mark)) == 0  # the cut goes: no mark left
    wait_for(qtbot, win, lambda: win.doc.project.layout is not lay and not win.lake_ctl.editing)
    wait_idle(qtbot, win)
    new = win.doc.project.layout
    assert len(new.cuts) == len(lay.cuts) - 1
    assert not any(len(c) == len(marked) and np.allclose(c, marked) for c in new.cuts)  # the one marked went
    assert len(_line(mark)) == 0


def _ctrl_z(qtbot, win) -> None:
    from PySide6 import QtCore

    win.canvas.setFocus()
    qtbot.keyClick(win.canvas, QtCore.Qt.Key.Key_Z, QtCore.Qt.KeyboardModifier.ControlModifier)


def layout_drag_cancelled(qtbot, win, cancel):
    """A cut end of :func:`_h_layout` dragged and ``cancel(qtbot, win)`` pressed in the drag, after its step
    landed, then while its first step is being made: each time the layout it began with, nothing of it in
    the history, the rest of the drag doing nothing.  ``(tool, stack, layout, end, (count, index, undo
    text))`` (also used by ``tests/app/test_app39b.py``)."""
    from app.layout_edit import handles
    from tests.app.waits import wait_for, wait_idle

    lay0 = _h_layout(win)
    wait_idle(qtbot, win)
    tool, stack = win.canvas.tool, win.stack
    n, idx, undo_text = stack.count(), stack.index(), stack.undoText()
    end = next(h for h in handles(lay0) if h.kind == "end" and h.cut == 0)
    x, y = end.xy

    # 1. a step landed: the layout back to the drag's start, the step out of the history
    assert tool.drag("start", end.xy, end.xy)
    tool.drag("move", (x + 300.0, y), end.xy)
    wait_for(qtbot, win, lambda: win.doc.project.layout is not lay0 and not win.lake_ctl.editing)
    assert stack.count() == n + 1
    cancel(qtbot, win)
    assert win.doc.project.layout is lay0 and (stack.count(), stack.index()) == (n, idx)
    assert "Drag cancelled" in win._status.text()
    assert tool.drag("move", (x + 500.0, y), end.xy)  # the rest of the drag: used (no pan), nothing made
    assert tool.drag("finish", (x + 500.0, y), end.xy)
    wait_idle(qtbot, win)
    assert win.doc.project.layout is lay0 and (stack.count(), stack.index()) == (n, idx)
    assert stack.undoText() == undo_text and stack.redoText() == ""

    # 2. cancelled while the drag's first step is being made: Auto layout stays, the step is not set
    assert tool.drag("start", end.xy, end.xy)
    tool.drag("move", (x + 300.0, y), end.xy)
    assert win.lake_ctl.editing
    cancel(qtbot, win)
    tool.drag("move", (x + 400.0, y), end.xy)
    tool.drag("finish", (x + 400.0, y), end.xy)
    wait_idle(qtbot, win)
    assert win.doc.project.layout is lay0 and (stack.count(), stack.index()) == (n, idx)
    return tool, stack, lay0, end, (n, idx, undo_text)


def test_ctrl_z_in_the_middle_of_a_layout_drag_cancels_the_drag(qtbot, win):
    """Ctrl+Z with a cut end held: the stack undid under the drag — Auto layout itself when no step had
    landed yet, then the next step set the dragged layout over the undone one (the layout back, Redo
    gone); after a step, the drag's own step, and the next move pushed it again.  Now Ctrl+Z cancels the
    drag: the layout it began with, no step of it to undo or redo, the rest of the drag (moves, release)
    doing nothing; Ctrl+Z again undoes the step before it.  Ctrl+Y waits for the drag's end."""
    from tests.app.waits import wait_idle

    tool, stack, lay0, end, (_n, _idx, undo_text) = layout_drag_cancelled(qtbot, win, _ctrl_z)
    assert "not made" not in win._status.text()  # (the cancel said it)

    # 3. Ctrl+Y in a drag waits; Ctrl+Z after the drag undoes the step before it (the split)
    win.lake_ctl.set_cell_size(150.0)  # a step to redo (the layout stays)
    stack.undo()
    assert stack.redoText() == "Set cell size" and win.doc.project.layout is lay0
    assert tool.drag("start", end.xy, end.xy)
    win.a_redo.trigger()
    assert "waits for the end of the drag" in win._status.text() and stack.redoText() == "Set cell size"
    tool.drag("finish", end.xy, end.xy)  # back where it began: nothing made
    wait_idle(qtbot, win)
    assert win.doc.project.layout is lay0 and stack.redoText() == "Set cell size"
    _ctrl_z(qtbot, win)
    assert win.doc.project.layout is None and stack.redoText() == undo_text


def test_ctrl_z_in_the_middle_of_a_point_drag_cancels_the_drag(qtbot, win):
    """Edit tool, a point just inserted held (nothing moved yet), Ctrl+Z: the insert was undone under the
    drag and its next move set points by indices that were gone (IndexError, or the wrong points moved).
    After a move, Ctrl+Z undid the move and the next move pushed it again.  Now Ctrl+Z cancels the drag:
    the points as they were when it began, nothing of it in the history, the rest of it doing nothing."""
    win.set_tool("draw")
    for xy in ((0.0, 0.0), (10.0, 0.0), (10.0, 6.0), (0.0, 6.0)):
        win.canvas.tool.click(xy)
    win.canvas.tool.double_click((0.0, 6.0))
    win.set_tool("edit")
    tool, stack = win.canvas.tool, win.stack
    tool.click((5.0, 0.0))  # a point inserted on the bottom side
    assert stack.undoText() == "Insert point"
    before, n, idx = win.doc.project, stack.count(), stack.index()

    assert tool.drag("start", (5.0, 0.0), (5.0, 0.0))  # held, not moved yet
    _ctrl_z(qtbot, win)
    assert win.doc.project is before and (stack.count(), stack.index()) == (n, idx)
    assert tool.drag("move", (5.0, -2.0), (5.0, 0.0))
    assert tool.drag("finish", (5.0, -2.0), (5.0, 0.0))
    assert win.doc.project is before and (stack.count(), stack.index()) == (n, idx)

    assert tool.drag("start", (5.0, 0.0), (5.0, 0.0))  # moved, then Ctrl+Z
    tool.drag("move", (5.0, -1.0), (5.0, 0.0))
    assert stack.count() == n + 1 and not np.array_equal(win.doc.block.points, before.blocks[0].points)
    _ctrl_z(qtbot, win)
    assert win.doc.project is before and (stack.count(), stack.index()) == (n, idx)
    assert stack.redoText() == ""  # no redo of half a drag
    tool.drag("move", (5.0, -3.0), (5.0, 0.0))
    tool.drag("finish", (5.0, -3.0), (5.0, 0.0))
    assert win.doc.project is before and stack.undoText() == "Insert point"
    _ctrl_z(qtbot, win)  # no drag: the insert is undone
    assert len(win.doc.block.points) == 4 and stack.redoText() == "Insert point"


def test_auto_layout_takes_over_the_count_still_being_made(qtbot, win, monkeypatch):
    """Ctrl+L while the Lake panel's count of the size just set is being made: that layout becomes Auto
    layout's (busy, its seconds counted, set when made) — it is not made twice."""
    import threading

    from app import lake_controller
    from tests.app.waits import wait_for, wait_idle

    lake, area = _y_lake()
    made, hold = [], threading.Event()
    job = lake_controller._layout_job

    def held_job(*args):
        made.append(args)
        hold.wait(60)
        return job(*args)

    monkeypatch.setattr(lake_controller, "_layout_job", held_job)
    win.editor.set_lake(lake, "Import")
    win.lake_ctl.set_cell_size(float(np.sqrt(area / 100)))
    assert win.lake_ctl.counting(win.lake_ctl.lake())
    wait_for(qtbot, win, lambda: len(made) == 1)  # the count is being made
    assert win.lake_ctl.auto_layout()
    assert win.lake_ctl.busy and "Computing the block layout" in win._status.text()
    hold.set()
    wait_for(qtbot, win, lambda: win.doc.project.layout is not None)
    wait_idle(qtbot, win)
    assert len(made) == 1 and win.stack.undoText() == "Auto layout"
    assert not win.lake_ctl.busy and "256 cells" in win.lake_panel.summary.text()


def test_a_layout_drag_undone_from_the_history_stops(qtbot, win):
    """An undo that is not Ctrl+Z (the Undo history dock) in a drag of the layout: the drag's next steps,
    made from the layout it began with, would set it again over the undo; the drag stops instead."""
    from app.layout_edit import handles
    from tests.app.waits import wait_for, wait_idle

    lay0 = _h_layout(win)
    wait_idle(qtbot, win)
    tool, stack = win.canvas.tool, win.stack
    n = stack.count()
    end = next(h for h in handles(lay0) if h.kind == "end" and h.cut == 0)
    x, y = end.xy
    assert tool.drag("start", end.xy, end.xy)
    tool.drag("move", (x + 300.0, y), end.xy)
    wait_for(qtbot, win, lambda: win.doc.project.layout is not lay0 and not win.lake_ctl.editing)
    stack.undo()  # the history dock's undo: the drag's step
    assert win.doc.project.layout is lay0
    assert tool.drag("move", (x + 500.0, y), end.xy)
    assert "drag stops here" in win._status.text()
    assert tool.drag("finish", (x + 500.0, y), end.xy)
    wait_idle(qtbot, win)
    assert win.doc.project.layout is lay0 and stack.count() == n + 1 and stack.redoText().startswith("Move cut end")


def test_two_ctrl_z_in_a_drag_leave_auto_layout_undone(qtbot, win):
    """An imported lake laid out, a cut end dragged, Ctrl+Z twice with the button still down: the first
    undid the drag's step, the second Auto layout; the next move set the dragged layout again over the
    lake without one, and "Auto layout" was gone from the history (Import, Move cut end).  Now the first
    cancels the drag, the second undoes Auto layout, and the rest of the drag does nothing."""
    from app.lake import compute_layout
    from app.layout_edit import handles
    from tests.app.test_app33 import _small_lake
    from tests.app.waits import wait_for, wait_idle

    lake = _small_lake()
    win.editor.set_lake(lake, "Import lake.geojson")
    lay0 = compute_layout(lake)
    win.editor.set_lake(lake.replaced(layout=lay0), "Auto layout")
    win.set_tool("layout")
    wait_idle(qtbot, win)
    tool, stack = win.canvas.tool, win.stack
    end = next(h for h in handles(lay0) if h.kind == "end")
    (x, y), h = end.xy, lay0.cell_size
    assert tool.drag("start", end.xy, end.xy)
    tool.drag("move", (x + h, y + h), end.xy)
    wait_for(qtbot, win, lambda: win.doc.project.layout is not lay0 and not win.lake_ctl.editing)
    _ctrl_z(qtbot, win)
    _ctrl_z(qtbot, win)
    tool.drag("move", (x + 1.5 * h, y + 1.5 * h), end.xy)
    tool.drag("finish", (x + 1.5 * h, y + 1.5 * h), end.xy)
    wait_idle(qtbot, win)
    assert win.doc.project.layout is None and win.doc.project.lake is not None
    assert (stack.count(), stack.index()) == (2, 1) and stack.redoText() == "Auto layout"
    win.a_redo.trigger()
    assert win.doc.project.layout is lay0
