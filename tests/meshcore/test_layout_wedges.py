"""Arms that taper to a point (``meshcore.testing.narrow_arms``): the block at a wedge's end has
two corners either side of its tip (:func:`meshcore.layout.corners.wedge_corners`), so that its
grid lines run along the wedge and converge on the tip.  With a corner at the tip and the fourth
on a side, the cells fanned out from the tip across the whole end block (every node beyond 3°).
``mesh_outline(..., layout_options=LayoutOptions(wedges=True))``: off by default (measured mixed,
docs/lake-grids-journal.md)."""

from __future__ import annotations

import numpy as np
import pytest

from meshcore import testing
from meshcore.lakegrid import mesh_outline
from meshcore.layout import LayoutOptions
from meshcore.layout.corners import wedge_corners
from meshcore.quality import lake_metrics


def test_a_wedge_tip_is_split_between_two_corners():
    # a strip 5 wide ending in a wedge of 30°, cut by a chord; its flanks turn by 1.4° at 1.5 from
    # the tip (on straight flanks the corners stay: test_layout_straight_corners.py)
    import shapely
    from shapely.geometry import Polygon

    poly = Polygon([(0, -2.5), (10, -2.5), (17.89, -0.42), (19.33, 0), (17.89, 0.42), (10, 2.5), (0, 2.5)])
    ring = np.asarray(shapely.segmentize(poly, 0.5).exterior.coords)[:-1]
    tip = int(np.argmax(ring[:, 0]))
    corners = sorted([0, int(np.argmin(np.hypot(*(ring - (10, -2.5)).T))), tip, len(ring) - 1])
    new = wedge_corners(ring, corners, 1.5, shore=np.ones(len(ring), bool))
    assert tip not in new and len(set(new)) == 4
    a, b = sorted(set(new) - {0, len(ring) - 1})  # the two corners either side of the tip
    assert a < tip < b
    # the end side spans about a cell (h = sigma / 1.5 = 1) and its corners are a cell or more from the tip
    assert np.hypot(*(ring[a] - ring[b])) == pytest.approx(1.0, abs=0.5)
    assert min(np.hypot(*(ring[a] - ring[tip])), np.hypot(*(ring[b] - ring[tip]))) >= 1.0
    # a star's centre (not on the shore) turns as much: left alone
    shore = np.ones(len(ring), bool)
    shore[tip] = False
    assert tuple(wedge_corners(ring, corners, 1.5, shore=shore)) == tuple(corners)


def test_narrow_arms_with_wedge_ends():
    """`narrow_arms(770000)` (arms 3-6 cells wide, 123 blocks): 88.8 % of the nodes within 3°
    without the option, 92.3 % with it (the option on by default then; its width limit since)."""
    poly = testing.narrow_arms(770000)
    mb = mesh_outline(poly, target_cells=15000, layout_options=LayoutOptions(wedges=True))
    s = lake_metrics(mb, polygon=poly).summary()
    assert s["folded_cells"] == 0
    assert s["pct_nodes_within_3deg"] >= 90.0
