"""The app on inputs a new lake modeller sends (session 22's sweep): a clear message, the work kept."""

from __future__ import annotations

import numpy as np
import pytest

from tests.app.waits import answer_questions

pytestmark = pytest.mark.gui

T = np.linspace(0, 2 * np.pi, 24, endpoint=False)


def test_a_lake_of_points_on_one_line_is_refused_by_auto_layout_naming_the_place():
    from app.lake import Lake, compute_layout
    from meshcore.errors import InvalidInputError

    # a sliver 4 cm wide and 1.6 km long (lon/lat on a parallel, 6 decimals, projected): was
    # "internal error: ValueError: All-NaN slice encountered" from the layout (90 s at 10 000 cells)
    x = np.linspace(0.0, 1560.0, 20)
    y = 0.02 * np.sin(np.linspace(0, np.pi, 20))
    lake = Lake(outline=np.r_[np.c_[x, y], np.c_[x[-2:0:-1], -y[-2:0:-1]]], target_cells=200)
    with pytest.raises(InvalidInputError, match=r"on one line.*Lake panel"):
        compute_layout(lake)
    channel = Lake(outline=np.array([[0.0, 0.0], [20000.0, 0.0], [20000.0, 200.0], [0.0, 200.0]]), cell_size=300.0)
    assert compute_layout(channel).n_cells > 0  # narrower than a cell set by the user: laid out


def test_the_lonlat_order_note_of_a_y_x_header_tells_no_command_line_option(win, tmp_path):
    f = tmp_path / "yx.csv"
    f.write_text("Y,X\n" + "".join(f"{47.3 + 0.01 * np.sin(a):.6f},{8.5 + 0.02 * np.cos(a):.6f}\n" for a in T))
    seen = []
    win.doc.reported.connect(lambda level, text: seen.append(text))
    assert win.io.import_points(f, project_lonlat=True)
    notes = [t for t in seen if "the header says" in t]
    assert notes and all("--columns" not in t for t in notes), seen  # the app has no --columns


# a triangle lake, 4 × 3 km (metres) and the same in lon/lat near Zurich
TRIANGLE = [(0.0, 0.0), (4000.0, 0.0), (2000.0, 3000.0)]


@pytest.mark.parametrize("lonlat", [False, True])
def test_a_triangle_lake_imports_and_auto_layout_grids_it_as_meshcore_mesh_does(qtbot, win, tmp_path, lonlat):
    from tests.app.waits import wait_for, wait_idle

    f = tmp_path / "tri.csv"
    if lonlat:
        f.write_text("lon,lat\n8.500000,47.300000\n8.560000,47.300000\n8.530000,47.340000\n")
    else:
        f.write_text("x,y\n" + "".join(f"{x},{y}\n" for x, y in TRIANGLE))
    seen = []
    win.doc.reported.connect(lambda level, text: seen.append((level, text)))
    # was: "Cannot import points: tri.csv: needs at least 4 points, found 3" (meshcore mesh grids it)
    assert win.io.import_points(f, project_lonlat=True), (win._status.text(), seen)
    lake = win.doc.project.lake
    assert lake is not None and len(lake.outline) >= 3
    win.lake_ctl.auto_layout()
    wait_for(qtbot, win, lambda: win.doc.project.layout is not None or win.lake_ctl.last_error is not None)
    wait_idle(qtbot, win)
    assert win.lake_ctl.last_error is None
    assert len(win.doc.grids) == len(win.doc.project.blocks) > 1  # every block gridded


def test_a_clicked_triangle_is_laid_out_and_gridded_and_generate_says_how(qtbot, win):
    from PySide6 import QtCore

    from tests.app.waits import wait_for, wait_idle

    win.set_tool("draw")
    for xy in TRIANGLE:
        win.canvas.tool.click(np.asarray(xy, float))
    win.canvas.tool.key(QtCore.Qt.Key.Key_Return)
    assert win.doc.block.closed and len(win.doc.block.points) == 3
    win.generate()  # F5: no four corners on three points; says what grids it
    assert "Auto layout" in win._status.text(), win._status.text()
    win.auto_corners()
    assert "Auto layout" in win._status.text(), win._status.text()
    win.lake_ctl.auto_layout()
    wait_for(qtbot, win, lambda: win.doc.project.layout is not None or win.lake_ctl.last_error is not None)
    wait_idle(qtbot, win)
    assert win.lake_ctl.last_error is None
    assert len(win.doc.grids) == len(win.doc.project.blocks) > 1


def test_a_lonlat_header_over_latitude_longitude_values_is_refused_not_read_as_metres(win, tmp_path):
    f = tmp_path / "shasta.csv"
    lon, lat = -122.4 + 0.05 * np.cos(T), 40.8 + 0.03 * np.sin(T)
    f.write_text("lon,lat\n" + "".join(f"{b:.6f},{a:.6f}\n" for a, b in zip(lon, lat, strict=True)))
    seen = []
    win.doc.reported.connect(lambda level, text: seen.append((level, text)))
    # was: imported "as local metres: its numbers are no longitude/latitude", a lake 0.1 m across
    assert not win.io.import_points(f, project_lonlat=True)
    assert win.doc.project.lake is None
    errors = [t for lv, t in seen if lv == "error"]
    assert errors and "look like latitude, longitude" in errors[0] and "the header 'lat,lon'" in errors[0], seen


def test_headerless_latitude_longitude_degrees_are_noted_with_what_to_change_in_the_file(win, tmp_path):
    f = tmp_path / "shasta.csv"
    lon, lat = -122.4 + 0.05 * np.cos(T), 40.8 + 0.03 * np.sin(T)
    f.write_text("".join(f"{b:.6f},{a:.6f}\n" for a, b in zip(lon, lat, strict=True)))
    seen = []
    win.doc.reported.connect(lambda level, text: seen.append((level, text)))
    assert win.io.import_points(f, project_lonlat=True)
    notes = [t for lv, t in seen if "latitude, longitude" in t]
    assert notes and "header 'lat,lon'" in notes[0] and "--columns" not in notes[0], seen


def test_a_bow_tie_outline_is_said_to_cross_itself_on_import(win, tmp_path):
    f = tmp_path / "bowtie.csv"
    f.write_text("x,y\n0,0\n4000,3000\n4000,0\n0,3000\n")
    seen = []
    win.doc.reported.connect(lambda level, text: seen.append((level, text)))
    assert win.io.import_points(f, project_lonlat=True)
    # was: only the corners' "reflex vertex (interior angle 307°)"; Auto layout said why later
    crossing = [t for lv, t in seen if lv == "warning" and "crosses itself" in t]
    assert crossing and "bowtie.csv" in crossing[0] and "point 1 to 2" in crossing[0], seen


def test_the_import_message_of_degrees_says_where_the_lake_lands(win, tmp_path):
    # Bolsena (lon 11.93, lat 42.59) written lat, lon under a lon,lat header: both within ±90, nothing
    # to refuse; the message's centroid (lon 42.59, lat 11.93) shows the lake is not where it should be
    f = tmp_path / "bolsena.csv"
    f.write_text("lon,lat\n" + "".join(f"{42.59 + 0.05 * np.sin(a):.6f},{11.93 + 0.06 * np.cos(a):.6f}\n" for a in T))
    assert win.io.import_points(f, project_lonlat=True)
    assert "centroid lon 42.59000, lat 11.93000; projected to EPSG:32638" in win._status.text(), win._status.text()


def test_export_without_a_grid_says_there_is_nothing_to_export(win, tmp_path):
    out = tmp_path / "lake.grd"
    # was (called directly, as app.bench does): "expected a StructuredGrid, a list of them or ... got list"
    assert not win.io.export_mesh(out, "delft3d-single")
    assert "Nothing to export yet" in win._status.text() and not out.exists()


def test_the_lon_lat_question_says_where_the_lake_is(win, tmp_path, monkeypatch):

    asked = answer_questions(monkeypatch)
    monkeypatch.setattr(win, "quiet", False)
    monkeypatch.setattr(win.lake_ctl, "offer", lambda *_a: None)
    f = tmp_path / "bolsena.csv"  # written lat, lon under a lon,lat header: the question shows lon 42.6
    f.write_text("lon,lat\n" + "".join(f"{42.59 + 0.05 * np.sin(a):.6f},{11.93 + 0.06 * np.cos(a):.6f}\n" for a in T))
    assert win.io.import_points(f)
    assert "(centroid lon 42.59000, lat 11.93000)" in asked[0], asked


def test_an_export_the_layout_cannot_take_says_its_reasons_once(qtbot, win, tmp_path):
    from meshcore import testing
    from tests.app.test_lake import lay_out

    shore = 1000.0 * np.asarray(testing.y_junction().exterior.coords)[:-1]  # a star at the junction
    src = tmp_path / "y.csv"
    np.savetxt(src, shore, delimiter=",", header="x,y", comments="")
    lay_out(qtbot, win, src, cell_size=100.0)
    for name, fmt in [("y.ddb", None), ("y.grd", "delft3d-single")]:
        assert not win.io.export_mesh(tmp_path / name, fmt)
        said = win._status.text()
        # was: the writer's reasons, then the same again ("… couples no corner where 3 or 5 blocks meet")
        assert said.count("3 or 5 blocks meet") == 1 and "then export again" in said, said
