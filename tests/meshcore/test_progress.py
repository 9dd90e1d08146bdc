"""Progress is one type for one block and many: relative residuals, grids, stop (issue 14, item 2)."""

from __future__ import annotations

import io
import threading
from contextlib import redirect_stderr

import numpy as np
import pytest

import meshcore
from meshcore import EllipticConfig, SolverProgress
from meshcore.multiblock import initial_grids, iterate_multiblock, solve_multiblock
from tests.meshcore.test_multiblock import EXAMPLES, assert_glued, curved_rectangle, two_blocks

EVERY_CHECK = EllipticConfig(report_interval=1e-9)  # a snapshot at every residual check


def _collect(gen, stop_after=None):
    snaps = []
    try:
        snap = next(gen)
        while True:
            snaps.append(snap)
            snap = gen.send("stop" if stop_after is not None and len(snaps) >= stop_after else None)
    except StopIteration as fin:
        return snaps, fin.value


def test_single_block_history_is_relative_like_the_residual():
    X, Y = curved_rectangle(32, 16)
    snaps, g = _collect(meshcore.iterate(meshcore.StructuredGrid(X, Y), EVERY_CHECK, method="sor"))
    assert snaps and g.converged
    for s in snaps:
        assert s.grid is not None and s.grids == ()
        assert s.history[-1][1] == pytest.approx(s.residual, rel=1e-12)
    # the same numbers as the grid's own (relative) history
    final = dict(g.info.residual_history)
    i, r = snaps[-1].history[-1]
    assert final[i] == pytest.approx(r, rel=1e-12)


@pytest.mark.parametrize("kw", [{}, {"engine": "blocks"}, {"mode": "frozen"}], ids=["multigrid", "sor", "frozen"])
def test_multiblock_yields_progress_with_every_block_and_drains_to_the_same_grid(kw):
    X, Y = curved_rectangle(32, 16)
    topo = two_blocks(X, Y, 16)
    snaps, mb = _collect(iterate_multiblock(topo, config=EVERY_CHECK, **kw))
    assert snaps and mb.converged
    for s in snaps:
        assert isinstance(s, SolverProgress) and s.grid is None
        assert [g.shape for g in s.grids] == [g.shape for g in mb.grids]
        assert s.history[-1][1] == pytest.approx(s.residual, rel=1e-12) and s.tolerance == mb.info.tolerance
    # the snapshots move towards the answer: the last one is closer than the start
    start = initial_grids(topo)
    err = lambda gs: max(np.abs(g.x - h.x).max() for g, h in zip(gs, mb.grids, strict=True))  # noqa: E731
    assert err(snaps[-1].grids) < err(start)
    again = solve_multiblock(topo, **kw)  # drained without a callback: bit for bit the same
    for g, h in zip(mb.grids, again.grids, strict=True):
        assert np.array_equal(g.x, h.x) and np.array_equal(g.y, h.y)


@pytest.mark.parametrize("kw", [{}, {"engine": "table"}, {"mode": "frozen"}], ids=["multigrid", "sor", "frozen"])
def test_multiblock_stops_on_send_and_on_the_event(kw):
    X, Y = curved_rectangle(32, 16)
    topo = two_blocks(X, Y, 16)
    _snaps, mb = _collect(iterate_multiblock(topo, config=EVERY_CHECK, tolerance=1e-14, **kw), stop_after=1)
    assert not mb.converged and mb.info.message == "stopped"
    if kw.get("mode") != "frozen":
        assert_glued(mb)  # stopped, the interface nodes are still shared
    ev = threading.Event()
    ev.set()
    mb = solve_multiblock(topo, config=EVERY_CHECK, stop_event=ev, **kw)
    assert not mb.converged and mb.info.message == "stopped"


def test_generate_case_reports_multiblock_progress_and_the_cli_prints_it():
    from meshcore.case import generate_case, load_case
    from meshcore.cli.generate import _Progress

    case = load_case(EXAMPLES / "confluence-multiblock.toml")
    seen: list[SolverProgress] = []
    mb = generate_case(case, callback=seen.append, solver=case.solver.replaced(report_interval=1e-9))
    assert seen and all(len(s.grids) == len(mb.grids) for s in seen)
    err = io.StringIO()
    with redirect_stderr(err):
        p = _Progress(quiet=False)
        p(SolverProgress(7, 1e-5, 1e-6, None, 2.0, "smooth/multigrid", grids=mb.grids))
        p.done()
    assert "smooth/multigrid: iteration      7" in err.getvalue()


def test_a_slow_snapshot_of_a_small_grid_does_not_space_the_next(monkeypatch):
    """On a busy machine a snapshot may take long because the process waited for a core; on a
    small grid that is no reason to wait 20 × as long for the next one (the live view froze)."""
    from meshcore.elliptic import solver

    clock = iter(np.arange(0.0, 1e6, 1.0))  # every reading of the clock one second later
    monkeypatch.setattr(solver.time, "perf_counter", lambda: float(next(clock)))
    X, Y = curved_rectangle(32, 16)
    gen = meshcore.iterate(meshcore.StructuredGrid(X, Y), EllipticConfig(report_interval=0.5), method="sor")
    snaps = [next(gen) for _ in range(5)]
    gen.close()
    # one sweep (one clock reading) between snapshots, however long the last copy seemed to take
    steps = np.diff([s.iteration for s in snaps])
    assert steps.max() <= 2 * steps.min(), [s.iteration for s in snaps]
