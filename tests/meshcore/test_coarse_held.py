"""A held coarse reading taken by its caller (:meth:`meshcore.lakegrid.CoarseReadings.held`): it goes on with
snapshots (``every``) to the grid of a fresh solve, and stops on its ``stop_event``."""

from __future__ import annotations

import threading

import numpy as np

from meshcore import testing
from meshcore.lakegrid import CoarseReadings, mesh_layout
from meshcore.layout import auto_layout


def _layout(readings):
    return auto_layout(testing.y_junction(), target_cells=800, multiple=4, reading=readings)


def _drive(gen, first):
    """Every snapshot's grids of the held solve ``gen`` from ``first`` on, and its result."""
    seen = [first.grids]
    try:
        while True:
            seen.append(gen.send(None).grids)
    except StopIteration as fin:
        return seen, fin.value


def test_a_held_solve_taken_goes_on_with_snapshots_to_the_fresh_grid():
    event = threading.Event()
    readings = CoarseReadings(levels=2, every=10, stop_event=event)
    lay = _layout(readings)
    levels: list = []
    taken = readings.held(lay, lambda kind, value: levels.append(value[0]) if kind == "level" else None)
    assert taken is not None and readings.held(lay) is None  # taken once
    gen, (lev, coarse), first = taken
    assert lev == 0 and first.grids == tuple(coarse.grids)
    seen, mb = _drive(gen, first)
    assert levels == [1, 2] and len(seen) > 3  # the later levels, told, with snapshots between
    fresh = mesh_layout(lay, levels=2)
    assert all(
        np.array_equal(a.x, b.x) and np.array_equal(a.y, b.y) for a, b in zip(mb.grids, fresh.grids, strict=True)
    )
    assert mb.info.iterations == fresh.info.iterations


def test_a_held_solve_stops_on_its_stop_event():
    event = threading.Event()
    readings = CoarseReadings(levels=2, every=10, stop_event=event)
    lay = _layout(readings)
    gen, _done, first = readings.held(lay)
    event.set()
    _seen, mb = _drive(gen, first)
    assert not mb.info.converged and mb.info.message == "stopped"
