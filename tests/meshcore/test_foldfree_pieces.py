"""The fold-free repair works piece by piece: generated one-block shapes (meshcore.testing)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import meshcore
from meshcore import testing
from meshcore.foldfree import invalid_cells, repair
from meshcore.grid import StructuredGrid
from meshcore.io.outline import guess_cells, guess_corners


def one_block(poly, nodes: int) -> StructuredGrid:
    """A shape's outer ring as one block, corners and cell ratio as ``meshcore import`` chooses,
    about ``nodes`` nodes, Winslow without repair."""
    loop = np.asarray(poly.exterior.coords)[:-1]
    corners = guess_corners(loop)
    ci, cj = guess_cells(loop, corners)
    s = math.sqrt(nodes / ((ci + 1) * (cj + 1)))
    cells = (max(4, round(ci * s)), max(4, round(cj * s)))
    return meshcore.generate_block(loop=loop, corners=corners, cells=cells, repair="off", threads=1)


SHAPES = {
    "arms-0": lambda: testing.round_lake(0, kind="arms"),
    "arms-1": lambda: testing.round_lake(1, kind="arms"),
    "network-0": lambda: testing.channel_network(0),
    "rough-network-10": lambda: testing.channel_network(10, roughness=0.15),
}


@pytest.mark.parametrize("name", sorted(SHAPES))
def test_repair_keeps_the_grid_away_from_the_folds(name):
    # these fold in several places; some places need the coarse-grid start. The repair used to
    # move 91–95 % of the nodes (all places grew together until the multilevel start replaced
    # the whole grid); now each place is repaired on its own
    w = one_block(SHAPES[name](), 6000)
    bad = invalid_cells(w.x, w.y)
    assert bad.sum() > 20
    r = repair(w)
    # fold-free; a block corner on a reflex shore vertex is exempt (reported, not counted)
    assert r.ok and r.invalid_after == 0 and meshcore.quality(r.grid).n_folded == 0, r.message
    moved = np.hypot(r.grid.x - w.x, r.grid.y - w.y) > 0
    assert moved.any()
    assert moved.sum() < 0.4 * moved.size
    for b in meshcore.BORDER_NAMES:
        np.testing.assert_array_equal(r.grid.border(b), w.border(b))
    # the same result twice
    r2 = repair(w)
    np.testing.assert_array_equal(r2.grid.x, r.grid.x)
    np.testing.assert_array_equal(r2.grid.y, r.grid.y)


def _rectangle(ni: int, nj: int) -> tuple[np.ndarray, np.ndarray]:
    x, y = np.meshgrid(np.linspace(0.0, ni / 4, ni + 1), np.linspace(0.0, nj / 4, nj + 1), indexing="ij")
    return x.copy(), y.copy()


def test_a_failed_repair_keeps_the_places_it_repaired():
    # two places: an interior node thrown across its neighbours (repairable where it is) and a
    # top-border node pulled below the bottom border (no grid with these borders is valid there)
    x, y = _rectangle(60, 20)
    x[10, 10] += 0.6  # across two columns: folds the cells around it
    y[45, -1] = -1.0
    w = StructuredGrid(x, y)
    bad = invalid_cells(x, y)
    assert bad[8:12, 8:12].any() and bad[43:47, 17:20].any()
    r = repair(w, strict=False)
    assert not r.ok and not r.grid.converged
    after = invalid_cells(r.grid.x, r.grid.y)
    assert not after[:30].any()  # the interior fold is repaired and stays so
    assert after[40:50].any()
    assert "no fold-free grid" in r.message
    assert r.invalid_after < r.invalid_before


def test_the_failure_names_each_place():
    # two top-border nodes pulled below the bottom border, far apart: two places no grid with these
    # borders makes valid; the message says how many places and where each is
    x, y = _rectangle(60, 20)
    y[12, -1] = -1.0
    y[45, -1] = -1.0
    r = repair(StructuredGrid(x, y), strict=False)
    assert not r.ok
    assert "lie in 2 places" in r.message
    assert "2 cell(s) at i 11–12, j 19 by the top border, around (3.125, 3.375)" in r.message
    assert "2 cell(s) at i 44–45, j 19 by the top border, around (11.375, 3.375)" in r.message


def _spied(monkeypatch, mm) -> list:
    """The first columns of the nodes every call of ``mm.minimise`` gets, as it goes."""
    tried: list = []
    real = mm.minimise

    def spy(x, y, nodes, *args, **kw):
        tried.append(nodes[:, 0].copy())
        return real(x, y, nodes, *args, **kw)

    monkeypatch.setattr(mm, "minimise", spy)
    return tried


def test_pieces_grow_no_wider_than_max_radius(monkeypatch):
    # a top-border node pulled below the bottom border: no patch repairs it; with max_radius the
    # pieces tried stay within that many cells of it (the coarse start's case), without it they
    # grew until they covered 30 % of the block
    import meshcore.foldfree.minimise as mm

    x, y = _rectangle(120, 20)
    y[60, -1] = -1.0
    bad = invalid_cells(x, y)
    tried = _spied(monkeypatch, mm)
    opts = {"tolerance": 1e-4, "max_sweeps": 50}
    ex = np.zeros(bad.shape, dtype=np.uint8)
    ok, _, _ = mm.patches(x.copy(), y.copy(), bad, ex, radius=2, max_fraction=0.3, max_radius=8, **opts)
    assert not ok and tried
    assert all(abs(i - 60).max() <= 8 + 1 for i in tried)
    tried.clear()
    ok, _, _ = mm.patches(x.copy(), y.copy(), bad, ex, radius=2, max_fraction=0.3, **opts)
    assert not ok and max(abs(i - 60).max() for i in tried) > 8 + 1


def test_a_transplant_that_must_fail_stops_at_its_first_failed_piece(monkeypatch):
    # two places no patch within the transplant's radius repairs (top-border nodes below the
    # bottom border): give_up_early gives the same verdict once the failure is certain (the first
    # piece failed at the last radius), the second piece untried then; where every piece
    # succeeds (a node pushed across its neighbour) it returns the same grid
    import meshcore.foldfree.minimise as mm

    x, y = _rectangle(120, 20)
    y[30, -1] = -1.0  # tried first (column order)
    y[90, -1] = -1.0
    bad = invalid_cells(x, y)
    tried = _spied(monkeypatch, mm)
    opts = {"tolerance": 1e-4, "max_sweeps": 50, "radius": 2, "max_fraction": 0.3, "max_radius": 8}
    ex = np.zeros(bad.shape, dtype=np.uint8)
    full = mm.patches(x.copy(), y.copy(), bad, ex, **opts)
    n_full = len(tried)
    near_90 = sum(abs(i - 90).max() <= 8 + 1 for i in tried)
    tried.clear()
    early = mm.patches(x.copy(), y.copy(), bad, ex, give_up_early=True, **opts)
    assert not full[0] and not early[0]
    assert len(tried) == n_full - 1  # radius 2, 4, 8 for the first place, 2, 4 for the second
    assert abs(tried[-1] - 30).max() <= 8 + 1
    assert sum(abs(i - 90).max() <= 8 + 1 for i in tried) == near_90 - 1
    # a repairable place: the same grid either way
    x, y = _rectangle(120, 20)
    x[90, 10] += 0.4
    bad = invalid_cells(x, y)
    assert bad.any()
    grids = []
    for early_stop in (False, True):
        xc, yc = x.copy(), y.copy()
        assert mm.patches(xc, yc, bad, ex, give_up_early=early_stop, **opts)[0]
        grids.append((xc, yc))
    np.testing.assert_array_equal(grids[0][0], grids[1][0])
    np.testing.assert_array_equal(grids[0][1], grids[1][1])


@pytest.mark.parametrize(("wide", "seam"), [(True, False), (True, True), (False, False)])
def test_a_coarse_level_goes_to_the_whole_start_when_the_level_below_needed_it(monkeypatch, wide, seam):
    # the coarse start's own repair needed its whole coarse start ("wide"): on a coarse level
    # (seam=False: its grid is only the start of the finer one) the transplant is not tried; on the
    # given grid (seam=True), or when the level below was repaired by a transplant, it is
    import meshcore.foldfree.driver as dr

    x, y = _rectangle(40, 20)
    x2, y2 = x.copy(), y.copy()  # a valid coarse start
    x[10, 10] += 0.6
    ex = np.zeros((40, 20), dtype=np.uint8)
    assert invalid_cells(x, y).any()
    monkeypatch.setattr(dr, "_coarse_start", lambda grid, *a: (x2.copy(), y2.copy(), wide))
    radii = []
    real = dr.patches

    def spy(*args, **kw):
        radii.append(kw.get("max_radius"))
        return real(*args, **kw)

    monkeypatch.setattr(dr, "patches", spy)
    path: list[str] = []
    opts = {"tolerance": 1e-4, "max_sweeps": 400, "periodic": False}
    ok, _, _ = dr._multilevel(StructuredGrid(x, y), x, y, ex, 2, opts, 0, 0, seam=seam, path=path, skip=True)
    assert ok and not invalid_cells(x, y).any()
    skipped = wide and not seam
    assert (dr.TRANSPLANT in radii) is not skipped
    assert path == (["skip", "coarse"] if skipped else ["transplant"])


@pytest.mark.parametrize("wide", [True, False])
def test_the_coarse_start_decides_after_one_round_of_patches(monkeypatch, wide):
    # EARLY_START: a place the first round of patches (radius 2) does not repair gets the coarse
    # start at once; when its repair needed the whole coarse start ("wide") no wider patches
    # follow, otherwise the wider patches (4, 8) do. Then the transplant (the given grid) and,
    # here, the whole coarse start: the fold cannot be repaired locally
    import meshcore.foldfree.driver as dr

    x, y = _rectangle(40, 20)
    x2, y2 = x.copy(), y.copy()  # a valid coarse start (the boundary node is put back below)
    y[20, -1] = 0.6  # a top-border node pulled down to the third row: no patch can fit the rows above it
    x2[:, -1], y2[:, -1] = x[:, -1], y[:, -1]
    y2[:, :-1] *= 0.55 / y2[:, -2:-1].max()  # every row below the top border lies under the dip
    assert invalid_cells(x, y).any() and not invalid_cells(x2, y2).any()
    monkeypatch.setattr(dr, "_coarse_start", lambda grid, *a: (x2.copy(), y2.copy(), wide))
    calls = []
    real = dr.patches

    def spy(*args, **kw):
        calls.append((kw.get("radius"), kw.get("max_radius")))
        return real(*args, **kw)

    monkeypatch.setattr(dr, "patches", spy)
    res = dr.repair(StructuredGrid(x, y), strict=False)
    assert calls[0] == (2, 2)  # one round before the coarse start
    wider = any(r == 4 for r, _ in calls)
    assert wider is not wide
    assert res.ok and not invalid_cells(res.grid.x, res.grid.y).any()


COARSE_SHAPES = {
    # (shape, nodes): the first needs the whole coarse start on the given grid, the second a transplant
    "network-826003": (lambda: testing.channel_network(826003, n_branches=6), 3000),
    "estuary-826001": (lambda: testing.estuary(826001), 1500),
}


@pytest.mark.parametrize("name", sorted(COARSE_SHAPES))
@pytest.mark.parametrize("solve", [False, True])
def test_the_coarse_start_from_the_grids_own_lines_repairs_as_the_solved_one(monkeypatch, name, solve):
    # the coarse grids of the multilevel start are every second line of the given grid, not
    # re-solved (COARSE_SOLVE off); both starts repair these shapes
    import meshcore.elliptic
    import meshcore.foldfree.driver as dr

    make, nodes = COARSE_SHAPES[name]
    g = one_block(make(), nodes)
    monkeypatch.setattr(dr, "COARSE_SOLVE", solve)
    calls = []
    real = meshcore.elliptic.solve
    monkeypatch.setattr(meshcore.elliptic, "solve", lambda grid, *a, **k: calls.append(1) or real(grid, *a, **k))
    path: list[str] = []
    res = dr._repair(g, whole=False, path=path)
    assert res.ok and res.invalid_before > 0 and not invalid_cells(res.grid.x, res.grid.y).any()
    assert path[-1] in ("coarse", "transplant")
    assert bool(calls) == solve


def test_a_transplant_that_gives_up_early_fails_as_the_full_one():
    # patches(give_up_early=True) tries the last round's widest piece first; it fails where the
    # patches with every piece tried fail, and repairs the same grid where they succeed
    from meshcore.foldfree.minimise import patches

    ni, nj = 40, 30
    xs, ys = np.meshgrid(np.arange(ni + 1.0), np.arange(nj + 1.0), indexing="ij")
    for broken in (False, True):  # kinks that can be undone; and two border nodes swapped, which cannot
        x, y = xs.copy(), ys.copy()
        for i, j in ((8, 8), (30, 20), (20, 12), (21, 13)):
            x[i, j] += 1.6
        if broken:
            x[5, 0], x[6, 0] = x[6, 0], x[5, 0]
        bad = invalid_cells(x, y)
        ex = np.zeros((ni, nj), np.uint8)
        kw = {"radius": 2, "max_fraction": 0.3, "max_radius": 8, "tolerance": 1e-4, "max_sweeps": 100}
        a = (x.copy(), y.copy())
        b = (x.copy(), y.copy())
        ok_full = patches(*a, bad, ex, **kw)[0]
        ok_early = patches(*b, bad, ex, give_up_early=True, **kw)[0]
        assert bad.any() and ok_full == ok_early == (not broken)
        if ok_full:
            assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])
