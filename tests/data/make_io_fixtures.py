"""Regenerate the derived lake fixtures (shapefile, DXF, KMZ) from the copied lake files.

Run from the repository root: ``python tests/data/make_io_fixtures.py``.  The
outputs derive from GSHHG data and carry its LGPL-3.0-or-later licence.
"""

from __future__ import annotations

import contextlib
import zipfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
WGS84_PRJ = (
    'GEOGCS["GCS_WGS_1984",DATUM["D_WGS_1984",SPHEROID["WGS_1984",6378137.0,298.257223563]],'
    'PRIMEM["Greenwich",0.0],UNIT["Degree",0.0174532925199433]]'
)


def lonlat(name: str) -> np.ndarray:
    return np.loadtxt(HERE / f"{name}.csv", delimiter=",", skiprows=1)


def main() -> None:
    import ezdxf
    import pyproj
    import shapefile

    win = lonlat("windermere_sparse")
    # shapefile: polygon ring closed and clockwise (ESRI outer-ring convention), WGS84 .prj
    ring = win[::-1].tolist()
    ring.append(ring[0])
    # our own file objects: pyshp 3.1.9's Writer leaves the .dbf it opens unclosed
    with contextlib.ExitStack() as files:
        f = {e: files.enter_context(open(HERE / f"windermere_sparse.{e}", "wb")) for e in ("shp", "shx", "dbf")}
        with shapefile.Writer(shapeType=shapefile.POLYGON, **f) as w:
            w.field("name", "C", 60)
            w.poly([ring])
            w.record("Windermere")
    (HERE / "windermere_sparse.prj").write_text(WGS84_PRJ)

    # DXF: Lake Zurich in UTM 32N metres as a closed LWPOLYLINE, plus a SPLINE through it
    zur = lonlat("lake_zurich_sparse")
    t = pyproj.Transformer.from_crs("EPSG:4326", "EPSG:32632", always_xy=True)
    E, N = t.transform(zur[:, 0], zur[:, 1])
    doc = ezdxf.new("R2010")
    msp = doc.modelspace()
    msp.add_lwpolyline(np.column_stack([E, N]).tolist(), close=True, dxfattribs={"layer": "shore"})
    msp.add_spline(np.column_stack([E[:8], N[:8], np.zeros(8)]).tolist(), dxfattribs={"layer": "inlet"})
    doc.saveas(HERE / "lake_zurich_sparse_utm32.dxf")

    # KMZ: the Lake Zurich KML zipped as Google Earth does (doc.kml)
    with zipfile.ZipFile(HERE / "lake_zurich_sparse.kmz", "w", zipfile.ZIP_DEFLATED) as z:
        z.write(HERE / "lake_zurich_sparse.kml", "doc.kml")


if __name__ == "__main__":
    main()
