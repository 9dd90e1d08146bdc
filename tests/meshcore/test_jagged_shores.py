"""Shores jagged below the cell size: the layout and the grid follow the shore the grid can see.

:mod:`meshcore.layout.shore` smooths a shore where it zig-zags at the scale of the cells; the
layout reads it smoothed more where it bends back and forth at the scale of block corners.
Tested on :func:`meshcore.testing.jagged_cells` (random teeth of a given size in cells) of
the textbook shapes, over seeds: the blocks do not multiply, no cell folds, the grid stays
orthogonal, and the notes say how far the grid's shore is from the outline.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from shapely.geometry import Point, Polygon, box

from meshcore import testing
from meshcore.layout import auto_layout
from meshcore.layout.shore import shore_at_scale, wiggle


def _channel(cells: float, seed: int):
    return testing.jagged_cells(testing.straight_channel(50.0, 1.0), cells, seed)


# ------------------------------------------------------------------ the wiggle
def test_wiggle_is_zero_where_the_shore_turns_one_way():
    circle = np.asarray(Point(0, 0).buffer(10.0, quad_segs=64).exterior.coords)[:-1]
    square = np.asarray(box(0, 0, 10, 10).exterior.coords)[:-1]
    for ring in (circle, square):
        assert wiggle(ring, 0.5).max() < 1.0


def test_wiggle_measures_a_zig_zag():
    # teeth 0.6 cells apart and 0.3 cells high on a straight line: turns of about ±90° that
    # are taken back within a cell
    x = np.arange(0.0, 40.0, 0.3)
    y = np.where(np.arange(len(x)) % 2, 0.15, -0.15)
    ring = np.vstack([np.column_stack([x, y]), [[40.0, 10.0], [0.0, 10.0]]])
    w = wiggle(ring, 0.5)
    assert np.median(w[5 : len(x) - 5]) > 60.0


# ------------------------------------------------------------------ the smoothed shore
def test_a_clean_shore_is_left_alone():
    for poly in (testing.straight_channel(), testing.y_junction(), testing.rectangle_with_hole()):
        h = math.sqrt(poly.area / 10_000)
        sh = shore_at_scale(poly, h)
        assert sh.grid is poly and sh.layout is poly and sh.change is None


@pytest.mark.parametrize("seed", range(4))
def test_a_jagged_shore_is_smoothed_to_its_mean_line(seed):
    clean = testing.straight_channel(50.0, 1.0)
    poly = testing.jagged_cells(clean, 1.4, seed)
    h = math.sqrt(poly.area / 10_000)
    sh = shore_at_scale(poly, h)
    assert sh.change is not None
    for p in (sh.grid, sh.layout):
        assert p.is_valid
        assert abs(p.area - poly.area) < 0.01 * poly.area  # the teeth are cut from both sides
        assert wiggle(np.asarray(p.exterior.coords)[:-1], h).max() < 60.0
    # the grid's shore runs through the teeth: on the whole closer to the clean shore than
    # the jagged one is (the area between them is smaller)
    assert sh.grid.symmetric_difference(clean).area < 0.8 * poly.symmetric_difference(clean).area
    # the reported distance is the distance to the outline as given
    assert sh.change.hausdorff_cells == pytest.approx(sh.grid.exterior.hausdorff_distance(poly.exterior) / h, abs=0.1)
    # both shores have the same vertices, in the same order
    assert len(sh.grid.exterior.coords) == len(sh.layout.exterior.coords)


def test_islands_are_smoothed_and_kept():
    outer = testing.straight_channel(40.0, 10.0)
    islands = [Point(10, 5).buffer(2.0), Point(28, 5).buffer(1.0)]
    poly = testing.jagged_cells(Polygon(outer.exterior, [i.exterior for i in islands]), 1.0, 3)
    h = math.sqrt(poly.area / 10_000)
    sh = shore_at_scale(poly, h)
    assert len(sh.grid.interiors) == len(sh.layout.interiors) == 2
    for a, b in zip(poly.interiors, sh.grid.interiors, strict=True):
        assert abs(Polygon(b).area - Polygon(a).area) < 0.1 * Polygon(a).area


# ------------------------------------------------------------------ layouts
#: Known since 94ac9b5 (cuts along the shore's normal, landed after these tests were written): on
#: some jagged shores the new cuts from bays add blocks (a jagged Y: 10-11 blocks, clean 6). Strict:
#: these cases fail the test until the layout no longer does that.
NORMAL_CUTS = pytest.mark.xfail(strict=True, reason="normal cuts from bays add blocks on jagged shores (94ac9b5)")


@pytest.mark.parametrize(
    ("cells", "seed"),
    [
        pytest.param(c, s, marks=NORMAL_CUTS) if (c, s) == (2.8, 0) else (c, s)
        for s in range(3)
        for c in (0.7, 1.4, 2.8)
    ],
)
def test_a_jagged_straight_channel_stays_a_few_blocks(cells, seed):
    poly = _channel(cells, seed)
    lay = auto_layout(poly)
    assert len(lay.blocks) <= 3
    assert all(min(b.cells) >= 3 for b in lay.blocks)
    note = [n for n in lay.notes if "Hausdorff" in n]
    assert len(note) == 1 and "cells from the outline" in note[0]


# seed 0 passes since the Y's star has six blocks round its centre (the clean Y 6 -> 9 blocks, its
# jagged twin 11 as before); seeds 1 and 2 still fail on their networks (10 -> 15, 14 -> 20 blocks)
@pytest.mark.parametrize("seed", [0, pytest.param(1, marks=NORMAL_CUTS), pytest.param(2, marks=NORMAL_CUTS)])
def test_jagged_branched_lakes_keep_their_layout_size(seed):
    for clean in (testing.y_junction(), testing.channel_network(seed + 1, n_branches=5)):
        n_clean = len(auto_layout(clean).blocks)
        lay = auto_layout(testing.jagged_cells(clean, 1.4, seed))
        assert len(lay.blocks) <= n_clean + 3, (n_clean, len(lay.blocks))


@pytest.mark.parametrize("seed", [0, pytest.param(1, marks=NORMAL_CUTS)])
def test_a_jagged_round_lake_with_an_island(seed):
    clean = testing.round_lake(seed + 5, kind="blob", n_islands=1)
    poly = testing.jagged_cells(clean, 1.4, seed)
    lay = auto_layout(poly)
    assert len(lay.polygon.interiors) == len(poly.interiors)
    assert len(lay.blocks) <= len(auto_layout(clean).blocks) + 3


# ------------------------------------------------------------------ grids
@pytest.mark.slow
@pytest.mark.parametrize(("cells", "seed"), [(0.7, 0), (1.4, 1), (2.8, 2)])
def test_grids_of_a_jagged_channel_are_orthogonal_and_unfolded(cells, seed):
    from meshcore.lakegrid import mesh_outline
    from meshcore.quality import lake_metrics

    poly = _channel(cells, seed)
    mb = mesh_outline(poly)
    m = lake_metrics(mb, polygon=poly)
    assert int(m.values("folded").sum()) == 0
    if cells <= 1.5:  # teeth of 2.8 cells: 79 % since d3ab72d, 94 % before (docs/lake-grids-journal.md, limits)
        assert m.share("deviation", 3.0) >= 0.9
    s = m.summary()
    assert abs(s["area_ratio"] - 1.0) < 0.01


# ------------------------------------------------------------------ arms narrower than two cells
def _basin_with_arm(width: float, h: float = 0.3):
    import shapely
    from shapely.geometry import LineString

    arm = LineString([(30 - 1e-9, 15), (36, 15), (40, 18)]).buffer(width / 2, cap_style="flat", quad_segs=4)
    return shapely.union_all([box(0, 0, 30, 30), arm]).simplify(1e-9)


@pytest.mark.parametrize("cells", [0.6, 1.2, 1.8])
def test_an_arm_narrower_than_two_cells_is_left_out_with_a_note(cells):
    h = 0.3
    poly = _basin_with_arm(cells * h, h)
    lay = auto_layout(poly, cell_size=h)
    note = [n for n in lay.notes if "narrower than two cells" in n]
    assert len(note) == 1
    assert "near (3" in note[0] and "% of the water" in note[0]  # names the place (x ≈ 38)
    assert not lay.polygon.buffer(1e-9).contains(Point(39.0, 17.25))  # the arm's far end
    assert lay.polygon.area == pytest.approx(900.0, rel=1e-3)  # the basin is all there


@pytest.mark.parametrize("cells", [2.2, 3.0])
def test_an_arm_two_cells_wide_or_more_is_kept(cells):
    h = 0.3
    poly = _basin_with_arm(cells * h, h)
    lay = auto_layout(poly, cell_size=h)
    assert not [n for n in lay.notes if "narrower" in n]
    assert lay.polygon.area == pytest.approx(poly.area, rel=1e-6)


def test_a_narrow_passage_between_two_basins_is_kept():
    import shapely

    from meshcore.layout.shore import without_narrow_arms

    poly = shapely.union_all([box(0, 0, 10, 10), box(15, 0, 25, 10), box(9, 4.8, 16, 5.2)])
    out, notes = without_narrow_arms(poly, 0.3)
    assert out is poly and notes == []


def test_a_lake_that_tapers_into_a_narrow_end_keeps_it():
    from meshcore.layout.shore import without_narrow_arms

    h = 0.3
    # 3 cells wide for 10 cells, narrowing over 6 cells to a tail 0.5 cells wide and 12 long
    lake = Polygon([(0, 0), (3, 0), (4.8, 0.375), (8.4, 0.375), (8.4, 0.525), (4.8, 0.525), (3, 0.9), (0, 0.9)])
    out, notes = without_narrow_arms(lake, h)
    assert out is lake and notes == []


def test_a_narrow_arm_leaving_a_basin_at_its_corner_is_left_out():
    """Round a mouth in a corner the water within four cells is a quarter disc, too small for a
    disc of 1.75 cells, but the basin holds one a little further out: a side arm, not a narrow end
    the lake tapers into (a block of the basin fanned into it; held-out g180510, Long Point)."""
    from meshcore.layout.shore import without_narrow_arms

    h = 0.3
    arm = box(0.0, -3.0, 0.22, 0.0)  # 0.73 cells wide, 10 cells long, from the basin's corner
    lake = shapely.union_all([box(0.0, 0.0, 10.0, 10.0), arm])
    out, notes = without_narrow_arms(lake, h)
    assert len(notes) == 1 and "near (0.11, -1.5)" in notes[0]
    assert out.area == pytest.approx(100.0, rel=1e-6) and not out.buffer(-1e-6).intersects(arm)
    # the same arm at the end of a channel 3 cells wide that narrows into it: kept
    funnel = shapely.union_all([box(-0.34, 0.0, 0.56, 10.0), arm])
    assert without_narrow_arms(funnel, h)[1] == []


@pytest.mark.slow
def test_the_grid_of_a_basin_with_a_narrow_arm_has_no_folds():
    from meshcore.lakegrid import mesh_outline
    from meshcore.quality import lake_metrics

    poly = _basin_with_arm(1.2 * 0.3)
    mb = mesh_outline(poly, cell_size=0.3)
    m = lake_metrics(mb, polygon=poly)
    assert int(m.values("folded").sum()) == 0
    assert m.share("deviation", 3.0) >= 0.9


@pytest.mark.parametrize("seed", range(6))
def test_gauss_leaves_out_only_zero_weights(seed):
    """``_gauss`` stops where every weight is exactly zero: the same rings, bit for bit, as the sum
    over every offset its step allows (a ring with one short edge: all the way round)."""
    from meshcore.layout import shore

    rng = np.random.default_rng(seed + 861100)
    n = int(rng.integers(40, 600))
    ds = rng.uniform(0.5, 1.5, n)
    k = int(rng.integers(n - 1))
    ds[k : k + 2] = 1e-4  # two short edges: the step allows every offset (n // 2 either way)
    s = np.concatenate([[0.0], np.cumsum(ds)[:-1]])
    total = float(ds.sum())
    edge = np.diff(np.append(s, total))
    dsv = 0.5 * (edge + np.roll(edge, 1))  # as _gauss weighs the vertices
    ring = rng.normal(size=(n, 2)) * 10 + 1e4
    sigma = rng.choice([0.0, 1.0, 2.5, 4.0], n)
    sigma[0] = 3.0
    want = np.zeros_like(ring)
    den = np.zeros(n)
    for o in range(-(n // 2), n // 2 + 1):  # the sum without the reach
        idx = np.arange(n) + o
        j = idx % n
        d = s[j] + total * (idx // n) - s
        w = np.exp(-0.5 * (d / np.where(sigma > 0, sigma, 1.0)) ** 2) * dsv[j]
        w = np.where(sigma > 0, w, 1.0 if o == 0 else 0.0)
        want += w[:, None] * ring[j]
        den += w
    want /= den[:, None]
    assert 3.0 * sigma.max() / dsv.min() > n // 2 > shore._reach(s, total, sigma)
    assert np.array_equal(shore._gauss(ring, s, total, sigma), want)
