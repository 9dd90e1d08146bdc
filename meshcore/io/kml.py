"""KML and KMZ point files as Google Earth saves them.

Every ``Placemark`` with a ``LineString``, ``LinearRing``, ``Polygon``
(outer and inner boundaries, also inside ``MultiGeometry``) or ``gx:Track`` (a
GPS track; also inside ``gx:MultiTrack``) becomes a named
polyline; consecutive ``Point`` placemarks (points picked by hand) are joined
into one polyline.  Coordinates are ``lon,lat[,alt]`` tuples (``EPSG:4326``).

Security: the XML is parsed by :mod:`defusedxml` with DTDs forbidden, so
entity expansion ("billion laughs") and external entities are refused; a KMZ
archive whose uncompressed size exceeds :data:`KMZ_LIMIT` is refused before
anything is decompressed, and the KML member is read with the same cap.
"""

from __future__ import annotations

import re
import warnings
import zipfile
from pathlib import Path
from typing import Any

import numpy as np

from .._validation import check_allocation, max_points
from ..crs import LONLAT, check_lonlat, normalize_crs
from ..errors import ReadError
from ._base import PointSet, Polyline, make_polyline, merge_point_runs, parse_xml, read_bytes
from ._holes import check_holes_inside

__all__ = ["KMZ_LIMIT", "read_points_kml", "read_points_kmz"]

#: Largest uncompressed KMZ content accepted (bytes).
KMZ_LIMIT = 64 * 2**20
#: Largest number of members in a KMZ archive.
KMZ_MAX_MEMBERS = 10_000


def _local(tag: Any) -> str:
    return tag.rsplit("}", 1)[-1] if isinstance(tag, str) else ""


def _parse_xml(data: bytes, where: str):
    return parse_xml(data, where, kind="KML")


def _what_else(root: Any) -> str:
    """What a KML without shapes holds instead, for the message: a network link (the shapes are in
    the file it links to) or image overlays (a picture, no outline)."""
    for el in root.iter():
        if _local(el.tag) == "NetworkLink":
            href = next((h.text or "" for h in el.iter() if _local(h.tag) == "href"), "").strip()
            where = f" {href[:200]!r}" if href else ""
            return (
                f"; it holds a network link to{where}: the shapes are in the file it links to (in Google Earth, "
                "open the link and save the places it shows: right-click ▸ Save Place As…, .kml)"
            )
    if any(_local(el.tag) in ("GroundOverlay", "ScreenOverlay", "PhotoOverlay") for el in root.iter()):
        return "; it holds image overlays (a picture, no outline): draw the shore on it as a path or polygon"
    return ""


_SPLIT = re.compile(r"\s+")


def _coordinates(text: str | None, where: str) -> np.ndarray:
    """``lon,lat[,alt]`` tuples → ``(n, 2)``: one C pass; the slow loop runs only to name a bad tuple."""
    if text is None or not text.strip():
        raise ReadError(f"{where}: empty <coordinates>")
    commas = text.count(",")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            v = np.fromstring(text.replace(",", " "), dtype=np.float64, sep=" ")
    except (ValueError, DeprecationWarning):
        v = None
    if v is not None and v.size == 2 * commas and v.size:
        return v.reshape(-1, 2)
    if v is not None and 2 * v.size == 3 * commas and v.size:
        return v.reshape(-1, 3)[:, :2].copy()
    pts = []  # tuples that mix lon,lat and lon,lat,alt, or a bad one to name
    for k, tup in enumerate(_SPLIT.split(text.strip())):
        vals = tup.split(",")
        if len(vals) not in (2, 3):
            raise ReadError(f"{where}: coordinate tuple {k + 1} {tup[:40]!r} is not lon,lat[,alt]")
        try:
            pts.append((float(vals[0]), float(vals[1])))
            if len(vals) == 3:
                float(vals[2])
        except ValueError:
            raise ReadError(f"{where}: coordinate tuple {k + 1} {tup[:40]!r} is not numeric") from None
    return np.array(pts, dtype=np.float64)


def _placemark_geoms(elem, name: str, where: str, out: list[Polyline]) -> None:
    """Every geometry of one placemark, in document order.

    One walk that does not descend into a geometry once it is read (nor into a
    nested placemark, which is read on its own), so the work is linear in the
    size of the placemark whatever the nesting.
    """
    stack = list(reversed(list(elem)))
    while stack:
        child = stack.pop()
        tag = _local(child.tag)
        if tag == "LineString":
            c = _find_child(child, "coordinates")
            out.append(make_polyline(name, _coordinates(c, f"{where} LineString"), closed=None, where=where))
        elif tag == "Polygon":
            k = 0
            outer, holes = None, []
            for bnd in child:
                btag = _local(bnd.tag)
                if btag not in ("outerBoundaryIs", "innerBoundaryIs"):
                    continue
                for ring in bnd.iter():
                    if _local(ring.tag) != "LinearRing":
                        continue
                    c = _find_child(ring, "coordinates")
                    nm = name if btag == "outerBoundaryIs" else f"{name} hole {k + 1}"
                    pts = _coordinates(c, f"{where} {btag}")
                    if btag == "innerBoundaryIs":
                        k += 1
                        holes.append((f"innerBoundaryIs ring {k} ({nm!r})", pts))
                    elif outer is None:
                        outer = pts
                    out.append(make_polyline(nm, pts, closed=True, where=where))
            if outer is not None:
                check_holes_inside(outer, holes, where, "outerBoundaryIs ring")
        elif tag == "LinearRing":
            c = _find_child(child, "coordinates")
            out.append(make_polyline(name, _coordinates(c, f"{where} LinearRing"), closed=True, where=where))
        elif tag == "Track":  # gx:Track (a GPS track, Google Earth's own extension): <gx:coord>lon lat alt
            out.append(make_polyline(name, _track(child, f"{where} gx:Track"), closed=None, where=where))
        elif tag == "Point":
            c = _find_child(child, "coordinates")
            pl = Polyline(name, _coordinates(c, f"{where} Point"))
            object.__setattr__(pl, "orientation", "point")
            out.append(pl)
        elif tag != "Placemark":
            stack.extend(reversed(list(child)))


def _track(elem, where: str) -> np.ndarray:
    """The ``lon lat [alt]`` of a ``gx:Track``'s ``gx:coord`` elements as ``(n, 2)``."""
    pts = []
    for k, c in enumerate(e for e in elem if _local(e.tag) == "coord"):
        vals = (c.text or "").split()
        try:
            if len(vals) not in (2, 3):
                raise ValueError
            pts.append((float(vals[0]), float(vals[1])))
        except ValueError:
            raise ReadError(f"{where}: gx:coord {k + 1} {(c.text or '')[:40]!r} is not 'lon lat [alt]'") from None
    if not pts:
        raise ReadError(f"{where}: no <gx:coord>")
    return np.array(pts, dtype=np.float64)


def _find_child(elem, tag: str) -> str | None:
    for c in elem:
        if _local(c.tag) == tag:
            return c.text or ""
    return None


def _from_xml(data: bytes, where: str, stem: str, crs: Any) -> PointSet:
    # every coordinate tuple holds a comma: an upper bound on the points, counted before parsing
    check_allocation(
        data.count(b","),
        max_points(),
        what=f"{where}: commas (coordinate tuples)",
        env="MESHCORE_MAX_POINTS",
        error=ReadError,
    )
    root = _parse_xml(data, where)
    if _local(root.tag) != "kml":
        raise ReadError(f"{where}: root element is <{_local(root.tag)}>, not <kml>")
    out: list[Polyline] = []
    n_marks = 0
    for pm in root.iter():
        if _local(pm.tag) != "Placemark":
            continue
        n_marks += 1
        nm = (_find_child(pm, "name") or "").strip() or f"placemark {n_marks}"
        _placemark_geoms(pm, nm, f"{where}: placemark {n_marks} ({nm})", out)
    merged = merge_point_runs(out, f"{stem} points", where)
    if not merged:
        raise ReadError(
            f"{where}: no coordinates: none of {n_marks} placemark(s) has a LineString, "
            f"LinearRing, Polygon, gx:Track or two or more Points{_what_else(root)}"
        )
    declared = normalize_crs(crs) if crs is not None else LONLAT
    if declared == LONLAT:
        for pl in merged:
            check_lonlat(
                pl.points,
                where=f"{where}: {pl.name}",
                swapped="; KML coordinates are longitude,latitude[,altitude]: write them in that order",
            )
    return PointSet(tuple(merged), declared, where)


def read_points_kml(path: Path, *, crs: Any = None, **_: Any) -> PointSet:
    """Read the placemark geometries of a ``.kml`` file."""
    return _from_xml(read_bytes(path, limit=KMZ_LIMIT), str(path), path.stem, crs)


def read_points_kmz(path: Path, *, crs: Any = None, **_: Any) -> PointSet:
    """Read the main KML of a ``.kmz`` archive (``doc.kml`` or the first ``.kml``)."""
    try:
        zf = zipfile.ZipFile(path)
    except (zipfile.BadZipFile, zipfile.LargeZipFile, EOFError, ValueError) as exc:
        raise ReadError(f"{path}: corrupt KMZ (not a valid zip archive: {exc})") from None
    with zf:
        infos = zf.infolist()
        if len(infos) > KMZ_MAX_MEMBERS:
            raise ReadError(f"{path}: refused: KMZ has {len(infos)} members")
        total = sum(i.file_size for i in infos)
        if total > KMZ_LIMIT:
            raise ReadError(f"{path}: refused: KMZ would uncompress to {total} bytes (limit {KMZ_LIMIT})")
        kmls = [i for i in infos if i.filename.lower().endswith(".kml")]
        if not kmls:
            raise ReadError(f"{path}: KMZ archive holds no .kml file")
        main = next((i for i in kmls if i.filename.lower() == "doc.kml"), kmls[0])
        try:
            with zf.open(main) as fh:
                data = fh.read(KMZ_LIMIT + 1)
        except (zipfile.BadZipFile, EOFError, OSError, ValueError, NotImplementedError) as exc:
            raise ReadError(f"{path}: corrupt KMZ member {main.filename} ({exc})") from None
        if len(data) > KMZ_LIMIT:
            raise ReadError(f"{path}: refused: {main.filename} uncompresses beyond {KMZ_LIMIT} bytes")
    return _from_xml(data, f"{path}:{main.filename}", path.stem, crs)
