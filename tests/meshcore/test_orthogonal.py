"""The orthogonal smoother: its formula against the NumPy oracle, fixed points, sliding shores,
no folds, and the whole lake pipeline on synthetic water bodies."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from meshcore import StructuredGrid, testing
from meshcore.boundary import Borders
from meshcore.multiblock.topology import Block, MultiBlockTopology
from meshcore.orthogonal import _kernels, orthogonalize
from meshcore.orthogonal._reference import ortho_targets
from meshcore.orthogonal.levels import coarsen_topology, refine
from meshcore.quality import lake_metrics


def _one_block(x, y):
    bd = Borders(
        bottom=np.c_[x[:, 0], y[:, 0]], right=np.c_[x[-1], y[-1]], top=np.c_[x[:, -1], y[:, -1]], left=np.c_[x[0], y[0]]
    )
    topo = MultiBlockTopology((Block("a", bd),), (), check_geometry=False)
    return topo, StructuredGrid(x, y)


@pytest.mark.parametrize(
    ("smooth", "lo", "hi"), [(0.0, np.inf, np.inf), (0.3, np.inf, np.inf), (1.0, 1.2, 2.0), (0.05, 1.05, 1.5)]
)
def test_the_kernel_update_is_the_numpy_oracle(smooth, lo, hi):
    rng = np.random.default_rng(1)
    xi, eta = np.meshgrid(np.linspace(0, 3, 13), np.linspace(0, 1, 7), indexing="ij")
    x = xi + 0.05 * rng.standard_normal(xi.shape) + 0.2 * eta**2
    y = eta + 0.05 * rng.standard_normal(xi.shape) + 0.1 * np.sin(xi)
    topo, _ = _one_block(x, y)
    m = topo.node_map
    X, Y = x.ravel().copy(), y.ravel().copy()
    ids = m.ids[0].ravel()
    gx, gy = np.empty(m.n_nodes), np.empty(m.n_nodes)
    gx[ids], gy[ids] = X, Y
    tx, ty = np.empty(len(m.nodes)), np.empty(len(m.nodes))
    lox, loy = np.full(len(m.nodes), lo), np.full(len(m.nodes), lo)
    _kernels.jacobi_targets(gx, gy, m.nodes, m.nbr, smooth, lox, loy, hi, 0.0, tx, ty)
    rx, ry = ortho_targets(gx, gy, m.nodes, m.nbr, smooth, lo, hi)
    np.testing.assert_allclose(tx, rx, rtol=0, atol=1e-13)
    np.testing.assert_allclose(ty, ry, rtol=0, atol=1e-13)
    if np.isfinite(lo):  # each node's own start of the blend along each of its lines (the shore rows')
        lox, loy = np.where(rng.random(len(m.nodes)) < 0.5, 1.0, lo), np.where(rng.random(len(m.nodes)) < 0.5, 1.0, lo)
        _kernels.jacobi_targets(gx, gy, m.nodes, m.nbr, smooth, lox, loy, hi, 0.0, tx, ty)
        rx, ry = ortho_targets(gx, gy, m.nodes, m.nbr, smooth, lox, hi, lo_y=loy)
        np.testing.assert_allclose(tx, rx, rtol=0, atol=1e-13)
        np.testing.assert_allclose(ty, ry, rtol=0, atol=1e-13)
        ux, _ = ortho_targets(gx, gy, m.nodes, m.nbr, smooth, lo, hi)
        assert smooth == 1.0 or np.abs(tx - ux).max() > 1e-6  # (smooth 1: the blend is whole anyway)
    # the floor: edges shorter than it get the blend too (the edges here are 0.1–0.25 long)
    floor = 0.3
    _kernels.jacobi_targets(gx, gy, m.nodes, m.nbr, smooth, lox, loy, hi, floor, tx, ty)
    rx, ry = ortho_targets(gx, gy, m.nodes, m.nbr, smooth, lox, hi, lo_y=loy, floor=floor)
    np.testing.assert_allclose(tx, rx, rtol=0, atol=1e-13)
    np.testing.assert_allclose(ty, ry, rtol=0, atol=1e-13)
    fx, _ = ortho_targets(gx, gy, m.nodes, m.nbr, smooth, lox, hi, lo_y=loy)
    assert smooth == 1.0 or np.abs(rx - fx).max() > 1e-6


def test_an_orthogonal_grid_is_a_fixed_point():
    # a stretched rectangular grid (unequal spacing) and a polar sector are orthogonal
    xs = np.cumsum(np.r_[0, np.linspace(1, 2, 12)])
    ys = np.cumsum(np.r_[0, np.linspace(0.5, 0.2, 8)])
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    topo, g = _one_block(X, Y)
    res = orthogonalize(topo, [g], [], max_sweeps=5, smooth=0.0, size_ratio=None)
    np.testing.assert_allclose(res.grids[0].x, X, atol=1e-12)
    np.testing.assert_allclose(res.grids[0].y, Y, atol=1e-12)


def test_a_distorted_channel_becomes_orthogonal_with_sliding_shores():
    # a curved channel (annulus sector) with its nodes shuffled along both banks and inside
    r = np.linspace(2.0, 3.0, 9)
    th = np.linspace(0.0, math.pi / 2, 33)
    R, T = np.meshgrid(r, th, indexing="ij")
    T = T + 0.15 * np.sin(3 * T) * (R - 2.0) * (3.0 - R) + 0.04 * np.sin(5 * T)
    T[:, 0], T[:, -1] = 0.0, math.pi / 2
    x, y = R * np.cos(T), R * np.sin(T)
    x, y = x.T[::-1].copy(), y.T[::-1].copy()  # i along the channel (clockwise), j outwards
    topo, g = _one_block(x, y)
    before = lake_metrics(g)
    t = np.linspace(0, math.pi / 2, 400)
    ring = np.vstack([np.c_[2 * np.cos(t), 2 * np.sin(t)], np.c_[3 * np.cos(t[::-1]), 3 * np.sin(t[::-1])]])
    res = orthogonalize(topo, [g], [ring], max_sweeps=3000, omega=1.5, smooth=0.2)
    after = lake_metrics(res.grids[0])
    assert before.mean("deviation") > 3.0
    assert after.mean("deviation") < 0.3
    assert after.share("deviation", 1.0) > 0.95
    # the shore nodes stayed on the shore
    gx, gy = res.grids[0].x, res.grids[0].y
    np.testing.assert_allclose(np.hypot(gx[:, 0], gy[:, 0]), 2.0, atol=2e-5)  # on the 400-edge polyline
    np.testing.assert_allclose(np.hypot(gx[:, -1], gy[:, -1]), 3.0, atol=3e-5)


def test_refine_and_coarsen_keep_interfaces_shared():
    lay_poly = testing.y_junction(arm=4.0, width=1.0)
    from meshcore.layout import auto_layout

    lay = auto_layout(lay_poly, cell_size=0.1, multiple=4)
    topo = lay.topology()
    coarse = coarsen_topology(topo, 4)
    from meshcore.multiblock import initial_grids

    fine = refine(refine(initial_grids(coarse)))
    for g, b in zip(fine, topo.blocks, strict=True):
        assert g.cells == b.cells
    # every interface pair of nodes coincides after refinement
    from meshcore.multiblock import MultiBlockGrid

    mb = MultiBlockGrid(tuple(fine), tuple(b.name for b in topo.blocks), topo.interfaces, topology=topo)
    assert mb.interface_mismatch() == 0.0


@pytest.mark.parametrize(
    "make",
    [
        lambda: testing.y_junction(),
        lambda: testing.channel_network(4, n_branches=5),  # round bulges outside a hairpin bend
        lambda: testing.channel_network(2, n_branches=4),
    ],
)
def test_lake_grids_have_no_folds_and_are_orthogonal(make):
    from meshcore.lakegrid import mesh_outline

    poly = make()
    mb = mesh_outline(poly, target_cells=3000)
    m = lake_metrics(mb, polygon=poly)
    assert m.values("folded").sum() == 0
    assert mb.interface_mismatch() == 0.0
    assert m.share("deviation", 3.0) >= 0.85
    assert m.coverage.area_error < 0.01


@pytest.mark.parametrize("jump", [2.0, 4.0])
@pytest.mark.parametrize("lo_hi", [(1.1, 1.5), (1.2, 2.0)])
def test_the_size_blend_evens_out_a_jump_in_spacing(jump, lo_hi):
    # a rectangle whose columns jump from width 1 to ``jump`` halfway: orthogonal, so a fixed
    # point of the plain update; with the size blend (shore nodes sliding) the jump spreads
    # out over several columns and the grid stays orthogonal
    w = np.r_[np.ones(10), np.full(10, jump)]
    xs = np.cumsum(np.r_[0.0, w])
    xs *= 20.0 / xs[-1]
    X, Y = np.meshgrid(xs, np.linspace(0.0, 4.0, 9), indexing="ij")
    topo, g = _one_block(X, Y)
    ring = np.array([[0.0, 0.0], [20.0, 0.0], [20.0, 4.0], [0.0, 4.0]])
    ring = np.vstack(
        [ring[k] + np.linspace(0, 1, 80, endpoint=False)[:, None] * (ring[(k + 1) % 4] - ring[k]) for k in range(4)]
    )

    def worst_ratio(x):
        d = np.diff(x[:, 4])
        return float(np.max(np.maximum(d[1:] / d[:-1], d[:-1] / d[1:])))

    plain = orthogonalize(topo, [g], [ring], max_sweeps=200, smooth=0.0, shore_smooth=0.0, size_ratio=None)
    np.testing.assert_allclose(plain.grids[0].x, X, atol=1e-9)
    res = orthogonalize(topo, [g], [ring], max_sweeps=3000, smooth=0.0, shore_smooth=0.0, size_ratio=lo_hi)
    x, y = res.grids[0].x, res.grids[0].y
    assert worst_ratio(X) == pytest.approx(jump)
    assert worst_ratio(x) < 0.5 * (lo_hi[0] + lo_hi[1])
    assert lake_metrics(res.grids[0]).max("deviation") < 0.5
    assert np.all(np.diff(x, axis=0) > 0) and np.all(np.diff(y, axis=1) > 0)


@pytest.mark.parametrize("limit", [0.02, 0.05, 0.3])
def test_the_orthogonal_share_is_the_quality_modules_share(limit):
    from meshcore.orthogonal.driver import _assemble, orthogonal_share

    rng = np.random.default_rng(7)
    xi, eta = np.meshgrid(np.linspace(0, 3, 25), np.linspace(0, 1, 11), indexing="ij")
    x = xi + 0.2 * eta**2 + 0.01 * rng.standard_normal(xi.shape)
    y = eta + 0.1 * np.sin(2 * xi) + 0.01 * rng.standard_normal(xi.shape)
    topo, g = _one_block(x, y)
    X, Y = _assemble([g], topo.node_map)
    share = orthogonal_share(X, Y, topo.node_map.nodes, topo.node_map.nbr, limit)
    assert 0.0 < share < 1.0  # a mix: the comparison means something
    assert share == pytest.approx(lake_metrics(g).share("cos", limit), abs=1e-12)


def _jittered_strip():
    """A 32 × 8 strip whose interior nodes are jittered by 2 % of a cell (borders straight)."""
    rng = np.random.default_rng(3)
    xi, eta = np.meshgrid(np.linspace(0, 4, 33), np.linspace(0, 1, 9), indexing="ij")
    x = xi + 0.02 * rng.standard_normal(xi.shape)
    y = eta + 0.02 * rng.standard_normal(xi.shape)
    x[:, [0, -1]], y[:, [0, -1]] = xi[:, [0, -1]], eta[:, [0, -1]]
    x[[0, -1]], y[[0, -1]] = xi[[0, -1]], eta[[0, -1]]
    return _one_block(x, y)


def test_stall_stops_the_sweeps_once_orthogonality_stops_improving():
    topo, g = _jittered_strip()
    opts = {"max_sweeps": 400, "tol": 0.0, "smooth": 0.0, "size_ratio": None}
    full = orthogonalize(topo, [g], [], **opts)
    assert full.sweeps == 400 and not full.converged
    # no gain of 100 % of the nodes in 10 sweeps: stops at the first check
    assert orthogonalize(topo, [g], [], stall=1.0, stall_every=10, **opts).sweeps == 10
    early = orthogonalize(topo, [g], [], stall=0.001, stall_every=10, **opts)
    assert early.converged and 10 <= early.sweeps < 400
    share = lake_metrics(list(early.grids)).share("cos", 0.02)
    assert share >= lake_metrics(list(full.grids)).share("cos", 0.02) - 0.01


def test_stall_waits_while_any_watched_share_still_rises():
    """A share that does not move (``|cos| ≤ 0``: no node) stops the sweeps at the first check
    alone, not while another watched share (``|cos| ≤ 0.02``) still rises: the finest level of a
    lake grid whose 0.02 share stood still over its first 20 sweeps while its 3° share rose
    stopped there (``docs/lake-grids-journal.md``, *Lakes with many islands*)."""
    topo, g = _jittered_strip()
    opts = {"max_sweeps": 400, "tol": 0.0, "smooth": 0.0, "size_ratio": None, "stall": 0.001, "stall_every": 10}
    assert orthogonalize(topo, [g], [], stall_limits=(0.0,), **opts).sweeps == 10
    assert orthogonalize(topo, [g], [], stall_limits=(0.0, 0.02), **opts).sweeps > 10


def test_the_finest_level_gets_the_last_sweep_count():
    from meshcore.lakegrid import mesh_layout
    from meshcore.layout import auto_layout

    lay = auto_layout(testing.y_junction(), target_cells=600, multiple=2)
    done = []

    def level(kind, v):
        if kind == "level":  # (the equalize step reports after them)
            done.append(v[1].sweeps)

    mesh_layout(lay, levels=1, sweeps=(11, 7, 5), stall=None, callback=level)
    assert done == [7, 5]


def test_the_start_grids_solve_stops_at_its_iteration_cap(monkeypatch):
    """The coarsest level's start is a start: its solve stops after START_ITERATIONS even where
    it does not converge (a held-out lake's SOR fallback ran 50 000 sweeps there)."""
    import meshcore.lakegrid as lg
    from meshcore import testing
    from meshcore.layout import auto_layout

    topo = auto_layout(testing.y_junction(), target_cells=600).topology()
    monkeypatch.setattr(lg, "START_ITERATIONS", 1)
    grids, how = lg._start(topo, "winslow")
    assert "not converged after 1 iteration" in how
    assert len(grids) == len(topo.blocks)
    monkeypatch.setattr(lg, "START_ITERATIONS", 2000)
    _, how = lg._start(topo, "winslow")
    assert "(converged" in how


def test_a_start_that_leaves_the_lake_is_replaced_by_the_relaxed_algebraic_one(monkeypatch):
    """Winslow's solution stays within its borders' hull (a maximum principle); a multiblock SOR
    that blew up on a tangled coarse level left it (generated headlands, regular layout: nodes 8
    lake widths out, 2215 folded cells in the final grid).  Such a start is dropped for the
    algebraic grids relaxed as one grid; a start that did not converge but stayed inside is kept."""
    import meshcore.lakegrid as lg
    from meshcore import multiblock, testing
    from meshcore.layout import auto_layout

    topo = auto_layout(testing.y_junction(), target_cells=600).topology()
    g0 = multiblock.initial_grids(topo)
    assert not lg.escaped(g0, g0)
    real = multiblock.solve_multiblock

    def blown_up(*args, **kw):
        mb = real(*args, **dict(kw, max_iterations=1))
        far = [g.replaced(x=np.asarray(g.x) + 10.0 * (k == 1)) for k, g in enumerate(mb.grids)]
        return dataclasses.replace(mb, grids=tuple(far))

    assert lg.escaped(blown_up(topo, initial=g0).grids, g0)
    monkeypatch.setattr(multiblock, "solve_multiblock", blown_up)
    grids, how = lg._start(topo, "winslow", g0)
    assert how.startswith("algebraic grids relaxed as one grid") and "left the lake's extent" in how
    assert not lg.escaped(grids, g0)
    monkeypatch.setattr(lg, "START_ITERATIONS", 1)
    monkeypatch.setattr(multiblock, "solve_multiblock", real)
    grids, how = lg._start(topo, "winslow", g0)  # not converged, still inside: kept
    assert how.startswith("multiblock Winslow (not converged")


@pytest.mark.slow
def test_a_regular_layout_whose_start_blew_up_still_gives_a_grid_inside_the_lake():
    """Generated headlands, regular layout (the `.ddb` path), 10 000 cells: the coarse Winslow
    start's SOR blew up (nodes 8 lake widths out; 2 215 folded cells in the grid on main)."""
    from meshcore.lakegrid import mesh_outline

    poly = testing.headlands(991100, n=6)
    mb = mesh_outline(poly, target_cells=10000, regular=True)
    x0, y0, x1, y1 = poly.bounds
    pad = 1e-6 * max(x1 - x0, y1 - y0)
    for g in mb.grids:
        assert np.asarray(g.x).min() >= x0 - pad and np.asarray(g.x).max() <= x1 + pad
        assert np.asarray(g.y).min() >= y0 - pad and np.asarray(g.y).max() <= y1 + pad
    assert lake_metrics(mb, polygon=poly).summary()["folded_cells"] == 0


def test_escaped_reads_non_finite_nodes_as_out():
    import meshcore.lakegrid as lg

    g = StructuredGrid(*np.meshgrid(np.linspace(0, 1, 5), np.linspace(0, 1, 4), indexing="ij"))
    bad = np.asarray(g.x).copy()
    bad[2, 2] = np.nan
    assert lg.escaped([StructuredGrid(bad, np.asarray(g.y))], [g])
    inside = np.asarray(g.x) * 1.005  # within ESCAPE_MARGIN of the extent
    assert not lg.escaped([StructuredGrid(inside, np.asarray(g.y))], [g])


def test_the_ring_search_from_a_hint_is_the_bisection():
    """The shore sweep's walk from a segment near the point finds the segment bisection finds,
    for any hint: far ones, ties (zero-length segments), the ends and just outside them."""
    rng = np.random.default_rng(7)
    for trial in range(40):
        n = int(rng.integers(1, 300))
        seg = rng.uniform(0.0, 2.0, n) * (rng.random(n) > 0.2)  # a fifth of zero length
        S = np.concatenate([[0.0], np.cumsum(seg)])
        pad = int(rng.integers(0, 5))  # the ring's table starts at an offset in the shared array
        SS = np.concatenate([np.full(pad, -1.0), S, np.full(3, 1e9)])
        total = S[-1]
        us = np.concatenate([rng.uniform(0.0, max(total, 1e-9), 30), S[:-1], [0.0, -1e-17, total, total + 1e-12]])
        for u in us:
            want = _kernels._segment(SS, pad, n, u)
            for hint in {0, n - 1, want, max(0, want - 5), min(n - 1, want + 40), int(rng.integers(0, n))}:
                assert _kernels._segment_from(SS, pad, n, u, hint) == want, (trial, u, hint)


def _fan(theta, blocks, r=1.0):
    """A cut end at the origin with lines at angles ``theta`` (the first and last on the shore),
    one cell between each two (of block ``blocks[q]``), closed by a node further out."""
    m = len(theta) - 1
    X = np.r_[0.0, r * np.cos(theta), 1.6 * np.cos(0.5 * (theta[:-1] + theta[1:]))]
    Y = np.r_[0.0, r * np.sin(theta), 1.6 * np.sin(0.5 * (theta[:-1] + theta[1:]))]
    cells = np.array([[0, 1 + q, 2 + m + q, 2 + q] for q in range(m)], dtype=np.int64)
    boundary = np.zeros(len(X), dtype=bool)
    boundary[[0, 1, 1 + m]] = True
    cnt = np.bincount(cells.ravel(), minlength=len(X))
    bn = np.flatnonzero(boundary)
    return X, Y, cells, np.asarray(blocks), boundary, bn, cnt


@pytest.mark.parametrize(
    ("theta_deg", "blocks"),
    [
        ([0, 40, 200, 290], [0, 1, 1]),  # a corner block squeezed, the side block's line off
        ([0, 175, 230, 300], [0, 1, 1]),  # a corner block opened into a fan (the shore-end fan)
        ([0, 100, 150, 200, 330], [0, 1, 1, 2]),  # two corner blocks beside a side
        ([0, 30, 100, 200], [0, 1, 1]),  # under the least water angle: left alone
    ],
)
def test_the_fan_hold_is_the_numpy_oracle(theta_deg, blocks):
    from meshcore.orthogonal._reference import fan_targets
    from meshcore.orthogonal.driver import _cut_end_fans, _node_cells

    X, Y, cells, blk, boundary, bn, cnt = _fan(np.radians(theta_deg), blocks, r=0.3)
    free = np.zeros(len(bn), dtype=bool)
    ends, fptr, fan, corner = _cut_end_fans(cells, blk, boundary, bn, free, cnt)
    assert list(ends) == [0] and list(fan) == list(range(1, len(theta_deg) + 1))
    cptr, ncells, _ = _node_cells(cells, len(X))
    args = (np.radians(225.0), 0.3, 1.15)
    nodes, tx, ty = fan_targets(X, Y, ends, fptr, fan, corner, *args)
    x1, y1 = X.copy(), Y.copy()
    _kernels.hold_fans(
        x1, y1, ends, fptr, fan, corner, cptr, ncells, np.full(len(X), -np.inf), *args, np.zeros(len(X), np.uint8)
    )
    moved = np.flatnonzero((x1 != X) | (y1 != Y))
    assert sorted(moved) == sorted(nodes)
    np.testing.assert_allclose(x1[nodes], tx, atol=1e-13)
    np.testing.assert_allclose(y1[nodes], ty, atol=1e-13)
    if theta_deg[-1] >= 225:
        assert len(nodes)  # every case above the least angle is off its place or too short


@pytest.mark.parametrize(
    "make",
    [
        lambda: testing.channel_network(24, n_branches=5),
        lambda: testing.channel_network(26, n_branches=7),
        lambda: testing.lake_with_islands(12),
    ],
)
def test_no_block_corner_opens_into_a_fan_at_a_cut_end(make, monkeypatch):
    """Where a cut ends at a reflex shore corner, the solves can turn its first edge until the
    corner block's angle there is 150-180 degrees (a polar fan: cells 10-60 times smaller than
    across the cut; without ``hold_ends`` 180 and 140 degrees on the first and last lake here);
    the fan hold keeps it near its share of the water angle.  (Measured without the shore rows'
    size blend, ``driver.SHORE_ROW_LO``, which ``hold_ends``, off by default, predates: with it the
    first lake's worst such angle is 141°.)"""
    from meshcore.lakegrid import mesh_outline
    from meshcore.orthogonal import driver
    from meshcore.orthogonal.driver import _assemble, _cut_end_fans

    monkeypatch.setattr(driver, "SHORE_ROW_LO", None)
    poly = make()
    mb = mesh_outline(poly, target_cells=4000, hold_ends=True)
    m = mb.topology.node_map
    X, Y = _assemble(mb.grids, m)
    cells = m.cells.astype(np.int64)
    cnt = np.bincount(cells.ravel(), minlength=m.n_nodes)
    bn = np.flatnonzero(m.boundary)
    ends, fptr, fan, corner = _cut_end_fans(cells, m.cell_block, m.boundary, bn, np.zeros(len(bn), bool), cnt)
    worst = 0.0
    for k, c in enumerate(ends):
        f = fan[fptr[k] : fptr[k + 1]]
        d = np.degrees(np.mod(np.diff(np.arctan2(Y[f] - Y[c], X[f] - X[c])), 2 * np.pi))
        if d.sum() >= 225:
            worst = max(worst, float(d[corner[fptr[k] : fptr[k + 1] - 1]].max(initial=0.0)))
    assert 0 < worst < 140
    assert lake_metrics(mb, polygon=poly).values("folded").sum() == 0


def _shore_row(cols):
    """A block of nodes ``cols × (0, 1, 2)`` whose row y = 0 lies on the shore (a ring along y = 0 from
    x = -10): the shore sweep's tables, and each shore node's index by its point."""
    from types import SimpleNamespace

    from meshcore.orthogonal import driver

    x, y = np.meshgrid(np.asarray(cols, float), np.arange(3.0), indexing="ij")
    topo, g = _one_block(x, y)
    m = topo.node_map
    X, Y = driver._assemble([g], m)
    cells = m.cells.astype(np.int64)
    cptr, ncells, cnt = driver._node_cells(cells, m.n_nodes)
    ring = np.array([[-10.0, 0.0], [40.0, 0.0], [40.0, -5.0], [-10.0, -5.0]])
    bn, binner, bprev, bnext, bring, bs, free = driver._shore_data(X, Y, m, cells, cnt, [ring])
    R, S, roff = driver._ring_tables([ring])
    at = {(round(X[p], 6), round(Y[p], 6)): i for i, p in enumerate(bn)}
    return SimpleNamespace(
        X=X, Y=Y, m=m, cptr=cptr, ncells=ncells, bn=bn, binner=binner, bprev=bprev, bnext=bnext, bring=bring,
        bs=bs, free=free, R=R, S=S, roff=roff, at=at,
    )  # fmt: skip


@pytest.mark.parametrize("beyond_next", [4.0, 8.0, 20.0])
def test_a_shore_node_between_two_cut_ends_never_passes_a_neighbour(beyond_next):
    # A free shore node (x = 2) between two fixed cut ends (x = 1 and 3) keeps its edge to each
    # end within ``lo`` of the edge beyond it: 1 before, ``beyond_next`` after.  Those two limits
    # cannot both hold; halfway between them lay beyond the node's own neighbour at x = 1, and a
    # node past a cut's end measures its arcs the other way round the ring and may end anywhere
    # on it (generated `lake_with_islands(955300, n_islands=6, lobes=4)`: a coarse node round an
    # island's corner, the grid 1.19 cells over the island).
    c = _shore_row([0.0, 1.0, 2.0, 3.0, 3.0 + beyond_next])
    X, Y, m, bn, bs, at = c.X, c.Y, c.m, c.bn, c.bs, c.at
    bprev, bnext = c.bprev, c.bnext
    k, before, after = at[(2.0, 0.0)], at[(0.0, 0.0)], at[(3.0 + beyond_next, 0.0)]
    assert c.free[k] and (bprev[k], bnext[k]) == (at[(1.0, 0.0)], at[(3.0, 0.0)])
    across = -np.ones((len(bn), 2), dtype=np.int64)
    across[k] = before, after
    jmin = np.full(m.n_nodes, 1e-3)  # the fold guard's floor (cells of area >= 1 here)
    lo, hi = 1.15, 2.0
    bz = np.zeros(1)
    p = bn[k]
    for _ in range(30):
        _kernels.shore_sweep(
            X, Y, np.array([k]), bn, c.binner, bprev, bnext, c.bring, bs, c.R, c.S, c.roff, c.cptr, c.ncells,
            1.0, 0.15, 0.25, jmin, lo, hi, 0.0, bz, 0.05, across, np.array([lo]), np.zeros(m.n_nodes, np.uint8),
        )  # fmt: skip
        assert Y[p] == 0.0  # on the shore
        assert 1.0 + 0.1 * 2.0 - 1e-9 <= X[p] <= 3.0 - 0.1 * 2.0 + 1e-9  # within its own arc, a tenth from either end


def test_a_shore_node_whose_neighbours_are_not_on_its_two_sides_stays_put():
    # Round a spike of water narrower than a cell, nodes on its two flanks can be projected onto one
    # flank, so that a node's previous neighbour lies a little ahead of it along the shore.  Its arcs
    # to its neighbours then measured round the whole ring, the foot or the middle of that arc lay
    # anywhere on it: generated `dendritic(952505)` at 15 000 cells had a node thrown 190 cells along
    # the shore (one edge 11 units long across the land, nodes 0.0025 apart beside it).
    c = _shore_row(np.arange(5.0))
    X, Y, m, bn, bs, at, bprev = c.X, c.Y, c.m, c.bn, c.bs, c.at, c.bprev
    k = at[(2.0, 0.0)]
    assert c.free[k] and (bprev[k], c.bnext[k]) == (at[(1.0, 0.0)], at[(3.0, 0.0)])
    jmin = np.full(m.n_nodes, -np.inf)  # no fold guard: the slide's own rule alone
    p = bn[k]

    def sweep(bs):
        X1, Y1 = X.copy(), Y.copy()
        _kernels.shore_sweep(
            X1, Y1, np.array([k]), bn, c.binner, bprev, c.bnext, c.bring, bs, c.R, c.S, c.roff, c.cptr, c.ncells,
            1.0, 0.15, 0.25, jmin, 1.2, 2.0, 0.0, np.zeros(1), 0.05, -np.ones((len(bn), 2), dtype=np.int64),
            np.array([1.2]), np.zeros(m.n_nodes, np.uint8),
        )  # fmt: skip
        return X1[p], Y1[p]

    assert sweep(bs.copy()) == (2.0, 0.0)  # between its neighbours at its foot already: it stays
    crossed = bs.copy()
    crossed[bprev[k]] = bs[k] + 0.05  # the previous neighbour a little ahead of it
    assert sweep(crossed) == (2.0, 0.0)  # (before: thrown to the far side of the ring)
