"""Fixtures for the app's GUI tests: a main window with private settings and recovery file."""

from __future__ import annotations

import gc

import pytest


def pytest_collection_finish(session) -> None:
    """Compile (or load from the numba cache) the solver kernels once, before the first GUI test.

    In a checkout whose numba cache is cold (a new worktree, or a kernel file changed) the first
    solve compiles its kernels in the solver's worker thread: minutes on a busy machine (a
    300 × 300 block: 130 s wall, 124 s of it compiling ``fmg_start``, at load 4-9), all inside
    one test's wait.  Here it happens once, outside every test and its time limit.  The app's
    own start-up warm-up (one block), then a generated lake with islands at three times the
    default cell size (~1200 cells, several blocks): the lake grid's multigrid, hierarchy and
    repair kernels, which the warm-up's tiny strip does not reach.
    """
    if not any(item.get_closest_marker("gui") for item in session.items):
        return
    from app.pipeline import warmup
    from meshcore import testing
    from meshcore.cellsize import default_cell_size
    from meshcore.lakegrid import mesh_layout
    from meshcore.layout import auto_layout

    warmup()
    lake = testing.lake_with_islands(1)
    mesh_layout(auto_layout(lake, cell_size=3 * default_cell_size(lake.area)))


@pytest.fixture(autouse=True)
def _qt_garbage_collected_in_the_gui_thread():
    """Collect each test's garbage here, in the GUI thread, after its windows closed.

    A window dropped by a test sits in reference cycles (psygnal connections to its methods)
    until Python's cyclic collector runs — in whatever thread allocates at that moment.  When
    that was the next test's layout worker (scipy's Voronoi allocating), ``QObject::~QObject``
    of the old window's objects ran there and deadlocked with the GUI thread's paint: the suite
    hung in ``test_lake.py`` (py-spy: the worker in ``Shiboken::GilState::acquire``).
    """
    yield
    gc.collect()


@pytest.fixture
def win(qtbot, tmp_path):
    from PySide6 import QtCore

    from app.main_window import MainWindow
    from app.window_frame import LIVE

    settings = QtCore.QSettings(str(tmp_path / "settings.ini"), QtCore.QSettings.Format.IniFormat)
    # Live (auto-generate) off for lakes, as a user who turned it off: the app's default is on for a lake's
    # layout (tests/app/test_app33.py checks it); these tests solve a layout when they say so (F5, or Live
    # switched on by a click)
    settings.setValue(LIVE["lake"][0], False)
    w = MainWindow(settings=settings, recovery=tmp_path / "recovery.gcmesh")
    w.quiet = True  # no modal dialogs in tests: errors go to the status bar
    qtbot.addWidget(w)
    w.resize(1200, 800)
    w.show()
    qtbot.waitExposed(w)
    yield w
    # a busy machine may need long for a worker to reach its next sweep; it must get there
    assert w.solver.shutdown(msecs=120_000), "a solver worker did not stop"
    w.stack.setClean()
