"""A cut that passes close by a land tip, bent through the tip (meshcore.layout.pinch), as a
candidate of the layout choice's tip draw (docs/lake-grids-journal.md, session 35)."""

import numpy as np
import pytest
import shapely
from shapely.geometry import Point, Polygon, box

from meshcore.layout import pinch
from meshcore.layout.pinch import Water, pinched
from meshcore.layout.split import _orient
from meshcore.layout.tipcuts import _tip

H = 0.4  # the cell size


def _c_and_neighbour():
    """A basin 10 × 10 with a land tongue 1 wide from its west shore, rounded at its tip (6, 5),
    cut at x = 7 (0.5 from the tip, 1.25 cells): the piece west of the cut is a C round the
    tip, the piece east of it a rectangle; both rings share the cut's points."""
    tongue = box(0, 4.5, 6, 5.5).union(Point(6, 5).buffer(0.5, 16))
    water = box(0, 0, 10, 10).difference(tongue)
    ys = np.arange(1.0, 10.0)
    return water, _with_cut(water.intersection(box(0, 0, 7, 10)), 7.0, ys), _with_cut(box(7, 0, 10, 10), 7.0, ys)


def _with_cut(poly, xc: float, ys: np.ndarray) -> np.ndarray:
    """The exterior ring of ``poly`` (the water on its left) with the points ``(xc, ys)`` along its
    side on the line x = ``xc``: the cut, the same points on both sides."""
    r = _orient(np.asarray(poly.exterior.coords)[:-1])
    out = []
    for k in range(len(r)):
        p, q = r[k], r[(k + 1) % len(r)]
        out.append(p)
        if p[0] == q[0] == xc:
            out += [(xc, y) for y in (ys if q[1] > p[1] else ys[::-1])]
    return np.array(out, dtype=float)


def test_a_cut_passing_close_by_a_tip_is_bent_through_it():
    water, c, east = _c_and_neighbour()
    rings, forced = pinched([c, east], [(), ()], Water(water, H), 1.5 * H, 3 * H)
    assert len(rings) == 3 and forced == [(), (), ()]
    polys = [Polygon(r) for r in rings]
    assert all(p.is_valid for p in polys)
    # the pieces tile the water; every one has the tongue's tip (6.5, 5) as a vertex
    assert sum(p.area for p in polys) == pytest.approx(water.area, rel=1e-9)
    assert shapely.union_all(polys).symmetric_difference(water).area < 1e-9 * water.area
    assert all(np.any(np.hypot(*(r - (6.5, 5.0)).T) < 1e-9) for r in rings)


def test_a_cut_far_from_any_tip_is_left_alone():
    water = box(0, 0, 10, 10)
    ys = np.arange(1.0, 10.0)
    west = np.array([(0, 0), (7, 0), *[(7, y) for y in ys], (7, 10), (0, 10)], dtype=float)
    east = np.array([(7, 0), (10, 0), (10, 10), (7, 10), *[(7, y) for y in ys[::-1]]], dtype=float)
    rings, _ = pinched([west, east], [(), ()], Water(water, H), 1.5 * H, 3 * H)
    assert len(rings) == 2


def _round_tongue(xc: float):
    """A basin 12 × 10 with a land tongue 6 wide from its west shore, ended by a half disc of
    radius 3 (its tip (8, 5)), cut at x = ``xc``: the piece west of the cut a C round the tongue,
    blunt at the channels' scale (no tip to :func:`~meshcore.layout.tipcuts._tip`)."""
    water = box(0, 0, 12, 10).difference(box(0, 2, 5, 8).union(Point(5, 5).buffer(3.0, 32)))
    ys = np.linspace(0.0, 10.0, 26)[1:-1]
    return water, _with_cut(water.intersection(box(0, 0, xc, 10)), xc, ys), _with_cut(box(xc, 0, 12, 10), xc, ys)


@pytest.mark.parametrize("gap", [0.1, 0.3])
def test_a_cut_grazing_a_blunt_tongue_is_bent_through_the_neck(gap):
    """Within a cell of the tongue (:data:`~meshcore.layout.pinch.NECK_CELLS`) the C is split at
    its neck: the cut runs to the tongue's nearest point and on (held-out g182250, session 44)."""
    water, c, east = _round_tongue(8.0 + gap)
    assert _tip(c, 1.5 * H) is None  # no tip: the neck is what bends the cut
    rings, forced = pinched([c, east], [(), ()], Water(water, H), 1.5 * H, 3 * H)
    assert len(rings) == 3 and forced == [(), (), ()]
    polys = [Polygon(r) for r in rings]
    assert all(p.is_valid for p in polys)
    assert shapely.union_all(polys).symmetric_difference(water).area < 1e-9 * water.area
    assert all(np.any(np.hypot(*(r - (8.0, 5.0)).T) < 0.05) for r in rings)  # the tongue's nearest point


@pytest.mark.parametrize("gap", [0.5, 1.0])
def test_a_cut_clear_of_a_blunt_tongue_is_left_alone(gap):
    water, c, east = _round_tongue(8.0 + gap)
    rings, _ = pinched([c, east], [(), ()], Water(water, H), 1.5 * H, 3 * H)
    assert len(rings) == 2


def test_necks_off_leaves_a_grazing_cut_alone(monkeypatch):
    monkeypatch.setattr(pinch, "NECK", False)
    water, c, east = _round_tongue(8.1)
    rings, _ = pinched([c, east], [(), ()], Water(water, H), 1.5 * H, 3 * H)
    assert len(rings) == 2


def _within_3(layout) -> float:
    from meshcore.lakegrid import mesh_layout
    from meshcore.quality import lake_metrics

    mb = mesh_layout(layout)
    s = lake_metrics(mb, polygon=layout.polygon, cell_size=layout.cell_size).summary()
    assert s["folded_cells"] == 0
    return s["pct_nodes_within_3deg"]


@pytest.mark.slow
def test_two_arms_joining_round_a_tongue_grid_better_with_the_cut_through_its_tip():
    """A basin 12 × 10 with a pointed tongue 1 wide from its south shore (tip (5, 6.8)): the arms
    either side of it join the basin round its tip.  Cut from (0, 8.5) to (12, 5.5), 1.1 cells
    from the tip, the southern block runs round the tip and its lines fan out of it;
    :func:`pinched` bends that cut through the tip, which leaves each arm a block with a corner on
    the tip and the basin's side passing it."""
    from shapely.geometry import Polygon as Poly

    from meshcore.layout.edit import layout_from_cuts

    tip = (5.0, 6.8)
    water = box(0, 0, 12, 10).difference(Poly([(4.5, 0), (5.5, 0), (5.5, 6), tip, (4.5, 6)]))
    straight = layout_from_cuts(water, [[(0.0, 8.5), (12.0, 5.5)]], cell_size=H, multiple=4)
    rings, _ = pinched([p.ring for p in straight.pieces], [(), ()], Water(water, H), 1.5 * H, 3 * H)
    assert len(rings) == 3
    assert all(np.any(np.hypot(*(r - tip).T) < 1e-9) for r in rings)
    bent = layout_from_cuts(water, [[(0.0, 8.5), tip], [tip, (12.0, 5.5)]], cell_size=H, multiple=4)
    assert len(straight.blocks) == 2 and len(bent.blocks) == 3
    before, after = _within_3(straight), _within_3(bent)
    assert before < 80.0 and after > 95.0, (before, after)


@pytest.mark.slow
def test_a_c_round_a_blunt_tongue_grids_better_cut_at_its_neck():
    """:func:`_round_tongue` cut 0.2 (half a cell) from the tongue: the C's grid squeezes through
    the neck; bent through the tongue's nearest point, each channel is a block of its own."""
    from meshcore.layout.edit import layout_from_cuts

    water, _, _ = _round_tongue(8.2)
    straight = layout_from_cuts(water, [[(8.2, 0.0), (8.2, 10.0)]], cell_size=H, multiple=4)
    rings, _ = pinched([p.ring for p in straight.pieces], [(), ()], Water(water, H), 1.5 * H, 3 * H)
    assert len(rings) == 3
    tip = (8.0, 5.0)
    bent = layout_from_cuts(water, [[(8.2, 0.0), tip], [tip, (8.2, 10.0)]], cell_size=H, multiple=4)
    before, after = _within_3(straight), _within_3(bent)
    assert before < 90.0 and after > 97.0, (before, after)


def test_necked_lines_split_a_chord_grazing_the_land_at_its_nearest_point():
    """The regular layouts' form (:func:`~meshcore.layout.pinch.necked_lines`): the chord across
    :func:`_round_tongue`'s channels 0.1 from the tongue becomes two, meeting on the tongue's end;
    one 1.0 from it stays whole."""
    from meshcore.layout.pinch import necked_lines

    water, _, _ = _round_tongue(8.1)
    dense = shapely.segmentize(water, H)
    near = np.array([(8.1, 0.0), (8.1, 10.0)])
    got = necked_lines([near], Water(dense, H), H, 2 * H)
    assert len(got) == 2
    assert np.allclose(got[0][0], near[0]) and np.allclose(got[1][-1], near[1])
    assert np.allclose(got[0][-1], got[1][0]) and np.hypot(*(got[0][-1] - (8.0, 5.0))) < 0.5 * H
    far = np.array([(9.0, 0.0), (9.0, 10.0)])
    assert len(necked_lines([far], Water(dense, H), H, 2 * H)) == 1


@pytest.mark.slow
@pytest.mark.parametrize("regular", [False, True])
def test_a_bay_chord_grazing_a_tongue_leaves_no_neck(regular):
    """Held-out g182250 (session 44; `tests/data/README.md`): at 10 000 cells the junction chord
    across its north-east bay runs on past a blunt tongue, 0.06 cells from it, to the far shore of
    the north arm; the block beyond held both lobes joined by that neck (82.6 % of nodes within 3°,
    an edge of 0.03 cells).  Default layouts bend the cut in the tip draw, regular ones split the
    chord."""
    from pathlib import Path

    from meshcore.cli.lakefile import local_frame
    from meshcore.io import read_points
    from meshcore.lakegrid import mesh_outline
    from meshcore.layout.polygon import water_from_points, water_polygon
    from meshcore.quality import lake_metrics

    f = Path(__file__).parents[1] / "data" / "gshhg_g182250.geojson"
    pts, _ = local_frame(read_points(f), "auto")
    outer, islands = water_from_points(pts)
    poly, _ = water_polygon(outer, holes=islands)
    mb = mesh_outline(poly, target_cells=10_000, regular=regular)
    s = lake_metrics(mb, polygon=poly, cell_size=(poly.area / 10_000) ** 0.5).summary()
    assert s["folded_cells"] == 0
    assert s["pct_nodes_within_3deg"] > 95.0 and s["min_edge_cells"] > 0.05, s
