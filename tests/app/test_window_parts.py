"""The window's parts: the action table, autosave, logging, the views' import contract."""

from __future__ import annotations

import logging
import subprocess
import sys
import traceback
from pathlib import Path

import numpy as np
import pytest
from PySide6 import QtGui, QtWidgets

from app import actions, recovery
from tests.app.waits import wait_for

pytestmark = pytest.mark.gui

ROOT = Path(__file__).resolve().parents[2]


def _menu(win, title):
    for m in win.menuBar().findChildren(QtWidgets.QMenu):
        if m.title().replace("&", "") == title:
            return m
    raise KeyError(title)


def test_every_action_comes_from_the_table(qtbot, win):
    seen = {}
    for spec in actions.ACTIONS:
        if spec.key in ("recent", "docks", "examples"):
            continue
        a = getattr(win, f"a_{spec.key}")
        assert a.shortcuts() == [QtGui.QKeySequence(s) for s in spec.shortcuts]
        for s in a.shortcuts():
            assert s.toString() not in seen, f"{s.toString()} is on {seen.get(s.toString())} and {spec.key}"
            seen[s.toString()] = spec.key
        if spec.toolbar:
            assert a in win.findChild(QtWidgets.QToolBar, "main-toolbar").actions()
    assert set(win.tool_actions) == {"pan", "draw", "edit", "corners", "cut", "layout"}
    help_keys = " ".join(k for k, _ in actions.shortcut_rows())
    assert "Ctrl+Y" in help_keys and "F5" in help_keys


def test_redo_shows_ctrl_y_in_the_edit_menu(qtbot, win):
    edit = _menu(win, "Edit")
    redo = next(a for a in edit.actions() if a.text().replace("&", "").startswith("Redo"))
    assert redo.shortcut().toString() == "Ctrl+Y"  # the one the menu shows
    assert QtGui.QKeySequence("Ctrl+Shift+Z") in redo.shortcuts()
    win.editor.add_point((0.0, 0.0))
    win.stack.undo()
    assert len(win.doc.block.points) == 0
    redo.trigger()
    assert len(win.doc.block.points) == 1


def test_autosave_follows_edits_without_being_asked(qtbot, win):
    path = win.io.recovery_path
    win.io.open_example("bottle-coarse", confirm=False)
    assert not recovery.exists(path)
    win.editor.set_block_options(weights=(0.25, 0.75))
    wait_for(qtbot, win, lambda: path.exists() and not win.io.autosaving)  # debounced: shortly after the edit
    q, _ = recovery.read(path)
    assert q == win.doc.project
    # a long drag: edits keep coming, and the work is saved while they do
    path.unlink()
    p = np.array(win.doc.block.points[3])
    drag = win.editor.new_drag_id()
    for k in range(60):
        win.editor.set_points([3], [p + [0.001 * k, 0.0]], drag_id=drag)
        qtbot.wait(100)
        if path.exists():
            break
    assert path.exists(), "nothing autosaved during 6 s of continuous edits"
    # a save makes the recovery files pointless
    assert win.io.save_to(win.io.recovery_path.parent / "saved.toml")
    assert not recovery.exists(path)


def test_failures_are_logged_with_their_traceback(qtbot, win, tmp_path, caplog, monkeypatch):
    def broken(path):
        raise RuntimeError("exporter broke")

    monkeypatch.setattr(win.canvas, "export_image", broken)
    with caplog.at_level(logging.INFO, logger="app"):
        assert not win.io.export_figure(tmp_path / "f.png")
    rec = [r for r in caplog.records if r.exc_info and r.exc_info[0] is RuntimeError]
    assert rec and rec[0].exc_info[2] is not None  # the traceback travels with the record
    assert "exporter broke" in win._status.text()


def test_views_never_import_the_solver_controller():
    code = (
        "import sys; import app.views.canvas, app.views.panels, app.views.params_panel; "
        "bad = [m for m in ('app.solver_controller', 'app.pipeline', 'app.io_controller') if m in sys.modules]; "
        "print(bad); sys.exit(1 if bad else 0)"
    )
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, timeout=120)
    assert r.returncode == 0, r.stdout + r.stderr


def test_a_bug_in_the_solver_is_logged_with_its_traceback(qtbot, win, caplog, monkeypatch):
    import app.solver_controller as sc

    def broken(*a, **k):
        yield from ()
        raise ZeroDivisionError("a bug in the pipeline")

    monkeypatch.setattr(sc, "solve_project", broken)
    win.io.open_example("bottle-coarse", confirm=False)
    with caplog.at_level(logging.INFO, logger="app"):
        win.generate()
        wait_for(qtbot, win, lambda: not win.solver.running)
    rec = [r for r in caplog.records if r.exc_info and r.exc_info[0] is ZeroDivisionError]
    assert rec and "broken" in "".join(traceback.format_tb(rec[0].exc_info[2]))
    assert "internal error" in win._status.text() and "ZeroDivisionError" in win._status.text()


def test_autosave_waits_for_the_end_of_a_generate_solve(qtbot, win, monkeypatch):
    """The save (tenths of a second of Python on a big lake) would take the solver's turn: it
    waits until Generate's solve ends; with auto-generate the edits are saved as they come."""
    writes = []
    monkeypatch.setattr(recovery, "write", lambda *a, **k: writes.append(1))
    win.io.open_example("bottle-coarse", confirm=False)
    win.editor.set_block_options(weights=(0.3, 0.7))
    monkeypatch.setattr(win.solver, "state", "running")
    win.io.autosave()
    assert writes == [] and win.io._autosave.isActive()  # tried again later
    win.solver.auto = True
    win.io.autosave()
    assert writes == [1]
    win.solver.auto = False
    win.editor.set_block_options(weights=(0.4, 0.6))
    monkeypatch.setattr(win.solver, "state", "idle")
    wait_for(qtbot, win, lambda: len(writes) == 2)


def test_the_message_count_follows_repeats_the_oldest_dropped_and_clear(qtbot, win, monkeypatch):
    """The counts under the message list are kept as messages come and go, not read back from the list."""
    panel = win.messages_panel
    panel.clear()
    monkeypatch.setattr(panel, "MAX_ITEMS", 4)
    for level, text in [("error", "e1"), ("warning", "w1"), ("warning", "w1"), ("info", "i1"), ("warning", "w2")]:
        win.doc.report(level, text)
    assert panel.count.text() == "1 error(s), 2 warning(s)"  # the repeated w1 listed once
    win.doc.report("info", "i2")  # five messages: the oldest (the error) drops out
    assert [lv for lv, _t in panel.messages()] == ["info", "warning", "info", "warning"]
    assert panel.count.text() == "0 error(s), 2 warning(s)"
    panel.clear()
    assert panel.count.text() == "no messages"
