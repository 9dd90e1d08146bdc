"""A lake outline gets the layout ``meshcore mesh`` gives, also when it is compact and has no islands;
a point file of plain numbers (a duct, an airfoil) stays one block."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from PySide6 import QtWidgets

from app.__main__ import solve_as_opened
from meshcore import testing
from tests.app.waits import wait_for, wait_idle

pytestmark = pytest.mark.gui


def _lonlat_lake(path, seed: int, lon0: float = 9.2, lat0: float = 45.8):
    """A compact generated lake without islands, a few km across, as a lon/lat GeoJSON polygon."""
    poly = testing.round_lake(seed, kind="blob", radius=1500.0)  # its shore alone
    xy = np.asarray(poly.exterior.coords, float)
    lat = lat0 + xy[:, 1] / 111_320.0
    lon = lon0 + xy[:, 0] / (111_320.0 * math.cos(math.radians(lat0)))
    ring = [[float(a), float(b)] for a, b in zip(lon, lat, strict=True)]
    geometry = {"type": "Polygon", "coordinates": [ring]}
    feature = {"type": "Feature", "properties": {"name": "lake"}, "geometry": geometry}
    path.write_text(json.dumps({"type": "FeatureCollection", "features": [feature]}))
    return path


def test_a_compact_lake_gets_auto_layout_offered_and_solve_lays_it_out(qtbot, win, tmp_path):
    """``python -m app LAKE --solve`` gridded a compact lake without islands as one block with
    automatic corners (~22° mean deviation on a set-10 lake) where ``meshcore mesh`` lays it out."""
    from app.lake import looks_branched

    path = _lonlat_lake(tmp_path / "lake.geojson", 864213)
    assert win.io.import_points(path, project_lonlat=True)
    p = win.doc.project
    assert p.lake is not None and not p.lake.holes and not looks_branched(p.lake.outline)
    box = win.lake_ctl.prompt
    assert box is not None and box.windowTitle() == "A lake outline" and "meshcore mesh" in box.text()
    win.lake_panel.cell_size.setValue(150.0)  # ~300 cells: a quick grid
    win.lake_panel.cell_size.editingFinished.emit()
    assert solve_as_opened(QtWidgets.QApplication.instance(), win)
    wait_idle(qtbot, win)
    lay = win.doc.project.layout
    assert lay is not None and len(lay.blocks) > 1
    assert len(win.doc.grids) == len(lay.blocks) == len(win.doc.project.blocks)
    # the layout is one undo step: Ctrl+Z gives the one block back, with the imported shore
    win.stack.undo()
    assert win.doc.project.layout is None and len(win.doc.project.blocks) == 1
    np.testing.assert_array_equal(win.doc.block.points, win.doc.project.lake.outline)


def test_opened_for_solve_a_lonlat_lake_is_projected_without_a_question(qtbot, win, tmp_path, monkeypatch):
    """``python -m app LAKE --solve`` stopped at "Project them to metres?" (the run waited for a
    click); opened for a solve the degrees are projected as that question's default does."""
    from app import io_adapter as fio
    from tests.app.waits import answer_questions

    win.quiet = False  # as a user's window: questions are asked (answered here without a dialog)
    asked = answer_questions(monkeypatch, "No")
    path = _lonlat_lake(tmp_path / "lake.geojson", 864214)
    assert win.io.open_path(path, project_lonlat=True)
    assert asked == []
    pts = win.doc.project.lake.outline
    assert np.ptp(pts[:, 0]) > 1000.0  # metres across a lake a few km wide, not degrees
    frame = fio.project_frame(win.doc.project)
    assert frame is not None and str(frame.crs).startswith("EPSG:326")
    # opened by hand (no --solve) the user is still asked
    win.io.set_project(type(win.doc.project)())
    assert win.io.open_path(path) and len(asked) == 1 and "metres" in asked[0]


def test_a_point_file_of_plain_numbers_stays_one_block(qtbot, win, tmp_path):
    """A compact shape in plain numbers without a CRS (a duct, an airfoil's box) is no lake on the
    map: no offer, and ``--solve`` grids the one block with automatic corners, as before."""
    t = np.linspace(0.0, 2.0 * np.pi, 40, endpoint=False)
    ring = np.c_[2.0 * np.cos(t) + 0.3 * np.cos(3 * t), np.sin(t)]  # a rounded duct section
    path = tmp_path / "duct.csv"
    path.write_text("x,y\n" + "\n".join(f"{x:.6f},{y:.6f}" for x, y in ring) + "\n")
    assert win.io.import_points(path)
    assert win.lake_ctl.prompt is None
    assert solve_as_opened(QtWidgets.QApplication.instance(), win)
    wait_idle(qtbot, win)
    assert win.doc.project.layout is None and len(win.doc.project.blocks) == 1
    assert list(win.doc.grids) == [0]


def test_a_saved_lake_reopens_with_the_outline_imported(qtbot, win, tmp_path):
    """Save, then reopen: the lake's shore and islands came back with every vertex the layout's
    blocks put on them (a 40-point shore as ~390 points), and Clear layout or a new Auto layout
    started from those.  The case holds the water as imported (``[lake]``)."""
    from app.lake import default_cell_size, water
    from tests.app.test_modeller import _metres_lake

    assert win.io.import_points(_metres_lake(tmp_path / "lake.csv", 873311))
    lake = win.doc.project.lake
    assert lake.holes
    win.lake_panel.cell_size.setValue(default_cell_size(water(lake.outline, lake.holes)[0].area, 500))
    win.lake_panel.cell_size.editingFinished.emit()
    win.a_auto_layout.trigger()
    wait_for(qtbot, win, lambda: win.doc.project.layout is not None or bool(win.lake_ctl.last_error))
    wait_idle(qtbot, win)
    lake, lay = win.doc.project.lake, win.doc.project.layout
    assert lay is not None and len(lay.blocks) > 1 and len(win.doc.grids) == len(lay.blocks)
    before = {k: (g.x.copy(), g.y.copy()) for k, g in win.doc.grids.items()}
    path = tmp_path / "lake.toml"
    assert win.io.save_to(path)
    assert win.io.open_path(path)
    back = win.doc.project.lake
    np.testing.assert_array_equal(back.outline, lake.outline)
    assert len(back.holes) == len(lake.holes)
    for a, b in zip(back.holes, lake.holes, strict=True):
        np.testing.assert_array_equal(a, b)
    assert back.cell_size == lake.cell_size
    got = win.doc.project.layout
    assert [(b.name, b.cells, b.corners) for b in got.blocks] == [(b.name, b.cells, b.corners) for b in lay.blocks]
    win.generate()
    wait_idle(qtbot, win)
    assert sorted(win.doc.grids) == sorted(before)
    for k, (x, y) in before.items():
        np.testing.assert_allclose(win.doc.grids[k].x, x, rtol=0, atol=1e-9 * np.ptp(x))
        np.testing.assert_allclose(win.doc.grids[k].y, y, rtol=0, atol=1e-9 * np.ptp(y))
    # Clear layout: the one block of the shore as imported
    win.a_clear_layout.trigger()
    assert win.doc.project.layout is None
    np.testing.assert_array_equal(win.doc.block.points, lake.outline)


def test_a_lake_saved_before_auto_layout_keeps_its_islands_and_settings(qtbot, win, tmp_path):
    """Import a lake with islands, set the cell size and "regular", save, reopen: the case held the
    one block only, and the project came back without islands, cell size or the lake itself."""
    from tests.app.test_modeller import _metres_lake

    assert win.io.import_points(_metres_lake(tmp_path / "lake.csv", 873377))
    win.lake_ctl.set_cell_size(250.0)
    win.lake_ctl.set_regular(True)
    lake = win.doc.project.lake
    assert lake.holes and lake.layout is None and len(win.doc.project.blocks) == 1
    path = tmp_path / "lake.toml"
    assert win.io.save_to(path)
    assert win.io.open_path(path)
    back = win.doc.project.lake
    assert back is not None and back.layout is None
    np.testing.assert_array_equal(back.outline, lake.outline)
    assert len(back.holes) == len(lake.holes)
    for a, b in zip(back.holes, lake.holes, strict=True):
        np.testing.assert_array_equal(a, b)
    assert (back.cell_size, back.regular, back.single) == (250.0, True, False)
    np.testing.assert_array_equal(win.doc.block.points, win.doc.project.blocks[0].points)
    assert len(win.doc.project.blocks) == 1


@pytest.mark.parametrize("name", ["windermere"])
def test_a_lake_example_opens_as_a_lake_and_solve_lays_it_out(qtbot, win, name):
    """Examples ▸ a real lake opened as one block with automatic corners (no shore kept for Auto
    layout, none offered): ``--example windermere --solve`` gave one fanned block.  It now opens as
    its file imported: the lake kept, Auto layout offered, no undo step (the example is where the
    history starts), nothing in File ▸ Open recent; the solve lays it out."""
    from shapely.geometry import Polygon

    from app.examples import LAKES

    recent_before = win.io.recent()
    assert win.io.open_example(name, confirm=False)
    p = win.doc.project
    assert p.lake is not None and len(p.blocks) == 1 and p.crs.startswith("EPSG:326")
    assert p.title == LAKES[name][1]
    assert win.lake_ctl.prompt is not None
    assert win.stack.count() == 0 and win.stack.isClean()
    assert win.io.recent() == recent_before
    area = Polygon(p.lake.outline).area
    win.lake_panel.cell_size.setValue(float(np.sqrt(area / 600.0)))  # ~600 cells: a quick grid
    win.lake_panel.cell_size.editingFinished.emit()
    assert solve_as_opened(QtWidgets.QApplication.instance(), win)
    wait_idle(qtbot, win)
    lay = win.doc.project.layout
    assert lay is not None and len(lay.blocks) > 1
    assert len(win.doc.grids) == len(lay.blocks)
