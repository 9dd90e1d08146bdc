"""GPX files (GPS tracks, routes and waypoints), as GPS units, phone apps and OSM tools save them.

Every track segment (``trk/trkseg/trkpt``) and route (``rte/rtept``) becomes a named polyline
(a ring when its last point repeats the first); the waypoints (``wpt``, points marked by hand)
are joined in file order into one polyline, as KML's point placemarks are.  Points are
``lat``/``lon`` attributes (``EPSG:4326``); elevations and times are ignored.  The XML is
parsed as KML is (:func:`~meshcore.io._base.parse_xml`: DTDs and entities refused).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from .._validation import check_allocation, max_points
from ..crs import LONLAT, check_lonlat, normalize_crs
from ..errors import ReadError
from ._base import PointSet, Polyline, make_polyline, parse_xml, read_bytes

__all__ = ["read_points_gpx"]


def _local(tag: Any) -> str:
    return tag.rsplit("}", 1)[-1] if isinstance(tag, str) else ""


def _name(elem: Any) -> str:
    return next(((c.text or "").strip() for c in elem if _local(c.tag) == "name"), "")


def _points(elems: list[Any], where: str) -> np.ndarray:
    pts = []
    for k, e in enumerate(elems):
        lat, lon = e.get("lat"), e.get("lon")
        try:
            pts.append((float(lon), float(lat)))  # type: ignore[arg-type]
        except (TypeError, ValueError):
            raise ReadError(f"{where}: point {k + 1}: lat={lat!r} lon={lon!r} is not a pair of numbers") from None
    return np.array(pts, dtype=np.float64).reshape(-1, 2)


def read_points_gpx(path: Path, *, crs: Any = None, **_: Any) -> PointSet:
    """Read the tracks, routes and waypoints of a ``.gpx`` file."""
    data = read_bytes(path)
    check_allocation(
        data.count(b"lat"), max_points(), what=f"{path}: points", env="MESHCORE_MAX_POINTS", error=ReadError
    )
    root = parse_xml(data, str(path), kind="GPX")
    if _local(root.tag) != "gpx":
        raise ReadError(f"{path}: root element is <{_local(root.tag)}>, not <gpx>")
    out: list[Polyline] = []
    wpts: list[Any] = []
    for k, el in enumerate(root):
        tag = _local(el.tag)
        if tag == "wpt":
            wpts.append(el)
            continue
        if tag not in ("trk", "rte"):
            continue
        name = _name(el) or f"{'track' if tag == 'trk' else 'route'} {k + 1}"
        segs = [s for s in el if _local(s.tag) == "trkseg"] if tag == "trk" else [el]
        for j, seg in enumerate(segs):
            pts = [p for p in seg if _local(p.tag) in ("trkpt", "rtept")]
            nm = name if len(segs) == 1 else f"{name} segment {j + 1}"
            where = f"{path}: {tag} {nm!r}"
            if len(pts) < 2:
                raise ReadError(f"{where}: has {len(pts)} point(s); a line needs at least 2")
            out.append(make_polyline(nm, _points(pts, where), closed=None, where=where))
    if len(wpts) >= 2:
        out.append(make_polyline(f"{path.stem} waypoints", _points(wpts, f"{path}: waypoints"), where=str(path)))
    if not out:
        raise ReadError(f"{path}: no track, route or two or more waypoints")
    declared = normalize_crs(crs) if crs is not None else LONLAT
    if declared == LONLAT:
        for pl in out:
            check_lonlat(pl.points, where=f"{path}: {pl.name}")
    return PointSet(tuple(out), declared, str(path))
