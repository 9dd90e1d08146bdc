"""Measure the app's interactive numbers (offscreen is fine)::

    python -m app.bench [lake] [--profile FILE] [--live-off]

* redraws/s of the grid curve at 257×257 nodes (setData + forced paint), and
  the live rate the window reaches during a solve at that size;
* Stop latency during a long solve;
* drag-to-converged latency with auto-generate on a ~100×100 grid;
* Lake Como (~10 000 cells): import → Auto layout → orthogonal grid → Delft3D DD export, the
  computing time of each step; then a cut line's end dragged along the shore with
  auto-generate on: redraws/s while dragging and the frames that showed a start grid (0);
  ``--live-off``: the drag again with auto-generate off and F5 at the release (the new grid's wait);
* start-up time of the main window (see also ``python -m app --screenshot``).
"""

from __future__ import annotations

import os
import statistics
import sys
import time
from typing import Any

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")


def _wait(app, cond, timeout=60.0):
    """Process events until ``cond()``; seconds waited.  Blocks for events between checks (a timer
    wakes it every 5 ms) instead of spinning: a busy loop would take a core, and CPU time, from the
    worker threads it waits for."""
    from PySide6 import QtCore

    wake = QtCore.QTimer()
    wake.start(5)
    flags = QtCore.QEventLoop.ProcessEventsFlag.AllEvents | QtCore.QEventLoop.ProcessEventsFlag.WaitForMoreEvents
    t0 = time.perf_counter()
    try:
        while not cond():
            app.processEvents(flags)
            if time.perf_counter() - t0 > timeout:
                raise TimeoutError
    finally:
        wake.stop()
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
    args = sys.argv[1:]
    profile = args[args.index("--profile") + 1] if "--profile" in args else None
    if "lake" not in args:  # ``python -m app.bench lake``: the lake rows only
        redraw_rate(win)
        live_rate_and_stop(app, win)
        drag_to_converged(app, win)
    lake_como(app, win, profile=profile, live_off="--live-off" in args)
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
    if not win.solver.auto:  # on already when the user's last session left it on (remembered)
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


def lake_como(app, win, profile: str | None = None, live_off: bool = False) -> None:
    """Como in, layout out, grid, .ddb; then a cut line's end dragged along the shore (auto-generate).

    ``profile``: a file for the cProfile statistics of the drag (the GUI thread's CPU time).
    """
    import tempfile
    from pathlib import Path

    como = Path(__file__).resolve().parent.parent / "benchmarks" / "lakes" / "lake_como.geojson"
    if win.solver.auto:
        win.a_auto.trigger()
    # step -> (wall s, CPU s of the process (every thread), CPU s of the GUI thread)
    steps: dict[str, tuple[float, float, float]] = {}

    def step(name: str, run) -> Any:
        t, c, g = time.perf_counter(), time.process_time(), time.thread_time()
        out = run()
        steps[name] = (time.perf_counter() - t, time.process_time() - c, time.thread_time() - g)
        return out

    step("import", lambda: win.io.import_points(como, project_lonlat=True))
    step("auto layout", lambda: (win.lake_ctl.auto_layout(), _wait(app, lambda: not win.lake_ctl.busy, timeout=300)))
    step(
        "orthogonal grid",
        lambda: _wait(app, lambda: not win.solver.running and not win.solver._debounce.isActive(), timeout=600),
    )
    lay = win.doc.project.layout
    with tempfile.TemporaryDirectory() as d:
        ok = step("Delft3D DD", lambda: win.io.export_mesh(Path(d) / "como.ddb"))
    m = win.doc.lake_metrics
    wall, cpu = (sum(v[k] for v in steps.values()) for k in (0, 1))
    print(
        f"Como: {len(lay.blocks)} blocks, {lay.n_cells} cells, {m.summary()['folded_cells']} folded, mean deviation "
        f"{m.mean('deviation'):.2f}°, Delft3D DD {'written' if ok else 'REFUSED'}; load {os.getloadavg()[0]:.1f}"
    )
    for name, (w, c, g) in steps.items():
        print(f"  {name:16s} CPU {c:5.1f} s (GUI thread {g:4.1f} s)   wall {w:5.1f} s")
    print(f"Como import -> Delft3D DD: computing (CPU) {cpu:.1f} s, wall {wall:.1f} s")
    drag_cut_end(app, win, profile=profile)
    if live_off:  # the same drag with auto-generate off, back and forth: what Live saves a modeller
        win.stack.undo()
        _wait(app, lambda: not win.lake_ctl.editing and not win.solver.running, timeout=600)
        drag_cut_end(app, win, live=False)


def _thread_cpu() -> dict[int, float]:
    """CPU seconds (user + system) of every thread of this process by its native id (Linux; else {})."""
    out = {}
    tick = os.sysconf("SC_CLK_TCK") if hasattr(os, "sysconf") else 100
    try:
        tasks = os.listdir("/proc/self/task")
    except OSError:
        return out
    for t in tasks:
        try:
            with open(f"/proc/self/task/{t}/stat") as f:
                fields = f.read().rsplit(")", 1)[1].split()
        except OSError:  # the thread ended
            continue
        out[int(t)] = (int(fields[11]) + int(fields[12])) / tick  # utime, stime
    return out


def drag_cut_end(app, win, profile: str | None = None, *, live: bool = True) -> dict:
    """A cut line's end of the window's lake layout dragged along the shore with auto-generate on:
    redraws/s of wall time, the CPU time per redraw of the GUI thread and of the other threads
    (the solver and layout workers), and the redraws that showed a start grid (must be 0).
    ``live`` False: auto-generate off (the old grid greyed while dragging), F5 pressed at the release;
    "done after release" is then the wait for the new grid after F5.

    The start-grid check runs after the drag (the frames' grids are kept until then): it would
    otherwise count in the GUI thread's CPU time it measures.  ``profile``: a file for the
    cProfile statistics of the drag (the GUI thread's CPU time).  Returns the numbers printed.
    """
    import threading

    import numpy as np

    from app.layout_edit import handles, place

    lay = win.doc.project.layout
    if win.solver.auto != live:
        win.a_auto.trigger()  # auto-generate on: the grid follows the layout
    win.set_tool("layout")
    end = next(h for h in handles(lay) if h.kind == "end")
    tool = win.tools["layout"]
    frames: list[float] = []
    shown: list[tuple] = []  # per redraw: (grid, its algebraic start grid) of every block, checked after the drag

    def redrawn() -> None:
        frames.append(time.perf_counter())
        doc = win.doc
        shown.append(tuple((g, doc.initial.get(k)) for k, g in doc.grids.items()))

    win.solver.redrawn.connect(redrawn)
    layouts: list[float] = []  # the layouts shown while dragging (each restarts the solve)

    def laid(lay) -> None:
        if lay is not None:
            layouts.append(time.perf_counter())

    win.lake_ctl.layout_done.connect(laid)
    import app.layout_edit as edit

    made: list[float] = []  # per layout the worker made: CPU seconds of its thread in moved_layout
    moved = edit.moved_layout

    def timed(*args):  # the tool looks moved_layout up at each step: this one is timed
        c = time.thread_time()
        try:
            return moved(*args)
        finally:
            made.append(time.thread_time() - c)

    edit.moved_layout = timed
    h = lay.cell_size
    prof = None
    if profile:
        import cProfile

        prof = cProfile.Profile(time.thread_time)  # the GUI thread's CPU time, not the load's wall time
        prof.enable()
    gui_id = threading.get_native_id()
    threads0 = _thread_cpu()
    t_drag, c_drag, g_drag = time.perf_counter(), time.process_time(), time.thread_time()
    tool.drag("start", end.xy, end.xy)
    for s in np.linspace(0, 1, 180)[1:]:  # 3 s at 60 Hz: three cells along the shore and back
        f = 3 * h * np.sin(np.pi * s)
        tool.drag("move", place(lay, end, (end.xy[0] + f, end.xy[1] + f)), end.xy)
        _sleep(app, 1 / 60)
    tool.drag("finish", place(lay, end, (end.xy[0] + h, end.xy[1] + h)), end.xy)
    t_release, c_release, g_release = time.perf_counter(), time.process_time(), time.thread_time()
    threads1 = _thread_cpu()
    if not live:  # the user presses F5 once the drag's last layout is shown
        _wait(app, lambda: not win.lake_ctl.editing, timeout=600)
        win.a_generate.trigger()
    if prof is not None:
        prof.disable()
        prof.dump_stats(profile)
    n_during = len([f for f in frames if t_drag <= f <= t_release])
    n_made = len(made)
    dt = _wait(app, lambda: not win.lake_ctl.editing and not win.solver.running, timeout=600)
    edit.moved_layout = moved
    win.solver.redrawn.disconnect(redrawn)
    win.lake_ctl.layout_done.disconnect(laid)
    starts = sum(any(_is_start(g, a) for g, a in frame) for frame in shown)
    n_lay = len([t for t in layouts if t <= t_release])
    wall, cpu, gui = t_release - t_drag, c_release - c_drag, g_release - g_drag
    others = {t: c - threads0.get(t, 0.0) for t, c in threads1.items() if t != gui_id}
    busy = sorted((c for c in others.values() if c >= 0.05), reverse=True)
    n = max(n_during, 1)
    how = "on" if live else "off, F5 at release"
    print(
        f"drag a cut end on Como ({lay.n_cells} cells, auto-generate {how}; load {os.getloadavg()[0]:.1f}): "
        f"{n_during / wall:.1f} redraws/s while dragging ({n_during} in {wall:.1f} s wall for 3 s of mouse "
        f"moves); {n_lay / wall:.1f} layouts/s while dragging, {n_lay / max(cpu, 1e-9):.1f} per CPU-s "
        f"({n_lay} shown, {n_made} made, "
        f"{1000 * sum(made[:n_made]) / max(n_made, 1):.0f} ms CPU each in the layout worker); "
        f"CPU while dragging {cpu:.1f} s (GUI thread {gui:.1f} s): "
        f"{n_during / max(cpu, 1e-9):.1f} redraws per CPU-s; {starts} of {len(frames)} redraws showed a "
        f"start grid, done {dt:.1f} s after release ({win.stack.undoText()!r}, {win.lake_ctl.edit_error or 'no error'})"
    )
    print(
        f"  CPU per redraw: GUI thread {1000 * gui / n:.1f} ms, other threads {1000 * (cpu - gui) / n:.1f} ms "
        f"(busiest: {', '.join(f'{c:.1f}' for c in busy[:4]) or '-'} s)"
    )
    return {
        "redraws": n_during,
        "wall": wall,
        "cpu": cpu,
        "gui": gui,
        "layouts": n_lay,
        "layout_cpu": sum(made[:n_made]) / max(n_made, 1),
        "start_frames": starts,
        "frames": len(frames),
    }


def _is_start(grid, algebraic) -> bool:
    """True when ``grid`` is the algebraic start grid (the raw TFI / weighted average, unsmoothed)."""
    import numpy as np

    if algebraic is None or grid.shape != algebraic.shape:
        return False
    if grid is algebraic:
        return True
    # every 7th node first: a smoothed grid differs there (the check runs in the GUI thread it measures)
    few = (slice(None, None, 7), slice(None, None, 7))
    if not np.array_equal(grid.x[few], algebraic.x[few]):
        return False
    return np.array_equal(grid.x, algebraic.x) and np.array_equal(grid.y, algebraic.y)


if __name__ == "__main__":
    sys.exit(main())
