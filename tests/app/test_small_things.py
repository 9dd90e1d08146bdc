"""Small things a lake modeller trips over (session 21b): the unit of where each part of water
lies, Open recent of a file of several parts, and the export of a single-domain grid."""

from __future__ import annotations

import json

import numpy as np
import pytest

from tests.app.test_modeller_walk5 import _ellipse, _reservoir

pytestmark = pytest.mark.gui


def _two_basins(tmp_path, x0: float = 0.0, y0: float = 0.0, crs: str | None = None):
    """Two basins in metres: a CSV of two rings (no CRS), or a GeoJSON MultiPolygon in ``crs``."""
    big = _ellipse(x0 + 5000.0, y0 + 3000.0, 2500.0, 1000.0)
    small = _ellipse(x0 + 5500.0, y0 + 500.0, 1200.0, 600.0)
    if crs is None:
        path = tmp_path / "basins.csv"
        rings = ["\n".join(f"{x},{y}" for x, y in r) for r in (big, small)]
        path.write_text("> big\n" + rings[0] + "\n> small\n" + rings[1] + "\n")
        return path
    geom = {"type": "MultiPolygon", "coordinates": [[big], [small]]}
    path = tmp_path / "basins.geojson"
    feat = {"type": "Feature", "properties": {"name": "Basins"}, "geometry": geom}
    legacy = {"type": "name", "properties": {"name": crs}}
    path.write_text(json.dumps({"type": "FeatureCollection", "crs": legacy, "features": [feat]}))
    return path


def _near(dlg):
    t = dlg.table
    head = t.horizontalHeaderItem(t.columnCount() - 1).text()
    xy = [[float(v) for v in t.item(r, t.columnCount() - 1).text().split(",")] for r in range(t.rowCount())]
    return head, np.array(xy)


def test_the_parts_dialog_says_in_what_unit_each_part_lies(qtbot, tmp_path):
    """Was "near (x, y)" with no unit, and for a lon/lat file the numbers were metres from the
    project's local origin (the upper basin "near -1.2e+03, 2.3e+03"), which the user finds in
    neither the file nor a map.  Now: a lon/lat file's parts in lon/lat, a file in metres in its
    own numbers with "m"."""
    from app.lake import read_lake_parts
    from app.parts_dialog import PartsDialog
    from meshcore.io import read_points

    parts, frame, _ = read_lake_parts(read_points(_reservoir(tmp_path)), lonlat=True)
    dlg = PartsDialog("reservoir.kml", parts, frame=frame, lonlat=True)
    qtbot.addWidget(dlg)
    head, xy = _near(dlg)
    assert head == "near (lon, lat)"
    np.testing.assert_allclose(xy, [[10.0, 46.02], [10.01, 45.995]], atol=2e-3)  # the ellipses' centres
    # and the note in Messages on import names them the same way
    from app.lake import read_lake

    note = read_lake(read_points(_reservoir(tmp_path)), lonlat=True, part=2)[3][-1]
    assert "part 1 ('Upper basin'" in note and "near lon/lat (10, 46.02" in note, note
    # lon/lat kept as degrees (not projected): the same numbers, areas not in km²
    parts, frame, _ = read_lake_parts(read_points(_reservoir(tmp_path)), lonlat=False)
    dlg = PartsDialog("reservoir.kml", parts, metres=False, frame=frame, lonlat=True)
    qtbot.addWidget(dlg)
    assert _near(dlg)[0] == "near (lon, lat)"
    # plain metres: the file's own numbers, in m
    parts, frame, _ = read_lake_parts(read_points(_two_basins(tmp_path)))
    dlg = PartsDialog("basins.csv", parts, frame=frame)
    qtbot.addWidget(dlg)
    head, xy = _near(dlg)
    assert head == "near (x, y), m"
    np.testing.assert_allclose(xy, [[5000.0, 3000.0], [5500.0, 500.0]], atol=20.0)
    # a projected CRS, in a frame of a local origin (as a project in that CRS has it): the CRS's numbers
    from meshcore.crs import Frame

    frame = Frame("EPSG:32632", (600_000.0, 5_000_000.0))
    pts = read_points(_two_basins(tmp_path, 600_000.0, 5_000_000.0, crs="urn:ogc:def:crs:EPSG::32632"))
    parts, frame, _ = read_lake_parts(pts, frame)
    dlg = PartsDialog("basins.geojson", parts, frame=frame)
    qtbot.addWidget(dlg)
    head, xy = _near(dlg)
    assert head == "near (x, y), m"
    np.testing.assert_allclose(xy, [[605_000.0, 5_003_000.0], [605_500.0, 5_000_500.0]], atol=20.0)


def test_the_unit_of_a_projected_crs_is_its_own(qtbot):
    from app.lake import crs_unit, near_header

    assert crs_unit("EPSG:32632") == "m"
    assert crs_unit("EPSG:2227") == "US survey foot"  # California zone 3, ftUS
    assert near_header(crs_unit(None)) == "near (x, y), m"


def test_open_recent_opens_the_part_chosen_last_time(qtbot, win, tmp_path, monkeypatch):
    """Was: File ▸ Open recent on a file of several parts asked which part every time (and a user
    who always works on the lower basin chose it every time).  Now the recent-files record keeps the
    part chosen per file and Open recent opens it directly; File ▸ Import still asks."""
    from PySide6 import QtWidgets

    from app.parts_dialog import PartsDialog
    from tests.app.test_modeller_walk5 import pick_part

    path = _two_basins(tmp_path)
    asked: list[int] = []
    pick_second = pick_part(1, asked)
    monkeypatch.setattr(PartsDialog, "exec", pick_second)
    monkeypatch.setattr(QtWidgets.QMessageBox, "question", lambda *a: QtWidgets.QMessageBox.StandardButton.Discard)
    win.quiet = False
    try:
        assert win.io.import_points(path)
        assert asked == [2] and win.doc.project.title == "basins_part2"
        win.io.add_recent(tmp_path / "other.csv")  # another file opened since: the record keeps the part
        win.io.set_project(type(win.doc.project)())
        recent = {a.text(): a for a in win.io.recent_menu.actions()}
        recent[str(path)].trigger()
        assert asked == [2], "Open recent asked again"
        assert win.doc.project.title == "basins_part2"
        assert "opened last time" in win._status.text()
        # File ▸ Import asks (the dialog still reachable); the part chosen there is the one remembered
        monkeypatch.setattr(QtWidgets.QFileDialog, "getOpenFileName", lambda *a, **k: (str(path), ""))
        monkeypatch.setattr(PartsDialog, "exec", lambda dlg: PartsDialog.DialogCode.Accepted)  # the largest
        win.io.import_dialog()
        assert win.doc.project.title == "basins_part1"
        assert win.io.recent_parts()[str(path)] == 1
        # a part the file no longer has: asked again, not an error
        win.settings.setValue("recent_parts", json.dumps({str(path): 5}))
        monkeypatch.setattr(PartsDialog, "exec", pick_second)
        assert win.io.open_recent(str(path))
        assert asked == [2, 2] and win.doc.project.title == "basins_part2"
    finally:
        win.quiet = True


def _csv_of(tmp_path, name, polygon, scale=1000.0):
    """A lake (shapely polygon, islands as holes) as a CSV of rings in metres."""
    rings = [polygon.exterior, *polygon.interiors]
    text = "".join(
        f"> ring{k}\n" + "\n".join(f"{x * scale},{y * scale}" for x, y in r.coords) + "\n" for k, r in enumerate(rings)
    )
    path = tmp_path / name
    path.write_text(text)
    return path


def _asked(monkeypatch, answer):
    from PySide6 import QtWidgets

    asked = []

    def question(parent, title, text, *a):
        asked.append((title, text))
        return answer

    monkeypatch.setattr(QtWidgets.QMessageBox, "question", question)
    monkeypatch.setattr(QtWidgets.QMessageBox, "warning", lambda parent, title, text: asked.append((title, text)))
    return asked


def test_a_single_domain_export_that_does_not_fit_offers_a_regular_layout(qtbot, win, tmp_path, monkeypatch):
    """Was: Export mesh as a Delft3D single domain (.grd, the "[delft3d-single]" filter) or EFDC
    (.inp) of a layout with a 3- or 5-block corner showed the writer's error only; the regular layout
    that fits was offered for a .ddb alone.  Now the error and the offer, which makes the layout."""
    from PySide6 import QtWidgets

    from meshcore import testing
    from tests.app.test_lake import lay_out
    from tests.app.waits import wait_for, wait_idle

    lay_out(qtbot, win, _csv_of(tmp_path, "y.csv", testing.y_junction()), cell_size=100.0)
    m = win.doc.project.layout.topology().node_map
    assert any(c.free and c.valence != 4 for c in m.corners)  # the star: no single index space
    for name, fmt in [("y.grd", "delft3d-single"), ("cell.inp", None)]:
        assert not win.io.export_mesh(tmp_path / name, fmt)
        said = win._status.text()
        assert "one index space" in said and "a layout made for it" in said, said
        assert not (tmp_path / name).exists()
    win.quiet = False
    asked = _asked(monkeypatch, QtWidgets.QMessageBox.StandardButton.Yes)
    try:
        assert not win.io.export_mesh(tmp_path / "y.grd", "delft3d-single")
    finally:
        win.quiet = True
    assert len(asked) == 1 and "Make a layout for one index space now?" in asked[0][1]
    wait_for(qtbot, win, lambda: win.doc.project.lake.single and win.doc.project.layout is not None)
    wait_idle(qtbot, win)
    assert win.doc.project.lake.regular and win.doc.project.layout.single
    if not win.io.export_mesh(tmp_path / "y.grd", "delft3d-single"):  # made for it, it may still fold: said so
        assert "Cannot export" in win._status.text() and "Make a" not in win._status.text()


def test_a_lake_with_islands_is_offered_a_layout_for_one_index_space(qtbot, win, tmp_path, monkeypatch):
    """EFDC of a lake with islands: the default layout does not fit one index space; the export says
    why and offers a layout made for it (regular, each island's ring closed: ``single``), which EFDC
    then takes.  (Session 21: told that no layout of a lake with islands fits, nothing offered.)"""
    from PySide6 import QtWidgets

    from meshcore import testing
    from tests.app.test_lake import lay_out
    from tests.app.waits import wait_for, wait_idle

    lake = testing.lake_with_islands(927000, n_islands=2, lobes=4)
    h = 1000.0 * (lake.area / 15000) ** 0.5  # _csv_of's metres
    lay_out(qtbot, win, _csv_of(tmp_path, "isl.csv", lake), cell_size=h)
    assert len(win.doc.project.layout.polygon.interiors) == 2
    win.quiet = False
    asked = _asked(monkeypatch, QtWidgets.QMessageBox.StandardButton.Yes)
    try:
        assert not win.io.export_mesh(tmp_path / "cell.inp")
    finally:
        win.quiet = True
    assert [t for t, _ in asked] == ["One index space"], asked
    said = asked[0][1]
    assert "rings of blocks round islands" in said, said
    assert said.endswith("Make a layout for one index space now? cell.inp is written when its grid is done."), said
    wait_for(qtbot, win, lambda: win.doc.project.lake.single and win.doc.project.layout is not None)
    wait_idle(qtbot, win)
    # written when the grid of the new layout is done (session 24: was "then export again")
    assert (tmp_path / "cell.inp").exists() and (tmp_path / "dxdy.inp").exists(), win._status.text()
    assert win.io.export_mesh(tmp_path / "cell.inp"), win._status.text()


def test_the_active_blocks_border_labels_stand_out_from_the_grid_and_block_labels(qtbot, win, tmp_path):
    """Seen under Xvfb on a generated lake of 8 blocks: the label of the active block's inner border
    ("bottom · 73") lay over the next block's grid lines, which crossed it out, and a block label
    ("60×48", drawn above it) hid it at a zoomed-out view.  Now on a white ground, above the block
    labels, which keep clear of it (a shorter text, or none, where it lies)."""
    from meshcore import testing
    from tests.app.test_lake import lay_out

    lay_out(qtbot, win, _csv_of(tmp_path, "isl.csv", testing.lake_with_islands(800123, n_islands=2)))
    c = win.canvas
    c.fit()
    qtbot.wait(50)
    shown = [t for t in c.border_labels.values() if t.isVisible() and t.textItem.toPlainText()]
    assert shown
    top = max(t.zValue() for t in c.lake_items.labels)
    for t in shown:
        assert t.fill.color().alpha() >= 180 and t.fill.color().lightness() > 240
        assert t.zValue() > top
    # at every zoom, no block label shown overlaps a border label shown
    vb = c.getPlotItem().getViewBox()

    def box(t):
        r, p, px = t.textItem.boundingRect(), t.pos(), c.pixel()
        return np.array(
            [
                p.x() - 0.5 * r.width() * px,
                p.y() - 0.5 * r.height() * px,
                p.x() + 0.5 * r.width() * px,
                p.y() + 0.5 * r.height() * px,
            ]
        )

    overlaps = 0
    for k in range(6):
        if k:
            vb.scaleBy((1.6, 1.6))
        qtbot.wait(50)
        borders = [box(t) for t in c.border_labels.values() if t.isVisible() and t.textItem.toPlainText()]
        blocks = [box(t) for t in c.lake_items.labels if t.isVisible() and t.textItem.toPlainText()]
        for a in borders:
            for b in blocks:
                overlaps += bool(a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3])
    assert overlaps == 0


def test_label_levels_keep_clear_of_boxes_taken():
    from app.geometry import label_levels

    at = np.array([[0.0, 0.0], [10.0, 0.0]])
    half = np.array([[[2.0, 1.0], [1.0, 0.5]], [[2.0, 1.0], [1.0, 0.5]]])
    fits = np.ones((2, 2), bool)
    assert list(label_levels(at, half, fits, [0, 1])) == [0, 0]
    taken = np.array([[1.5, -3.0, 5.0, 3.0]])  # over the right of the first label's long text
    assert list(label_levels(at, half, fits, [0, 1], taken=taken)) == [1, 0]
    taken = np.array([[-5.0, -5.0, 5.0, 5.0]])  # over the whole first label
    assert list(label_levels(at, half, fits, [0, 1], taken=taken)) == [-1, 0]


def test_open_recent_of_a_lon_lat_file_does_not_ask_to_project_again(qtbot, win, tmp_path, monkeypatch):
    """Was: File ▸ Open recent on a lon/lat lake asked "Project them to metres?" every time.  The
    answer given at its import is kept with the recent file and used again; File ▸ Import asks."""
    from PySide6 import QtWidgets

    path = tmp_path / "pond.csv"
    ring = [(10.0, 46.0), (10.02, 46.0), (10.02, 46.01), (10.0, 46.01)]
    path.write_text("lon,lat\n" + "".join(f"{x},{y}\n" for x, y in ring))
    asked = []

    def question(_parent, title, *_a, **_k):
        asked.append(title)
        b = QtWidgets.QMessageBox.StandardButton
        return b.Yes if title == "Geographic coordinates" else b.Discard

    monkeypatch.setattr(QtWidgets.QMessageBox, "question", question)
    win.quiet = False
    try:
        assert win.io.import_points(path)
        assert asked.count("Geographic coordinates") == 1
        crs = win.doc.project.crs
        assert crs and "326" in str(crs)  # projected to the UTM zone (32632)
        win.io.set_project(type(win.doc.project)())
        assert win.io.open_recent(str(path))
        assert asked.count("Geographic coordinates") == 1, "Open recent asked again"
        assert win.doc.project.crs == crs
        win.io.import_points(path)  # File ▸ Import: asked
        assert asked.count("Geographic coordinates") == 2
    finally:
        win.quiet = True


def test_lake_menu_makes_a_layout_for_one_index_space_and_recovery_keeps_it(qtbot, win, tmp_path):
    """Lake ▸ Auto layout, one index space: the lake's setting and its layout say so, Auto layout
    again keeps it (until Auto layout, regular or the Regular box off), and the recovery state holds it."""
    from app import recovery
    from meshcore import testing
    from tests.app.test_lake import lay_out
    from tests.app.waits import wait_for, wait_idle

    lay_out(qtbot, win, _csv_of(tmp_path, "y.csv", testing.y_junction()), cell_size=100.0)
    assert not win.doc.project.lake.single and not win.doc.project.layout.single
    win.a_auto_layout_single.trigger()
    wait_for(qtbot, win, lambda: win.doc.project.lake.single and win.doc.project.layout.single)
    wait_idle(qtbot, win)
    assert win.doc.project.lake.regular
    assert "for one index space" in win.lake_panel.summary.text()
    state = recovery._lake_state(win.doc.project.lake)
    assert state["single"] and recovery._with_lake(win.doc.project.replaced(lake=None), state).lake.single
    win.a_auto_layout_regular.trigger()
    wait_for(qtbot, win, lambda: not win.doc.project.lake.single and win.doc.project.layout is not None)
    wait_idle(qtbot, win)
    assert win.doc.project.lake.regular and not win.doc.project.layout.single
    assert "index space" not in win.lake_panel.summary.text()
