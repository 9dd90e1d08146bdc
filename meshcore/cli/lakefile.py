"""A lake file's rings in a metric frame: the rules ``meshcore mesh`` and the app's import share.

* :func:`is_lonlat` — does a point set hold degrees (declared, or every point looks like them)?
* :func:`lonlat_order_note` — a note when headerless degrees could be in either column order;
* :func:`swapped_degrees_note` — a note when a file of no CRS holds latitude, longitude degrees;
* :func:`local_frame` — project degrees (and Web Mercator) to the grid's CRS about a round origin;
* :func:`without_lines_on_the_shore`, :func:`lake_rings` — the shore, the islands, and the open
  lines that are neither (an inlet drawn on the shore, a ferry route, pins), dropped with notes;
* :func:`without_repeated_rings` — a ring the file holds twice (a duplicated feature or hole, a
  ``ring`` id written twice over) read once, with a note naming both;
* :func:`in_world` — a message's places ``near (x, y)`` moved from the local frame to the CRS;
* :func:`check_crs_option` — a ``--crs`` / ``--source-crs`` value refused before any file is read.
"""

from __future__ import annotations

import re
from typing import Any

import numpy as np

__all__ = [
    "RINGS_MAY_BE_OPEN",
    "check_crs_option",
    "in_world",
    "is_lonlat",
    "lake_parts",
    "lake_rings",
    "local_frame",
    "lonlat_order_note",
    "scale_note",
    "swapped_degrees_note",
    "without_lines_on_the_shore",
    "without_repeated_rings",
]


def check_crs_option(value: Any, option: str) -> None:
    """Raise one error naming ``option`` when ``value`` is no CRS PROJ knows (None, auto, none, local pass)."""
    from ..crs import normalize_crs
    from ..errors import InvalidInputError

    if value is None or str(value).strip().lower() in ("auto", "none", "local"):
        return
    try:
        normalize_crs(value)
    except InvalidInputError as exc:
        raise InvalidInputError(f"{option} {value}: {str(exc).removeprefix('crs: ')}") from None


def is_lonlat(ps: Any, source_crs: Any = None) -> bool:
    """True when a point set holds longitude/latitude degrees.

    The rule shared by ``meshcore mesh`` and the app's import: the CRS the file declares
    (or ``source_crs``) is geographic, or the file declares none and every point looks like
    degrees (:func:`meshcore.crs.looks_lonlat`; e.g. a CSV of lon, lat numbers without a
    header).
    """
    from ..crs import is_geographic, looks_lonlat, normalize_crs

    src = normalize_crs(source_crs) if source_crs is not None else ps.crs
    if src is not None:
        return bool(is_geographic(src))
    pts = [np.asarray(pl.points, dtype=np.float64).reshape(-1, 2) for pl in ps.polylines]
    return bool(pts) and looks_lonlat(np.vstack(pts))


def lonlat_order_note(ps: Any, source_crs: Any = None, columns: Any = None) -> str | None:
    """A note when degrees were read as longitude, latitude with nothing in the file to say so.

    A file without a CRS, a lon/lat header or columns given, whose numbers look like degrees,
    is read as x = longitude, y = latitude; when every x is within ±90 the columns could as well
    be latitude, longitude (the order many GPS and spreadsheet exports use), and the grid of a
    swapped file is a lake elsewhere, stretched and mirrored, without a word.
    """
    if source_crs is not None or columns is not None or ps.crs is not None or not is_lonlat(ps):
        return None
    if not str(ps.source).lower().endswith(RINGS_MAY_BE_OPEN):  # a shapefile or DXF says x, y: lon, lat
        return None
    pts = np.vstack([np.asarray(pl.points, dtype=np.float64).reshape(-1, 2) for pl in ps.polylines])
    if np.abs(pts[:, 0]).max() > 90:
        return None
    named = ps.meta.get("columns")
    if named:  # a header of x, y (or easting, northing ...): it names the columns but not lon/lat
        x, y, ix, iy = named
        return (
            f"{ps.source}: the header says {x!r}, {y!r}, not longitude, latitude: read {x!r} as the "
            f"longitude, {y!r} as the latitude; if {x!r} holds the latitude, give --columns {iy} {ix}"
        )
    ix, iy = ps.meta.get("xy_columns", (0, 1))
    which = "the first column" if ix == 0 else f"column {ix} (from 0)"
    return (
        f"{ps.source}: no header says which column is which: read as longitude, latitude "
        f"(x, y); if {which} is the latitude, give --columns {iy} {ix}"
    )


def swapped_degrees_note(ps: Any, source_crs: Any = None, columns: Any = None) -> str | None:
    """A note when a file that says nothing of its CRS holds degrees in latitude, longitude order
    (:func:`meshcore.crs.looks_swapped`: a headerless or ``x,y`` CSV of "40.7375,-122.445"): read as
    x, y they are no degrees, and the grid kept the file's numbers, a lake 0.1 units across, without
    a word.  (A file that says lon/lat, by its header or format, is refused naming the swap.)"""
    from ..crs import looks_swapped

    if source_crs is not None or columns is not None or ps.crs is not None or not ps.polylines:
        return None
    pts = np.vstack([np.asarray(pl.points, dtype=np.float64).reshape(-1, 2) for pl in ps.polylines])
    if not looks_swapped(pts):
        return None
    ix, iy = ps.meta.get("xy_columns", (0, 1))
    named = ps.meta.get("columns")
    cols = f" (the header's {named[0]!r}, {named[1]!r})" if named else ""
    return (
        f"{ps.source}: its numbers look like latitude, longitude degrees (every first value within ±90, the "
        f"second beyond), read as x, y{cols} without a CRS; if they are degrees, give --columns {iy} {ix}"
    )


def degrees_note(ps: Any, source_crs: Any = None) -> str | None:
    """A note when a file said to hold metres (a projected CRS) holds numbers that look like degrees:
    a GeoJSON labelled EPSG:3857 with lon/lat in it became a lake 0.2 m across, without a word."""
    from ..crs import is_geographic, looks_lonlat, normalize_crs

    crs = normalize_crs(source_crs) if source_crs is not None else ps.crs
    if crs is None or is_geographic(crs) or not ps.polylines:
        return None
    pts = np.vstack([np.asarray(pl.points, dtype=np.float64).reshape(-1, 2) for pl in ps.polylines])
    if not looks_lonlat(pts):
        return None
    size = float(np.hypot(*(pts.max(axis=0) - pts.min(axis=0))))
    return (
        f"{ps.source}: its coordinates look like degrees (longitude, latitude) but are read in {crs}: "
        f"the lake is {size:.3g} units across; if they are degrees, give --source-crs EPSG:4326"
    )


def local_frame(ps: Any, crs: Any = "auto", *, source_crs: Any = None) -> tuple[Any, Any]:
    """Project a point set for a lake grid: ``(local point set, Frame)``.

    The rule shared by ``meshcore mesh`` and the app's import (:func:`app.lake.read_lake`):
    points in lon/lat (:func:`is_lonlat`, also when the file does not say so) go to ``crs``
    relative to the round origin of :func:`meshcore.crs.project` (``origin="auto"``); points
    not projected keep their coordinates.  Subtracting a round origin is exact, so the world
    coordinates are ``local + origin`` to the last bit.
    """
    from ..crs import LONLAT, is_geographic, is_web_mercator, project

    keep = crs is None or (isinstance(crs, str) and crs.strip().lower() in ("none", "local"))
    if source_crs is None and ps.crs is None and not keep and is_lonlat(ps):
        source_crs = LONLAT  # what project would guess: said here, where the app's import reads it too
    local, frame = project(ps, crs, origin=None, source_crs=source_crs)
    src = frame.source_crs
    projected = src is not None and (is_geographic(src) or is_web_mercator(src)) and frame.crs not in (None, src)
    if projected or _far_from_origin(local):
        local, frame = project(ps, crs, origin="auto", source_crs=source_crs)
    return local, frame


#: Points kept as they are get a local origin only when they lie this many times their extent from
#: (0, 0): a 2 km lake at 1e9 (5e5 times) made the layout fail with NaN ("All-NaN slice"); UTM
#: coordinates (about 500 times) keep theirs, as in the app.
FAR_FROM_ORIGIN = 1e4


def _far_from_origin(ps: Any) -> bool:
    pts = [np.asarray(p.points, dtype=np.float64) for p in ps.polylines if len(p.points)]
    if not pts:
        return False
    allp = np.vstack(pts)
    lo, hi = allp.min(axis=0), allp.max(axis=0)
    size = float(np.hypot(*(hi - lo)))
    return bool(size > 0 and np.hypot(*(0.5 * (lo + hi))) > FAR_FROM_ORIGIN * size)


def lake_rings(ps: Any) -> tuple[np.ndarray, list[np.ndarray], list[str]]:
    """Shore, islands and notes of a point set's rings: the rule shared by ``meshcore mesh`` and the app.

    Open polylines that touch the shore (an inlet or a cut drawn on it) are dropped with a
    note (:func:`without_lines_on_the_shore`); the rest is split into the shore (the ring of
    largest area) and islands by :func:`~meshcore.layout.polygon.water_from_points`, which
    raises :class:`~meshcore.errors.InvalidInputError` naming a ring that is not part of one
    lake.
    """
    from ..layout.polygon import water_from_points

    once, repeats = without_repeated_rings(ps)
    kept, notes = without_lines_on_the_shore(once)
    outer, islands = water_from_points(kept)
    return np.asarray(outer, dtype=np.float64), [np.asarray(r, dtype=np.float64) for r in islands], repeats + notes


def lake_parts(ps: Any) -> tuple[list[tuple[str, np.ndarray, list[np.ndarray]]], list[str]]:
    """The separate parts of the water, ``[(name, shore, islands), ...]`` largest first, and notes:
    :func:`lake_rings` for files of several parts (a lake split at a dam, several placemarks;
    :func:`~meshcore.layout.polygon.water_parts_from_points`)."""
    from ..layout.polygon import water_parts_from_points

    once, repeats = without_repeated_rings(ps)
    kept, notes = without_lines_on_the_shore(once)
    parts = [
        (name, np.asarray(o, dtype=np.float64), [np.asarray(r, dtype=np.float64) for r in isl])
        for name, o, isl in water_parts_from_points(kept)
    ]
    return parts, repeats + notes


#: A lon/lat lake whose scale in the grid's CRS is off by more than this somewhere on its shore gets
#: a note: UTM keeps its scale within 0.1 % inside its own 6° zone (0.9996 on the central meridian,
#: 1.00098 at 3° from it on the equator), so a lake inside one zone never gets the note and one that
#: reaches well beyond the zone of its centroid does.
SCALE_ERROR = 1e-3


def scale_note(ps: Any, frame: Any) -> str | None:
    """A note when the projection distorts a lon/lat lake by more than :data:`SCALE_ERROR`.

    The scale factor of ``frame.crs`` (pyproj ``Proj.get_factors``: the meridional scale, which
    for a conformal projection such as UTM is the scale in every direction) at every shore point;
    the note gives the worst, where it is and the lake's width in longitude.
    """
    import pyproj

    from ..crs import is_geographic

    src, crs = frame.source_crs, frame.crs
    if not src or not crs or not is_geographic(src) or is_geographic(crs):
        return None
    pts = np.vstack([np.asarray(pl.points, dtype=np.float64).reshape(-1, 2) for pl in ps.polylines])
    pts = pts[np.isfinite(pts).all(axis=1)]
    if not len(pts):
        return None
    try:
        lonlat = pyproj.Transformer.from_crs(src, "EPSG:4326", always_xy=True)
        lon, lat = lonlat.transform(pts[:, 0], pts[:, 1])
        k = np.asarray(pyproj.Proj(crs).get_factors(lon, lat).meridional_scale, dtype=np.float64)
    except Exception:  # a note only: a CRS pyproj cannot give factors for says nothing
        return None
    err = np.abs(k - 1.0)
    if not np.isfinite(err).any() or np.nanmax(err) <= SCALE_ERROR:
        return None
    i = int(np.nanargmax(err))
    span = float(np.ptp(np.unwrap(np.radians(lon)))) * 180.0 / np.pi
    return (
        f"{ps.source}: the lake spans {span:.3g}° of longitude; in {crs} its scale is off by up to "
        f"{100 * err[i]:.2g} % (at lon {lon[i]:.5g}, lat {lat[i]:.5g}; UTM keeps within 0.1 % inside its 6° "
        f"zone): the grid's lengths and areas are that far from the ground's there; give --crs a projection "
        f"made for the lake's extent (e.g. a Lambert conformal conic or an equidistant projection centred on it)"
    )


#: Point files in which an island's ring may be written without its closing point: an open
#: polyline there is a ring.  The other formats say it (KML, GeoJSON and shapefile geometry types,
#: a DXF polyline's closed flag): there an open line is a path.
RINGS_MAY_BE_OPEN = (".csv", ".txt", ".xy", ".dat", ".tsv")


def without_lines_on_the_shore(ps: Any) -> tuple[Any, list[str]]:
    """Drop open polylines that cannot be islands: ``(kept, notes)``.

    The shore is the ring of largest area, as :func:`~meshcore.layout.polygon.water_from_points`
    picks it.  An open line that meets it (an inlet or a cut drawn on it) is dropped; so is, in a
    file whose geometry says what is a ring (not a CSV) and that holds a polygon, an open line in
    the water (a ferry route, a survey line: read as a ring it was an island of water left out of
    the grid).  ``notes`` names the dropped lines (empty when none was dropped).
    """
    import shapely

    rings = [pl for pl in ps.polylines if len(pl.points) >= 3]
    if len(ps.polylines) < 2 or not rings:
        return ps, []  # water_from_points names what is missing
    shore = max(rings, key=lambda pl: abs(shapely.Polygon(pl.points).area))
    ring = shapely.LinearRing(shore.points)
    paths = any(pl.closed for pl in ps.polylines) and not str(ps.source).lower().endswith(RINGS_MAY_BE_OPEN)
    keep: list[Any] = []
    touching: list[Any] = []
    inside: list[Any] = []
    outside: list[Any] = []
    water = shapely.Polygon(shore.points)
    for pl in ps.polylines:
        if pl is shore or pl.closed or len(pl.points) < 2:  # a single point: named later
            keep.append(pl)
        elif shapely.LineString(pl.points).intersects(ring):
            touching.append(pl)
        elif not paths:
            keep.append(pl)
        else:
            (inside if water.contains(shapely.Point(pl.points[0])) else outside).append(pl)
    notes = []
    for dropped, where in (
        (touching, "touching the shore"),
        (inside, "in the water (a path, not a ring)"),
        (outside, "outside the shore (a path, not a ring)"),
    ):
        lines = [pl for pl in dropped if pl.orientation != "points"]
        if lines:
            names = ", ".join(repr(pl.name) for pl in lines)
            what = "an open line" if len(lines) == 1 else "open lines"
            notes.append(f"{names}: {what} {where}, not an island: ignored")
    for pl in (pl for pl in touching + inside + outside if pl.orientation == "points"):
        notes.append(f"{pl.name!r}: {len(pl.points)} single points (placemarks, pins), not a line or a ring: ignored")
    return (ps.with_points(keep, ps.crs), notes) if notes else (ps, [])


def _once_round(p: np.ndarray, tol: float) -> np.ndarray:
    """A ring's points without repeats in a row and without its closing point, and, when the points
    go round the same ring more than once (a CSV ``ring`` id written twice over), one round of it."""
    keep = np.r_[True, np.hypot(*np.diff(p, axis=0).T) > tol]
    p = p[keep]
    while len(p) > 3 and np.hypot(*(p[-1] - p[0])) <= tol:
        p = p[:-1]
    n = len(p)
    for m in range(3, n // 2 + 1):
        if n % m == 0 and np.abs(p - np.roll(p, -m, axis=0)).max() <= tol:
            return p[:m]
    return p


def _same_ring(a: np.ndarray, b: np.ndarray, tol: float) -> bool:
    """Do two rings (:func:`_once_round`) go through the same points, from any start, either way round?"""
    if len(a) != len(b) or np.abs(a.min(axis=0) - b.min(axis=0)).max() > tol:
        return False
    d = np.hypot(*(b - a[0]).T)
    for k in np.flatnonzero(d <= tol).tolist():
        rolled = np.roll(b, -k, axis=0)
        if np.abs(rolled - a).max() <= tol or np.abs(np.roll(rolled[::-1], 1, axis=0) - a).max() <= tol:
            return True
    return False


def without_repeated_rings(ps: Any) -> tuple[Any, list[str]]:
    """Each ring of the file once: ``(kept, notes)``, a note per ring left out naming it and the ring
    it repeats.

    A ring the file holds twice — a hole copied in a GeoJSON polygon, a feature or placemark
    exported twice, a CSV ``ring`` written twice (under two ids, or twice over under one) — has one
    meaning: that ring.  Read twice, an island repeated was "a pond on an island" (left out with a
    note that said so) and a shore repeated an island touching the shore (refused); both copies are
    the same points (to 1e-9 of the file's extent, from any start point, either way round), so the
    first is kept and the repeat left out, with a note, rather than refusing a file whose water is
    plain.  Rings that differ anywhere are left to the lake's checks (an island across another or
    across the shore is named there).
    """
    import shapely

    pls = list(ps.polylines)
    pts = [np.asarray(pl.points, dtype=np.float64).reshape(-1, 2) for pl in pls]
    allp = np.vstack(pts) if pts else np.zeros((0, 2))
    if len(allp) < 3:
        return ps, []
    tol = 1e-9 * float(np.ptp(allp, axis=0).max())
    ringy = str(ps.source).lower().endswith(RINGS_MAY_BE_OPEN)
    rounds = [
        _once_round(p, tol) if (pl.closed or ringy) and len(p) >= 3 else None for pl, p in zip(pls, pts, strict=True)
    ]
    area = [abs(shapely.Polygon(r).area) if r is not None and len(r) >= 3 else 0.0 for r in rounds]
    shore = int(np.argmax(np.asarray(area) >= (1 - 1e-9) * max(area)))  # the first of the largest (to rounding)
    notes: list[str] = []
    kept: list[Any] = []
    firsts: list[int] = []
    changed = False
    for k, (pl, r) in enumerate(zip(pls, rounds, strict=True)):
        if r is None or len(r) < 3:
            kept.append(pl)
            continue
        j = next((j for j in firsts if _same_ring(rounds[j], r, tol)), None)  # type: ignore[arg-type]
        if j is not None:
            what = f"the shore {pls[j].name!r}" if j == shore else f"{pls[j].name!r}"
            notes.append(
                f"{pl.name!r} is the same ring as {what} ({len(r)} points): a ring drawn twice, "
                f"read once — {pl.name!r} left out"
            )
            changed = True
            continue
        firsts.append(k)
        if len(r) < len(pts[k]) - 1 and len(r) * 2 <= len(pts[k]):
            notes.append(
                f"{pl.name!r} goes round its ring {len(pts[k]) // len(r)} times ({len(pts[k])} points, "
                f"{len(r)} in one round): a ring written twice over, read once"
            )
            pl = type(pl)(pl.name, r, True, pl.orientation or "")
            changed = True
        kept.append(pl)
    return (ps.with_points(kept, ps.crs), notes) if changed else (ps, [])


_NEAR = re.compile(r"near \((-?\d[\d.]*(?:e[+-]?\d+)?), (-?\d[\d.]*(?:e[+-]?\d+)?)\)")


def in_world(msg: str, frame: Any) -> str:
    """``msg`` with every place ``near (x, y)`` moved from the local frame the layout and the
    solver work in to the grid's CRS (``frame``'s origin added, to the centimetre), as the
    quality table and the written grid give them; unchanged without an origin."""
    ox, oy = getattr(frame, "origin", None) or (0.0, 0.0)
    if ox == 0.0 and oy == 0.0:
        return msg
    return _NEAR.sub(lambda m: f"near ({float(m[1]) + ox:.11g}, {float(m[2]) + oy:.11g})", msg)
