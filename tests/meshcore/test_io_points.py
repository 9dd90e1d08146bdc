"""Point-file readers on real lake files and on bad input (one-line ReadError messages)."""

from __future__ import annotations

import shutil
import tempfile
import zipfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from meshcore.errors import ReadError
from meshcore.io import read_points
from tests.conftest import DATA

ZURICH_CSV = np.loadtxt(DATA / "lake_zurich_sparse.csv", delimiter=",", skiprows=1)
WINDERMERE_CSV = np.loadtxt(DATA / "windermere_sparse.csv", delimiter=",", skiprows=1)


def _one_line(exc: pytest.ExceptionInfo) -> str:
    msg = str(exc.value)
    assert "\n" not in msg
    return msg


# ------------------------------------------------------------ real lake files
@pytest.mark.parametrize("name", ["lake_zurich_sparse.kml", "lake_zurich_sparse.kmz", "lake_zurich_sparse.geojson"])
def test_zurich_ring_formats_agree_with_the_csv(name):
    ps = read_points(DATA / name)
    assert ps.crs == "EPSG:4326"
    (pl,) = ps.polylines
    assert pl.name.startswith("Lake Zurich")
    # the closing point is dropped: the ring holds exactly the CSV's vertices
    assert pl.closed and pl.orientation == "ccw"
    np.testing.assert_array_equal(pl.points, ZURICH_CSV)


def test_csv_lake_lonlat_header():
    ps = read_points(DATA / "lake_zurich_sparse.csv")
    assert ps.crs == "EPSG:4326"
    (pl,) = ps.polylines
    np.testing.assert_array_equal(pl.points, ZURICH_CSV)
    assert not pl.closed  # implicit ring: the file does not repeat its first point


def test_csv_closed_forced():
    pl = read_points(DATA / "windermere_sparse.csv", closed=True).polylines[0]
    assert pl.closed and pl.orientation == "ccw"


def test_shapefile_polygon_with_prj():
    ps = read_points(DATA / "windermere_sparse.shp")
    assert ps.crs == "EPSG:4326"
    (pl,) = ps.polylines
    assert pl.name == "Windermere"
    assert pl.closed and pl.orientation == "cw"  # ESRI outer rings run clockwise
    # same vertex set as the CSV, in reverse order
    got = pl.points[::-1]
    k = int(np.flatnonzero((got == WINDERMERE_CSV[0]).all(axis=1))[0])
    np.testing.assert_array_equal(np.roll(got, -k, axis=0), WINDERMERE_CSV)


def test_dxf_polyline_and_spline_in_utm():
    pyproj = pytest.importorskip("pyproj")
    ps = read_points(DATA / "lake_zurich_sparse_utm32.dxf")
    assert ps.crs is None  # DXF carries no CRS
    shore, inlet = ps.polylines
    assert shore.name.startswith("shore") and shore.closed
    t = pyproj.Transformer.from_crs("EPSG:4326", "EPSG:32632", always_xy=True)
    E, N = t.transform(ZURICH_CSV[:, 0], ZURICH_CSV[:, 1])
    np.testing.assert_allclose(shore.points, np.column_stack([E, N]), rtol=0, atol=1e-6)
    # the flattened spline starts and ends at its end control points
    assert inlet.name.startswith("inlet") and not inlet.closed and len(inlet) > 8
    np.testing.assert_allclose(inlet.points[0], [E[0], N[0]], atol=1e-6)
    np.testing.assert_allclose(inlet.points[-1], [E[7], N[7]], atol=1e-6)


def test_kml_several_placemarks_lines_and_points(tmp_path):
    f = tmp_path / "mixed.kml"
    f.write_text(
        '<?xml version="1.0" encoding="UTF-8"?>\n<kml xmlns="http://www.opengis.net/kml/2.2">'
        "<Document><Folder>"
        "<Placemark><name>inlet</name><LineString><coordinates>8.5,47.3 8.6,47.3,12\n"
        "8.7,47.35</coordinates></LineString></Placemark>"
        "<Placemark><name>p1</name><Point><coordinates>8.5,47.2,0</coordinates></Point></Placemark>"
        "<Placemark><name>p2</name><Point><coordinates>8.6,47.2,0</coordinates></Point></Placemark>"
        "<Placemark><name>p3</name><Point><coordinates>8.6,47.1,0</coordinates></Point></Placemark>"
        "<Placemark><name>island</name><MultiGeometry><Polygon><outerBoundaryIs><LinearRing>"
        "<coordinates>8.55,47.25 8.56,47.25 8.56,47.26 8.55,47.25</coordinates></LinearRing>"
        "</outerBoundaryIs><innerBoundaryIs><LinearRing><coordinates>8.552,47.252 8.553,47.253 "
        "8.553,47.252 8.552,47.252</coordinates></LinearRing></innerBoundaryIs></Polygon>"
        "</MultiGeometry></Placemark>"
        "</Folder></Document></kml>",
        encoding="utf-8",
    )
    ps = read_points(f)
    assert ps.names == ("inlet", "mixed points", "island", "island hole 1")
    assert not ps["inlet"].closed and len(ps["inlet"]) == 3
    np.testing.assert_array_equal(ps["mixed points"].points, [[8.5, 47.2], [8.6, 47.2], [8.6, 47.1]])
    assert ps["island"].closed and len(ps["island"]) == 3 and ps["island"].orientation == "ccw"
    assert ps["island hole 1"].orientation == "cw"


def test_geojson_multi_geometries(tmp_path):
    f = tmp_path / "m.geojson"
    f.write_text(
        '{"type": "FeatureCollection", "features": ['
        '{"type": "Feature", "properties": {"name": "a"}, "geometry": {"type": '
        '"MultiLineString", "coordinates": [[[1, 2], [3, 4]], [[5, 6], [7, 8], [9, 9]]]}},'
        '{"type": "Feature", "id": "b", "properties": null, "geometry": {"type": '
        '"MultiPolygon", "coordinates": [[[[10, 10], [11, 10], [11, 11], [10, 10]]]]}}]}'
    )
    ps = read_points(f)
    assert ps.names == ("a 1", "a 2", "b")
    assert ps["b"].closed and len(ps["b"]) == 3


# ------------------------------------------------------------ CSV dialects
@pytest.mark.parametrize(
    ("text", "crs", "expected"),
    [
        (
            "# survey\nlat;lon\n47,30;8,50\n47,31;8,52\n47,33;8,55\n",
            "EPSG:4326",
            [[8.50, 47.30], [8.52, 47.31], [8.55, 47.33]],
        ),
        ("x\ty\tz\n1\t2\t0\n3\t4\t0\n5\t6\t0\n", None, [[1, 2], [3, 4], [5, 6]]),
        ("% gnuplot style\n1.0 2.0\n3.0   4.0  # trailing comment\n5 6\n", None, [[1, 2], [3, 4], [5, 6]]),
        (
            "Easting (m),Northing (m)\n500000.5,5200000.25\n500010,5200001\n",
            None,
            [[500000.5, 5200000.25], [500010, 5200001]],
        ),
        ("1d0 2D0\n3.5E+00 4\n", None, [[1, 2], [3.5, 4]]),
    ],
)
def test_csv_dialects(tmp_path, text, crs, expected):
    f = tmp_path / "p.txt"
    f.write_text(text, encoding="utf-8")
    ps = read_points(f)
    assert ps.crs == crs
    np.testing.assert_allclose(ps.polylines[0].points, expected)


def test_csv_segments_and_name_column(tmp_path):
    f = tmp_path / "s.xy"
    f.write_text("> shore\n0 0\n1 0\n1 1\n0 0\n\n> inlet\n5 5\n6 6\n", encoding="utf-8")
    ps = read_points(f)
    assert ps.names == ("shore", "inlet")
    assert ps["shore"].closed and len(ps["shore"]) == 3
    g = tmp_path / "n.csv"
    g.write_text("name,x,y\na,0,0\na,1,0\nb,5,5\nb,6,5\n", encoding="utf-8")
    assert read_points(g).names == ("a", "b")


def test_csv_user_columns(tmp_path):
    f = tmp_path / "c.csv"
    f.write_text("id,depth,east,north\n1,5,10,20\n2,6,11,21\n", encoding="utf-8")
    ps = read_points(f, columns=("east", "north"))
    np.testing.assert_array_equal(ps.polylines[0].points, [[10, 20], [11, 21]])
    ps = read_points(f, columns=(2, 3))
    np.testing.assert_array_equal(ps.polylines[0].points, [[10, 20], [11, 21]])


# ------------------------------------------------------------ bad input
def _write(tmp_path, name, data):
    f = tmp_path / name
    (f.write_bytes if isinstance(data, bytes) else f.write_text)(data)
    return f


@pytest.mark.parametrize(
    ("name", "data", "needle"),
    [
        ("empty.csv", "", "empty"),
        ("blank.csv", "\n  \n# only a comment\n", "no data lines"),
        ("words.csv", "name,kind\nfoo,bar\nbaz,qux\n", "no numeric"),
        ("words2.txt", "foo bar\nbaz qux\n", "no numeric"),
        ("range.csv", "lon,lat\n8.5,47.3\n8.6,97.3\n", "outside the lon/lat range"),
        ("mixed.csv", "1,2\n3,4,5\n6,7\n", "line 2: mixed dimensions"),
        ("mixed.geojson", '{"type": "LineString", "coordinates": [[1, 2], [3, 4, 5]]}', "mixed dimensions"),
        ("bad.geojson", '{"type": "LineString", "coordinates": [[1, 2], ', "line 1"),
        (
            "nocoords.kml",
            '<kml xmlns="http://www.opengis.net/kml/2.2"><Document><Placemark>'
            "<name>x</name></Placemark></Document></kml>",
            "no coordinates",
        ),
        (
            "emptycoords.kml",
            "<kml><Placemark><LineString><coordinates> </coordinates></LineString></Placemark></kml>",
            "empty <coordinates>",
        ),
        ("notxml.kml", "<kml><Placemark>", "not well-formed"),
        (
            "lonlat.kml",
            "<kml><Placemark><LineString><coordinates>200,10 201,11</coordinates></LineString></Placemark></kml>",
            "outside the lon/lat range",
        ),
        ("one.csv", "x,y\n1,2\n", "only 1 point"),
        ("bad.kmz", b"PK\x03\x04garbage", "corrupt KMZ"),
        ("nul.csv", b"1,2\n\x00\x00\x01", "binary"),
        ("empty.dxf", "", "empty"),
    ],
)
def test_bad_point_files(tmp_path, name, data, needle):
    f = _write(tmp_path, name, data)
    with pytest.raises(ReadError) as exc:
        read_points(f)
    msg = _one_line(exc)
    assert needle in msg and str(f) in msg


def test_billion_laughs_is_refused(tmp_path):
    lol = (
        '<?xml version="1.0"?>\n<!DOCTYPE lolz [\n<!ENTITY lol "lol">\n'
        + "".join(f'<!ENTITY lol{k} "{("&lol" + (str(k - 1) if k > 1 else "") + ";") * 10}">\n' for k in range(1, 10))
        + "]>\n<kml><Placemark><name>&lol9;</name></Placemark></kml>\n"
    )
    f = _write(tmp_path, "lol.kml", lol)
    with pytest.raises(ReadError) as exc:
        read_points(f)
    assert "refused" in _one_line(exc)


def test_external_entity_is_refused(tmp_path):
    xxe = (
        '<?xml version="1.0"?>\n<!DOCTYPE kml [<!ENTITY xxe SYSTEM "file:///etc/passwd">]>\n'
        "<kml><Placemark><name>&xxe;</name></Placemark></kml>"
    )
    f = _write(tmp_path, "xxe.kml", xxe)
    with pytest.raises(ReadError, match="refused"):
        read_points(f)


def test_oversized_kmz_is_refused_before_decompressing(tmp_path, monkeypatch):
    from meshcore.io import kml

    monkeypatch.setattr(kml, "KMZ_LIMIT", 10_000)
    f = tmp_path / "bomb.kmz"
    with zipfile.ZipFile(f, "w", zipfile.ZIP_DEFLATED) as z:
        z.writestr("doc.kml", b" " * 200_000)  # compresses to a few hundred bytes
    assert f.stat().st_size < 2_000
    with pytest.raises(ReadError) as exc:
        read_points(f)
    assert "refused" in _one_line(exc) and "200000" in str(exc.value)


def test_kmz_without_kml(tmp_path):
    f = tmp_path / "nokml.kmz"
    with zipfile.ZipFile(f, "w") as z:
        z.writestr("image.png", b"\x89PNG")
    with pytest.raises(ReadError, match=r"no \.kml"):
        read_points(f)


@pytest.mark.parametrize("missing", [".shx", ".dbf"])
def test_shapefile_missing_sidecar(tmp_path, missing):
    for s in (".shp", ".shx", ".dbf", ".prj"):
        shutil.copy(DATA / f"windermere_sparse{s}", tmp_path / f"w{s}")
    (tmp_path / f"w{missing}").unlink()
    with pytest.raises(ReadError) as exc:
        read_points(tmp_path / "w.shp")
    assert f"missing {missing}" in _one_line(exc)


def test_dxf_without_polylines(tmp_path):
    ezdxf = pytest.importorskip("ezdxf")
    doc = ezdxf.new()
    doc.modelspace().add_circle((0, 0), 1)
    doc.saveas(tmp_path / "c.dxf")
    with pytest.raises(ReadError) as exc:
        read_points(tmp_path / "c.dxf")
    assert "no LWPOLYLINE, POLYLINE or SPLINE" in _one_line(exc)


def test_missing_file_and_unknown_suffix(tmp_path):
    with pytest.raises(ReadError, match="no such file"):
        read_points(tmp_path / "nope.csv")
    f = _write(tmp_path, "a.weird", "1 2\n3 4\n")
    with pytest.raises(ReadError, match=r"cannot read points from \.weird"):
        read_points(f)
    # a format name overrides the suffix
    assert len(read_points(f, format="points-csv").polylines[0]) == 2


@pytest.mark.parametrize(
    ("name", "n", "zone"),
    [
        ("lake_bolsena.kml", 102, 32632),
        ("shasta_lake_sparse.kml", 54, 32610),
        ("lake_bolsena_sparse.geojson", 40, 32632),
    ],
)
def test_more_real_lakes_read_and_project(name, n, zone):
    pytest.importorskip("pyproj")
    from meshcore.crs import project

    ps = read_points(DATA / name)
    (pl,) = ps.polylines
    assert len(pl) == n and pl.closed and pl.orientation == "ccw"
    local, frame = project(ps)
    assert frame.crs == f"EPSG:{zone}"
    lon, lat = frame.to_lonlat(*local.polylines[0].points.T)
    np.testing.assert_allclose(np.column_stack([lon, lat]), pl.points, rtol=0, atol=1e-9)


# ------------------------------------------------- the one-pass parser of plain blocks
@pytest.mark.parametrize(
    ("data", "needle"),
    [
        ("1,2\n3,4,5\n6\n7,8\n", "line 2: mixed dimensions"),  # as many numbers as rows × 2, in the wrong rows
        ("x y\n1 2\n3 4 5\n6\n7 8\n", "line 3: mixed dimensions"),
        ("x,y\n1 2,\n5,6\n7,8\n", "line 2: not a number"),  # a space inside a field, an empty field
        ("1,2,3\n4,,5 6\n7,8,9\n", "line 2: not a number"),
    ],
)
def test_a_line_of_another_width_is_refused_in_a_plain_block(tmp_path, data, needle):
    f = _write(tmp_path, "p.csv", data)
    with pytest.raises(ReadError) as exc:
        read_points(f)
    assert needle in _one_line(exc)


_FIELDS = st.sampled_from(["1", "-2.5", "3e2", ".5", "+7.", "0", "1 2", "", "x", "1e400"])


@settings(max_examples=150, derandomize=True, deadline=None, database=None)
@given(
    rows=st.lists(st.lists(_FIELDS, min_size=2, max_size=4), min_size=2, max_size=6),
    delim=st.sampled_from([",", ";", "\t", " ", "|", ", ", " ; "]),
    pad=st.sampled_from(["", " ", "\t"]),
    header=st.booleans(),
    crlf=st.booleans(),
    chunk=st.sampled_from([8, 40, 1 << 18]),
)
def test_plain_blocks_read_as_the_line_loop_reads_them(rows, delim, pad, header, crlf, chunk):
    """The one-pass parser is a shortcut: every file reads (or fails) exactly as line by line
    (also when it is cut into blocks of a few characters)."""
    from unittest import mock

    from meshcore.io import points_csv

    lines = (["x" + delim + "y"] if header else []) + [pad + delim.join(r) + pad for r in rows]
    text = ("\r\n" if crlf else "\n").join(lines) + "\n"

    def outcome(fast: bool):
        with tempfile.TemporaryDirectory() as d:
            f = _write(Path(d), "p.csv", text)
            fast_points = points_csv._fast_points if fast else (lambda *a: None)
            with (
                mock.patch.object(points_csv, "_fast_points", fast_points),
                mock.patch.object(points_csv, "_CHUNK", chunk),
            ):
                try:
                    return [pl.points.tolist() for pl in read_points(f).polylines]
                except ReadError as exc:
                    return str(exc).replace(d, "")

    assert outcome(True) == outcome(False)
