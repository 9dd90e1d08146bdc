"""Point files as users send them (session 17's odd inputs): a right outline or one clear error."""

from __future__ import annotations

import contextlib
import re

import numpy as np
import pytest

from meshcore.errors import ReadError
from meshcore.io import read_points

RECT = [(0.0, 0.0), (4000.0, 0.0), (4000.0, 2000.0), (0.0, 2000.0)]


def _csv(rows, header="x,y"):
    return header + "\n" + "\n".join(",".join(f"{v:g}" for v in r) for r in rows) + "\n"


@pytest.mark.parametrize("header", ["id,x,y", "fid,x,y", "name,lon,lat"])
def test_a_column_that_numbers_the_points_is_not_a_ring_name(tmp_path, header):
    lonlat = "lon" in header
    pts = [(8.5 + x / 1e5, 47.3 + y / 1e5) for x, y in RECT] if lonlat else RECT
    f = tmp_path / "ids.csv"
    f.write_text(_csv([(k + 1, *p) for k, p in enumerate(pts)], header))
    ps = read_points(f)
    assert len(ps.polylines) == 1
    np.testing.assert_allclose(ps.polylines[0].points, pts)


def test_a_name_column_still_groups_rings(tmp_path):
    f = tmp_path / "named.csv"
    f.write_text(_csv([(1, *p) for p in RECT] + [(2, 100, 100), (2, 200, 100), (2, 200, 200)], "id,x,y"))
    assert [len(pl) for pl in read_points(f).polylines] == [4, 3]


def test_a_shore_cut_by_a_stray_blank_line_is_one_ring(tmp_path):
    f = tmp_path / "blank.csv"
    f.write_text("x,y\n0,0\n4000,0\n4000,2000\n\n0,2000\n0,0\n")
    (pl,) = read_points(f).polylines
    assert pl.closed
    np.testing.assert_allclose(pl.points, RECT)


def test_rings_apart_stay_apart(tmp_path):
    f = tmp_path / "rings.csv"
    f.write_text("x,y\n0,0\n4000,0\n4000,2000\n0,2000\n0,0\n\n100,100\n200,100\n200,200\n100,100\n")
    assert [len(pl) for pl in read_points(f).polylines] == [4, 3]


def _oval(n, cx=0.0, cy=0.0, a=4000.0, b=2000.0):
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    return np.c_[cx + a * np.cos(t), cy + b * np.sin(t)]


@pytest.mark.parametrize("cut", [(20,), (5, 40), (58,)])
def test_a_ring_without_its_closing_point_cut_by_blank_lines_is_one_ring(tmp_path, cut):
    ring = _oval(60)
    rows = [",".join(f"{v:.3f}" for v in p) for p in ring]
    for k in sorted(cut, reverse=True):
        rows.insert(k, "")
    f = tmp_path / "open_blank.csv"
    f.write_text("x,y\n" + "\n".join(rows) + "\n")
    (pl,) = read_points(f).polylines
    np.testing.assert_allclose(pl.points, ring, atol=1e-3)


def test_open_rings_apart_stay_apart(tmp_path):
    shore, island = _oval(60), _oval(12, 500.0, 0.0, 600.0, 400.0)[::-1]
    f = tmp_path / "open_rings.csv"
    f.write_text("x,y\n" + "\n\n".join("\n".join(f"{x:.3f},{y:.3f}" for x, y in r) for r in (shore, island)) + "\n")
    assert [len(pl) for pl in read_points(f).polylines] == [60, 12]


def test_a_one_point_piece_says_blank_lines_split(tmp_path):
    f = tmp_path / "b.csv"
    f.write_text("x,y\n0,0\n\n4000,0\n4000,2000\n0,2000\n")
    with pytest.raises(ReadError) as exc:
        read_points(f)
    assert "line 2" in str(exc.value) and "blank line starts a new polyline" in str(exc.value)


LONLAT = [(8.5 + x / 1e5, 47.3 + y / 1e5) for x, y in RECT]


def test_kml_gx_track_is_a_line(tmp_path):
    whens = "".join(f"<when>2020-01-01T00:00:0{k}Z</when>" for k in range(4))
    coords = "".join(f"<gx:coord>{lo} {la} 312</gx:coord>" for lo, la in LONLAT)
    f = tmp_path / "walk.kml"
    f.write_text(
        '<kml xmlns="http://www.opengis.net/kml/2.2" xmlns:gx="http://www.google.com/kml/ext/2.2"><Document>'
        f"<Placemark><name>shore walk</name><gx:MultiTrack><gx:Track>{whens}{coords}</gx:Track></gx:MultiTrack>"
        "</Placemark></Document></kml>"
    )
    ps = read_points(f)
    assert ps.crs == "EPSG:4326" and ps.names == ("shore walk",)
    np.testing.assert_allclose(ps.polylines[0].points, LONLAT)
    f.write_text(f.read_text().replace(f"{LONLAT[2][0]} {LONLAT[2][1]} 312", "8.5,47.3"))
    with pytest.raises(ReadError, match=r"placemark 1 \(shore walk\) gx:Track: gx:coord 3 '8.5,47.3'"):
        read_points(f)


def _gpx(body: str) -> str:
    return f'<?xml version="1.0"?><gpx version="1.1" xmlns="http://www.topografix.com/GPX/1/1">{body}</gpx>'


def test_gpx_tracks_routes_and_waypoints(tmp_path):
    pts = "".join(f'<trkpt lat="{la}" lon="{lo}"><ele>300</ele></trkpt>' for lo, la in [*LONLAT, LONLAT[0]])
    rte = "".join(f'<rtept lat="{la}" lon="{lo}"/>' for lo, la in LONLAT[:2])
    wpt = "".join(f'<wpt lat="{la}" lon="{lo}"><name>w</name></wpt>' for lo, la in LONLAT[:3])
    f = tmp_path / "gps.gpx"
    f.write_text(_gpx(f"{wpt}<trk><name>shore</name><trkseg>{pts}</trkseg></trk><rte>{rte}</rte>"))
    ps = read_points(f)
    assert ps.crs == "EPSG:4326" and ps.names == ("shore", "route 5", "gps waypoints")
    assert ps["shore"].closed
    np.testing.assert_allclose(ps["shore"].points, LONLAT)


@pytest.mark.parametrize(
    ("body", "needle"),
    [
        ("<metadata/>", "no track, route or two or more waypoints"),
        ('<trk><name>t</name><trkseg><trkpt lat="47" lon="8"/></trkseg></trk>', "trk 't': has 1 point(s)"),
        ('<trk><trkseg><trkpt lat="47" lon="x"/><trkpt lat="47" lon="8"/></trkseg></trk>', "point 1: lat='47' lon='x'"),
        ('<rte><rtept lat="95" lon="8"/><rtept lat="47" lon="8"/></rte>', "outside the lon/lat range"),
    ],
)
def test_bad_gpx_is_one_clear_error(tmp_path, body, needle):
    f = tmp_path / "bad.gpx"
    f.write_text(_gpx(body))
    with pytest.raises(ReadError) as exc:
        read_points(f)
    assert needle in str(exc.value) and str(f) in str(exc.value) and "\n" not in str(exc.value)


@pytest.mark.parametrize(("lat", "epsg"), [(89.5, "EPSG:5041"), (-85.0, "EPSG:5042"), (83.0, "EPSG:32631")])
def test_a_lake_beyond_utm_goes_to_polar_stereographic(lat, epsg):
    pyproj = pytest.importorskip("pyproj")
    from meshcore.crs import project
    from meshcore.io import PointSet, Polyline

    t = np.linspace(0, 2 * np.pi, 40, endpoint=False)
    lon, la = 0.3 * np.cos(t), lat + 0.02 * np.sin(t)  # ~2 km across
    local, frame = project(PointSet((Polyline("lake", np.column_stack([lon, la])),), "EPSG:4326"))
    assert frame.crs == epsg  # was: "no UTM zone for lon=0, lat=89.5" for the first two
    p = local.polylines[0].points
    edges = np.hypot(*np.diff(np.vstack([p, p[:1]]), axis=0).T)
    _, _, geodesic = pyproj.Geod(ellps="WGS84").inv(lon, la, np.roll(lon, -1), np.roll(la, -1))
    np.testing.assert_allclose(edges, geodesic, rtol=0.01)  # lengths true to 1 % (UPS scale 0.994 at the pole)


def test_a_spike_out_and_back_is_left_out_with_a_note():
    from meshcore.layout.polygon import water_polygon

    shore = [(0, 0), (2000, 0), (2000, -700), (2000, 0), (4000, 0), (4000, 2000), (2000, 2000), (0, 2000)]
    isle = [(1000, 800), (1500, 800), (1500, 1200), (1800, 1500), (1500, 1200), (1000, 1200)]
    poly, notes = water_polygon(shore, holes=[isle])  # was: "the outline crosses itself"
    assert poly.area == pytest.approx(4000 * 2000 - 500 * 400)
    assert sorted(map(tuple, np.asarray(poly.exterior.coords)[:-1].tolist())) == sorted(
        [(0.0, 0.0), (2000.0, 0.0), (4000.0, 0.0), (4000.0, 2000.0), (2000.0, 2000.0), (0.0, 2000.0)]
    )
    assert any("the outline goes out to a point and straight back" in n and "near (2000, -700)" in n for n in notes)
    assert any(n.startswith("island 1 goes out") and "near (1800, 1500)" in n for n in notes)


def test_a_straight_ring_is_refused_as_having_no_area():
    from meshcore.errors import InvalidInputError
    from meshcore.layout.polygon import water_polygon

    line = [(100.0 * k, 50.0 * k) for k in range(20)]
    with pytest.raises(InvalidInputError, match=r"the outline has no area: its 20 points lie on one straight line"):
        water_polygon(line)  # was: "crosses itself: the edge from point 2 to 3 meets …"


def test_a_ring_that_goes_on_straight_keeps_its_points():
    from meshcore.layout.polygon import water_polygon

    poly, notes = water_polygon([(0, 0), (2000, 0), (4000, 0), (4000, 2000), (0, 2000)])
    assert len(poly.exterior.coords) == 6 and not notes


def test_ctrl_c_while_the_command_loads_is_one_line_exit_130(monkeypatch, capsys):
    from meshcore import cli

    def interrupted(*_a, **_k):
        raise KeyboardInterrupt

    monkeypatch.setattr(cli, "build_parser", interrupted)  # Ctrl-C while numba loads the kernels
    assert cli.main(["mesh", "x.csv", "-o", "x.vtm"]) == 130
    assert capsys.readouterr().err == "meshcore: interrupted\n"  # was: a KeyboardInterrupt traceback


def test_ctrl_c_during_the_solve_leaves_no_output(tmp_path, monkeypatch, capsys):
    from meshcore import cli, lakegrid

    def interrupted(*_a, **_k):
        raise KeyboardInterrupt

    monkeypatch.setattr(lakegrid, "mesh_layout", interrupted)
    f = tmp_path / "lake.csv"
    f.write_text(_csv(RECT))
    out = tmp_path / "out"
    out.mkdir()
    rc = cli.main(
        ["mesh", str(f), "-q", "-o", str(out / "g.vtm"), "-o", str(out / "g.cgns"), "--png", str(out / "g.png")]
    )
    assert rc == 130 and capsys.readouterr().err.strip().endswith("interrupted")
    assert list(out.iterdir()) == []


def test_degrees_without_a_header_are_noted_as_read_lon_lat(tmp_path):
    from meshcore.cli.lakefile import lonlat_order_note

    t = np.linspace(0, 2 * np.pi, 30, endpoint=False)
    ring = np.column_stack([8.5 + 0.02 * np.cos(t), 47.3 + 0.01 * np.sin(t)])
    lat_lon = tmp_path / "gps.csv"  # a GPS export: latitude first, no header
    lat_lon.write_text("".join(f"{la:.6f},{lo:.6f}\n" for lo, la in ring))
    note = lonlat_order_note(read_points(lat_lon))
    assert note is not None and "read as longitude, latitude" in note and "--columns 1 0" in note
    assert lonlat_order_note(read_points(lat_lon), columns=("1", "0")) is None
    header = tmp_path / "h.csv"
    header.write_text("lat,lon\n" + "".join(f"{la:.6f},{lo:.6f}\n" for lo, la in ring))
    assert lonlat_order_note(read_points(header)) is None
    west = tmp_path / "w.csv"  # a longitude beyond ±90: the order is not in doubt
    west.write_text("".join(f"{lo - 100:.6f},{la:.6f}\n" for lo, la in ring))
    assert lonlat_order_note(read_points(west)) is None


def test_mesh_notes_the_column_order_it_assumed(tmp_path, capsys):
    from meshcore import cli

    t = np.linspace(0, 2 * np.pi, 30, endpoint=False)
    f = tmp_path / "gps.csv"
    f.write_text("".join(f"{47.3 + 0.01 * np.sin(a):.6f},{8.5 + 0.02 * np.cos(a):.6f}\n" for a in t))
    assert cli.main(["mesh", str(f), "--cells", "200", "-o", str(tmp_path / "g.vtm")]) == 0
    err = capsys.readouterr().err
    assert "note: " in err and "read as longitude, latitude (x, y)" in err and "--columns 1 0" in err


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("lat,lon\n46°6'0.0\"N,10°19'30\"E\n46°7'0\"N,10°19'30\"E\n46°7'0\"N,10°21'0\"E\n", None),
        ("lat;lon\n46 6 0.0 N;10 19 30 E\n46 7 0 N;10 19 30 E\n46 7 0 N;10 21 0 E\n", None),
        ("46°6.0'N,10°19.5'E\n46°7.0'N,10°19.5'E\n46°7'N,10°21'E\n", None),  # no header: N/S say which
        ("x,y\n10°19'30\"E,46°6'0\"N\n10°19'30\"E,46°7'0\"N\n10°21'0\"E,46°7'0\"N\n", None),
        ("S46°6'0\",W10°19'30\"\nS46°7'0\",W10°19'30\"\nS46°7'0\",W10°21'0\"\n", "south-west"),
    ],
    ids=["symbols", "spaces", "decimal-minutes", "lon-first", "hemisphere-first"],
)
def test_degrees_minutes_seconds_are_lon_lat(tmp_path, text, expected):
    f = tmp_path / "dms.csv"
    f.write_text(text, encoding="utf-8")
    ps = read_points(f)  # was: "line 2: not a number in column 2 or 1"
    want = np.array([[10.325, 46.1], [10.325, 46.1 + 1 / 60], [10.35, 46.1 + 1 / 60]])
    if expected == "south-west":
        want = -want
    assert ps.crs == "EPSG:4326"
    np.testing.assert_allclose(ps.polylines[0].points, want, atol=1e-12)


def test_a_bad_degrees_minutes_seconds_value_is_named(tmp_path):
    f = tmp_path / "dms.csv"
    f.write_text("lat,lon\n46°6'0\"N,10°19'30\"E\n46°7'0\"N,10°79'30\"E\n46°7'0\"N,10°21'0\"E\n", encoding="utf-8")
    with pytest.raises(ReadError, match=r"line 3: not a number in column 2 \(nor degrees, minutes, seconds"):
        read_points(f)


@pytest.mark.parametrize(
    ("header", "crs"),
    [("Breite;Länge", "EPSG:4326"), ("latitud;longitud", "EPSG:4326"), ("Hochwert;Rechtswert", None)],
)
def test_headers_of_other_languages_put_the_columns_the_right_way_round(tmp_path, header, crs):
    f = tmp_path / "p.csv"
    pts = np.array([[10.33, 46.1], [10.32, 46.11], [10.31, 46.1]]) * (1 if crs else 1e5)
    f.write_text(header + "\n" + "".join(f"{y:.6f};{x:.6f}\n".replace(".", ",") for x, y in pts), encoding="utf-8")
    ps = read_points(f)  # was: the first column read as x (longitude), silently swapped
    assert ps.crs == crs
    np.testing.assert_allclose(ps.polylines[0].points, pts)


@pytest.mark.parametrize("pond_first", [False, True])
def test_a_pond_on_an_island_is_left_out_as_such(pond_first):
    from meshcore.layout.polygon import water_polygon

    shore = [(0, 0), (4000, 0), (4000, 2000), (0, 2000)]
    isle = [(1000, 500), (2000, 500), (2000, 1500), (1000, 1500)]
    pond = [(1400, 900), (1600, 900), (1600, 1100), (1400, 1100)]
    poly, notes = water_polygon(shore, holes=[pond, isle] if pond_first else [isle, pond])
    assert len(poly.interiors) == 1 and poly.area == pytest.approx(8e6 - 1e6)
    # was: "islands 1 and 2 touch: joined into one"
    assert any("lies inside island" in n and "near (1500, 1000)" in n and "pond" in n for n in notes), notes


def test_pins_beside_a_lake_polygon_are_named_as_points(tmp_path):
    from meshcore.cli.lakefile import without_lines_on_the_shore

    ring = " ".join(f"{lo},{la}" for lo, la in [*LONLAT, LONLAT[0]])
    pins = "".join(
        f"<Placemark><name>{n}</name><Point><coordinates>{lo},{la}</coordinates></Point></Placemark>"
        for n, lo, la in (("pier", 8.52, 47.301), ("car park", 8.6, 47.4))
    )
    f = tmp_path / "lake.kml"
    f.write_text(
        '<kml xmlns="http://www.opengis.net/kml/2.2"><Document><Placemark><name>lake</name><Polygon><outerBoundaryIs>'
        f"<LinearRing><coordinates>{ring}</coordinates></LinearRing></outerBoundaryIs></Polygon></Placemark>{pins}"
        "</Document></kml>"
    )
    kept, notes = without_lines_on_the_shore(read_points(f))
    assert kept.names == ("lake",)
    # was: "'lake points': an open line touching the shore, not an island: ignored"
    assert notes == ["'lake points': 2 single points (placemarks, pins), not a line or a ring: ignored"]


def test_mesh_can_only_draw_the_grid(tmp_path, capsys):
    from meshcore import cli

    f = tmp_path / "lake.csv"
    f.write_text(_csv([(2000 * np.cos(a), 1000 * np.sin(a)) for a in np.linspace(0, 6.2, 30)]))
    png = tmp_path / "look.png"
    assert cli.main(["mesh", str(f), "--cells", "200", "-q", "--png", str(png)]) == 0  # was: "-o is required"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert cli.main(["mesh", str(f), "--cells", "200"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "nothing to write: give -o OUT" in err


def test_web_mercator_metres_go_to_utm():
    pyproj = pytest.importorskip("pyproj")
    from meshcore.cli.lakefile import local_frame
    from meshcore.crs import is_web_mercator
    from meshcore.io import PointSet, Polyline

    t = np.linspace(0, 2 * np.pi, 40, endpoint=False)
    lon, lat = 10.3 + 0.03 * np.cos(t), 46.1 + 0.01 * np.sin(t)
    x, y = pyproj.Transformer.from_crs(4326, 3857, always_xy=True).transform(lon, lat)
    merc = PointSet((Polyline("lake", np.column_stack([x, y])),), "EPSG:3857")
    deg = PointSet((Polyline("lake", np.column_stack([lon, lat])),), "EPSG:4326")
    assert is_web_mercator("EPSG:3857") and not is_web_mercator("EPSG:32632") and not is_web_mercator("EPSG:4326")
    (a, fa), (b, fb) = local_frame(merc), local_frame(deg)
    assert fa.crs == fb.crs == "EPSG:32632" and fa.origin == fb.origin  # was: EPSG:3857, areas 2.08 times too large
    np.testing.assert_allclose(a.polylines[0].points, b.polylines[0].points, atol=1e-6)


def test_two_lakes_of_one_name_are_told_apart_by_place(tmp_path, capsys):
    from meshcore import cli

    def poly(dlon):
        ring = " ".join(f"{8.5 + dlon + 0.02 * np.cos(a):.6f},{47.3 + 0.01 * np.sin(a):.6f}" for a in T30)
        ring = f"<LinearRing><coordinates>{ring}</coordinates></LinearRing>"
        return f"<Polygon><outerBoundaryIs>{ring}</outerBoundaryIs></Polygon>"

    T30 = np.linspace(0, 2 * np.pi, 30)
    f = tmp_path / "lakes.kml"
    f.write_text(
        '<kml xmlns="http://www.opengis.net/kml/2.2"><Placemark><name>lakes</name><MultiGeometry>'
        f"{poly(0.0)}{poly(0.2)}</MultiGeometry></Placemark></kml>"
    )
    # was exit 2, "one lake per file" (the place in the grid's CRS); now both are meshed, listed with
    # their centroids in the file's coordinates (lon/lat), which tell them apart
    assert cli.main(["mesh", str(f), "--cells", "300", "-o", str(tmp_path / "g.vtm"), "-q"]) == 0
    err = capsys.readouterr().err
    assert err == "", err
    assert cli.main(["mesh", str(f), "--cells", "300", "-o", str(tmp_path / "g.vtm")]) == 0
    err = capsys.readouterr().err
    assert "part 1: 'lakes', area" in err and "part 2: 'lakes', area" in err
    assert len(re.findall(r"centroid lon 8\.50000, lat 47\.30000|centroid lon 8\.70000, lat 47\.30000", err)) == 2, err
    # the app's one-lake reading names the second part by its place
    from meshcore.errors import InvalidInputError
    from meshcore.layout.polygon import water_from_points

    with pytest.raises(
        InvalidInputError, match=r"'lakes' near \(8\.[57]\d*, 47\.3\d*\) lies outside the outline 'lakes'"
    ):
        water_from_points(read_points(f))


def test_no_column_order_note_for_a_shapefile_without_prj(tmp_path):
    shapefile = pytest.importorskip("shapefile")
    from meshcore.cli.lakefile import lonlat_order_note

    t = np.linspace(0, 2 * np.pi, 30, endpoint=False)
    ring = [(8.5 + 0.02 * np.cos(a), 47.3 + 0.01 * np.sin(a)) for a in t][::-1]
    with contextlib.ExitStack() as files:  # pyshp 3.1.9's Writer leaves the .dbf it opens unclosed
        f = {e: files.enter_context(open(tmp_path / f"lake.{e}", "wb")) for e in ("shp", "shx", "dbf")}
        with shapefile.Writer(shapeType=shapefile.POLYGON, **f) as w:
            w.field("name", "C")
            w.poly([[*ring, ring[0]]])
            w.record("lake")
    assert lonlat_order_note(read_points(tmp_path / "lake.shp")) is None  # x, y is lon, lat in a shapefile
