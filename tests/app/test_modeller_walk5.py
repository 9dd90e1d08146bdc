"""What a fifth modeller's walk through the app (session 21, under Xvfb) found, each as it went
wrong, on generated shapes: water in several parts first (a reservoir split by a causeway)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
import shapely
from PySide6 import QtCore

from tests.app.drawing import drag_shore_end_round

pytestmark = pytest.mark.gui


def _ellipse(cx: float, cy: float, rx: float, ry: float, n: int = 48) -> list:
    ring = [[cx + rx * math.cos(2 * math.pi * k / n), cy + ry * math.sin(2 * math.pi * k / n)] for k in range(n)]
    return [*ring, ring[0]]


def _reservoir(tmp_path, fmt: str = "kml"):
    """A reservoir split by a causeway, in lon/lat: a larger upper basin with an island and a
    smaller lower basin; as one KML of two placemarks or one GeoJSON MultiPolygon."""
    upper = _ellipse(10.0, 46.02, 0.03, 0.012)
    island = _ellipse(10.005, 46.021, 0.004, 0.002, 24)[::-1]
    lower = _ellipse(10.01, 45.995, 0.018, 0.009)
    if fmt == "geojson":
        geom = {"type": "MultiPolygon", "coordinates": [[upper, island], [lower]]}
        feat = {"type": "Feature", "properties": {"name": "Causeway"}, "geometry": geom}
        path = tmp_path / "reservoir.geojson"
        path.write_text(json.dumps({"type": "FeatureCollection", "features": [feat]}))
        return path

    def ring(r):
        return " ".join(f"{x},{y},0" for x, y in r)

    def placemark(name, outer, holes=()):
        inner = "".join(
            f"<innerBoundaryIs><LinearRing><coordinates>{ring(h)}</coordinates></LinearRing></innerBoundaryIs>"
            for h in holes
        )
        return (
            f"<Placemark><name>{name}</name><Polygon><outerBoundaryIs><LinearRing><coordinates>{ring(outer)}"
            f"</coordinates></LinearRing></outerBoundaryIs>{inner}</Polygon></Placemark>"
        )

    path = tmp_path / "reservoir.kml"
    path.write_text(
        '<?xml version="1.0" encoding="UTF-8"?><kml xmlns="http://www.opengis.net/kml/2.2"><Document>'
        f"{placemark('Lower basin', lower)}{placemark('Upper basin', upper, [island])}</Document></kml>"
    )
    return path


def pick_part(row: int, asked: list[int]):
    """A stand-in for the parts dialog's ``exec``: notes how many parts it listed, picks ``row``."""
    from app.parts_dialog import PartsDialog

    def pick(dlg):
        asked.append(dlg.table.rowCount())
        dlg.table.selectRow(row)
        return PartsDialog.DialogCode.Accepted

    return pick


def test_the_parts_dialog_lists_every_part_by_name_and_area_largest_first(qtbot, tmp_path):
    """A file of two parts of water: the dialog's table has a row per part, numbered as
    ``meshcore mesh --part`` numbers them (largest first), with its name, water area in km² and
    islands; the largest is chosen at first, another by selecting its row."""
    from app.lake import read_lake_parts
    from app.parts_dialog import PartsDialog
    from meshcore.io import read_points

    parts, _frame, _ = read_lake_parts(read_points(_reservoir(tmp_path)), lonlat=True)
    dlg = PartsDialog("reservoir.kml", parts)
    qtbot.addWidget(dlg)
    t = dlg.table
    rows = [[t.item(r, c).text() for c in range(t.columnCount())] for r in range(t.rowCount())]
    assert [r[:2] for r in rows] == [["1", "Upper basin"], ["2", "Lower basin"]]
    assert [r[3] for r in rows] == ["1", "0"]  # the island is the upper basin's
    areas = [float(r[2].split()[0]) for r in rows]
    assert all(r[2].endswith("km²") for r in rows) and areas[0] > areas[1] > 0.5
    assert dlg.chosen() == 1
    t.selectRow(1)
    assert dlg.chosen() == 2


@pytest.mark.parametrize("fmt", ["kml", "geojson"])
def test_importing_water_in_two_parts_asks_which_part_and_opens_it(qtbot, win, tmp_path, monkeypatch, fmt):
    """Was: the app imported the largest part and said in Messages which were left out; the lower
    basin could not be opened at all.  Now a dialog lists the parts and the one chosen is the
    project's lake (its shore, no island), titled as ``meshcore mesh --case`` names its case
    (``reservoir_part2``); one undo step takes it back, and Cancel imports nothing."""
    from app.parts_dialog import PartsDialog

    path = _reservoir(tmp_path, fmt)
    asked: list[int] = []
    monkeypatch.setattr(PartsDialog, "exec", pick_part(1, asked))
    said = []
    win.doc.reported.connect(lambda level, text: said.append(text))
    win.quiet = False
    before = win.doc.project
    assert win.io.import_points(path, project_lonlat=True)
    assert asked == [2]
    lake = win.doc.project.lake
    assert lake is not None and len(lake.holes) == 0  # the lower basin: the island is the upper's
    area = shapely.Polygon(lake.outline).area  # pi * 1.39 km * 1.00 km: 4.4 km² (the upper 9.7)
    assert 3.5e6 < area < 5.5e6
    assert win.doc.project.title == "reservoir_part2"
    assert any("so part 2 (" in t and "part 1 (" in t and "is left out" in t for t in said), said
    win.stack.undo()
    assert win.doc.project is before or win.doc.project.lake is None
    win.quiet = True  # no more modal questions (the Auto layout offer for the island below)

    # the largest part by asking for part 1; Cancel leaves the project as it is
    assert win.io.import_points(path, project_lonlat=True, part=1)
    assert len(win.doc.project.lake.holes) == 1
    upper = win.doc.project
    monkeypatch.setattr(PartsDialog, "exec", lambda dlg: PartsDialog.DialogCode.Rejected)
    win.quiet = False
    try:
        assert not win.io.import_points(path, project_lonlat=True)
    finally:
        win.quiet = True  # Close must not ask to save
    assert win.doc.project is upper
    assert np.isfinite(win.doc.project.lake.outline).all()


def _laid_out_project(seed: int, cell_size=None):
    """A generated lake with islands (metres) laid out at ``cell_size`` (None: auto), no grid."""
    from app.lake import Lake, compute_layout, with_layout
    from app.project import Project
    from meshcore import testing

    poly = shapely.affinity.scale(testing.lake_with_islands(seed), 300, 300, origin=(0, 0))
    lake = Lake(
        outline=np.asarray(poly.exterior.coords)[:-1],
        holes=tuple(np.asarray(r.coords)[:-1] for r in poly.interiors),
        cell_size=cell_size,
    )
    return with_layout(Project(title="walk5"), lake.replaced(layout=compute_layout(lake)))


@pytest.mark.parametrize("cell_size", [None, 61.0])
def test_a_reopened_project_keeps_the_cell_size_auto(qtbot, win, tmp_path, cell_size):
    """A lake laid out with the cell size "auto (≈10 000 cells)", saved and opened again: the
    Lake panel said "32.3 m" (the layout's size, all a case file holds), so a shore dragged
    or an island added after kept that size instead of following the water.  Now a size that
    is the water's automatic one comes back as auto; a size the user typed stays typed."""
    from app.io_adapter import save_project
    from app.views.lake_panel import AUTO_TEXT

    if win.solver.auto:
        win.a_auto.trigger()  # no solve needed: the panel and the lake are what is looked at
    path = tmp_path / "walk5.toml"
    save_project(_laid_out_project(850_011, cell_size), path)
    assert win.io.open_path(path)
    lake = win.doc.project.lake
    assert lake is not None and lake.layout is not None
    assert lake.cell_size == cell_size
    win.show_lake()
    text = win.lake_panel.cell_size.text()
    assert (text == AUTO_TEXT) == (cell_size is None), text


def test_one_click_on_a_failed_limit_goes_to_its_worst_place(qtbot, win, tmp_path):
    """A new user clicked a failed limit of the verdict once: orange dots appeared somewhere, the
    view stayed; going to the worst place needed a double-click nobody guessed.  One click goes
    there now (the window zooms to it, its block active); a new verdict selecting its first failed
    limit by itself does not move the view."""
    from tests.app.test_modeller import _laid_out

    _laid_out(qtbot, win, tmp_path, 850_021)
    box = win.lake_quality
    v = box.verdict
    assert v is not None
    rows = [k for k, r in enumerate(v.results) if r.passed is False and r.worst]
    assert rows  # a coarse grid (20 cells to the square root of the area) misses delft3d's limits
    sent = []
    box.go_to.connect(lambda where, what: sent.append((where, what)))
    win.doc.quality_changed.emit()  # a verdict again: the first failed limit selected, no move
    assert sent == []
    rect = box.table.visualRect(box.table.model().index(rows[-1], 2))
    qtbot.mouseClick(box.table.viewport(), QtCore.Qt.MouseButton.LeftButton, pos=rect.center())
    assert len(sent) == 1 and sent[0][1] == v.results[rows[-1]].limit.label
    names = [b.name for b in win.doc.project.blocks]
    assert win.doc.active == names.index(sent[0][0].block)


def test_the_grid_of_before_stays_greyed_when_a_drag_gives_blocks_new_cells(qtbot, win):
    """Auto-generate off, a cut end of a ring lake dragged 40° round: at the drag's end the cells of
    the stretched blocks follow the cell size, and the grid on screen vanished (the document drops
    grids whose blocks changed cells) — the user had nothing to compare the new layout with.  The
    grid of before stays drawn, greyed, until F5 makes the new one; an export still refuses it."""
    from app.lake import Lake, compute_layout
    from meshcore import testing
    from tests.app.waits import wait_for, wait_idle

    poly = testing.round_lake(850_031, kind="ring", radius=2000.0)
    lake = Lake(
        outline=np.asarray(poly.exterior.coords)[:-1],
        holes=tuple(np.asarray(r.coords)[:-1] for r in poly.interiors),
        target_cells=3000,
    )
    win.editor.set_lake(lake.replaced(layout=compute_layout(lake)), "Auto layout")
    assert not win.solver.auto
    win.a_generate.trigger()
    wait_for(qtbot, win, lambda: bool(win.doc.grids) and not win.doc.solving and not win.doc.stale)
    wait_idle(qtbot, win)
    lay0 = win.doc.project.layout
    drawn = len(win.canvas.grid_curve.xData)
    assert drawn > 0
    drag_shore_end_round(qtbot, win, lay0)
    lay1 = win.doc.project.layout
    assert [b.cells for b in lay1.blocks] != [b.cells for b in lay0.blocks]  # the cells followed the drag
    assert not win.doc.grids  # no grid of this layout yet
    assert len(win.canvas.grid_curve.xData) == drawn  # the grid of before, still drawn
    assert win.canvas.grid_curve.opts["pen"].color().name() == "#b0b0b0"  # greyed
    assert "before the edit" in win.solve_status.label.text()


def test_a_drag_that_changes_the_cell_count_much_says_so_as_a_warning(qtbot, win):
    """A cut end of a ring lake dragged 40° round: at the drag's end the stretched blocks' cells
    followed the cell size and the grid went from 3,072 to 3,840 cells, said only as an info line
    among others ('Cells follow the drag ...: b0 16×148 → 20×132, ...').  A change of the total by
    more than a fifth is a warning now, with both counts and the change."""
    from app.lake import Lake, compute_layout
    from meshcore import testing

    poly = testing.round_lake(850_033, kind="ring", radius=2000.0)
    lake = Lake(
        outline=np.asarray(poly.exterior.coords)[:-1],
        holes=tuple(np.asarray(r.coords)[:-1] for r in poly.interiors),
        target_cells=3000,
    )
    win.lake_ctl.generate_after = False
    win.editor.set_lake(lake.replaced(layout=compute_layout(lake)), "Auto layout")
    lay0 = win.doc.project.layout
    said = []
    win.doc.reported.connect(lambda level, text: said.append((level, text)))
    drag_shore_end_round(qtbot, win, lay0)
    n0, n1 = lay0.n_cells, win.doc.project.layout.n_cells
    assert abs(n1 / n0 - 1) > 0.2  # the case: a large change (app.drag_cells.CELLS_WARN)
    warned = [t for level, t in said if level == "warning" and f"from {n0:,} to {n1:,} cells" in t]
    assert len(warned) == 1 and f"({100 * (n1 / n0 - 1):+.0f} %)" in warned[0], said


def test_an_island_the_layout_left_out_is_drawn_dashed_under_the_grid(qtbot, win, tmp_path):
    """An island narrower than two cells is left out by the layout (a note says so), but the canvas
    drew it as shore, over the grid, as if the grid went round it (seen on a generated archipelago).
    Now the shore is the outline and the islands the grid goes round; a left-out island is a dashed
    ring under the grid's lines."""
    from tests.app.test_lake import _thin_island_lake, lay_out

    lay = lay_out(qtbot, win, _thin_island_lake(tmp_path / "thin.geojson"), cell_size=500.0)
    lake = win.doc.project.lake
    assert len(lake.holes) == 2 and len(lay.polygon.interiors) == 1  # the needle left out
    items = win.canvas.lake_items

    def rings(item) -> int:
        y = item.yData
        return 0 if y is None else int(np.isnan(y).sum())

    assert rings(items.shore) == 2  # the shore and the island the grid goes round
    assert rings(items.left_out) == 1
    assert items.left_out.opts["pen"].style() == QtCore.Qt.PenStyle.DashLine
    assert items.left_out.zValue() < win.canvas.grid_curve.zValue()


def test_the_verdict_table_is_hidden_while_there_is_no_verdict(qtbot, win, tmp_path):
    """A laid-out lake opened with no grid yet (or with auto-generate off after Auto layout): the
    Quality dock said "The verdict follows when the grid of this layout is made" above an empty
    verdict table (its header, an empty box).  The table shows when there is a verdict."""
    from app.io_adapter import save_project

    if win.solver.auto:
        win.a_auto.trigger()
    path = tmp_path / "walk5.toml"
    save_project(_laid_out_project(850_051), path)
    assert win.io.open_path(path)
    box = win.lake_quality
    assert not box.isHidden() and "verdict follows" in box.headline.text()
    assert box.table.isHidden()
