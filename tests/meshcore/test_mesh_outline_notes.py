"""``meshcore.mesh_outline`` hands the layout's notes to the caller (``grid.notes``), as the CLI prints them.

Shapes: a disc with an island narrower than two cells (left out by the layout, with a note naming
it) beside one wide enough to keep, and generated lakes of :func:`meshcore.testing.small_islands`.
"""

from __future__ import annotations

import pytest
from shapely.geometry import LineString, Point, Polygon

from meshcore import mesh_outline, testing
from meshcore.layout import auto_layout

H = 0.5


def _needle_lake() -> Polygon:
    lake = Point(0, 0).buffer(10.0, quad_segs=32)
    needle = LineString([(-2.5, 0), (2.5, 0)]).buffer(0.6 * H, quad_segs=8)  # 1.2 cells wide: left out
    blob = Point(4, 4).buffer(2.0 * H, quad_segs=8)  # 4 cells across: kept
    return Polygon(lake.exterior, [needle.exterior, blob.exterior])


def _shapes():
    yield "needle", _needle_lake()
    for seed in (1, 4):
        yield f"small_islands({seed})", testing.small_islands(seed, cell_size=H, n_islands=4)


@pytest.mark.parametrize(("name", "poly"), list(_shapes()), ids=[n for n, _ in _shapes()])
def test_mesh_outline_returns_the_layouts_notes(name, poly):
    lay = auto_layout(poly, cell_size=H, multiple=4)
    mb = mesh_outline(poly, cell_size=H)
    assert mb.notes == lay.notes
    left_out = [n for n in mb.notes if "left out" in n]
    assert len(left_out) == len(poly.interiors) - len(lay.polygon.interiors)
    if name == "needle":
        assert len(left_out) == 1 and left_out[0].startswith("island 1 near (")
    if mb.notes:
        assert f"{len(mb.notes)} layout note" in mb.info.message


def test_mesh_outline_without_notes_says_none():
    mb = mesh_outline(Point(0, 0).buffer(10.0, quad_segs=8), cell_size=1.0)
    assert mb.notes == () and "layout note" not in mb.info.message
