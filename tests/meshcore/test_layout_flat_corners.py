"""No block corner on a straight shore (:func:`meshcore.layout.build._flat_corner_on_cut`).

A piece with three sharp corners (the pointed end of an arm beyond its tip chord, a corner zone
of a triangular lake) got its fourth corner on a side; on an outline drawn with few points the
side is a straight line, the corner cell a triangle with a 180° angle whose corner Jacobian is
zero up to rounding: ``meshcore mesh`` of a lon/lat triangle reported "1 folded cell" (exit code
3) at 10 000 cells, and 24 of 40 random hand-drawn polygons had such a cell.  The corner now goes
to the middle of the piece's cut, where the block beyond passes it and the solve opens it.
"""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from shapely.geometry import Polygon

from meshcore.lakegrid import mesh_outline
from meshcore.layout.build import _flat_corner_on_cut
from meshcore.quality.cells import cell_quality


def _hand_drawn(seed: int) -> np.ndarray:
    """A simple polygon of 3-9 points as a user clicks one (UTM-like metres, corners ≥ 25°)."""
    rng = np.random.default_rng(seed)
    while True:
        m = int(rng.integers(3, 10))
        ang = np.sort(rng.uniform(0, 2 * np.pi, m))
        r = rng.uniform(0.4, 1.0, m) * rng.uniform(1000, 8000)
        pts = np.c_[500_000 + r * np.cos(ang) * rng.uniform(0.5, 2), 5_200_000 + r * np.sin(ang)]
        p = Polygon(pts)
        if not p.is_valid or p.area < 1e5:
            continue
        a, b = np.roll(pts, 1, 0) - pts, np.roll(pts, -1, 0) - pts
        cos = (a * b).sum(1) / np.hypot(*a.T) / np.hypot(*b.T)
        if np.degrees(np.arccos(np.clip(cos, -1, 1))).min() >= 25:
            return pts


def _straight_angle_cells(mb) -> int:
    """Cells with a corner of 179° or more: a corner Jacobian below sin 1° of the cell's largest."""
    n = 0
    for g in mb.grids:
        cj = cell_quality(g)["corner_jacobians"]
        n += int((cj.min(axis=0) < np.sin(np.radians(1.0)) * np.abs(cj).max(axis=0)).sum())
    return n


def test_a_flat_corner_moves_to_the_middle_of_the_cut():
    # the pointed end of an arm: a chord from (0, 0) to (0, 4) (not shore), straight shores to the
    # tip at (6, 2); the fourth corner was put on the straight shore at (3, 1)
    poly = shapely.segmentize(Polygon([(0, 0), (6, 2), (0, 4)]), 0.5)
    ring = np.asarray(poly.exterior.coords)[:-1]
    if shapely.LinearRing(ring).is_ccw is False:
        ring = ring[::-1]
    on_shore = ring[:, 0] > 1e-9

    def at(p):
        return int(np.argmin(np.hypot(*(ring - p).T)))

    corners = sorted([at((0, 0)), at((6, 2)), at((0, 4)), at((3, 1))])
    new = _flat_corner_on_cut(ring, corners, on_shore, (), 0.5)
    assert len(new) == 4 and at((3, 1)) not in new
    moved = ring[sorted(set(new) - set(corners))[0]]
    np.testing.assert_allclose(moved, (0, 2), atol=0.26)  # the chord's middle vertex
    # left alone: a forced flat corner, a piece without a cut, no flat corner
    assert tuple(_flat_corner_on_cut(ring, corners, on_shore, (at((3, 1)),), 0.5)) == tuple(corners)
    assert tuple(_flat_corner_on_cut(ring, corners, np.ones(len(ring), bool), (), 0.5)) == tuple(corners)
    square = sorted([at((0, 0)), at((6, 2)), at((0, 4)), at((0, 2))])
    assert tuple(_flat_corner_on_cut(ring, square, on_shore, (), 0.5)) == tuple(square)


@pytest.mark.parametrize("seed", [0, 9, 11, 14])
def test_hand_drawn_polygons_have_no_straight_angle_cells(seed):
    pts = _hand_drawn(seed)
    pts = pts - np.round(pts.mean(axis=0), -3)
    mb = mesh_outline(pts, target_cells=4000)
    assert _straight_angle_cells(mb) == 0


def test_lonlat_triangle_meshes_without_folded_cells(tmp_path):
    """The lake a new user clicked near Zurich: three points, 10 000 cells."""
    import subprocess
    import sys

    f = tmp_path / "tri.csv"
    f.write_text("lon,lat\n8.50,47.30\n8.56,47.30\n8.53,47.34\n")
    out = tmp_path / "tri.vtm"
    r = subprocess.run(
        [sys.executable, "-m", "meshcore", "mesh", str(f), "--cells", "10000", "-o", str(out)],
        capture_output=True,
        text=True,
    )
    assert r.returncode == 0, r.stderr[-2000:]
    assert "folded" not in r.stderr.split("quality:")[-1].split("\n")[0] or "0 folded" in r.stderr
    assert out.exists()


def _ring_of(points, step):
    ring = np.asarray(shapely.segmentize(Polygon(points), step).exterior.coords)[:-1]
    return ring if shapely.LinearRing(ring).is_ccw else ring[::-1]


def test_a_flat_corner_beside_a_blunt_end_vertex_moves_onto_it():
    # an arm's blunt end drawn with two vertices, B = (4, 0) and A = (4.3, 2); the chord from
    # (0, 2) to (0, 0) is the cut; the fourth corner was put halfway along the end (M, flat):
    # a cell of 180° there (held-out set 12, g180626); B turns ~80° a cell away and takes it
    ring = _ring_of([(0, 0), (4, 0), (4.15, 1.0), (4.3, 2), (0, 2)], 0.5)
    on_shore = ring[:, 0] > 1e-9

    def at(p):
        return int(np.argmin(np.hypot(*(ring - p).T)))

    corners = sorted([at((0, 0)), at((0, 2)), at((4.3, 2)), at((4.15, 1.0))])
    new = _flat_corner_on_cut(ring, corners, on_shore, (), 1.5)
    assert sorted(new) == sorted([at((0, 0)), at((0, 2)), at((4.3, 2)), at((4, 0))])
    # at cells of 0.5 B is two cells away and the end straight for a cell either side of M: M
    # goes onto the cut's middle, as on any straight shore
    new = _flat_corner_on_cut(ring, corners, on_shore, (), 0.5)
    assert sorted(new) == sorted([at((0, 0)), at((0, 2)), at((4.3, 2)), at((0, 1))])


def test_a_flat_corner_beside_a_reflex_bump_moves_onto_the_cut():
    # the pointed end of an arm (chord (0, 0)-(0, 4), tip (6, 2)) whose lower shore has a bump of
    # land at (3.6, 1.6) (reflex for the water): the fourth corner on the straight shore between
    # the bump and the tip, less than a cell from the bump, has a corner cell beyond 180° whatever
    # the grid (held-out g180765's tip block): onto the cut with it
    ring = _ring_of([(0, 0), (3.6, 1.6), (6, 2), (0, 4)], 0.5)
    on_shore = ring[:, 0] > 1e-9

    def at(p):
        return int(np.argmin(np.hypot(*(ring - p).T)))

    flat = at((4.2, 1.7))
    assert abs(np.hypot(*(ring[flat] - (4.2, 1.7)))) < 0.2
    corners = sorted([at((0, 0)), at((6, 2)), at((0, 4)), flat])
    new = _flat_corner_on_cut(ring, corners, on_shore, (), 1.0)
    assert flat not in new and len(new) == 4
    np.testing.assert_allclose(ring[sorted(set(new) - set(corners))[0]], (0, 2), atol=0.26)


def test_no_layout_corner_on_a_straight_shore_of_a_coarse_outline():
    """A dendritic lake drawn with 200 points: one piece had its corner on a straight shore edge
    between two shore vertices (turning 0°, both sides shore): a corner cell of 180°."""
    from meshcore import testing
    from meshcore.layout import auto_layout
    from meshcore.layout.corners import raw_turning

    lay = auto_layout(testing.resampled(testing.dendritic(2700), points=200), target_cells=15000, multiple=4)
    shore = lay.polygon.boundary
    eps = 1e-6 * lay.cell_size
    flat = []
    for p in lay.pieces:
        r = np.asarray(p.ring)
        raw = raw_turning(r)
        on = shapely.distance(shore, shapely.points(r)) < eps
        n = len(r)
        flat += [(p.name, c) for c in p.corners if on[c] and on[c - 1] and on[(c + 1) % n] and abs(raw[c]) < 1.0]
    assert flat == []


def test_the_shore_fit_does_not_slide_a_block_corner_onto_a_straight_edge():
    """``estuary(8)`` at 4 000 cells: the shore fit (`fit_ends`) moved a one-cell block corner from
    its 90° bend past a notch of the shore onto a straight edge, where the coarse level's edges
    followed the shore best; on the finest level its corner cell was a triangle."""
    from meshcore import testing
    from meshcore.quality import lake_metrics

    poly = testing.estuary(8)
    s = lake_metrics(mesh_outline(poly, target_cells=4000), polygon=poly).summary()
    assert s["straight_angle_cells"] == 0
    assert s["folded_cells"] == 0
