"""Session 40 (branch app40): a lake grid made again (``FOLD_RETRY``) said while it is made, Auto layout
stopped by Stop/Esc and by closing the window."""

from __future__ import annotations

import threading

import numpy as np
import pytest

from tests.app.test_app39 import _y_lake
from tests.app.test_app39b import held_layout

pytestmark = pytest.mark.gui


def _folded_first(monkeypatch, first: int = 1, again: int = 0, gate=None):
    """``meshcore.lakegrid._n_folded`` answering ``first`` for the grid of the levels, then ``again`` for the
    grid made again (the retry forced); ``gate``: ``(entered, go)`` events the first count sets and waits on."""
    from meshcore import lakegrid

    said = [first, again]

    def n_folded(grids):
        if gate is not None and len(said) == 2:
            gate[0].set()
            gate[1].wait(60)
        return said.pop(0) if said else 0

    monkeypatch.setattr(lakegrid, "_n_folded", n_folded)


def _laid_out(win):
    from app.lake import compute_layout

    lake, _ = _y_lake()
    win.editor.set_lake(lake.replaced(layout=compute_layout(lake)), "Auto layout")


def test_a_lake_grid_made_again_is_said_while_it_is_made(qtbot, win, monkeypatch):
    """A lake grid whose levels left a folded cell is made once more with sliding ends (FOLD_RETRY): seconds
    without a frame (8 s on Vänern) in which the status line sat on the first grid's last sweep and nothing
    said why.  Now the status line and the Messages say the grid is made again and why, the solver label
    follows its levels as they end, and the end says which grid was kept, ahead of the grid's line."""
    from tests.app.waits import wait_idle

    _folded_first(monkeypatch, 1, 0)
    _laid_out(win)
    heard, labels, status = [], [], []

    def said(kind, text):  # (connected after the window's own slot: what it showed)
        heard.append(kind)
        labels.append(win.solve_status.label.text())
        status.append(win._status.text())

    win.solver.retry_said.connect(said)
    ended = []
    win.solver.finished.connect(lambda _r: ended.append(list(heard)))
    win.generate()
    wait_idle(qtbot, win)
    assert heard == ["retry", "again level", "again level", "again level", "again equalize", "retried"]
    assert ended == [heard]  # all said before the solve's end
    retry = "lake grid: 1 folded or non-convex cell left — making it again with block corners and cut ends"
    assert labels[0].startswith(retry) and status[0].startswith("Grid: 1 folded or non-convex cell left")
    assert labels[1].startswith("lake grid made again: level 1/3 (÷4, ") and "sweeps" in labels[1]
    assert labels[3].startswith("lake grid made again: level 3/3 (full, ")
    texts = [t for _lv, t in win.messages_panel.messages()]
    assert any(t.startswith(retry) for t in texts)
    assert "lake grid made again: 0 bad cells against 1 — that grid kept" in texts
    line = win._status.text()  # the outcome ahead of the grid's own line
    assert line.startswith("Grid made again: 0 bad cells against 1 — that grid kept — Lake grid: "), line
    assert (
        "made again with block corners and cut ends sliding along the shore: 1 → 0" in win.doc.multiblock.info.message
    )
    # its sweeps are its own, made after those plotted: the label says so, the plot marks where
    assert win.solve_status.label.text().startswith(
        f"orthogonal: {win.doc.multiblock.info.iterations} sweeps (made again)"
    )
    assert win.conv_panel.levels[-1][1] == "made again"


def test_a_stop_while_the_grid_is_made_again_ends_it_and_keeps_the_first_grid(qtbot, win, monkeypatch):
    """Stop (Esc) as the grid is about to be made again: the grid made again stops (the solve's stop reaches
    it), the first grid — finished, with its folded cell — stays, and that is said."""
    from tests.app.waits import wait_for, wait_idle

    entered, go = threading.Event(), threading.Event()
    _folded_first(monkeypatch, 1, 0, gate=(entered, go))
    _laid_out(win)
    label, shown = win.solve_status.label, []
    set_text = label.setText
    monkeypatch.setattr(label, "setText", lambda text: (shown.append(text), set_text(text)))
    win.generate()
    wait_for(qtbot, win, entered.is_set)  # the levels are done, their grid is being counted
    assert win.a_stop.isEnabled()
    win.a_stop.trigger()
    go.set()
    wait_idle(qtbot, win)
    assert any(t.startswith("lake grid: 1 folded or non-convex cell left") for t in shown)
    assert not any("made again: level" in t for t in shown)  # stopped before its first level ended
    texts = [t for _lv, t in win.messages_panel.messages()]
    assert "lake grid made again: stopped — the first grid kept (1 bad cell)" in texts
    mb = win.doc.multiblock
    assert mb is not None and mb.info.converged and "made again" not in mb.info.message
    assert [g.cells for g in mb.grids] == [tuple(b.cells) for b in win.doc.project.layout.blocks]


def test_stop_ends_a_running_auto_layout(qtbot, win, monkeypatch):
    """Ctrl+L on a big lake runs for seconds; Stop was greyed and Esc did nothing (the layout's worker took no
    stop).  Now Stop is on while the layout is computed, Esc (Generate ▸ Stop) ends it at its next coarse
    reading: the document unchanged, nothing to undo, "Auto layout stopped" said, and no grid started."""
    from tests.app.waits import wait_for, wait_idle

    entered, go, _read, ended, _done = held_layout(monkeypatch)
    lake, _ = _y_lake()
    win.editor.set_lake(lake, "Import")
    before, steps = win.doc.project, win.stack.count()
    assert win.lake_ctl.auto_layout()
    wait_for(qtbot, win, entered.is_set)
    assert win.lake_ctl.busy and win.a_stop.isEnabled()
    win.a_stop.trigger()  # Esc
    assert win.lake_panel.button.text() == "Stopping the layout…" and "Stopping Auto layout" in win._status.text()
    go.set()
    wait_for(qtbot, win, lambda: not win.lake_ctl.busy)
    wait_idle(qtbot, win)
    assert ended == [None]  # the worker stopped: no layout made
    assert win.doc.project is before and win.stack.count() == steps
    assert not win.solver.running and win.doc.grids == {}
    assert "Auto layout stopped" in win._status.text()
    assert not win.a_stop.isEnabled() and win.lake_panel.button.text() == "Auto layout"
    assert win.lake_ctl.auto_layout()  # and it can be laid out again
    wait_for(qtbot, win, lambda: win.doc.project.layout is not None)
    wait_idle(qtbot, win)


def test_stop_ends_an_auto_layout_that_took_over_the_count(qtbot, win, monkeypatch):
    """Ctrl+L while the Lake panel's count of the size just set was made takes that worker over: Stop ends
    it too (its stop is the count's), and nothing of it is set when it returns."""
    from tests.app.waits import wait_for, wait_idle

    entered, go, _read, ended, _done = held_layout(monkeypatch)
    lake, area = _y_lake()
    win.editor.set_lake(lake, "Import")
    win.lake_ctl.set_cell_size(float(np.sqrt(area / 100)))
    wait_for(qtbot, win, entered.is_set)  # the count is being made
    before, steps = win.doc.project, win.stack.count()
    assert win.lake_ctl.auto_layout() and win.lake_ctl.busy
    win.stop()  # Esc
    go.set()
    wait_for(qtbot, win, lambda: not win.lake_ctl.busy)
    wait_idle(qtbot, win)
    assert ended[0] is None and win.doc.project is before and win.stack.count() == steps
    assert "Auto layout stopped" in win._status.text()


def test_closing_the_window_stops_a_running_auto_layout(qtbot, win, monkeypatch):
    """The window closed while Auto layout ran: the close waited 2 s for the workers and the layout went on
    after the window (its worker, ending on a deleted controller, printed a traceback).  Now the close stops
    it at its next coarse reading before it waits."""
    entered, go, _read, ended, done = held_layout(monkeypatch)
    lake, _ = _y_lake()
    win.editor.set_lake(lake, "Import")
    assert win.lake_ctl.auto_layout()
    qtbot.waitUntil(entered.is_set, timeout=600_000)
    win.stack.setClean()
    threading.Timer(0.2, go.set).start()  # (the close waits for the workers: the reading goes on meanwhile)
    win.close()
    assert done.wait(600)  # (a hang guard)
    assert ended == [None]  # stopped after the reading under way


def test_a_grid_kept_by_a_stopped_solve_shows_its_own_convergence_and_an_undo_redo_forgets_the_stop(qtbot, win):
    """F5 on a finished lake grid, then Esc: the grid of before stays, but the convergence plot showed the
    stopped solve's sweeps, not that grid's; then Ctrl+Z, Ctrl+Y (the layout and its grid back) said
    "stopped: the grid of before kept" of the grid the redo brought back, its plot empty.  Now the plot is
    the kept grid's, and after the redo the grid's own summary is said with its plot."""
    from tests.app.waits import wait_idle

    _laid_out(win)
    win.generate()
    wait_idle(qtbot, win)
    curve = win.conv_panel.curve

    def plotted():
        return [] if curve.xData is None else list(curve.xData)

    sweeps = plotted()
    assert len(sweeps) > 3 and win.solve_status.label.text().startswith("orthogonal: ")
    win.generate()  # F5 on the finished grid, stopped at once
    win.stop()
    wait_idle(qtbot, win)
    assert win.solver.kept_grid and win.solve_status.label.text().endswith("the grid of before kept")
    assert plotted() == sweeps  # the kept grid's sweeps
    win.stack.undo()
    win.stack.redo()
    wait_idle(qtbot, win)
    assert win.doc.multiblock is not None
    assert win.solve_status.label.text().startswith("orthogonal: ")
    assert plotted() == sweeps


def test_the_cell_size_of_a_lake_a_few_units_across_can_be_typed(qtbot, win):
    """A lake in plain numbers a few units across (a generated shape, a CSV in km): the Lake panel's cell
    size had one decimal, so 0.0704 typed became 0.1 (or "auto" when it rounded to 0) and the cell size
    such a lake needs could not be set.  Now its decimals follow the lake's extent; a lake in metres keeps
    one."""
    from PySide6 import QtCore

    from app.lake import Lake
    from meshcore import testing

    ring = np.asarray(testing.y_junction().exterior.coords)[:-1]  # 11 units across
    win.editor.set_lake(Lake(outline=ring), "Import")
    box = win.lake_panel.cell_size
    box.lineEdit().selectAll()
    qtbot.keyClicks(box.lineEdit(), "0.0704")
    qtbot.keyClick(box.lineEdit(), QtCore.Qt.Key.Key_Return)
    assert win.lake_ctl.lake().cell_size == pytest.approx(0.0704)
    assert box.text().startswith("0.0704")
    lake, _ = _y_lake()  # 11 km across
    win.editor.set_lake(lake, "Import")
    assert box.decimals() == 1 and box.singleStep() == 10.0
