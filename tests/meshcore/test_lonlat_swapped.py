"""Degrees written latitude, longitude where the file says (or the reader assumes) longitude,
latitude: refused naming the swap and what to change, or noted; never a lake elsewhere in silence."""

from __future__ import annotations

import json

import numpy as np
import pytest

from meshcore.cli import main
from tests.meshcore.test_cli_bad_input import _bad

T = np.linspace(0, 2 * np.pi, 30, endpoint=False)
# an oval lake near Shasta: longitudes beyond ±90, so the swap is certain (latitude -122 is none)
LON, LAT = -122.4 + 0.05 * np.cos(T) + 0.01 * np.sin(3 * T), 40.8 + 0.03 * np.sin(T)


def _csv(path, header: str, first, second) -> None:
    path.write_text(
        (header + "\n" if header else "") + "".join(f"{a:.6f},{b:.6f}\n" for a, b in zip(first, second, strict=True))
    )


@pytest.mark.parametrize(
    ("header", "values", "column", "fixed"),
    [
        ("lon,lat", "lat,lon", 1, "lat,lon"),
        ("longitude,latitude", "lat,lon", 1, "latitude,longitude"),
        ("Lon,Lat", "lat,lon", 1, "lat,lon"),
        ("lat,lon", "lon,lat", 2, "lon,lat"),  # the header says lat first, the values are lon first
        ("id,lon,lat", "id,lat,lon", 2, "id,lat,lon"),
    ],
)
def test_a_lonlat_header_over_latitude_longitude_values_is_refused_naming_the_swap(
    tmp_path, capsys, header, values, column, fixed
):
    src, out = tmp_path / "shasta.csv", tmp_path / "g.vtm"
    cols = {"lat": LAT, "lon": LON, "id": np.arange(len(T))}
    src.write_text(
        header + "\n" + "".join(",".join(f"{cols[c][k]:.6f}" for c in values.split(",")) + "\n" for k in range(len(T)))
    )
    # was: "point 1 (40.8, -122.39) is outside the lon/lat range" and nothing on why
    err = _bad(capsys, ["mesh", src, "-o", out, "-q"], "shasta.csv", "point 1 (read as lon 40.", "look like latitude")
    assert f"if column {column} holds latitudes, write the header {fixed!r}" in err, err
    assert not out.exists()


def test_geojson_and_kml_written_latitude_longitude_are_refused_naming_their_order(tmp_path, capsys):
    ring = [[float(a), float(b)] for a, b in zip(LAT, LON, strict=True)]
    gj = tmp_path / "lake.geojson"
    geom = {"type": "Polygon", "coordinates": [ring + ring[:1]]}
    gj.write_text(json.dumps({"type": "Feature", "properties": {}, "geometry": geom}))
    err = _bad(capsys, ["mesh", gj, "-o", tmp_path / "g.vtm", "-q"], "lake.geojson", "look like latitude, longitude")
    assert "GeoJSON positions are [longitude, latitude]" in err and "--source-crs" not in err
    kml = tmp_path / "lake.kml"
    c = " ".join(f"{a},{b},0" for a, b in ring + ring[:1])
    kml.write_text(
        '<kml xmlns="http://www.opengis.net/kml/2.2"><Placemark><name>lake</name><Polygon><outerBoundaryIs>'
        f"<LinearRing><coordinates>{c}</coordinates></LinearRing></outerBoundaryIs></Polygon></Placemark></kml>"
    )
    _bad(capsys, ["mesh", kml, "-o", tmp_path / "g.vtm", "-q"], "lake.kml", "KML coordinates are longitude,latitude")


def test_a_mistyped_latitude_among_lonlat_points_is_no_swap(tmp_path, capsys):
    src = tmp_path / "typo.csv"
    lat = LAT.copy()
    lat[7] = 140.8  # 40.8 typed 140.8: within ±180, but the lake read the other way is no lake
    _csv(src, "lon,lat", LON, lat)
    err = _bad(capsys, ["mesh", src, "-o", tmp_path / "g.vtm", "-q"], "point 8 (", "outside the lon/lat range")
    assert "latitude, longitude" not in err


@pytest.mark.parametrize("header", ["", "x,y"])
def test_latitude_longitude_degrees_in_a_file_of_no_crs_are_noted_and_columns_swap_them(tmp_path, capsys, header):
    src = tmp_path / "shasta.csv"
    _csv(src, header, LAT, LON)
    assert main(["mesh", str(src), "-o", str(tmp_path / "a.vtm"), "--cells", "200"]) == 0
    err = capsys.readouterr().err
    # was: a grid 0.1 units across in the file's numbers, "no CRS: the grid keeps the file's coordinates"
    assert "look like latitude, longitude degrees" in err and "--columns 1 0" in err, err
    assert main(["mesh", str(src), "-o", str(tmp_path / "b.vtm"), "--cells", "200", "--columns", "1", "0"]) == 0
    err = capsys.readouterr().err
    assert "EPSG:32610" in err and "latitude, longitude" not in err, err


def test_the_read_line_of_a_lonlat_file_says_where_the_lake_lands(tmp_path, capsys):
    # Bolsena (lon 11.93, lat 42.59) written lat, lon under a lon,lat header: both columns within ±90,
    # nothing to refuse; the read line's centroid shows the lake landed at lon 42.6, lat 11.9
    src = tmp_path / "bolsena.csv"
    _csv(src, "lon,lat", 42.59 + 0.05 * np.sin(T), 11.93 + 0.06 * np.cos(T))
    assert main(["mesh", str(src), "-o", str(tmp_path / "a.vtm"), "--cells", "200"]) == 0
    err = capsys.readouterr().err
    assert "centroid lon 42.59000, lat 11.93000; grid CRS EPSG:32638" in err, err


def test_import_notes_latitude_longitude_degrees_as_mesh_does(tmp_path, capsys):
    src = tmp_path / "shasta.csv"
    _csv(src, "", LAT, LON)
    assert main(["import", str(src), "-o", str(tmp_path / "a.toml")]) == 0
    err = capsys.readouterr().err
    # was: imported without a word, a case in the file's numbers ("no CRS, origin (40.8, -122.3)")
    assert "meshcore import: note:" in err and "look like latitude, longitude degrees" in err, err
    assert main(["import", str(src), "-o", str(tmp_path / "b.toml"), "--columns", "1", "0"]) == 0
    out = capsys.readouterr()
    assert "EPSG:32610" in out.out and "latitude, longitude" not in out.err, out
