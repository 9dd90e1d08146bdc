"""Multigrid with wall control (issue 15): sources that follow the grid, monotone coarse
levels, fold-safe corrections; same grid as SOR; cost independent of the grid size."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

import meshcore
from meshcore.control import ControlSources, boundary_report, make_sources
from meshcore.elliptic import _mg_control as C
from meshcore.elliptic import multigrid

EXAMPLES = Path(__file__).resolve().parents[2] / "resources" / "examples"


def _ellipse_ogrid(ni, nj, b=0.3, radius=5.0):
    """O-grid round an ellipse (semi-axes 1, b) out to a circle, geometric wall stretching
    (first cell 0.02/nj of the way; ratio ≈ 1.1–1.2 per cell); returns (grid, first spacing)."""
    first = 0.02 / nj
    lo, hi = 1.0 + 1e-12, 2.0
    for _ in range(100):  # ratio r with first·(r^nj − 1)/(r − 1) = 1
        r = 0.5 * (lo + hi)
        lo, hi = (lo, r) if first * (r**nj - 1) / (r - 1) > 1.0 else (r, hi)
    s = np.concatenate([[0.0], np.cumsum(first * r ** np.arange(nj))])
    s /= s[-1]
    th = np.linspace(0.0, -2 * np.pi, ni + 1)
    inner = np.column_stack([np.cos(th), b * np.sin(th)])
    outer = radius * np.column_stack([np.cos(th), np.sin(th)])
    X = inner[:, :1] + (outer[:, :1] - inner[:, :1]) * s
    Y = inner[:, 1:] + (outer[:, 1:] - inner[:, 1:]) * s
    X[-1], Y[-1] = X[0], Y[0]
    return meshcore.StructuredGrid(X, Y, periodic=True), first * radius


def _controlled(ni, nj, method, b=0.3, **kw):
    g0, h = _ellipse_ogrid(ni, nj, b)
    src = make_sources({"thomas-middlecoff": True, "borders": {"bottom": {"spacing": h}}}, periodic=True)
    return meshcore.solve(g0, method=method, sources=src, max_iterations=100_000, **kw), h


def _no_fallback(g):
    h = g.info.residual_history
    return g.info.method == "multigrid" and [i for i, _ in h] == list(range(len(h)))


# ------------------------------------------------------------------------------ kernels
@pytest.mark.parametrize("periodic", [False, True])
def test_source_kernel_is_the_numpy_reference(periodic):
    rng = np.random.default_rng(3)
    g0, _ = _ellipse_ogrid(24, 10)
    x, y = g0.x + 0.002 * rng.standard_normal(g0.x.shape), g0.y + 0.002 * rng.standard_normal(g0.x.shape)
    x[-1], y[-1] = x[0], y[0]
    ph, qh = rng.uniform(-1, 1, x.shape), rng.uniform(-1, 1, x.shape)
    ph[-1], qh[-1] = ph[0], qh[0]
    p, q = np.zeros(x.shape), np.zeros(x.shape)
    pr, qr = np.zeros(x.shape), np.zeros(x.shape)
    C.apply(x, y, ph, qh, periodic, p, q)
    C.apply_reference(x, y, ph, qh, periodic, pr, qr)
    rows = slice(0, None) if periodic else slice(1, -1)
    np.testing.assert_allclose(p[rows, 1:-1], pr[rows, 1:-1], rtol=1e-12)
    np.testing.assert_allclose(q[rows, 1:-1], qr[rows, 1:-1], rtol=1e-12)
    # and normalising undoes it: the sources of a grid that did not move are kept
    ph2, qh2 = C.normalised(x, y, pr, qr, periodic)
    np.testing.assert_allclose(ph2[rows, 1:-1], ph[rows, 1:-1], rtol=1e-12)
    np.testing.assert_allclose(qh2[rows, 1:-1], qh[rows, 1:-1], rtol=1e-12)


def test_safe_step_keeps_every_cell_and_leaves_harmless_steps_alone():
    s = np.linspace(0.0, 1.0, 9)
    x0, y0 = np.meshgrid(s, s, indexing="ij")
    a0 = C.cell_areas(x0, y0)
    # a smooth small step: untouched
    x, y = x0 + 0.01 * np.sin(np.pi * x0) * np.sin(np.pi * y0), y0.copy()
    want = x.copy()
    assert C.safe_step(x, y, x0, y0) == 1.0 and np.array_equal(x, want)
    # a node pushed two cells over would fold four cells: the step is halved until none
    # keeps less than 1 − MAX_AREA_LOSS of its area, in the step's direction
    x, y = x0.copy(), y0.copy()
    x[4, 4] += 0.25
    theta = C.safe_step(x, y, x0, y0)
    assert 0.0 < theta < 1.0
    assert np.all(C.cell_areas(x, y) >= (1 - C.MAX_AREA_LOSS) * a0 - 1e-15)
    assert x[4, 4] == pytest.approx(x0[4, 4] + 0.25 * theta)
    assert C.safe_step(x.copy(), y.copy(), x, y) == 1.0  # no step at all


def test_coarsening_stops_before_the_coarse_sources_lose_monotonicity():
    """|φ| doubles per coarsening; with uniform sources a level is kept while they stay
    ≤ PECLET_BULK (the median bound of coarse_ok; the spike bound PECLET_MAX is larger)."""
    s = np.linspace(0.0, 1.0, 65)
    x, y = np.meshgrid(s, s, indexing="ij")
    free = multigrid._plan(x, y)
    for psi in (0.1, 0.3):
        norm = (np.zeros(x.shape), np.full(x.shape, psi))
        plan = multigrid._plan(x, y, False, norm)
        assert 1 <= len(plan) < len(free)
        cells = [x.shape[1] - 1] + [tj[6].size - 1 for *_, tj in plan]
        scaled = [psi * cells[0] / c for c in cells]
        assert max(scaled) <= C.PECLET_BULK <= C.PECLET_MAX
        nxt = cells[-1] // 2  # the level it did not take
        assert psi * cells[0] / nxt > C.PECLET_BULK


def test_coarse_levels_tolerate_source_spikes_but_not_sources_near_the_limit_everywhere():
    """A few nodes over PECLET_MAX (a trailing edge) are clipped and the level is kept; a
    level whose sources sit just under PECLET_MAX on every node (a geometric wall stretching
    coarsened four times: ψ ≈ 0.96 on the 33 × 7 level of the 64 × 24 ellipse) is not, and
    neither is one with more than PECLET_FRACTION of its nodes over; border rows do not count."""
    shape = (65, 13)
    rng = np.random.default_rng(5)
    ph = rng.uniform(-0.4, 0.4, shape)
    qh = rng.uniform(-0.4, 0.4, shape)
    qh[:, [0, -1]] = 3.0  # border rows: read by no kernel
    assert C.coarse_ok(ph, qh)
    spikes = ph.copy()
    few = int(C.PECLET_FRACTION * shape[0] * (shape[1] - 2))
    spikes[1 : 1 + few, 1] = 1.5
    assert C.coarse_ok(spikes, qh)
    spikes[1 : 2 + few, 1] = 1.5
    assert not C.coarse_ok(spikes, qh)
    near = np.full(shape, 0.96 * C.PECLET_MAX)
    assert not C.coarse_ok(ph, near)
    assert C.coarse_ok(ph, np.full(shape, 0.5 * C.PECLET_MAX))


# --------------------------------------------------------------------- model problems
@pytest.mark.parametrize("b", [0.3, 0.6])
def test_wall_controlled_ogrid_converges_by_multigrid_in_a_size_independent_number_of_cycles(b):
    """Before: the first cycle folded the wall cells and multigrid fell back to SOR, whose
    sweeps grow with the size (2004 at 128×48, 7718 at 256×96 for b = 0.3)."""
    small, h = _controlled(64, 24, "multigrid", b)
    large, h2 = _controlled(128, 48, "multigrid", b)
    assert multigrid.last_run["sources_follow_grid"] is True  # the second try
    for g, hh in ((small, h), (large, h2)):
        assert g.converged and g.info.message == "converged" and _no_fallback(g), g.info.message
        assert meshcore.quality(g).n_folded == 0
        rep = boundary_report(g, ("bottom",), {"bottom": hh})
        assert rep["max_spacing_error"] <= 0.05 and rep["max_angle_deviation"] <= 2.0
    assert large.iterations <= 1.25 * small.iterations + 4, (small.iterations, large.iterations)


def test_wall_controlled_multigrid_reaches_the_sor_grid():
    mg, _ = _controlled(64, 24, "multigrid")
    sor, _ = _controlled(64, 24, "sor")
    assert mg.converged and sor.converged and _no_fallback(mg)
    # both stop when the control has settled (source change ≤ 1e-4): the grids agree to that
    d = float(np.hypot(mg.x - sor.x, mg.y - sor.y).max())
    assert d <= 1e-4 * mg.size, d


def test_wall_controlled_serial_and_two_threads_give_bit_identical_grids():
    a, _ = _controlled(192, 72, "multigrid", threads=1)
    b, _ = _controlled(192, 72, "multigrid", threads=2)
    assert a.converged and b.converged and _no_fallback(a) and a.iterations == b.iterations
    assert np.array_equal(a.x, b.x) and np.array_equal(a.y, b.y)


# ---------------------------------------------------------------------- the examples
def test_naca_ogrid_example_converges_by_multigrid_to_the_sor_grid():
    from meshcore.case import generate_case, load_case

    cs = load_case(EXAMPLES / "naca0012-ogrid.toml")
    mg = generate_case(cs, config=dataclasses.replace(cs.solver, method="multigrid"))[0]
    sor = generate_case(cs, config=dataclasses.replace(cs.solver, method="sor"))[0]
    assert mg.converged and mg.info.message == "converged" and _no_fallback(mg), mg.info.message
    d = float(np.hypot(mg.x - sor.x, mg.y - sor.y).max())
    assert d <= 1e-4 * mg.size, d


def test_controlled_solves_that_converged_before_run_as_before():
    """Thomas–Middlecoff alone converges with the plain cycles (FMG start, fused coarse
    levels): the sources-following cycles are only the second try, so nothing changes."""
    s = np.linspace(0.0, 1.0, 65)
    bottom = np.column_stack([s, 0.08 * np.sin(2 * np.pi * s)])
    top = np.column_stack([s, 1.0 + 0.06 * np.sin(3 * np.pi * s)])
    left = np.column_stack([0 * s, s])
    right = np.column_stack([1.0 + 0.1 * np.sin(np.pi * s), s])
    g0 = meshcore.initial_grid(meshcore.prepare_borders(bottom, right, top, left))
    g = meshcore.solve(g0, method="multigrid", sources=make_sources({"thomas-middlecoff": True}))
    assert g.converged and g.info.message == "converged" and _no_fallback(g)
    assert multigrid.last_run["sources_follow_grid"] is False


def test_fallback_to_sor_starts_the_control_over_and_says_so(monkeypatch):
    """With sources frozen over a cycle (a control that does not say its sources are
    metric-scaled) multigrid diverges on the wall-controlled NACA O-grid: SOR then starts
    from the start grid *and* the control's start state, so the result is the SOR grid bit
    for bit, and the message keeps why SOR ran."""
    from meshcore.case import generate_case, load_case

    monkeypatch.setattr(ControlSources, "metric_scaled", False)
    cs = load_case(EXAMPLES / "naca0012-ogrid.toml")
    mg = generate_case(cs, config=dataclasses.replace(cs.solver, method="multigrid"))[0]
    sor = generate_case(cs, config=dataclasses.replace(cs.solver, method="sor"))[0]
    assert mg.converged and mg.info.message.startswith("converged (multigrid diverged; continued with SOR"), (
        mg.info.message
    )
    assert np.array_equal(mg.x, sor.x) and np.array_equal(mg.y, sor.y)
