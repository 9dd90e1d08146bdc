"""Nonlinear multigrid (FAS): same solution as SOR, any size, periodic, P/Q, rates, kernels."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

import meshcore
from meshcore.elliptic import _kernels, _mg_kernels, _reference, multigrid
from tests.conftest import annulus_sector, borders_of

E = np.zeros((0, 0))


def _start(X, Y, periodic=False):
    """Algebraic start grid on the boundary nodes of (X, Y)."""
    if periodic:
        Xs, Ys = X.copy(), Y.copy()
        # straight radial interpolation between the inner and outer ring
        t = np.linspace(0.0, 1.0, X.shape[1])
        Xs[:] = X[:, :1] + (X[:, -1:] - X[:, :1]) * t
        Ys[:] = Y[:, :1] + (Y[:, -1:] - Y[:, :1]) * t
        return meshcore.StructuredGrid(Xs, Ys, periodic=True)
    return meshcore.initial_grid(meshcore.prepare_borders(*borders_of(X, Y)))


def _curved(ni, nj, amp=0.3):
    """A domain with wavy bottom/top borders and a bulging right border."""
    s = np.linspace(0.0, 1.0, ni + 1)
    t = np.linspace(0.0, 1.0, nj + 1)
    bottom = np.column_stack([2 * s, amp * 0.4 * np.sin(2 * np.pi * s)])
    top = np.column_stack([2 * s, 1 + amp * 0.3 * np.sin(3 * np.pi * s)])
    left = np.column_stack([0 * t, t])
    right = np.column_stack([2 + amp * 0.5 * np.sin(np.pi * t), t])
    return meshcore.initial_grid(meshcore.prepare_borders(bottom, right, top, left))


def _ring(ni, nj, r0=1.0, r1=3.0):
    """Exact Winslow O-grid of an annulus: i along θ (clockwise, periodic), j along ln r."""
    th = np.linspace(0.0, -2 * np.pi, ni + 1)
    r = r0 * (r1 / r0) ** np.linspace(0.0, 1.0, nj + 1)
    T, R = np.meshgrid(th, r, indexing="ij")
    X, Y = R * np.cos(T), R * np.sin(T)
    X[-1], Y[-1] = X[0], Y[0]
    return X, Y


def _rates(grid):
    h = [r for _, r in grid.info.residual_history]
    return [h[k + 1] / h[k] for k in range(1, len(h) - 1)]


# --------------------------------------------------------------- hierarchy
@pytest.mark.parametrize("shape", [(7, 16), (38, 24), (101, 58), (2050, 18), (5, 5), (1025, 1025)])
def test_hierarchy_reaches_a_tiny_coarsest_level(shape):
    X, Y = np.meshgrid(np.linspace(0, 1, shape[0]), np.linspace(0, 1, shape[1]), indexing="ij")
    cells = multigrid.hierarchy(X, Y)
    assert cells[0] == (shape[0] - 1, shape[1] - 1)
    assert max(cells[-1]) < multigrid.MIN_COARSEN_CELLS
    for (a, b), (c, d) in itertools.pairwise(cells):
        assert c in (a, (a + 1) // 2) and d in (b, (b + 1) // 2)
        assert (c, d) != (a, b)


def test_long_cells_are_semi_coarsened_across():
    # cells 4x longer in ξ than in η: η is strongly coupled, so only η is coarsened first
    X, Y = np.meshgrid(np.linspace(0, 8, 65), np.linspace(0, 1, 33), indexing="ij")
    cells = multigrid.hierarchy(X, Y)
    assert cells[:3] == [(64, 32), (64, 16), (64, 8)]
    assert multigrid.hierarchy(Y.T, X.T)[:3] == [(32, 64), (16, 64), (8, 64)]
    assert multigrid.coarsening((64, 64), 1.0) == (True, True)


@pytest.mark.parametrize("n", [5, 7, 13, 33, 100, 125])
def test_every_level_is_uniform_in_the_finest_index(n):
    """Even uniform levels keep every other node; others spread ⌈n/2⌉ intervals evenly."""
    pos = np.arange(n + 1.0)
    for _ in range(6):
        if pos.size <= 3:
            break
        c = _mg_kernels.coarse_positions(pos, True)
        assert c.size - 1 == (pos.size - 1 + 1) // 2 and c[0] == 0 and c[-1] == n
        np.testing.assert_allclose(np.diff(c), n / (c.size - 1), rtol=1e-12)
        if (pos.size - 1) % 2 == 0:
            assert np.array_equal(c, pos[::2])  # nested: the coarse nodes are fine nodes
        pos = c


def _dense(tab, n):
    """Dense R̂ (sampling), R (restriction) and P (interpolation) of one direction."""
    si, swi, ri, rw, left, wl, pos_c = tab
    nc1 = pos_c.size
    S, R, P = np.zeros((nc1, n + 1)), np.zeros((nc1, n + 1)), np.zeros((n + 1, nc1))
    for I in range(nc1):
        S[I, si[I]] += swi[I]
        S[I, si[I] + 1] += 1 - swi[I]
        for a in range(ri.shape[1]):
            R[I, ri[I, a]] += rw[I, a]
    for i in range(n + 1):
        P[i, left[i]] += wl[i]
        P[i, left[i] + 1] += 1 - wl[i]
    return S, R, P


@pytest.mark.parametrize("n", [4, 5, 6, 7, 12, 13])
@pytest.mark.parametrize("periodic", [False, True])
def test_transfer_tables_interpolate_linear_functions_and_restrict_constants(n, periodic):
    pos = np.arange(n + 1) * 3.0 + 2  # positions on the finest level (a uniform level)
    tab = _mg_kernels.transfer_tables(pos, True, periodic)
    pos_c = tab[6]
    S, R, P = _dense(tab, n)
    f = 3.0 * pos + 1.0  # a linear function of the position
    np.testing.assert_allclose(S @ f, 3.0 * pos_c + 1.0, rtol=0, atol=1e-12)  # sampling
    np.testing.assert_allclose(P @ (3.0 * pos_c + 1.0), f, rtol=0, atol=1e-12)  # interpolation
    np.testing.assert_allclose(R.sum(axis=1), 1.0, rtol=0, atol=1e-15)
    assert np.all(tab[2] >= 0) and np.all(tab[2] <= n)
    # R is the normalised transpose of P (periodic: the seam node n is node 0)
    Pt = P.T.copy()
    if periodic:
        Pt[:, n] = 0.0  # a repeat of node 0, not a node of its own
        Pt[0] += Pt[-1]
        Pt[-1] = Pt[0]
    inner = slice(0, None) if periodic else slice(1, -1)
    np.testing.assert_allclose(R[inner], (Pt / Pt.sum(axis=1, keepdims=True))[inner], atol=1e-15)
    if n % 2 == 0:  # nested: injection and the 1/4 1/2 1/4 stencil
        assert set(tab[1]) <= {0.0, 1.0}
        full = R[inner][:, :n].max(axis=1) == 0.5
        assert full.all()


# -------------------------------------------------------------- kernels
@pytest.mark.kernel
def test_smoother_is_the_4_colour_gauss_seidel_sweep():
    rng = np.random.default_rng(3)
    # (.., 200): rows long enough for the vectorised row update (VECTOR_ROW)
    for ni, nj, periodic in [(9, 7, False), (16, 11, False), (12, 9, True), (6, 200, False), (8, 200, True)]:
        X, Y = np.meshgrid(np.arange(ni + 1.0), np.arange(nj + 1.0), indexing="ij")
        X = X + 0.2 * rng.standard_normal(X.shape)
        Y = Y + 0.2 * rng.standard_normal(Y.shape)
        if periodic:
            X[-1], Y[-1] = X[0], Y[0]
        p, q = rng.standard_normal(X.shape), rng.standard_normal(X.shape)
        a = (X.copy(), Y.copy())
        b = (X.copy(), Y.copy())
        _mg_kernels.smooth(a[0], a[1], E, E, p, q, periodic, 2)
        for _ in range(2):
            _reference.sweep4(b[0], b[1], p, q, 1.0, periodic)
        np.testing.assert_allclose(a[0], b[0], rtol=0, atol=1e-12)
        np.testing.assert_allclose(a[1], b[1], rtol=0, atol=1e-12)


@pytest.mark.kernel
def test_defect_is_the_jacobi_displacement_times_the_diagonal_and_rhs_shifts_it():
    rng = np.random.default_rng(4)
    X, Y = np.meshgrid(np.arange(14.0), np.arange(9.0), indexing="ij")
    X = X + 0.2 * rng.standard_normal(X.shape)
    Y = Y + 0.2 * rng.standard_normal(Y.shape)
    p, q = rng.standard_normal(X.shape), rng.standard_normal(X.shape)
    rx, ry = np.empty_like(X), np.empty_like(X)
    m = _mg_kernels.defect(X, Y, E, E, p, q, False, rx, ry)
    nx, ny = _reference.jacobi_update(X, Y, p, q)
    assert math.sqrt(m) == pytest.approx(_kernels.jacobi_residual(X, Y, p, q, False), rel=1e-12)
    xe, xw = X[2:, 1:-1], X[:-2, 1:-1]
    ye, yw = Y[2:, 1:-1], Y[:-2, 1:-1]
    xn, xs = X[1:-1, 2:], X[1:-1, :-2]
    yn, ys = Y[1:-1, 2:], Y[1:-1, :-2]
    den = 0.5 * ((xn - xs) ** 2 + (yn - ys) ** 2 + (xe - xw) ** 2 + (ye - yw) ** 2)
    np.testing.assert_allclose(rx[1:-1, 1:-1], den * (nx - X)[1:-1, 1:-1], rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(ry[1:-1, 1:-1], den * (ny - Y)[1:-1, 1:-1], rtol=1e-10, atol=1e-12)
    assert not rx[0].any() and not rx[-1].any() and not rx[:, 0].any() and not rx[:, -1].any()
    # f − N(u): adding f to the defect; the smoother then solves N(u) = f
    fx, fy = rx.copy(), ry.copy()
    rx2, ry2 = np.empty_like(X), np.empty_like(X)
    _mg_kernels.defect(X, Y, fx, fy, p, q, False, rx2, ry2)
    np.testing.assert_allclose(rx2, 2 * rx, rtol=1e-12, atol=1e-12)
    fx2, fy2 = np.zeros_like(X), np.zeros_like(X)
    _mg_kernels.add_operator(X, Y, p, q, False, fx2, fy2)
    np.testing.assert_allclose(fx2, -rx, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(fy2, -ry, rtol=1e-12, atol=1e-12)


@pytest.mark.kernel
def test_defect_measure_is_infinite_when_any_node_is_nan():
    X, Y = np.meshgrid(np.arange(60.0), np.arange(50.0), indexing="ij")
    rx, ry = np.empty_like(X), np.empty_like(X)
    assert _mg_kernels.defect(X, Y, E, E, E, E, False, rx, ry) == 0.0
    for i, j in [(1, 1), (30, 25), (58, 48)]:
        Xn = X.copy()
        Xn[i, j] = np.nan
        assert _mg_kernels.defect(Xn, Y, E, E, E, E, False, rx, ry) == np.inf
        assert _kernels.jacobi_residual(Xn, Y, E, E, False) == np.inf


@pytest.mark.kernel
@pytest.mark.parametrize("ni, nj", [(11, 8), (12, 8), (13, 9)])
def test_restriction_and_prolongation_are_the_tensor_products_of_the_tables(ni, nj):
    rng = np.random.default_rng(5)
    ti = _mg_kernels.transfer_tables(np.arange(ni + 1.0), True, False)
    tj = _mg_kernels.transfer_tables(np.arange(nj + 1.0), True, False)
    Si, Ri, Pi = _dense(ti, ni)
    Sj, Rj, Pj = _dense(tj, nj)
    shape_c = (ti[6].size, tj[6].size)
    r = rng.standard_normal((ni + 1, nj + 1))
    fx, fy = np.empty(shape_c), np.empty(shape_c)
    _mg_kernels.restrict(r, -r, ti[2], ti[3], tj[2], tj[3], 16.0, fx, fy)
    np.testing.assert_allclose(fx, 16.0 * Ri @ r @ Rj.T, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(fy, -fx, rtol=0, atol=0)
    # sampling R̂ (injection where nested)
    sx = np.empty(shape_c)
    _mg_kernels.sample(r, ti[0], ti[1], tj[0], tj[1], sx)
    np.testing.assert_allclose(sx, Si @ r @ Sj.T, rtol=1e-12, atol=1e-12)
    # prolongation of the correction: x += P (xc − R̂x) on interior nodes
    x, y = rng.standard_normal(r.shape), rng.standard_normal(r.shape)
    xc = Si @ x @ Sj.T + rng.standard_normal(shape_c)
    want = x + Pi @ (xc - Si @ x @ Sj.T) @ Pj.T
    want[0], want[-1], want[:, 0], want[:, -1] = x[0], x[-1], x[:, 0], x[:, -1]
    ex, ey = np.empty_like(fx), np.empty_like(fx)
    _mg_kernels.prolong_correct(
        x, y, xc, xc.copy(), ex, ey, ti[0], ti[1], tj[0], tj[1], ti[4], tj[4], ti[5], tj[5], False
    )
    np.testing.assert_allclose(x, want, rtol=0, atol=1e-12)


@pytest.mark.kernel
@pytest.mark.parametrize("ni, nj", [(40, 34), (101, 57), (64, 33)])
def test_fused_defect_restriction_is_defect_then_restriction(ni, nj):
    """No fine defect arrays: the same numbers bit for bit (nested and non-nested tables)."""
    rng = np.random.default_rng(ni)
    X, Y = np.meshgrid(np.linspace(0, 1, ni + 1), np.linspace(0, 1, nj + 1) ** 1.2, indexing="ij")
    X = X + 1e-3 * rng.standard_normal(X.shape)
    f, pq = 1e-4 * rng.standard_normal(X.shape), 0.1 * rng.standard_normal(X.shape)
    ti = _mg_kernels.transfer_tables(np.arange(ni + 1.0), True, False)
    tj = _mg_kernels.transfer_tables(np.arange(nj + 1.0), True, False)
    shape = (ti[6].size, tj[6].size)
    for F, P in ((E, E), (f, pq)):
        rx, ry = np.empty_like(X), np.empty_like(X)
        a, b = np.empty(shape), np.empty(shape)
        m = _mg_kernels.defect(X, Y, F, F, P, P, False, rx, ry)
        _mg_kernels.restrict(rx, ry, ti[2], ti[3], tj[2], tj[3], 16.0, a, b)
        for fn, chunks in itertools.product(
            (_mg_kernels.defect_restrict, _mg_kernels.defect_restrict_parallel), (1, 3, 16)
        ):
            c, d = np.empty(shape), np.empty(shape)
            assert fn(X, Y, F, F, P, P, ti[2], ti[3], tj[2], tj[3], 16.0, c, d, chunks) == m
            assert np.array_equal(a, c) and np.array_equal(b, d)


@pytest.mark.parametrize("periodic", [False, True])
def test_parallel_kernels_are_bit_identical(periodic):
    rng = np.random.default_rng(6)
    # odd periodic ni: rows 0 and ni-1 are same-parity neighbours; 60 nodes per row: the
    # vectorised row update; the serial smoother runs as a one-pass wavefront
    for ni, nj1 in itertools.product((40, 41), (34, 60)):
        X, Y = np.meshgrid(np.arange(ni + 1.0), np.arange(float(nj1)), indexing="ij")
        X = X + 0.2 * rng.standard_normal(X.shape)
        Y = Y + 0.2 * rng.standard_normal(Y.shape)
        if periodic:
            X[-1], Y[-1] = X[0], Y[0]
        f = rng.standard_normal(X.shape), rng.standard_normal(X.shape)
        a = [X.copy(), Y.copy()]
        b = [X.copy(), Y.copy()]
        _mg_kernels.smooth(a[0], a[1], f[0], f[1], E, E, periodic, 3)
        _mg_kernels.smooth_parallel(b[0], b[1], f[0], f[1], E, E, periodic, 3)
        assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])
        ra = [np.empty_like(X) for _ in range(2)]
        rb = [np.empty_like(X) for _ in range(2)]
        ma = _mg_kernels.defect(a[0], a[1], f[0], f[1], E, E, periodic, *ra)
        mb = _mg_kernels.defect_parallel(b[0], b[1], f[0], f[1], E, E, periodic, *rb)
        assert ma == mb and np.array_equal(ra[0], rb[0]) and np.array_equal(ra[1], rb[1])


def test_serial_and_parallel_compilations_are_cached_under_distinct_names():
    # numba's disk cache files a function by qualified name and line only: two compilations of
    # one Python function (serial and parallel=True) would load each other's machine code
    pairs = [(_kernels.sweep4, _kernels.sweep4_parallel)]
    pairs += [
        (getattr(_mg_kernels, n), getattr(_mg_kernels, n + "_parallel"))
        for n in ("smooth", "defect", "add_operator", "restrict", "prolong_correct", "defect_restrict")
    ]
    names = set()
    for serial, parallel in pairs:
        assert not serial.targetoptions.get("parallel") and parallel.targetoptions["parallel"]
        names |= {serial.py_func.__qualname__, parallel.py_func.__qualname__}
    assert len(names) == 2 * len(pairs)


# --------------------------------------------------------------- solver
def _compare_with_sor(g0, **kw):
    mg = meshcore.solve(g0, method="multigrid", tolerance=1e-12, **kw)
    sor = meshcore.solve(g0, method="sor", tolerance=1e-12, **kw)
    assert mg.converged and sor.converged, (mg.info.message, sor.info.message)
    assert mg.info.method == "multigrid"
    h = mg.info.residual_history
    assert [i for i, _ in h] == list(range(len(h))), "multigrid must not fall back to SOR"
    d = float(np.hypot(mg.x - sor.x, mg.y - sor.y).max())
    assert d <= 1e-8 * g0.size, d
    assert meshcore.quality(mg).n_folded == 0
    return mg


@pytest.mark.parametrize("cells", [(6, 15), (37, 23), (100, 57), (64, 64)])
def test_multigrid_and_sor_reach_the_same_grid(cells):
    X, Y = annulus_sector(*cells, th0=0.2, th1=1.9)
    g0 = _start(X, Y)
    mg = _compare_with_sor(g0)
    # and it is the discrete Winslow solution: second-order close to the exact map
    assert float(np.hypot(mg.x - X, mg.y - Y).max()) < 0.5 * (3.0 / min(cells)) ** 2


def test_multigrid_on_a_curved_domain_matches_sor():
    _compare_with_sor(_curved(48, 40))


def test_multigrid_with_sources_p_q_matches_sor():
    g0 = _curved(40, 33)
    ii, jj = np.meshgrid(np.linspace(0, 1, 41), np.linspace(0, 1, 34), indexing="ij")
    p = 20.0 * np.sin(np.pi * ii) * np.cos(np.pi * jj)
    q = -30.0 * np.exp(-5 * jj)
    mg = _compare_with_sor(g0, p=p, q=q)
    plain = meshcore.solve(g0, method="multigrid", tolerance=1e-12)
    assert float(np.hypot(mg.x - plain.x, mg.y - plain.y).max()) > 0.01 * g0.size


@pytest.mark.parametrize("ni", [48, 45])
def test_periodic_o_grid(ni):
    X, Y = _ring(ni, 24)
    g0 = _start(X, Y, periodic=True)
    mg = _compare_with_sor(g0)
    assert mg.periodic
    np.testing.assert_array_equal(mg.x[-1], mg.x[0])
    np.testing.assert_array_equal(mg.y[-1], mg.y[0])
    # rotational symmetry: every node stays near its exact (r, θ)
    assert float(np.hypot(mg.x - X, mg.y - Y).max()) < 0.05


def test_serial_and_two_threads_give_bit_identical_grids():
    X, Y = annulus_sector(150, 140)
    g0 = _start(X, Y)
    a = meshcore.solve(g0, method="multigrid", threads=1)
    b = meshcore.solve(g0, method="multigrid", threads=2)
    assert a.converged and b.converged and a.iterations == b.iterations
    assert np.array_equal(a.x, b.x) and np.array_equal(a.y, b.y)
    Xr, Yr = _ring(150, 70)
    g0 = _start(Xr, Yr, periodic=True)
    a = meshcore.solve(g0, method="multigrid", threads=1)
    b = meshcore.solve(g0, method="multigrid", threads=2)
    assert np.array_equal(a.x, b.x) and np.array_equal(a.y, b.y)


def test_default_threads_are_automatic_and_change_nothing():
    from meshcore.elliptic.solver import AUTO_THREADS_MIN_NODES, resolve_threads

    assert meshcore.EllipticConfig().threads == 0
    assert resolve_threads(0, AUTO_THREADS_MIN_NODES - 1) == 1
    assert resolve_threads(0, AUTO_THREADS_MIN_NODES) >= 1 and resolve_threads(3, 10) == 3
    g0 = _curved(160, 120)  # 19 481 nodes: threaded by default
    auto = meshcore.solve(g0)
    serial = meshcore.solve(g0, threads=1)
    assert auto.info.method == serial.info.method == "multigrid"
    assert np.array_equal(auto.x, serial.x) and np.array_equal(auto.y, serial.y)


@pytest.mark.parametrize("case", ["annulus", "curved"])
def test_convergence_factor_per_cycle(case):
    if case == "annulus":
        X, Y = annulus_sector(128, 128)
        g0 = _start(X, Y)
    else:
        g0 = _curved(256, 128)
    g = meshcore.solve(g0, method="multigrid", tolerance=1e-12)
    assert g.converged
    rates = _rates(g)
    assert len(rates) >= 3
    mean = math.exp(np.mean(np.log(rates)))
    assert mean <= 0.2, rates
    # cost is independent of the grid size: a grid 4x as large needs about as many cycles
    if case == "annulus":
        X2, Y2 = annulus_sector(256, 256)
        g2 = meshcore.solve(_start(X2, Y2), method="multigrid", tolerance=1e-12)
        assert g2.converged and g2.iterations <= g.iterations + 2


@pytest.mark.parametrize("cells", [(125, 63), (97, 64), (99, 49), (100, 57)])
def test_odd_sizes_converge_as_fast_as_even_ones(cells):
    """Odd cell counts coarsen to uniform non-nested levels: no slow mode at a short interval
    (a subset of fine nodes with one short interval ran at 0.2–0.4 per cycle, 125 × 63 diverged)."""
    g = meshcore.solve(_curved(*cells), method="multigrid", tolerance=1e-12)
    assert g.converged and g.info.message == "converged", g.info.message
    rates = _rates(g)
    assert math.exp(np.mean(np.log(rates))) <= 0.15, rates
    even = meshcore.solve(
        _curved(cells[0] + cells[0] % 2, cells[1] + cells[1] % 2), method="multigrid", tolerance=1e-12
    )
    assert g.iterations <= even.iterations + 1


def test_auto_picks_multigrid_for_large_grids_and_sor_for_tiny_ones():
    X, Y = annulus_sector(64, 64)
    assert meshcore.solve(_start(X, Y)).info.method == "multigrid"
    X, Y = annulus_sector(6, 15)
    assert meshcore.solve(_start(X, Y)).info.method == "sor"


def test_w_cycles_converge_to_the_same_grid():
    g0 = _curved(40, 31)
    v = meshcore.solve(g0, method="multigrid", tolerance=1e-12)
    w = meshcore.solve(g0, method="multigrid-w", tolerance=1e-12)
    assert w.converged and w.iterations <= v.iterations + 2
    assert float(np.hypot(v.x - w.x, v.y - w.y).max()) <= 1e-8 * g0.size


class _CountingSources:
    """A control-function updater: P grows towards a target as the grid converges."""

    def __init__(self):
        self.updates = []

    def initialize(self, x, y, p, q):
        p[...] = 0.0
        q[...] = 0.0

    def wants_update(self, it):
        return it % 2 == 0 and len(self.updates) < 4

    def update(self, x, y, p, q, it):
        self.updates.append(it)
        q[...] = -0.1 * len(self.updates)


def test_sources_are_updated_between_cycles():
    g0 = _curved(64, 40)
    src = _CountingSources()
    g = meshcore.solve(g0, method="multigrid", sources=src, tolerance=1e-12)
    assert g.converged and src.updates == [2, 4, 6, 8]
    # the result solves the equations with the final Q
    q = np.full(g.x.shape, -0.4)
    assert meshcore.elliptic.residual(g, np.zeros_like(q), q) <= 1e-12 * g.size * (1 + 1e-9)
    assert meshcore.elliptic.residual(g) > 1e-8 * g.size


def test_iterate_yields_snapshots_and_stops():
    X, Y = annulus_sector(200, 200)
    gen = meshcore.iterate(_start(X, Y), method="multigrid", tolerance=1e-15, report_interval=1e-9)
    snaps = [next(gen) for _ in range(3)]
    assert [s.method for s in snaps] == ["multigrid"] * 3
    assert snaps[0].iteration < snaps[2].iteration
    assert not np.array_equal(snaps[0].grid.x, snaps[2].grid.x)
    with pytest.raises(StopIteration) as fin:
        gen.send("stop")
    assert fin.value.value.info.message == "stopped"


def test_reused_workspaces_give_the_same_grids():
    """Small solves keep their working storage; nothing of one solve leaks into the next."""
    a0, b0 = _curved(64, 48), _curved(64, 48, amp=0.6)
    ii = np.linspace(0.0, 1.0, 65)[:, None] * np.ones(49)
    multigrid._WORKSPACES.clear()
    ref_a = meshcore.solve(a0, method="multigrid")
    multigrid._WORKSPACES.clear()
    ref_b = meshcore.solve(b0, method="multigrid", p=5 * ii, q=-ii)
    for _ in range(2):  # each from a workspace the other left behind
        a = meshcore.solve(a0, method="multigrid")
        b = meshcore.solve(b0, method="multigrid", p=5 * ii, q=-ii)
        assert np.array_equal(a.x, ref_a.x) and np.array_equal(b.y, ref_b.y)
    # two solves of one shape at once never share a workspace
    gen = meshcore.iterate(a0, method="multigrid", report_interval=1e-9)
    next(gen)
    b = meshcore.solve(b0, method="multigrid", p=5 * ii, q=-ii)
    for _ in gen:
        pass
    assert np.array_equal(b.x, ref_b.x)
    a = meshcore.solve(a0, method="multigrid")
    assert np.array_equal(a.x, ref_a.x)
    assert all(lv[0].x.size == 0 for lv, *_ in multigrid._WORKSPACES.values())


@pytest.mark.parametrize("periodic", [False, True])
def test_fused_fmg_start_is_the_level_by_level_one(monkeypatch, periodic):
    g0 = _start(*_ring(64, 30), periodic=True) if periodic else _curved(100, 57)
    a = meshcore.solve(g0, method="multigrid")
    ua = multigrid.last_run["node_updates"]
    monkeypatch.setattr(multigrid, "YIELD_NODES", 0)  # every FMG step from Python
    b = meshcore.solve(g0, method="multigrid")
    assert np.array_equal(a.x, b.x) and np.array_equal(a.y, b.y)
    assert a.iterations == b.iterations and ua == multigrid.last_run["node_updates"]


def test_max_iterations_caps_the_cycles():
    X, Y = annulus_sector(64, 64)
    g = meshcore.solve(_start(X, Y), method="multigrid", tolerance=1e-15, max_iterations=2)
    assert not g.converged and g.iterations == 2


@pytest.mark.parametrize("cells", [(30, 6), (40, 8), (64, 16)])
def test_full_ring_with_a_fixed_cut_does_not_coarsen_into_a_degenerate_ring(cells):
    """The paper's doubly connected case: a ring of 2 cells is a folded coarse grid."""
    t = np.linspace(0.0, -2 * np.pi, 41)
    cut = np.column_stack([np.linspace(1.0, 3.0, 5), np.zeros(5)])
    b = meshcore.Borders(
        bottom=np.column_stack([np.cos(t), np.sin(t)]),
        right=cut,
        top=np.column_stack([3 * np.cos(t), 3 * np.sin(t)]),
        left=cut,
    )
    g0 = meshcore.initial_grid(b.resampled(cells), weights=(0.05, 0.0))
    levels = multigrid.hierarchy(g0.x, g0.y)
    assert levels[-1][0] >= 3  # 2 cells around would be a folded coarse ring
    _compare_with_sor(g0)


@pytest.mark.kernel
def test_band_smoother_is_gauss_seidel_restricted_to_the_border_band():
    rng = np.random.default_rng(8)
    X, Y = np.meshgrid(np.arange(31.0), np.arange(27.0), indexing="ij")
    X = X + 0.2 * rng.standard_normal(X.shape)
    Y = Y + 0.2 * rng.standard_normal(Y.shape)
    a = [X.copy(), Y.copy()]
    _mg_kernels.smooth_band(a[0], a[1], E, E, E, E, False, 5, 1)
    inner = (slice(6, -6), slice(6, -6))
    np.testing.assert_array_equal(a[0][inner], X[inner])  # untouched away from the borders
    assert not np.array_equal(a[0], X)
    # with a band covering everything it is the full 4-colour sweep
    b = [X.copy(), Y.copy()]
    c = [X.copy(), Y.copy()]
    _mg_kernels.smooth_band(b[0], b[1], E, E, E, E, False, 40, 2)
    _mg_kernels.smooth(c[0], c[1], E, E, E, E, False, 2)
    assert np.array_equal(b[0], c[0]) and np.array_equal(b[1], c[1])


@pytest.mark.parametrize("periodic", [False, True])
def test_band_smoother_on_long_strips_solves_the_band_problem(periodic):
    """Long η-border strips are relaxed transposed (ξ ↔ η, P ↔ Q): many band sweeps
    must reach the solution of the equations on the band with everything else
    held fixed — the fixed point of the NumPy point-Jacobi oracle restricted to it."""
    rng = np.random.default_rng(9)
    ni, nj, w = 60, 52, _mg_kernels.TRANSPOSE_MAX_WIDTH
    if periodic:
        X, Y = _ring(ni, nj)
    else:
        X, Y = np.meshgrid(np.linspace(0, 1, ni + 1), np.linspace(0, 1, nj + 1) ** 1.3, indexing="ij")
        X = X + 0.05 * np.sin(3 * Y)
    X[1:-1, 1:-1] += 0.002 * rng.standard_normal((ni - 1, nj - 1))
    if periodic:
        X[-1], Y[-1] = X[0], Y[0]
    p, q = 0.3 * rng.standard_normal(X.shape), np.full(X.shape, -0.2)
    band = np.zeros(X.shape, bool)
    band[:, 1 : w + 1] = band[:, nj - w : nj] = True
    if not periodic:
        band[1 : w + 1, 1:-1] = band[ni - w : ni, 1:-1] = True
        band[0] = band[-1] = False
    a = [X.copy(), Y.copy()]
    _mg_kernels.smooth_band(a[0], a[1], E, E, p, q, periodic, w, 300)
    assert np.array_equal(a[0][~band], X[~band]) and np.array_equal(a[1][~band], Y[~band])
    b = [X.copy(), Y.copy()]
    for _ in range(3000):
        nx, ny = _reference.jacobi_update(b[0], b[1], p, q, periodic)
        b[0][band], b[1][band] = nx[band], ny[band]
    moved = float(np.abs(a[0] - X).max())
    assert moved > 1e-3
    assert float(np.abs(a[0] - b[0]).max()) < 1e-10 * moved * 1e3
    assert float(np.abs(a[1] - b[1]).max()) < 1e-10 * moved * 1e3


def test_generate_block_threads_option_is_bit_identical():
    import meshcore
    from tests.conftest import annulus_sector, borders_of

    X, Y = annulus_sector(120, 90)
    a = meshcore.generate_block(*borders_of(X, Y), threads=2)
    b = meshcore.generate_block(*borders_of(X, Y), threads=1)
    assert a.info.method.startswith("multigrid")
    assert np.array_equal(a.x, b.x) and np.array_equal(a.y, b.y)
