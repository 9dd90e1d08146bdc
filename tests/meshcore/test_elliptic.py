"""Mathematics of the elliptic solver: fixed points, exact solutions, order, kernels."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import meshcore
from meshcore.elliptic import _kernels, _reference
from tests.conftest import annulus_sector, borders_of, rectangle_borders


def test_uniform_rectangle_is_exact_fixed_point():
    g0 = meshcore.generate_block(*rectangle_borders(3.0, 1.0, 12, 5), smooth=False)
    assert meshcore.elliptic.residual(g0) <= 1e-14 * g0.size
    g = meshcore.generate_block(*rectangle_borders(3.0, 1.0, 12, 5), method="sor")
    assert g.converged and g.iterations == 0
    np.testing.assert_array_equal(g.x, g0.x)
    np.testing.assert_array_equal(g.y, g0.y)


@pytest.mark.parametrize("method", ["sor", "auto"])
def test_annulus_sector_second_order(method):
    """θ and ln r are harmonic: the exact Winslow grid is known in closed form."""
    errors = []
    ns = (8, 16, 32, 64)
    for n in ns:
        X, Y = annulus_sector(n, n)
        g = meshcore.generate_block(*borders_of(X, Y), tolerance=1e-13, method=method)
        assert g.converged
        errors.append(float(np.hypot(g.x - X, g.y - Y).max()))
    orders = [math.log2(errors[k] / errors[k + 1]) for k in range(len(ns) - 1)]
    assert min(orders) >= 1.8, (errors, orders)


def test_annulus_sector_anisotropic_order():
    errors = []
    for n in (8, 16, 32):
        X, Y = annulus_sector(2 * n, n, r0=1.0, r1=2.0, th0=0.3, th1=2.0)
        g = meshcore.generate_block(*borders_of(X, Y), tolerance=1e-13)
        errors.append(float(np.hypot(g.x - X, g.y - Y).max()))
    assert math.log2(errors[0] / errors[1]) >= 1.8
    assert math.log2(errors[1] / errors[2]) >= 1.8


def _random_grid(rng, ni, nj, periodic=False):
    X, Y = np.meshgrid(np.arange(ni + 1.0), np.arange(nj + 1.0), indexing="ij")
    X = X + 0.3 * rng.standard_normal(X.shape)
    Y = Y + 0.3 * rng.standard_normal(Y.shape)
    if periodic:
        X[-1], Y[-1] = X[0], Y[0]
    return np.ascontiguousarray(X), np.ascontiguousarray(Y)


@pytest.mark.kernel
@pytest.mark.parametrize("periodic", [False, True])
@pytest.mark.parametrize("with_pq", [False, True])
def test_kernel_matches_numpy_reference(periodic, with_pq):
    rng = np.random.default_rng(42)
    for ni, nj in [(2, 2), (3, 5), (8, 6), (11, 7), (16, 16)]:
        if periodic and ni % 2:
            continue
        X, Y = _random_grid(rng, ni, nj, periodic)
        if with_pq:
            p, q = rng.standard_normal(X.shape), rng.standard_normal(X.shape)
        else:
            p = q = np.zeros((0, 0))
        omega = 1.37
        x1, y1 = X.copy(), Y.copy()
        x2, y2 = X.copy(), Y.copy()
        d1 = _kernels.sweep4(x1, y1, p, q, omega, periodic)
        d2 = _reference.sweep4(x2, y2, p if with_pq else None, q if with_pq else None, omega, periodic)
        np.testing.assert_allclose(x1, x2, rtol=0, atol=1e-13)
        np.testing.assert_allclose(y1, y2, rtol=0, atol=1e-13)
        assert d1 == pytest.approx(d2, rel=1e-12)
        r1 = _kernels.jacobi_residual(X, Y, p, q, periodic)
        r2 = _reference.jacobi_residual(X, Y, p if with_pq else None, q if with_pq else None, periodic)
        assert r1 == pytest.approx(r2, rel=1e-12)


def test_serial_and_parallel_sweeps_are_bit_identical():
    rng = np.random.default_rng(7)
    X, Y = _random_grid(rng, 40, 33)
    a = (X.copy(), Y.copy())
    b = (X.copy(), Y.copy())
    e = np.zeros((0, 0))
    for _ in range(5):
        _kernels.sweep4(a[0], a[1], e, e, 1.5, False)
        _kernels.sweep4_parallel(b[0], b[1], e, e, 1.5, False)
    assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])


def test_boundary_nodes_never_move():
    X, Y = annulus_sector(12, 9)
    rng = np.random.default_rng(1)
    Xp, Yp = X.copy(), Y.copy()
    Xp[1:-1, 1:-1] += 0.05 * rng.standard_normal((11, 8))
    g = meshcore.solve(meshcore.StructuredGrid(Xp, Yp), method="sor")
    for name in meshcore.BORDER_NAMES:
        np.testing.assert_array_equal(g.border(name), meshcore.StructuredGrid(X, Y).border(name))


def test_nonconvergence_is_a_result():
    X, Y = annulus_sector(40, 40)
    g = meshcore.generate_block(*borders_of(X, Y), max_iterations=3, tolerance=1e-14, method="sor")
    assert not g.converged
    assert g.iterations == 3
    assert "not converged" in g.info.message


def test_iterate_yields_copies_and_stops():
    X, Y = annulus_sector(60, 60)
    g0 = meshcore.initial_grid(meshcore.prepare_borders(*borders_of(X, Y)))
    gen = meshcore.iterate(g0, method="sor", tolerance=1e-15, report_interval=1e-9)
    snaps = [next(gen) for _ in range(3)]
    assert [s.iteration for s in snaps] == sorted(s.iteration for s in snaps)
    assert snaps[0].grid is not snaps[1].grid
    assert not np.array_equal(snaps[0].grid.x, snaps[2].grid.x)
    with pytest.raises(StopIteration) as fin:
        gen.send("stop")
    res = fin.value.value
    assert not res.converged and res.info.message == "stopped"


def test_solve_callback_can_stop():
    X, Y = annulus_sector(60, 60)
    seen = []

    def cb(snap):
        seen.append(snap.iteration)
        return "stop"

    g = meshcore.generate_block(
        *borders_of(X, Y),
        method="sor",
        tolerance=1e-15,
        config=meshcore.EllipticConfig(method="sor", tolerance=1e-15, report_interval=1e-9),
        callback=cb,
    )
    assert len(seen) == 1 and not g.converged


def test_source_terms_shift_lines():
    """A positive Q attracts η-lines towards η = 0 side? Check it moves nodes and stays valid."""
    b = rectangle_borders(1.0, 1.0, 16, 16)
    g0 = meshcore.generate_block(*b, method="sor")
    q = np.full(g0.shape, -0.05)
    g1 = meshcore.generate_block(*b, method="sor", q=q)
    assert g1.converged
    assert meshcore.quality(g1).n_folded == 0
    # With Q < 0 the η-lines move towards η = 0 (Thompson: negative Q attracts to lower η)
    assert g1.y[8, 1:-1].mean() < g0.y[8, 1:-1].mean()


@settings(max_examples=25, deadline=None)
@given(st.integers(2, 9), st.integers(2, 9), st.floats(-1, 1), st.floats(-1, 1), st.floats(-1, 1), st.floats(-1, 1))
def test_tfi_reproduces_bilinear_maps(ni, nj, a, b, c, d):
    # bilinear map of the unit square with corners perturbed (kept convex)
    c00 = np.array([0.0, 0.0])
    c10 = np.array([2.0 + 0.5 * a, 0.3 * b])
    c01 = np.array([0.3 * c, 2.0 + 0.5 * d])
    c11 = np.array([2.0 + 0.4 * b, 2.0 + 0.4 * c])
    s = np.linspace(0, 1, ni + 1)[:, None, None]
    t = np.linspace(0, 1, nj + 1)[None, :, None]
    P = (1 - s) * (1 - t) * c00 + s * (1 - t) * c10 + (1 - s) * t * c01 + s * t * c11
    X, Y = np.ascontiguousarray(P[..., 0]), np.ascontiguousarray(P[..., 1])
    g = meshcore.tfi(meshcore.prepare_borders(*borders_of(X, Y)))
    np.testing.assert_allclose(g.x, X, atol=1e-12)
    np.testing.assert_allclose(g.y, Y, atol=1e-12)


def test_nan_grid_is_never_converged():
    X, Y = annulus_sector(6, 6)
    X = X.copy()
    X[3, 3] = np.nan
    e = np.zeros((0, 0))
    assert _kernels.jacobi_residual(np.ascontiguousarray(X), np.ascontiguousarray(Y), e, e, False) == np.inf


def test_warmup_loads_every_kernel_a_default_solve_uses():
    """The app warms up in a background thread: after it, a large default solve (multigrid,
    threads=0 → parallel kernels) dispatches to kernels that are already loaded."""
    import subprocess
    import sys

    code = (
        "import meshcore.elliptic as e\n"
        "from meshcore.elliptic import _kernels as K0, _mg_kernels as K\n"
        "e.warmup()\n"
        "fs = [K0.sweep4, K0.sweep4_parallel, K.smooth, K.smooth_parallel, K.vcycle, K.fmg_start,\n"
        "      K.defect_restrict, K.defect_restrict_parallel, K.prolong_correct,\n"
        "      K.prolong_correct_parallel, K.add_operator_parallel, K.sample, K.smooth_band]\n"
        "print(sum(1 for f in fs if not f.signatures))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "0", out.stdout + out.stderr
