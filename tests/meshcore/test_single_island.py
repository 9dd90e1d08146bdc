"""A lake with one island always gets a single-domain layout (one ``(I, J)`` index space):
the fallback of :mod:`meshcore.layout.ringcuts` (four cut ends on the island) and of
:func:`meshcore.layout.build._closed` (new corners of any turning)."""

from __future__ import annotations

import numpy as np
import pytest
from shapely.geometry import Point

from meshcore import testing
from meshcore.algebraic import tfi
from meshcore.lakegrid import mesh_outline
from meshcore.layout import auto_layout
from meshcore.layout.frames import frame_defects
from meshcore.layout.ringcuts import ring_cuts
from meshcore.multiblock.indexspace import embed
from meshcore.quality.lake import block_metrics


def _fits_one_index_space(lay) -> None:
    assert not frame_defects(list(lay.pieces), single=True)
    topo = lay.topology()
    embed([tfi(b.borders) for b in topo.blocks], [b.name for b in topo.blocks])  # raises if it does not fit


# round_lake(0, 1, 4), lake_with_islands(8) with one island and the annulus round_lake(1, "ring")
# were refused before the fallback
# (session 28, 10 000 cells: their rings turned twice or half; islands near the shore with two
# or three cut ends); lake_with_islands(0) fitted already
@pytest.mark.slow
@pytest.mark.parametrize(
    "poly",
    [
        pytest.param(testing.round_lake(0, n_islands=1), id="round_lake(0)"),
        pytest.param(testing.round_lake(1, n_islands=1), id="round_lake(1)"),
        pytest.param(testing.round_lake(4, n_islands=1), id="round_lake(4)"),
        pytest.param(testing.lake_with_islands(8, n_islands=1), id="lake_with_islands(8)"),
        pytest.param(testing.lake_with_islands(0, n_islands=1), id="lake_with_islands(0)"),
        pytest.param(testing.round_lake(1, kind="ring"), id="ring(1)"),
    ],
)
def test_one_island_fits_one_index_space(poly):
    lay = auto_layout(poly, target_cells=10_000, multiple=4, single=True)
    assert len(poly.interiors) == 1
    _fits_one_index_space(lay)


@pytest.mark.slow
def test_annulus_gets_a_single_domain_grid():
    # a disc with one large island: refused before the fallback (no counts closed the two blocks)
    poly = testing.round_lake(0, kind="ring")
    mb = mesh_outline(poly, target_cells=2000, single=True)
    embed(list(mb.grids), [f"b{k}" for k in range(len(mb.grids))])  # the solved grid, in one index space
    assert sum(int(block_metrics(g).folded.sum()) for g in mb.grids) == 0
    assert len(mb.grids) >= 4  # a frame of blocks round the island, each cut end a corner of its hole


def test_ring_cuts_give_an_island_four_spread_ends():
    lake = Point(0, 0).buffer(10.0).difference(Point(0.5, 0).buffer(3.0))
    first = np.array([[3.5, 0.0], [10.0, 0.0]])  # one cut: an island one end short of a ring
    more = ring_cuts(lake, [first], sigma=0.5)
    assert len(more) == 3
    hole = lake.interiors[0]
    at = sorted(hole.project(Point(*c[0]), normalized=True) for c in [first, *more])
    gaps = np.diff([*at, at[0] + 1.0])
    assert gaps.min() > 0.1  # spread round the island, no two ends together
    for c in more:  # from the island into the water, to the outer shore
        assert hole.distance(Point(*c[0])) < 1e-6
        assert lake.exterior.distance(Point(*c[1])) < 1e-6


def test_ring_cuts_leave_an_island_with_four_ends_alone():
    lake = Point(0, 0).buffer(10.0).difference(Point(0, 0).buffer(3.0))
    ring = np.asarray(lake.interiors[0].coords)[:-1]
    starts = ring[:: len(ring) // 4][:4]  # four vertices of the island a quarter apart
    cuts = [np.array([p, p * 10.0 / 3.0]) for p in starts]
    assert ring_cuts(lake, cuts, sigma=0.5) == []
    assert len(ring_cuts(lake, cuts[:3], sigma=0.5)) == 1
