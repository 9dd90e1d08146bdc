"""What a modeller's afternoon in the app (under Xvfb, driven by xdotool) found, each as it went wrong."""

from __future__ import annotations

import json

import numpy as np
import pytest
import shapely

from meshcore import testing

pytestmark = pytest.mark.gui


def _lonlat_lake(path, seed: int, lon: float, lat: float = 50.0):
    """A generated lake with islands, about 4 km across, written as a lon/lat GeoJSON at (lon, lat)."""
    poly = testing.lake_with_islands(seed)
    poly = shapely.affinity.affine_transform(poly, [0.002, 0, 0, 0.002, lon, lat])
    feature = {"type": "Feature", "properties": {"name": path.stem}, "geometry": shapely.geometry.mapping(poly)}
    path.write_text(json.dumps({"type": "FeatureCollection", "features": [feature]}))
    return path


def _metres_lake(path, seed: int):
    """A generated lake with islands in plain metres (no CRS), written as a CSV of rings."""
    poly = shapely.affinity.scale(testing.lake_with_islands(seed), 300, 300, origin=(0, 0))
    rings = [poly.exterior, *poly.interiors]
    lines = ["x,y"]
    for k, ring in enumerate(rings):
        if k:
            lines.append("")
        lines += [f"{x:.2f},{y:.2f}" for x, y in ring.coords]
    path.write_text("\n".join(lines) + "\n")
    return path


def test_a_second_lake_replaces_the_first_in_its_own_frame(qtbot, win, tmp_path):
    """A lake imported over another (no File ▸ New) was added as a second block in the first
    lake's CRS and origin: Lake Zurich over Windermere went into UTM zone 30 at x ≈ 880 km, and
    the offer on it ("3 island(s) … Auto layout") laid out the first lake and dropped the new one."""
    first = _lonlat_lake(tmp_path / "west.geojson", 761201, lon=-3.0)
    second = _lonlat_lake(tmp_path / "east.geojson", 761202, lon=9.0)
    assert win.io.import_points(first, project_lonlat=True)
    assert win.doc.project.crs == "EPSG:32630"
    west = win.doc.project
    assert win.io.import_points(second, project_lonlat=True)
    p = win.doc.project
    assert p.crs == "EPSG:32632"  # the UTM zone of the new lake, as meshcore mesh projects it
    assert len(p.blocks) == 1 and p.blocks[0].name == "east"
    assert p.lake is not None and len(p.lake.holes) == len(testing.lake_with_islands(761202).interiors)
    np.testing.assert_array_equal(p.blocks[0].points, p.lake.outline)
    assert np.abs(p.lake.outline).max() < 10_000  # about a round local origin, not 1000 km off
    win.stack.undo()  # one step brings the first lake back
    assert win.doc.project is west


def test_a_lake_in_metres_over_a_projected_one_has_no_crs(qtbot, win, tmp_path):
    """A CSV of metres (no CRS) imported over a lon/lat lake took that lake's UTM zone and origin:
    exported, its grid lay at E 500 000 + x in a zone it has nothing to do with."""
    assert win.io.import_points(_lonlat_lake(tmp_path / "west.geojson", 761203, lon=-3.0), project_lonlat=True)
    src = _metres_lake(tmp_path / "plain.csv", 761204)
    assert win.io.import_points(src)
    p = win.doc.project
    assert p.crs == "" and tuple(p.origin) == (0.0, 0.0)
    assert len(p.blocks) == 1 and p.lake is not None
    ring = np.asarray(
        shapely.affinity.scale(testing.lake_with_islands(761204), 300, 300, origin=(0, 0)).exterior.coords
    )
    assert np.abs(p.lake.outline).max() == pytest.approx(np.abs(ring).max(), abs=0.01)  # the file's own numbers
