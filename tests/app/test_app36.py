"""Session 36 (branch app36): a lake modeller's walk under Xvfb — two windows, one autosave."""

from __future__ import annotations

import subprocess
import sys

import pytest

pytestmark = pytest.mark.gui

_HOLD = """
import sys
from PySide6.QtCore import QLockFile
lock = QLockFile(sys.argv[1])
lock.setStaleLockTime(0)
print("held" if lock.tryLock(0) else "refused", flush=True)
sys.stdin.read()
"""


def test_a_second_gcmesh_keeps_off_the_autosave_of_one_still_running(qtbot, tmp_path, monkeypatch):
    """Every gcmesh autosaved to one recovery.toml.  A second window started while the first had
    unsaved work said "gcmesh did not shut down cleanly last time. Restore the autosaved project?"
    about the first one's lake, and "No" deleted its autosave (seen under Xvfb: kyoga's 60 blocks
    gone from the data folder, the first window still open); its own edits overwrote it and its clean
    exit removed it.  Now each running gcmesh has its own recovery file; one whose process is gone
    is offered to the next window."""
    from PySide6 import QtCore, QtWidgets

    from app import recovery
    from app.main_window import MainWindow
    from app.project import Project

    path = tmp_path / "recovery.toml"
    other = subprocess.Popen(
        [sys.executable, "-c", _HOLD, str(path) + ".lock"], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True
    )
    try:
        assert other.stdout.readline().strip() == "held"  # the first gcmesh, running
        theirs = Project(title="the other window's lake")
        recovery.write(theirs, path)  # its unsaved work, autosaved
        asked = []
        monkeypatch.setattr(QtWidgets.QMessageBox, "question", lambda *a, **k: asked.append(a[1]))
        settings = QtCore.QSettings(str(tmp_path / "s.ini"), QtCore.QSettings.Format.IniFormat)
        w = MainWindow(settings=settings, recovery=path)
        w.quiet = True
        qtbot.addWidget(w)
        assert not w.io.offer_recovery() and asked == []  # not offered: it is not from a crash
        assert w.io.recovery_path != path
        w.editor.add_point((0.0, 0.0))
        w.io.autosave()
        w.io.shutdown()  # a clean exit of the second window
        assert recovery.read(path)[0].title == "the other window's lake"  # still there
    finally:
        other.kill()  # the first gcmesh crashes
        other.wait()
        other.stdin.close()
        other.stdout.close()
    monkeypatch.setattr(QtWidgets.QMessageBox, "question", lambda *a, **k: QtWidgets.QMessageBox.StandardButton.Yes)
    w2 = MainWindow(settings=settings, recovery=path)
    w2.quiet = True
    qtbot.addWidget(w2)
    assert w2.io.recovery_path == path
    assert w2.io.offer_recovery() and w2.doc.project.title == "the other window's lake"
    w2.stack.setClean()


def test_a_lake_saved_before_its_layout_is_offered_auto_layout_when_opened(qtbot, win, tmp_path):
    """Taal imported (one island), its cell size set, saved before Auto layout, opened the next day:
    no Auto layout offer, and the status line said "press F5 to generate" — F5 makes the one block
    over the island that the import had called a poor grid.  Opened, it is offered as imported."""
    from pathlib import Path

    from PySide6 import QtCore

    from app.main_window import MainWindow

    lakes = Path(__file__).resolve().parents[2] / "benchmarks" / "lakes"
    assert win.io.import_points(lakes / "taal_lake.kml", project_lonlat=True)
    win.lake_ctl.set_cell_size(500.0)
    assert win.io.save_to(tmp_path / "taal.toml")
    settings = QtCore.QSettings(str(tmp_path / "s.ini"), QtCore.QSettings.Format.IniFormat)
    w = MainWindow(settings=settings, recovery=tmp_path / "r.toml")  # the next day
    w.quiet = True
    qtbot.addWidget(w)
    assert w.io.open_path(tmp_path / "taal.toml")
    assert w.doc.project.layout is None and w.doc.project.lake.cell_size == 500.0
    assert w.lake_ctl.prompt is not None  # Auto layout offered
    assert "Auto layout (Ctrl+L)" in w._status.text() and "press F5 to generate" not in w._status.text()
    assert not w.solver.running


def test_a_lake_grid_brought_back_by_undo_says_its_own_solve_time(qtbot, win, tmp_path):
    """Another lake imported and gridded, then Ctrl+Z: the first lake's grid came back and the solver label
    said its sweeps with the other grid's time ("orthogonal: 1240 sweeps, 9.8 s" for Kyoga's grid of 3.7 s,
    after Taal's solve), and the convergence plot showed the other solve's history (or none after Clear
    layout).  The label and the plot are of the grid shown, as they were after its solve."""
    import numpy as np

    from tests.app.test_lake import ISEO, lay_out
    from tests.app.waits import wait_idle

    lay_out(qtbot, win, ISEO)  # about 10 000 cells: a second or so, the oval's grid a tenth
    mb = win.doc.multiblock
    first = win.solve_status.label.text()
    assert first.startswith(f"orthogonal: {mb.info.iterations} sweeps, ")
    plot = win.conv_panel.curve.getData()[1].copy()
    assert len(plot) > 10
    t = np.linspace(0, 2 * np.pi, 80, endpoint=False)
    box = tmp_path / "oval.csv"
    np.savetxt(box, np.c_[300 * np.cos(t), 100 * np.sin(t)], delimiter=",", header="x,y", comments="")
    assert win.io.import_points(box)
    win.generate()
    wait_idle(qtbot, win)
    assert win.solve_status.label.text() != first
    win.a_undo.trigger()  # the import: Iseo's grid again
    wait_idle(qtbot, win)
    assert win.doc.multiblock is mb
    assert win.solve_status.label.text() == first
    assert list(win.conv_panel.curve.getData()[1]) == list(plot)  # its convergence, not the oval's


def test_export_while_the_grid_is_being_made_does_not_ask_for_f5(qtbot, win, tmp_path):
    """Export (Ctrl+E) while Auto layout's grid was being made said "Nothing to export yet: generate a grid
    first (F5)" — F5 starts that grid over.  It says the grid is being made, and to export when it is done."""
    from tests.app.test_lake import ISEO
    from tests.app.waits import wait_for, wait_idle

    assert win.io.import_points(ISEO, project_lonlat=True)
    win.a_auto_layout.trigger()
    assert win.lake_ctl.busy
    win.io.export_dialog()  # (no dialog: refused before it)
    assert "being made" in win._status.text() and "F5" not in win._status.text()
    wait_for(qtbot, win, lambda: win.doc.project.layout is not None)
    assert win.solver.running
    assert not win.io.export_mesh(tmp_path / "a.vtm")
    assert "being made" in win._status.text() and "F5" not in win._status.text()
    wait_idle(qtbot, win)
    assert win.io.export_mesh(tmp_path / "a.vtm")
