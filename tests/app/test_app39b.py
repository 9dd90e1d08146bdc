"""Session 39 (branch app39b): what the app39 walk left — Esc in a drag cancels it as Ctrl+Z does, the
cancel is said where it stays readable, a stale count of the Lake panel stops, and the caches a count shares
with another layout's work are safe from two threads."""

from __future__ import annotations

import numpy as np
import pytest

from tests.app.test_app38 import _h_layout
from tests.app.test_app39 import _y_lake, layout_drag_cancelled

pytestmark = pytest.mark.gui


def _esc(qtbot, win) -> None:
    from PySide6 import QtCore

    win.canvas.setFocus()
    qtbot.keyClick(win.canvas, QtCore.Qt.Key.Key_Escape)


def test_esc_in_the_middle_of_a_layout_drag_cancels_the_drag(qtbot, win, monkeypatch):
    """Esc with a cut end held did nothing (only Ctrl+Z cancelled; Esc is Generate ▸ Stop, disabled without
    a solve, and the Layout tool had no use for it): the drag went on.  Now Esc cancels it as Ctrl+Z does —
    the layout it began with, nothing of it in the history, the rest of the drag doing nothing — with or
    without a solve running (Stop, which owns Esc, cancels the drag first)."""
    from tests.app.waits import wait_idle

    assert not win.a_stop.isEnabled()  # no solve: the key reaches the window (Stop, which owns Esc, is off)
    tool, stack, lay0, end, (n, idx, _undo) = layout_drag_cancelled(qtbot, win, _esc)
    assert "Drag cancelled (Esc)" in win._status.text()
    x, y = end.xy

    # 3. Stop enabled (a solve running), Esc in a drag: the drag is cancelled, not the solve stopped
    win.a_stop.setEnabled(True)  # (as while a grid is solved: the action then takes Esc)
    stopped = []
    monkeypatch.setattr(win.solver, "stop", lambda: stopped.append(True))
    assert tool.drag("start", end.xy, end.xy)
    tool.drag("move", (x + 300.0, y), end.xy)
    _esc(qtbot, win)
    assert not stopped and not tool.in_drag
    tool.drag("finish", (x + 300.0, y), end.xy)
    wait_idle(qtbot, win)
    assert win.doc.project.layout is lay0 and (stack.count(), stack.index()) == (n, idx)
    _esc(qtbot, win)  # no drag: Esc stops the solver as before
    assert stopped == [True]
    win.a_stop.setEnabled(False)


def test_esc_in_the_middle_of_a_point_drag_cancels_it_and_outside_a_drag_does_what_it_did(qtbot, win):
    """Edit tool: Esc with a point held cancels the drag (the points as they were, nothing in the history);
    Esc in the Cut line tool still clears the line being drawn."""
    from tests.app.test_appwalk import _draw

    _draw(win, [(0.0, 0.0), (10.0, 0.0), (10.0, 6.0), (0.0, 6.0)])
    win.set_tool("edit")
    tool, stack = win.canvas.tool, win.stack
    before, n, idx = win.doc.project, stack.count(), stack.index()
    assert tool.drag("start", (10.0, 0.0), (10.0, 0.0))
    tool.drag("move", (12.0, -1.0), (10.0, 0.0))
    assert stack.count() == n + 1
    _esc(qtbot, win)
    assert win.doc.project is before and (stack.count(), stack.index()) == (n, idx) and stack.redoText() == ""
    tool.drag("move", (13.0, -2.0), (10.0, 0.0))
    tool.drag("finish", (13.0, -2.0), (10.0, 0.0))
    assert win.doc.project is before and (stack.count(), stack.index()) == (n, idx)

    win.set_tool("cut")  # no drag: the tool's own Esc (the line drawn so far cleared)
    cut = win.canvas.tool
    cut.click((1.0, 1.0))
    cut.click((5.0, 5.0))
    _esc(qtbot, win)
    assert cut.points == [] and "Drag cancelled" not in win._status.text()


def test_a_cancelled_drag_is_said_in_the_messages_and_stays_ahead_of_the_grid_line(qtbot, win):
    """ "Drag cancelled" was in the status line only, and the grid of before the drag, solved again a moment
    later, wrote its line over it.  Now it is in the Messages and leads the grid's line that follows; a
    message of something else, or a step done (a new drag's), ends it."""
    from app.layout_edit import handles
    from tests.app.waits import wait_for, wait_idle

    lay0 = _h_layout(win)
    wait_idle(qtbot, win)
    tool = win.canvas.tool
    end = next(h for h in handles(lay0) if h.kind == "end" and h.cut == 0)
    x, y = end.xy
    assert tool.drag("start", end.xy, end.xy)
    tool.drag("move", (x + 300.0, y), end.xy)
    wait_for(qtbot, win, lambda: win.doc.project.layout is not lay0 and not win.lake_ctl.editing)
    _esc(qtbot, win)
    tool.drag("finish", (x + 300.0, y), end.xy)
    assert any("Drag cancelled (Esc)" in text for _level, text in win.messages_panel.messages())
    win.generate()  # the grid of the layout of before, with its line
    wait_for(qtbot, win, lambda: "Lake grid" in win._status.text())
    wait_idle(qtbot, win)
    text = win._status.text()
    assert text.startswith("Drag cancelled (Esc): back to before it — ") and "Lake grid:" in text
    win.message("Saved")  # anything else said: the note goes
    win.solve_status.on_final()
    assert win._status.text().startswith("Lake grid:")
    win.message("Drag cancelled (Esc): back to before it", note=True)
    win.lake_ctl.set_cell_size(150.0)  # a step done (a new drag's): the grid line that follows is its own
    win.message("Lake grid: 3 blocks", summary=True)
    assert win._status.text() == "Lake grid: 3 blocks"


def test_a_count_of_a_cell_size_no_longer_wanted_stops(qtbot, win, monkeypatch):
    """A cell size typed, its layout being counted, another size typed: the count of the first ran to its end
    (3.8 s of a core on Shasta Lake at 26 m after two more sizes; the count wanted waited for it).  Now it
    stops at its next coarse reading (a reading under way, at its next sweep): no layout of it is made, no
    reading after that one, and the size wanted is counted when it has stopped."""
    import threading

    import app.lake_controller as lc
    from app.lake import compute_layout
    from meshcore.lakegrid import CoarseReadings
    from tests.app.waits import wait_for

    entered, gate, read = threading.Event(), threading.Event(), []
    real_reading, real_job = CoarseReadings.__call__, lc._layout_job

    def gated(self, layout):  # the first reading waits for the test: the size changes while it is made
        read.append(layout.cell_size)
        entered.set()
        gate.wait(60)
        return real_reading(self, layout)

    ended = []

    def job(*args):
        value = real_job(*args)
        ended.append(value)
        return value

    monkeypatch.setattr(CoarseReadings, "__call__", gated)
    monkeypatch.setattr(lc, "_layout_job", job)
    lake, area = _y_lake()
    win.editor.set_lake(lake, "Import")
    h1, h2 = float(np.sqrt(area / 100)), float(np.sqrt(area / 150))
    win.lake_ctl.set_cell_size(h1)
    wait_for(qtbot, win, entered.is_set)
    win.lake_ctl.set_cell_size(h2)
    assert win.lake_ctl.counting(win.lake_ctl.lake())
    wait_for(qtbot, win, lambda: not win.lake_ctl._count_timer.isActive())  # its count waits for the stop
    win.lake_panel.refresh()
    assert win.lake_ctl.counting(win.lake_ctl.lake()) and "counting" in win.lake_panel.summary.text()
    gate.set()
    wait_for(qtbot, win, lambda: win.lake_ctl.layout_count(win.lake_ctl.lake()) is not None)
    assert ended[0] is None and read.count(h1) == 1  # stopped after the reading under way: nothing more of h1
    want = compute_layout(lake.replaced(cell_size=h2))
    assert win.lake_ctl.layout_count(win.lake_ctl.lake()) == (want.n_cells, len(want.blocks))
    assert f"{want.n_cells:,} cells in {len(want.blocks)} blocks" in win.lake_panel.summary.text()


def held_layout(monkeypatch):
    """A layout's worker (the count's, Auto layout's) held at each coarse reading until ``gate`` is set:
    ``(entered, gate, read, ended, done)`` — ``read`` gets the cell size of each reading, ``ended`` the worker's
    return value, then ``done`` is set."""
    import threading

    import app.lake_controller as lc
    from meshcore.lakegrid import CoarseReadings

    entered, gate, read = threading.Event(), threading.Event(), []
    real_reading, real_job = CoarseReadings.__call__, lc._layout_job

    def gated(self, layout):
        read.append(layout.cell_size)
        entered.set()
        gate.wait(60)
        return real_reading(self, layout)

    ended, done = [], threading.Event()

    def job(*args):
        ended.append(real_job(*args))
        done.set()
        return ended[-1]

    monkeypatch.setattr(CoarseReadings, "__call__", gated)
    monkeypatch.setattr(lc, "_layout_job", job)
    return entered, gate, read, ended, done


def test_a_count_being_made_stops_when_the_window_closes(qtbot, win, monkeypatch):
    """The window closed while a count was made: the close waited for the workers 2 s, the process ~6 s more
    (Shasta Lake at 26 m) and the count's worker, ending after the window, printed a traceback.  Now the
    close stops it (at its next coarse reading) before it waits."""
    from tests.app.waits import wait_for

    entered, gate, read, ended, done = held_layout(monkeypatch)
    lake, area = _y_lake()
    win.editor.set_lake(lake, "Import")
    win.lake_ctl.set_cell_size(float(np.sqrt(area / 100)))
    wait_for(qtbot, win, entered.is_set)
    win.stack.setClean()
    gate.set()
    win.close()  # (its wait for the workers quits them: a worker's end is then not signalled)
    assert done.wait(600)  # (a hang guard)
    assert ended == [None] and len(read) == 1  # stopped after the reading under way
