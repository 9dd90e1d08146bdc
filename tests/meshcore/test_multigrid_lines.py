"""Alternating zebra-line smoothing of the multigrid on grids with mixed cell aspects (issue 15).

Branched lakes meshed as one block have cells far longer in ξ in some arms and far
longer in η in others: point Gauss–Seidel with any one (semi-)coarsening stalls
there.  These tests check the ξ ↔ η symmetry the ξ-line pass relies on, the
sweep against the NumPy reference, the convergence rate on a stretched, curved
model problem, and generated branched lakes as one block: solved by the
multigrid (no SOR hand-over) to the grid SOR gives.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import meshcore
from meshcore import testing
from meshcore.elliptic import _mg_kernels, _mg_lines, multigrid
from tests.conftest import borders_of, one_block_kwargs

E = np.zeros((0, 0))


def _wavy(ni, nj, seed=0, amp=0.15):
    rng = np.random.default_rng(seed)
    X, Y = np.meshgrid(np.linspace(0, 1, ni + 1), np.linspace(0, 2, nj + 1), indexing="ij")
    X = X + amp / ni * rng.standard_normal(X.shape)
    Y = Y + amp / nj * rng.standard_normal(Y.shape)
    return X, Y


def _mixed_aspect(ni: int, nj: int, beta: float = 3.0, bend: float = 0.3):
    """A curved square whose ξ spacing is fine at the left and η spacing fine at the top:
    cells ≈ 1:10 tall at the bottom left, 10:1 long at the top right."""
    s = np.tanh(beta * np.linspace(0, 1, ni + 1)) / np.tanh(beta)
    u = 1.0 - (np.tanh(beta * np.linspace(0, 1, nj + 1)) / np.tanh(beta))[::-1]
    X, Y = np.meshgrid(s, u, indexing="ij")
    return X + bend * np.sin(math.pi * Y), Y + 0.5 * bend * np.sin(math.pi * X)


@pytest.mark.kernel
def test_the_operator_is_the_same_under_xi_eta_exchange():
    """``N`` of the transposed grid with P ↔ Q is the transposed ``N``: what lets the η-line
    kernel relax ξ lines (:func:`multigrid._alt_lines`)."""
    X, Y = _wavy(23, 17, seed=3)
    rng = np.random.default_rng(4)
    p, q = rng.uniform(-2, 2, X.shape), rng.uniform(-2, 2, X.shape)
    fx, fy = rng.standard_normal(X.shape), rng.standard_normal(X.shape)
    r = [np.zeros_like(X), np.zeros_like(X)]
    m = _mg_kernels.defect(X, Y, fx, fy, p, q, False, r[0], r[1])
    t = [np.zeros_like(X.T), np.zeros_like(X.T)]
    c = np.ascontiguousarray
    mt = _mg_kernels.defect(c(X.T), c(Y.T), c(fx.T), c(fy.T), c(q.T), c(p.T), False, t[0], t[1])
    np.testing.assert_allclose(t[0].T, r[0], rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(t[1].T, r[1], rtol=1e-12, atol=1e-12)
    assert mt == pytest.approx(m, rel=1e-12)


@pytest.mark.kernel
@pytest.mark.parametrize("sources", [False, True])
def test_alternating_sweep_matches_the_reference(sources):
    X, Y = _wavy(19, 14, seed=5)
    rng = np.random.default_rng(6)
    p, q = (rng.uniform(-1, 1, X.shape), rng.uniform(-1, 1, X.shape)) if sources else (E, E)
    fx, fy = 0.01 * rng.standard_normal(X.shape), 0.01 * rng.standard_normal(X.shape)
    lv = multigrid._Level(X.copy(), Y.copy(), fx, fy, p, q)
    multigrid._alt_lines(lv)
    # reference: damped η-line sweep, then the same on the transposed arrays (P ↔ Q)
    w = multigrid.LINE_OMEGA
    x, y = X.copy(), Y.copy()
    _mg_lines.smooth_lines_reference(x, y, fx, fy, p, q, 0, 1)
    x, y = X + w * (x - X), Y + w * (y - Y)
    xt, yt = x.T.copy(), y.T.copy()
    _mg_lines.smooth_lines_reference(xt, yt, fx.T, fy.T, q.T if sources else E, p.T if sources else E, 0, 1)
    x, y = x + w * (xt.T - x), y + w * (yt.T - y)
    np.testing.assert_allclose(lv.x, x, rtol=0, atol=1e-12)
    np.testing.assert_allclose(lv.y, y, rtol=0, atol=1e-12)
    assert not np.array_equal(lv.x, X)


def test_anisotropy_measure():
    X, Y = np.meshgrid(np.linspace(0, 1, 41), np.linspace(0, 1, 41), indexing="ij")
    assert not multigrid.anisotropic(X, Y)
    assert multigrid.anisotropic(*_mixed_aspect(64, 64))
    assert multigrid.anisotropic(X * 10.0, Y)  # uniformly long cells too (one direction)


def _far_fraction_numpy(x, y, stride, lim2):
    """The NumPy reference of ``_mg_kernels.far_fraction`` (the measure ``anisotropic`` compares)."""
    i = np.arange(0, x.shape[0] - 1, stride)[:, None]
    j = np.arange(0, x.shape[1] - 1, stride)[None, :]
    a2 = (x[i + 1, j] - x[i, j]) ** 2 + (y[i + 1, j] - y[i, j]) ** 2
    b2 = (x[i, j + 1] - x[i, j]) ** 2 + (y[i, j + 1] - y[i, j]) ** 2
    far = (a2 > lim2 * b2) | (b2 > lim2 * a2)
    return float(far.mean()) if far.size else 0.0


@pytest.mark.parametrize("stride", [1, 2, 3, 7])
def test_the_compiled_aspect_share_is_the_numpy_one(stride):
    """On mixed aspects, a plain square, uniformly long cells, a grid with zero-length sides (a
    collapsed row) and random nodes: the same share, and so the same answer of ``anisotropic``."""
    X, Y = np.meshgrid(np.linspace(0, 1, 41), np.linspace(0, 1, 37), indexing="ij")
    Xc = X.copy()
    Xc[5] = Xc[6]  # a collapsed row: sides of length zero
    rng = np.random.default_rng(3)
    grids = [
        _mixed_aspect(64, 64),
        _mixed_aspect(96, 48),
        (X, Y),
        (X * 10.0, Y),
        (Xc, Y),
        (rng.random((30, 20)), rng.random((30, 20))),
    ]
    lim2 = multigrid.LINE_ASPECT**2
    shares = []
    for x, y in grids:
        got = _mg_kernels.far_fraction(x, y, stride, lim2)
        assert got == pytest.approx(_far_fraction_numpy(x, y, stride, lim2), abs=1e-15)
        shares.append(got)
    assert shares[2] == 0.0 and shares[3] == 1.0 and 0.0 < shares[0] < 1.0
    assert _mg_kernels.far_fraction(np.zeros((1, 5)), np.zeros((1, 5)), 1, lim2) == 0.0  # no cell


@pytest.mark.parametrize("cells", [(64, 64), (96, 48)])
def test_line_smoothing_rate_on_a_stretched_curved_grid(cells):
    """Cells 1:10 one way in one corner and 10:1 the other way in the opposite one: the
    line-smoothed cycle contracts ≤ 0.35 per cycle (point smoothing: 0.73–0.86, measured)."""
    X, Y = _mixed_aspect(*cells)
    g0 = meshcore.initial_grid(meshcore.prepare_borders(*borders_of(X, Y)))
    g = meshcore.solve(g0, method="multigrid", tolerance=1e-10)
    assert g.converged and g.info.message == "converged", g.info.message
    assert multigrid.last_run["lines"]
    h = [r for _, r in g.info.residual_history]
    assert [i for i, _ in g.info.residual_history] == list(range(len(h))), "no SOR hand-over"
    rate = (h[-1] / h[1]) ** (1.0 / (len(h) - 2))
    assert rate <= 0.35, (rate, len(h))


def test_folded_start_grid_keeps_coarsening():
    """The algebraic start grid of a branched lake folds a few % of its cells; coarse levels
    sampled from it fold about twice that, which is no reason to stop coarsening."""
    kw = one_block_kwargs(testing.channel_network(0), 4000)
    g0 = meshcore.generate_block(**kw, smooth=False)
    assert meshcore.quality(g0).n_folded > 0
    levels = multigrid.hierarchy(np.asarray(g0.x), np.asarray(g0.y))
    assert len(levels) >= 5, levels
    assert min(levels[-1]) <= 8, levels


@pytest.mark.parametrize("seed", [0, 5, 7])
def test_branched_lake_as_one_block_converges_by_multigrid_to_the_sor_grid(seed):
    """Generated channel networks as one block (~4000 nodes): before line smoothing these
    three stalled and went on with SOR; now the multigrid converges, to SOR's grid."""
    kw = one_block_kwargs(testing.channel_network(seed), 4000)
    mg = meshcore.generate_block(**kw, threads=1, repair="off", method="multigrid", tolerance=1e-11)
    assert mg.converged and mg.info.message == "converged", mg.info.message
    assert multigrid.last_run["lines"]
    h = mg.info.residual_history
    assert [i for i, _ in h] == list(range(len(h))), "multigrid must not fall back to SOR"
    sor = meshcore.generate_block(**kw, threads=1, repair="off", method="sor", tolerance=1e-11)
    assert sor.converged
    size = max(np.ptp(mg.x), np.ptp(mg.y))
    assert float(np.hypot(mg.x - sor.x, mg.y - sor.y).max()) <= 1e-6 * size


def test_point_smoothing_that_stalls_goes_on_with_lines(monkeypatch):
    """A grid the aspect measure lets through with point smoothing: when that stalls the
    multigrid goes on with line smoothing from the current grid, not with SOR."""
    monkeypatch.setattr(multigrid, "anisotropic", lambda x, y: False)
    X, Y = _mixed_aspect(64, 64)
    g0 = meshcore.initial_grid(meshcore.prepare_borders(*borders_of(X, Y)))
    monkeypatch.setattr(multigrid, "STALL_START", 4)
    monkeypatch.setattr(multigrid, "STALL_WINDOW", 3)
    monkeypatch.setattr(multigrid, "STALL_FACTOR", 0.5)
    g = meshcore.solve(g0, method="multigrid", tolerance=1e-10)
    assert g.converged and "SOR" not in g.info.message, g.info.message
    assert multigrid.last_run["lines"]
    ref = meshcore.solve(g0, method="sor", tolerance=1e-10)
    assert float(np.hypot(g.x - ref.x, g.y - ref.y).max()) <= 1e-6


@pytest.mark.kernel
@pytest.mark.parametrize("sources", [False, True])
def test_compiled_alternating_sweeps_are_the_numpy_steps(sources):
    """``_alt_lines(lv, 3)`` (one compiled call) against three sweeps of NumPy steps around the
    η-line kernel: bit for bit."""
    X, Y = _wavy(21, 9, seed=8)
    rng = np.random.default_rng(9)
    p, q = (rng.uniform(-1, 1, X.shape), rng.uniform(-1, 1, X.shape)) if sources else (E, E)
    fx, fy = 0.01 * rng.standard_normal(X.shape), 0.01 * rng.standard_normal(X.shape)
    lv = multigrid._Level(X.copy(), Y.copy(), fx, fy, p, q)
    multigrid._alt_lines(lv, 3)
    w, c = multigrid.LINE_OMEGA, np.ascontiguousarray
    x, y = X.copy(), Y.copy()
    for _ in range(3):
        x0, y0 = x.copy(), y.copy()
        _mg_lines.smooth_lines(x, y, fx, fy, p, q, 0, 1)
        xt, yt = c((x0 + w * (x - x0)).T), c((y0 + w * (y - y0)).T)
        x0, y0 = xt.copy(), yt.copy()
        _mg_lines.smooth_lines(xt, yt, c(fx.T), c(fy.T), c(q.T), c(p.T), 0, 1)
        x[...], y[...] = (x0 + w * (xt - x0)).T, (y0 + w * (yt - y0)).T
    np.testing.assert_array_equal(lv.x, x)
    np.testing.assert_array_equal(lv.y, y)
    assert not np.array_equal(lv.x, X)
