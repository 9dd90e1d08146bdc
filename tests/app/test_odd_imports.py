"""The app's import of point files that meshcore mesh reads differently or refuses (session 17)."""

from __future__ import annotations

import contextlib

import numpy as np
import pytest

pytestmark = pytest.mark.gui

pyproj = pytest.importorskip("pyproj")
shapefile = pytest.importorskip("shapefile")

T = np.linspace(0, 2 * np.pi, 40, endpoint=False)
LON, LAT = 8.5 + 0.02 * np.cos(T), 47.3 + 0.01 * np.sin(T)  # a lake ~3 km across


def _shapefile(path, crs: int):
    x, y = pyproj.Transformer.from_crs(4326, crs, always_xy=True).transform(LON, LAT)
    ring = list(zip(x[::-1], y[::-1], strict=True))  # shapefile outer rings run clockwise
    # our own file objects: pyshp 3.1.9's Writer leaves the .dbf it opens unclosed (ResourceWarning)
    with contextlib.ExitStack() as files:
        f = {e: files.enter_context(open(path.with_suffix(f".{e}"), "wb")) for e in ("shp", "shx", "dbf")}
        with shapefile.Writer(shapeType=shapefile.POLYGON, **f) as w:
            w.field("name", "C")
            w.poly([[*ring, ring[0]]])
            w.record("lake")
    path.with_suffix(".prj").write_text(pyproj.CRS.from_epsg(crs).to_wkt(pyproj.enums.WktVersion.WKT1_ESRI))
    return np.column_stack([x, y])


def test_a_projected_shapefile_keeps_its_crs(win, tmp_path):
    world = _shapefile(tmp_path / "lake.shp", 2056)
    assert win.io.import_points(tmp_path / "lake.shp")
    p = win.doc.project
    assert p.crs == "EPSG:2056" and tuple(p.origin) == (0.0, 0.0)  # was: no CRS (exports without one)
    assert np.min(np.hypot(*(win.doc.block.points[0] - world).T)) < 1e-6


def test_a_projected_file_goes_into_the_projects_frame(win, tmp_path):
    """Points joining a project that has a frame but no lake (a case opened with its CRS) go into
    that frame; over a lake they replace it (the next test)."""
    import dataclasses

    win.doc.set_project(dataclasses.replace(win.doc.project, crs="EPSG:32632", origin=(460000.0, 5239000.0)))
    frame = (win.doc.project.crs, tuple(win.doc.project.origin))
    _shapefile(tmp_path / "lake.shp", 2056)
    assert win.io.import_points(tmp_path / "lake.shp")
    p = win.doc.project
    assert (p.crs, tuple(p.origin)) == frame
    x, y = pyproj.Transformer.from_crs(4326, 32632, always_xy=True).transform(LON, LAT)
    local = np.column_stack([x - frame[1][0], y - frame[1][1]])
    pts = win.doc.block.points  # was: LV95 metres (2.7e6, 1.2e6) beside UTM metres about the origin
    assert np.abs(pts.mean(axis=0) - local.mean(axis=0)).max() < 5.0


def test_a_projected_lake_over_a_lake_replaces_it_in_its_own_crs(win, tmp_path):
    csv = tmp_path / "a.csv"
    csv.write_text("lon,lat\n" + "\n".join(f"{a},{b}" for a, b in zip(LON + 0.1, LAT, strict=True)) + "\n")
    assert win.io.import_points(csv, project_lonlat=True)
    assert win.doc.project.lake is not None and win.doc.project.crs == "EPSG:32632"
    world = _shapefile(tmp_path / "lake.shp", 2056)
    assert win.io.import_points(tmp_path / "lake.shp")
    p = win.doc.project
    assert p.crs == "EPSG:2056" and tuple(p.origin) == (0.0, 0.0)  # not LV95 metres in the UTM frame
    assert np.min(np.hypot(*(p.lake.outline[0] - world).T)) < 1e-6


def test_a_file_that_is_not_one_lake_says_why(win, tmp_path):
    said = []
    win.doc.reported.connect(lambda level, text: said.append((level, text)))
    f = tmp_path / "two.csv"
    rows = [f"{x},{y},A" for x, y in zip(2000 * np.cos(T), 1000 * np.sin(T), strict=True)]
    rows += [f"{x + 9000},{y},B" for x, y in zip(1000 * np.cos(T), 500 * np.sin(T), strict=True)]  # the smaller
    f.write_text("x,y,name\n" + "\n".join(rows) + "\n")
    assert win.io.import_points(f)
    # was: no lake ("not read as a lake … one lake per file"), the largest line imported as a plain block;
    # now the largest part is the lake and the Messages say which part was left out and how to grid it
    lake = win.doc.project.lake
    assert lake is not None and np.ptp(lake.outline[:, 0]) == pytest.approx(4000, rel=1e-3)
    assert np.max(lake.outline[:, 0]) < 5000  # part A (x about 0), not B (x about 9000)
    said = [t for level, t in said if level == "warning" and t.startswith("two.csv: 2 separate parts of water")]
    assert len(said) == 1 and "part 2 ('B'" in said[0] and "left out" in said[0] and "meshcore mesh" in said[0]


def test_degrees_without_a_header_warn_of_the_column_order(win, tmp_path):
    said = []
    win.doc.reported.connect(lambda level, text: said.append((level, text)))
    f = tmp_path / "gps.csv"
    f.write_text("".join(f"{b:.6f},{a:.6f}\n" for a, b in zip(LON, LAT, strict=True)))  # lat, lon
    assert win.io.import_points(f, project_lonlat=True)
    assert any(lv == "warning" and "read as longitude, latitude" in t and "'lat,lon'" in t for lv, t in said)


def test_web_mercator_is_imported_in_utm_metres(win, tmp_path):
    import json

    x, y = pyproj.Transformer.from_crs(4326, 3857, always_xy=True).transform(LON, LAT)
    ring = [[float(a), float(b)] for a, b in zip(x, y, strict=True)]
    f = tmp_path / "osm.geojson"
    crs = {"type": "name", "properties": {"name": "urn:ogc:def:crs:EPSG::3857"}}
    f.write_text(json.dumps({"type": "Polygon", "coordinates": [[*ring, ring[0]]], "crs": crs}))
    assert win.io.import_points(f)
    assert win.doc.project.crs == "EPSG:32632"  # was EPSG:3857: cells 1.45 times their size in true metres
    pts = win.doc.block.points
    assert 3000 < np.ptp(pts[:, 0]) < 3050  # 0.04° of longitude at 47.3° N: 3.02 km (4.45 "km" in Web Mercator)
