"""The orthogonal multiblock grid of a lake layout, as a generator the solver worker runs (no Qt).

:func:`solve_layout` yields ``(ALL_BLOCKS, SolverProgress)`` items with every block's grid and
returns a :class:`~app.results.BlockResult` carrying the
:class:`~meshcore.multiblock.MultiBlockGrid`.  Two ways, one result:

* **cold** (a new layout, or blocks whose cell counts changed):
  :func:`meshcore.lakegrid.mesh_layout`, coarse to fine; it reports once per level (through
  its callback, run in a helper thread so that this generator can yield), and a stop takes
  effect at the end of a level.
* **warm** (the same blocks with the same cells, e.g. a cut line dragged): the previous
  grid moved onto the new borders (``A_new + (G_old − A_old)``, :func:`app.pipeline.warm_start`'s
  rule, without its residual test) and orthogonalised on the full level only, in short
  chunks of sweeps so that the canvas follows and a stop takes effect within a chunk.  The
  options are :func:`~meshcore.lakegrid.mesh_layout`'s own defaults (read from its signature).

Seam: when ``meshcore.lakegrid.iterate_layout`` exists this module should drain it instead.
"""

from __future__ import annotations

import inspect
import queue
import threading
import time
from collections.abc import Generator, Mapping

import numpy as np

from meshcore import SolverProgress, StructuredGrid

from .results import ALL_BLOCKS, BlockResult

__all__ = ["TOLERANCE", "solve_layout"]

#: the sweep tolerance of :func:`meshcore.lakegrid.mesh_layout` (largest move / cell size)
TOLERANCE = 1e-5
#: wall time a chunk of warm sweeps aims at (the canvas redraws after each)
CHUNK_SECONDS = 0.08


class _Stopped(Exception):
    """Raised in mesh_layout's callback to end it at a level boundary."""


def _options() -> dict:
    """mesh_layout's orthogonaliser options (its defaults), and its full-level sweep budget."""
    from meshcore.lakegrid import mesh_layout

    sig = inspect.signature(mesh_layout).parameters
    opts = {k: sig[k].default for k in ("smooth", "omega", "pin_angle", "shore_smooth") if k in sig}
    sweeps = sig["sweeps"].default if "sweeps" in sig else (80,)
    return opts | {"max_sweeps": int(sweeps[-1])}


def _rings(layout) -> list[np.ndarray]:
    """The shore and island rings the shore nodes slide on (sampled at a quarter cell)."""
    import shapely

    dense = shapely.segmentize(layout.polygon, layout.cell_size / 4)
    return [np.asarray(dense.exterior.coords)[:-1], *(np.asarray(r.coords)[:-1] for r in dense.interiors)]


def _progress(grids, it: int, residual: float, t0: float, history) -> SolverProgress:
    return SolverProgress(
        iteration=it,
        residual=float(residual),
        tolerance=TOLERANCE,
        grid=None,
        elapsed=time.perf_counter() - t0,
        method="orthogonal",
        history=tuple(history),
        grids=tuple(grids),
    )


def solve_layout(
    lake,
    *,
    warm: Mapping[int, tuple[StructuredGrid, StructuredGrid]] | None = None,
    stop_event: threading.Event | None = None,
) -> Generator[tuple[int, object], object, BlockResult]:
    """Grid the lake's layout; yield ``(ALL_BLOCKS, SolverProgress)``; return the result."""
    from meshcore.multiblock import initial_grids

    layout = lake.layout
    topo = layout.topology()
    algebraic = initial_grids(topo)
    starts = dict(enumerate(algebraic))
    if warm and all(k in warm and warm[k][0].shape == a.shape for k, a in starts.items()):
        return (yield from _warm(layout, topo, starts, warm, stop_event))
    return (yield from _cold(layout, starts, stop_event))


def _cold(layout, starts: dict, stop_event):
    from meshcore.lakegrid import mesh_layout

    q: queue.Queue = queue.Queue()
    quit_flag = threading.Event()

    def level(kind, value) -> None:
        if quit_flag.is_set() or (stop_event is not None and stop_event.is_set()):
            raise _Stopped
        if kind == "level":
            q.put(("level", value))

    def run() -> None:
        try:
            q.put(("done", mesh_layout(layout, callback=level)))
        except BaseException as exc:  # handed to the generator, which raises it in the worker
            q.put(("error", exc))

    t0 = time.perf_counter()
    threading.Thread(target=run, name="gcmesh-lake-grid", daemon=True).start()
    history: list[tuple[int, float]] = []
    sweeps = 0
    try:
        while True:
            kind, value = q.get()
            if kind == "level":
                _lev, res = value
                sweeps += res.sweeps
                history += [(sweeps - len(res.history) + i + 1, d) for i, d in enumerate(res.history)]
                yield ALL_BLOCKS, _progress(res.grids, sweeps, res.history[-1] if res.history else 0.0, t0, history)
            elif kind == "done":
                mb = value
                return BlockResult(grids=dict(enumerate(mb.grids)), initial=starts, multiblock=mb)
            elif isinstance(value, _Stopped):
                return BlockResult(grids={}, initial={})
            else:
                raise value
    finally:
        quit_flag.set()


def _warm(layout, topo, starts: dict, warm, stop_event):
    from meshcore.grid import SolveInfo
    from meshcore.multiblock import MultiBlockGrid
    from meshcore.orthogonal import orthogonalize

    opts = _options()
    budget = opts.pop("max_sweeps")
    grids = []
    for k, a in starts.items():
        a_old, g_old = warm[k]
        grids.append(a.replaced(x=a.x + (g_old.x - a_old.x), y=a.y + (g_old.y - a_old.y)))
    rings = _rings(layout)
    t0 = time.perf_counter()
    history: list[tuple[int, float]] = []
    done, chunk, converged = 0, 2, False
    while done < budget and not converged:
        if stop_event is not None and stop_event.is_set():
            break
        n = min(chunk, budget - done)
        t = time.perf_counter()
        res = orthogonalize(topo, grids, rings, tol=TOLERANCE, max_sweeps=n, **opts)
        per_sweep = (time.perf_counter() - t) / max(res.sweeps, 1)
        chunk = max(1, int(CHUNK_SECONDS / max(per_sweep, 1e-6)))
        grids = list(res.grids)
        history += [(done + i + 1, d) for i, d in enumerate(res.history)]
        done += res.sweeps
        converged = res.converged
        yield ALL_BLOCKS, _progress(grids, done, res.history[-1] if res.history else 0.0, t0, history)
    msg = f"orthogonal grid from the previous one (full level only), {done} sweeps"
    info = SolveInfo(
        method="orthogonal", converged=True, iterations=done, elapsed=time.perf_counter() - t0, message=msg
    )
    names = tuple(b.name for b in topo.blocks)
    mb = MultiBlockGrid(tuple(grids), names, topo.interfaces, "orthogonal", info, topo)
    return BlockResult(grids=dict(enumerate(grids)), initial=starts, multiblock=mb)
