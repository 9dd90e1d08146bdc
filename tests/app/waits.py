"""Waiting in GUI tests on what the app does (its signals), never on how fast it does it.

A wait ends when its condition holds; it wakes on the signals that can make the condition true
(the solver's state and result, the layout's busy flag and result, new grids, a new project, the
solver's debounce timer firing) and, as a safety net for flags that change without a signal,
every :data:`POLL_MS`.  Its limit, :data:`HANG_MS`, only catches a hang: a slow machine must
never fail a test.  Ten minutes: the slowest wait in these tests (Como at ~10 000 cells, import
to grid) took 1-2 min of wall time at load 9 on 2 cores with a warm numba cache; the suite's
per-test limit (pytest-timeout, 900 s) stays above it.  The numba kernels are compiled once per
session before the first GUI test (``tests/app/conftest.py``), not inside a wait.
"""

from __future__ import annotations

import time
from collections.abc import Callable

from PySide6 import QtCore

__all__ = ["HANG_MS", "POLL_MS", "idle", "wait_for", "wait_idle"]

HANG_MS = 600_000
POLL_MS = 100


def idle(win) -> bool:
    """Nothing being computed: no layout, no layout edit, no solve, no solve about to start, no measure, no export."""
    lake = win.lake_ctl
    return not (
        lake.busy
        or lake.editing
        or win.solver.running
        or win.solver._debounce.isActive()
        or win.measurer.busy
        or win.io.exporting
    )


def _signals(win) -> list:
    return [
        win.solver.state_changed,
        win.solver.finished,
        win.solver._debounce.timeout,
        win.lake_ctl.busy_changed,
        win.lake_ctl.layout_done,
        win.doc.grids_changed,
        win.doc.project_changed,
        win.doc.quality_changed,
    ]


def wait_for(qtbot, win, done: Callable[[], bool], timeout: int = HANG_MS) -> None:
    """Process events until ``done()``; raises TimeoutError after ``timeout`` ms (a hang)."""
    if done():
        return
    loop = QtCore.QEventLoop()

    def check(*_args) -> None:
        if done():
            loop.quit()

    poll = QtCore.QTimer()
    poll.timeout.connect(check)
    poll.start(POLL_MS)
    limit = QtCore.QTimer()
    limit.setSingleShot(True)
    limit.timeout.connect(loop.quit)
    limit.start(timeout)
    signals = _signals(win)
    for s in signals:
        s.connect(check)
    deadline = time.monotonic() + timeout / 1000
    try:
        QtCore.QTimer.singleShot(0, check)  # in case it came true in between
        while not done() and time.monotonic() < deadline:
            loop.exec()  # again when something else ended it early (a stray quit)
    finally:
        for s in signals:
            s.disconnect(check)
        poll.stop()
        limit.stop()
    if not done():
        lake, solver = win.lake_ctl, win.solver
        state = (
            f"layout busy {lake.busy}, layout edit {lake.editing}, solver {solver.state}, "
            f"solve pending {solver._debounce.isActive()}"
        )
        raise TimeoutError(f"not done after {timeout / 1000:.0f} s (a hang?): {state}")


def wait_idle(qtbot, win, timeout: int = HANG_MS) -> None:
    """Until nothing is being computed (:func:`idle`)."""
    wait_for(qtbot, win, lambda: idle(win), timeout)


def drag_a_cut_end(qtbot, win, reach: float = 1.0) -> None:
    """Drag the first cut end of the layout ``reach`` cells along both axes with the Layout tool,
    in three moves, and wait until the edit is done and the app idle."""
    import numpy as np

    from app.layout_edit import handles

    lay0 = win.doc.project.layout
    end = next(h for h in handles(lay0) if h.kind == "end")
    tool, h = win.canvas.tool, lay0.cell_size
    path = [np.add(end.xy, (f * h, f * h)) for f in np.linspace(0, reach, 4)]
    assert tool.drag("start", tuple(path[0]), end.xy)
    for p in path[1:]:
        tool.drag("move", tuple(p), end.xy)
        qtbot.wait(30)
    tool.drag("finish", tuple(path[-1]), end.xy)
    wait_for(qtbot, win, lambda: win.doc.project.layout is not lay0 and not win.lake_ctl.editing)
    wait_idle(qtbot, win)


def answer_questions(monkeypatch, answer: str = "Yes") -> list[str]:
    """Every ``QMessageBox.question`` answered ``answer`` (a StandardButton name) without a dialog;
    returns the list their texts are appended to, in the order asked."""
    from PySide6 import QtWidgets

    asked: list[str] = []

    def question(_parent, _title, text, *_a):
        asked.append(text)
        return getattr(QtWidgets.QMessageBox.StandardButton, answer)

    monkeypatch.setattr(QtWidgets.QMessageBox, "question", question)
    return asked
