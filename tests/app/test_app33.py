"""Session 33 (branch app33): a lake modeller's import-to-export path without stalls or noise."""

from __future__ import annotations

import threading
from pathlib import Path

import numpy as np
import pytest

from tests.app.waits import wait_idle

pytestmark = pytest.mark.gui

LAKES = Path(__file__).resolve().parents[2] / "benchmarks" / "lakes"


def _big_outline(path: Path, n: int = 4000) -> Path:
    """A wavy closed outline of ``n`` points in metres (no CRS: plain numbers, one block)."""
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    r = 1000 * (1 + 0.3 * np.sin(7 * t) + 0.05 * np.sin(97 * t))
    rows = (f"{a:.3f},{b:.3f}" for a, b in zip(r * np.cos(t), 0.6 * r * np.sin(t), strict=True))
    path.write_text("x,y\n" + "\n".join(rows) + "\n")
    return path


def test_the_import_computes_off_the_gui_thread_which_keeps_drawing(qtbot, win, tmp_path, monkeypatch):
    """The block's corners and cells (the Winslow cell ratio: 0.5 s on a 40 000-point outline) and the
    file's reading ran in the GUI thread: the window froze.  They run in a thread of their own now,
    the GUI thread's timers firing meanwhile, and the block is the same as computed directly."""
    from PySide6 import QtCore

    import app.io_controller as ioc
    from app.project import block_from_points

    gui = threading.current_thread()
    ticked = threading.Event()
    beat = QtCore.QTimer()
    beat.setInterval(5)
    beat.timeout.connect(ticked.set)
    beat.start()
    seen = {}

    def watched(points, name):
        seen["thread"] = threading.current_thread()
        ticked.clear()
        seen["gui_alive"] = ticked.wait(30)  # a hang guard only: the GUI thread's timer fires within ms
        return block_from_points(points, name)

    monkeypatch.setattr(ioc, "block_from_points", watched)
    path = _big_outline(tmp_path / "big.csv")
    assert win.io.import_points(path)
    beat.stop()
    assert seen["thread"] is not gui and seen["gui_alive"]
    b = win.doc.block
    direct = block_from_points(b.points, "x")
    assert b.corners == direct.corners and b.cells == direct.cells and len(b.points) == 4000


def test_a_file_that_cannot_be_read_off_the_gui_thread_says_why_and_keeps_the_document(qtbot, win, tmp_path):
    """A reading error raised in the import's thread reaches the user as before (no traceback), and the
    lake already open stays."""
    path = _big_outline(tmp_path / "big.csv", 400)
    assert win.io.import_points(path)
    before = win.doc.project
    bad = tmp_path / "bad.csv"
    bad.write_text("x,y\n1,2\nthree,4\n")
    assert not win.io.import_points(bad)
    assert win.doc.project is before
    assert "Cannot import points" in win._status.text() and "bad.csv" in win._status.text()


def test_input_is_held_while_a_step_runs_off_the_gui_thread(qtbot, win):
    """A key pressed (Ctrl+Z) while the import's step computes does nothing then: the document cannot
    change under the import."""
    from PySide6 import QtCore, QtGui, QtWidgets

    from app.off_gui import off_gui

    win.editor.add_point((0.0, 0.0))
    n = win.stack.count()

    pressed = threading.Event()

    def press() -> None:  # in the GUI thread, while the step runs
        for key in (QtCore.Qt.Key.Key_Z, QtCore.Qt.Key.Key_Delete):
            ev = QtGui.QKeyEvent(QtCore.QEvent.Type.KeyPress, key, QtCore.Qt.KeyboardModifier.ControlModifier)
            QtWidgets.QApplication.sendEvent(win.canvas, ev)
        pressed.set()

    def step():
        pressed.wait(30)  # a hang guard only
        return 7

    QtCore.QTimer.singleShot(0, press)
    assert off_gui(step) == 7 and pressed.is_set()
    qtbot.wait(50)
    assert win.stack.count() == n and win.stack.index() == n  # not undone
    assert QtWidgets.QApplication.overrideCursor() is None  # the busy cursor went with the step


def test_an_imported_lake_offered_auto_layout_gets_no_corner_advice_until_f5_makes_one_block(qtbot, win):
    """Atlin (sparse) imported: beside the Auto layout offer, Messages warned "corner NW is on point 45,
    a reflex vertex ... move corner NW to a convex vertex" about the one block a lake modeller will not
    make.  Now the advice waits: F5 on the one block gives it; Auto layout's blocks never."""
    assert win.io.import_points(LAKES / "atlin_lake_sparse.geojson", project_lonlat=True)
    assert win.lake_ctl.prompt is not None  # Auto layout offered
    reflex = [t for _lv, t in win.messages_panel.messages() if "reflex" in t]
    assert reflex == []
    win.generate()  # the user wants the one block after all
    reflex = [t for _lv, t in win.messages_panel.messages() if "reflex" in t]
    assert len(reflex) == 1 and "corner NW" in reflex[0]
    win.solver.stop()
    wait_idle(qtbot, win)


def test_corners_moved_on_an_imported_lake_are_advised_at_once(qtbot, win):
    """The hold is for the import's automatic corners only: corners the user sets are advised as before."""
    assert win.io.import_points(LAKES / "atlin_lake_sparse.geojson", project_lonlat=True)
    c = list(win.doc.block.corners)
    c[3] += 2  # NW two points on: point 47, reflex too (221°)
    win.editor.set_corners(tuple(c))
    reflex = [t for _lv, t in win.messages_panel.messages() if "reflex" in t]
    assert len(reflex) == 1 and "point 47" in reflex[0]


def test_the_autosave_after_an_edit_writes_in_a_thread_of_its_own(qtbot, win, tmp_path, monkeypatch):
    """One second after an edit the autosave wrote the project in the GUI thread: a 40 000-point lake
    stalled the window 1.6 s (0.4 s of CPU) after every edit.  It writes in a writer thread now; a
    save meanwhile waits for that write, and no recovery file is left behind it."""
    from app import recovery
    from tests.app.waits import wait_for

    gui = threading.current_thread()
    threads = []
    write = recovery.write

    def watched(*a, **k):
        threads.append(threading.current_thread())
        threading.Event().wait(0.3)  # a slow disk: the save below comes while this writes
        return write(*a, **k)

    monkeypatch.setattr(recovery, "write", watched)
    assert win.io.import_points(_big_outline(tmp_path / "big.csv", 400))
    wait_for(qtbot, win, lambda: bool(threads))  # the debounced autosave started
    assert threads[0] is not gui
    assert win.io.save_to(tmp_path / "saved.toml")  # while it writes
    assert not recovery.exists(win.io.recovery_path)
    win.editor.set_block_options(weights=(0.3, 0.7))
    win.io.autosave()  # asked for directly (a test, a clean exit's path): written when it returns
    assert threads[-1] is gui and recovery.read(win.io.recovery_path)[0] == win.doc.project


def _small_lake():
    from app.lake import Lake
    from meshcore import testing

    poly = testing.round_lake(850_031, kind="ring", radius=2000.0)
    return Lake(
        outline=np.asarray(poly.exterior.coords)[:-1],
        holes=tuple(np.asarray(r.coords)[:-1] for r in poly.interiors),
        target_cells=1500,
    )


def test_live_is_on_for_a_lake_layout_and_remembered_apart_from_blocks(qtbot, win):
    """Live (auto-generate) was off for everything by default: a cut end dragged left the old grid greyed
    under "F5 makes the new one".  A lake's layout turns it on (the user's earlier choice for lakes
    kept), one block keeps its own state; the choice made with a layout is remembered for lakes only."""
    from app.lake import compute_layout
    from app.window_frame import LIVE
    from tests.app.waits import wait_for

    win.settings.remove(LIVE["lake"][0])  # a user who never chose (the fixture's user turned it off)
    assert not win.solver.auto and not win.a_auto.isChecked()  # a block document: off
    lake = _small_lake()
    win.editor.set_lake(lake.replaced(layout=compute_layout(lake)), "Auto layout")
    assert win.solver.auto and win.a_auto.isChecked()
    wait_for(qtbot, win, lambda: bool(win.doc.grids) and not win.doc.stale)  # gridded without F5
    wait_idle(qtbot, win)
    win.a_auto.trigger()  # the user turns it off, with a layout shown
    assert not win.solver.auto
    win.stack.undo()  # back to no layout: the blocks' state (off)
    assert not win.solver.auto
    win.a_auto.trigger()  # on for blocks
    win.stack.redo()  # the layout again: off, as the user left it for lakes
    assert not win.solver.auto and win.settings.value(LIVE["block"][0]) in (True, "true")
    win.stack.undo()
    assert win.solver.auto  # the blocks' on
    win.a_auto.trigger()
    wait_idle(qtbot, win)


def test_a_lake_grid_exported_to_a_one_block_format_says_which_file_types_take_its_blocks(qtbot, win, tmp_path):
    """File ▸ Export of a laid-out lake to ``lake.nc``: "the sgrid format holds one block, got 45", and no
    way on.  Now it names the file types that take blocks (and those that merge them), writes nothing,
    and the same grid goes to .vtm."""
    from app.lake import compute_layout
    from tests.app.waits import wait_for

    lake = _small_lake()
    win.editor.set_lake(lake.replaced(layout=compute_layout(lake)), "Auto layout")
    win.generate()
    wait_for(qtbot, win, lambda: bool(win.doc.grids) and not win.doc.stale and win.doc.multiblock is not None)
    wait_idle(qtbot, win)
    n = len(win.doc.project.layout.blocks)
    assert not win.io.export_mesh(tmp_path / "lake.nc")
    said = win._status.text()
    assert f"NetCDF (.nc) holds one block and this grid has {n}" in said and ".vtm" in said and ".ddb" in said
    assert not (tmp_path / "lake.nc").exists()
    assert win.io.export_mesh(tmp_path / "lake.vtm") and (tmp_path / "lake.vtm").exists()


def test_an_outline_that_crosses_itself_is_said_so_without_corner_advice(qtbot, win, tmp_path):
    """A bow tie imported: beside "the outline crosses itself: the edge from point 1 to 2 meets the edge
    from point 3 to 4" came "corner NE is on point 3, a reflex vertex (interior angle 315°)" twice — advice
    about corners of a loop that is no polygon.  The crossing alone is said; the document of before comes
    back by one undo."""
    path = tmp_path / "bowtie.csv"
    path.write_text("x,y\n0,0\n1000,1000\n1000,0\n0,1000\n")
    before = win.doc.project
    assert win.io.import_points(path)
    texts = [t for _lv, t in win.messages_panel.messages()]
    assert any("crosses itself" in t and "point 1 to 2" in t for t in texts), texts
    assert not any("reflex" in t for t in texts), texts
    assert "crosses itself" in win._status.text()
    win.stack.undo()
    assert win.doc.project == before


def test_another_lake_imported_clears_the_convergence_plot_of_the_one_before(qtbot, win, tmp_path):
    """A lake gridded, then another imported over it: the Convergence dock went on showing the first
    lake's sweeps and levels under the new lake's outline, with no grid of it."""
    from app.lake import compute_layout
    from tests.app.waits import wait_for

    lake = _small_lake()
    win.editor.set_lake(lake.replaced(layout=compute_layout(lake)), "Auto layout")
    win.generate()
    wait_for(qtbot, win, lambda: bool(win.doc.grids) and not win.doc.stale and win.doc.multiblock is not None)
    wait_idle(qtbot, win)
    assert len(win.conv_panel.curve.xData)  # the lake's sweeps
    assert win.io.import_points(_big_outline(tmp_path / "other.csv", 400))
    assert not win.doc.grids
    assert win.conv_panel.curve.xData is None or len(win.conv_panel.curve.xData) == 0


def test_a_lake_kept_in_degrees_is_said_to_be_with_its_distortion(qtbot, win):
    """ "No" to "Project them to metres?": the lake came in as degrees, drawn stretched, and the status line
    said only "Imported 578 points and 2 islands ...; Auto layout (Ctrl+L) lays it out" — nothing about
    the degrees.  It says so, and Messages say what it costs at the lake's latitude."""
    assert win.io.import_points(LAKES / "lake_como_sparse.geojson", project_lonlat=False)
    assert "kept in degrees" in win._status.text()
    notes = [t for lv, t in win.messages_panel.messages() if lv == "warning" and "degrees" in t]
    assert len(notes) == 1 and "latitude 46." in notes[0] and "answer Yes" in notes[0], notes


def test_a_project_is_read_off_the_gui_thread(qtbot, win, tmp_path, monkeypatch):
    """File ▸ Open read the case in the GUI thread (a laid-out lake of 45 blocks: 0.2-0.6 s of CPU)."""
    from app import io_adapter as fio

    assert win.io.import_points(_big_outline(tmp_path / "o.csv", 400))
    assert win.io.save_to(tmp_path / "o.toml")
    threads = []
    load = fio.load_project
    monkeypatch.setattr(fio, "load_project", lambda p: threads.append(threading.current_thread()) or load(p))
    saved = win.doc.project
    assert win.io.open_path(tmp_path / "o.toml")
    assert threads and threads[0] is not threading.current_thread()
    assert len(win.doc.block.points) == len(saved.blocks[0].points)


def test_a_kml_of_a_line_only_says_it_has_no_polygon(qtbot, win, tmp_path):
    """A KML of one LineString (a road, a river's centre line) came in as a lake of its three points, the
    status line "Imported 3 points ... Auto layout splits it into blocks": nothing said the file has no
    polygon.  Messages say so and which line became the outline."""
    kml = tmp_path / "road.kml"
    kml.write_text(
        '<kml xmlns="http://www.opengis.net/kml/2.2"><Document><Placemark><name>road</name><LineString>'
        "<coordinates>10.0,60.0,0 10.1,60.1,0 10.2,60.0,0</coordinates></LineString></Placemark></Document></kml>"
    )
    assert win.io.import_points(kml, project_lonlat=True)
    notes = [t for lv, t in win.messages_panel.messages() if lv == "warning" and "no polygon" in t]
    assert len(notes) == 1 and "'road'" in notes[0] and "3 points" in notes[0], notes
    csv = _big_outline(tmp_path / "shore.csv", 100)  # a CSV's rows are an outline: nothing said
    assert win.io.import_points(csv)
    assert len([t for _lv, t in win.messages_panel.messages() if "no polygon" in t]) == 1


def test_a_dialog_opened_while_a_step_runs_off_the_gui_thread_takes_its_input(qtbot, win):
    """An error of another worker shown in a modal dialog during the hold: the user's click on OK was
    held too, the dialog never closed and the step's end waited behind it."""
    from PySide6 import QtCore, QtWidgets

    from app.off_gui import off_gui

    shown = threading.Event()
    closed = []

    def dialog() -> None:  # in the GUI thread, while the step runs
        box = QtWidgets.QMessageBox(QtWidgets.QMessageBox.Icon.Warning, "Error", "a worker failed", parent=win)
        QtCore.QTimer.singleShot(50, lambda: qtbot.keyClick(box, QtCore.Qt.Key.Key_Escape))  # the user's key
        shown.set()
        closed.append(box.exec())

    QtCore.QTimer.singleShot(0, dialog)
    assert off_gui(lambda: shown.wait(30)) is True
    assert closed  # the dialog closed by the user's key
