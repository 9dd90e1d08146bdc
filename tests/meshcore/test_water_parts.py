"""Water in several separate parts (a MultiPolygon, KML placemarks, CSV rings): one grid of all of
them, blocks named by part, ``--part``; overlapping parts refused; a part too small left out; the
note on a lon/lat lake wider than its UTM zone (:mod:`meshcore.lakeparts`, :mod:`meshcore.cli.mesh_parts`)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from tests.meshcore.test_mesh_cli import _refused, cgns_blocks, mesh, plot3d_blocks, vtm_blocks

shapely = pytest.importorskip("shapely")
pyproj = pytest.importorskip("pyproj")

T = np.linspace(0, 2 * np.pi, 40, endpoint=False)


def ellipse(x0, y0, a, b, n=40):
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    return np.column_stack([x0 + a * np.cos(t), y0 + b * np.sin(t)])


def closed(r):
    return [*r.tolist(), r[0].tolist()]


# lon/lat: two lakes 7 km apart at 47.3° N, each with an island (the MultiPolygon's holes)
WEST, WEST_ISLE = ellipse(8.50, 47.30, 0.04, 0.015), ellipse(8.515, 47.302, 0.004, 0.002)[::-1]
EAST, EAST_ISLE = ellipse(8.60, 47.30, 0.025, 0.012), ellipse(8.59, 47.30, 0.004, 0.002)[::-1]
UTM32 = pyproj.Transformer.from_crs("EPSG:4326", "EPSG:32632", always_xy=True)


def utm(r):
    return np.column_stack(UTM32.transform(r[:, 0], r[:, 1]))


def block_names(path):
    vtk = pytest.importorskip("vtk")
    r = vtk.vtkXMLMultiBlockDataReader()
    r.SetFileName(str(path))
    r.Update()
    mb = r.GetOutput()
    return [mb.GetMetaData(k).Get(vtk.vtkCompositeDataSet.NAME()) for k in range(mb.GetNumberOfBlocks())]


def inside(blocks, poly, tol):
    return all(
        shapely.contains(poly.buffer(tol), shapely.points(np.column_stack([x.ravel(), y.ravel()]))).all()
        for x, y in blocks
    )


def test_a_multipolygon_geojson_gives_a_grid_of_every_part(tmp_path):
    """Both parts meshed at one cell size, their blocks named part1_…/part2_…, read back by VTK
    and by the Delft3D DD reader: no coupling between parts, every block inside its own part."""
    from meshcore.io.delft3d_dd import read_dd

    f = tmp_path / "lakes.geojson"
    geom = {
        "type": "MultiPolygon",
        "coordinates": [[closed(WEST), closed(WEST_ISLE)], [closed(EAST), closed(EAST_ISLE)]],
    }
    f.write_text(json.dumps({"type": "Feature", "properties": {"name": "mp"}, "geometry": geom}))
    outs = [tmp_path / f"g.{s}" for s in ("vtm", "ddb", "cgns", "xyz")]
    run = mesh(f, "--cells", 800, *(a for o in outs for a in ("-o", o)), "--regular")
    assert run.rc == 0, run.err
    assert "2 separate parts of water" in run.err
    assert "part 1: 'mp 1', area" in run.err and "centroid lon 8.49" in run.err
    assert "part 2: 'mp 2', area" in run.err and "centroid lon 8.6" in run.err and "1 island" in run.err
    assert "| 1 | mp 1 |" in run.out and "| 2 | mp 2 |" in run.out  # the quality per part, then the total
    names = block_names(tmp_path / "g.vtm")
    parts = {n.split("_")[0] for n in names}
    assert parts == {"part1", "part2"}
    water = {
        "part1": shapely.Polygon(utm(WEST), [utm(WEST_ISLE)]),
        "part2": shapely.Polygon(utm(EAST), [utm(EAST_ISLE)]),
    }
    blocks = vtm_blocks(tmp_path / "g.vtm")
    h = np.sqrt(sum(p.area for p in water.values()) / 800)
    for name, xy in zip(names, blocks, strict=True):
        assert inside([xy], water[name.split("_")[0]], 0.5 * h), name
    crs, cg = cgns_blocks(tmp_path / "g.cgns")  # every part in the CGNS and PLOT3D files too, node for node
    assert crs == "EPSG:32632"
    for other in (cg, plot3d_blocks(tmp_path / "g.xyz")):
        assert len(other) == len(blocks)
        for (x, y), (X, Y) in zip(other, blocks, strict=True):
            np.testing.assert_array_equal(x, X)
            np.testing.assert_array_equal(y, Y)
    dd = read_dd(tmp_path / "g.ddb")
    assert sorted(dd.blocks.block_names) == sorted(names)
    assert dd.interfaces and all(i.a.block.split("_")[0] == i.b.block.split("_")[0] for i in dd.interfaces)


def test_kml_placemarks_and_the_part_option(tmp_path):
    """Two placemarks are two parts named after them; --part 2 (or a list) meshes only those asked."""

    def placemark(name, r):
        ring = " ".join(f"{x:.6f},{y:.6f}" for x, y in closed(r))
        return (
            f"<Placemark><name>{name}</name><Polygon><outerBoundaryIs><LinearRing><coordinates>{ring}"
            f"</coordinates></LinearRing></outerBoundaryIs></Polygon></Placemark>"
        )

    f = tmp_path / "two.kml"
    f.write_text(
        '<kml xmlns="http://www.opengis.net/kml/2.2"><Document>'
        f"{placemark('Pond', EAST)}{placemark('Main basin', WEST)}</Document></kml>"
    )
    run = mesh(f, "--cells", 500, "--part", 2, "-o", tmp_path / "p2.vtm")
    assert run.rc == 0, run.err
    assert "part 1: 'Main basin'" in run.err and "part 2: 'Pond'" in run.err and "meshing part 2 of 2" in run.err
    names = block_names(tmp_path / "p2.vtm")
    assert names and all(n.startswith("part2_") for n in names)
    assert inside(vtm_blocks(tmp_path / "p2.vtm"), shapely.Polygon(utm(EAST)), 30.0)
    run = mesh(f, "--cells", 500, "--part", "1,2", "-o", tmp_path / "all.vtm", "-q")
    assert run.rc == 0 and {n.split("_")[0] for n in block_names(tmp_path / "all.vtm")} == {"part1", "part2"}
    out = tmp_path / "none"
    out.mkdir()
    run = mesh(f, "--part", 3, "-o", out / "x.vtm")  # after the parts are listed: which there are
    assert run.rc == 2 and "error: " in run.err and "no part 3: the water has 2 parts" in run.err
    assert "Traceback" not in run.err and not list(out.iterdir())


def csv_rings(path, rings):
    rows = ["x,y,ring"] + [f"{x:.3f},{y:.3f},{name}" for name, r in rings for x, y in closed(r)]
    path.write_text("\n".join(rows) + "\n")
    return path


def test_csv_rings_islands_go_to_their_part_and_a_part_too_small_is_left_out(tmp_path):
    """Rings in metres: an island inside the second shore belongs to it; a pond 1.5 cells across is
    left out with a note naming it and the cell size that would keep it."""
    f = csv_rings(
        tmp_path / "lakes.csv",
        [
            ("main", ellipse(0, 0, 3000, 1500)),
            ("side", ellipse(8000, 0, 1500, 1000)),
            ("isle", ellipse(8200, 0, 300, 200)[::-1]),
            ("pond", ellipse(0, 4000, 70, 70, 16)),  # 140 m across, cells of ~100 m
        ],
    )
    run = mesh(
        f, "--cell-size", 100, "-o", tmp_path / "g.vtm", "--png", tmp_path / "g.png", "--case", tmp_path / "L.toml"
    )
    assert run.rc == 0, run.err
    # a case holds one lake: one per part meshed, each generating that part's blocks again
    assert sorted(p.name for p in tmp_path.glob("L*.toml")) == ["L_part1.toml", "L_part2.toml"]
    from meshcore.case import generate_case, load_case

    again = generate_case(load_case(tmp_path / "L_part2.toml"))
    # the water of the part (its island's 0.19 km² taken off), its centroid in the file's coordinates
    assert "part 2: 'side', area 4.50531e+06, centroid (7991.67, 0), 1 island" in run.err
    note = [ln for ln in run.err.splitlines() if "part 3 ('pond')" in ln]
    assert len(note) == 1 and "left out" in note[0] and "fewer than 3 cells" in note[0], run.err
    names = block_names(tmp_path / "g.vtm")
    assert {n.split("_")[0] for n in names} == {"part1", "part2"}
    side = [xy for n, xy in zip(names, vtm_blocks(tmp_path / "g.vtm"), strict=True) if n.startswith("part2_")]
    assert len(again.grids) == len(side) and {f"part2_{n}" for n in again.names} <= set(names)
    isle = shapely.Polygon(ellipse(8200, 0, 300, 200))
    assert inside(side, shapely.Polygon(ellipse(8000, 0, 1500, 1000)), 50.0)
    pts = shapely.points(np.vstack([np.column_stack([x.ravel(), y.ravel()]) for x, y in side]))
    assert not shapely.contains(isle.buffer(-50.0), pts).any()  # the grid goes round the island


def test_overlapping_or_touching_parts_are_refused_naming_both(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    a, b = ellipse(0, 0, 3000, 1500), ellipse(3500, 0, 1000, 800)  # b reaches 500 m into a
    run = mesh(csv_rings(tmp_path / "over.csv", [("big", a), ("small", b)]), "-o", out / "g.vtm")
    _refused(run, out, "over.csv", "'big' and 'small' overlap or touch near (", "one outline")
    sq = np.array([[0, 0], [1000, 0], [1000, 1000], [0, 1000]], float)  # two squares meeting at a corner
    run = mesh(csv_rings(tmp_path / "touch.csv", [("A", sq), ("B", sq + 1000 + [0, 0])]), "-o", out / "g.vtm")
    _refused(run, out, "touch.csv", "overlap or touch near (1000, 1000)")


def test_mesh_outline_of_several_parts_equals_each_part_meshed_alone():
    """The library: a MultiPolygon with islands given apart; each part's blocks are the grid of that
    part meshed alone at the same cell size (parts share nothing); parts= picks some."""
    import meshcore
    from meshcore.errors import InvalidInputError
    from meshcore.lakeparts import part_grids, select_parts

    a, b = shapely.Polygon(ellipse(0, 0, 6, 3)), shapely.Polygon(ellipse(14, 0, 3, 2))
    isle = ellipse(14.3, 0, 0.8, 0.5)
    mb = meshcore.mesh_outline(shapely.MultiPolygon([b, a]), holes=[isle], cell_size=0.3)
    by_part = part_grids(mb)
    assert sorted(by_part) == [1, 2] and not any(
        i.a.block.split("_")[0] != i.b.block.split("_")[0] for i in mb.interfaces
    )
    alone = meshcore.mesh_outline(shapely.Polygon(b.exterior.coords, [isle]), cell_size=0.3)
    assert len(by_part[2].grids) == len(alone.grids)
    for g, h in zip(by_part[2].grids, alone.grids, strict=True):
        np.testing.assert_allclose(g.x, h.x, atol=1e-9)
    only = meshcore.mesh_outline([a, b], parts=[1], cell_size=0.3)
    assert all(n.startswith("part1_") for n in only.names)
    with pytest.raises(InvalidInputError, match="inside no part"):
        meshcore.mesh_outline([a, b], holes=[ellipse(30, 0, 1, 1)], cell_size=0.3)
    tiny = shapely.Polygon(ellipse(0, 10, 0.3, 0.3))
    kept, notes = select_parts([a, tiny], None, 0.3)
    assert [k for k, _ in kept] == [1] and len(notes) == 1 and "part 2" in notes[0]
    kept, notes = select_parts([a, tiny], [2], 0.3)  # the only one asked for: kept, the layout decides
    assert [k for k, _ in kept] == [2] and not notes


def test_a_lake_wider_than_its_utm_zone_gets_one_note_naming_crs(tmp_path):
    """A synthetic outline 40° of longitude wide: the UTM zone of its centroid is off by several %
    at its ends; one note on stderr with the largest error, its place and --crs.  A lake 1° wide
    (inside one zone): no note."""
    from meshcore.cli.lakefile import SCALE_ERROR, scale_note
    from meshcore.crs import Frame
    from meshcore.io import PointSet, Polyline

    wide = ellipse(20.0, 10.0, 20.0, 2.0, 200)
    f = tmp_path / "wide.csv"
    f.write_text("lon,lat\n" + "\n".join(f"{x:.6f},{y:.6f}" for x, y in wide) + "\n")
    run = mesh(f, "--cells", 200, "-o", tmp_path / "w.npz", "-q")
    notes = [ln for ln in run.err.splitlines() if "scale is off" in ln]
    assert len(notes) == 1 and "--crs" in notes[0] and "spans 40° of longitude" in notes[0], run.err
    zone = 32634  # UTM 34N: central meridian 21°, the centroid's zone
    pct = float(notes[0].split("off by up to ")[1].split(" %")[0])
    k = pyproj.Proj(f"EPSG:{zone}").get_factors(0.0, 10.0).meridional_scale  # the far west end, 21° off
    assert f"EPSG:{zone}" in notes[0] and pct == pytest.approx(100 * (k - 1), rel=0.05) and pct > 5
    small = PointSet((Polyline("lake", ellipse(20.5, 10.0, 0.5, 0.2)),), "EPSG:4326")
    assert scale_note(small, Frame("EPSG:32634", (0.0, 0.0), "EPSG:4326")) is None and SCALE_ERROR == 1e-3


def test_a_shapefile_of_two_lake_records_gives_both_parts(tmp_path):
    """A national lake layer's two records (one with a hole): two parts, the hole the island of the
    first, both meshed."""
    import contextlib

    shp = pytest.importorskip("shapefile")

    north, hole, south = ellipse(0, 0, 3000, 1500)[::-1], ellipse(800, 0, 300, 200), ellipse(8000, 0, 1500, 1000)[::-1]
    with contextlib.ExitStack() as files:  # pyshp's Writer leaves the .dbf it opens unclosed
        f = {e: files.enter_context(open(tmp_path / f"lakes.{e}", "wb")) for e in ("shp", "shx", "dbf")}
        with shp.Writer(shapeType=shp.POLYGON, **f) as w:
            w.field("name", "C")
            w.poly([closed(north), closed(hole)])
            w.record("North basin")
            w.poly([closed(south)])
            w.record("South basin")
    run = mesh(tmp_path / "lakes.shp", "--cells", 600, "-o", tmp_path / "g.vtm")
    assert run.rc == 0, run.err
    assert "part 1: 'North basin" in run.err and "1 island" in run.err and "part 2: 'South basin'" in run.err
    names = block_names(tmp_path / "g.vtm")
    assert {n.split("_")[0] for n in names} == {"part1", "part2"}
    first = [xy for n, xy in zip(names, vtm_blocks(tmp_path / "g.vtm"), strict=True) if n.startswith("part1_")]
    pts = shapely.points(np.vstack([np.column_stack([x.ravel(), y.ravel()]) for x, y in first]))
    assert not shapely.contains(shapely.Polygon(hole).buffer(-50.0), pts).any()
