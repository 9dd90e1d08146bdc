"""A chord ends on a sharp outline vertex, not a hair beside it (:func:`meshcore.layout.chords._snapped`).

A chord's ends are where two rays hit the shore; on an outline of a few points one can land a
hair from a corner (hand-drawn seed 6 at 4 000 cells: 0.02 m down a side from a 109° corner).
The block beside it then has a side piece of 0.02 m that turns as much as the corner: a cell edge
of 6e-5 cells and a fan of four cells from the corner.  Such an end now goes onto the vertex.
"""

from __future__ import annotations

import numpy as np
from shapely.geometry import Polygon

from meshcore.lakegrid import mesh_outline
from meshcore.layout.chords import SNAP, SNAP_TURN, _sharp_vertices, _snapped
from tests.meshcore.test_layout_flat_corners import _hand_drawn


def test_an_end_beside_a_sharp_vertex_goes_onto_it():
    water = Polygon([(0, 0), (10, 0), (10, 4), (0, 4)])
    corners = _sharp_vertices(water, SNAP_TURN)
    assert len(corners) == 4
    room = water.buffer(1e-9)
    got = _snapped(np.array([[10.0, 0.02], [0.0, 2.0]]), corners, room, 0.5)
    np.testing.assert_array_equal(got, [[10.0, 0.0], [0.0, 2.0]])  # the far end stays
    # left alone: an end farther than the tolerance, a vertex that hardly turns
    far = np.array([[10.0, 0.6], [0.0, 2.0]])
    np.testing.assert_array_equal(_snapped(far, corners, room, 0.5), far)
    bent = Polygon([(0, 0), (5, 0.05), (10, 0), (10, 4), (0, 4)])  # (5, 0.05): a 1° turn
    near = np.array([[5.0, 0.1], [5.0, 4.0]])
    np.testing.assert_array_equal(_snapped(near, _sharp_vertices(bent, SNAP_TURN), room, 0.5), near)


def test_hand_drawn_corner_has_no_sliver_cell():
    pts = _hand_drawn(6)
    pts = pts - np.round(pts.mean(axis=0), -3)
    mb = mesh_outline(pts, target_cells=4000)
    h = np.sqrt(Polygon(pts).area / 4000)
    shortest = min(min(np.hypot(np.diff(g.x, axis=k), np.diff(g.y, axis=k)).min() for k in (0, 1)) for g in mb.grids)
    assert shortest > 0.1 * h  # main: 6e-5 h, the 0.02 m side piece
    # every chord end is an outline vertex or farther than the tolerance from every sharp one
    from meshcore.layout import auto_layout

    lay = auto_layout(pts, target_cells=4000)
    sharp = _sharp_vertices(Polygon(pts), SNAP_TURN)
    for ch in lay.chords:
        for end in ch.points:
            d = np.hypot(*(sharp - end).T).min()
            assert d == 0.0 or d > SNAP * lay.cell_size - 1e-9 * h
