"""Inputs a new lake modeller sends (session 22's sweep) that failed on main: each now gives a
grid of the water in the file, or exit 2 and one line naming the file and the place."""

from __future__ import annotations

import numpy as np
import pytest

from meshcore.cli import main
from tests.meshcore.test_cli_bad_input import _bad


def test_lonlat_points_on_a_line_but_for_their_decimals_are_refused_naming_the_place(tmp_path, capsys):
    # 20 points along a parallel, 6 decimals: a sliver 4 cm wide and 1.6 km long, exit 1 after a
    # minute and a half ("internal error ... All-NaN slice encountered" in the layout's skeleton)
    src, out = tmp_path / "line.csv", tmp_path / "line.vtm"
    lon = 11.9 + 0.001 * np.arange(20)
    src.write_text("lon,lat\n" + "".join(f"{a:.6f},42.600000\n" for a in lon))
    err = _bad(capsys, ["mesh", src, "-o", out, "--cells", "200", "-q"], "line.csv", "on one line", "--cell-size")
    assert "across at its widest (near (7" in err  # the place, in the grid's UTM metres
    assert not out.exists()


def _kml(placemarks: str) -> str:
    return f'<kml xmlns="http://www.opengis.net/kml/2.2"><Document>{placemarks}</Document></kml>'


def _placemark(name: str, kind: str, pts) -> str:
    c = " ".join(f"{lo},{la},0" for lo, la in pts)
    geom = (
        f"<Polygon><outerBoundaryIs><LinearRing><coordinates>{c}</coordinates></LinearRing></outerBoundaryIs></Polygon>"
        if kind == "ring"
        else f"<LineString><coordinates>{c}</coordinates></LineString>"
    )
    return f"<Placemark><name>{name}</name>{geom}</Placemark>"


def test_an_open_line_far_from_the_lake_is_not_said_to_be_in_the_water(tmp_path):
    from meshcore.cli.lakefile import without_lines_on_the_shore
    from meshcore.io import read_points

    t = np.linspace(0, 2 * np.pi, 24)
    lake = np.c_[8.5 + 0.02 * np.cos(t), 47.3 + 0.01 * np.sin(t)]
    ferry = [(8.49, 47.3), (8.51, 47.3)]  # across the water
    road = [(9.5, 47.3), (9.6, 47.35)]  # 75 km east, on land
    f = tmp_path / "lake.kml"
    f.write_text(
        _kml(_placemark("lake", "ring", lake) + _placemark("ferry", "line", ferry) + _placemark("road", "line", road))
    )
    kept, notes = without_lines_on_the_shore(read_points(f))
    assert kept.names == ("lake",)
    # was: "'ferry', 'road': open lines in the water (a path, not a ring), not an island: ignored"
    assert notes == [
        "'ferry': an open line in the water (a path, not a ring), not an island: ignored",
        "'road': an open line outside the shore (a path, not a ring), not an island: ignored",
    ]


def test_a_file_without_a_suffix_is_named_in_plain_words(tmp_path, capsys):
    src = tmp_path / "shore"
    src.write_text("x,y\n0,0\n1000,0\n1000,1000\n")
    err = _bad(
        capsys,
        ["mesh", src, "-o", tmp_path / "g.vtm", "-q"],
        "shore: cannot read points from a file without a suffix (known suffixes: .csv",
    )
    assert "suffix files" not in err  # was: "from files without a suffix files"


def test_the_lonlat_order_note_of_a_y_x_header_names_the_columns_as_the_header_does(tmp_path):
    from meshcore.cli.lakefile import lonlat_order_note
    from meshcore.io import read_points

    t = np.linspace(0, 2 * np.pi, 24, endpoint=False)
    f = tmp_path / "yx.csv"
    f.write_text("Y,X\n" + "".join(f"{47.3 + 0.01 * np.sin(a):.6f},{8.5 + 0.02 * np.cos(a):.6f}\n" for a in t))
    ps = read_points(f)
    assert 8.4 < ps.polylines[0].points[:, 0].min() < 8.5  # X is the longitude, as the header says
    # was: "no header says which column is which ... give --columns 1 0" (which swapped them)
    note = lonlat_order_note(ps)
    assert "the header says 'x', 'y'" in note and "--columns 0 1" in note and "no header" not in note


def test_a_grd_of_a_lake_of_several_blocks_is_told_of_single(tmp_path, capsys):
    src, out = tmp_path / "oval.csv", tmp_path / "oval.grd"
    t = np.linspace(0, 2 * np.pi, 60, endpoint=False)
    src.write_text("x,y\n" + "".join(f"{6000 * np.cos(a):.3f},{1500 * np.sin(a):.3f}\n" for a in t))
    # was: "write .vtm, .cgns, .xyz, .ddb, .npz, .su2 or .msh", the way to one Delft3D grid unsaid
    _bad(
        capsys,
        ["mesh", src, "-o", out, "--cells", "300", "-q"],
        "oval.grd",
        "the delft3d format holds one block",
        "--single",
    )
    assert not out.exists()
    assert main(["mesh", str(src), "-o", str(out), "--cells", "300", "-q", "--single"]) == 0
    assert out.exists() and out.with_suffix(".enc").exists()


@pytest.mark.parametrize("decl", ['<?xml version="1.0" encoding="UTF-8"?>\n', '<?xml version="1.0"?>\n', ""])
def test_a_kml_whose_name_was_saved_as_latin_1_is_read(tmp_path, decl):
    from meshcore.io import read_points

    t = np.linspace(0, 2 * np.pi, 24)
    ring = " ".join(f"{8.5 + 0.02 * np.cos(a):.6f},{47.3 + 0.01 * np.sin(a):.6f},0" for a in t)
    f = tmp_path / "see.kml"
    text = (
        f'{decl}<kml xmlns="http://www.opengis.net/kml/2.2"><Document><Placemark><name>Zürichsee Ufer</name>'
        f"<Polygon><outerBoundaryIs><LinearRing><coordinates>{ring}</coordinates></LinearRing></outerBoundaryIs>"
        "</Polygon></Placemark></Document></kml>"
    )
    f.write_bytes(text.encode("latin-1"))  # an 8-bit editor's save: 'ü' as one byte
    ps = read_points(f)  # was: "line 1: not well-formed XML (not well-formed (invalid token) ...)"
    assert ps.names == ("Zürichsee Ufer",) and len(ps.polylines[0].points) == 23


def test_a_kml_declaring_another_encoding_is_read_in_it(tmp_path):
    from meshcore.io import read_points

    t = np.linspace(0, 2 * np.pi, 24)
    ring = " ".join(f"{8.5 + 0.02 * np.cos(a):.6f},{47.3 + 0.01 * np.sin(a):.6f},0" for a in t)
    f = tmp_path / "see.kml"
    text = (
        '<?xml version="1.0" encoding="ISO-8859-1"?>\n<kml xmlns="http://www.opengis.net/kml/2.2"><Document>'
        f"<Placemark><name>Zürichsee</name><Polygon><outerBoundaryIs><LinearRing><coordinates>{ring}"
        "</coordinates></LinearRing></outerBoundaryIs></Polygon></Placemark></Document></kml>"
    )
    f.write_bytes(text.encode("latin-1"))
    assert read_points(f).names == ("Zürichsee",)


@pytest.mark.parametrize("sep", [",", " ", "\t"])
def test_a_headerless_point_number_column_is_not_read_as_x(tmp_path, sep):
    from meshcore.cli.lakefile import lonlat_order_note
    from meshcore.io import read_points

    t = np.linspace(0, 2 * np.pi, 24, endpoint=False)
    lon, lat = 8.5 + 0.02 * np.cos(t), 47.3 + 0.01 * np.sin(t)
    f = tmp_path / "n_lat_lon.txt"
    f.write_text("".join(f"{k + 1}{sep}{b:.6f}{sep}{a:.6f}\n" for k, (a, b) in enumerate(zip(lon, lat, strict=True))))
    ps = read_points(f)
    # was: the point number read as x (1 … 24 against the latitude: "the outline crosses itself")
    np.testing.assert_allclose(ps.polylines[0].points, np.c_[lat, lon], atol=1e-6)
    assert "give --columns 2 1" in lonlat_order_note(ps)  # the swap that reads it right


def test_a_headerless_first_column_that_is_not_a_count_stays_x(tmp_path):
    from meshcore.io import read_points

    f = tmp_path / "xyz.txt"
    f.write_text("0 0 5\n4000 0 6\n4000 2000 7\n0 2000 8\n")
    np.testing.assert_allclose(read_points(f).polylines[0].points, [[0, 0], [4000, 0], [4000, 2000], [0, 2000]])


def test_an_island_touching_the_shore_at_a_point_is_said_to_touch_it(tmp_path, capsys):
    src = tmp_path / "touch.csv"
    shore = [(0, 0), (4000, 0), (4000, 2000), (0, 2000)]
    isle = [(2000, 0), (2400, 600), (1600, 600), (2000, 0)]  # one corner on the shore's bottom edge
    src.write_text(
        "x,y,ring\n" + "".join(f"{x},{y},shore\n" for x, y in shore) + "".join(f"{x},{y},isle\n" for x, y in isle)
    )
    # was: "'isle' crosses the shore", for a ring inside the water that only reaches it
    _bad(capsys, ["mesh", src, "-o", tmp_path / "t.vtm", "-q"], "'isle' touches the shore of 'shore' near (2000, 0)")


def test_crs_of_a_file_of_metres_that_does_not_say_its_crs_tells_source_crs(tmp_path, capsys):
    src = tmp_path / "utm.csv"
    src.write_text("x,y\n240000,4719000\n244000,4719000\n244000,4721000\n240000,4721000\n")
    # was: "the points' CRS is unknown (give source_crs / --source-crs)"
    _bad(capsys, ["mesh", src, "--crs", "EPSG:32633", "-o", tmp_path / "g.vtm", "-q"], "--source-crs EPSG:32633")
    # was: "crs: unknown CRS ..." (no option named)
    _bad(
        capsys,
        ["mesh", src, "--crs", "EPSG:9999999", "-o", tmp_path / "g.vtm", "-q"],
        "--crs EPSG:9999999: unknown CRS",
    )


@pytest.mark.parametrize(
    ("body", "needle"),
    [
        (
            "<NetworkLink><name>lakes</name><Link><href>http://example.com/lakes.kml</href></Link></NetworkLink>",
            "network link to 'http://example.com/lakes.kml'",
        ),
        (
            "<GroundOverlay><Icon><href>map.png</href></Icon><LatLonBox><north>42.7</north><south>42.5</south>"
            "<east>12.0</east><west>11.8</west></LatLonBox></GroundOverlay>",
            "image overlays (a picture, no outline)",
        ),
    ],
)
def test_a_kml_without_shapes_says_what_it_holds_instead(tmp_path, capsys, body, needle):
    src = tmp_path / "saved.kml"
    src.write_text(f'<?xml version="1.0" encoding="UTF-8"?><kml xmlns="http://www.opengis.net/kml/2.2">{body}</kml>')
    # was: "no coordinates: none of 0 placemark(s) has a LineString ..." and nothing on why
    _bad(capsys, ["mesh", src, "-o", tmp_path / "g.vtm", "-q"], "saved.kml: no coordinates", needle)


def test_a_figure_of_an_unknown_suffix_lists_the_figure_suffixes(tmp_path, capsys):
    src = tmp_path / "lake.csv"
    src.write_text("x,y\n0,0\n4000,0\n4000,2000\n0,2000\n")
    # was: "cannot write .jpg files (known suffixes: .cgns .csv .ddb .g .grd .inp ...)"
    err = _bad(capsys, ["mesh", src, "--png", tmp_path / "look.jpg", "-q"], "--png", "look.jpg: expected a figure file")
    assert ".cgns" not in err


@pytest.mark.parametrize("part", [".dbf", ".shx", ".prj"])
def test_a_shapefile_opened_by_another_of_its_files_names_the_shp(tmp_path, capsys, part):
    for suffix in (".shp", ".shx", ".dbf", ".prj"):
        (tmp_path / f"lake{suffix}").write_bytes(b"x")
    # was: "cannot read points from .dbf files (known suffixes: ...)"
    _bad(capsys, ["mesh", tmp_path / f"lake{part}", "-o", tmp_path / "g.vtm", "-q"], "give its .shp", "lake.shp")


def test_a_topojson_file_is_named_as_such(tmp_path, capsys):
    src = tmp_path / "lake.json"
    src.write_text(
        '{"type":"Topology","objects":{"lake":{"type":"Polygon","arcs":[[0]]}},"arcs":[[[0,0],[1,0],[0,1]]]}'
    )
    # was: "unsupported geometry type 'Topology'"
    _bad(capsys, ["mesh", src, "-o", tmp_path / "g.vtm", "-q"], "TopoJSON", "convert it to GeoJSON")


def test_import_of_points_on_a_line_is_refused_unless_cells_are_given(tmp_path, capsys):
    """``meshcore import`` of the same points wrote a one-block case 4 cm wide that ``generate``
    solved (session 22's sweep, left then); now exit 2 naming the place, no case file; with
    ``--cells`` the user's block is written."""
    src, out = tmp_path / "line.csv", tmp_path / "line.toml"
    lon = 11.9 + 0.001 * np.arange(20)
    src.write_text("lon,lat\n" + "".join(f"{a:.6f},42.600000\n" for a in lon))
    err = _bad(capsys, ["import", src, "-o", out], "line.csv", "on one line", "--cells")
    assert "across at its widest (near (7" in err
    assert not out.exists()
    assert main(["import", str(src), "-o", str(out), "--cells", "40", "2"]) == 0 and out.exists()


def test_import_of_a_triangle_says_that_meshcore_mesh_grids_it(tmp_path, capsys):
    src, out = tmp_path / "tri.csv", tmp_path / "tri.toml"
    src.write_text("x,y\n0,0\n4000,0\n2000,3000\n")
    # was: "needs at least 4 points, got 3" only; meshcore mesh (and the app's Auto layout) grid it
    _bad(capsys, ["import", src, "-o", out], "tri.csv", "needs at least 4 points, got 3", "meshcore mesh grids")
    assert not out.exists()
    assert main(["mesh", str(src), "-o", str(tmp_path / "tri.vtm"), "--cells", "300", "-q"]) == 0


def test_a_file_of_one_point_says_so_without_a_blank_line_it_does_not_have(tmp_path, capsys):
    src = tmp_path / "one.csv"
    src.write_text("lon,lat\n8.5,47.3\n")
    # was: "polyline 'one' (line 2) has only 1 point (a blank line starts a new polyline)"
    err = _bad(capsys, ["mesh", src, "-o", tmp_path / "g.vtm"], "one.csv: only 1 point (line 2)", "3 or more")
    assert "blank line" not in err
    two = tmp_path / "two.csv"
    two.write_text("x,y\n0,0\n1000,0\n1000,1000\n\n5000,5000\n")  # a stray point after a blank line: still said
    _bad(capsys, ["mesh", two, "-o", tmp_path / "g.vtm"], "(line 6) has only 1 point (a blank line starts")


def test_import_names_the_rings_it_leaves_out(tmp_path, capsys):
    t = np.linspace(0, 2 * np.pi, 30, endpoint=False)
    north = np.c_[8.5 + 0.05 * np.cos(t), 47.3 + 0.03 * np.sin(t)]
    south = np.c_[8.5 + 0.04 * np.cos(t[::2]), 47.2 + 0.02 * np.sin(t[::2])]
    src, out = tmp_path / "two.kml", tmp_path / "two.toml"
    src.write_text(_kml(_placemark("north", "ring", north) + _placemark("south", "ring", south)))
    assert main(["import", str(src), "-o", str(out)]) == 0
    err = capsys.readouterr().err
    # was: 'south' left out without a word
    assert "'north' is imported" in err and "left out ('south')" in err, err
