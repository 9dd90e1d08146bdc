"""Islands a cell or two across: kept and followed, or left out with a note — never meshed over silently.

Shapes: :func:`meshcore.testing.small_islands` (islands 0.3–5 cells across: blobs, needles,
bent spikes, near the shore and each other), at a cell size ``h`` given to the layout.
"""

from __future__ import annotations

import re

import numpy as np
import pytest
from shapely.geometry import Polygon

from meshcore import testing
from meshcore.layout.polygon import water_polygon
from meshcore.quality import lake_metrics
from meshcore.quality.coverage import island_width

H = 0.25


def _islands(poly) -> list[Polygon]:
    return [Polygon(r) for r in poly.interiors]


@pytest.mark.parametrize("seed", range(6))
def test_small_islands_are_what_they_say(seed):
    poly = testing.small_islands(seed, cell_size=H, n_islands=8)
    assert poly.is_valid and len(poly.interiors) == 8
    assert testing.small_islands(seed, cell_size=H, n_islands=8).equals(poly)
    for isl in _islands(poly):
        w, _ = island_width(isl, 0.005 * H)
        assert 0.3 * H * 0.9 <= w <= 5.0 * H * 1.05
        assert isl.distance(poly.exterior) >= 0.25 * H


def test_island_width_is_the_widest_disc():
    from shapely.geometry import LineString, Point

    disc = Point(0, 0).buffer(1.0, quad_segs=64)
    assert island_width(disc, 1e-4)[0] == pytest.approx(2.0, rel=1e-3)
    needle = LineString([(0, 0), (10, 0)]).buffer(0.5, quad_segs=16)  # 1 wide, 11 long
    assert island_width(needle, 1e-4)[0] == pytest.approx(1.0, rel=1e-3)
    assert 4 * needle.area / needle.length > 1.8  # what the old rule read as its width


@pytest.mark.parametrize("seed", range(30))
def test_islands_narrower_than_two_cells_are_left_out_with_a_note_naming_them(seed):
    poly = testing.small_islands(seed, cell_size=H, n_islands=8)
    out, notes = water_polygon(poly, drop_islands_below=2 * H)
    widths = [island_width(isl, 0.02 * H)[0] for isl in _islands(poly)]
    dropped = [k + 1 for k, w in enumerate(widths) if w < 2 * H]
    assert len(out.interiors) == len(widths) - len(dropped)
    kept = _islands(out)
    for k, isl in enumerate(_islands(poly), start=1):
        assert (k not in dropped) == any(isl.equals(o) for o in kept)
    assert len(notes) == len(dropped)
    for k, note in zip(dropped, notes, strict=True):
        m = re.match(r"island (\d+) near \((\S+), (\S+)\) is (\S+) across at its widest \(area (\S+), ", note)
        assert m and int(m[1]) == k, note
        isl = _islands(poly)[k - 1]
        assert isl.contains(Polygon(isl.exterior).representative_point())
        assert isl.buffer(1e-4).contains(Polygon([(float(m[2]), float(m[3]))] * 3).centroid)  # the place is on it
        assert float(m[4]) == pytest.approx(widths[k - 1], rel=0.02)
        assert float(m[5]) == pytest.approx(isl.area, rel=5e-3)


def test_a_needle_narrower_than_two_cells_is_left_out_however_long():
    """A needle 1.2 cells wide and 11 long: no block side can turn round its ends (the old rule,
    4 · area / perimeter ≈ 2.2 cells, kept it and the grid covered its ends)."""
    from shapely.geometry import LineString, Point

    lake = Point(0, 0).buffer(10.0, quad_segs=32)
    needle = LineString([(-1.25, 0), (1.25, 0)]).buffer(0.6 * H, quad_segs=8)
    blob = Point(4, 4).buffer(1.5 * H, quad_segs=8)  # 3 cells across: kept
    out, notes = water_polygon(Polygon(lake.exterior, [needle.exterior, blob.exterior]), drop_islands_below=2 * H)
    assert len(out.interiors) == 1 and Polygon(out.interiors[0]).equals(blob)
    assert len(notes) == 1 and notes[0].startswith("island 1 near (")
    assert "a cell size of at most 0.15 would keep it" in notes[0]


# --------------------------------------------------------------- the quality report
def _ring_blocks():
    from tests.meshcore.test_lake_quality import ring_of_blocks

    return ring_of_blocks()


def test_the_report_names_an_island_under_the_grid_and_measures_the_shores_it_follows():
    blocks, poly = _ring_blocks()  # four blocks round the square [1, 2]² in [0, 3]²
    small = [(0.2, 0.2), (0.5, 0.2), (0.5, 0.3), (0.2, 0.3)]  # under block 0: 0.3 × 0.1
    c = lake_metrics(blocks, polygon=Polygon(poly.exterior, [poly.interiors[0], small])).coverage
    assert len(c.islands_covered) == 1
    isl = c.islands_covered[0]
    assert isl.index == 2 and isl.area == pytest.approx(0.03) and isl.width == pytest.approx(0.1, rel=0.02)
    assert isl.share == pytest.approx(1.0) and 0.2 < isl.x < 0.5 and 0.2 < isl.y < 0.3
    assert c.hausdorff == pytest.approx(0.0, abs=1e-12)  # shore and the square island: followed exactly
    assert c.as_dict()["islands_covered"] == 1
    rows = {r[0]: r for r in c.rows()}
    row = rows["islands under the grid"]
    assert row[1].startswith("1 (") and "island 2 (" in row[2]
    assert c.islands_lost == () and c.warnings() == []
    # without the small island: nothing to report
    c0 = lake_metrics(blocks, polygon=poly).coverage
    assert c0.islands_covered == () and c0.island_cells == () and len(c0.rows()) == 2


def test_an_island_two_cells_wide_under_the_grid_is_lost_and_measured():
    blocks, poly = _ring_blocks()  # cell size sqrt(8 / 64) = 0.354: two cells are 0.71
    wide = [(1.1, 0.1), (1.9, 0.1), (1.9, 0.9), (1.1, 0.9)]  # 0.8 across, under block 0
    c = lake_metrics(blocks, polygon=Polygon(poly.exterior, [poly.interiors[0], wide])).coverage
    (isl,) = c.islands_covered
    assert c.islands_lost == (isl,) and isl.index == 2 and isl.width == pytest.approx(0.8, rel=0.02)
    assert c.hausdorff == pytest.approx(0.5, abs=c.cell_size / 20)  # its middle is 0.5 from the grid's rims
    assert c.as_dict()["islands_lost"] == 1
    (w,) = c.warnings()
    assert w.startswith("island 2 (2.3 cells across") and "lost it" in w
    assert "1 lost" in next(r[1] for r in c.rows() if r[0] == "islands under the grid")


def test_the_report_counts_cells_over_an_island_the_grid_goes_round():
    blocks, poly = _ring_blocks()
    # the island drawn larger than the hole the grid leaves: a strip of it lies under block 0's cells
    bigger = [(1, 0.6), (2, 0.6), (2, 2), (1, 2)]
    c = lake_metrics(blocks, polygon=Polygon(poly.exterior, [bigger])).coverage
    assert c.islands_covered == ()
    (k, n, depth, x, y), *_ = c.island_cells
    assert k == 1 and n >= 1 and Polygon(bigger).contains(Polygon([(x, y)] * 3).centroid)
    assert depth * c.cell_size == pytest.approx(Polygon(bigger).exterior.distance(Polygon([(x, y)] * 3).centroid))
    assert c.as_dict()["cells_over_islands"] == sum(t[1] for t in c.island_cells)
    assert any(r[0] == "cells with their centre on land" and "island 1: " in r[2] for r in c.rows())
    assert c.hausdorff == pytest.approx(0.4, rel=1e-9)  # the island's rim lies 0.4 below the grid's
    assert any("inside its shore" in w for w in c.warnings())  # 0.275 = 0.78 cells deep
    assert [w for w in c.warnings() if "on island 1, up to" in w] == (
        [
            f"{n} cell(s) lie on island 1, up to {d:.2g} cells inside its shore near ({x:.6g}, {y:.6g}): "
            "the grid cuts across it there"
            for _, n, d, x, y in c.island_cells
            if d > 0.5
        ]
    )


# --------------------------------------------------------------- the pipeline
def _mesh(seed: int, regular: bool):
    from meshcore.lakegrid import mesh_layout
    from meshcore.layout import auto_layout

    poly = testing.small_islands(seed, cell_size=H, n_islands=8)
    lay = auto_layout(poly, cell_size=H, multiple=4, regular=regular)
    return poly, lay, mesh_layout(lay, levels=2)


@pytest.mark.slow
@pytest.mark.parametrize("regular", [False, True])
@pytest.mark.parametrize("seed", [0, 1, 2, 3, 4, 7])
def test_every_island_is_followed_or_reported(seed, regular):
    """Each island of the outline is either a hole of the grid or left out with a note naming it,
    and the quality report against the outline says the same."""
    poly, lay, mb = _mesh(seed, regular)
    m = lake_metrics(mb, polygon=poly, cell_size=H)
    c = m.coverage
    # each island left out has its own note, among the notes or (four or more: one summary note
    # among the notes) in the layout's details
    own = (*lay.notes, *lay.details)
    noted = {int(n.split()[1]) for n in own if n.startswith("island ") and "left out" in n}
    summary = [n for n in lay.notes if "islands are less than" in n and "left out" in n]
    assert len(summary) == (len(noted) >= 4)
    if summary:
        assert summary[0].startswith(f"{len(noted)} islands are less than")
    covered = {i.index for i in c.islands_covered}
    assert covered == noted
    for k, isl in enumerate(_islands(poly), start=1):
        w, _ = island_width(isl, 0.02 * H)
        assert (k in noted) == (w < 2 * H), (k, w / H)
    # every island kept is a hole of the layout's water, alone or joined with others less than three
    # cells away (a note names how many): one hole fewer for each island joined to another
    joined = sum(int(n.split()[0]) - 1 for n in lay.notes if " islands near (" in n and "joined into one island" in n)
    assert len(lay.polygon.interiors) == len(poly.interiors) - len(noted) - joined
    holes = [Polygon(r) for r in lay.polygon.interiors]
    for k, isl in enumerate(_islands(poly), start=1):
        if k not in noted:
            assert any(h.buffer(1e-6 * H).contains(isl) for h in holes), k
    rows = {r[0] for r in m.coverage.rows()}
    assert ("islands under the grid" in rows) == bool(noted)


def test_the_report_counts_cells_beyond_the_outer_shore():
    """A notch of land cut into the shore under block 0's cells (a peninsula the grid crossed)."""
    blocks, poly = _ring_blocks()
    shore = [(0, 0), (1.0, 0), (1.4, 0.8), (1.8, 0), (3, 0), (3, 3), (0, 3)]
    c = lake_metrics(blocks, polygon=Polygon(shore, [poly.interiors[0]])).coverage
    (k, n, depth, x, y), *rest = c.island_cells
    assert k == 0 and n >= 1 and not rest
    assert not Polygon(shore).contains(Polygon([(x, y)] * 3).centroid)
    assert depth * c.cell_size == pytest.approx(Polygon(shore).exterior.distance(Polygon([(x, y)] * 3).centroid))
    assert depth > 0 and c.warnings() == []  # in the table, not a warning (a jagged shore is smoothed on purpose)
    assert "beyond the outer shore: " in next(r[2] for r in c.rows() if r[0] == "cells with their centre on land")


def test_the_cli_warns_and_exits_3_when_the_grid_lost_an_island(tmp_path, monkeypatch):
    """A layout made without the island (as a grid that slid off it would be): the grid is
    written, the island named on stderr (even with -q), exit code 3."""
    from meshcore import layout as layout_module
    from tests.meshcore.test_mesh_cli import _synthetic_rings, mesh

    f = tmp_path / "lake.csv"
    shore, island = _synthetic_rings()
    rows = [f"{x:.3f},{y:.3f},shore" for x, y in shore] + [f"{x:.3f},{y:.3f},island" for x, y in island]
    f.write_text("x,y,ring\n" + "\n".join(rows) + "\n")
    real = layout_module.auto_layout

    def without_islands(poly, **kw):
        return real(Polygon(poly.exterior), **kw)

    monkeypatch.setattr(layout_module, "auto_layout", without_islands)
    run = mesh(f, "--cells", 400, "-o", tmp_path / "s.vtm", "-q")
    assert run.rc == 3, run.err
    lines = run.err.splitlines()
    assert any(ln.startswith("meshcore mesh: warning: island 1 (") and "lost it" in ln for ln in lines), run.err
    assert lines[-1] == "meshcore mesh: warning: 1 island(s) under the grid (exit code 3)"
    assert (tmp_path / "s.vtm").exists()
    monkeypatch.setattr(layout_module, "auto_layout", real)
    run = mesh(f, "--cells", 400, "-o", tmp_path / "t.vtm", "-q")
    assert run.rc == 0 and "warning" not in run.err, run.err


def test_a_thin_peninsula_smoothed_out_is_named():
    """A spike of land 0.3 cells wide and 4 long from the shore: the grid cannot follow it
    (narrower than half a cell); the note says where it is and how long."""
    from shapely.geometry import LineString, Point

    from meshcore.layout.polygon import without_slivers

    lake = Point(0, 0).buffer(10.0, quad_segs=32)
    spike = LineString([(0, -11), (0, -10 + 4 * H)]).buffer(0.15 * H, cap_style="flat")
    poly = Polygon(lake.difference(spike).exterior)
    out, (note,) = without_slivers(poly, 0.5 * H)
    m = re.search(r"the largest: land (\S+) long near \((\S+), (\S+)\)", note)
    assert m, note
    assert float(m[1]) == pytest.approx(4 * H, rel=0.1)
    assert abs(float(m[2])) < 0.15 * H and -10 < float(m[3]) < -10 + 4 * H
    assert out.area > poly.area  # the spike's land is water now
    # a shore with teeth only: no place named
    teeth = testing.jagged(Point(0, 0).buffer(10.0, quad_segs=32), 0.02 * H, seed=1)
    assert all("the largest" not in n for n in without_slivers(teeth, 0.5 * H)[1])


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(12))
def test_peninsulas_are_followed_or_named(seed):
    """small_islands with thin spikes of land from the shore: cells beyond the shore stay within
    half a cell of it, and a peninsula left out is named by place in a note."""
    from meshcore.lakegrid import mesh_layout
    from meshcore.layout import auto_layout

    poly = testing.small_islands(seed, cell_size=H, n_islands=4, peninsulas=5)
    lay = auto_layout(poly, cell_size=H, multiple=4)
    c = lake_metrics(mesh_layout(lay, levels=2), polygon=poly, cell_size=H).coverage
    beyond = [t for t in c.island_cells if t[0] == 0]
    assert all(d <= 0.6 for _, _, d, _, _ in beyond), beyond
    if c.hausdorff_cells > 1.0:  # the grid's shore is far from the outline somewhere: a note says where
        x, y = c.where
        places = [tuple(map(float, p)) for n in lay.notes for p in re.findall(r"near \((\S+), (\S+)\)", n)]
        assert any(np.hypot(x - px, y - py) < 6 * H for px, py in places), (c.where, lay.notes)


@pytest.mark.parametrize(("width", "left_out"), [(0.1, True), (1.0, False)])
def test_a_spike_of_land_narrower_than_half_a_cell_is_measured_apart(width, left_out):
    # a 10 x 10 lake gridded as a square (cell 0.5) with a spike of land 2 long from its bottom
    # shore: narrower than half a cell, the layout smooths it out (with a note) and the shore
    # distance leaves it out, the distance to the shore as given keeps it; wider, both keep it
    from meshcore import StructuredGrid

    w = width / 2
    poly = Polygon([(0, 0), (5 - w, 0), (5, 2), (5 + w, 0), (10, 0), (10, 10), (0, 10)])
    x, y = np.meshgrid(np.linspace(0, 10, 21), np.linspace(0, 10, 21), indexing="ij")
    cov = lake_metrics(StructuredGrid(x, y), polygon=poly).coverage
    assert cov.hausdorff_as_given / cov.cell_size == pytest.approx(4.0, rel=0.05)
    if left_out:
        assert cov.hausdorff_cells < 0.1
        assert any("spikes included" in r[0] for r in cov.rows())
    else:
        assert cov.hausdorff_cells == pytest.approx(4.0, rel=0.05)
        assert not any("spikes included" in r[0] for r in cov.rows())
