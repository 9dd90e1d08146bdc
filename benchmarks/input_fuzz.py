"""Bad and pathological inputs through the ``meshcore`` command line: every one must end cleanly.

Builds malformed and pathological outlines in every format :mod:`meshcore.io` reads outlines from
(CSV/TXT/XY, GeoJSON, KML, KMZ, GPX, shapefile, DXF), CLI option errors, case files for
``meshcore generate`` and point files for ``meshcore import``, runs each in a fresh process with a
timeout and classifies the outcome:

* ``ok`` — exit 0 with every output complete, or exit 3 (a grid written, its folds or
  non-convergence told);
* ``clear`` — exit 2 with one ``meshcore …: error: …`` line on stderr and no traceback;
* ``BAD`` — a traceback, exit 1 (internal error), another exit code, a hang (timeout), output
  files left after a failure, exit 0 with folded cells, or a water area far from the shape's.

Run from the repository root::

    python benchmarks/input_fuzz.py [--seed 0] [--only SUBSTR] [--jobs 2] [--timeout 240]
        [--out /tmp/fuzz.json] [--keep DIR]

The seed moves the shapes' wiggles and the places of the bad values; the case list is fixed.
A Ctrl-C case interrupts a long run and checks that it leaves no output (exit 130).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import signal
import subprocess
import sys
import tempfile
import threading
import time
import zipfile
from collections import Counter
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
CODE = ROOT  # the meshcore under test (--code)
CELLS = "300"  # small grids: the harness tests input handling, not the solver

# ------------------------------------------------------------------ shapes
Ring = np.ndarray


def blob(rng: np.random.Generator, n: int = 120, r: float = 3000.0, c=(0.0, 0.0), wiggle: float = 0.12) -> Ring:
    """A wavy closed ring (counter-clockwise, last point not repeated)."""
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    k = rng.integers(3, 7)
    rad = r * (1 + wiggle * np.sin(k * t + rng.uniform(0, 6.28)))
    return np.column_stack([c[0] + rad * np.cos(t), c[1] + rad * np.sin(t)])


def to_lonlat(ring: Ring, lon0: float, lat0: float) -> Ring:
    """Metres around (lon0, lat0) to degrees (equirectangular, good enough for a few km)."""
    lat = lat0 + ring[:, 1] / 111_320.0
    lon = lon0 + ring[:, 0] / (111_320.0 * math.cos(math.radians(lat0)))
    return np.column_stack([lon, lat])


def ring_area(r: Ring) -> float:
    x, y = r[:, 0], r[:, 1]
    return 0.5 * abs(float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))))


@dataclass
class Geo:
    """A lake: a list of parts, each ``[shore, *islands]``; ``lonlat`` says the numbers are degrees."""

    parts: list[list[Ring]]
    lonlat: bool = False
    area_m2: float | None = None  # the water area the run must report (when it is well defined)


def geometries(rng: np.random.Generator) -> dict[str, Geo]:
    """Named pathological lakes (most in metres, some in degrees)."""
    shore = blob(rng)
    isl = blob(rng, 40, 600, (300, 200), 0.05)
    g: dict[str, Geo] = {}
    g["good"] = Geo([[shore]], area_m2=ring_area(shore))
    g["good_island"] = Geo([[shore, isl]], area_m2=ring_area(shore) - ring_area(isl))
    g["clockwise"] = Geo([[shore[::-1]]], area_m2=ring_area(shore))
    g["one_point"] = Geo([[shore[:1]]])
    g["two_points"] = Geo([[shore[:2]]])
    g["triangle"] = Geo([[np.array([[0, 0], [4000, 0], [2000, 3000.0]])]], area_m2=6e6)
    g["all_equal"] = Geo([[np.repeat(shore[:1], 50, axis=0)]])
    g["collinear"] = Geo([[np.column_stack([np.linspace(0, 5000, 60), np.linspace(0, 2000, 60)])]])
    g["duplicates"] = Geo([[np.repeat(shore, 3, axis=0)]], area_m2=ring_area(shore))
    g["retrace"] = Geo([[np.vstack([shore[:60], shore[59:0:-1]])]])
    sp = shore.copy()
    tip = sp[30] * 1.6
    g["spike"] = Geo([[np.vstack([sp[:31], tip[None], sp[30:]])]], area_m2=ring_area(shore))
    g["bowtie"] = Geo([[np.array([[0, 0], [4000, 3000], [4000, 0], [0, 3000.0]])]])
    g["figure8"] = Geo([[np.vstack([blob(rng, 60, 1500, (-1500, 0), 0), blob(rng, 60, 1500, (1500, 0), 0)[::1]])]])
    sq = np.array([[-1000, -1000], [1000, -1000], [1000, 1000], [-1000, 1000.0]])
    g["island_touching"] = Geo([[shore, blob(rng, 40, 500, tuple(shore[10] * 0.84), 0)]])
    g["island_crossing"] = Geo([[shore, blob(rng, 40, 800, tuple(shore[10]), 0)]])
    g["island_outside"] = Geo([[shore, blob(rng, 40, 500, (9000, 9000), 0)]])
    g["island_nested"] = Geo([[shore, sq * 1.2, sq * 0.5]])
    g["islands_overlap"] = Geo([[shore, sq * 0.6, sq * 0.6 + 500]])
    g["islands_touching"] = Geo([[shore, sq * 0.5, sq * 0.5 + [1000, 0]]])
    g["island_equals_shore"] = Geo([[shore, shore.copy()]])
    g["island_duplicate"] = Geo([[shore, isl, isl.copy()]])
    g["island_tiny"] = Geo([[shore, sq * 1e-4]])
    g["two_lakes"] = Geo([[shore], [blob(rng, 80, 2000, (20000, 0))]])
    g["two_lakes_overlap"] = Geo([[shore], [blob(rng, 80, 2000, (1000, 0))]])
    g["scale_1e7"] = Geo([[shore * 3e3]])
    g["scale_1e-6"] = Geo([[shore * 3e-10]])
    g["scale_1e-300"] = Geo([[shore * 1e-303]])
    g["offset_1e9"] = Geo([[shore + 1e9]])
    g["offset_1e15"] = Geo([[shore + 1e15]])
    g["thin_sliver"] = Geo([[np.array([[0, 0], [100000, 0], [100000, 0.5], [0, 0.5]])]])
    g["nan_point"] = Geo([[np.vstack([shore[:10], [[np.nan, 5.0]], shore[10:]])]])
    g["inf_point"] = Geo([[np.vstack([shore[:10], [[np.inf, 5.0]], shore[10:]])]])
    g["huge_coord_1e300"] = Geo([[np.vstack([shore[:10], [[1e300, 5.0]], shore[10:]])]])
    path = np.column_stack([np.linspace(0, 30000, 100_000), 2000 * np.sin(np.linspace(0, 15, 100_000))])
    g["retrace_100k"] = Geo([[np.vstack([path, path[-2:0:-1]])]])
    g["many_islands"] = Geo(
        [[blob(rng, 400, 30000)] + [blob(rng, 12, 150, (x, y), 0) for x in range(-15000, 15001, 1500)
                                    for y in range(-15000, 15001, 1500) if x * x + y * y < 2.2e8]]
    )  # fmt: skip
    t = np.linspace(0, 2 * np.pi, 1_000_000, endpoint=False)
    g["million_points"] = Geo([[np.column_stack([3000 * np.cos(t), 2000 * np.sin(t)])]], area_m2=math.pi * 6e6)
    # degrees
    g["ll_good"] = Geo([[to_lonlat(shore, 10.3, 47.5)]], lonlat=True, area_m2=ring_area(shore))
    g["ll_lat_out_of_range"] = Geo([[to_lonlat(shore, 10.3, 47.5) + [0, 50]]], lonlat=True)
    g["ll_lon_out_of_range"] = Geo([[to_lonlat(shore, 10.3, 47.5) + [200, 0]]], lonlat=True)
    mixed = to_lonlat(shore, 10.3, 47.5)
    mixed[40:45] = shore[40:45] + [500000, 5200000]
    g["ll_mixed_metres"] = Geo([[mixed]], lonlat=True)
    g["ll_antimeridian"] = Geo([[_wrap(to_lonlat(shore, 179.99, -16.5))]], lonlat=True, area_m2=ring_area(shore))
    g["ll_near_pole"] = Geo([[to_lonlat(shore * 0.3, 20.0, 89.9)]], lonlat=True)
    g["ll_at_pole"] = Geo([[to_lonlat(shore * 0.3, 20.0, 89.99)]], lonlat=True)
    g["ll_utm_border"] = Geo([[to_lonlat(shore, 6.0, 47.5)]], lonlat=True, area_m2=ring_area(shore))
    g["ll_equator_zero"] = Geo([[to_lonlat(shore, 0.0, 0.0)]], lonlat=True, area_m2=ring_area(shore))
    g["ll_whole_world"] = Geo([[np.array([[-180, -90], [180, -90], [180, 90], [-180, 90.0]])]], lonlat=True)
    g["ll_tiny"] = Geo([[to_lonlat(shore * 1e-4, 10.3, 47.5)]], lonlat=True)
    return g


def _wrap(ll: Ring) -> Ring:
    out = ll.copy()
    out[:, 0] = (out[:, 0] + 180) % 360 - 180
    return out


# ------------------------------------------------------------------ writers of a Geo
def _rings(geo: Geo):
    for k, part in enumerate(geo.parts):
        for j, r in enumerate(part):
            yield k, j, r


def _num(v: float) -> str:
    return repr(float(v)) if math.isfinite(v) else ("nan" if math.isnan(v) else ("inf" if v > 0 else "-inf"))


def write_csv(geo: Geo, d: Path) -> Path:
    head = "lon,lat,ring" if geo.lonlat else "x,y,ring"
    lines = [head]
    for k, j, r in _rings(geo):
        name = f"p{k}_{'shore' if j == 0 else f'island{j}'}"
        lines += [f"{_num(x)},{_num(y)},{name}" for x, y in (_closed(r) if len(r) > 2 else r)]
    p = d / "lake.csv"
    p.write_text("\n".join(lines) + "\n")
    return p


def write_txt(geo: Geo, d: Path) -> Path:
    blocks = []
    for k, j, r in _rings(geo):
        blocks.append(f"> p{k}_{j}\n" + "\n".join(f"{_num(x)} {_num(y)}" for x, y in r))
    p = d / "lake.txt"
    p.write_text("\n".join(blocks) + "\n")
    return p


def _closed(r: Ring) -> list[list[float]]:
    pts = [[float(x), float(y)] for x, y in r]
    return pts + pts[:1] if pts else pts


def _json_num(obj):
    return json.dumps(obj).replace("NaN", "NaN").replace("Infinity", "1e999")


def write_geojson(geo: Geo, d: Path) -> Path:
    polys = [[_closed(r) for r in part] for part in geo.parts]
    if len(polys) == 1:
        g = {"type": "Polygon", "coordinates": polys[0]}
    else:
        g = {"type": "MultiPolygon", "coordinates": polys}
    p = d / "lake.geojson"
    p.write_text(_json_num({"type": "Feature", "properties": {"name": "lake"}, "geometry": g}))
    return p


def _kml_coords(r: Ring) -> str:
    return " ".join(f"{_num(x)},{_num(y)}" for x, y in _closed(r))


def _kml_doc(geo: Geo) -> str:
    marks = []
    for k, part in enumerate(geo.parts):
        inner = "".join(
            f"<innerBoundaryIs><LinearRing><coordinates>{_kml_coords(r)}</coordinates></LinearRing></innerBoundaryIs>"
            for r in part[1:]
        )
        marks.append(
            f"<Placemark><name>lake{k}</name><Polygon><outerBoundaryIs><LinearRing><coordinates>"
            f"{_kml_coords(part[0])}</coordinates></LinearRing></outerBoundaryIs>{inner}</Polygon></Placemark>"
        )
    return KML_HEAD + "".join(marks) + KML_TAIL


KML_HEAD = '<?xml version="1.0" encoding="UTF-8"?>\n<kml xmlns="http://www.opengis.net/kml/2.2"><Document>'
KML_TAIL = "</Document></kml>\n"


def write_kml(geo: Geo, d: Path) -> Path:
    p = d / "lake.kml"
    p.write_text(_kml_doc(geo))
    return p


def write_kmz(geo: Geo, d: Path) -> Path:
    p = d / "lake.kmz"
    with zipfile.ZipFile(p, "w") as z:
        z.writestr("doc.kml", _kml_doc(geo))
    return p


def write_gpx(geo: Geo, d: Path) -> Path:
    segs = []
    for _, _, r in _rings(geo):
        pts = "".join(f'<trkpt lat="{_num(y)}" lon="{_num(x)}"/>' for x, y in _closed(r))
        segs.append(f"<trkseg>{pts}</trkseg>")
    p = d / "lake.gpx"
    p.write_text(
        '<?xml version="1.0"?><gpx version="1.1" creator="fuzz" xmlns="http://www.topografix.com/GPX/1/1">'
        f"<trk><name>lake</name>{''.join(segs)}</trk></gpx>"
    )
    return p


def write_shp(geo: Geo, d: Path, *, prj: bool = True) -> Path:
    import shapefile

    p = d / "lake.shp"
    with shapefile.Writer(str(p.with_suffix("")), shapeType=shapefile.POLYGON) as w:
        w.field("name", "C")
        for k, part in enumerate(geo.parts):
            rings = [_closed(part[0][::-1])] + [_closed(r) for r in part[1:]]  # outer clockwise
            w.poly(rings)
            w.record(f"lake{k}")
    if prj and geo.lonlat:
        p.with_suffix(".prj").write_text(WGS84_WKT)
    return p


WGS84_WKT = (
    'GEOGCS["GCS_WGS_1984",DATUM["D_WGS_1984",SPHEROID["WGS_1984",6378137.0,298.257223563]],'
    'PRIMEM["Greenwich",0.0],UNIT["Degree",0.0174532925199433]]'
)


def write_dxf(geo: Geo, d: Path) -> Path:
    import ezdxf

    doc = ezdxf.new()
    msp = doc.modelspace()
    for _, _, r in _rings(geo):
        msp.add_lwpolyline([(float(x), float(y)) for x, y in r], close=True)
    p = d / "lake.dxf"
    doc.saveas(p)
    return p


WRITERS: dict[str, Callable[[Geo, Path], Path]] = {
    "csv": write_csv,
    "txt": write_txt,
    "geojson": write_geojson,
    "kml": write_kml,
    "kmz": write_kmz,
    "gpx": write_gpx,
    "shp": write_shp,
    "dxf": write_dxf,
}
#: Formats that carry degrees (the others hold metres only; DXF none).
LONLAT_OK = {"csv", "txt", "geojson", "kml", "kmz", "gpx", "shp"}
#: Formats whose numbers must be degrees (KML, KMZ and GPX are lon/lat by definition).
LONLAT_ONLY = {"kml", "kmz", "gpx"}


# ------------------------------------------------------------------ cases
@dataclass
class Case:
    name: str
    fmt: str
    make: Callable[[Path], list[str]]  # writes inputs into the folder, returns the argv after "meshcore"
    area_m2: float | None = None
    allow: tuple[str, ...] = ("ok", "clear")  # outcomes that are fine (all but BAD, by default)
    sigint_after: float | None = None  # the signal at the latest this many seconds in ...
    signal: int = signal.SIGINT
    signal_on: str | None = None  # ... or as soon as a line of stderr starts with this (the run's stage)


@dataclass
class Result:
    name: str
    fmt: str
    verdict: str  # ok / clear / BAD
    why: str
    rc: int | None
    seconds: float
    message: str = ""
    leftovers: list[str] = field(default_factory=list)


def mesh_argv(inp: Path, out: Path, *extra: str) -> list[str]:
    return ["mesh", str(inp), "--cells", CELLS, "-o", str(out / "grid.vtm"), *extra]


#: Shapes run through every format (the rest through CSV and GeoJSON only: the readers differ in
#: parsing, not in what happens to the points after).
EVERY_FORMAT = {
    "good", "good_island", "one_point", "two_points", "all_equal", "nan_point", "inf_point", "bowtie",
    "island_outside", "two_lakes", "ll_good", "ll_lat_out_of_range", "ll_antimeridian", "duplicates",
}  # fmt: skip


def geo_cases(rng: np.random.Generator) -> list[Case]:
    cases = []
    for gname, geo in geometries(rng).items():
        for fmt, writer in WRITERS.items():
            if geo.lonlat and fmt not in LONLAT_OK:
                continue
            g = geo
            if not geo.lonlat and fmt in LONLAT_ONLY | {"geojson"}:  # metres placed at 10.3° E, 47.5° N
                g = Geo([[to_lonlat(r, 10.3, 47.5) for r in part] for part in geo.parts], True, geo.area_m2)
            if fmt not in ("csv", "geojson") and gname not in EVERY_FORMAT:
                continue

            def make(d: Path, g=g, writer=writer) -> list[str]:
                return mesh_argv(writer(g, d / "in"), d / "out")

            cases.append(Case(f"{gname}", fmt, make, area_m2=geo.area_m2))
    return cases


def _raw(name: str, data: bytes | str, *extra: str, cmd: str = "mesh") -> Callable[[Path], list[str]]:
    def make(d: Path) -> list[str]:
        p = d / "in" / name
        if isinstance(data, str):
            p.write_text(data)
        else:
            p.write_bytes(data)
        if cmd == "mesh":
            return mesh_argv(p, d / "out", *extra)
        if cmd == "import":
            return ["import", str(p), "-o", str(d / "out" / "case.toml"), *extra]
        return ["generate", str(p), "-o", str(d / "out" / "grid.vts"), *extra]

    return make


def raw_cases(rng: np.random.Generator) -> list[Case]:
    shore = blob(rng)
    ll = to_lonlat(shore, 10.3, 47.5)
    good_csv = "x,y\n" + "\n".join(f"{x},{y}" for x, y in shore)
    good_ll = "lon,lat\n" + "\n".join(f"{x},{y}" for x, y in ll)
    coords = _kml_coords(ll)
    junk = bytes(rng.integers(0, 256, 4000, dtype=np.uint8))
    c: list[Case] = []

    def add(name: str, fmt: str, fn: Callable[[Path], list[str]], **kw) -> None:
        c.append(Case(name, fmt, fn, **kw))

    # CSV / TXT
    add("empty", "csv", _raw("a.csv", ""))
    add("header_only", "csv", _raw("a.csv", "x,y\n"))
    add("comments_only", "csv", _raw("a.csv", "# nothing\n# here\n"))
    add("text_in_numbers", "csv", _raw("a.csv", good_csv.replace(str(shore[7][0]), "abc", 1)))
    add("text_in_numbers_noheader", "txt", _raw("a.txt", good_csv.split("\n", 1)[1].replace(",", " ") + "\n1 foo\n"))
    add("nan_text", "csv", _raw("a.csv", good_csv.replace(str(shore[7][0]), "nan", 1)))
    add("inf_text", "csv", _raw("a.csv", good_csv.replace(str(shore[7][0]), "inf", 1)))
    add("1e999", "csv", _raw("a.csv", good_csv.replace(str(shore[7][0]), "1e999", 1)))
    rows = good_csv.split("\n")
    rows[12] = rows[12] + ",5,6"
    add("extra_columns_one_row", "csv", _raw("a.csv", "\n".join(rows)))
    rows = good_csv.split("\n")
    rows[12] = rows[12].split(",")[0]
    add("missing_column_one_row", "csv", _raw("a.csv", "\n".join(rows)))
    add("one_column", "csv", _raw("a.csv", "x\n" + "\n".join(f"{x}" for x, _ in shore)))
    add("binary_as_csv", "csv", _raw("a.csv", junk))
    add("nul_bytes_csv", "csv", _raw("a.csv", good_csv.encode().replace(b"\n", b"\n\x00", 3)))
    add("utf16_csv", "csv", _raw("a.csv", good_csv.encode("utf-16")))
    add(
        "latin1_header",
        "csv",
        _raw("a.csv", good_csv.replace("x,y", "Rechtswert,Hochwert,Bemerkung\xe4").encode("latin-1")),
    )
    add("decimal_comma_semicolon", "csv", _raw("a.csv", good_csv.replace(",", ";").replace(".", ",")))
    add("lonlat_header_metres", "csv", _raw("a.csv", good_csv.replace("x,y", "lon,lat")))
    add("xy_header_degrees", "csv", _raw("a.csv", good_ll.replace("lon,lat", "x,y")))
    add("latlon_swapped", "csv", _raw("a.csv", "lat,lon\n" + "\n".join(f"{x},{y}" for x, y in ll)))
    add("columns_bad_name", "csv", _raw("a.csv", good_csv, "--columns", "foo", "bar"))
    add("columns_index_out", "csv", _raw("a.csv", good_csv, "--columns", "0", "7"))
    add("columns_same", "csv", _raw("a.csv", good_csv, "--columns", "0", "0"))
    add("columns_negative", "csv", _raw("a.csv", good_csv, "--columns", "-1", "0"))
    add("very_long_line", "csv", _raw("a.csv", "x,y\n" + "1" * 5_000_000 + ",2\n" + good_csv.split("\n", 1)[1]))
    add("many_columns", "csv", _raw("a.csv", "\n".join(",".join(["1"] * 5000) for _ in range(50))))
    add("blank_lines_everywhere", "csv", _raw("a.csv", good_csv.replace("\n", "\n\n")))
    add("unknown_suffix", "none", _raw("a.foo", good_csv))
    add("no_suffix", "none", _raw("lake", good_csv))
    add("dat_suffix", "csv", _raw("a.dat", good_csv))
    add("dms_bad", "csv", _raw("a.csv", "lon,lat\n10°61'0\"E,47°0'0\"N\n10°1'0\"E,47°0'0\"N\n10°0'0\"E,47°1'0\"N\n"))
    # GeoJSON
    add("empty", "geojson", _raw("a.geojson", ""))
    add("invalid_json", "geojson", _raw("a.geojson", '{"type": "Feature", "geometry": {'))
    add("empty_object", "geojson", _raw("a.geojson", "{}"))
    add("json_list", "geojson", _raw("a.geojson", "[1, 2, 3]"))
    add("json_number", "geojson", _raw("a.geojson", "42"))
    add("null_geometry", "geojson", _raw("a.geojson", '{"type": "Feature", "properties": {}, "geometry": null}'))
    add("point", "geojson", _raw("a.geojson", '{"type": "Point", "coordinates": [10.3, 47.5]}'))
    ls = json.dumps({"type": "LineString", "coordinates": _closed(ll)[:-1]})
    add("linestring_open", "geojson", _raw("a.geojson", ls))
    ls = json.dumps({"type": "LineString", "coordinates": _closed(ll)})
    add("linestring_closed", "geojson", _raw("a.geojson", ls))
    fc = {
        "type": "FeatureCollection",
        "features": [
            {"type": "Feature", "properties": {"name": f"l{k}"}, "geometry": {"type": "Polygon",
             "coordinates": [_closed(to_lonlat(shore, 10.3 + 0.2 * k, 47.5))]}}
            for k in range(3)
        ],
    }  # fmt: skip
    add("featurecollection_3_lakes", "geojson", _raw("a.geojson", json.dumps(fc)))
    fc2 = {"type": "FeatureCollection", "features": []}
    add("featurecollection_empty", "geojson", _raw("a.geojson", json.dumps(fc2)))
    gc = {"type": "GeometryCollection", "geometries": [{"type": "Polygon", "coordinates": [_closed(ll)]},
                                                      {"type": "Point", "coordinates": [10, 47]}]}  # fmt: skip
    add("geometrycollection", "geojson", _raw("a.geojson", json.dumps(gc)))
    add(
        "coords_strings",
        "geojson",
        _raw("a.geojson", json.dumps({"type": "Polygon", "coordinates": [[[str(x), str(y)] for x, y in _closed(ll)]]})),
    )
    add(
        "coords_3d",
        "geojson",
        _raw("a.geojson", json.dumps({"type": "Polygon", "coordinates": [[[x, y, 100.0] for x, y in _closed(ll)]]})),
    )
    add(
        "coords_1d",
        "geojson",
        _raw("a.geojson", json.dumps({"type": "Polygon", "coordinates": [[[x] for x, y in _closed(ll)]]})),
    )
    add(
        "coords_too_deep",
        "geojson",
        _raw("a.geojson", json.dumps({"type": "Polygon", "coordinates": [[[[x, y]] for x, y in _closed(ll)]]})),
    )
    add("coords_empty", "geojson", _raw("a.geojson", json.dumps({"type": "Polygon", "coordinates": []})))
    add("coords_empty_ring", "geojson", _raw("a.geojson", json.dumps({"type": "Polygon", "coordinates": [[]]})))
    add("coords_null", "geojson", _raw("a.geojson", json.dumps({"type": "Polygon", "coordinates": None})))
    add(
        "coords_bool",
        "geojson",
        _raw("a.geojson", json.dumps({"type": "Polygon", "coordinates": [[[True, False]] * 5]})),
    )
    add("type_unknown", "geojson", _raw("a.geojson", json.dumps({"type": "Blob", "coordinates": [[_closed(ll)]]})))
    add("type_missing", "geojson", _raw("a.geojson", json.dumps({"coordinates": [_closed(ll)]})))
    add(
        "crs_member_bad",
        "geojson",
        _raw(
            "a.geojson",
            json.dumps(
                {
                    "type": "Polygon",
                    "crs": {"type": "name", "properties": {"name": "urn:ogc:def:crs:EPSG::99999999"}},
                    "coordinates": [_closed(shore)],
                }
            ),
        ),
    )
    add(
        "crs_member_metres",
        "geojson",
        _raw(
            "a.geojson",
            json.dumps(
                {
                    "type": "Polygon",
                    "crs": {"type": "name", "properties": {"name": "urn:ogc:def:crs:EPSG::32632"}},
                    "coordinates": [_closed(shore + [500000, 5200000])],
                }
            ),
        ),
    )
    add("deep_nesting", "geojson", _raw("a.geojson", "[" * 100000 + "]" * 100000))
    add(
        "huge_number",
        "geojson",
        _raw(
            "a.geojson",
            json.dumps({"type": "Polygon", "coordinates": [_closed(ll)]}).replace(str(ll[5][0]), "1e999", 1),
        ),
    )
    add(
        "big_int",
        "geojson",
        _raw(
            "a.geojson",
            json.dumps({"type": "Polygon", "coordinates": [_closed(ll)]}).replace(str(ll[5][0]), "9" * 5000, 1),
        ),
    )
    add(
        "bom",
        "geojson",
        _raw("a.geojson", b"\xef\xbb\xbf" + json.dumps({"type": "Polygon", "coordinates": [_closed(ll)]}).encode()),
    )
    add("binary", "geojson", _raw("a.geojson", junk))
    # KML / KMZ
    add("empty", "kml", _raw("a.kml", ""))
    add("no_coordinates", "kml", _raw("a.kml", KML_HEAD + "<Placemark><name>x</name></Placemark>" + KML_TAIL))
    add(
        "empty_coordinates",
        "kml",
        _raw(
            "a.kml",
            KML_HEAD
            + "<Placemark><Polygon><outerBoundaryIs><LinearRing><coordinates>  </coordinates></LinearRing></outerBoundaryIs></Polygon></Placemark>"  # noqa: E501
            + KML_TAIL,
        ),
    )
    alt = " ".join(f"{x},{y},123.5" for x, y in _closed(ll))
    add(
        "altitude",
        "kml",
        _raw(
            "a.kml",
            KML_HEAD
            + f"<Placemark><Polygon><outerBoundaryIs><LinearRing><coordinates>{alt}</coordinates></LinearRing></outerBoundaryIs></Polygon></Placemark>"  # noqa: E501
            + KML_TAIL,
        ),
    )
    add(
        "coords_garbage",
        "kml",
        _raw(
            "a.kml",
            KML_HEAD
            + f"<Placemark><LineString><coordinates>{coords[:200]} abc,def {coords[200:]}</coordinates></LineString></Placemark>"  # noqa: E501
            + KML_TAIL,
        ),
    )
    add(
        "coords_one_number",
        "kml",
        _raw(
            "a.kml",
            KML_HEAD
            + "<Placemark><LineString><coordinates>1 2 3 4 5</coordinates></LineString></Placemark>"
            + KML_TAIL,
        ),
    )
    add(
        "point_placemark",
        "kml",
        _raw("a.kml", KML_HEAD + "<Placemark><Point><coordinates>10,47</coordinates></Point></Placemark>" + KML_TAIL),
    )
    add("malformed_xml", "kml", _raw("a.kml", KML_HEAD + "<Placemark><Polygon>"))
    add("not_kml_xml", "kml", _raw("a.kml", "<html><body>hi</body></html>"))
    add(
        "entity_bomb",
        "kml",
        _raw(
            "a.kml",
            '<?xml version="1.0"?><!DOCTYPE k [<!ENTITY a "aaaaaaaaaa"><!ENTITY b "&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;">]><kml>&b;</kml>',  # noqa: E501
        ),
    )
    add("binary", "kml", _raw("a.kml", junk))
    add("not_a_zip", "kmz", _raw("a.kmz", junk))
    add("empty_zip", "kmz", lambda d: _zip(d, {}))
    add("zip_without_kml", "kmz", lambda d: _zip(d, {"readme.txt": "hi"}))
    add("zip_bad_kml", "kmz", lambda d: _zip(d, {"doc.kml": "<kml"}))
    add("zip_bomb", "kmz", lambda d: _zip(d, {"doc.kml": KML_HEAD + " " * 600_000_000 + KML_TAIL}))
    # GPX
    add("empty", "gpx", _raw("a.gpx", ""))
    add("no_tracks", "gpx", _raw("a.gpx", '<?xml version="1.0"?><gpx version="1.1"></gpx>'))
    add(
        "bad_lat",
        "gpx",
        _raw(
            "a.gpx",
            '<gpx><trk><trkseg><trkpt lat="abc" lon="1"/><trkpt lat="1" lon="2"/><trkpt lat="2" lon="2"/></trkseg></trk></gpx>',  # noqa: E501
        ),
    )
    add(
        "missing_lon",
        "gpx",
        _raw(
            "a.gpx",
            '<gpx><trk><trkseg><trkpt lat="1"/><trkpt lat="1" lon="2"/><trkpt lat="2" lon="2"/></trkseg></trk></gpx>',
        ),
    )
    add("two_waypoints", "gpx", _raw("a.gpx", '<gpx><wpt lat="47" lon="10"/><wpt lat="47.1" lon="10.1"/></gpx>'))
    # shapefile
    add("missing_shx", "shp", lambda d: _shp_without(d, rng, ".shx"))
    add("missing_dbf", "shp", lambda d: _shp_without(d, rng, ".dbf"))
    add("truncated_shp", "shp", lambda d: _shp_truncated(d, rng))
    add("empty_shapefile", "shp", lambda d: _shp_empty(d))
    add("point_shapefile", "shp", lambda d: _shp_points(d, rng))
    add("null_shape", "shp", lambda d: _shp_null(d))
    add("bad_prj", "shp", lambda d: _shp_prj(d, rng, "GEOGCS[nonsense"))
    add("binary", "shp", _raw("a.shp", junk))
    # DXF
    add("empty", "dxf", _raw("a.dxf", ""))
    add("binary", "dxf", _raw("a.dxf", junk))
    add("garbage_text", "dxf", _raw("a.dxf", "0\nSECTION\n2\nENTITIES\n0\nLWPOLYLINE\n10\nabc\n"))
    add("lines_only", "dxf", lambda d: _dxf_lines(d, shore))
    # CLI options (a good lake, one bad option)
    good = _raw("a.csv", good_csv)
    for opt, val in [("--cell-size", "0"), ("--cell-size", "-5"), ("--cell-size", "nan"), ("--cell-size", "inf"),
                     ("--cell-size", "1e-9"), ("--cell-size", "1e12"), ("--cell-size", "abc"), ("--cells", "0"),
                     ("--cells", "-3"), ("--cells", "1000000000000"), ("--cells", "2.5"), ("--crs", "nonsense"),
                     ("--crs", "EPSG:4326"), ("--crs", "EPSG:999999"), ("--crs", ""), ("--source-crs", "nonsense"),
                     ("--source-crs", "EPSG:4326"), ("--part", "0"), ("--part", "3"), ("--part", "x")]:  # fmt: skip
        add(f"opt {opt} {val!r}", "cli", _without_cells(_raw("a.csv", good_csv, f"{opt}={val}")))
    add("opt -o missing dir", "cli", lambda d: _with_o(good, d, str(d / "nowhere" / "g.vtm")))
    add("opt -o unknown suffix", "cli", lambda d: _with_o(good, d, str(d / "out" / "g.foo")))
    add("opt -o no suffix", "cli", lambda d: _with_o(good, d, str(d / "out" / "g")))
    add("opt -o is a directory", "cli", lambda d: _with_o(good, d, str(d / "out")))
    add("opt -o the input", "cli", lambda d: _with_o(good, d, str(d / "in" / "a.csv"), replace=True))
    add("opt -o into /proc", "cli", lambda d: _with_o(good, d, "/proc/g.vtm"))
    add("opt -o twice same", "cli", lambda d: _with_o(good, d, str(d / "out" / "grid.vtm")))
    add("opt --png bad suffix", "cli", lambda d: good(d) + ["--png", str(d / "out" / "f.jpgx")])
    add("opt --case bad suffix", "cli", lambda d: good(d) + ["--case", str(d / "out" / "c.txt")])
    add("opt outline missing", "cli", lambda d: ["mesh", str(d / "in" / "nope.csv"), "-o", str(d / "out" / "g.vtm")])
    add("opt outline a directory", "cli", lambda d: ["mesh", str(d / "in"), "-o", str(d / "out" / "g.vtm")])
    add("opt outline /dev/zero", "cli", lambda d: ["mesh", "/dev/zero", "-o", str(d / "out" / "g.vtm")])
    add("opt no outputs", "cli", lambda d: good(d)[:4])
    # import
    add("import empty", "import", _raw("a.csv", "", cmd="import"))
    add("import good", "import", _raw("a.csv", good_csv, cmd="import"))
    add("import bowtie", "import", _raw("a.csv", "x,y\n0,0\n4000,3000\n4000,0\n0,3000\n", cmd="import"))
    add("import two points", "import", _raw("a.csv", "x,y\n0,0\n4000,3000\n", cmd="import"))
    add("import all equal", "import", _raw("a.csv", "x,y\n" + "5,5\n" * 20, cmd="import"))
    add("import corners bad", "import", _raw("a.csv", good_csv, "--corners", "0", "0", "0", "0", cmd="import"))
    add("import corners out", "import", _raw("a.csv", good_csv, "--corners", "0", "10", "20", "9999", cmd="import"))
    add("import cells huge", "import", _raw("a.csv", good_csv, "--cells", "100000", "100000", cmd="import"))
    add("import cells zero", "import", _raw("a.csv", good_csv, "--cells", "0", "5", cmd="import"))
    add("import polyline missing", "import", _raw("a.csv", good_csv, "--polyline", "nope", cmd="import"))
    add(
        "import -o bad suffix",
        "import",
        lambda d: _raw("a.csv", good_csv, cmd="import")(d)[:3] + [str(d / "out" / "c.txt")],
    )
    # generate
    for name, text in CASES_TOML.items():
        add(f"generate {name}", "generate", _raw("c.toml", text, cmd="generate"))
    add("generate binary", "generate", _raw("c.toml", junk, cmd="generate"))
    # Ctrl-C in the middle of a long run: exit 130, nothing written
    big = blob(rng, 400, 30000)
    add("sigint during solve", "signal", lambda d: ["mesh", str(write_csv(Geo([[big]]), d / "in")), "--cells", "60000",
                                                 "-o", str(d / "out" / "g.vtm"), "-o", str(d / "out" / "g.npz")],
        sigint_after=60.0, signal_on="grid level")  # fmt: skip
    add("sigterm during solve", "signal", lambda d: ["mesh", str(write_csv(Geo([[big]]), d / "in")), "--cells", "60000",
                                                  "-o", str(d / "out" / "g.vtm")],
        sigint_after=60.0, signal=signal.SIGTERM, signal_on="grid level")  # fmt: skip
    return c


def _case(points: str = "", cells: str = "[20, 20]", corners: str = "[0, 10, 20, 30]", extra: str = "") -> str:
    """A one-block case file (the layout of ``meshcore import``) with one field replaced."""
    if not points:
        t = np.linspace(0, 2 * np.pi, 40, endpoint=False)
        points = "[" + ", ".join(f"[{1000 * math.cos(a):.3f}, {700 * math.sin(a):.3f}]" for a in t) + "]"
    return (
        f'title = "fuzz"\n{extra}\n[[blocks]]\nname = "a"\ncells = {cells}\n\n'
        f"[blocks.boundary]\npoints = {points}\ncorners = {corners}\n"
    )


CASES_TOML = {
    "good": _case(),
    "empty": "",
    "invalid_toml": "[blocks\nni = ",
    "unknown_key": _case(extra="bogus = 1"),
    "negative_cells": _case(cells="[-10, 20]"),
    "nan_cells": _case(cells="[nan, 20]"),
    "float_cells": _case(cells="[10.5, 20]"),
    "huge_cells": _case(cells="[100000000, 100000000]"),
    "string_cells": _case(cells='["ten", 20]'),
    "one_cell_count": _case(cells="[20]"),
    "corners_out": _case(corners="[0, 10, 20, 300]"),
    "corners_same": _case(corners="[0, 0, 20, 30]"),
    "corners_unordered": _case(corners="[0, 20, 10, 30]"),
    "points_empty": _case(points="[]"),
    "points_nan": _case(points="[[0, 0], [1000, 0], [nan, 500], [0, 700]]", corners="[0, 1, 2, 3]"),
    "points_inf": _case(points="[[0, 0], [1000, 0], [inf, 500], [0, 700]]", corners="[0, 1, 2, 3]"),
    "points_3": _case(points="[[0, 0], [1000, 0], [0, 700]]", corners="[0, 1, 2, 0]"),
    "points_bowtie": _case(points="[[0, 0], [4000, 3000], [4000, 0], [0, 3000]]", corners="[0, 1, 2, 3]"),
    "points_strings": _case(points='[["a", 0], [1000, 0], [1000, 500], [0, 700]]', corners="[0, 1, 2, 3]"),
    "points_1d": _case(points="[0, 1000, 1000, 0]", corners="[0, 1, 2, 3]"),
    "solver_bad_method": _case(extra='[solver]\nmethod = "bogus"'),
    "solver_bad_tolerance": _case(extra="[solver]\ntolerance = -1.0"),
    "solver_nan_tolerance": _case(extra="[solver]\ntolerance = nan"),
    "solver_zero_iterations": _case(extra="[solver]\nmax_iterations = 0"),
    "crs_nonsense": _case(extra='[crs]\ncrs = "nonsense"'),
}


def _without_cells(make: Callable[[Path], list[str]]) -> Callable[[Path], list[str]]:
    """The argv without ``--cells N`` (which --cell-size may not go with)."""

    def f(d: Path) -> list[str]:
        argv = make(d)
        k = argv.index("--cells")
        return argv[:k] + argv[k + 2 :] if not any(a.startswith("--cells=") for a in argv) else argv

    return f


def _zip(d: Path, files: dict[str, str]) -> list[str]:
    p = d / "in" / "a.kmz"
    with zipfile.ZipFile(p, "w", zipfile.ZIP_DEFLATED) as z:
        for k, v in files.items():
            z.writestr(k, v)
    return mesh_argv(p, d / "out")


def _with_o(good: Callable[[Path], list[str]], d: Path, out: str, replace: bool = False) -> list[str]:
    argv = good(d)
    return argv[:4] + ["-o", out] if replace else argv + ["-o", out]


def _shp_without(d: Path, rng, suffix: str) -> list[str]:
    p = write_shp(Geo([[blob(rng)]]), d / "in")
    p.with_suffix(suffix).unlink()
    return mesh_argv(p, d / "out")


def _shp_truncated(d: Path, rng) -> list[str]:
    p = write_shp(Geo([[blob(rng)]]), d / "in")
    data = p.read_bytes()
    p.write_bytes(data[: len(data) // 2])
    return mesh_argv(p, d / "out")


def _shp_empty(d: Path) -> list[str]:
    import shapefile

    p = d / "in" / "a.shp"
    with shapefile.Writer(str(p.with_suffix("")), shapeType=shapefile.POLYGON) as w:
        w.field("name", "C")
    return mesh_argv(p, d / "out")


def _shp_points(d: Path, rng) -> list[str]:
    import shapefile

    p = d / "in" / "a.shp"
    with shapefile.Writer(str(p.with_suffix("")), shapeType=shapefile.POINT) as w:
        w.field("name", "C")
        for x, y in blob(rng, 30):
            w.point(float(x), float(y))
            w.record("p")
    return mesh_argv(p, d / "out")


def _shp_null(d: Path) -> list[str]:
    import shapefile

    p = d / "in" / "a.shp"
    with shapefile.Writer(str(p.with_suffix("")), shapeType=shapefile.POLYGON) as w:
        w.field("name", "C")
        w.null()
        w.record("nothing")
    return mesh_argv(p, d / "out")


def _shp_prj(d: Path, rng, text: str) -> list[str]:
    p = write_shp(Geo([[blob(rng)]]), d / "in")
    p.with_suffix(".prj").write_text(text)
    return mesh_argv(p, d / "out")


def _dxf_lines(d: Path, shore: Ring) -> list[str]:
    import ezdxf

    doc = ezdxf.new()
    msp = doc.modelspace()
    for a, b in zip(shore, np.roll(shore, -1, axis=0), strict=True):
        msp.add_line(tuple(a), tuple(b))
    p = d / "in" / "a.dxf"
    doc.saveas(p)
    return mesh_argv(p, d / "out")


# ------------------------------------------------------------------ running and judging
def _default_sigint() -> None:
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def _signalled_run(proc: subprocess.Popen, case: Case, timeout: float) -> tuple[bytes, bytes, bool, bool]:
    """``(stdout, stderr, signalled, timed out)`` of a run that gets ``case.signal`` as soon as a line of
    its stderr starts with ``case.signal_on`` (the stage it should be in: the grid's solve), at the
    latest ``case.sigint_after`` seconds in (a fixed 8 s let faster runs finish first: skipped, the
    Ctrl-C path untested)."""
    outs: list[bytes] = []
    errs: list[bytes] = []
    seen = threading.Event()

    def pump(stream, sink, marker=None):
        for raw in iter(stream.readline, b""):
            sink.append(raw)
            if marker and raw.decode(errors="replace").startswith(marker):
                seen.set()

    readers = [
        threading.Thread(target=pump, args=(proc.stdout, outs), daemon=True),
        threading.Thread(target=pump, args=(proc.stderr, errs, case.signal_on), daemon=True),
    ]
    for t in readers:
        t.start()
    deadline = time.perf_counter() + float(case.sigint_after or 0.0)
    while proc.poll() is None and not seen.is_set() and time.perf_counter() < deadline:
        time.sleep(0.02)
    signalled = proc.poll() is None
    if signalled:
        proc.send_signal(case.signal)
    timed_out = False
    try:
        proc.wait(timeout)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait()
        timed_out = True
    for t in readers:
        t.join(10)
    return b"".join(outs), b"".join(errs), signalled, timed_out


def run_case(case: Case, root: Path, timeout: float) -> Result:
    d = root / f"{case.fmt}__{case.name}".replace(" ", "_").replace("/", "_").replace("'", "")
    (d / "in").mkdir(parents=True, exist_ok=True)
    (d / "out").mkdir(exist_ok=True)
    try:
        argv = case.make(d)
    except Exception as exc:  # the harness could not build the input
        return Result(case.name, case.fmt, "skip", f"build failed: {exc!r}", None, 0.0)
    env = dict(os.environ, PYTHONPATH=str(CODE), PYTHONUNBUFFERED="1")
    env.pop("MESHCORE_DEBUG", None)
    t0 = time.perf_counter()
    proc = subprocess.Popen(
        [sys.executable, "-m", "meshcore", *argv],
        cwd=d,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        preexec_fn=_default_sigint,  # a harness started with & ignores SIGINT, and so would its children
    )
    timed_out = False
    signalled = False
    if case.sigint_after:
        out, err, signalled, timed_out = _signalled_run(proc, case, timeout)
    else:
        try:
            out, err = proc.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:
            proc.kill()
            out, err = proc.communicate()
            timed_out = True
    dt = time.perf_counter() - t0
    rc = proc.returncode
    stdout, stderr = out.decode(errors="replace"), err.decode(errors="replace")
    (d / "stdout.txt").write_text(stdout)
    (d / "stderr.txt").write_text(stderr)
    (d / "argv.txt").write_text(" ".join(argv))
    files = sorted(str(p.relative_to(d / "out")) for p in (d / "out").rglob("*"))
    errs = [ln for ln in stderr.splitlines() if ": error: " in ln or "internal error" in ln]
    msg = errs[-1] if errs else (stderr.strip().splitlines() or [""])[-1]
    r = Result(case.name, case.fmt, "BAD", "", rc, round(dt, 1), msg[:300], files)
    if timed_out:
        r.why = f"hang: no exit in {timeout:.0f} s"
    elif "Traceback" in stderr:
        r.why = "traceback"
    elif rc == 1:
        r.why = "exit 1 (internal error)"
    elif case.sigint_after and not signalled:
        r.verdict, r.why = "skip", f"finished before the signal ({case.signal_on or ''} {case.sigint_after:.0f} s)"
    elif case.sigint_after:
        want = (130,) if case.signal == signal.SIGINT else (143, -case.signal)  # 143: handled, -15: killed
        r.verdict, r.why = ("ok", "interrupted cleanly") if rc in want and not files else ("BAD", "")
        r.why = r.why or f"after signal {case.signal}: exit {rc}, files {files}"
    elif rc == 2:
        if files:
            r.why = f"exit 2 but left {files}"
        elif len(errs) != 1:
            r.why = f"exit 2 with {len(errs)} error lines"
        elif not _names_place(argv, msg):
            r.why = "the message names no file and no option"
        else:
            r.verdict, r.why = "clear", ""
    elif rc in (0, 3):
        r.verdict, r.why = _judge_grid(case, d, rc, stderr, files)
    else:
        r.why = f"exit {rc}"
    return r


def _names_place(argv: list[str], msg: str) -> bool:
    """The error line names an input or output file of the run, an option, or an argument."""
    paths = [Path(a) for a in argv[1:] if "/" in a or "." in a]
    names = [p.name for p in paths] + [f"{p.stem}." for p in paths]  # a file beside it too (.prj of a .shp)
    return any(n and n in msg for n in names) or " --" in msg or "-o " in msg or "argument" in msg


def _judge_grid(case: Case, d: Path, rc: int, stderr: str, files: list[str]) -> tuple[str, str]:
    import re

    if case.fmt in ("import", "generate"):
        return ("ok", "") if files else ("BAD", f"exit {rc} and no output")
    if not any(f.endswith(".vtm") for f in files) and "-o" in (d / "argv.txt").read_text():
        return "BAD", f"exit {rc} and no .vtm written"
    if any(".tmp" in f for f in files):
        return "BAD", f"temporaries left: {files}"
    m = re.search(r"quality: (\d+) folded", stderr)
    if rc == 0 and m and int(m.group(1)):
        return "BAD", f"exit 0 with {m.group(1)} folded cells"
    a = re.search(r"water area ([0-9.e+-]+) km²", stderr)
    if case.area_m2 and a:
        got = float(a.group(1)) * 1e6
        if abs(got / case.area_m2 - 1) > 0.05:
            return "BAD", f"water area {got:.4g} m² where the shape has {case.area_m2:.4g} m²"
    return "ok", ("exit 3" if rc == 3 else "")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--only", action="append", help="run cases whose 'fmt name' contains this (repeatable)")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--timeout", type=float, default=240.0)
    ap.add_argument("--out", type=Path, help="write the results as JSON")
    ap.add_argument("--code", type=Path, default=ROOT, help="the checkout whose meshcore runs (default this one)")
    ap.add_argument("--keep", type=Path, help="run folder (kept); default a temporary one, removed")
    args = ap.parse_args()
    global CODE
    CODE = args.code.resolve()
    rng = np.random.default_rng(args.seed)
    cases = geo_cases(rng) + raw_cases(rng)
    if args.only:
        cases = [c for c in cases if any(s in f"{c.fmt} {c.name}" for s in args.only)]
    tmp = None
    if args.keep:
        root = args.keep
        root.mkdir(parents=True, exist_ok=True)
    else:
        tmp = tempfile.TemporaryDirectory(prefix="input_fuzz_")
        root = Path(tmp.name)
    results: list[Result] = []
    with ThreadPoolExecutor(args.jobs) as pool:
        for r in pool.map(lambda c: run_case(c, root, args.timeout), cases):
            results.append(r)
            flag = "  " if r.verdict != "BAD" else "!!"
            print(f"{flag} {r.verdict:5s} {r.fmt:8s} {r.name:32s} rc={r.rc} {r.seconds:6.1f}s {r.why} | {r.message}",
                  flush=True)  # fmt: skip
    table: dict[str, Counter] = {}
    for r in results:
        table.setdefault(r.fmt, Counter())[r.verdict] += 1
    print("\nformat    ok  clear  BAD  skip")
    for fmt, cnt in table.items():
        print(f"{fmt:8s} {cnt['ok']:3d} {cnt['clear']:6d} {cnt['BAD']:4d} {cnt['skip']:5d}")
    tot = Counter(r.verdict for r in results)
    print(f"{'all':8s} {tot['ok']:3d} {tot['clear']:6d} {tot['BAD']:4d} {tot['skip']:5d}")
    if args.out:
        args.out.write_text(json.dumps([r.__dict__ for r in results], indent=1))
    if tmp is not None:
        tmp.cleanup()
    return 1 if tot["BAD"] else 0


if __name__ == "__main__":
    sys.exit(main())
