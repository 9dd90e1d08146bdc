"""How long the app's lake solve takes to end after Stop, and where its worker is meanwhile.

:func:`app.lake_solve.solve_layout` (what the app's solver worker runs for a lake layout) of a
generated lake with islands (:func:`meshcore.testing.lake_with_islands`) laid out at about CELLS
cells, in a thread; the stop event is set AT seconds after the start, then the time until the
generator returns is printed, with the places the worker was sampled at (every 50 ms) until then::

    python benchmarks/stop_latency.py CELLS AT [AT ...]

Session 28, 2 shared cores (wall time, noisy): 1.78 million cells (15 blocks), Stop at 8 s: 199 s
before (the start solve fell back to SOR, then the fold-free repair and the untangling before the
first sweep, none of which looked at Stop), 7.3 s after; 381 000 cells, Stop at 3 / 12 / 30 s:
31.9 / 18.1 / 2.4 s before, 1.3 / 1.4 / 2.0 s after.
"""

from __future__ import annotations

import collections
import sys
import threading
import time
import traceback
from pathlib import Path
from types import SimpleNamespace


def main(argv: list[str]) -> None:
    from app.lake_solve import solve_layout
    from meshcore import testing
    from meshcore.cellsize import default_cell_size
    from meshcore.layout import auto_layout

    cells, stops = float(argv[0]), [float(a) for a in argv[1:]]
    water = testing.lake_with_islands(1)
    layout = auto_layout(water, cell_size=default_cell_size(water.area) * (10_000 / cells) ** 0.5)
    print(f"{layout.n_cells:,} cells, {len(layout.blocks)} blocks", flush=True)
    lake = SimpleNamespace(layout=layout)
    for at in stops:
        ev, out = threading.Event(), {}

        def work(ev=ev, out=out) -> None:
            gen = solve_layout(lake, stop_event=ev)
            try:
                while True:
                    next(gen)
            except StopIteration as fin:
                out["result"] = fin.value
            out["t"] = time.perf_counter()

        th = threading.Thread(target=work)
        th.start()
        time.sleep(at)
        if not th.is_alive():
            print(f"stop at {at:g} s: finished before it", flush=True)
            continue
        where: collections.Counter = collections.Counter()
        t_stop = time.perf_counter()
        ev.set()
        while th.is_alive():
            frame = sys._current_frames().get(th.ident or 0)
            if frame is not None:
                stack = [f for f in traceback.extract_stack(frame) if "numpy" not in f.filename][-1:-5:-1]
                where[" < ".join(f"{Path(f.filename).stem}.{f.name}:{f.lineno}" for f in stack)] += 1
            time.sleep(0.05)
        grids = len(out["result"].grids)
        print(f"stop at {at:g} s: ended {out['t'] - t_stop:.2f} s later ({grids} grids in the result)", flush=True)
        for place, n in where.most_common(8):
            print(f"  {n * 0.05:5.1f} s  {place}")


if __name__ == "__main__":
    main(sys.argv[1:])
