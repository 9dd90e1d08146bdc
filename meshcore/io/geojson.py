"""GeoJSON point files (RFC 7946): LineString, Polygon, Multi*, GeometryCollection.

Coordinates are lon/lat (``EPSG:4326``) unless a legacy ``crs`` member names
another CRS.  Polygon exterior rings become closed polylines named after the
feature (``properties.name``/``id``); holes become ``"<name> hole k"``.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from .._validation import check_allocation, max_points
from ..crs import LONLAT, check_lonlat, looks_swapped, normalize_crs
from ..errors import InvalidInputError, ReadError
from ._base import PointSet, Polyline, decode_text, make_polyline, merge_point_runs, read_bytes
from ._holes import check_holes_inside

__all__ = ["read_points_geojson"]


def _coords(c: Any, where: str) -> np.ndarray:
    if not isinstance(c, list) or not c:
        raise ReadError(f"{where}: coordinates must be a non-empty list of positions")
    dims = set()
    for k, pos in enumerate(c):
        if (
            not isinstance(pos, list)
            or len(pos) < 2
            or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in pos)
        ):
            raise ReadError(f"{where}: position {k + 1} is not a list of numbers: {str(pos)[:40]}")
        dims.add(len(pos))
    if len(dims) > 1:
        raise ReadError(f"{where}: mixed dimensions {sorted(dims)} among positions")
    return np.array([pos[:2] for pos in c], dtype=np.float64)


def _geometry(geom: Any, name: str, where: str, out: list[Polyline]) -> None:
    if geom is None:
        return
    if not isinstance(geom, dict) or "type" not in geom:
        raise ReadError(f"{where}: geometry is not an object with a 'type'")
    t = geom["type"]
    c = geom.get("coordinates")
    if t == "LineString":
        out.append(make_polyline(name, _coords(c, where), closed=None, where=where))
    elif t == "Polygon":
        if not isinstance(c, list) or not c:
            raise ReadError(f"{where}: Polygon without rings")
        rings = []
        for k, ring in enumerate(c):
            nm = name if k == 0 else f"{name} hole {k}"
            rings.append(
                (f"interior ring {k} (ring {k + 1} of the Polygon, {nm!r})", _coords(ring, f"{where} ring {k + 1}"))
            )
            out.append(make_polyline(nm, rings[-1][1], closed=True, where=where))
        check_holes_inside(rings[0][1], rings[1:], where, "exterior ring (ring 1)")
    elif t in ("MultiLineString", "MultiPolygon"):
        if not isinstance(c, list):
            raise ReadError(f"{where}: {t} coordinates must be a list")
        sub = t.removeprefix("Multi")
        for k, part in enumerate(c):
            nm = f"{name} {k + 1}" if len(c) > 1 else name
            _geometry({"type": sub, "coordinates": part}, nm, f"{where} part {k + 1}", out)
    elif t == "GeometryCollection":
        for k, g in enumerate(geom.get("geometries") or []):
            _geometry(g, f"{name} {k + 1}", f"{where} geometry {k + 1}", out)
    elif t in ("Point", "MultiPoint"):
        pts = _coords([c] if t == "Point" else c, where)
        out.append(Polyline(name, pts))  # gathered below
        object.__setattr__(out[-1], "orientation", "point")
    elif t == "Topology":  # TopoJSON: arcs shared between shapes, not GeoJSON coordinates
        raise ReadError(
            f"{where}: a TopoJSON file (type 'Topology'), not GeoJSON: convert it to GeoJSON first "
            "(e.g. mapshaper -o format=geojson, or ogr2ogr -f GeoJSON)"
        )
    else:
        raise ReadError(f"{where}: unsupported geometry type {t!r}")


def read_points_geojson(path: Path, *, crs: Any = None, **_: Any) -> PointSet:
    """Read the line and polygon geometries of a GeoJSON file."""
    data = read_bytes(path)
    # every position opens a "[": an upper bound on the points, counted before parsing
    check_allocation(
        data.count(b"["), max_points(), what=f"{path}: positions", env="MESHCORE_MAX_POINTS", error=ReadError
    )
    text = decode_text(path, data)
    try:
        doc = json.loads(text)
    except json.JSONDecodeError as exc:
        raise ReadError(f"{path}: line {exc.lineno}: invalid JSON ({exc.msg})") from None
    except RecursionError:
        raise ReadError(f"{path}: JSON nested too deeply") from None
    except ValueError:  # Python refuses integers of more than 4300 digits
        raise ReadError(f"{path}: a number of thousands of digits: not a coordinate") from None
    if not isinstance(doc, dict) or "type" not in doc:
        raise ReadError(f"{path}: not a GeoJSON object (no 'type')")
    declared = LONLAT
    legacy = doc.get("crs")
    if isinstance(legacy, dict):
        nm = (legacy.get("properties") or {}).get("name")
        if isinstance(nm, str):
            code = nm.split(":")[-1]
            if nm.upper().endswith("CRS84"):
                declared = LONLAT
            elif code.isdigit():
                declared = f"EPSG:{code}"
    if crs is not None:
        declared = normalize_crs(crs)
    elif declared != LONLAT:  # checked here, where the file is named (was: when the points were projected)
        try:
            normalize_crs(declared)
        except InvalidInputError as exc:
            raise ReadError(f"{path}: its 'crs' member names {nm!r}: {str(exc).removeprefix('crs: ')}") from None
    if doc["type"] == "FeatureCollection":
        feats = doc.get("features")
        if not isinstance(feats, list):
            raise ReadError(f"{path}: FeatureCollection without a 'features' list")
    elif doc["type"] == "Feature":
        feats = [doc]
    else:
        feats = [{"type": "Feature", "geometry": doc, "properties": {}}]
    out: list[Polyline] = []
    for k, f in enumerate(feats):
        if not isinstance(f, dict):
            raise ReadError(f"{path}: feature {k + 1} is not an object")
        props = f.get("properties") or {}
        name = None
        if isinstance(props, dict):
            name = props.get("name") or props.get("Name") or props.get("NAME")
        name = str(name or f.get("id") or (path.stem if len(feats) == 1 else f"feature {k + 1}"))
        _geometry(f.get("geometry"), name, f"{path}: feature {k + 1} ({name})", out)
    # consecutive Point features form one polyline (points picked by hand)
    merged = merge_point_runs(out, f"{path.stem} points", str(path))
    if not merged:
        raise ReadError(f"{path}: no LineString or Polygon coordinates in {len(feats)} feature(s)")
    try:
        if declared == LONLAT:
            for pl in merged:
                check_lonlat(
                    pl.points,
                    where=f"{path}: {pl.name}",
                    swapped="; GeoJSON positions are [longitude, latitude]: write them in that order",
                )
    except (InvalidInputError, ReadError) as exc:
        if any(looks_swapped(pl.points) for pl in merged):  # the message names the order
            raise ReadError(str(exc)) from None
        hint = "GeoJSON positions are lon/lat; for projected coordinates give their CRS: --source-crs EPSG:nnnn"
        raise ReadError(f"{exc} — {hint}") from None
    return PointSet(tuple(merged), declared, str(path))
