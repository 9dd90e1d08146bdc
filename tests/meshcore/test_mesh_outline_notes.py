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
    # each island's own note, or (from SUMMARY_FROM on) one for all and each in the details
    left_out = [n for n in (*mb.notes, *lay.details) if "left out" in n and "islands are less than" not in n]
    assert len(left_out) == len(poly.interiors) - len(lay.polygon.interiors)
    if name == "needle":
        assert len(left_out) == 1 and left_out[0].startswith("island 1 near (")
    if mb.notes:
        assert f"{len(mb.notes)} layout note" in mb.info.message


def test_mesh_outline_without_notes_says_none():
    mb = mesh_outline(Point(0, 0).buffer(10.0, quad_segs=8), cell_size=1.0)
    assert mb.notes == () and "layout note" not in mb.info.message


def test_many_left_out_islands_are_one_note_with_the_details_kept():
    """From SUMMARY_FROM islands too narrow for the grid on, one note says how many, which is the
    largest and the cell size that keeps them all; each island's own note is in ``details``; at
    that cell size none is left out (a lake with dozens of islets read as dozens of lines)."""
    import re

    from meshcore.layout import auto_layout
    from meshcore.layout.polygon import MIN_ISLAND_CELLS, SUMMARY_FROM, water_polygon

    poly = testing.small_islands(861200, n_islands=10)
    lay = auto_layout(poly, cell_size=0.25)
    summary = [n for n in lay.notes if "islands are less than" in n]
    assert len(summary) == 1 and len(lay.details) >= SUMMARY_FROM
    assert not any(n in lay.notes for n in lay.details)
    assert summary[0].startswith(f"{len(lay.details)} islands")
    numbers = [int(re.match(r"island (\d+) ", d).group(1)) for d in lay.details]
    largest = int(re.search(r"the largest, island (\d+) ", summary[0]).group(1))
    assert largest in numbers
    keep = float(re.search(r"a cell size of at most ([0-9.e+-]+) would keep them all", summary[0]).group(1))
    # (widths are measured to 1 % of the two cells asked for, the cell size printed to 3 digits)
    _, notes = water_polygon(poly, drop_islands_below=MIN_ISLAND_CELLS * keep * 0.97)
    assert not any("too narrow for the grid to go round" in n for n in notes)
    _, notes = water_polygon(poly, drop_islands_below=MIN_ISLAND_CELLS * keep * 1.03)
    assert any("too narrow for the grid to go round" in n for n in notes)
