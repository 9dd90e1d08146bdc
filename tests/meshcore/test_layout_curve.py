"""The shore between an outline's points as a smooth curve (meshcore.layout.curve)."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from shapely.geometry import LineString, Point, Polygon

from meshcore.layout import LayoutOptions, auto_layout
from meshcore.layout.curve import BULGE, CORNER, curve_ring, curved_shore


def _polygon_ngon(n, radius=10.0, phase=0.0):
    t = phase + np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    return np.column_stack([radius * np.cos(t), radius * np.sin(t)])


def _vertex_positions(curve, ring):
    """Index in ``curve`` of every vertex of ``ring`` (in order), or fail."""
    out = []
    for v in ring:
        k = np.flatnonzero(np.all(curve == v, axis=1))
        assert len(k) == 1, f"vertex {v} not exactly once in the curve"
        out.append(int(k[0]))
    return out


def test_passes_through_every_vertex_in_order():
    ring = _polygon_ngon(9) * [1.0, 0.6]
    curve = curve_ring(ring, 1.0)
    pos = _vertex_positions(curve, ring)
    assert pos == sorted(pos) and pos[0] == 0
    assert len(curve) > 3 * len(ring)  # segments of ~4 cells sampled every half cell


def test_leaves_each_vertex_along_the_bisector_of_evenly_spaced_points():
    # a regular 24-gon of radius 100 (segments 26, sagitta 0.86) at h = 5: no bulge limit binds
    ring = _polygon_ngon(24, radius=100.0)
    curve = curve_ring(ring, 5.0)
    pos = _vertex_positions(curve, ring)
    for i in (0, 7, 13):
        v = ring[i]
        ahead = curve[pos[i] + 1] - v
        tangent = np.array([-v[1], v[0]]) / np.hypot(*v)  # the circle's direction at v
        cos = ahead @ tangent / np.hypot(*ahead)
        assert cos > np.cos(np.radians(1.0))  # the chord to the next sample: half of 15° / 11 off
    # and the curve is within 2 % of the circle's sagitta from the circle
    sagitta = 100 * (1 - np.cos(np.pi / 24))
    assert np.abs(np.hypot(*curve.T) - 100).max() < 0.1 * sagitta


def test_a_long_straight_side_beside_a_round_end_stays_straight():
    # a channel 40 long and 4 wide with round ends of 8 segments (a shapely buffer): its
    # straight sides are straight shore, not chords of a curve
    poly = LineString([(0, 0), (40, 0)]).buffer(2.0, quad_segs=4)
    ring = np.asarray(poly.exterior.coords)[:-1]
    curve = curve_ring(ring, 0.5)
    side = curve[(np.abs(curve[:, 1]) > 1.999) & (curve[:, 0] > 0.5) & (curve[:, 0] < 39.5)]
    assert len(side) > 100
    assert np.abs(np.abs(side[:, 1]) - 2.0).max() < 0.01 * 0.5  # a hundredth of a cell


def test_a_sparse_circle_gets_closer_to_the_circle():
    ring = _polygon_ngon(12, radius=10.0)  # segments 5.2 cells, turning 30°
    curve = curve_ring(ring, 1.0)
    mid = 0.5 * (ring + np.roll(ring, -1, axis=0))
    chord_error = np.abs(np.hypot(*mid.T) - 10.0).max()
    curve_error = np.abs(np.hypot(*curve.T) - 10.0).max()
    assert curve_error < 0.35 * chord_error


@pytest.mark.parametrize("h", [0.3, 1.0, 3.0])
def test_stays_within_the_bulge_of_its_chords(h):
    rng = np.random.default_rng(7)
    t = np.sort(rng.uniform(0, 2 * np.pi, 30))
    r = 20 + 4 * rng.uniform(-1, 1, 30)
    ring = np.column_stack([r * np.cos(t), r * np.sin(t)])
    curve = curve_ring(ring, h)
    pos = _vertex_positions(curve, ring) + [len(curve)]
    for i in range(len(ring)):
        seg = curve[pos[i] : pos[i + 1]]
        chord = LineString([ring[i], ring[(i + 1) % len(ring)]])
        d = max(chord.distance(Point(q)) for q in seg)
        assert d <= BULGE * h * (1 + 1e-9)


def test_corners_stay_sharp_and_straight_sides_straight():
    # a rectangle with one corner cut at 45°: every turn ≥ 45°; the 90° corners are corners,
    # and the sides between two corners are straight lines
    ring = np.array([[0, 0], [20, 0], [20, 6], [14, 12], [0, 12]], float)
    curve = curve_ring(ring, 1.0)
    pos = _vertex_positions(curve, ring)
    bottom = curve[pos[0] : pos[1]]
    assert np.allclose(bottom[:, 1], 0.0)  # between two 90° corners
    left = curve[pos[4] :]
    assert np.allclose(left[:, 0], 0.0)
    # the 45° turns at (20, 6) and (14, 12) are below CORNER: rounded, within the bulge
    assert CORNER > 45
    diagonal = curve[pos[2] : pos[3]]
    d, e = diagonal - ring[2], ring[3] - ring[2]
    assert not np.allclose(d[:, 0] * e[1] - d[:, 1] * e[0], 0.0)


def test_short_segments_stay_as_they_are():
    ring = _polygon_ngon(200, radius=10.0)  # segments 0.31 cells at h = 1
    assert curve_ring(ring, 1.0) is not None
    np.testing.assert_array_equal(curve_ring(ring, 1.0), ring)
    poly = Polygon(ring)
    assert curved_shore(poly, 1.0) == (poly, [])


def test_islands_that_would_touch_keep_their_segments():
    # an octagonal island (radius 10) whose flat bottom segment runs 0.1 cells above the
    # lake's straight bottom shore: its curve would bulge 0.25 cells down through the shore.
    # The island keeps its segments; the shore's top, drawn through a point 0.5 above its
    # corners' line, is still curved.
    c = -20 + 0.1 + 10 * np.cos(np.radians(22.5))
    island = _polygon_ngon(8, radius=10.0, phase=np.radians(22.5)) + [0.0, c]
    outer = np.array([[-20, -20], [20, -20], [20, 20], [0, 20.5], [-20, 20]], float)
    poly = Polygon(outer, [island])
    assert poly.is_valid
    assert not Polygon(curve_ring(outer, 1.0), [curve_ring(island, 1.0)]).is_valid
    new, notes = curved_shore(poly, 1.0)
    assert new.is_valid and len(new.interiors) == 1
    kept = np.asarray(new.interiors[0].coords)[:-1]
    assert len(kept) == len(island)
    assert Polygon(kept).equals(Polygon(island))
    assert len(new.exterior.coords) > len(outer) + 1
    assert notes and "islands kept as given" in notes[0]


@settings(max_examples=40, deadline=None)
@given(
    n=st.integers(5, 40),
    seed=st.integers(0, 10_000),
    h=st.floats(0.2, 3.0),
)
def test_random_rings_give_a_valid_polygon_near_the_outline(n, seed, h):
    rng = np.random.default_rng(seed)
    t = np.sort(rng.uniform(0, 2 * np.pi, n))
    t = t[np.diff(np.r_[t, t[0] + 2 * np.pi]) > 1e-3]
    if len(t) < 3:
        return
    r = 10 * (1 + 0.5 * rng.uniform(-1, 1, len(t)))
    poly = Polygon(np.column_stack([r * np.cos(t), r * np.sin(t)]))
    if not poly.is_valid:
        return
    new, notes = curved_shore(poly, h)
    assert new.is_valid
    # every point of the curve within the bulge of the outline, and back
    assert new.exterior.hausdorff_distance(poly.exterior) <= BULGE * h + 1e-9
    assert bool(notes) == (new is not poly)


def test_auto_layout_uses_it_when_asked():
    ring = _polygon_ngon(10, radius=10.0) * [3.0, 1.0]  # an ellipse drawn with 10 points
    on = auto_layout(ring, cell_size=0.5, options=LayoutOptions(curve=True))
    off = auto_layout(ring, cell_size=0.5)
    assert any("smooth curve" in n for n in on.notes)
    assert not any("smooth curve" in n for n in off.notes)
    assert len(on.polygon.exterior.coords) > len(off.polygon.exterior.coords)
    # the curved water is nearer the ellipse the points were taken from
    t = np.linspace(0, 2 * np.pi, 2000)
    ellipse = LineString(np.column_stack([30 * np.cos(t), 10 * np.sin(t)]))
    assert on.polygon.exterior.hausdorff_distance(ellipse) < off.polygon.exterior.hausdorff_distance(ellipse)


def test_layout_on_the_straight_segments_shore_on_the_curve(monkeypatch):
    # CURVE_ON_STRAIGHT (off by default): the blocks of the straight outline, their shore on the curve
    import meshcore.layout as layout

    ring = _polygon_ngon(10, radius=10.0) * [3.0, 1.0]
    off = auto_layout(ring, cell_size=0.5)
    monkeypatch.setattr(layout, "CURVE_ON_STRAIGHT", True)
    on = auto_layout(ring, cell_size=0.5, options=LayoutOptions(curve=True))
    assert any("smooth curve" in n for n in on.notes)
    assert len(on.blocks) == len(off.blocks)
    curved = Polygon(curve_ring(np.asarray(Polygon(ring).exterior.coords)[:-1], 0.5))
    pieces = [Polygon(pc.ring) for pc in on.pieces]
    assert all(p.is_valid for p in pieces)
    assert abs(sum(p.area for p in pieces) - curved.area) < 1e-6 * curved.area
    for a, b in zip(on.blocks, off.blocks, strict=True):  # corners within a quarter cell of the straight ones
        assert np.hypot(*(np.array(a.corners) - np.array(b.corners)).T).max() <= BULGE * 0.5 + 1e-9
