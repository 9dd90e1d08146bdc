"""The orthogonal multiblock grid of a lake layout, as a generator the solver worker runs (no Qt).

:func:`solve_layout` yields ``(ALL_BLOCKS, SolverProgress)`` items with every block's grid and
returns a :class:`~app.results.BlockResult` carrying the
:class:`~meshcore.multiblock.MultiBlockGrid` and its lake metrics.  Two ways, one result:

* **cold** (a new layout, or blocks whose cell counts changed):
  :func:`meshcore.lakegrid.iterate_layout`, coarse to fine, as ``meshcore mesh`` makes it (the grid of
  a layout just made by :func:`app.lake.compute_layout` goes on from the solve of its coarse level that
  chose the layout, :func:`hold_readings`, as ``meshcore mesh`` goes on from it: that level is not
  solved twice);
* **warm** (the same blocks with the same cells, e.g. a cut line dragged): the previous grid
  moved onto the new borders (``A_new + (G_old − A_old)``, the rule of
  :func:`app.pipeline.warm_start`) and orthogonalised on the full level
  (:func:`meshcore.orthogonal.iterate_orthogonalize`, at most :data:`WARM_SWEEPS` sweeps) with
  the options of the full level of :func:`~meshcore.lakegrid.iterate_layout` (read from its
  signature), a snapshot every few sweeps so that the canvas follows a drag; then, when no newer
  edit stops it, the cold solve without showing its snapshots: the final grid of an edit is the
  grid ``meshcore generate`` makes of the saved layout (on Iseo a warm solve alone stalled at a
  mean deviation of 0.61° after a long drag and its undo, the cold one reaches 0.30°, and a
  warm start keeps folds a large move made).  While the user still drags (``hold`` not set) the
  worker waits after the warm sweeps instead: the next step of the drag would stop the cold solve
  long before it shows anything (on Como it took a tenth of the process's CPU time of a drag).

A stop (``stop_event``) ends either within a few sweeps; a cold solve stopped before its full
level returns no grid (the coarse grids are never kept as a result).

A grid whose levels end with folded or non-convex cells is made again with sliding block corners
(:data:`meshcore.lakegrid.FOLD_RETRY`) without yielding anything (seconds on a large lake): ``notify(kind,
text)`` is told of it in the words ``meshcore mesh`` prints (:func:`meshcore.lakegrid.retry_words`), from the
worker's thread.
"""

from __future__ import annotations

import inspect
import threading
import time
from collections.abc import Callable, Generator, Mapping
from dataclasses import dataclass, field

import numpy as np

from meshcore import SolverProgress, StructuredGrid
from meshcore.lakegrid import level_labels, retry_words

from .results import ALL_BLOCKS, BlockResult

__all__ = [
    "TOLERANCE",
    "LakeProgress",
    "coarse_readings",
    "hold_readings",
    "layout_topology",
    "level_labels",
    "retry_words",
    "solve_layout",
]

#: the sweep tolerance of :func:`meshcore.lakegrid.iterate_layout` (largest move / cell size)
TOLERANCE = 1e-5
#: sweeps between two snapshots of a warm solve (the canvas redraws after each)
WARM_EVERY = 2
#: seconds between looks at the stop event while a held warm solve waits for the end of a drag
HOLD_POLL_S = 0.5
#: sweeps between two snapshots of a cold solve (:func:`meshcore.lakegrid.iterate_layout`'s ``every``)
COLD_EVERY = 25
#: most sweeps of the full level from the previous grid (the live frames of an edit) before the grid is
#: made again coarse to fine (what the final grid of an edit is)
WARM_SWEEPS = 60


@dataclass(frozen=True, slots=True)
class LakeProgress(SolverProgress):
    """A :class:`~meshcore.SolverProgress` of a lake grid with its levels so far.

    ``levels``: ``(sweep, label)`` for each level of the grid sequencing begun so far (the
    sweep count at its start, e.g. ``(0, "cells ÷4"), (200, "÷2"), (350, "full")``):
    the convergence plot marks them (the change per sweep rises where a finer level begins).
    """

    levels: tuple[tuple[int, str], ...] = field(default=(), repr=False)


_topologies: dict[int, tuple] = {}  # id(layout) -> (layout, topology): the last few layouts' topologies
#: guards :data:`_topologies` and :data:`_readings`: the Lake panel's count of a cell size makes a layout in
#: a worker beside Auto layout's, a layout edit's and the solve's threads (two evicting the same oldest
#: topology raised KeyError: "internal error" for the count or Auto layout; a held reading taken while
#: another was kept could delete the other, or an index no longer there)
_LOCK = threading.Lock()


def layout_topology(layout):
    """``layout.topology()``, remembered for the last few layouts (it takes a while on a big lake)."""
    with _LOCK:
        hit = _topologies.get(id(layout))
    if hit is not None and hit[0] is layout:
        return hit[1]
    topo = layout.topology()  # (outside the lock: a layout's topology is made once, Layout.topology)
    with _LOCK:
        while len(_topologies) >= 4:
            _topologies.pop(next(iter(_topologies)))
        _topologies[id(layout)] = (layout, topo)
    return topo


class _StopRelay:
    """The stop event of held coarse readings: that of the solve which goes on from one (none before)."""

    def __init__(self) -> None:
        self.event: threading.Event | None = None

    def is_set(self) -> bool:
        event = self.event
        return event is not None and event.is_set()


#: the readings of the last few layouts made: (layout, the CoarseReadings that chose it), newest last
_readings: list[tuple] = []
#: layouts whose held readings are kept (each holds a paused solve of every layout it read)
READINGS_KEPT = 2


def coarse_readings():
    """A :class:`~meshcore.lakegrid.CoarseReadings` for :func:`meshcore.layout.auto_layout` (``reading=``)
    whose held solves give the snapshots and take the stop of :func:`solve_layout`'s cold solve."""
    from meshcore.lakegrid import CoarseReadings

    return CoarseReadings(every=COLD_EVERY, stop_event=_StopRelay())


def hold_readings(layout, readings) -> None:
    """Keep ``readings`` (:func:`coarse_readings`, that chose ``layout``) for the first cold solve of ``layout``."""
    with _LOCK:
        _readings[:] = [r for r in _readings if r[0] is not layout][-(READINGS_KEPT - 1) :]
        _readings.append((layout, readings))


def _held_solve(layout, stop_event, callback):
    """The solve of ``layout`` held after its coarse level by the readings that chose it (taken: once), or
    None: ``(solve, coarse level, progress)`` of :meth:`meshcore.lakegrid.CoarseReadings.held`."""
    with _LOCK:
        taken = next((r for lay, r in _readings if lay is layout), None)
        _readings[:] = [r for r in _readings if r[0] is not layout]
    if taken is None:
        return None
    taken.stop_event.event = stop_event
    return taken.held(layout, callback)


def _options() -> dict:
    """The full level's options of :func:`meshcore.lakegrid.iterate_layout` (its defaults)."""
    from meshcore.lakegrid import iterate_layout

    sig = inspect.signature(iterate_layout).parameters

    def last(v):
        return v[-1] if isinstance(v, tuple) else v

    opts = {k: last(sig[k].default) for k in ("smooth", "omega", "pin_angle", "shore_smooth") if k in sig}
    return opts | {"max_sweeps": int(last(sig["sweeps"].default))}


def _rings(layout) -> list[np.ndarray]:
    """The shore and island rings the shore nodes slide on (sampled at a quarter cell, as meshcore does)."""
    import shapely

    dense = shapely.segmentize(layout.polygon, layout.cell_size / 4)
    return [np.asarray(dense.exterior.coords)[:-1], *(np.asarray(r.coords)[:-1] for r in dense.interiors)]


def solve_layout(
    lake,
    *,
    warm: Mapping[int, tuple[StructuredGrid, StructuredGrid]] | None = None,
    stop_event: threading.Event | None = None,
    hold: threading.Event | None = None,
    notify: Callable[[str, str], None] | None = None,
) -> Generator[tuple[int, object], object, BlockResult]:
    """Grid the lake's layout; yield ``(ALL_BLOCKS, SolverProgress)``; return the result.

    ``hold``: a warm solve waits for it after its live frames before it makes the final grid
    (set by the app when the drag ends; set with ``stop_event`` to stop the waiting solve).
    ``notify(kind, text)``: told, from this generator's thread, of a grid made again and its steps
    (:func:`meshcore.lakegrid.retry_words`; ``kind`` as :func:`meshcore.lakegrid.iterate_layout` reports them), which
    yield nothing.
    """
    layout = lake.layout
    cells = [tuple(b.cells) for b in layout.blocks]
    if warm and all(k in warm and warm[k][0].cells == c for k, c in enumerate(cells)):
        return (yield from _warm(layout, warm, stop_event, hold, notify))
    return (yield from _cold(layout, stop_event, notify=notify))


def _cold(layout, stop_event, *, shown: bool = True, before: tuple = ((), (), 0), notify=None):
    """:func:`meshcore.lakegrid.iterate_layout` of ``layout`` (coarse to fine), as the CLI makes it.

    ``shown`` False: its snapshots carry no grids (the grid on screen stays until the result
    replaces it); ``before``: ``(history, levels, sweeps)`` of a warm phase that came first (the
    convergence plot goes on after it).  Stopped before its full level: an empty result.
    """
    from meshcore.lakegrid import iterate_layout
    from meshcore.multiblock import initial_grids

    n_levels = 1 + (max(0, int(np.log2(layout.multiple))) if layout.multiple > 1 else 0)  # as iterate_layout
    labels = level_labels(n_levels)
    history0, levels0, offset = before
    levels = [*levels0, (offset, labels[0])]

    def level_done(what, value):  # called by iterate_layout as a level ends, before the next one's sweeps
        if what != "level":  # ("equalize", patches): after the last level; the grid made again ("retry", ...)
            stopped = stop_event is not None and stop_event.is_set()
            text = retry_words(what, value, labels, stopped=stopped) if notify is not None else None
            if text is not None:
                notify(what, text)
            return
        lev, res = value
        if lev + 1 < n_levels:
            levels.append((levels[-1][0] + res.sweeps, labels[lev + 1]))

    held = _held_solve(layout, stop_event, level_done)
    if held is not None:  # the layout's coarse level, solved as Auto layout read it: go on from there
        gen, done, paused = held
        level_done("level", done)
    else:
        gen = iterate_layout(layout, stop_event=stop_event, level_callback=level_done, every=COLD_EVERY)
        paused = None
    try:
        snap = next(gen) if paused is None else paused
        while True:
            hist = (*history0, *((offset + k, d) for k, d in snap.history)) if history0 else snap.history
            s = snap
            progress = LakeProgress(
                offset + s.iteration, s.residual, s.tolerance, None, s.elapsed, s.method, hist,
                s.grids if shown else (), tuple(levels),
            )  # fmt: skip
            cmd = yield ALL_BLOCKS, progress
            snap = gen.send(cmd)
    except StopIteration as fin:
        mb = fin.value
    full = [g.cells for g in mb.grids] == [tuple(b.cells) for b in layout.blocks]
    stopped = not mb.info.converged and mb.info.message == "stopped"
    if not full or (stopped and not shown):  # stopped on a coarse level, or a polish stopped by a newer edit
        return BlockResult(grids={}, initial={})
    starts = dict(enumerate(initial_grids(mb.topology)))
    metrics = _metrics(layout, mb, coverage=not stopped)
    return BlockResult(grids=dict(enumerate(mb.grids)), initial=starts, multiblock=mb, metrics=metrics)


def _warm(layout, warm, stop_event, hold=None, notify=None):
    """The previous grid moved onto the new layout and swept on the full level (the live frames of an
    edit), then, unless a newer edit stops it, the grid made again coarse to fine without showing its
    snapshots: the final grid of an edit is the one ``meshcore generate`` makes of the saved layout
    (a warm start alone stalls above it after a large move, and keeps folds the move made)."""
    from meshcore.grid import SolveInfo
    from meshcore.multiblock import MultiBlockGrid, initial_grids
    from meshcore.orthogonal import iterate_orthogonalize

    topo = layout_topology(layout)
    starts = dict(enumerate(initial_grids(topo)))
    grids = []
    for k, a in starts.items():
        a_old, g_old = warm[k]
        grids.append(a.replaced(x=a.x + (g_old.x - a_old.x), y=a.y + (g_old.y - a_old.y)))
    t0 = time.perf_counter()
    history: list[tuple[int, float]] = []
    # the moved grid is shown at once (never the start grid): a drag's redraw does not wait for sweeps
    warm_level = ((0, "warm start"),)
    first = LakeProgress(0, float("nan"), TOLERANCE, None, 0.0, "orthogonal", (), tuple(grids), warm_level)
    cmd = yield ALL_BLOCKS, first
    stopped = cmd == "stop" or (stop_event is not None and stop_event.is_set())
    if stopped:  # a newer edit is waiting: the moved grid is the result (no metrics: nobody reads them)
        return BlockResult(grids=dict(enumerate(grids)), initial=starts)
    opts = _options() | {"max_sweeps": WARM_SWEEPS}
    gen = iterate_orthogonalize(topo, grids, _rings(layout), every=WARM_EVERY, tol=TOLERANCE, **opts)
    try:
        it, d, snap = next(gen)
        while True:
            history.append((it, d))
            elapsed = time.perf_counter() - t0
            progress = LakeProgress(
                it, float(d), TOLERANCE, None, elapsed, "orthogonal", tuple(history), snap, warm_level
            )
            cmd = yield ALL_BLOCKS, progress
            stopped = cmd == "stop" or (stop_event is not None and stop_event.is_set())
            it, d, snap = gen.send("stop" if stopped else None)
    except StopIteration as fin:
        res = fin.value
    msg = f"orthogonal grid from the previous one (full level only), {res.sweeps} sweeps"
    info = SolveInfo(method="orthogonal", converged=True, iterations=res.sweeps, elapsed=res.elapsed, message=msg)
    names = tuple(b.name for b in topo.blocks)
    mb = MultiBlockGrid(
        tuple(res.grids), names, topo.interfaces, "orthogonal", _stopped(info) if stopped else info, topo
    )
    # stopped: no metrics (on a big lake they would only delay the next edit's solve; the document
    # measures a grid it keeps without them)
    moved = BlockResult(grids=dict(enumerate(res.grids)), initial=starts, multiblock=mb)
    if not stopped and hold is not None:
        # a drag goes on: its next step restarts the solve (no CPU time spent meanwhile).  Every stop sets
        # the hold too; one that did not is seen within HOLD_POLL_S: the worker never waits without a bound
        while not hold.wait(HOLD_POLL_S):
            if stop_event is not None and stop_event.is_set():
                break
    if stopped or (stop_event is not None and stop_event.is_set()):
        return moved
    final = yield from _cold(
        layout, stop_event, shown=False, before=(tuple(history), warm_level, res.sweeps), notify=notify
    )
    if final.grids:
        return final
    # the remake stopped (Esc, F5 on a grid): the warm grid stays, said to be stopped (it was summed up as
    # finished: 'orthogonal: 60 sweeps', without the coarse-to-fine remake, its repairs and equalizing)
    mb = MultiBlockGrid(tuple(res.grids), names, topo.interfaces, "orthogonal", _stopped(info), topo)
    return BlockResult(grids=dict(enumerate(res.grids)), initial=starts, multiblock=mb)


def _stopped(info):
    """``info`` of a solve that was stopped before its end (``converged`` False, message "stopped")."""
    import dataclasses

    return dataclasses.replace(info, converged=False, message="stopped")


def _metrics(layout, mb, *, coverage: bool = True):
    """The lake metrics of the grid, measured here in the worker (they take a while on a big lake).

    ``coverage`` False (a grid stopped half way): without the grid's coverage of the water (the union
    of every block's cells: on a lake of 380 000 cells 8 s of the 10 s a Stop took to end)."""
    from meshcore.quality import lake_metrics

    return lake_metrics(mb, polygon=layout.polygon if coverage else None, cell_size=layout.cell_size)
