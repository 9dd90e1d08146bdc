"""Measure the app's interactive numbers: ``python -m app.bench`` (offscreen is fine).

* redraws/s of the grid curve at 257×257 nodes (setData + forced paint), and
  the live rate the window reaches during a solve at that size;
* Stop latency during a long solve;
* drag-to-converged latency with auto-generate on a ~100×100 grid;
* start-up time of the main window (see also ``python -m app --screenshot``).
"""

from __future__ import annotations

import os
import statistics
import sys
import time

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")


def _wait(app, cond, timeout=60.0):
    from PySide6 import QtCore

    t0 = time.perf_counter()
    while not cond():
        app.processEvents(QtCore.QEventLoop.ProcessEventsFlag.AllEvents, 5)
        if time.perf_counter() - t0 > timeout:
            raise TimeoutError
    return time.perf_counter() - t0


def _sleep(app, seconds):
    t_end = time.perf_counter() + seconds
    _wait(app, lambda: time.perf_counter() >= t_end)


def main() -> int:
    t0 = time.perf_counter()
    import meshcore.elliptic

    meshcore.elliptic.warmup()
    from PySide6 import QtWidgets

    from app.main_window import MainWindow

    app = QtWidgets.QApplication.instance() or QtWidgets.QApplication(sys.argv[:1])
    win = MainWindow()
    win.quiet = True
    win.resize(1400, 880)
    win.show()
    app.processEvents()
    print(f"start-up to a shown window (warm numba cache, in-process): {time.perf_counter() - t0:.2f} s")
    redraw_rate(win)
    live_rate_and_stop(app, win)
    drag_to_converged(app, win)
    win.stack.setClean()
    win.close()
    return 0


def redraw_rate(win, n: int = 257) -> None:
    """Raw redraw rate of the grid curve at ``n`` × ``n`` nodes (setData + forced paint)."""
    import numpy as np

    from meshcore import StructuredGrid

    xi, eta = np.meshgrid(np.linspace(0, 1, n), np.linspace(0, 1, n), indexing="ij")
    win.canvas.zoom_to((0, 0, 1, 1))
    times = []
    for k in range(30):
        g = StructuredGrid(xi + 0.01 * np.sin(k + 6 * eta), eta)
        t = time.perf_counter()
        win.canvas.set_grids({0: g})
        win.canvas.viewport().repaint()
        times.append(time.perf_counter() - t)
    med = statistics.median(times)
    print(f"redraw {n}x{n} (setData + paint): median {med * 1000:.1f} ms = {1 / med:.1f} redraws/s")


def live_rate_and_stop(app, win) -> None:
    """Live redraws during a 257 × 257 solve, then the Stop latency."""
    win.io.open_example("bottle-fine", confirm=False)
    win.editor.set_block_options(cells=(256, 256))
    win.editor.set_solver(method="sor", tolerance=1e-300, max_iterations=10_000_000)
    frames = []
    win.solver.redrawn.connect(lambda: frames.append(time.perf_counter()))
    win.generate()
    _wait(app, lambda: len(frames) > 0)
    t = time.perf_counter()
    _sleep(app, 3.0)
    fr = [f for f in frames if f >= t]
    print(f"live redraws during a 257x257 solve: {len(fr) / 3.0:.1f} /s")
    lat = []
    for _ in range(5):
        if not win.solver.running:
            win.generate()
            _wait(app, lambda: win.solver.running)
            _sleep(app, 0.5)
        t = time.perf_counter()
        win.solver.stop()
        lat.append(_wait(app, lambda: not win.solver.running))
    print(f"stop latency (5 runs): median {statistics.median(lat) * 1000:.0f} ms, max {max(lat) * 1000:.0f} ms")


def drag_to_converged(app, win) -> None:
    """Drag a corner of a ~100 × 100 grid with auto-generate on; time from release to converged."""
    import numpy as np

    win.io.open_example("annulus-sector", confirm=False)
    win.editor.set_block_options(cells=(100, 100))
    win.editor.set_solver(method="auto")
    win.a_auto.trigger()
    _wait(app, lambda: not win.solver.running and win.doc.grid is not None)
    k = int(win.doc.block.corners[2])
    p = np.array(win.doc.block.points[k])
    results = []
    delta = np.array([0.15, 0.075])
    frames = []
    start_frames = []  # redraws that showed an algebraic start grid (the flicker of issue 13)

    def redrawn() -> None:
        frames.append(time.perf_counter())
        doc = win.doc
        if any(_is_start(g, doc.initial.get(k)) for k, g in doc.grids.items()):
            start_frames.append(frames[-1])

    win.solver.redrawn.connect(redrawn)
    for rep in range(6):  # drag the NE corner out and back, ~0.5 s per drag at 60 Hz
        drag = win.editor.new_drag_id()
        t_drag = time.perf_counter()
        for s in np.linspace(0, 1, 30)[1:]:
            f = s if rep % 2 == 0 else 1.0 - s
            win.editor.set_points([k], [p + f * delta], drag_id=drag)
            _sleep(app, 1 / 60)
        t_release = time.perf_counter()
        dt = _wait(app, lambda: not win.solver.running and not win.solver._debounce.isActive())
        g = win.doc.grid
        results.append(dt)
        previews = [t for t in frames if t_drag <= t <= t_release]
        starts = [t for t in start_frames if t >= t_drag]
        print(
            f"  drag {rep}: {len(previews)} preview redraws while dragging, {len(starts)} of them "
            f"showed a start grid; converged={g.converged} ({g.info.method}, {g.iterations} it) "
            f"{dt * 1000:.0f} ms after release"
        )
    print(f"drag-to-converged 101x101 nodes: median {statistics.median(results) * 1000:.0f} ms")
    print(f"redraws showing an algebraic start grid during the drags: {len(start_frames)} of {len(frames)}")


def _is_start(grid, algebraic) -> bool:
    """True when ``grid`` is the algebraic start grid (the raw TFI / weighted average, unsmoothed)."""
    import numpy as np

    if algebraic is None or grid.shape != algebraic.shape:
        return False
    return grid is algebraic or (np.array_equal(grid.x, algebraic.x) and np.array_equal(grid.y, algebraic.y))


if __name__ == "__main__":
    sys.exit(main())
