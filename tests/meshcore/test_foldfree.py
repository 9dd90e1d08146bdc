"""Fold-free grids: kernels vs the NumPy oracle, repair of real lakes, the "cannot" report."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import meshcore
from meshcore.boundary import borders_from_loop
from meshcore.corners import choose_corners, corner_problems, interior_angles
from meshcore.errors import BoundaryError, FoldedGridError
from meshcore.foldfree import (
    _kernels,
    _reference,
    _sweep,
    block_corner_problems,
    invalid_cells,
    repair,
    smooth,
)
from meshcore.foldfree.cells import _nodes_of
from tests.conftest import annulus_sector, borders_of

LAKES = Path(__file__).resolve().parent.parent / "data" / "lakes"
LAKE_NAMES = sorted(p.stem for p in LAKES.glob("*.csv"))


def load_lake(name: str) -> np.ndarray:
    """Lake outline in local metres (equirectangular about the mean point)."""
    a = np.loadtxt(LAKES / f"{name}.csv", delimiter=",", skiprows=1)
    lon, lat = a[:, 0], a[:, 1]
    r = 6371008.8
    x = r * np.radians(lon - lon.mean()) * math.cos(math.radians(lat.mean()))
    y = r * np.radians(lat - lat.mean())
    return np.column_stack([x, y])


def cells_for(loop: np.ndarray, corners, nodes: int) -> tuple[int, int]:
    """(ni, nj) with (ni+1)(nj+1) ≈ nodes and ni/nj ≈ (bottom+top)/(left+right) lengths."""
    b = borders_from_loop(loop, corners)
    length = {k: float(np.hypot(*np.diff(v, axis=0).T).sum()) for k, v in b.items()}
    r = (length["bottom"] + length["top"]) / (length["left"] + length["right"])
    nj = max(2, round((-(1 + r) + math.sqrt((1 + r) ** 2 - 4 * r * (1 - nodes))) / (2 * r)))
    ni = max(2, round(nodes / (nj + 1)) - 1)
    return ni, nj


def assert_valid_except_exempt(g: meshcore.StructuredGrid) -> None:
    ex = block_corner_problems(g)
    bits = np.zeros(g.cells, dtype=np.uint8)
    for c in ex:
        bits[c.cell] |= np.uint8(1 << ("sw", "se", "ne", "nw").index(c.corner))
    assert not invalid_cells(g.x, g.y, bits).any()
    q = meshcore.quality(g)
    assert q.n_nonconvex <= len(ex)
    assert q.n_folded == 0


def random_grid(ni=7, nj=5, amp=0.15, seed=0):
    rng = np.random.default_rng(seed)
    X, Y = np.meshgrid(np.linspace(0, 2, ni + 1), np.linspace(0, 1, nj + 1), indexing="ij")
    X = X + 0.3 * Y**2
    X[1:-1, 1:-1] += amp * 2 / ni * rng.standard_normal((ni - 1, nj - 1))
    Y[1:-1, 1:-1] += amp / nj * rng.standard_normal((ni - 1, nj - 1))
    return np.ascontiguousarray(X), np.ascontiguousarray(Y)


# ---------------------------------------------------------------- kernels vs oracle
@pytest.mark.kernel
@pytest.mark.parametrize("eps", [0.0, 1e-3, 0.05])
def test_node_gradient_matches_reference(eps):
    x, y = random_grid(seed=3)
    gx, gy = _reference.gradient(x, y, eps)
    out = np.empty(6)
    ref_total = _reference.energy(x, y, eps)
    cells = np.argwhere(np.ones((x.shape[0] - 1, x.shape[1] - 1), bool)).astype(np.int32)
    e_kernel, _ = _kernels.patch_stats(x, y, cells, eps, np.zeros(cells.max(axis=0) + 1, np.uint8))
    assert e_kernel == pytest.approx(ref_total, rel=1e-12)
    for i in range(1, x.shape[0] - 1):
        for j in range(1, x.shape[1] - 1):
            assert _kernels.node_local(x, y, i, j, x[i, j], y[i, j], eps, out)
            assert out[1] == pytest.approx(gx[i, j], rel=1e-9, abs=1e-9 * abs(gx).max())
            assert out[2] == pytest.approx(gy[i, j], rel=1e-9, abs=1e-9 * abs(gy).max())


@pytest.mark.kernel
@pytest.mark.parametrize("eps", [0.0, 1e-3])
@pytest.mark.parametrize("periodic", [False, True])
def test_trial_energy_is_the_full_evaluations_energy(eps, periodic):
    # the sweep's trial points sum the energy alone (no gradient, no Hessian): the same value, bit
    # for bit, and the same verdict on inverted triangles, at points that invert some of them
    x, y = random_grid(ni=9, nj=6, amp=0.2, seed=11)
    if periodic:
        x[-1, :], y[-1, :] = x[0, :], y[0, :]
    rng = np.random.default_rng(12)
    full, trial = np.empty(6), np.empty(6)
    cx, cy = np.empty(4), np.empty(4)
    verdicts = set()
    for i in range(0 if periodic else 1, x.shape[0] - 1):
        for j in range(1, x.shape[1] - 1):
            for scale in (0.0, 0.05, 0.3):
                qx, qy = x[i, j] + scale * rng.standard_normal(), y[i, j] + scale * rng.standard_normal()
                a = _kernels.node_local(x, y, i, j, qx, qy, eps, full, periodic)
                b = _kernels._node_local(x, y, i, j, qx, qy, eps, trial, periodic, cx, cy, False)
                assert a == b
                verdicts.add(a)
                if a:
                    assert trial[0] == full[0]
    assert verdicts == ({True, False} if eps == 0.0 else {True})


@pytest.mark.parametrize("eps", [0.0, 0.02])
@pytest.mark.parametrize("periodic", [False, True])
def test_the_sweep_forms_give_the_node_energy_here_and_at_trial_points(eps, periodic):
    # the sweep takes each node's triangle forms (F quadratic, D affine in the node) once: the
    # energy, gradient and Hessian from them are node_local's (up to rounding: summed in another
    # order), and so is a trial point's energy from them, with the same verdict on inverted
    # triangles (at points that invert some of them)
    x, y = random_grid(ni=9, nj=6, amp=0.2, seed=21)
    if periodic:
        x[-1, :], y[-1, :] = x[0, :], y[0, :]
    rng = np.random.default_rng(22)
    ref, out, there = np.empty(6), np.empty(6), np.empty(6)
    cx, cy = np.empty(9), np.empty(9)
    forms = np.empty((7, 12))
    verdicts = set()
    for i in range(0 if periodic else 1, x.shape[0] - 1):
        for j in range(1, x.shape[1] - 1):
            n = _kernels._node_forms(x, y, i, j, periodic, cx, cy, forms)
            assert n == 12  # four cells round every node here
            ok = _kernels.node_local(x, y, i, j, x[i, j], y[i, j], eps, ref, periodic)
            assert _kernels._form_local(forms, n, eps, out) == ok
            if not ok:
                continue
            np.testing.assert_allclose(out, ref, rtol=1e-12, atol=1e-12 * np.abs(ref).max())
            assert _kernels._form_energy(forms, n, 0.0, 0.0, eps) == pytest.approx(ref[0], rel=1e-12)
            for scale in (0.05, 0.3):
                dx, dy = scale * rng.standard_normal(2)
                ok = _kernels.node_local(x, y, i, j, x[i, j] + dx, y[i, j] + dy, eps, there, periodic)
                e = _kernels._form_energy(forms, n, dx, dy, eps)
                assert ok == np.isfinite(e)
                verdicts.add(ok)
                if ok:
                    assert e == pytest.approx(there[0], rel=1e-9)
    assert verdicts == ({True, False} if eps == 0.0 else {True})


@pytest.mark.parametrize("eps", [0.0, 0.02])
def test_node_hessian_matches_finite_differences(eps):
    x, y = random_grid(seed=5)
    i, j, h = 3, 2, 1e-6
    out, op, om = np.empty(6), np.empty(6), np.empty(6)
    _kernels.node_local(x, y, i, j, x[i, j], y[i, j], eps, out)
    hess = np.array([[out[3], out[4]], [out[4], out[5]]])
    fd = np.zeros((2, 2))
    for k, (dx, dy) in enumerate([(h, 0.0), (0.0, h)]):
        _kernels.node_local(x, y, i, j, x[i, j] + dx, y[i, j] + dy, eps, op)
        _kernels.node_local(x, y, i, j, x[i, j] - dx, y[i, j] - dy, eps, om)
        fd[k] = [(op[1] - om[1]) / (2 * h), (op[2] - om[2]) / (2 * h)]
    np.testing.assert_allclose(hess, fd, rtol=1e-5, atol=1e-5 * abs(hess).max())


def test_barrier_energy_is_winslow_functional_on_uniform_grid():
    # F/D = 2 for every square corner: E = 8 per cell, and the uniform grid is stationary.
    X, Y = np.meshgrid(np.arange(6.0), np.arange(5.0), indexing="ij")
    assert _reference.energy(X, Y, 0.0) == pytest.approx(8.0 * 5 * 4)
    gx, gy = _reference.gradient(X, Y, 0.0)
    assert np.abs(gx[1:-1, 1:-1]).max() < 1e-12 and np.abs(gy[1:-1, 1:-1]).max() < 1e-12


def test_sweeps_descend_and_never_invert():
    x, y = random_grid(ni=12, nj=9, amp=0.1, seed=7)
    assert not invalid_cells(x, y).any()
    nodes = np.argwhere(np.ones_like(x, bool)[1:-1, 1:-1]).astype(np.int32) + 1
    nodes = nodes[np.argsort((nodes[:, 0] % 2) * 2 + nodes[:, 1] % 2, kind="stable")]
    e = [_reference.energy(x, y, 0.0)]
    for _ in range(30):
        _kernels.sweep(x, y, np.ascontiguousarray(nodes), 0.0, np.inf)
        e.append(_reference.energy(x, y, 0.0))
        assert not invalid_cells(x, y).any()
    assert np.all(np.diff(e) <= 1e-12 * e[0])
    assert e[-1] < e[0]


def _folded_square():
    X, Y = np.meshgrid(np.linspace(0, 1, 9), np.linspace(0, 1, 9), indexing="ij")
    X[4, 4], Y[4, 4] = 0.95, 0.9  # drag one node across many cells
    X[2, 5], Y[2, 5] = 0.8, 0.1
    return X, Y


@pytest.mark.kernel
@pytest.mark.parametrize(
    "case, eps, omega",
    [("random", 0.0, 1.0), ("random", 0.0, 1.9), ("folded", 0.05, 1.0), ("folded", 0.002, 1.0), ("o-grid", 0.0, 1.9)],
)
def test_fast_sweep_takes_the_steps_of_sweep(case, eps, omega):
    # fast_sweep (one pass per node) against sweep (forms, then sums): the same steps, sums in
    # another order, so the same grid up to rounding after every one of 20 sweeps
    periodic = case == "o-grid"
    if case == "random":
        x, y = random_grid(ni=12, nj=9, amp=0.2, seed=11)
    elif case == "folded":
        x, y = _folded_square()
        assert invalid_cells(x, y).any()
    else:
        x, y = o_grid()
        x[0, 4:8] += 0.2
        x[-1] = x[0]
    nodes = _nodes_of(np.ones((x.shape[0] - 1, x.shape[1] - 1), bool), periodic)
    xa, ya, xb, yb = x.copy(), y.copy(), x.copy(), y.copy()
    scale = np.ptp(x) + np.ptp(y)
    for _ in range(20):
        da = _kernels.sweep(xa, ya, nodes, eps, np.inf, omega, periodic)
        db = _sweep.fast_sweep(xb, yb, nodes, eps, omega, periodic)
        assert db == pytest.approx(da, rel=1e-9, abs=1e-12 * scale)
        np.testing.assert_allclose(xb, xa, rtol=0, atol=1e-10 * scale)
        np.testing.assert_allclose(yb, ya, rtol=0, atol=1e-10 * scale)
    assert np.abs(xb - x).max() > 1e-3 * scale  # the sweeps moved nodes
    if periodic:
        np.testing.assert_array_equal(xb[0], xb[-1])


def test_smooth_recovers_uniform_square_grid():
    X, Y = np.meshgrid(np.linspace(0, 1, 9), np.linspace(0, 1, 9), indexing="ij")
    rng = np.random.default_rng(2)
    Xp, Yp = X.copy(), Y.copy()
    Xp[1:-1, 1:-1] += 0.04 * rng.standard_normal((7, 7))
    Yp[1:-1, 1:-1] += 0.04 * rng.standard_normal((7, 7))
    r = smooth(meshcore.StructuredGrid(Xp, Yp), tolerance=1e-10, max_sweeps=20000)
    assert r.ok
    np.testing.assert_allclose(r.grid.x, X, atol=1e-7)
    np.testing.assert_allclose(r.grid.y, Y, atol=1e-7)


def test_untangles_a_folded_grid():
    X, Y = np.meshgrid(np.linspace(0, 1, 9), np.linspace(0, 1, 9), indexing="ij")
    Xp, Yp = X.copy(), Y.copy()
    Xp[4, 4], Yp[4, 4] = 0.95, 0.9  # drag one node across many cells
    Xp[2, 5], Yp[2, 5] = 0.8, 0.1
    g = meshcore.StructuredGrid(Xp, Yp)
    assert meshcore.quality(g).n_folded > 0
    r = repair(g)
    assert r.ok and r.folded_before > 0
    assert meshcore.quality(r.grid).ok
    for name in meshcore.BORDER_NAMES:
        np.testing.assert_array_equal(r.grid.border(name), g.border(name))


def o_grid(ni=48, nj=12):
    """Periodic O-grid between an ellipse and a wavy circle (i clockwise: positive Jacobian)."""
    t = -np.linspace(0, 2 * np.pi, ni + 1)
    t[-1] = 0.0
    s = np.linspace(0, 1, nj + 1)
    r = 3 + 0.6 * np.cos(5 * t)
    X = 1.5 * np.cos(t)[:, None] * (1 - s) + (r * np.cos(t))[:, None] * s
    Y = 0.6 * np.sin(t)[:, None] * (1 - s) + (r * np.sin(t))[:, None] * s
    X[-1], Y[-1] = X[0], Y[0]
    return X, Y


@pytest.mark.kernel
def test_periodic_seam_gradient_matches_reference():
    x, y = o_grid()
    x[0, 5] += 0.05
    x[-1, 5] = x[0, 5]
    gx, gy = _reference.gradient(x, y, 0.0)
    out = np.empty(6)
    assert _kernels.node_local(x, y, 0, 5, x[0, 5], y[0, 5], 0.0, out, True)
    # the seam node is column 0 and column ni at once
    assert out[1] == pytest.approx(gx[0, 5] + gx[-1, 5], rel=1e-10)
    assert out[2] == pytest.approx(gy[0, 5] + gy[-1, 5], rel=1e-10)


def test_periodic_grid_is_repaired_across_the_seam():
    X, Y = o_grid()
    assert meshcore.quality(meshcore.StructuredGrid(X, Y, periodic=True)).ok
    X[0, 4:8] += 0.9  # fold cells on both sides of the seam
    X[-1] = X[0]
    g = meshcore.StructuredGrid(X, Y, periodic=True)
    assert meshcore.quality(g).n_folded > 0
    for r in (repair(g), smooth(g)):
        assert r.ok and meshcore.quality(r.grid).ok and r.grid.periodic
        np.testing.assert_array_equal(r.grid.x[0], r.grid.x[-1])
        np.testing.assert_array_equal(r.grid.y[0], r.grid.y[-1])
        for name in ("bottom", "top"):
            np.testing.assert_array_equal(r.grid.border(name), g.border(name))


# ----------------------------------------------------------------------- corners
def test_choose_corners_rectangle_and_orientation():
    pts = np.array([[0, 0], [1, 0], [2, 0], [3, 0], [3, 1], [2, 1], [1, 1], [0, 1]], float)
    assert choose_corners(pts) == (0, 3, 4, 7)
    # clockwise input: indices refer to the given points, still usable by borders_from_loop
    c = choose_corners(pts[::-1])
    b = borders_from_loop(pts[::-1], c)
    assert {tuple(b.bottom[0]), tuple(b.top[-1])} <= {
        (0.0, 0.0),
        (3.0, 1.0),
        (3.0, 0.0),
        (0.0, 1.0),
    }
    assert choose_corners(pts, method="hull") == (0, 3, 4, 7)


def test_choose_corners_is_rotation_invariant():
    t = np.linspace(0, 2 * np.pi, 60, endpoint=False)
    ell = np.column_stack([4 * np.cos(t), np.sin(t)])
    c0 = choose_corners(ell)
    for ang in (0.3, 1.2, 2.5):
        rot = np.array([[math.cos(ang), -math.sin(ang)], [math.sin(ang), math.cos(ang)]])
        c = choose_corners(ell @ rot.T)
        # same vertices up to the 180° ambiguity of the long axis
        assert sorted(c) == sorted(c0) or sorted(c) == sorted((k + 30) % 60 for k in c0)


def test_reflex_corner_is_reported_with_the_corner_to_move():
    # L-shape; index 3 is the reflex vertex
    L = np.array([[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]], float)
    ang = interior_angles(L)
    assert ang[3] == pytest.approx(270.0)
    assert np.sum(ang) == pytest.approx(180.0 * (len(L) - 2))
    probs = corner_problems(L, (0, 1, 3, 5))
    assert [p.corner for p in probs] == ["ne"]
    assert "move corner ne" in probs[0].message and "point 3" in probs[0].message
    assert corner_problems(L, choose_corners(L)) == []


@pytest.mark.parametrize("name", LAKE_NAMES)
def test_automatic_corners_on_lakes_are_convex(name):
    loop = load_lake(name)
    c = choose_corners(loop)
    assert corner_problems(loop, c) == []
    borders_from_loop(loop, c)  # valid cyclic order


def test_reflex_block_corner_is_exempt_and_named():
    # corner ne on the reflex vertex of an L: its corner cell cannot be convex
    L = np.array([[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]], float)
    g = meshcore.generate_block(loop=L, corners=(0, 1, 3, 5), cells=(12, 12))
    ex = block_corner_problems(g)
    assert [c.corner for c in ex] == ["ne"]
    assert "move corner ne" in g.info.message
    assert_valid_except_exempt(g)


def test_generate_block_accepts_automatic_corners():
    loop = load_lake("windermere_sparse")
    g = meshcore.generate_block(loop=loop, corners="auto", cells=(60, 8))
    h = meshcore.generate_block(loop=loop, corners=choose_corners(loop), cells=(60, 8))
    np.testing.assert_array_equal(g.x, h.x)


def test_foldfree_method_warns_that_sources_shape_only_the_start():
    bs = borders_of(*annulus_sector(12, 8))
    with pytest.warns(meshcore.MeshcoreWarning, match="P, Q"):
        g = meshcore.generate_block(*bs, method="foldfree", q=0.1)
    assert meshcore.quality(g).ok


# ------------------------------------------------------------------ real lakes
def _lake_grid(name: str, nodes: int):
    loop = load_lake(name)
    c = choose_corners(loop)
    cells = cells_for(loop, c, nodes)
    return meshcore.generate_block(loop=loop, corners=c, cells=cells)


def test_shasta_folds_under_winslow_and_is_repaired():
    loop = load_lake("shasta_lake")
    c = choose_corners(loop)
    cells = cells_for(loop, c, 6000)
    w = meshcore.generate_block(loop=loop, corners=c, cells=cells, repair="off")
    qw = meshcore.quality(w)
    assert qw.n_folded > 0 and qw.n_nonconvex > qw.n_folded
    g = meshcore.generate_block(loop=loop, corners=c, cells=cells)
    q = meshcore.quality(g)
    assert q.n_folded == 0 and q.n_nonconvex == 0
    assert g.converged and g.method.endswith("+foldfree")
    assert f"{qw.n_nonconvex} non-convex cell(s) ({qw.n_folded} folded)" in g.info.message
    # only nodes near the bad cells moved; the borders never
    moved = np.hypot(g.x - w.x, g.y - w.y) > 0
    assert 0 < moved.sum() < 0.25 * moved.size
    for name in meshcore.BORDER_NAMES:
        np.testing.assert_array_equal(g.border(name), w.border(name))


@pytest.mark.parametrize("name", LAKE_NAMES)
def test_lakes_6000_nodes_fold_free(name):
    g = _lake_grid(name, 6000)
    assert abs(g.n_nodes - 6000) < 300
    q = meshcore.quality(g)
    assert q.n_folded == 0 and q.n_nonconvex == 0, g.info.message
    assert g.converged
    assert q.min_jacobian_ratio > 0


@pytest.mark.slow
@pytest.mark.parametrize("name", LAKE_NAMES)
def test_lakes_24000_nodes_fold_free(name):
    g = _lake_grid(name, 24000)
    assert abs(g.n_nodes - 24000) < 800
    q = meshcore.quality(g)
    assert q.n_folded == 0 and q.n_nonconvex == 0, g.info.message
    assert g.converged


# ----------------------------------------------------------- C shape, paper-like
def c_shape(n_side: int = 6):
    """Unit square with a deep slot from the right side (slot 0.2 wide, 0.8 deep)."""
    return np.array([[0, 0], [1, 0], [1, 0.4], [0.2, 0.4], [0.2, 0.6], [1, 0.6], [1, 1], [0, 1]], float)


def test_c_shaped_domain_has_no_nonconvex_cells():
    loop = c_shape()
    # corners sw=0, se=1, ne=6, nw=7: the slot lies in the right border
    for cells in [(20, 40), (30, 60)]:
        w = meshcore.generate_block(loop=loop, corners=(0, 1, 6, 7), cells=cells, repair="off")
        g = meshcore.generate_block(loop=loop, corners=(0, 1, 6, 7), cells=cells)
        assert meshcore.quality(w).n_nonconvex > 0  # Winslow alone is not enough here
        assert meshcore.quality(g).ok, g.info.message


def test_heavily_folded_c_shape_needs_and_gets_the_multilevel_start():
    # at 60 × 120 cells SOR converges to a Winslow solution that folds dozens of cells across
    # the slot (multigrid happens to find an unfolded one); local patches fail on it
    loop = c_shape()
    w = meshcore.generate_block(loop=loop, corners=(0, 1, 6, 7), cells=(60, 120), repair="off", method="sor")
    assert meshcore.quality(w).n_folded > 20
    r = repair(w)
    assert r.ok and meshcore.quality(r.grid).ok
    assert "multilevel" in r.message


@pytest.mark.parametrize("cells", [(20, 30), (40, 60)])
def test_hairpin_slot_is_repaired(cells):
    # a slot 0.02 wide and 9 long: Winslow folds tens of cells around its end
    loop = np.array([[0, 0], [10, 0], [10, 2.02], [0, 2.02], [0, 1.02], [9, 1.02], [9, 1], [0, 1]], float)
    w = meshcore.generate_block(loop=loop, corners=(0, 1, 2, 3), cells=cells, repair="off")
    assert meshcore.quality(w).n_folded > 10
    g = meshcore.generate_block(loop=loop, corners=(0, 1, 2, 3), cells=cells)
    assert g.converged and meshcore.quality(g).ok, g.info.message


EXAMPLES = sorted(
    p
    for p in (Path(__file__).resolve().parents[2] / "resources" / "examples").glob("*.toml")
    if "[multiblock]" not in p.read_text(encoding="utf-8")  # single-block cases only
)


@pytest.mark.parametrize(
    "path",
    # the C-grid example takes ~10 s per solve with SOR (strongly stretched wall cells)
    [pytest.param(p, marks=pytest.mark.slow) if "cgrid" in p.stem else p for p in EXAMPLES],
    ids=[p.stem for p in EXAMPLES],
)
def test_paper_cases_fold_free_and_close_to_valid_winslow(path):
    from meshcore.case import generate_case, load_case

    case = load_case(path)
    w = meshcore.generate_block(case.blocks[0], case.solver.replaced(repair="off"))
    g = generate_case(case)[0]
    qw, qg = meshcore.quality(w), meshcore.quality(g)
    assert qg.ok and g.converged, g.info.message
    if qw.ok:  # a valid Winslow grid is returned unchanged ...
        assert "foldfree" not in g.method
        np.testing.assert_array_equal(g.x, w.x)
    else:  # ... an invalid one is repaired, and the message says so
        assert g.method.endswith("+foldfree")
        assert f"{qw.n_nonconvex} non-convex cell(s)" in g.info.message
    f = meshcore.generate_block(case.blocks[0], case.solver.replaced(method="foldfree"))
    assert f.method == "foldfree" and f.converged and meshcore.quality(f).ok
    # the whole-block barrier minimiser stays close to a valid Winslow grid (it has no
    # grid control, so controlled examples are not compared)
    if qw.ok and case.blocks[0].control is None:
        h = np.median(np.hypot(np.diff(w.x, axis=0), np.diff(w.y, axis=0)))
        assert np.hypot(f.x - w.x, f.y - w.y).max() < 0.1 * h


@pytest.mark.parametrize("case", ["annulus", "trapezoid"])
def test_foldfree_method_stays_close_to_valid_winslow(case):
    if case == "annulus":
        bs = borders_of(*annulus_sector(24, 16))
    else:
        X, Y = np.meshgrid(np.linspace(0, 3, 25), np.linspace(0, 1, 13), indexing="ij")
        X = X * (1 - 0.3 * Y)
        Y = Y * (1 + 0.2 * np.sin(np.pi * X / 3))
        bs = borders_of(X, Y)
    w = meshcore.generate_block(*bs)
    assert meshcore.quality(w).ok and "foldfree" not in w.method
    f = meshcore.generate_block(*bs, method="foldfree")
    assert f.method == "foldfree" and meshcore.quality(f).ok
    h = np.median(np.hypot(np.diff(w.x, axis=0), np.diff(w.y, axis=0)))
    assert np.hypot(f.x - w.x, f.y - w.y).max() < 0.05 * h


# ------------------------------------------------------------------- "cannot"
def dipped_strip():
    """One row of cells (no interior node) whose top border dips: cell (0, 0) is a dart."""
    return (
        np.array([[0, 0], [1, 0], [2, 0]], float),
        np.array([[2, 0], [2, 1]], float),
        np.array([[0, 1], [0.3, 0.1], [2, 1]], float),
        np.array([[0, 0], [0, 1]], float),
    )


def test_cannot_is_reported_not_returned_as_success():
    bs = dipped_strip()
    g = meshcore.generate_block(*bs)
    assert not g.converged
    assert "no fold-free grid" in g.info.message
    assert "(0, 0) at (0.325, 0.275)" in g.info.message  # names the cell and where it is
    assert not meshcore.quality(g).ok
    assert "more nodes" in g.info.message and "split" in g.info.message
    with pytest.raises(FoldedGridError, match="no fold-free grid"):
        meshcore.generate_block(*bs, repair="strict")
    # repair="off" returns the elliptic grid untouched
    assert "foldfree" not in meshcore.generate_block(*bs, repair="off").method


# ------------------------------------------------------------------- hypothesis
def _outcome_is_honest(loop, cells):
    try:
        c = choose_corners(loop)
        g = meshcore.generate_block(loop=loop, corners=c, cells=cells)
    except BoundaryError:
        return  # rejected input is fine
    if g.converged:
        assert_valid_except_exempt(g)
    else:
        q = meshcore.quality(g)
        assert q.ok or "no fold-free grid" in g.info.message or "not converged" in g.info.message


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    radii=st.lists(st.floats(0.25, 1.0), min_size=8, max_size=24),
    ni=st.integers(6, 24),
    nj=st.integers(4, 16),
)
def test_random_star_shaped_polygons(radii, ni, nj):
    n = len(radii)
    t = 2 * np.pi * np.arange(n) / n
    loop = np.column_stack([np.array(radii) * np.cos(t), np.array(radii) * np.sin(t)])
    _outcome_is_honest(loop, (ni, nj))


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    boxes=st.lists(
        st.tuples(st.integers(0, 30), st.integers(0, 30), st.integers(3, 20), st.integers(3, 20)),
        min_size=2,
        max_size=6,
    ),
    ni=st.integers(6, 24),
    nj=st.integers(4, 16),
)
def test_random_simple_polygons(boxes, ni, nj):
    from shapely.geometry import box
    from shapely.ops import unary_union

    poly = unary_union([box(x0, y0, x0 + w, y0 + h) for x0, y0, w, h in boxes]).simplify(0.0)
    if poly.geom_type != "Polygon":
        poly = max(poly.geoms, key=lambda p: p.area)
    poly = poly.simplify(0.0)
    loop = np.asarray(poly.exterior.coords)[:-1]
    if len(loop) < 4:
        return
    _outcome_is_honest(loop, (ni, nj))


@pytest.mark.parametrize("seed", range(4))
def test_a_point_given_twice_is_not_a_reflex_corner(seed):
    """A repeated point (a double click) takes the angle of the point it repeats: the corner
    advice neither calls a convex vertex reflex nor misses a reflex one (generated outlines)."""
    from meshcore import testing

    rng = np.random.default_rng(seed)
    shapes = [
        testing.round_lake(seed, kind="blob", n_islands=0),
        testing.round_lake(seed, kind="arms", n_islands=0),
        testing.lake_with_islands(seed),
        testing.channel_network(seed),
    ]
    for poly in shapes:
        ring = np.asarray(poly.exterior.coords)[:-1]
        n = len(ring)
        for k in rng.choice(n, 4, replace=False):
            k = int(k)
            twice = np.insert(ring, k + 1, ring[k], axis=0)  # point k clicked twice
            corners = [(k + q * n // 4) % n for q in range(4)]
            want = [(p.corner, p.angle) for p in corner_problems(ring, corners)]
            for first in (k, k + 1):  # the corner on either copy
                on_twice = [first] + [c + (c > k) for c in corners[1:]]
                got = [(p.corner, p.angle) for p in corner_problems(twice, on_twice)]
                assert [c for c, _ in got] == [c for c, _ in want], (k, first, got, want)
                np.testing.assert_allclose([a for _, a in got], [a for _, a in want], atol=1e-9)
