"""No block corner on a straight shore in regular layouts and wedge ends.

A block corner at a vertex of a straight edge gives a corner cell with a 180° angle: a triangle
(:data:`meshcore.quality.cells.STRAIGHT_SINE`), which no model grid wants.  Default layouts move
such corners (``layout.build._flat_corner_on_cut``); regular layouts (Delft3D ``.ddb``,
``--single``) re-choose corners to close every island's ring of blocks
(:func:`meshcore.layout.frames.close_frames`) and took vertices of straight edges beside a bend
(whose turning at the corners' scale they borrow); the ``wedges`` option put the two corners
beside a tip at a set distance along its flanks.  Now a moved corner goes where the shore turns
(a wedge's corner: if its flank turns near that distance).
"""

from __future__ import annotations

import numpy as np
import pytest

from meshcore import testing
from meshcore.layout import auto_layout
from meshcore.layout.corners import OWN_TURN, raw_turning, wedge_corners
from meshcore.layout.frames import frame_defects

shapely = pytest.importorskip("shapely")


def _straight_corners(lay) -> list[tuple[str, tuple[float, float]]]:
    """``(block, point)`` of every block corner at a shore vertex turning by less than
    :data:`OWN_TURN` with both ring neighbours on the shore."""
    shore = shapely.boundary(lay.polygon)
    eps = 1e-9 * shore.length
    found = []
    for pc in lay.pieces:
        ring = pc.ring
        for c in pc.corners:
            trio = ring[[c - 1, c, (c + 1) % len(ring)]]
            if max(shapely.distance(shapely.points(trio), shore)) < eps and raw_turning(ring)[c] < OWN_TURN:
                found.append((pc.name, tuple(ring[c].tolist())))
    return found


#: generated lakes with islands whose regular layouts at 10 000 cells closed their frames with
#: corners on straight island shores beside a cut's end or a bend (main at bb41a43: 2 each, a
#: cell of 180° each in the grid).  Not every such layout has another choice: (0) at 10 000 and
#: (5) at 2000 close only with theirs (docs/lake-grids-journal.md).
CASES = ["lake_with_islands(4)", "lake_with_islands(8)"]


@pytest.mark.parametrize("expr", CASES)
def test_regular_layouts_close_their_frames_without_corners_on_a_straight_shore(expr):
    poly = eval(f"testing.{expr}", {"testing": testing})
    lay = auto_layout(poly, target_cells=10_000, multiple=4, regular=True)
    assert not frame_defects(list(lay.pieces))
    assert _straight_corners(lay) == []


@pytest.mark.slow
def test_regular_grid_of_a_lake_with_islands_has_no_straight_corner_cells():
    # main at bb41a43: 2 cells with a straight corner (85.2 % of nodes within 3°); here 0 (93.7 %)
    from meshcore.lakegrid import mesh_outline
    from meshcore.quality import lake_metrics

    poly = testing.lake_with_islands(4)
    mb = mesh_outline(poly, target_cells=10_000, regular=True)
    s = lake_metrics(mb, polygon=poly).summary()
    assert s["straight_angle_cells"] == 0
    assert s["folded_cells"] == 0


def _wedge(bend: float):
    """A strip 5 wide ending in a wedge of 30° (its tip at x = 19.33), cut by a chord at x = 10,
    as a dense ring (vertices 0.5 apart); ``bend`` > 0: each flank has a vertex 1.5 from the tip
    pushed out by ``0.015 bend`` (``bend`` 2: a turn of 1.4° towards the water)."""
    from shapely.geometry import Polygon

    tip = np.array([19.33, 0.0])
    pts = [(0, -2.5), (10, -2.5)]
    for side in (-1, 1):
        flank = (np.array([10.0, 2.5 * side]) - tip) / np.hypot(9.33, 2.5)
        pts.append(tuple(tip + 1.5 * flank - bend * 0.015 * np.array([-flank[1], flank[0]]) * side))
        if side == -1:
            pts.append(tuple(tip))
    pts.append((10, 2.5))
    pts.append((0, 2.5))
    ring = np.asarray(shapely.segmentize(Polygon(pts), 0.5).exterior.coords)[:-1]
    t = int(np.argmax(ring[:, 0]))
    corners = sorted([0, int(np.argmin(np.hypot(*(ring - (10, -2.5)).T))), t, len(ring) - 1])
    return ring, corners, t


def test_wedge_corners_go_where_the_flanks_turn():
    # main: the vertices 1.5 from the tip along the flanks, wherever they are (here a vertex of
    # the dense ring a quarter from the flanks' bends, on a straight edge: cells of 180°)
    ring, corners, tip = _wedge(bend=2.0)
    new = wedge_corners(ring, corners, 1.5, shore=np.ones(len(ring), bool))
    assert tip not in new and len(set(new)) == 4
    raw = raw_turning(ring)
    a, b = sorted(set(new) - {0, len(ring) - 1})
    assert a < tip < b
    assert raw[a] >= OWN_TURN and raw[b] >= OWN_TURN
