"""ESRI shapefiles (``.shp`` + ``.shx`` + ``.dbf``, optional ``.prj``) via pyshp.

POLYLINE parts become open polylines, POLYGON parts closed rings (the
repeated closing point dropped; shapefile outer rings run clockwise, which the
ring's ``orientation`` records).  Names come from a ``name``/``id`` attribute
when the ``.dbf`` has one.  The CRS is the ``.prj`` WKT (None without it).
"""

from __future__ import annotations

import stat
import warnings
from pathlib import Path
from typing import Any

import numpy as np

from .._validation import check_allocation, max_bytes, max_points
from ..crs import LONLAT, check_lonlat, is_geographic, normalize_crs
from ..errors import InvalidInputError, ReadError
from ._base import PointSet, Polyline, make_polyline

__all__ = ["read_points_shp"]


def _sibling(path: Path, suffix: str) -> Path | None:
    for s in (suffix, suffix.upper()):
        p = path.with_suffix(s)
        if p.exists():
            return p
    return None


def read_points_shp(path: Path, *, crs: Any = None, **_: Any) -> PointSet:
    """Read the line and polygon shapes of a shapefile."""
    try:
        import shapefile  # pyshp
    except ImportError as exc:  # pragma: no cover
        raise ReadError(f"{path}: reading shapefiles needs pyshp (pip install pyshp)") from exc
    if not path.exists():
        raise ReadError(f"{path}: no such file")
    shx, dbf = _sibling(path, ".shx"), _sibling(path, ".dbf")
    missing = [s for s, p in ((".shx", shx), (".dbf", dbf)) if p is None]
    if missing:
        raise ReadError(f"{path}: the shapefile is incomplete: missing {' and '.join(missing)} next to it")
    assert shx is not None and dbf is not None  # for mypy: both found above
    for part in (path, shx, dbf, _sibling(path, ".prj")):
        if part is not None and not stat.S_ISREG(part.stat().st_mode):  # a fifo would block the read for ever
            raise ReadError(f"{part}: not a regular file (a device, pipe or socket): give the path of a file")
    for part in (path, shx, dbf):
        check_allocation(
            part.stat().st_size,
            max_bytes(),
            what=f"{part}: file size in bytes",
            env="MESHCORE_MAX_BYTES",
            error=ReadError,
        )
    # a point takes 16 bytes in the .shp: an upper bound on the points, known before reading
    check_allocation(
        path.stat().st_size // 16, max_points(), what=f"{path}: points", env="MESHCORE_MAX_POINTS", error=ReadError
    )
    prj = _sibling(path, ".prj")
    declared = None
    if crs is not None:
        declared = normalize_crs(crs)
    elif prj is not None:
        if prj.stat().st_size > 2**20:
            raise ReadError(f"{prj}: {prj.stat().st_size} bytes is not a projection file")
        raw = prj.read_bytes()  # Windows tools may write a byte order mark (UTF-8 or UTF-16)
        utf16 = raw[:2] in (b"\xff\xfe", b"\xfe\xff")
        wkt = raw.decode("utf-16" if utf16 else "utf-8-sig", errors="replace").strip()
        if wkt:
            try:
                declared = normalize_crs(wkt)
            except InvalidInputError as exc:
                raise ReadError(f"{prj}: unreadable projection ({exc})") from None
    with (
        open(path, "rb") as fshp,
        open(shx, "rb") as fshx,
        open(dbf, "rb") as fdbf,
        warnings.catch_warnings(),  # pyshp's header-size warnings printed two lines of its source
    ):
        warnings.simplefilter("ignore")
        try:
            reader = shapefile.Reader(shp=fshp, shx=fshx, dbf=fdbf)
        except shapefile.ShapefileException as exc:
            raise ReadError(f"{path}: not a valid shapefile ({exc})") from None
        fields = [f[0] for f in reader.fields[1:]]
        name_field = next((f for f in fields if f.lower() in ("name", "id", "label", "title")), None)
        polygon_types = {shapefile.POLYGON, shapefile.POLYGONZ, shapefile.POLYGONM}
        line_types = {shapefile.POLYLINE, shapefile.POLYLINEZ, shapefile.POLYLINEM}
        point_types = {
            shapefile.POINT,
            shapefile.POINTZ,
            shapefile.POINTM,
            shapefile.MULTIPOINT,
            shapefile.MULTIPOINTZ,
            shapefile.MULTIPOINTM,
        }
        out: list[Polyline] = []
        points: list[np.ndarray] = []
        n = len(reader)
        for k in range(n):
            sr = reader.shapeRecord(k)
            shp, rec = sr.shape, sr.record
            nm = None
            if name_field is not None:
                nm = rec[name_field]
            name = str(nm).strip() if nm not in (None, "") else (path.stem if n == 1 else f"{path.stem} {k + 1}")
            where = f"{path}: shape {k} ({name})"
            if shp.shapeType == shapefile.NULL:
                continue
            pts = np.asarray(shp.points, dtype=np.float64).reshape(-1, 2)
            if shp.shapeType in point_types:
                points.append(pts)
                continue
            if shp.shapeType not in polygon_types | line_types:
                raise ReadError(f"{where}: unsupported shape type {shp.shapeTypeName}")
            parts = [*list(shp.parts), len(pts)]
            for p in range(len(parts) - 1):
                seg = pts[parts[p] : parts[p + 1]]
                if len(seg) < 2:
                    raise ReadError(f"{where}: part {p} has fewer than 2 points")
                nmp = name if len(parts) == 2 else f"{name} part {p + 1}"
                out.append(
                    make_polyline(nmp, seg, closed=True if shp.shapeType in polygon_types else None, where=where)
                )
        if points:
            allp = np.vstack(points)
            if len(allp) >= 2:
                out.append(make_polyline(f"{path.stem} points", allp, where=str(path)))
    if not out:
        raise ReadError(f"{path}: no line or polygon shapes in {n} record(s)")
    if declared is not None and (declared == LONLAT or is_geographic(declared)):
        for pl in out:
            check_lonlat(pl.points, where=f"{path}: {pl.name}")
    return PointSet(tuple(out), declared, str(path))
