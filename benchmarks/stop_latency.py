"""How long the app's lake solve, or its Auto layout, takes to end after Stop, and where its worker is meanwhile.

:func:`app.lake_solve.solve_layout` (what the app's solver worker runs for a lake layout) of a
generated lake with islands (:func:`meshcore.testing.lake_with_islands`) laid out at about CELLS
cells, in a thread; the stop event is set AT seconds after the start, then the time until the
generator returns is printed, with the places the worker was sampled at (every 50 ms) until then::

    python benchmarks/stop_latency.py CELLS AT [AT ...]

Session 28, 2 shared cores (wall time, noisy): 1.78 million cells (15 blocks), Stop at 8 s: 199 s
before (the start solve fell back to SOR, then the fold-free repair and the untangling before the
first sweep, none of which looked at Stop), 7.3 s after; 381 000 cells, Stop at 3 / 12 / 30 s:
31.9 / 18.1 / 2.4 s before, 1.3 / 1.4 / 2.0 s after.

With ``--layout LAKE`` (a lake file, lon/lat or projected, read as the app imports it): Auto layout's
worker instead (:func:`app.lake_controller._layout_job`)::

    python benchmarks/stop_latency.py --layout LAKE AT [AT ...]

Session 41, Vänern (GSHHG 180525, 7 islands, 10 000 cells; load ~1.6): the stop was heard only at the
layout choice's first coarse reading, ~4.2 s after the start (five draws before it): Stop at 0.3 / 1 /
2 / 3 s ended 3.7–5.0 / 2.9–3.0 / 1.8–2.0 / 0.8–1.0 s later.  With the checks of
:mod:`meshcore.layout.stopping` (between a draw's stages and between draws): 0.00–0.25 s at any of
0.3–5 s; the longest stretch without a check is one cell-count program (a HiGHS solve, up to ~1 s).
"""

from __future__ import annotations

import collections
import sys
import threading
import time
import traceback
from pathlib import Path
from types import SimpleNamespace


def stopped_after(body, at: float):
    """``body(event, out)`` in a thread, ``event`` set ``at`` seconds after its start: ``(seconds from the
    set to the end, the places the thread was sampled at meanwhile, out)``; None when it ended before."""
    ev, out = threading.Event(), {}

    def work() -> None:
        body(ev, out)
        out["t"] = time.perf_counter()

    th = threading.Thread(target=work)
    th.start()
    th.join(at)
    if not th.is_alive():
        return None
    where: collections.Counter = collections.Counter()
    t_stop = time.perf_counter()
    ev.set()
    while th.is_alive():
        frame = sys._current_frames().get(th.ident or 0)
        if frame is not None:
            stack = [f for f in traceback.extract_stack(frame) if "numpy" not in f.filename][-1:-5:-1]
            where[" < ".join(f"{Path(f.filename).stem}.{f.name}:{f.lineno}" for f in stack)] += 1
        time.sleep(0.05)
    return out["t"] - t_stop, where, out


def main(argv: list[str]) -> None:
    if argv[0] == "--layout":
        from app.lake import Lake, read_lake
        from app.lake_controller import _layout_job
        from meshcore.io import read_points

        outer, holes, _frame, _notes = read_lake(read_points(argv[1]), lonlat=True)
        lake = Lake(outline=outer, holes=tuple(holes))

        def body(ev, out) -> None:
            out["result"] = "no layout" if _layout_job(lake, None, ev) is None else "a layout"

        stops = [float(a) for a in argv[2:]]
    else:
        from app.lake_solve import solve_layout
        from meshcore import testing
        from meshcore.cellsize import default_cell_size
        from meshcore.layout import auto_layout

        cells, stops = float(argv[0]), [float(a) for a in argv[1:]]
        water = testing.lake_with_islands(1)
        layout = auto_layout(water, cell_size=default_cell_size(water.area) * (10_000 / cells) ** 0.5)
        print(f"{layout.n_cells:,} cells, {len(layout.blocks)} blocks", flush=True)
        lake_ = SimpleNamespace(layout=layout)

        def body(ev, out) -> None:
            gen = solve_layout(lake_, stop_event=ev)
            try:
                while True:
                    next(gen)
            except StopIteration as fin:
                out["result"] = f"{len(fin.value.grids)} grids in the result"

    for at in stops:
        got = stopped_after(body, at)
        if got is None:
            print(f"stop at {at:g} s: finished before it", flush=True)
            continue
        seconds, where, out = got
        print(f"stop at {at:g} s: ended {seconds:.2f} s later ({out['result']})", flush=True)
        for place, n in where.most_common(8):
            print(f"  {n * 0.05:5.1f} s  {place}")


if __name__ == "__main__":
    main(sys.argv[1:])
