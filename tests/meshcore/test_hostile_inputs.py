"""Inputs from the session-19 hostile sweep that failed on main: each gives exit 2 and one
line naming the file and the problem — no traceback, no output file, nothing silently wrong."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from meshcore.cli import main
from meshcore.io import read_blocks
from tests.conftest import DATA, ROOT
from tests.meshcore.test_cli_bad_input import _bad

BOTTLE = ROOT / "resources" / "examples" / "bottle-coarse.toml"


@pytest.mark.parametrize(
    "text",
    [
        "a = " + "[" * 5000 + "]" * 5000 + "\n",  # RecursionError in tomllib: exit 1 "internal error"
        "a = " + "{b = " * 3000 + "1" + "}" * 3000 + "\n",
    ],
)
def test_a_case_nested_too_deep_is_a_clear_error(tmp_path, capsys, text):
    case, out = tmp_path / "case.toml", tmp_path / "out.vts"
    case.write_text(text)
    _bad(capsys, ["generate", case, "-o", out, "-q"], "case.toml", "nested too deep")
    assert not out.exists()


@pytest.mark.parametrize("origin", ["[nan, 0.0]", "[0.0, inf]", "[1e300, 0.0]"])
def test_a_case_origin_that_is_not_a_finite_number_is_refused(tmp_path, capsys, origin):
    # nan was accepted: every coordinate written was nan (exit 0)
    case, out = tmp_path / "case.toml", tmp_path / "out.vts"
    case.write_text(BOTTLE.read_text() + f'\n[crs]\norigin = {origin}\ncrs = "EPSG:32632"\n')
    _bad(capsys, ["generate", case, "-o", out, "-q"], "case.toml", "origin")
    assert not out.exists()


def _circle_csv(path, radius, centre=0.0, n=40):
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    pts = np.c_[np.cos(t), np.sin(t)] * radius + centre
    path.write_text("x,y\n" + "".join(f"{a:.17g},{b:.17g}\n" for a, b in pts))
    return path


def test_a_lake_far_from_the_origin_gets_a_local_origin(tmp_path, capsys):
    # a 2 km circle at (1e10, 1e10) in plain x, y: exit 1 (the layout's NaN, "All-NaN slice")
    src, out = _circle_csv(tmp_path / "far.csv", 1000.0, 1e10), tmp_path / "far.vtm"
    assert main(["mesh", str(src), "-o", str(out), "--cells", "200", "-q"]) in (0, 3), capsys.readouterr().err
    gs = read_blocks(out)
    x = np.concatenate([g.x.ravel() for g in gs.blocks]) - 1e10
    y = np.concatenate([g.y.ravel() for g in gs.blocks]) - 1e10
    assert np.hypot(x, y).max() < 1000.5 and np.hypot(x, y).max() > 990  # world coordinates, the circle's size


def test_coordinates_beyond_what_the_layout_meshes_are_refused(tmp_path, capsys):
    # a circle of radius 1e80: exit 1 (Qhull "initial simplex is flat" in the layout)
    src, out = _circle_csv(tmp_path / "huge.csv", 1e80), tmp_path / "huge.vtm"
    _bad(capsys, ["mesh", src, "-o", out, "--cells", "200", "-q"], "huge.csv", "coordinates reach 1e+80")
    assert not out.exists()


@pytest.mark.parametrize(("crs", "kind"), [("EPSG:4978", "geocentric"), ("EPSG:5703", "vertical")])
@pytest.mark.parametrize("command", ["mesh", "import"])
def test_a_crs_that_is_not_a_map_is_refused(tmp_path, capsys, crs, kind, command):
    # EPSG:4978 gave a grid of the lake squashed onto the equator's plane (exit 0)
    out = tmp_path / ("o.vtm" if command == "mesh" else "o.toml")
    _bad(capsys, [command, DATA / "lake_zurich_sparse.csv", "-o", out, "--crs", crs], crs, kind)
    assert not out.exists()


def test_the_cell_ratio_of_a_shore_of_very_many_points_triangulates_a_thinned_border(monkeypatch):
    # meshcore import of a 10⁶-point shore spent 69 s in this triangulation (timed out at 60 s)
    import shapely

    from meshcore import cellratio

    seen = []
    real = shapely.constrained_delaunay_triangles
    monkeypatch.setattr(
        shapely, "constrained_delaunay_triangles", lambda p: seen.append(len(p.exterior.coords)) or real(p)
    )
    m = 20_000
    s = np.linspace(0, 1, m, endpoint=False)
    loop = np.vstack([np.c_[3 * s, 0 * s], np.c_[3 + 0 * s, s], np.c_[3 - 3 * s, 1 + 0 * s], np.c_[0 * s, 1 - s]])
    assert round(cellratio.cell_ratio(loop, (0, m, 2 * m, 3 * m)), 6) == 3.0
    assert seen and seen[0] <= 4 * cellratio.MAX_BORDER_POINTS + 1


@pytest.mark.parametrize(
    ("argv", "needle"),
    [
        (["import", "{f}", "-o", "{f}"], "a case file ends in .toml"),  # wrote the case over the points
        (["mesh", "{f}", "-o", "{f}", "--cells", "200", "-q"], "the same file as the outline"),  # the grid's CSV
    ],
)
def test_an_output_over_the_outline_is_refused_and_the_outline_kept(tmp_path, capsys, argv, needle):
    src = tmp_path / "lake.csv"
    src.write_bytes((DATA / "lake_zurich_sparse.csv").read_bytes())
    _bad(capsys, [str(src) if a == "{f}" else a for a in argv], "lake.csv", needle)
    assert src.read_bytes() == (DATA / "lake_zurich_sparse.csv").read_bytes()


def test_convert_refuses_to_write_over_its_input(tmp_path, capsys):
    from meshcore import StructuredGrid
    from meshcore.io import write

    xi, eta = np.meshgrid(np.linspace(0, 2, 5), np.linspace(0, 1, 3), indexing="ij")
    src = write(tmp_path / "g.vts", StructuredGrid(xi, eta))
    before = src.read_bytes()
    _bad(capsys, ["convert", src, tmp_path / "." / "g.vts"], "g.vts", "the same file as the input")
    assert src.read_bytes() == before


def test_a_quoted_value_holding_the_delimiter_is_one_value(tmp_path):
    # "1,234.5","5,678.9" (thousands separators, as spreadsheets export) was read as the points (1, 234.5)
    # of columns 1 and 2: silently wrong; now each quoted value is one value, refused as no number
    from meshcore.errors import ReadError
    from meshcore.io import read_points

    f = tmp_path / "lake.csv"
    f.write_text('x,y\n"1,234.5","5,678.9"\n"2,234.5","5,678.9"\n"2,234.5","6,678.9"\n')
    with pytest.raises(ReadError, match=r"lake.csv: line 2: not a number in column 1"):
        read_points(f)
    f.write_text('lon,lat\n"8.5","47.2"\n"8.6", "47.2"\n"8.55","47.3"\n')
    assert read_points(f).polylines[0].points.tolist() == [[8.5, 47.2], [8.6, 47.2], [8.55, 47.3]]


def test_degrees_in_a_file_said_to_hold_metres_get_a_note(tmp_path, capsys):
    # a GeoJSON labelled EPSG:3857 holding lon/lat became a lake 0.3 m across, exit 0 without a word
    import json

    gj = json.loads((DATA / "lake_zurich_sparse.geojson").read_text())
    gj["crs"] = {"type": "name", "properties": {"name": "EPSG:3857"}}
    src, out = tmp_path / "lake.geojson", tmp_path / "o.vtm"
    src.write_text(json.dumps(gj))
    assert main(["mesh", str(src), "-o", str(out), "--cells", "200", "-q"]) in (0, 3)
    err = capsys.readouterr().err
    assert "look like degrees" in err and "EPSG:3857" in err and "--source-crs EPSG:4326" in err, err
    assert main(["mesh", str(DATA / "lake_zurich_sparse.geojson"), "-o", str(out), "--cells", "200", "-q"]) == 0
    assert "look like degrees" not in capsys.readouterr().err


def test_a_shapefile_of_no_records_is_one_line(tmp_path, capsys):
    # pyshp's PossiblyCorruptFileHeader warning printed two more lines (its source) before the error
    shapefile = pytest.importorskip("shapefile")
    import io

    parts = {s: io.BytesIO() for s in ("shp", "shx", "dbf")}
    w = shapefile.Writer(**parts, shapeType=shapefile.POLYGON)
    w.field("name", "C")
    w.close()
    for s, b in parts.items():
        (tmp_path / f"lake.{s}").write_bytes(b.getvalue() + (b" " * 35 if s == "dbf" else b""))  # .dbf too long
    _bad(capsys, ["import", tmp_path / "lake.shp", "-o", tmp_path / "c.toml"], "lake.shp", "no line or polygon shapes")


def test_import_refuses_an_outline_that_crosses_itself_naming_the_place(tmp_path, capsys):
    # a bow tie in lon/lat was written as a case (exit 0); only generate said it crosses itself
    src, out = tmp_path / "lake.csv", tmp_path / "c.toml"
    src.write_text("lon,lat\n8.5,47.2\n8.55,47.25\n8.55,47.2\n8.5,47.25\n")
    err = _bad(capsys, ["import", src, "-o", out], "lake.csv", "crosses itself", "edge from point 1 to 2")
    assert "near (46" in err  # the place in the grid's CRS (UTM 32N eastings), not local coordinates
    assert not out.exists()


def test_a_spherical_grd_of_metres_is_refused_naming_the_node(tmp_path):
    # Cartesian metres under 'Coordinate System = Spherical' were read as degrees (lon 480000), exit 0
    from meshcore import StructuredGrid
    from meshcore.errors import ReadError
    from meshcore.io import write

    xi, eta = np.meshgrid(np.linspace(0, 2, 6), np.linspace(0, 1, 4), indexing="ij")
    p = write(tmp_path / "g.grd", StructuredGrid(xi * 1000 + 480000, eta * 1000 + 5240000))
    text = p.read_text()
    p.write_text(text.replace("Cartesian", "Spherical"))
    with pytest.raises(ReadError, match=r"g.grd: Coordinate System = Spherical, but node \(m=1, n=1\)"):
        read_blocks(p)
    q = write(tmp_path / "d.grd", StructuredGrid(xi * 0.01 + 8.5, eta * 0.01 + 47.2))
    q.write_text(q.read_text().replace("Cartesian", "Spherical"))
    g = read_blocks(q).blocks[0]  # lon/lat in range: read as before
    assert abs(g.x.min() - 8.5) < 1e-9 and abs(g.y.max() - 47.21) < 1e-9


@pytest.mark.skipif(not Path("/proc/self").is_dir(), reason="needs /proc (a folder no one can create files in)")
@pytest.mark.parametrize("late", [["--png", "/proc/f.png"], ["--case", "/proc/c.toml"]])
def test_an_output_folder_that_refuses_files_is_found_before_any_output_is_written(tmp_path, capsys, late):
    # /proc passes the permission bits for root: the grid was written, then --png failed (exit 2, o.vtm left)
    out = tmp_path / "o.vtm"
    argv = ["mesh", DATA / "lake_zurich_sparse.csv", "-o", out, *late, "--cells", "200", "-q"]
    _bad(capsys, argv, late[0], "cannot write in the folder /proc")
    assert not out.exists() and not (tmp_path / "o").exists()


@pytest.mark.parametrize("encoding", ["utf-8-sig", "utf-16"])
def test_a_prj_with_a_byte_order_mark_is_read(tmp_path, encoding):
    # a .prj written with a BOM (Windows tools) was 'unreadable projection' (exit 2)
    from meshcore.io import read_points

    for suffix in (".shp", ".shx", ".dbf"):
        (tmp_path / f"w{suffix}").write_bytes((DATA / f"windermere_sparse{suffix}").read_bytes())
    wkt = (DATA / "windermere_sparse.prj").read_text()
    (tmp_path / "w.prj").write_bytes(wkt.encode(encoding))
    assert read_points(tmp_path / "w.shp").crs == "EPSG:4326"


@pytest.mark.parametrize("encoding", ["utf-8-sig", "utf-16"])
def test_a_case_saved_with_a_byte_order_mark_is_read(tmp_path, encoding):
    # a case edited in Notepad (UTF-8 with BOM, or "Unicode") was "invalid TOML … line 1, column 1" (exit 2)
    from meshcore.case import load_case

    case = tmp_path / "case.toml"
    case.write_bytes(BOTTLE.read_text().encode(encoding))
    assert load_case(case).blocks[0].name == load_case(BOTTLE).blocks[0].name


def test_a_dxf_with_a_byte_order_mark_is_read(tmp_path):
    # a DXF saved as UTF-8 with a BOM was "not a valid DXF file (… is not a DXF file.)"
    from meshcore.io import read_points

    src = DATA / "lake_zurich_sparse_utm32.dxf"
    f = tmp_path / "lake.dxf"
    f.write_bytes(b"\xef\xbb\xbf" + src.read_bytes())
    got, want = read_points(f), read_points(src)
    assert [p.points.tolist() for p in got.polylines] == [p.points.tolist() for p in want.polylines]


def test_a_geojson_number_of_thousands_of_digits_is_named_without_python_internals(tmp_path):
    # the message was Python's "use sys.set_int_max_str_digits() to increase the limit"
    from meshcore.errors import ReadError
    from meshcore.io import read_points

    f = tmp_path / "lake.geojson"
    f.write_text('{"type": "LineString", "coordinates": [[' + "9" * 5000 + ", 1], [2, 3]]}")
    with pytest.raises(ReadError, match=r"lake.geojson: a number of thousands of digits") as e:
        read_points(f)
    assert "sys." not in str(e.value)
