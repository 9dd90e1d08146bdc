"""The app's solve of a case against the library's (the CLI's), same case, same machine, same run.

Run from the repository root (no display needed)::

    python benchmarks/app_vs_cli.py [CASE.toml ...] [--repeats 3]

CLI = what ``meshcore generate CASE -q`` does after reading its arguments:
``generate_case(load_case(CASE))`` and the quality report of every block (the command's folded-cell
check), timed in this process after one warm-up call.
App = the main window (offscreen) opens the case, *Generate* is pressed and the clock stops
when the solver controller reports the grid (every live redraw of the solve included).
Both use the case's own solver settings.

A lake outline (``.kml``, ``.geojson``, ``.csv``…, e.g. ``benchmarks/lakes/taal_lake.kml``) is
compared on its automatic layout, the way a user makes its grid: CLI = the grid and quality stages of
``meshcore mesh FILE`` (its layout made with :class:`meshcore.lakegrid.CoarseReadings`, not timed, then
:func:`meshcore.lakegrid.mesh_layout` going on from the chosen layout's coarse level as the command
does, then :func:`meshcore.quality.lake_metrics`, which the app measures before it shows the grid);
app = the window (Live as a user gets it: on for a lake's layout) imports the file, *Auto layout* runs
and the grid follows by itself, timed from the layout set to the grid.  The run stops with an error
when the two layouts differ (blocks or cells), the grids' nodes are not identical, or the app solved
the grid more than once.

CPU seconds are counted too (the CLI's thread; the
app's solver thread): on a loaded machine the two threads of the app wait for each other's
turn on the GIL and the CPU, so the wall-clock ratio grows with the load while the CPU ratio
says whether the app does more work.  The lines printed are
``name<TAB>cli_s<TAB>app_s<TAB>cli_cpu_s<TAB>app_cpu_s<TAB>app_process_cpu_s`` (medians; the last
is every thread of the app during the solve: the solver's, the drawing's), for
``benchmarks/robust.py --section app`` to read.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from pathlib import Path

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

#: Cases of resources/examples: a 7-block lake (multiblock Winslow), a single block with wall
#: control and an orthogonal-mode multiblock case.
DEFAULT_CASES = ("shasta-multiblock-fine", "naca0012-ogrid", "bottle-orthogonal", "taal_lake.kml")
#: Suffixes read as lake outlines (the rest are case files).
OUTLINES = (".kml", ".kmz", ".geojson", ".json", ".csv", ".txt", ".shp", ".dxf")


def _cli_lake_layout(path: Path, readings=None):
    """The layout ``meshcore mesh FILE`` makes (its own reading, projection and cell size; ``readings``: a
    :class:`~meshcore.lakegrid.CoarseReadings` that keeps the coarse level of the chosen layout solved)."""
    import argparse

    from meshcore.cli import mesh

    parser = argparse.ArgumentParser()
    mesh.add_args(parser)  # every option at its default, as the command line gives them
    ns = parser.parse_args([str(path)])
    say = mesh._Say(quiet=True)
    poly, _frame = mesh._read(ns, say)
    h, _ = mesh._cell_size(ns, poly, "")
    return mesh._layout(ns, poly, h, False, say, readings=readings)


def cli_lake_seconds(path: Path, repeats: int):
    from meshcore.cli.mesh_steps import LEVELS
    from meshcore.lakegrid import CoarseReadings, mesh_layout
    from meshcore.quality import lake_metrics

    lay = _cli_lake_layout(path)
    mesh_layout(lay, levels=LEVELS)  # warm-up
    ts, cs = [], []
    for _ in range(repeats):
        readings = CoarseReadings(levels=LEVELS)  # as meshcore mesh: the grid goes on from the layout's reading
        lay = _cli_lake_layout(path, readings)
        t, c = time.perf_counter(), time.thread_time()
        mb = mesh_layout(lay, levels=LEVELS, readings=readings)
        lake_metrics(mb, polygon=lay.polygon, cell_size=lay.cell_size)  # the CLI's quality stage, as the app's
        ts.append(time.perf_counter() - t)
        cs.append(time.thread_time() - c)
    return statistics.median(ts), statistics.median(cs), lay, mb


def cli_seconds(path: Path, repeats: int) -> tuple[float, float]:
    """``meshcore generate CASE -q``'s work: the grid, then the quality report of every block, which
    the command makes even when quiet (its folded-cell check; the app shows it with the grid)."""
    from meshcore.case import generate_case, load_case
    from meshcore.quality import quality

    def run():
        result = generate_case(load_case(path))
        return [quality(g) for g in getattr(result, "blocks", result)]  # as the command: a list or blocks

    run()  # warm-up: kernels loaded
    ts, cs = [], []
    for _ in range(repeats):
        t, c = time.perf_counter(), time.thread_time()
        run()
        ts.append(time.perf_counter() - t)
        cs.append(time.thread_time() - c)
    return statistics.median(ts), statistics.median(cs)


def _lake_grid_in(win, path: Path, loop) -> tuple[float, float]:
    """Import a lake outline into the window, press *Auto layout* and wait for the grid that follows it;
    ``(wall, process CPU)`` seconds from the layout set (its grid begins) to the grid."""
    if not win.io.open_path(path):
        raise SystemExit(f"the app could not open {path}")
    win.lake_ctl.generate_after = True  # (the default) the grid follows the layout, as a user gets it
    began: list = []
    failed: list = []

    def set_(lay) -> None:
        if lay is None:
            failed.append(win.lake_ctl.last_error)
            loop.quit()
        else:
            began.append((time.perf_counter(), time.process_time()))

    win.lake_ctl.layout_done.connect(set_)
    try:
        if not win.lake_ctl.auto_layout():
            raise SystemExit(f"the app could not lay out {path}")
        loop.exec()  # until the solver reports the grid
    finally:
        win.lake_ctl.layout_done.disconnect(set_)
    if failed or not began:
        raise SystemExit(f"the app's layout of {path} failed: {failed}")
    return time.perf_counter() - began[0][0], time.process_time() - began[0][1]


def window(app, main_window):
    """The main window as a user who watches the solve sees it: 1400 × 880, the default dock layout (not
    the one another run saved: settings in a temporary file) with the convergence plot shown.

    The window's layout is restored from the user's settings, which every app window (tests, other
    runs) writes when it closes: the convergence plot, a tab beside the messages, was shown in some runs
    and hidden in others, and it is most of the GUI thread's drawing in a live frame.
    """
    import tempfile

    from PySide6 import QtCore

    # one file, emptied for each window (Qt writes it back when the window's settings are dropped, after
    # any clean-up at exit: a folder per run was left behind by every run)
    ini = Path(tempfile.gettempdir()) / "gcmesh-app_vs_cli-settings.ini"
    ini.unlink(missing_ok=True)
    win = main_window(settings=QtCore.QSettings(str(ini), QtCore.QSettings.Format.IniFormat))
    win.quiet = True
    win.fit_on_show = False  # the offscreen screen is 800 × 800: keep the size asked for
    win.resize(1400, 880)
    win.show()
    win.docks["convergence"].raise_()
    app.processEvents()
    return win


def app_seconds(path: Path, repeats: int, lake: bool = False) -> tuple[float, float, object]:
    from PySide6 import QtCore, QtWidgets

    import app.solver_controller as controller
    from app.main_window import MainWindow

    cpu: list[float] = []
    solve = controller.solve_project

    def counted(*args, **kwargs):  # the solver thread's CPU time of one solve
        c = time.thread_time()
        result = yield from solve(*args, **kwargs)
        cpu.append(time.thread_time() - c)
        return result

    controller.solve_project = counted

    app = QtWidgets.QApplication.instance() or QtWidgets.QApplication(sys.argv[:1])
    win = window(app, MainWindow)
    loop = QtCore.QEventLoop()  # the app's own event loop waits (no polling that eats a core)
    win.solver.finished.connect(lambda _result: loop.quit())
    ts, proc = [], []
    for k in range(repeats + 1):  # the first run warms up like the CLI's
        n = len(cpu)
        if lake:
            wall, pcpu = _lake_grid_in(win, path, loop)
        else:
            if not win.io.open_path(path):
                raise SystemExit(f"the app could not open {path}")
            app.processEvents()
            t, pc = time.perf_counter(), time.process_time()
            win.generate()
            loop.exec()
            wall, pcpu = time.perf_counter() - t, time.process_time() - pc
        if not win.doc.grids:
            raise SystemExit(f"the app's solve of {path.name} gave no grid ({win.solver.last_error})")
        if len(cpu) != n + 1:
            raise SystemExit(f"the app solved {path.name} {len(cpu) - n} times for one grid")
        if k:
            ts.append(wall)
            proc.append(pcpu)
    controller.solve_project = solve
    mb = win.doc.multiblock if lake else None
    win.stack.setClean()
    win.close()
    return statistics.median(ts), statistics.median(cpu[1:]), mb, statistics.median(proc)


def same_lake_grid(path: Path, cli_layout, cli_mb, app_mb) -> None:
    """Stop unless the app made the CLI's layout and grid (nodes equal up to the local origin)."""
    import numpy as np

    if app_mb is None:
        raise SystemExit(f"{path.name}: the app kept no multiblock grid")
    a = [g.cells for g in cli_mb.grids]
    b = [g.cells for g in app_mb.grids]
    if a != b:
        raise SystemExit(f"{path.name}: the layouts differ: CLI {len(a)} blocks {a}, app {len(b)} blocks {b}")
    for k, (g, h) in enumerate(zip(cli_mb.grids, app_mb.grids, strict=True)):
        if not (np.array_equal(g.x, h.x) and np.array_equal(g.y, h.y)):
            d = max(np.abs(g.x - h.x).max(), np.abs(g.y - h.y).max())
            raise SystemExit(f"{path.name}: block {k}: the grids differ (largest node distance {d:.3g})")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("cases", nargs="*", default=list(DEFAULT_CASES))
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args(argv)
    for name in args.cases:
        path = Path(name)
        if not path.suffix:
            path = ROOT / "resources" / "examples" / f"{name}.toml"
        if path.suffix.lower() in OUTLINES:
            if not path.exists():
                path = ROOT / "benchmarks" / "lakes" / path.name
            cli, cli_cpu, lay, cli_mb = cli_lake_seconds(path, args.repeats)
            gui, gui_cpu, app_mb, gui_proc = app_seconds(path, args.repeats, lake=True)
            same_lake_grid(path, lay, cli_mb, app_mb)
        else:
            cli, cli_cpu = cli_seconds(path, args.repeats)
            gui, gui_cpu, _, gui_proc = app_seconds(path, args.repeats)
        print(f"{path.stem}\t{cli:.4f}\t{gui:.4f}\t{cli_cpu:.4f}\t{gui_cpu:.4f}\t{gui_proc:.4f}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
