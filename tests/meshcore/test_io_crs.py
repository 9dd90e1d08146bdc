"""Map projections and the local origin: UTM zones, round trips, and the 1e-9 grid invariance."""

from __future__ import annotations

import numpy as np
import pytest

import meshcore
from meshcore.crs import Frame, looks_lonlat, project, utm_epsg
from meshcore.errors import InvalidInputError
from meshcore.io import PointSet, Polyline, read_points
from meshcore.io.outline import guess_cells, guess_corners
from tests.conftest import DATA

pyproj = pytest.importorskip("pyproj")


@pytest.mark.parametrize(
    ("lon", "lat", "epsg"),
    [
        (8.67, 47.28, 32632),
        (-122.27, 40.81, 32610),
        (-2.94, 54.35, 32630),
        (11.93, 42.59, 32632),
        (151.2, -33.9, 32756),
        (5.3, 60.4, 32632),
        (15.0, 78.0, 32633),
        (-180.0, 0.0, 32601),
        (180.0, 10.0, 32660),
    ],
)
def test_utm_zone(lon, lat, epsg):
    assert utm_epsg(lon, lat) == epsg
    # pyproj agrees where the zone is the plain 6° band
    if not (56 <= lat < 64 or lat >= 72 or abs(lon) == 180):
        info = pyproj.database.query_utm_crs_info(
            datum_name="WGS 84", area_of_interest=pyproj.aoi.AreaOfInterest(lon, lat, lon, lat)
        )
        assert str(epsg) in {i.code for i in info}


def test_looks_lonlat():
    zur = read_points(DATA / "lake_zurich_sparse.csv").all_points()
    assert looks_lonlat(zur)
    assert not looks_lonlat([[0, 0], [1, 0], [1, 1]])  # a unit square is model units
    assert not looks_lonlat([[500000, 5e6], [500100, 5e6]])
    assert not looks_lonlat([[-100.5, 10.25], [100.5, 10.25]])  # 159° wide either way: not a lake
    assert looks_lonlat([[179.951, -16.55], [-179.932, -16.55], [-179.932, -16.4]])  # 0.12° across 180°
    assert not looks_lonlat([[0, 0], [8, 0], [8, 4], [0, 4.5]])  # model units, few decimals


def test_project_to_utm_and_back():
    ps = read_points(DATA / "lake_zurich_sparse.kml")
    local, frame = project(ps)
    assert frame.crs == "EPSG:32632" and frame.source_crs == "EPSG:4326"
    # origin: bounding-box centre rounded to 10 km (the outline is ~26 km across)
    X, Y = frame.to_world(*local.polylines[0].points.T)
    assert frame.origin == (round(0.5 * (X.min() + X.max()), -4), round(0.5 * (Y.min() + Y.max()), -4))
    t = pyproj.Transformer.from_crs("EPSG:4326", "EPSG:32632", always_xy=True)
    E, N = t.transform(*ps.polylines[0].points.T)
    np.testing.assert_allclose(X, E, rtol=0, atol=1e-9)
    np.testing.assert_allclose(Y, N, rtol=0, atol=1e-9)
    lon, lat = frame.to_lonlat(*local.polylines[0].points.T)
    np.testing.assert_allclose(np.column_stack([lon, lat]), ps.polylines[0].points, atol=1e-10)
    # the local coordinates are small: |x| ≤ extent, far below UTM's 10⁶–10⁷
    assert np.abs(local.all_points()).max() < 2e4


def test_a_lake_across_the_antimeridian_is_projected_like_its_neighbour():
    """179.9° and −179.9° are 0.2° apart: the UTM zone is 60 (or 1), not the zone of 0°.

    The naive centre of the longitudes, 0°, put the lake 180° from its zone's meridian:
    a grid in coordinates of ~10⁷ m, distorted out of shape, without a word.
    """
    lat = [-16.45, -16.45, -16.35, -16.35]
    across = PointSet((Polyline("across", np.column_stack([[179.9, -179.9, -179.9, 179.9], lat]), closed=True),))
    beside = PointSet((Polyline("beside", np.column_stack([[178.9, 179.1, 179.1, 178.9], lat]), closed=True),))
    a, fa = project(across, source_crs="EPSG:4326")
    b, fb = project(beside, source_crs="EPSG:4326")
    assert fa.crs in ("EPSG:32760", "EPSG:32701") and fb.crs == "EPSG:32760"
    pa, pb = a.polylines[0].points, b.polylines[0].points

    # the same 0.2° × 0.1° box, 1° apart in the same zone: the same sides in metres (~21 km × 11 km;
    # UTM's scale differs by < 0.1 % between 2° and 3° from the zone's meridian)
    def sides(p):
        return np.hypot(*np.diff(np.vstack([p, p[:1]]), axis=0).T)

    np.testing.assert_allclose(sides(pa), sides(pb), rtol=0.002)
    assert np.all((sides(pa) > 10e3) & (sides(pa) < 23e3))
    lon, lat2 = fa.to_lonlat(*pa.T)
    np.testing.assert_allclose(np.mod(lon, 360), np.mod(across.polylines[0].points[:, 0], 360), atol=1e-9)
    np.testing.assert_allclose(lat2, lat, atol=1e-9)


def test_project_to_given_epsg_and_none():
    ps = read_points(DATA / "lake_zurich_sparse.geojson")
    local, frame = project(ps, 2056)  # Swiss LV95
    assert frame.crs == "EPSG:2056"
    X, _ = frame.to_world(*local.polylines[0].points.T)
    assert 2.68e6 < X.mean() < 2.72e6
    same, f2 = project(ps, None)  # no projection; still a local origin (0.1° steps)
    assert f2.crs == "EPSG:4326" and f2.origin == (8.7, 47.3)
    np.testing.assert_allclose(same.polylines[0].points + f2.origin, ps.polylines[0].points, rtol=0, atol=1e-13)
    raw, f3 = project(ps, None, origin=None)
    assert f3.origin == (0.0, 0.0)
    np.testing.assert_array_equal(raw.polylines[0].points, ps.polylines[0].points)


def test_unknown_crs_cannot_be_projected():
    ps = PointSet((Polyline("a", [[0, 0], [1000, 0], [1000, 1000]]),), None, "model.csv")
    _, frame = project(ps)  # auto: unknown and not lon/lat -> left as is
    assert frame.crs is None and frame.origin == (0.0, 0.0)
    with pytest.raises(InvalidInputError, match=r"model\.csv.*unknown"):
        project(ps, 32632)
    with pytest.raises(InvalidInputError, match=r"no CRS|unknown"):
        Frame().to_lonlat([0.0], [0.0])


def test_same_lake_in_lonlat_and_utm_gives_the_same_grid(tmp_path):
    """Issue 5: lon/lat input and UTM input give the same grid to 1e-9 relative."""
    ps = read_points(DATA / "lake_bolsena_sparse.geojson")
    local_ll, frame_ll = project(ps)
    # the same outline as a UTM CSV, as a GIS would export it (mm precision is plenty)
    X, Y = frame_ll.to_world(*local_ll.polylines[0].points.T)
    f = tmp_path / "bolsena_utm.csv"
    f.write_text("easting,northing\n" + "".join(f"{a:.6f},{b:.6f}\n" for a, b in zip(X, Y, strict=True)))
    ps_utm = read_points(f, crs=frame_ll.crs)
    local_utm, frame_utm = project(ps_utm)
    assert frame_utm.crs == frame_ll.crs and frame_utm.origin == frame_ll.origin
    loop_ll, loop_utm = local_ll.polylines[0].points, local_utm.polylines[0].points
    corners = guess_corners(loop_ll)
    cells = guess_cells(loop_ll, corners, total=24)
    g1 = meshcore.generate_block(loop=loop_ll, corners=corners, cells=cells)
    g2 = meshcore.generate_block(loop=loop_utm, corners=corners, cells=cells)
    assert g1.converged and g2.converged
    size = g1.size
    diff = max(np.abs(g1.x - g2.x).max(), np.abs(g1.y - g2.y).max())
    assert diff <= 1e-9 * size, diff / size
