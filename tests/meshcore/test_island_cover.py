"""Islands the layout keeps are not covered by the grid.

A block side that runs round an island's convex side, short in cells for its length, is one
or two straight edges on the coarsest level: the coarse grid crosses the island and refinement
does not bring it back (:mod:`meshcore.multiblock.shorecells`).  The cell counts pay
:data:`~meshcore.multiblock.counts.LAND_WEIGHT` per cell such a side falls short of its least
count (:func:`~meshcore.multiblock.shorecells.over_island`).  Shapes: generated lakes with
islands on which the default grid lost an island before (an island 7 cells wide under a side
of 4 cells; islands 4.6 and 6 cells wide between a needle or the shore and a cut).
"""

from __future__ import annotations

import numpy as np
import pytest
from shapely.geometry import Point, Polygon
from shapely.ops import unary_union

from meshcore import testing
from meshcore.multiblock.counts import LAND_WEIGHT, LEAST_WEIGHT
from meshcore.multiblock.shorecells import islands_of, least_weights, over_island


def _half_circle(cx: float, r: float, n: int = 17) -> np.ndarray:
    a = np.linspace(np.pi, 0.0, n)
    return np.column_stack([cx + r * np.cos(a), r * np.sin(a)])


def test_a_side_round_an_island_is_over_it_and_a_bay_or_a_headland_is_not():
    # two blocks, above and below y = 0, round a disc island at the origin: the upper block's
    # bottom side bulges up round the island (its chord y = 0 crosses the island); a bay (the
    # side bulging away from the block) and a headland of the outer shore (land, but no island)
    # are not over an island
    upper, lower = _half_circle(0.0, 1.0), _half_circle(0.0, 1.0) * [1.0, -1.0]
    above = np.vstack([[-3.0, 0.0], upper, [3.0, 0.0], [3.0, 4.0], [-3.0, 4.0]])
    below = np.vstack([[-3.0, 0.0], [-3.0, -4.0], [3.0, -4.0], [3.0, 0.0], lower[::-1]])
    (island,) = islands_of([above, below])
    assert island.area == pytest.approx(Point(0, 0).buffer(1.0).area, rel=0.05)
    islands = unary_union([island])
    assert over_island(upper, islands) and over_island(lower, islands)
    bay = _half_circle(8.0, 1.0) * [1.0, -1.0]  # a block whose bottom side dips into a bay
    bay_block = np.vstack([[5.0, 0.0], bay, [11.0, 0.0], [11.0, 4.0], [5.0, 4.0]])
    headland = _half_circle(16.0, 1.0)  # a block whose bottom side runs round a headland
    head_block = np.vstack([[13.0, 0.0], headland, [19.0, 0.0], [19.0, 4.0], [13.0, 4.0]])
    regions = [above, below, bay_block, head_block]
    islands = unary_union(islands_of(regions))
    assert not over_island(bay, islands) and not over_island(headland, islands)
    straight = np.column_stack([np.linspace(-1, 1, 5), np.zeros(5)])
    assert not over_island(straight, islands)
    got = least_weights([upper, headland, upper], [True, True, False], regions)
    assert list(got) == [LAND_WEIGHT, LEAST_WEIGHT, LEAST_WEIGHT]


def _coarse_depth(lay, factor: int = 4) -> float:
    """How far, in cells, the coarsest level's blocks (every ``factor``-th border node joined by
    straight edges) reach into the layout's islands: the largest distance from an island's
    shore of a point of the island inside a coarse block (points 0.2 cells apart)."""
    import shapely

    h = lay.cell_size
    rings = []
    for b in lay.topology().blocks:
        bd = b.borders
        loop = np.vstack([bd.bottom[:-1], bd.right[:-1], bd.top[::-1][:-1], bd.left[::-1][:-1]])
        rings.append(shapely.make_valid(Polygon(loop[::factor])))
    blocks = shapely.union_all(rings)
    deepest = 0.0
    for ring in lay.polygon.interiors:
        isl = Polygon(ring)
        x0, y0, x1, y1 = isl.bounds
        gx, gy = np.meshgrid(np.arange(x0, x1, 0.2 * h), np.arange(y0, y1, 0.2 * h))
        x, y = gx.ravel(), gy.ravel()
        inside = shapely.contains_xy(isl, x, y) & shapely.contains_xy(blocks, x, y)
        if inside.any():
            d = shapely.distance(isl.exterior, shapely.points(x[inside], y[inside]))
            deepest = max(deepest, float(d.max()) / h)
    return deepest


COVERED_BEFORE = [  # the default layout at 15 000 cells before the weight: 3.6, 2.2 and 3.0 cells deep
    "lake_with_islands(263303, n_islands=9, lobes=7)",
    "small_islands(158851, n_islands=10)",
    "small_islands(911851, n_islands=10)",
]


@pytest.mark.parametrize("expr", COVERED_BEFORE)
def test_the_coarsest_blocks_go_round_every_island(expr):
    # 263303: a block side of 4 cells round 2.4 of an island 7 cells wide (26 cells, least 20):
    # one coarse edge, along the island's far side, and the block over all of it
    from meshcore.layout import auto_layout

    lay = auto_layout(eval(f"testing.{expr}", {"testing": testing}), target_cells=15000, multiple=4)
    assert _coarse_depth(lay) <= 1.5  # within a cell or so of the shore (SAG), as the least counts ask


# lakes whose default grid at 15 000 cells covered a kept island before the weight
# (shoreline distance 16, 3.4 and 4.7 cells), and three that never did
CASES = [
    "lake_with_islands(263303, n_islands=9, lobes=7)",
    "small_islands(158851, n_islands=10)",
    "small_islands(911851, n_islands=10)",
    "lake_with_islands(7302)",
    "small_islands(760003, n_islands=10)",
    "lake_with_islands(760301, n_islands=7, lobes=5)",
]


@pytest.mark.slow
@pytest.mark.parametrize("expr", CASES)
def test_no_kept_island_is_under_the_grid(expr):
    from meshcore.cellsize import default_cell_size
    from meshcore.lakegrid import mesh_outline
    from meshcore.layout.polygon import water_polygon
    from meshcore.quality import lake_metrics

    poly = eval(f"testing.{expr}", {"testing": testing})
    mb = mesh_outline(poly, target_cells=15000)
    h = default_cell_size(water_polygon(poly)[0].area, 15000)
    c = lake_metrics(mb, polygon=poly, cell_size=h).coverage
    assert not c.islands_lost, [i.describe(h) for i in c.islands_lost]
    deep = [(k, n, d) for k, n, d, _, _ in c.island_cells if k and d > 0.5]
    assert not deep, deep
    for k, ring in enumerate(poly.interiors, start=1):  # and the grid follows every kept island
        isl = Polygon(ring)
        if isl.buffer(-h).is_empty:  # left out (narrower than two cells)
            continue
        assert c.hausdorff_cells <= 1.0 or Point(c.where).distance(isl) > 2 * h, (k, c.hausdorff_cells, c.where)
