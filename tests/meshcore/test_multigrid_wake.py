"""The C-grid wake cut as unknowns of the multigrid (issue 15): the cut kernels against their
NumPy references, nested coarse cuts, same grid as SOR, serial = two threads; and the
adaptive feedback gain of the wall control under multigrid."""

from __future__ import annotations

import numpy as np
import pytest

import meshcore
from meshcore.airfoil import naca4_body
from meshcore.control import make_sources, sources
from meshcore.control.sources import GAIN_MAX, _adapt, _BorderState
from meshcore.control.spec import BorderControl
from meshcore.elliptic import _mg_wake as W
from meshcore.elliptic import multigrid
from meshcore.topology import cgrid


def _cgrid(body_cells, wake, normal):
    c = cgrid(naca4_body("0012", body_cells), cells_wake=wake, cells_normal=normal)
    return c.grid, c.wake


def _perturbed(seed):
    """A C-grid with random interior and cut displacements (the cut mirrored) and random f."""
    g, wake = _cgrid(24, 12, 16)
    rng = np.random.default_rng(seed)
    x, y = np.array(g.x), np.array(g.y)
    ni = x.shape[0] - 1
    h = 0.05 * np.hypot(np.diff(x, axis=0), np.diff(y, axis=0)).min()
    x[1:-1, 1:-1] += h * rng.standard_normal((ni - 1, x.shape[1] - 2))
    y[1:-1, 1:-1] += h * rng.standard_normal((ni - 1, x.shape[1] - 2))
    i = np.arange(1, wake)
    x[i, 0] += h * rng.standard_normal(i.size)
    y[i, 0] += h * rng.standard_normal(i.size)
    x[ni - i, 0], y[ni - i, 0] = x[i, 0], y[i, 0]
    fx, fy = 1e-3 * rng.standard_normal(x.shape), 1e-3 * rng.standard_normal(x.shape)
    return x, y, fx, fy, wake


@pytest.mark.parametrize("seed", [0, 1])
def test_cut_defect_kernel_is_the_numpy_reference(seed):
    x, y, fx, fy, wake = _perturbed(seed)
    rcx, rcy = np.full(x.shape[0], 7.0), np.full(x.shape[0], 7.0)
    worst = W.cut_defect(x, y, fx, fy, wake, rcx, rcy)
    rx, ry, den = W.cut_defect_reference(x, y, fx, fy, wake)
    np.testing.assert_allclose(rcx[1:wake], rx, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(rcy[1:wake], ry, rtol=1e-12, atol=1e-15)
    assert not rcx[wake:].any() and rcx[0] == 0.0  # zero off the cut
    assert worst == pytest.approx(float(np.max((rx**2 + ry**2) / den**2)), rel=1e-12)


@pytest.mark.parametrize("seed", [0, 1])
def test_relax_cut_kernel_is_the_numpy_reference_and_solves_the_cut_equations(seed):
    x, y, fx, fy, wake = _perturbed(seed)
    xr, yr = x.copy(), y.copy()
    W.relax_cut(x, y, fx, fy, wake, 3)
    W.relax_cut_reference(xr, yr, fx, fy, wake, 3)
    np.testing.assert_allclose(x, xr, rtol=1e-13, atol=1e-15)
    np.testing.assert_allclose(y, yr, rtol=1e-13, atol=1e-15)
    ni = x.shape[0] - 1
    i = np.arange(1, wake)
    assert np.array_equal(x[i, 0], x[ni - i, 0]) and np.array_equal(y[i, 0], y[ni - i, 0])
    # many sweeps with the rest held: the cut equations hold
    W.relax_cut(x, y, fx, fy, wake, 2000)
    rx, ry, den = W.cut_defect_reference(x, y, fx, fy, wake)
    assert np.max(np.hypot(rx, ry) / den) < 1e-12


def test_coarse_levels_keep_the_cut_nested():
    g, wake = _cgrid(48, 24, 24)
    x, y = np.array(g.x), np.array(g.y)
    plan = multigrid._plan(x, y, False, None, wake)
    assert plan
    ni, w = x.shape[0] - 1, wake
    for ci, _cj, tab_i, _tab_j in plan:
        if ci:
            assert ni % 2 == 0 and w % 2 == 0 and w // 2 >= W.MIN_CUT_CELLS
            ni, w = ni // 2, w // 2
            # coarse cut node I and its mirror sit on fine cut node 2I and its mirror
            i = np.arange(1, w)
            assert np.array_equal(tab_i[0][i], 2 * i) and np.array_equal(tab_i[0][ni - i], 2 * (ni - i))
        assert tab_i[6].size - 1 == ni


def _solve(grid, wake, method, **kw):
    return meshcore.solve(grid, method=method, sources=make_sources({"wake": wake}), max_iterations=100_000, **kw)


def _no_fallback(g):
    h = g.info.residual_history
    return g.info.method == "multigrid" and [i for i, _ in h] == list(range(len(h)))


@pytest.mark.parametrize("size", [(24, 12, 16), (96, 32, 56)])
def test_wake_cgrid_converges_by_multigrid_to_the_sor_grid(size):
    """Before: the cut moved once per cycle (the updater's Jacobi step) and the multigrid
    stalled, handing over to SOR."""
    g0, wake = _cgrid(*size)
    mg = _solve(g0, wake, "multigrid", threads=1)
    sor = _solve(g0, wake, "sor")
    assert mg.converged and mg.info.message == "converged" and _no_fallback(mg), mg.info.message
    assert sor.converged
    ni = mg.shape[0] - 1
    i = np.arange(1, wake)
    assert np.array_equal(mg.x[i, 0], mg.x[ni - i, 0]) and np.array_equal(mg.y[i, 0], mg.y[ni - i, 0])
    assert not np.allclose(mg.x[i, 0], g0.x[i, 0])  # the cut nodes moved
    d = float(np.hypot(mg.x - sor.x, mg.y - sor.y).max())
    assert d <= 1e-4 * mg.size, d
    assert meshcore.quality(mg).n_folded == 0


def test_wake_cgrid_serial_and_two_threads_give_bit_identical_grids():
    g0, wake = _cgrid(96, 32, 56)  # 257 × 57 nodes: the finest levels run the threaded kernels
    a = _solve(g0, wake, "multigrid", threads=1)
    b = _solve(g0, wake, "multigrid", threads=2)
    assert a.converged and b.converged and a.iterations == b.iterations
    assert np.array_equal(a.x, b.x) and np.array_equal(a.y, b.y)


def test_adaptive_gain_grows_while_the_error_keeps_its_sign_and_backs_off_on_a_flip():
    n = 5
    bs = _BorderState(
        name="bottom",
        spec=BorderControl(spacing=1.0),
        idx=np.arange(1, n - 1),
        s_t=np.zeros(n),
        s_n=np.zeros(n),
        spacing_eff=np.ones(n),
        angle_eff=np.ones(n),
        weight=np.ones((n, 2)),
    )
    e = np.array([0.1, -0.2, 0.0])
    first = _adapt(bs, 0, e)
    assert np.array_equal(first, e)  # no history yet: gain 1
    for _ in range(40):
        out = _adapt(bs, 0, e)
    assert np.allclose(out, GAIN_MAX * e)  # capped
    flipped = _adapt(bs, 0, -e)
    assert np.allclose(flipped, -0.5 * GAIN_MAX * e)
    assert bs.gain[1].tolist() == [1.0] * n  # the angle row untouched


# ------------------------------------------------------------------ η-line relaxation
@pytest.mark.parametrize("seed", [0, 1])
@pytest.mark.parametrize("with_cut", [False, True])
@pytest.mark.parametrize("terms", ["none", "sources", "all"])
def test_line_kernel_is_the_numpy_reference_and_serial_is_parallel(seed, with_cut, terms):
    from meshcore.elliptic import _mg_lines as L

    x, y, fx, fy, wake = _perturbed(seed)
    rng = np.random.default_rng(seed + 10)
    empty = np.zeros((0, 0))
    p = rng.uniform(-2.0, 2.0, x.shape) if terms != "none" else empty
    q = rng.uniform(-3.0, 3.0, x.shape) if terms != "none" else empty  # |½D²Q| > γ: clipped
    f = (fx, fy) if terms == "all" else (empty, empty)
    cut = wake if with_cut else 0
    a, b, r = (x.copy(), y.copy()), (x.copy(), y.copy()), (x.copy(), y.copy())
    L.smooth_lines(*a, *f, p, q, cut, 3)
    L.smooth_lines_parallel(*b, *f, p, q, cut, 3)
    L.smooth_lines_reference(*r, *f, p, q, cut, 3)
    assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])
    np.testing.assert_allclose(a[0], r[0], rtol=0, atol=1e-12)
    np.testing.assert_allclose(a[1], r[1], rtol=0, atol=1e-12)
    ni = x.shape[0] - 1
    i = np.arange(1, wake)
    assert np.array_equal(a[0][i, 0], a[0][ni - i, 0])  # the cut stays one set of nodes
    moved = not np.array_equal(a[0][i, 0], x[i, 0])
    assert moved == with_cut  # without the cut its nodes are left to relax_cut
    assert np.array_equal(a[0][[0, -1]], x[[0, -1]]) and np.array_equal(a[0][:, -1], x[:, -1])


def test_line_sweeps_through_the_cut_solve_the_cut_and_interior_equations():
    """Many sweeps with nothing else: the fixed point is the discrete equations (P, Q, f
    included), at the interior and at the cut nodes alike."""
    from meshcore.elliptic import _mg_lines as L
    from meshcore.elliptic._reference import jacobi_update

    x, y, _fx, _fy, wake = _perturbed(3)
    empty = np.zeros((0, 0))
    rng = np.random.default_rng(4)
    p, q = rng.uniform(-0.5, 0.5, x.shape), rng.uniform(-0.5, 0.5, x.shape)
    L.smooth_lines(x, y, empty, empty, p, q, wake, 2000)
    nx, ny = jacobi_update(x, y, p, q)
    assert float(np.hypot(nx - x, ny - y).max()) < 1e-11
    rx, ry, den = W.cut_defect_reference(x, y, empty, empty, wake)
    assert float(np.max(np.hypot(rx, ry) / den)) < 1e-11


def _wall_cgrid(code, body_cells, wake, normal, first, method, **kw):
    """A NACA C-grid with the wall spacing and angle controlled on the body, Thomas–Middlecoff
    and the wake cut, solved."""
    c = cgrid(naca4_body(code, body_cells), cells_wake=wake, cells_normal=normal, first=first)
    ni = c.grid.x.shape[0] - 1
    spec = {
        "wake": c.wake,
        "thomas-middlecoff": True,
        "borders": {"bottom": {"spacing": first, "start": c.wake + 1, "stop": ni - c.wake}},
    }
    g = meshcore.solve(c.grid, method=method, sources=make_sources(spec), max_iterations=100_000, **kw)
    return g, c


@pytest.mark.parametrize("case", [("0012", 48, 16, 24, 1e-3), ("2412", 48, 16, 24, 1e-3)])
def test_wall_controlled_cgrid_converges_by_multigrid(case):
    """Before: the sources-following cycles stalled at the wake (point smoothing of cells
    ~100× longer in ξ, the cut relaxed apart from its lines) and handed over to SOR."""
    g, c = _wall_cgrid(*case, "multigrid", threads=1)
    assert g.converged and g.info.message == "converged" and _no_fallback(g), g.info.message
    assert multigrid.last_run["sources_follow_grid"] is True
    assert meshcore.quality(g).n_folded == 0
    ni = g.shape[0] - 1
    i = np.arange(1, c.wake)
    assert np.array_equal(g.x[i, 0], g.x[ni - i, 0]) and np.array_equal(g.y[i, 0], g.y[ni - i, 0])
    # the wall spacing is what was asked for
    body = np.arange(c.wake + 1, ni - c.wake)
    h = np.hypot(g.x[body, 1] - g.x[body, 0], g.y[body, 1] - g.y[body, 0])
    assert np.max(np.abs(h / case[4] - 1.0)) <= 0.05


def test_sources_frozen_the_cgrid_cycle_contracts(monkeypatch):
    """The rate per cycle of the sources-following cycle on a wall-controlled C-grid once
    the sources stop moving: the smoother, not the control, sets it (0.98 per cycle with the
    cut relaxed apart from its lines, ≈ 0.6 with the joined lines).  Fixed feedback gains
    (no ``_adapt``): the sources frozen after 40 updates are the plain iteration's, so the
    rate measured is the smoother's on the same problem as before."""
    monkeypatch.setattr(sources, "_adapt", lambda bs, row, e: e)
    c = cgrid(naca4_body("0012", 48), cells_wake=16, cells_normal=24, first=1e-3)
    ni = c.grid.x.shape[0] - 1
    spec = {
        "wake": c.wake,
        "thomas-middlecoff": True,
        "borders": {"bottom": {"spacing": 1e-3, "start": c.wake + 1, "stop": ni - c.wake}},
    }
    src = make_sources(spec)
    wants = src.wants_update
    src.wants_update = lambda it: it < 40 and wants(it)  # the sources freeze after 40 cycles
    g = meshcore.solve(c.grid, method="multigrid", sources=src, threads=1, max_iterations=70)
    h = dict(g.info.residual_history)
    assert _no_fallback(g)
    rate = (h[70] / h[50]) ** (1 / 20)
    assert rate < 0.8, rate
