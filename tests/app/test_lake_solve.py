"""The lake grid's solve generator (no Qt): during a drag a warm solve waits instead of making its final grid."""

from __future__ import annotations

import threading

import numpy as np
import pytest

from app.lake import Lake
from app.lake_solve import solve_layout

WARM = "warm start"


def _shapes():
    from meshcore import testing

    return {
        "y junction": testing.y_junction(),
        "lake with islands": testing.lake_with_islands(3),
        "channel network": testing.channel_network(5),
    }


class _Hold:
    """A hold that records what the solve had yielded when it waited, then lets it go on (or stops it:
    ``stop`` is set as the app's next drag step sets it with the hold)."""

    def __init__(self, yielded: list, stop: threading.Event | None = None) -> None:
        self.yielded = yielded
        self.stop = stop
        self.waits: list[int] = []  # the number of items yielded before each wait

    def is_set(self) -> bool:
        return False

    def wait(self, timeout=None) -> bool:
        self.waits.append(len(self.yielded))
        if self.stop is not None:
            self.stop.set()
        return True


def _drain(gen, items: list):
    try:
        while True:
            items.append(next(gen)[1])
    except StopIteration as fin:
        return fin.value


def _dragged(name):
    """A generated lake laid out and gridded, and the layout after a cut end moved along the shore."""
    from app.layout_edit import handles, moved_layout, moved_parts, place
    from meshcore.errors import MeshcoreError
    from meshcore.layout import auto_layout
    from meshcore.layout.outline import outline_parts

    poly = _shapes()[name]
    h = float(np.sqrt(poly.area / 300))
    lay = auto_layout(poly, cell_size=h, multiple=2)
    if not lay.cuts:
        pytest.skip("one block: no cut to drag")
    lake = Lake(
        outline=np.asarray(lay.polygon.exterior.coords)[:-1],
        holes=tuple(np.asarray(r.coords)[:-1] for r in lay.polygon.interiors),
        layout=lay,
    )
    first = _drain(solve_layout(lake), [])
    end = next(k for k in handles(lay) if k.kind == "end")
    tol = 1e-9 * max(1.0, float(np.sqrt(lay.polygon.area)))
    parts = outline_parts(lay)
    for f in (0.5, -0.5, 0.25, -0.25):  # a step along the shore that keeps the blocks
        q = place(lay, end, (end.xy[0] + f * h, end.xy[1] + f * h), parts)
        try:
            lay2 = moved_layout(lay, moved_parts(parts, end.xy, q, tol))
            break
        except MeshcoreError:  # this step changes the blocks: try another
            continue
    else:
        pytest.skip("no small move of a cut end keeps the blocks")
    warm = {k: (first.initial[k], g) for k, g in first.grids.items()}
    return lake.replaced(layout=lay2), warm


@pytest.mark.parametrize("name", sorted(_shapes()))
def test_a_held_warm_solve_waits_after_its_live_frames_then_makes_the_final_grid(name):
    from meshcore.lakegrid import mesh_layout

    lake, warm = _dragged(name)
    items: list = []
    hold = _Hold(items)
    result = _drain(solve_layout(lake, warm=warm, hold=hold), items)
    # one wait, after the live frames (every one a grid from the warm start) and before the final solve
    assert len(hold.waits) == 1
    before, after = items[: hold.waits[0]], items[hold.waits[0] :]
    assert before and all(ev.grids and [lv for _k, lv in ev.levels] == [WARM] for ev in before)
    assert after and all(not ev.grids and [lv for _k, lv in ev.levels][:2] == [WARM, "cells ÷2"] for ev in after)
    # released, it goes on to the grid `meshcore generate` makes of the layout
    ref = mesh_layout(lake.layout)
    for k, g in enumerate(ref.grids):
        np.testing.assert_array_equal(result.grids[k].x, g.x)
        np.testing.assert_array_equal(result.grids[k].y, g.y)


@pytest.mark.parametrize("name", sorted(_shapes()))
def test_a_held_warm_solve_stopped_by_the_next_drag_step_returns_its_live_grid(name):
    lake, warm = _dragged(name)
    items: list = []
    stop = threading.Event()
    hold = _Hold(items, stop=stop)
    result = _drain(solve_layout(lake, warm=warm, stop_event=stop, hold=hold), items)
    assert len(hold.waits) == 1 and hold.waits[0] == len(items)  # nothing after the wait
    last = items[-1].grids
    assert sorted(result.grids) == list(range(len(last)))
    for k, g in enumerate(last):  # the last frame shown is the result (the next solve starts from it)
        np.testing.assert_array_equal(result.grids[k].x, g.x)
    assert result.metrics is None  # nobody reads them: the next step's solve replaces this grid


def test_an_unheld_warm_solve_never_waits():
    lake, warm = _dragged("y junction")
    items: list = []
    hold = threading.Event()
    hold.set()
    _drain(solve_layout(lake, warm=warm, hold=hold), items)
    assert any(not ev.grids for ev in items)  # it went on to the final solve by itself


def test_a_warm_solve_stopped_in_its_final_remake_returns_its_live_grid_as_stopped():
    """Esc (or Stop) while F5 remade a grid from the previous one: the remake, stopped, gave no grid,
    and the warm grid it kept was said to be finished ("orthogonal: 60 sweeps", converged): the
    status line summed it up as a finished lake grid.  It is "stopped" now, as a cold solve stopped."""
    lake, warm = _dragged("y junction")
    stop = threading.Event()
    items: list = []
    gen = solve_layout(lake, warm=warm, stop_event=stop)
    try:
        while True:
            ev = next(gen)[1]
            items.append(ev)
            if not ev.grids and ev.iteration > 0:  # the remake (unseen) has begun: stop it
                stop.set()
    except StopIteration as fin:
        result = fin.value
    assert stop.is_set() and result.grids
    live = next(ev.grids for ev in reversed(items) if ev.grids)
    for k, g in enumerate(live):  # the warm grid stays
        np.testing.assert_array_equal(result.grids[k].x, g.x)
    info = result.multiblock.info
    assert not info.converged and info.message == "stopped"


class _StopWithoutHold(_Hold):
    """A hold never set, and a stop that comes while the solve waits on it without setting it."""

    def wait(self, timeout=None) -> bool:
        assert timeout is not None, "a held solve waits without a bound"  # was: hold.wait()
        self.waits.append(len(self.yielded))
        self.stop.set()
        return False


def test_a_held_warm_solve_waits_with_a_bound_and_sees_a_stop_that_left_the_hold_unset():
    lake, warm = _dragged("y junction")
    items: list = []
    stop = threading.Event()
    hold = _StopWithoutHold(items, stop=stop)
    result = _drain(solve_layout(lake, warm=warm, stop_event=stop, hold=hold), items)
    assert len(hold.waits) == 1 and hold.waits[0] == len(items)  # stopped at the wait: nothing after it
    for k, g in enumerate(items[-1].grids):  # the live grid is the result, as with a stop that sets the hold
        np.testing.assert_array_equal(result.grids[k].x, g.x)


def test_the_topologies_and_held_readings_are_kept_safely_from_threads():
    """The Lake panel's count makes a layout in a worker beside Auto layout's, a layout edit's and the
    solve's: two evicting the same oldest topology raised KeyError (or "dictionary changed size during
    iteration") — the count or Auto layout said "internal error".  Held readings are taken by the layout
    they were held for, never another's."""
    from app import lake_solve
    from tests.meshcore.test_shore_threads import hammer

    class Lay:
        def __init__(self, k: int) -> None:
            self.k = k

        def topology(self) -> int:
            return self.k

    lays = [Lay(k) for k in range(6)]

    def topologies(k: int) -> None:
        for i in range(200_000):
            lay = lays[(i + k) % 6]
            assert lake_solve.layout_topology(lay) == lay.k

    assert hammer(topologies) == []

    class Relay:
        event = None

    class Readings:
        def __init__(self, lay) -> None:
            self.lay, self.stop_event = lay, Relay()

        def held(self, layout, callback):
            return layout is self.lay

    def readings(k: int) -> None:
        for _ in range(20_000):
            lay = object()
            lake_solve.hold_readings(lay, Readings(lay))
            assert lake_solve._held_solve(lay, None, None) in (True, None)  # its own, or evicted by another's

    assert hammer(readings) == []
