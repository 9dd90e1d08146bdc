"""No block side crowds its cells into a short piece of shore beside a cut's end
(:mod:`meshcore.layout.tipsplit`; the tests switch it on).

Where a cut ends at an island's tip and a block's side runs on past it along a short piece of
the island's shore, the counts gave that piece what the side's opposite asks for: on these
generated lakes the start grid's border edges at the tip were 10–20× apart (the block's grid
lines fanning into the tip).  The passing block is now split across from the cut's end, the
piece of shore a side of its own.  Measured on the start grids, as in ``test_layout_tips``:
at every block-border node on an island's tip, the two border edges meeting there.
"""

from __future__ import annotations

import numpy as np
import pytest
from shapely.geometry import Polygon

from meshcore import testing
from meshcore.layout import auto_layout, tipsplit
from tests.meshcore.test_layout_tips import JUMP, _worst_tip_jump, assert_tiles_the_water

#: Generated lakes whose layouts (without the split) had a block side with its border edges at
#: an island's tip 17.6×, 15.3×, 9.6× and 20.0× apart.
CASES = {
    "lake with islands 951001": lambda: testing.lake_with_islands(951001, n_islands=6),
    "lake with islands 987304": lambda: testing.lake_with_islands(987304, n_islands=10, lobes=8),
    "lake with islands 988302": lambda: testing.lake_with_islands(988302, n_islands=8, lobes=6),
    "lake with islands 988304": lambda: testing.lake_with_islands(988304, n_islands=10, lobes=8),
}


@pytest.fixture(scope="module", params=list(CASES))
def layout(request):
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(tipsplit, "SPLIT", True)
        return auto_layout(CASES[request.param](), target_cells=15000, multiple=4)


def test_no_fan_into_an_island_tip(layout):
    assert _worst_tip_jump(layout) <= JUMP


def test_no_side_left_crowded_where_a_split_can_be_made(layout):
    """Every crowded place left is one the split refuses (an unsound block, no counts)."""
    pieces, h = list(layout.pieces), layout.cell_size
    _, todo = tipsplit.crowded(pieces, h, layout.multiple)
    shortest = tipsplit.MIN_SHARE * max(3, layout.multiple) * h
    for _jump, pi, v, piece in todo:
        assert tipsplit._split(pieces, pi, v, piece, shortest) is None


def test_the_blocks_still_tile_the_water(layout):
    assert_tiles_the_water(layout)
    assert len({pc.name for pc in layout.pieces}) == len(layout.pieces)


def test_cells_agree_across_every_interface(layout):
    topo = layout.topology()  # raises when two blocks disagree on a shared chain's count
    assert len(topo.blocks) == len(layout.blocks)
    assert all(min(b.cells) >= 3 for b in layout.blocks)


def test_the_split_is_off_when_switched_off():
    poly = testing.lake_with_islands(951001, n_islands=6)
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(tipsplit, "SPLIT", False)
        off = auto_layout(poly, target_cells=15000, multiple=4)
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(tipsplit, "SPLIT", True)
        on = auto_layout(poly, target_cells=15000, multiple=4)
    assert len(on.blocks) > len(off.blocks)
    assert _worst_tip_jump(off) > JUMP  # the fan the split removes
    assert np.isclose(sum(Polygon(p.ring).area for p in on.pieces), off.polygon.area)
