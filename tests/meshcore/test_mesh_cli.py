"""``meshcore mesh``: a lake outline in, a multiblock grid out — end to end.

Each output is read back by an independent reader (VTK, h5py, a Fortran-record parser, the
Delft3D parsers of ``test_delft3d_dd``) and by meshcore's own, and its world coordinates are
checked against the input outline projected here with pyproj directly.  Exit codes: 0, 2
(bad input: one line, nothing written), 3 (a grid with folded cells, written), 1 (a bug).
"""

from __future__ import annotations

import contextlib
import dataclasses
import io
import json
import math
import os
import re
import xml.etree.ElementTree as ET
from collections import Counter
from pathlib import Path

import numpy as np
import pytest

from meshcore.cli import main
from meshcore.io import read_blocks
from tests.conftest import ROOT
from tests.meshcore.test_delft3d_dd import parse_ddb, parse_grd, segment

LAKES = ROOT / "benchmarks" / "lakes"
shapely = pytest.importorskip("shapely")
pyproj = pytest.importorskip("pyproj")


@dataclasses.dataclass
class Run:
    rc: int
    out: str
    err: str


def mesh(*argv) -> Run:
    """``meshcore mesh ARGV`` in this process (the compiled kernels stay loaded)."""
    o, e = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(o), contextlib.redirect_stderr(e):
        rc = main(["mesh", *map(str, argv)])
    return Run(rc, o.getvalue(), e.getvalue())


# ------------------------------------------------------------------ independent geometry
def geojson_rings(path: Path) -> list[np.ndarray]:
    d = json.loads(path.read_text())
    geom = d["features"][0]["geometry"] if "features" in d else d.get("geometry", d)
    return [np.asarray(r, float)[:, :2] for r in geom["coordinates"]]


def kml_rings(path: Path) -> list[np.ndarray]:
    ns = {"k": "http://www.opengis.net/kml/2.2"}
    poly = ET.parse(path).getroot().find(".//k:Polygon", ns)
    rings = poly.findall("k:outerBoundaryIs//k:coordinates", ns) + poly.findall("k:innerBoundaryIs//k:coordinates", ns)
    return [np.array([[float(v) for v in t.split(",")[:2]] for t in r.text.split()]) for r in rings]


def projected(rings: list[np.ndarray], crs: str):
    t = pyproj.Transformer.from_crs("EPSG:4326", crs, always_xy=True)
    xy = [np.column_stack(t.transform(r[:, 0], r[:, 1])) for r in rings]
    return shapely.Polygon(xy[0], xy[1:])


def blocks_of(gs) -> list[tuple[np.ndarray, np.ndarray]]:
    return [gs.world(k) for k in range(len(gs.blocks))]


def check_covers_the_water(blocks, water) -> None:
    """Grid nodes in the water, shore nodes on the shore, no cell on an island, about the water's area.

    The node checks (to 1e-7 of the lake's size) pin the coordinates down: a grid in another
    CRS, shifted by an origin or scaled, fails them.  The area is a sanity check only (10 %);
    the pipeline's own tests hold the coverage targets.
    """
    size = math.sqrt(water.area)
    tol = 1e-7 * size
    nodes = np.vstack([np.column_stack([x.ravel(), y.ravel()]) for x, y in blocks])
    assert np.abs(nodes).max() > 0
    assert shapely.distance(water, shapely.points(nodes)).max() <= tol
    # a border node of one block only lies on the shore (or an island's); shared ones are interfaces
    owners: Counter = Counter()
    border = {}
    for x, y in blocks:
        sides = ((x[:, 0], y[:, 0]), (x[-1], y[-1]), (x[:, -1], y[:, -1]), (x[0], y[0]))
        ring = np.concatenate([np.column_stack(side) for side in sides])
        keys = {tuple(k): p for k, p in zip(np.round(ring / tol).astype(np.int64).tolist(), ring, strict=True)}
        owners.update(keys.keys())
        border.update(keys)
    shore = np.array([border[k] for k, n in owners.items() if n == 1])
    assert shapely.distance(water.boundary, shapely.points(shore)).max() <= tol
    quads = []
    for x, y in blocks:
        c = [(x[:-1, :-1], y[:-1, :-1]), (x[1:, :-1], y[1:, :-1]), (x[1:, 1:], y[1:, 1:]), (x[:-1, 1:], y[:-1, 1:])]
        quads.append(np.stack([np.column_stack([a.ravel(), b.ravel()]) for a, b in c], axis=1))
    cells = shapely.polygons(np.concatenate(quads))
    assert abs(shapely.area(cells).sum() / water.area - 1.0) <= 0.1
    for hole in water.interiors:
        island = shapely.Polygon(hole)
        assert not shapely.contains(island, shapely.centroid(cells)).any()  # no cell over the island
        # ... and the grid goes round it: its shore nodes follow the island's whole ring
        on = shore[shapely.distance(island.exterior, shapely.points(shore)) <= tol]
        along = shapely.line_locate_point(island.exterior, shapely.points(on))
        assert len(on) >= 8 and shapely.Polygon(on[np.argsort(along)]).area > 0.8 * island.area


# ------------------------------------------------------------------ independent readers
def vtm_blocks(path: Path) -> list[tuple[np.ndarray, np.ndarray]]:
    vtk = pytest.importorskip("vtk")
    from vtk.util.numpy_support import vtk_to_numpy

    r = vtk.vtkXMLMultiBlockDataReader()
    r.SetFileName(str(path))
    r.Update()
    mb = r.GetOutput()
    out = []
    for k in range(mb.GetNumberOfBlocks()):
        b = mb.GetBlock(k)
        e = b.GetExtent()
        shape = (e[1] - e[0] + 1, e[3] - e[2] + 1)
        pts = vtk_to_numpy(b.GetPoints().GetData())
        out.append((pts[:, 0].reshape(shape, order="F"), pts[:, 1].reshape(shape, order="F")))
    return out


def plot3d_blocks(path: Path) -> list[tuple[np.ndarray, np.ndarray]]:
    """A multi-grid 2-D PLOT3D file in Fortran records (little-endian, double)."""
    raw, pos, recs = path.read_bytes(), 0, []
    while pos < len(raw):
        n = int(np.frombuffer(raw, "<i4", 1, pos)[0])
        assert int(np.frombuffer(raw, "<i4", 1, pos + 4 + n)[0]) == n
        recs.append(raw[pos + 4 : pos + 4 + n])
        pos += n + 8
    nb = int(np.frombuffer(recs[0], "<i4")[0])
    dims = np.frombuffer(recs[1], "<i4").reshape(nb, 2)
    assert len(recs) == 2 + nb
    out = []
    for (ni, nj), rec in zip(dims, recs[2:], strict=True):
        xy = np.frombuffer(rec, "<f8").reshape(2, nj, ni)
        out.append((xy[0].T, xy[1].T))
    return out


def cgns_blocks(path: Path) -> tuple[str, list[tuple[np.ndarray, np.ndarray]]]:
    h5py = pytest.importorskip("h5py")
    with h5py.File(path, "r") as h:
        (base,) = (h[k] for k in h if not k.startswith(" ") and k != "CGNSLibraryVersion")
        crs = bytes(base["CRS"][" data"][:].astype(np.uint8)).decode()
        zones = [base[k] for k in base if bytes(np.asarray(base[k].attrs.get("label", b""))).startswith(b"Zone_t")]
        out = [
            (z["GridCoordinates/CoordinateX/ data"][:].T, z["GridCoordinates/CoordinateY/ data"][:].T) for z in zones
        ]
    return crs, out


def node_set(blocks) -> set:
    return {tuple(p) for x, y in blocks for p in np.round(np.column_stack([x.ravel(), y.ravel()]), 3).tolist()}


# ------------------------------------------------------------------ a real lake, every format
@pytest.fixture(scope="module")
def ness(tmp_path_factory):
    d = tmp_path_factory.mktemp("ness")
    src = LAKES / "loch_ness_sparse.geojson"
    outs = [d / f"ness.{s}" for s in ("vtm", "ddb", "cgns", "xyz", "npz")]
    run = mesh(
        src,
        "--cells",
        1500,
        *[a for o in outs for a in ("-o", o)],
        "--png",
        d / "ness.png",
        "--preset",
        "delft3d",
        "--preset",
        "efdc",
    )
    water = projected(geojson_rings(src), "EPSG:32630")  # Loch Ness: 4.5° W, UTM zone 30 N
    return run, d, water


def test_ness_runs_with_progress_summary_and_verdicts(ness):
    run, d, _ = ness
    assert run.rc == 0, run.err
    gs = read_blocks(d / "ness.npz")
    n = len(gs.blocks)
    assert n >= 2
    err = run.err.splitlines()
    stages = [
        "read ",
        "water area",
        f"layout: {n} blocks",
        "grid level 1/3",
        "grid level 2/3",
        "grid level 3/3",
        "quality:",
    ]
    starts = [next(k for k, ln in enumerate(err) if s in ln) for s in stages]
    assert starts == sorted(starts)
    assert "EPSG:32630" in err[starts[0]] and "no islands" in err[starts[0]]
    assert any("ness.ddb" in ln and "--regular" in ln for ln in err)  # said, not silently done
    for s in ("vtm", "ddb", "cgns", "xyz", "npz", "png"):
        assert f"wrote {d / f'ness.{s}'}" in run.err
    cells = sum(g.cells[0] * g.cells[1] for g in gs.blocks)
    assert 750 <= cells <= 3000  # --cells 1500: within 0.5-2×
    assert "| blocks / cells / interior nodes" in run.out and f"{n} / {cells} /" in run.out
    assert "delft3d: " in run.out and "efdc: " in run.out and run.out.count("verdict: ") == 2
    assert f"{n} blocks, {cells:,} cells in" in run.out


def test_ness_world_coordinates_are_the_projected_outline(ness):
    _, d, water = ness
    gs = read_blocks(d / "ness.npz")
    assert gs.frame.crs == "EPSG:32630" and gs.frame.origin == (0.0, 0.0)
    check_covers_the_water(blocks_of(gs), water)


def test_ness_vtm_cgns_plot3d_read_back_by_independent_readers(ness):
    _, d, _ = ness
    ref = blocks_of(read_blocks(d / "ness.npz"))
    crs, cg = cgns_blocks(d / "ness.cgns")
    assert crs == "EPSG:32630"
    for got in (vtm_blocks(d / "ness.vtm"), cg, plot3d_blocks(d / "ness.xyz")):
        assert len(got) == len(ref)
        for (x, y), (X, Y) in zip(got, ref, strict=True):
            np.testing.assert_array_equal(x, X)
            np.testing.assert_array_equal(y, Y)
    for f in ("ness.vtm", "ness.cgns", "ness.xyz"):  # and by meshcore's readers, with the CRS where stored
        gs = read_blocks(d / f)
        assert gs.frame.origin == (0.0, 0.0) and gs.frame.crs == (None if f.endswith("xyz") else "EPSG:32630")
        for (x, y), (X, Y) in zip(blocks_of(gs), ref, strict=True):
            np.testing.assert_array_equal(x, X)
            np.testing.assert_array_equal(y, Y)


def test_ness_delft3d_domain_decomposition_reads_back(ness):
    _, d, _ = ness
    ref = blocks_of(read_blocks(d / "ness.npz"))
    lines = parse_ddb(d / "ness.ddb")
    files = sorted({ln[0] for ln in lines} | {ln[2] for ln in lines})
    assert len(files) == len(ref)  # every block coupled
    grd = {f: parse_grd(d / f) for f in files}
    assert node_set(grd.values()) == node_set(ref)  # the same nodes, in world coordinates
    for f in files:
        assert any(ln.startswith("* Projection: EPSG:32630") for ln in (d / f).read_text().splitlines())
    for fa, mna, fb, mnb in lines:  # each coupling joins coinciding grid points
        np.testing.assert_allclose(segment(*grd[fa], mna), segment(*grd[fb], mnb), atol=1e-6)
    assert len(read_blocks(d / "ness.ddb").blocks) == len(ref)


def test_ness_figure_is_an_image(ness):
    _, d, _ = ness
    assert (d / "ness.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


# ------------------------------------------------------------------ islands
def test_kml_islands_are_left_out_of_the_grid(tmp_path):
    src = LAKES / "quabbin_sparse.kml"  # one island (innerBoundaryIs)
    run = mesh(src, "--cells", 1500, "-o", tmp_path / "q.vtm", "--png", tmp_path / "q.png", "--colour", "deviation")
    assert run.rc == 0, run.err
    assert "1 island" in run.err
    water = projected(kml_rings(src), "EPSG:32618")  # 72.3° W: UTM zone 18 N
    assert len(water.interiors) == 1
    check_covers_the_water(vtm_blocks(tmp_path / "q.vtm"), water)
    assert (tmp_path / "q.png").stat().st_size > 10_000


def test_a_lake_with_an_island_is_written_as_domain_decomposition(tmp_path):
    """Lake Iseo (one island) as Delft3D DD: the blocks round the island close up (before the
    regular layout's corners were re-chosen, every lake with islands was refused here)."""
    src = LAKES / "lake_iseo_sparse.geojson"
    run = mesh(src, "--cells", 2000, "-o", tmp_path / "i.ddb", "-o", tmp_path / "i.npz")
    assert run.rc == 0, run.err
    assert "1 island" in run.err
    ref = blocks_of(read_blocks(tmp_path / "i.npz"))
    lines = parse_ddb(tmp_path / "i.ddb")
    files = sorted({ln[0] for ln in lines} | {ln[2] for ln in lines})
    assert len(files) == len(ref)  # every block coupled
    grd = {f: parse_grd(tmp_path / f) for f in files}
    assert node_set(grd.values()) == node_set(ref)
    for fa, mna, fb, mnb in lines:  # each coupling joins coinciding grid points, M-lines to M-lines
        assert (mna[0] == mna[2]) == (mnb[0] == mnb[2])
        np.testing.assert_allclose(segment(*grd[fa], mna), segment(*grd[fb], mnb), atol=1e-6)
    from meshcore.io.delft3d_dd import read_dd

    read_dd(tmp_path / "i.ddb").topology(check_geometry=False)
    water = projected(geojson_rings(src), "EPSG:32632")  # 10.1° E: UTM zone 32 N
    check_covers_the_water(ref, water)


def _synthetic_rings(x0: float = 500_000.0, y0: float = 5_200_000.0):
    """An elliptic lake (6 × 3.6 km) with a round island (1 km) off its centre, in metres."""
    t = np.linspace(0, 2 * np.pi, 48, endpoint=False)
    s = np.linspace(0, 2 * np.pi, 16, endpoint=False)
    shore = np.column_stack([x0 + 3000 * np.cos(t), y0 + 1800 * np.sin(t)])
    island = np.column_stack([x0 + 800 + 500 * np.cos(s), y0 + 200 + 500 * np.sin(-s)])
    return shore, island


@pytest.fixture
def synthetic_csv(tmp_path):
    """The synthetic lake as ``x,y,ring`` rows in metres, no CRS (an extra ring = an island)."""
    f = tmp_path / "lake.csv"
    shore, island = _synthetic_rings()
    rows = [f"{x:.3f},{y:.3f},shore" for x, y in shore] + [f"{x:.3f},{y:.3f},island" for x, y in island]
    f.write_text("x,y,ring\n" + "\n".join(rows) + "\n")
    return f


def test_a_fine_grids_figure_fades_its_lines_instead_of_going_dark(tmp_path, synthetic_csv):
    """At 40 000 cells the --png lines were ~1 pixel apart: the figure went dark, hiding the blocks'
    colours (a 100 000-cell lake, a long river: black bands). Lines fade with the cells' size in
    pixels, as on the app's canvas: the figure stays about as light as a coarse grid's."""
    from PIL import Image

    light = {}
    for cells in (2000, 40000):
        run = mesh(synthetic_csv, "--cells", cells, "-o", tmp_path / "s.npz", "--png", tmp_path / f"f{cells}.png")
        assert run.rc == 0, run.err
        light[cells] = float(np.asarray(Image.open(tmp_path / f"f{cells}.png").convert("L"), float).mean())
    assert light[2000] - light[40000] < 9.0, light  # 15.4 grey levels darker before


def test_csv_rings_without_a_crs_keep_the_file_coordinates(tmp_path, synthetic_csv):
    run = mesh(synthetic_csv, "--cell-size", 150, "-o", tmp_path / "s.vtm", "-o", tmp_path / "s.npz")
    assert run.rc == 0, run.err
    assert (
        "1 island" in run.err
        and "no CRS: the grid keeps the file's coordinates" in run.err
        and "cell size 150 (--cell-size" in run.err
    )
    gs = read_blocks(tmp_path / "s.npz")
    assert gs.frame.crs is None and gs.frame.origin == (0.0, 0.0)
    shore, island = (np.round(r, 3) for r in _synthetic_rings())
    water = shapely.Polygon(shore, [island])
    check_covers_the_water(vtm_blocks(tmp_path / "s.vtm"), water)
    cells = sum(g.cells[0] * g.cells[1] for g in gs.blocks)
    assert 0.5 <= cells / (water.area / 150**2) <= 2.0


def test_geojson_interior_ring_in_lon_lat_to_a_given_crs(tmp_path):
    """Lon/lat in, ``--crs EPSG:3035`` (ETRS89-LAEA) out: coordinates and CRS are that CRS's."""
    to_ll = pyproj.Transformer.from_crs("EPSG:32633", "EPSG:4326", always_xy=True)
    rings = [np.column_stack(to_ll.transform(r[:, 0], r[:, 1])) for r in _synthetic_rings()]
    f = tmp_path / "lake.geojson"
    coords = [[[round(a, 7), round(b, 7)] for a, b in [*r, r[0]]] for r in rings]
    f.write_text(
        json.dumps({"type": "Feature", "properties": {}, "geometry": {"type": "Polygon", "coordinates": coords}})
    )
    run = mesh(f, "--cells", 600, "--crs", "EPSG:3035", "-o", tmp_path / "s.cgns", "-q")
    assert run.rc == 0 and run.out == "" and run.err == "", run.err
    crs, blocks = cgns_blocks(tmp_path / "s.cgns")
    assert crs == "EPSG:3035"
    check_covers_the_water(blocks, projected(geojson_rings(f), "EPSG:3035"))


def test_an_open_line_in_the_water_of_a_geojson_is_a_path_not_an_island(tmp_path, synthetic_csv):
    """A ferry route (a LineString) in a file with the lake's Polygon was read as a ring: an island
    of water left out of the grid, without a word. In a CSV an open ring is still an island."""
    to_ll = pyproj.Transformer.from_crs("EPSG:32633", "EPSG:4326", always_xy=True)
    shore, island = _synthetic_rings()
    lo, hi = shore.min(axis=0), shore.max(axis=0)
    route = np.array([lo + (hi - lo) * f for f in ((0.2, 0.3), (0.5, 0.45), (0.8, 0.3))])  # in the water
    ll = [np.column_stack(to_ll.transform(r[:, 0], r[:, 1])).round(7).tolist() for r in (shore, island, route)]
    feats = [
        {
            "type": "Feature",
            "properties": {"name": "lake"},
            "geometry": {"type": "Polygon", "coordinates": [ll[0] + ll[0][:1], ll[1] + ll[1][:1]]},
        },
        {"type": "Feature", "properties": {"name": "ferry"}, "geometry": {"type": "LineString", "coordinates": ll[2]}},
    ]
    areas = []
    for k, fs in enumerate((feats[:1], feats)):  # without the route, then with it
        f = tmp_path / f"lake{k}.geojson"
        f.write_text(json.dumps({"type": "FeatureCollection", "features": fs}))
        run = mesh(f, "--cells", 600, "-o", tmp_path / f"s{k}.npz")
        assert run.rc == 0, run.err
        areas.append(next(ln for ln in run.err.splitlines() if ln.startswith("water area")))
    assert "'ferry': an open line in the water" in run.err and "1 island" in run.err
    assert areas[0] == areas[1]  # the same water, the same cells
    # a CSV's rings need no closing point: its open third ring is an island (the route as a ring)
    rows = [f"{x:.3f},{y:.3f},{n}" for n, r in (("shore", shore), ("isle", island), ("route", route)) for x, y in r]
    g = tmp_path / "rings.csv"
    g.write_text("x,y,ring\n" + "\n".join(rows) + "\n")
    run = mesh(g, "--cells", 600, "-o", tmp_path / "t.npz")
    assert run.rc == 0 and "2 islands" in run.err, run.err


def test_geojson_in_projected_metres_needs_and_takes_source_crs(tmp_path):
    """GeoJSON is lon/lat by its spec; a file in UTM metres is refused with the way out named,
    and ``--source-crs`` reads it as such (the grid stays in those metres)."""
    f = tmp_path / "utm.geojson"
    coords = [[[round(a, 3), round(b, 3)] for a, b in [*r, r[0]]] for r in _synthetic_rings()]
    f.write_text(json.dumps({"type": "Polygon", "coordinates": coords}))
    run = mesh(f, "--cells", 600, "-o", tmp_path / "s.cgns", "-q")
    assert run.rc == 2 and "outside the lon/lat range" in run.err and "--source-crs" in run.err, run.err
    assert not (tmp_path / "s.cgns").exists()
    run = mesh(f, "--cells", 600, "--source-crs", "EPSG:32633", "-o", tmp_path / "s.cgns", "-q")
    assert run.rc == 0, run.err
    crs, blocks = cgns_blocks(tmp_path / "s.cgns")
    assert crs == "EPSG:32633"
    shore, island = (np.round(r, 3) for r in _synthetic_rings())
    check_covers_the_water(blocks, shapely.Polygon(shore, [island]))


def test_shapefile_hole_is_an_island(tmp_path):
    shp = pytest.importorskip("shapefile")
    shore, island = _synthetic_rings()
    # our own file objects, closed here: pyshp 3.1.9's Writer leaves the .dbf it opens unclosed
    # (a ResourceWarning, an error under the suite's filterwarnings)
    with contextlib.ExitStack() as files:
        f = {ext: files.enter_context(open(tmp_path / f"lake.{ext}", "wb")) for ext in ("shp", "shx", "dbf")}
        with shp.Writer(shapeType=shp.POLYGON, **f) as w:
            w.field("name", "C")
            w.poly(
                [shore[::-1].tolist(), island[::-1].tolist()]
            )  # shapefile: outer ring clockwise, holes counter-clockwise
            w.record("lake")
    run = mesh(tmp_path / "lake.shp", "--cells", 400, "-o", tmp_path / "s.vtm")
    assert run.rc == 0, run.err
    assert "1 island" in run.err
    check_covers_the_water(vtm_blocks(tmp_path / "s.vtm"), shapely.Polygon(shore, [island]))


def test_dxf_shore_with_an_inlet_line_in_utm(tmp_path):
    """A DXF (no CRS in the file) in UTM metres: --source-crs names it; the open inlet line drawn
    from the shore is not an island."""
    ezdxf = pytest.importorskip("ezdxf")
    src = ROOT / "tests" / "data" / "lake_zurich_sparse_utm32.dxf"
    run = mesh(src, "--source-crs", "EPSG:32632", "--cells", 600, "-o", tmp_path / "z.vtm")
    assert run.rc == 0, run.err
    assert "'inlet" in run.err and "not an island: ignored" in run.err and "no islands" in run.err
    (shore,) = ezdxf.readfile(src).modelspace().query("LWPOLYLINE")
    gs = read_blocks(tmp_path / "z.vtm")
    assert gs.frame.crs == "EPSG:32632"
    check_covers_the_water(blocks_of(gs), shapely.Polygon(np.array(shore.get_points("xy"))))


def test_the_command_is_mesh_outline(tmp_path, synthetic_csv):
    """The grid written is the one ``meshcore.mesh_outline`` returns for the same outline."""
    import meshcore
    from meshcore import lakegrid, layout

    assert meshcore.mesh_outline is lakegrid.mesh_outline and meshcore.auto_layout is layout.auto_layout
    assert mesh(synthetic_csv, "--cells", 400, "-o", tmp_path / "s.npz", "-q").rc == 0
    shore, island = (np.round(r, 3) for r in _synthetic_rings())
    water = shapely.Polygon(shore, [island])
    mb = meshcore.mesh_outline(shore, holes=[island], cell_size=math.sqrt(water.area / 400))
    got = read_blocks(tmp_path / "s.npz").blocks
    assert len(got) == len(mb.grids) == len(meshcore.auto_layout(water, cell_size=math.sqrt(water.area / 400)).blocks)
    for a, b in zip(got, mb.grids, strict=True):
        np.testing.assert_array_equal(a.x, b.x)
        np.testing.assert_array_equal(a.y, b.y)


# ------------------------------------------------------------------ exit code 2: nothing written
def _refused(run: Run, folder: Path, *needles: str, before: set | None = None) -> None:
    assert run.rc == 2, (run.rc, run.err)
    assert run.err.count("\n") == 1 and "Traceback" not in run.err, run.err
    for n in needles:
        assert n in run.err, (n, run.err)
    assert set(os.listdir(folder)) == (before or set()), "an output was written"


def test_default_cell_size_and_a_one_block_format_refused_before_the_solve(tmp_path, synthetic_csv):
    """Without --cell-size: about 10 000 cells; a .vts cannot hold them: refused after the layout."""
    out = tmp_path / "out"
    out.mkdir()
    run = mesh(synthetic_csv, "-o", out / "s.vtm", "-o", out / "s.vts")
    assert run.rc == 2 and "Traceback" not in run.err
    assert "sqrt(water area / 10000), about 10,000 cells" in run.err
    assert "grid level" not in run.err  # refused before the solve
    layout_cells = int(next(ln for ln in run.err.splitlines() if ln.startswith("layout:")).split()[3].replace(",", ""))
    assert 5_000 <= layout_cells <= 20_000
    assert "-o" in run.err.splitlines()[-1] and "s.vts" in run.err.splitlines()[-1] and "holds one block" in run.err
    assert os.listdir(out) == []


def test_a_vtm_whose_block_folder_holds_the_input_is_refused_before_the_solve(tmp_path, synthetic_csv):
    """``-o lake.vtm`` puts its blocks in ``lake/``, replaced whole: with the outline in that folder
    the write deleted it (after the solve); now the command stops before any work."""
    lake = tmp_path / "lake"
    lake.mkdir()
    src = lake / "outline.csv"
    src.write_bytes(Path(synthetic_csv).read_bytes())
    run = mesh(src, "-o", tmp_path / "lake.vtm")
    assert run.rc == 2 and "Traceback" not in run.err
    assert "outline.csv" in run.err.splitlines()[-1] and "grid level" not in run.err
    assert not (tmp_path / "lake.vtm").exists() and os.listdir(lake) == ["outline.csv"]


@pytest.mark.parametrize(
    ("text", "needles"),
    [
        ("x,y\n0,0\n4000,0\nabc,2000\n0,2000\n", ("bad.csv", "line 4")),
        ("x,y\n0,0\n4000,2000\n4000,0\n0,2000\n", ("bad.csv", "crosses itself", "point")),  # a bow tie
        (  # a second ring reaching into the shore: two parts of water that overlap (was: a second lake)
            "x,y,ring\n0,0,shore\n4000,0,shore\n4000,2000,shore\n0,2000,shore\n0,0,shore\n"
            "3500,500,other\n6000,500,other\n6000,1000,other\n3500,500,other\n",
            ("bad.csv", "'shore' and 'other' overlap or touch near (4000,"),
        ),
        (  # an island drawn across the shore: named, with the place where it crosses
            "x,y,ring\n0,0,shore\n4000,0,shore\n4000,2000,shore\n0,2000,shore\n"
            "3000,800,isle\n4500,800,isle\n4500,1200,isle\n3000,1200,isle\n3000,800,isle\n",
            ("bad.csv", "'isle' crosses the shore of 'shore' near (4000, 1200)"),
        ),
    ],
    ids=["not-a-number", "bow-tie", "overlapping-parts", "island-across-the-shore"],
)
def test_bad_outline_file(tmp_path, text, needles):
    f = tmp_path / "bad.csv"
    f.write_text(text)
    out = tmp_path / "out"
    out.mkdir()
    _refused(mesh(f, "-o", out / "s.vtm", "--png", out / "s.png"), out, *needles)


def test_missing_file_and_unknown_crs(tmp_path, synthetic_csv):
    out = tmp_path / "out"
    out.mkdir()
    _refused(mesh(tmp_path / "nope.kml", "-o", out / "s.vtm"), out, "nope.kml", "no such file")
    src = LAKES / "loch_ness_sparse.kml"
    _refused(mesh(src, "--crs", "EPSG:999999", "-o", out / "s.vtm"), out, "unknown CRS 'EPSG:999999'")
    _refused(mesh(src, "--crs", "EPSG:4326", "-o", out / "s.vtm"), out, "--crs", "projected")


@pytest.mark.parametrize(
    ("outputs", "needles"),
    [
        (["-o", "{out}/missing/s.vtm"], ("-o", "missing", "does not exist")),
        (["-o", "{out}/s.vtm", "-o", "{out}/s.foo"], ("-o", "s.foo", "cannot write .foo")),
        (["-o", "{out}/s.vtm", "--png", "{out}/s.vtm"], ("--png", "figure")),
        (["-o", "{out}/s.vtm", "-o", "{out}/s.vtm"], ("-o", "the same file")),
        (["-o", "{out}"], ("-o", "is a folder")),
    ],
    ids=["no-folder", "unknown-format", "png-not-a-figure", "twice", "a-folder"],
)
def test_unwritable_output_refused_before_reading(tmp_path, synthetic_csv, outputs, needles):
    out = tmp_path / "out"
    out.mkdir()
    argv = [a.format(out=out) for a in outputs]
    _refused(mesh(synthetic_csv, *argv), out, *needles)


@pytest.mark.skipif(os.name != "posix" or os.geteuid() == 0, reason="needs a folder the user cannot write")
def test_read_only_folder_refused(tmp_path, synthetic_csv):
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o500)
    try:
        _refused(mesh(synthetic_csv, "-o", ro / "s.vtm"), ro, "permission denied")
    finally:
        ro.chmod(0o700)


@pytest.mark.parametrize(
    ("argv", "needle"),
    [
        (["--cells", "0"], "--cells must be >= 16"),
        (["--cell-size", "-5"], "--cell-size must be a positive"),
        (["--cell-size", "nan"], "--cell-size must be a positive"),
        (["--cell-size", "0.01"], "--cell-size 0.01 gives about 161,508,"),
        (["--cell-size", "1e-300"], "gives about inf cells"),
        (["--cell-size", "5000"], "give a cell size of at most 1005"),
    ],
)
def test_bad_sizes(tmp_path, synthetic_csv, argv, needle):
    out = tmp_path / "out"
    out.mkdir()
    _refused(mesh(synthetic_csv, *argv, "-o", out / "s.vtm", "-q"), out, needle)


# ------------------------------------------------------------------ exit code 3 and 1
def _spoiled(fold: bool):
    from meshcore import lakegrid

    real = lakegrid.mesh_layout

    def spoiled(lay, **kw):
        mb = real(lay, **kw)
        if not fold:
            return dataclasses.replace(mb, info=dataclasses.replace(mb.info, converged=False))
        g = mb.grids[0]
        x, y = np.array(g.x), np.array(g.y)
        x[1, 1], y[1, 1] = x[-2, -2], y[-2, -2]  # an interior node thrown across its block: folds
        return dataclasses.replace(mb, grids=(g.replaced(x=x, y=y), *mb.grids[1:]))

    return spoiled


@pytest.mark.parametrize(("fold", "needle"), [(True, "folded or non-convex cells"), (False, "did not converge")])
def test_a_grid_with_folds_or_not_converged_is_written_and_exits_3(tmp_path, synthetic_csv, monkeypatch, fold, needle):
    from meshcore import lakegrid

    monkeypatch.setattr(lakegrid, "mesh_layout", _spoiled(fold))
    run = mesh(synthetic_csv, "--cells", 400, "-o", tmp_path / "s.vtm")
    assert run.rc == 3, run.err
    assert needle in run.err.splitlines()[-1] and "exit code 3" in run.err
    assert len(read_blocks(tmp_path / "s.vtm").blocks) >= 1
    quality = next(ln for ln in run.err.splitlines() if ln.startswith("quality:"))
    assert (int(quality.split()[1]) > 0) == fold


def test_a_cell_far_smaller_than_the_rest_is_told_even_quietly(tmp_path, synthetic_csv, monkeypatch):
    from meshcore.quality import lake

    run = mesh(synthetic_csv, "--cells", 400, "-o", tmp_path / "s.vtm", "-q")
    assert run.rc == 0 and "note: cell" not in run.err  # this lake's cells are alike
    monkeypatch.setattr(lake, "SHRINK_NOTE", 1.0)  # every grid's smallest cell told
    run = mesh(synthetic_csv, "--cells", 400, "-o", tmp_path / "t.vtm", "-q")
    notes = [ln for ln in run.err.splitlines() if ln.startswith("meshcore mesh: note: cell")]
    assert run.rc == 0 and len(notes) == 1, run.err
    shrink = float(re.search(r"explicit time step ÷ ([0-9.]+)\)", notes[0]).group(1))
    m = lake.lake_metrics(read_blocks(tmp_path / "t.vtm").blocks)
    assert shrink == pytest.approx(m.max("shrink"), rel=0.05)  # against the written grid's own (its mean size)


def test_a_bug_in_the_pipeline_is_one_line_and_exit_1(tmp_path, synthetic_csv, monkeypatch):
    from meshcore import lakegrid

    def broken(lay, **kw):
        raise IndexError("index 7 is out of bounds")

    monkeypatch.setattr(lakegrid, "mesh_layout", broken)
    out = tmp_path / "out"
    out.mkdir()
    run = mesh(synthetic_csv, "--cells", 400, "-o", out / "s.vtm", "-q")
    assert run.rc == 1 and run.err.count("\n") == 1 and "Traceback" not in run.err
    assert "internal error" in run.err and "IndexError: index 7" in run.err and "lake.csv" in run.err
    assert os.listdir(out) == []


# ------------------------------------------------------------------ the layout as a case file
def test_case_file_of_the_layout_generates_the_same_grid_and_can_be_edited(tmp_path, synthetic_csv):
    """``--case`` writes the layout; ``meshcore generate`` of it gives the grid ``mesh`` wrote."""
    from meshcore.case import load_case

    run = mesh(synthetic_csv, "--cells", 400, "-o", tmp_path / "m.npz", "--case", tmp_path / "lay.toml", "-q")
    assert run.rc == 0, run.err
    case = load_case(tmp_path / "lay.toml")
    assert case.settings.mode == "orthogonal" and len(case.outline.holes) == 1  # the island
    # the water as read, for the app ([lake]): the shore of the file, not the layout's (every block vertex)
    shore, _island = _synthetic_rings()
    assert len(case.lake.shore) == len(shore) < len(case.outline.points) and len(case.lake.islands) == 1
    assert case.lake.cell_size is not None and not case.lake.regular  # --cells 400
    o, e = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(o), contextlib.redirect_stderr(e):
        rc = main(["generate", str(tmp_path / "lay.toml"), "-o", str(tmp_path / "g.npz")])
    assert rc == 0, e.getvalue()
    a, b = read_blocks(tmp_path / "m.npz").blocks, read_blocks(tmp_path / "g.npz").blocks
    assert len(a) == len(b) == len(case.outline.blocks)
    for ga, gb in zip(a, b, strict=True):  # to the last bit: the same shore, vertex for vertex
        np.testing.assert_array_equal(ga.x, gb.x)
        np.testing.assert_array_equal(ga.y, gb.y)


def test_case_option_refused_before_the_work(tmp_path, synthetic_csv):
    run = mesh(synthetic_csv, "--cells", 400, "-o", tmp_path / "m.npz", "--case", tmp_path / "lay.txt")
    _refused(run, tmp_path, "--case", ".toml", before={"lake.csv"})
    run = mesh(synthetic_csv, "--cells", 400, "-o", tmp_path / "m.npz", "--case", tmp_path / "no" / "lay.toml")
    _refused(run, tmp_path, "--case", "folder", before={"lake.csv"})


def test_lake_rings_and_lonlat_rules_shared_with_the_app(tmp_path):
    """The rules ``meshcore mesh`` and the app's import share (:mod:`meshcore.cli.mesh`): bare
    numbers that look like degrees are lon/lat, metres are not, a declared CRS decides; an open
    line of two points touching the shore is dropped with a note, one off the shore is an error."""
    from meshcore.cli.lakefile import is_lonlat, lake_rings
    from meshcore.errors import InvalidInputError
    from meshcore.io import read_points

    shore, island = _synthetic_rings()
    to_ll = pyproj.Transformer.from_crs("EPSG:32633", "EPSG:4326", always_xy=True)
    ll = [np.column_stack(to_ll.transform(r[:, 0], r[:, 1])) for r in (shore, island)]
    inlet = np.vstack([ll[0][5], ll[0][5] + 0.2 * (ll[1].mean(axis=0) - ll[0][5])])

    def csv(name, rings, header=""):
        f = tmp_path / name
        f.write_text(header + "\n\n".join("\n".join(f"{x:.7f},{y:.7f}" for x, y in r) for r in rings) + "\n")
        return read_points(f)

    bare = csv("bare.csv", [*ll, inlet])
    assert bare.crs is None and is_lonlat(bare) and not is_lonlat(bare, "EPSG:32633")
    assert not is_lonlat(csv("metres.csv", [shore, island]))
    outer, islands, notes = lake_rings(bare)
    assert len(outer) == len(shore) and len(islands) == 1 and len(notes) == 1 and "touching the shore" in notes[0]
    away = np.vstack([ll[1].mean(axis=0), ll[1].mean(axis=0) + 1e-3])  # two points inside the island's bay
    with pytest.raises(InvalidInputError, match="3 distinct points"):
        lake_rings(csv("away.csv", [*ll, away]))
    run = mesh(tmp_path / "bare.csv", "--cells", 300, "-o", tmp_path / "b.npz")
    assert run.rc == 0 and "touching the shore" in run.err and "EPSG:32633" in run.err, run.err


def test_places_in_notes_are_in_the_grids_crs(tmp_path, monkeypatch):
    """A note's ``near (x, y)`` names a place in the output's coordinates (the CRS, origin
    added), as the quality table does: a lon/lat lake whose layout has too few cells."""
    from meshcore import testing
    from meshcore.layout import choice, fans

    poly = testing.round_lake(1021, kind="blob")  # regular: a layout with 0.25 × the asked cells
    monkeypatch.setattr(fans, "_wraps", lambda *a, **k: False)  # (with its C-shaped block round the island)
    monkeypatch.setattr(choice, "WIDE_SCALES", ())  # (the wide scales find a layout with more cells)
    lon0, lat0, deg = 10.0, 45.0, 300.0 / 111_320.0  # 1 unit = 300 m
    rings = [np.asarray(r.coords) for r in (poly.exterior, *poly.interiors)]
    kx = deg / math.cos(math.radians(lat0))
    lonlat = [np.column_stack([lon0 + r[:, 0] * kx, lat0 + r[:, 1] * deg]) for r in rings]
    path = tmp_path / "lake.geojson"
    geom = {"type": "Polygon", "coordinates": [r.tolist() for r in lonlat]}
    path.write_text(json.dumps({"type": "Feature", "geometry": geom, "properties": {}}))
    water = projected(lonlat, "EPSG:32632")
    h = math.sqrt(water.area / 3000)
    r = mesh(path, "--cell-size", h, "-o", tmp_path / "g.vtm", "-q", "--regular")
    assert r.rc in (0, 3), r.err
    (note,) = [n for n in r.err.splitlines() if "× the cells of the asked size" in n]
    x, y = (float(v) for v in note.split("near (")[1].split(")")[0].split(", "))
    assert water.buffer(h).contains(shapely.Point(x, y)), (x, y, water.bounds)


def test_in_world_moves_only_places_by_the_origin():
    from types import SimpleNamespace

    from meshcore.cli.lakefile import in_world

    frame = SimpleNamespace(origin=(500000.0, 5000000.0))
    msg = "block b3 (24, 16) near (-5920.77, 2728.88) and near (1e-05, -3.5e+02); cells (4, 8)"
    assert in_world(msg, frame) == (
        "block b3 (24, 16) near (494079.23, 5002728.88) and near (500000.00001, 4999650); cells (4, 8)"
    )
    assert in_world(msg, SimpleNamespace(origin=(0.0, 0.0))) == msg
    assert in_world(msg, None) == msg


def test_curve_draws_the_shore_through_the_points_and_stays_near_them(tmp_path, synthetic_csv):
    """``--layout-option curve``: the grid's shore follows a smooth curve through the outline's points (a note
    says so). The synthetic lake's 48 points (about two cells apart) lie on an ellipse: the
    grid's shore nodes get nearer that ellipse than along the straight segments, and stay
    within half a cell of the outline as given."""
    x0, y0 = 500_000.0, 5_200_000.0
    t = np.linspace(0, 2 * np.pi, 20_000)
    ellipse = shapely.LinearRing(np.column_stack([x0 + 3000 * np.cos(t), y0 + 1800 * np.sin(t)]))
    shore, _ = _synthetic_rings()
    given = shapely.LinearRing(np.round(shore, 3))
    worst = {}
    for flag in ((), ("--layout-option", "curve")):
        out = tmp_path / f"c{len(flag)}.npz"
        run = mesh(synthetic_csv, "--cell-size", 150, *flag, "-o", out)
        assert run.rc == 0, run.err
        assert ("smooth curve through the outline's points" in run.err) == bool(flag)
        border = np.concatenate(
            [np.column_stack([g.x[k], g.y[k]]) for g in read_blocks(out).blocks for k in (0, -1)]
            + [np.column_stack([g.x[:, k], g.y[:, k]]) for g in read_blocks(out).blocks for k in (0, -1)]
        )
        on_shore = border[shapely.distance(shapely.points(border), given) < 0.3 * 150]
        assert len(on_shore) > 50
        worst[flag] = float(shapely.distance(shapely.points(on_shore), ellipse).max())
        assert float(shapely.distance(shapely.points(on_shore), given).max()) < 0.5 * 150
    assert worst[("--layout-option", "curve")] < 0.5 * worst[()]


def test_layout_options_name_every_field_and_refuse_others(tmp_path, synthetic_csv):
    """Every ``--layout-option`` name is a field of LayoutOptions and every field has a name; an
    unknown name is refused by the parser (exit 2, the choices listed) before any work."""
    import dataclasses
    from types import SimpleNamespace

    from meshcore.cli.mesh_steps import LAYOUT_OPTIONS, layout_options
    from meshcore.layout import LayoutOptions

    fields = {f.name for f in dataclasses.fields(LayoutOptions)}
    assert {n.replace("-", "_") for n in LAYOUT_OPTIONS} == fields
    both = layout_options(SimpleNamespace(layout_option=["thin-arms", "wedges"]))
    assert both == LayoutOptions(thin_arms=True, wedges=True)
    assert str(both) == "thin arms, wedges" and str(LayoutOptions()) == "defaults"
    out = tmp_path / "x.npz"
    run = mesh(synthetic_csv, "--layout-option", "spline", "-o", out)
    assert run.rc == 2 and "spline" in run.err and "thin-arms" in run.err
    assert not out.exists()


def test_a_layout_of_many_small_blocks_names_the_cells_that_would_give_them_more(tmp_path, synthetic_csv):
    """Lakes of many arms at the cells asked have blocks a few cells across, whose grids miss the
    edge-pair target (session 29); the command says so and names a --cells, and leaves the cells
    to the user. A coarse grid of a few blocks gets no such hint."""
    from meshcore import testing
    from meshcore.cellsize import MANY_BLOCKS, SMALL_BLOCKS

    net = tmp_path / "net.csv"
    ring = np.asarray(testing.channel_network(5, n_branches=12).exterior.coords)[:-1] * 1000.0
    net.write_text("x,y,ring\n" + "\n".join(f"{x:.3f},{y:.3f},shore" for x, y in ring) + "\n")
    hints = []
    for f, cells in ((net, 3000), (synthetic_csv, 400)):
        run = mesh(f, "--cells", cells, "-o", tmp_path / "s.npz")
        assert run.rc == 0, run.err
        n, c = (int(v.replace(",", "")) for v in re.search(r"layout: (\d+) blocks, ([\d,]+) cells", run.err).groups())
        hint = re.search(r"hint: (\d+) blocks of (\d+) cells on average.* --cells (\d+) gives", run.err)
        assert (hint is not None) == (n >= MANY_BLOCKS and c < SMALL_BLOCKS * n), run.err
        hints.append(hint is not None)
        if hint:
            assert int(hint[1]) == n and int(hint[2]) == c // n
            assert int(hint[3]) >= SMALL_BLOCKS * n > c
    assert hints == [True, False]  # the network of 12 arms, the 3-block lake
    assert "hint:" not in mesh(net, "--cells", 3000, "-o", tmp_path / "s.npz", "-q").err
