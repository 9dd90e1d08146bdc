"""Cuts that free an island (:func:`meshcore.layout.regions.partition`): two of them, never alongside
each other or alongside a chord that already reaches the island — the strip between two cuts a cell
apart is a sliver block, meshed with its chain's count of cells in a cell's area (fresh sweep
``round_lake(499400)``: 8 × 8 cells in 1.2 h², 3 folded cells)."""

from __future__ import annotations

import numpy as np
import pytest
from shapely.geometry import LineString, Point, Polygon, box

from meshcore import testing
from meshcore.layout import auto_layout, regions

H = 0.25  # the cell size of the unit cases
SIGMA = 1.5 * H  # the corners' scale the layout passes to partition


def _near_side(chord: bool):
    """A 10 × 10 lake (its shore sampled every cell, as the layout does) with a round island 0.6
    (2.4 cells) from its lower side, with or without a chord from its top to the upper side:
    from every point of the island the nearest shore is the lower side, so every nearest-point
    cut ends there, within a cell or two of the shortest."""
    import shapely

    island = Point(5.0, 1.3).buffer(0.7, quad_segs=16)
    poly = shapely.segmentize(Polygon(box(0.0, 0.0, 10.0, 10.0).exterior, [island.exterior]), H)
    cuts = [np.array([[5.0, 2.0], [5.0, 10.0]])] if chord else []
    return poly, cuts


def _areas(rings):
    return sorted(Polygon(r).area for r in rings)


@pytest.mark.parametrize("chord", [True, False])
def test_no_sliver_between_island_cuts(chord):
    poly, cuts = _near_side(chord)
    rings, all_cuts = regions.partition(poly, cuts, SIGMA)
    assert abs(sum(Polygon(r).area for r in rings) - poly.area) < 1e-9 * poly.area
    assert _areas(rings)[0] > 4 * SIGMA**2, _areas(rings)  # no strip a cell or two wide
    new = all_cuts[len(cuts) :]
    for i, a in enumerate(new):
        for b in [*cuts, *new[:i]]:
            assert LineString(a).hausdorff_distance(LineString(b)) >= 2 * SIGMA


# lakes whose islands lie near one side of a wide region, or beside a chord (fresh sweep seeds
# 499400 and more); layouts only
ISLAND_LAKES = [
    ("round_lake(499400, blob)", lambda: testing.round_lake(499400, kind="blob", n_islands=5)),
    *((f"round_lake({s}, blob)", lambda s=s: testing.round_lake(s, kind="blob", n_islands=5)) for s in (1000, 1004)),
    *((f"lake_with_islands({s})", lambda s=s: testing.lake_with_islands(s, n_islands=6 + s % 5)) for s in (1001, 1006)),
]


@pytest.mark.parametrize("name,make", ISLAND_LAKES, ids=[n for n, _ in ISLAND_LAKES])
def test_layouts_of_lakes_with_islands_have_no_sliver_blocks(name, make):
    """Every block at least 2 h² (3 cells each way of at least h/2 is 2.25 h²)."""
    lay = auto_layout(make(), target_cells=15000, multiple=4)
    h = lay.cell_size
    small = [(p.name, round(Polygon(p.ring).area / h**2, 2)) for p in lay.pieces if Polygon(p.ring).area < 2 * h * h]
    assert not small, small
