"""The app's GUI-thread stalls on large cases, measured with a heartbeat (a 10 ms QTimer in the GUI thread).

A single block of a generated lake's shore (:func:`meshcore.testing.lake_with_islands`, its outline only)
with TOTAL cells along its longer side (1500: 1 752 000 cells), in an off-screen main window::

    python benchmarks/gui_stalls.py solve TOTAL STOP_AT [--before]
    python benchmarks/gui_stalls.py steps TOTAL STEP...      (STEP: import layout draw colour export)
    python benchmarks/gui_stalls.py restop CELLS STOP_AT

``solve``: Generate, Stop after STOP_AT seconds (0: let it finish), then wait until the quality report is
in; prints the longest gaps of the heartbeat (the GUI thread's stalls) and the longest one from Stop on.
``--before``: the quality measured in the GUI thread, as before session 29 (``Document.measure_async``
None).  ``steps``: the stall and the GUI thread's CPU time of each step: three imports of a 40 000-point outline
(the second and third replace the lake), Auto layout of it (``import layout``), the drawing
and measure of the grid, colouring it by skewness and back, export to .vtm and EFDC.  Timings are wall
time on a shared machine: compare runs made side by side.  Session 29 numbers: ``benchmarks/RESULTS.md``.
``restop``: a generated lake with islands laid out at about CELLS cells and solved; one block's cells
changed (a cold solve), Stop after STOP_AT seconds (on a coarse level): what the canvas shows after the
Stop (the grid of before the edit, or a coarse level's frames) and the longest stall from Stop on.
"""

from __future__ import annotations

import os
import pathlib
import sys
import tempfile
import time

import numpy as np

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")


def _window():
    from PySide6 import QtCore, QtWidgets

    from app.main_window import MainWindow

    app = QtWidgets.QApplication.instance() or QtWidgets.QApplication([])
    tmp = pathlib.Path(tempfile.mkdtemp())
    settings = QtCore.QSettings(str(tmp / "s.ini"), QtCore.QSettings.Format.IniFormat)
    win = MainWindow(settings=settings, recovery=tmp / "r.gcmesh")
    win.quiet = True
    win.resize(1200, 800)
    win.show()
    beats: list[float] = []
    heart = QtCore.QTimer()
    heart.setInterval(10)
    heart.timeout.connect(lambda: beats.append(time.perf_counter()))
    heart.start()
    return app, win, beats, heart, tmp


def _run_until(cond, limit: float) -> None:
    """Run the event loop (sleeping in it, as the app does) until ``cond()`` or ``limit`` seconds."""
    from PySide6 import QtCore

    loop, check, t0 = QtCore.QEventLoop(), QtCore.QTimer(), time.perf_counter()
    check.setInterval(100)
    check.timeout.connect(lambda: loop.quit() if cond() or time.perf_counter() - t0 > limit else None)
    check.start()
    loop.exec()
    check.stop()


def _block(total: int):
    from app.project import block_from_points
    from meshcore import testing

    poly = testing.lake_with_islands(1)
    return block_from_points(np.asarray(poly.exterior.coords)[:-1] * 300, "lake", total=total)


def solve(total: int, stop_at: float, before: bool) -> None:
    from PySide6 import QtCore

    from app.project import Project

    _app, win, beats, _heart, _tmp = _window()
    blk = _block(total)
    print(f"{blk.cells[0] * blk.cells[1]:,} cells{' (quality in the GUI thread)' if before else ''}", flush=True)
    win.io.set_project(Project(blocks=(blk,)))
    if before:
        win.doc.measure_async = None
    marks: dict[str, float] = {}
    win.solver.finished.connect(lambda _r: marks.setdefault("finished", time.perf_counter()))
    win.doc.quality_changed.connect(
        lambda: marks.setdefault("quality", time.perf_counter()) if win.doc.quality else None
    )
    t0 = time.perf_counter()
    win.generate()
    if stop_at > 0:
        QtCore.QTimer.singleShot(
            int(stop_at * 1000), lambda: (marks.setdefault("stop", time.perf_counter()), win.a_stop.trigger())
        )
    _run_until(lambda: "finished" in marks, 900)
    _run_until(lambda: win.doc.quality is not None and time.perf_counter() - marks.get("quality", 1e18) > 2, 60)
    b = np.array(beats)
    gaps = np.diff(b)
    since = gaps[b[1:] > marks.get("stop", marks.get("finished", t0)) - 0.5]
    top = np.argsort(gaps)[::-1][:3]
    print("at (s):", {k: round(v - t0, 1) for k, v in marks.items()}, "|", win.solve_status.label.text())
    print(f"longest stall from Stop (or the end) on: {since.max():.2f} s; longest three (ending at s, length s):",
          [(round(b[j + 1] - t0, 1), round(gaps[j], 2)) for j in top])  # fmt: skip
    win.solver.shutdown()
    win.close()


def steps(total: int, names: list[str]) -> None:
    from app.pipeline import block_initial_grid
    from app.project import Project

    _app, win, beats, _heart, tmp = _window()

    def busy() -> bool:
        return win.lake_ctl.busy or win.solver.running or win.measurer.busy or win.io.exporting

    def measure(name, action, limit=600) -> None:
        _run_until(lambda: False, 0.3)
        t0, n0, c0 = time.perf_counter(), len(beats), time.thread_time()
        action()
        _run_until(lambda: not busy(), limit)
        b = np.array([t0, *beats[n0:]])
        print(
            f"{name}: longest stall {np.diff(b).max():.2f} s, GUI thread CPU {time.thread_time() - c0:.2f} s, "
            f"done after {time.perf_counter() - t0:.1f} s",
            flush=True,
        )

    if "import" in names:
        t = np.linspace(0, 2 * np.pi, 40000, endpoint=False)
        r = 1000 * (1 + 0.3 * np.sin(7 * t) + 0.05 * np.sin(97 * t))
        csv = tmp / "big.csv"
        rows = (f"{a:.3f},{b:.3f}" for a, b in zip(r * np.cos(t), 0.6 * r * np.sin(t), strict=True))
        csv.write_text("x,y\n" + "\n".join(rows) + "\n")
        for k in range(3):  # the first import, then two that replace the lake
            measure(f"import {k + 1} of a 40 000-point outline", lambda: win.io.import_points(csv))
        if "layout" in names:
            measure("Auto layout", win.a_auto_layout.trigger)
    if any(s in names for s in ("draw", "colour", "export")):
        blk = _block(total)
        g = block_initial_grid(blk)
        win.io.set_project(Project(blocks=(blk,)))
        measure(f"draw and measure {g.cells[0] * g.cells[1]:,} cells", lambda: win.doc.set_grids({0: g}))
    if "colour" in names:
        measure("colour by skewness", lambda: win.doc.set_colour_by("skewness"))
        measure("colour off", lambda: win.doc.set_colour_by("none"))
    if "export" in names:
        measure("export .vtm", lambda: win.io.export_mesh(tmp / "out.vtm"))
        measure("export EFDC", lambda: win.io.export_mesh(tmp / "cell.inp"))
        measure("export Delft3D .grd", lambda: win.io.export_mesh(tmp / "out.grd"))
        print("written:", sorted(p.name for p in tmp.iterdir() if p.suffix in (".vtm", ".inp", ".grd", ".enc")))
    win.solver.shutdown()
    win.close()


def restop(cells: int, stop_at: float) -> None:
    import math

    import shapely

    from meshcore import testing

    _app, win, beats, _heart, tmp = _window()
    poly = shapely.affinity.scale(testing.lake_with_islands(1), 300, 300, origin=(0, 0))
    rows = ["x,y"]
    for k, ring in enumerate([poly.exterior, *poly.interiors]):
        rows += [""] * bool(k) + [f"{x:.2f},{y:.2f}" for x, y in ring.coords]
    csv = tmp / "lake.csv"
    csv.write_text("\n".join(rows) + "\n")
    win.io.import_points(csv)
    win.lake_ctl.set_cell_size(math.sqrt(poly.area / cells))
    win.a_auto_layout.trigger()
    _run_until(lambda: win.doc.project.layout is not None and not win.solver.running and not win.measurer.busy, 900)
    old = dict(win.doc.grids)
    print(f"{sum(g.cells[0] * g.cells[1] for g in old.values()):,} cells in {len(old)} blocks solved", flush=True)
    blk = win.doc.project.layout.blocks[0]
    win.lake_ctl.set_block_cells(0, (blk.cells[0] + 4, blk.cells[1]))
    _run_until(lambda: win.doc.project.layout.blocks[0].cells != blk.cells and not win.lake_ctl.editing, 300)
    win.generate()
    _run_until(lambda: False, stop_at)
    t0 = time.perf_counter()
    win.a_stop.trigger()
    _run_until(lambda: not win.solver.running and not win.measurer.busy, 300)
    b = np.array([t0, *(x for x in beats if x > t0)])
    shown = win.doc.grids or win.doc.before_grids
    kept = bool(shown) and all(shown.get(k) is g for k, g in old.items())
    what = "the grid of before the edit" if kept else "coarse frames"
    n = sum(g.cells[0] * g.cells[1] for g in shown.values())
    print(f"after Stop ({win.solve_status.label.text()}): shown {what}, {n:,} cells, greyed {not win.doc.grids}")
    print(f"longest stall from Stop on: {np.diff(b).max():.2f} s, Stop took {time.perf_counter() - t0:.1f} s")
    win.solver.shutdown()
    win.close()


if __name__ == "__main__":
    args = sys.argv[1:]
    if args[:1] == ["solve"]:
        solve(int(args[1]), float(args[2]), "--before" in args)
    elif args[:1] == ["restop"]:
        restop(int(args[1]), float(args[2]))
    elif args[:1] == ["steps"]:
        steps(int(args[1]), args[2:])
    else:
        sys.exit(__doc__)
