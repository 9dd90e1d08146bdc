"""The app's solve of a case against the library's (the CLI's), same case, same machine, same run.

Run from the repository root (no display needed)::

    python benchmarks/app_vs_cli.py [CASE.toml ...] [--repeats 3]

CLI = what ``meshcore generate CASE`` does after reading its arguments:
``generate_case(load_case(CASE))``, timed in this process after one warm-up call.
App = the main window (offscreen) opens the case, *Generate* is pressed and the clock stops
when the solver controller reports the grid (every live redraw of the solve included).
Both use the case's own solver settings.  CPU seconds are counted too (the CLI's thread; the
app's solver thread): on a loaded machine the two threads of the app wait for each other's
turn on the GIL and the CPU, so the wall-clock ratio grows with the load while the CPU ratio
says whether the app does more work.  The lines printed are
``name<TAB>cli_s<TAB>app_s<TAB>cli_cpu_s<TAB>app_cpu_s`` (medians), for
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
DEFAULT_CASES = ("shasta-multiblock-fine", "naca0012-ogrid", "bottle-orthogonal")


def cli_seconds(path: Path, repeats: int) -> tuple[float, float]:
    from meshcore.case import generate_case, load_case

    generate_case(load_case(path))  # warm-up: kernels loaded
    ts, cs = [], []
    for _ in range(repeats):
        t, c = time.perf_counter(), time.thread_time()
        generate_case(load_case(path))
        ts.append(time.perf_counter() - t)
        cs.append(time.thread_time() - c)
    return statistics.median(ts), statistics.median(cs)


def app_seconds(path: Path, repeats: int) -> tuple[float, float]:
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
    win = MainWindow()
    win.quiet = True
    win.resize(1400, 880)
    win.show()
    loop = QtCore.QEventLoop()  # the app's own event loop waits (no polling that eats a core)
    win.solver.finished.connect(lambda _result: loop.quit())
    ts = []
    for k in range(repeats + 1):  # the first run warms up like the CLI's
        if not win.io.open_path(path):
            raise SystemExit(f"the app could not open {path}")
        app.processEvents()
        t = time.perf_counter()
        win.generate()
        loop.exec()
        if not win.doc.grids:
            raise SystemExit(f"the app's solve of {path.name} gave no grid ({win.solver.last_error})")
        if k:
            ts.append(time.perf_counter() - t)
    controller.solve_project = solve
    win.stack.setClean()
    win.close()
    return statistics.median(ts), statistics.median(cpu[1:])


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("cases", nargs="*", default=list(DEFAULT_CASES))
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args(argv)
    for name in args.cases:
        path = Path(name)
        if not path.suffix:
            path = ROOT / "resources" / "examples" / f"{name}.toml"
        cli, cli_cpu = cli_seconds(path, args.repeats)
        gui, gui_cpu = app_seconds(path, args.repeats)
        print(f"{path.stem}\t{cli:.4f}\t{gui:.4f}\t{cli_cpu:.4f}\t{gui_cpu:.4f}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
