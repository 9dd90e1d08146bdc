"""Islands closer than two cells to each other or to the shore (:mod:`meshcore.layout.islandgaps`).

No grid line fits between two islands, or an island and the shore, less than two cells apart:
on main such gaps made the layout cut blocks a cell across through them, and the lakes of
clustered islands (:func:`meshcore.testing.island_clusters`) folded cells
(`island_clusters(966006, n_islands=120)` at 10 000 cells: 34 folded cells).  They are joined,
the water between them given up with a note naming where and how much.
"""

from __future__ import annotations

import math
import re

import pytest
from shapely.geometry import Polygon

from meshcore import testing
from meshcore.cellsize import default_cell_size
from meshcore.layout.islandgaps import GAP_CELLS, SHORE_GAP_CELLS, close_pairs, without_island_gaps
from meshcore.layout.polygon import MIN_ISLAND_CELLS, water_polygon


def _kept_islands(poly, cells=10_000):
    h = default_cell_size(water_polygon(poly)[0].area, cells)
    out, _ = water_polygon(poly, drop_islands_below=MIN_ISLAND_CELLS * h)
    return out, h


def _given_up(notes):
    return sum(float(a) for n in notes for a in re.findall(r"\(area ([0-9.e+-]+),", n))


@pytest.mark.parametrize(("seed", "n"), [(971000, 60), (971001, 120), (971002, 200), (971003, 300)])
def test_island_clusters_are_clustered(seed, n):
    poly = testing.island_clusters(seed, n_islands=n)
    assert poly.is_valid and 0.8 * n <= len(poly.interiors) <= n
    assert testing.island_clusters(seed, n_islands=n).equals(poly)
    h = math.sqrt(Polygon(poly.exterior).area / 10_000)
    islands = [Polygon(r) for r in poly.interiors]
    gaps = [min(a.distance(b) for b in islands if b is not a) for a in islands]
    assert min(gaps) >= 0.299 * h and min(Polygon(r).distance(poly.exterior) for r in poly.interiors) >= 0.299 * h
    assert sum(g < 2 * h for g in gaps) >= 0.3 * len(gaps)  # many islands in narrow passages


@pytest.mark.parametrize(("seed", "n"), [(972000, 80), (972001, 150), (972002, 250), (972003, 300), (972004, 40)])
def test_joined_islands_keep_their_land_and_the_notes_account_for_the_water(seed, n):
    water, h = _kept_islands(testing.island_clusters(seed, n_islands=n))
    assert close_pairs(water, GAP_CELLS * h, SHORE_GAP_CELLS * h)  # the case has gaps to join
    out, notes = without_island_gaps(water, h)
    assert out.is_valid and out.geom_type == "Polygon"
    assert out.difference(water).area <= 1e-9 * water.area  # only water is given up
    for ring in water.interiors:  # every island stays land: a hole of the water, or joined to the shore
        assert out.intersection(Polygon(ring)).area <= 1e-9 * water.area
    assert not close_pairs(out, 0.999 * GAP_CELLS * h, 0.999 * SHORE_GAP_CELLS * h)  # no such gap left
    assert _given_up(notes) == pytest.approx(water.area - out.area, rel=2e-3)
    assert water.area - out.area <= 0.06 * water.area  # 0.7–4.5 % on these (300 islands in 8 clusters)


@pytest.mark.parametrize("seed", [973000, 973001, 973002])
def test_well_separated_islands_are_not_touched(seed):
    poly = testing.lake_with_islands(seed, n_islands=3, near_shore=False)
    water, h = _kept_islands(poly)
    if close_pairs(water, GAP_CELLS * h, SHORE_GAP_CELLS * h):
        pytest.skip("islands within two cells")
    out, notes = without_island_gaps(water, h)
    assert out is water and notes == []


def test_two_islands_a_cell_apart_become_one_and_the_gap_is_named():
    shore = [(0, 0), (40, 0), (40, 30), (0, 30)]
    a = [(10, 10), (18, 10), (18, 20), (10, 20)]
    b = [(19, 10), (27, 10), (27, 20), (19, 20)]  # 1 apart, cells of 1
    water, _ = water_polygon(shore, holes=[a, b])
    out, notes = without_island_gaps(water, 1.0)
    assert len(out.interiors) == 1  # arcs of the closing at the ends of the gap: a hair short of 170
    assert Polygon(out.interiors[0]).area == pytest.approx(170.0, abs=0.1)
    assert len(notes) == 1 and "2 islands near (18.5, 15)" in notes[0] and "narrowest gap 1 cells" in notes[0]
    assert _given_up(notes) == pytest.approx(water.area - out.area, rel=1e-3) == pytest.approx(10.0, abs=0.1)


def test_an_island_a_cell_from_the_shore_joins_it_when_asked():
    shore = [(0, 0), (40, 0), (40, 30), (0, 30)]
    a = [(10, 1), (18, 1), (18, 10), (10, 10)]  # 1 from the shore below
    water, _ = water_polygon(shore, holes=[a])
    assert without_island_gaps(water, 1.0)[0] is water  # off by default
    out, notes = without_island_gaps(water, 1.0, shore_cells=2.0)
    given = _given_up(notes)
    assert len(out.interiors) == 0 and "and the shore" in notes[0]
    assert out.area + given == pytest.approx(1200 - 72, rel=1e-4)  # the note accounts for the water
    assert 8.0 <= given <= 12.0  # the gap below the island, and a little beside it


def test_clustered_islands_give_a_grid_without_folds_round_every_kept_island():
    """34 folded cells on main; every island the layout keeps is a hole of the grid."""
    from meshcore.lakegrid import mesh_layout
    from meshcore.layout import auto_layout
    from meshcore.quality import lake_metrics

    lay = auto_layout(testing.island_clusters(966006, n_islands=120), target_cells=10_000, multiple=4)
    mb = mesh_layout(lay, levels=2)
    m = lake_metrics(mb, polygon=lay.polygon, cell_size=lay.cell_size)
    assert m.summary()["folded_cells"] == 0
    assert len(lay.polygon.interiors) >= 15
    assert all(k == 0 or depth <= 0.5 for k, _, depth, *_ in m.coverage.island_cells)
    assert not m.coverage.islands_covered  # no kept island under the grid
