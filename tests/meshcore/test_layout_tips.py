"""No block fans into an island's tip: the cells along a block side at a cut's end on an island's
tip stay alike on both sides of it (:mod:`meshcore.layout.tipends`, an option that is off:
:data:`~meshcore.layout.tipends.SLIDE`; the tests switch it on).

Where a cut ends at an island's tip and a block's side passes it (the cut and a few cells of the
island's shore in a row, up to the block's corner where another cut ends), the counts gave the
short piece of shore what the side's opposite asks for: 17–22× the cut's spacing on these
generated lakes.  Measured on the start grids of the layouts' topology, independently of how the
layout finds such places: at every block-border node on an island's tip (the water round it
spans ≥ 250°), the two border edges meeting there.
"""

from __future__ import annotations

import numpy as np
import pytest
from shapely.geometry import Polygon
from shapely.geometry.polygon import orient

from meshcore import testing
from meshcore.grid import BORDER_NAMES
from meshcore.layout import auto_layout, tipends
from meshcore.multiblock import initial_grids

#: Generated lakes whose layouts had a block side passing an island's tip with its border edges
#: 17.6× and 21.6× apart there (before the cut ends were slid onto the tips).
CASES = {
    "lake with islands 951001": lambda: testing.lake_with_islands(951001, n_islands=6),
    "small islands 951005": lambda: testing.small_islands(951005, n_islands=8),
}

#: The largest ratio of the two border edges at an island's tip (a grid line bunching into a tip
#: from a side that spaces its cells evenly elsewhere shows as one edge many times the other).
JUMP = 8.0


def _tips(poly) -> np.ndarray:
    """Vertices of the islands where the water round them spans at least 250°."""
    out = [np.zeros((0, 2))]
    for ring in orient(poly, 1.0).interiors:  # water on the left
        r = np.asarray(ring.coords)[:-1]
        a = r - np.roll(r, 1, axis=0)
        b = np.roll(r, -1, axis=0) - r
        turn = np.degrees(np.arctan2(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0], (a * b).sum(axis=1)))
        out.append(r[180.0 - turn >= 250.0])
    return np.vstack(out)


def _worst_tip_jump(lay) -> float:
    tips = _tips(lay.polygon)
    worst = 1.0
    for g in initial_grids(lay.topology()):
        for side in BORDER_NAMES:
            e = np.asarray(g.border(side))
            L = np.hypot(*np.diff(e, axis=0).T)
            for k in range(1, len(e) - 1):  # border nodes between two edges
                if len(tips) and np.min(np.hypot(*(tips - e[k]).T)) < 1e-6 * lay.cell_size:
                    worst = max(worst, L[k - 1] / L[k], L[k] / L[k - 1])
    return worst


@pytest.fixture(scope="module", params=list(CASES))
def layout(request):
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(tipends, "SLIDE", True)
        return auto_layout(CASES[request.param](), target_cells=15000, multiple=4)


def test_no_fan_into_an_island_tip(layout):
    assert _worst_tip_jump(layout) <= JUMP


def assert_tiles_the_water(layout) -> None:
    """Every block a valid counter-clockwise four-cornered piece, together the water's area."""
    total = 0.0
    for pc in layout.pieces:
        P = Polygon(pc.ring)
        assert P.is_valid and P.exterior.is_ccw
        assert len(set(pc.corners)) == 4
        total += P.area
    assert total == pytest.approx(layout.polygon.area, rel=1e-9)


def test_the_blocks_still_tile_the_water(layout):
    assert_tiles_the_water(layout)


def test_a_layout_without_the_pattern_is_left_as_it_is():
    lay = auto_layout(testing.channel_network(23031, n_branches=4), target_cells=4000, multiple=4)
    pieces = list(lay.pieces)
    assert tipends.slide_tip_ends(pieces, lay.cell_size) is pieces  # no islands: no tips
