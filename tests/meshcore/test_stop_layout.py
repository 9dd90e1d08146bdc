"""A Stop (``stop_event``) during a lake grid's start: the start solve, the repairs and the untangling
before the first sweep looked at it only once they were done (on 1.7 million cells, half a minute)."""

from __future__ import annotations

import threading

import pytest

from meshcore import testing
from meshcore.lakegrid import mesh_layout
from meshcore.layout import auto_layout


@pytest.fixture(scope="module")
def layout():
    return auto_layout(testing.lake_with_islands(1), target_cells=3000)


def test_a_stop_set_at_the_start_ends_the_start_solve_and_skips_the_steps_before_the_sweeps(layout, monkeypatch):
    import meshcore.multiblock as mbk
    from meshcore.orthogonal import untangle as unt

    starts: list = []
    solve = mbk.solve_multiblock

    def spy(*a, **kw):
        mb = solve(*a, **kw)
        starts.append((kw.get("stop_event"), mb.info))
        return mb

    def no_untangle(*_a, **_kw):
        raise AssertionError("untangled after the stop")

    monkeypatch.setattr(mbk, "solve_multiblock", spy)
    free = mesh_layout(layout, levels=0, equalize=False)
    assert starts and starts[-1][1].iterations > 1  # the start solve has work on this lake
    monkeypatch.setattr(unt, "untangle", no_untangle)
    ev = threading.Event()
    ev.set()
    mb = mesh_layout(layout, stop_event=ev)
    assert starts[-1][0] is ev and starts[-1][1].iterations <= 1  # was: run to its end, not told
    assert not mb.info.converged and mb.info.message == "stopped" and mb.info.iterations == 0
    assert len(mb.grids) == len(free.grids)


def test_the_full_multigrid_start_looks_at_stop_between_its_levels(layout):
    """``iterate_fas``'s first cycle (the full-multigrid start, several seconds on 1.7 million cells)
    ran to its end after a Stop: ``should_stop`` is looked at before each level's cycle."""
    import numpy as np

    from meshcore.multiblock.multigrid import iterate_fas, levels

    topo = layout.topology()
    x, y = _assemble(topo)
    lvs = levels(topo)
    assert len(lvs) > 1
    asked: list[int] = []

    def stop_at_the_second_look() -> bool:
        asked.append(1)
        return len(asked) >= 2

    x0, y0 = x.copy(), y.copy()
    gen = iterate_fas(x, y, topo, 1e-12, 10, lvs=lvs, should_stop=stop_at_the_second_look)
    try:
        next(gen)
        raise AssertionError("a cycle was reported after the stop")
    except StopIteration as fin:
        cycles, _r, _history, message, _n = fin.value
    assert message == "stopped" and cycles == 1 and len(asked) >= 2
    assert np.array_equal(x, x0) and np.array_equal(y, y0)  # the finest level's cycle never ran


def _assemble(topo):
    from meshcore.multiblock import initial_grids
    from meshcore.orthogonal.driver import _assemble as assemble

    return assemble(initial_grids(topo), topo.node_map)
