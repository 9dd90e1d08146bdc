"""Rivers, meanders and estuaries (:mod:`meshcore.testing.rivers`): the generators make what they
say, and lake grids of them are grids (or a clear error) with no folded cell, the shore within
half a cell and every block at least 3 cells each way."""

from __future__ import annotations

import math

import numpy as np
import pytest
from shapely.geometry import Polygon

from meshcore import mesh_outline, testing
from meshcore.cellsize import default_cell_size
from meshcore.errors import MeshcoreError
from meshcore.layout.polygon import water_polygon
from meshcore.quality import lake_metrics
from meshcore.testing import rivers


@pytest.mark.parametrize("seed", [3, 4])
def test_meander_is_what_it_says(seed):
    poly = testing.meander(seed)
    assert poly.is_valid and not poly.interiors and testing.meander(seed).equals(poly)
    # 20-80 widths long, width 0.7-1.3: the area in widths², one channel nowhere pinched
    assert 0.7 * 20 < poly.area < 1.3 * 80
    assert poly.buffer(-0.3).geom_type == "Polygon"
    # with ω = 110° the channel turns back on itself (loops nearly cut off) and no loop touches
    # another: the banks of different loops are half a width apart
    s, xy, theta, half, p = rivers._reach(np.random.default_rng(seed), 1.0, 40.0, 110.0, 0.3, 0.5, 1 / 16)
    th = np.unwrap(theta)
    assert np.degrees(th.max() - th.min()) > 180.0
    assert p.is_valid and rivers._fits(s, xy, theta, half, 0.5)


@pytest.mark.parametrize("n", [1, 2, 4])
def test_meander_bars_are_islands_along_the_flow(n):
    poly = testing.meander_bars(10 + n, n_bars=n)
    assert poly.is_valid and len(poly.interiors) == n
    for ring in poly.interiors:
        bar = Polygon(ring)
        assert bar.distance(poly.exterior) >= 0.04
        r = np.asarray(bar.minimum_rotated_rectangle.exterior.coords)
        sides = sorted(np.hypot(*np.diff(r[:3], axis=0).T))
        assert sides[1] > 2.0 * sides[0]  # elongated
        assert 0.25 <= sides[0] <= 0.6


def test_confluence_and_estuary_are_what_they_say():
    c = testing.confluence(5)
    assert c.is_valid and not c.interiors and testing.confluence(5).equals(c)
    e = testing.estuary(5, n_creeks=3)
    assert e.is_valid and not e.interiors
    # the mouth is 8-25 head widths wide: a disc of 3.5 widths fits there, and the head, the
    # creeks and the tributary are channels about a width wide
    assert not e.buffer(-3.5).is_empty
    assert e.buffer(-0.7).area < 0.8 * e.area


CASES = [("meander", 5), ("meander_bars", 6), ("confluence", 7), ("estuary", 8), ("estuary", 9)]


@pytest.mark.parametrize(("family", "seed"), CASES)
def test_river_grids_are_grids(family, seed):
    poly = getattr(testing, family)(seed)
    cells = 4000
    try:
        mb = mesh_outline(poly, target_cells=cells)
    except MeshcoreError:
        return  # a clear error is allowed
    h = default_cell_size(water_polygon(poly)[0].area, cells)
    s = lake_metrics(mb, polygon=poly, cell_size=h).summary()
    assert s["folded_cells"] == 0
    assert s["hausdorff_cells"] <= 0.5
    assert min(min(g.cells) for g in mb.grids) >= 3
    assert 0.3 < sum(math.prod(g.cells) for g in mb.grids) / cells < 2.0
