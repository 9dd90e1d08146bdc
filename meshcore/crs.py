r"""Coordinate reference systems: lon/lat detection, UTM projection, local origin.

Shorelines usually arrive in WGS84 longitude/latitude.  A grid is generated in
a *metric* CRS — by default the UTM zone of the outline's centroid (beyond UTM's
80°S–84°N the polar stereographic UPS), or a user-given EPSG code — and, to keep
every digit, *relative to a local origin*:

.. math::

    (x, y)_{\text{local}} = (E, N) - (E_0, N_0),

where ``(E, N)`` are projected coordinates (UTM northings are ≈ 7·10⁶ m, so
an absolute float64 keeps only ≈ 1e-9 m of the digits, and differences of
them cancel) and ``(E_0, N_0)`` is the bounding-box centre rounded to a power
of ten of the outline's size (an exactly representable integer of metres).
:class:`Frame` carries the CRS and the origin to every writer, which adds the
origin back (``to_world``) or returns to lon/lat (``to_lonlat``).

pyproj is imported lazily, inside the functions that need it, and every PROJ call runs on
one long-lived thread of meshcore's (:func:`proj_call`): pyproj keeps a PROJ context per
thread, and a pool that re-uses an operating-system thread under a new Python thread state
(Qt's ``QThreadPool``, where the app solves) handed PROJ a freed context — the app's second
solve of a lon/lat case crashed the process inside ``proj_create``.
"""

from __future__ import annotations

import functools
import math
import threading
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import Any

import numpy as np

from .errors import InvalidInputError, ReadError

__all__ = [
    "LONLAT",
    "Frame",
    "auto_epsg",
    "crs_name",
    "crs_wkt",
    "frame_from_case",
    "frame_from_table",
    "is_geographic",
    "lon_span",
    "looks_lonlat",
    "looks_swapped",
    "not_a_map",
    "project",
    "project_arrays",
    "utm_epsg",
]

#: The CRS of GeoJSON, KML and lon/lat CSV files (axis order lon, lat).
LONLAT = "EPSG:4326"
_GEOGRAPHIC_ALIASES = {"EPSG:4326", "OGC:CRS84", "WGS84", "CRS84", "EPSG:4979", "LONLAT"}


def _pyproj():
    try:
        import pyproj
    except ImportError as exc:  # pragma: no cover - pyproj is in the io extra
        raise InvalidInputError("map projections need pyproj: pip install pyproj") from exc
    return pyproj


_PROJ_POOL: ThreadPoolExecutor | None = None
_PROJ_LOCK = threading.Lock()


def proj_call(fn, *args, **kwargs):
    """``fn(*args, **kwargs)`` run on meshcore's one PROJ thread (see the module docstring).

    Every use of pyproj objects goes through here, so no CRS or transformer
    object ever meets a second thread's PROJ context; exceptions reach the caller.
    """
    global _PROJ_POOL
    if threading.current_thread().name.startswith("meshcore-proj"):
        return fn(*args, **kwargs)
    with _PROJ_LOCK:
        if _PROJ_POOL is None:
            _PROJ_POOL = ThreadPoolExecutor(max_workers=1, thread_name_prefix="meshcore-proj")
        pool = _PROJ_POOL
    return pool.submit(fn, *args, **kwargs).result()


def normalize_crs(crs: Any) -> str | None:
    """An authority string (``"EPSG:32632"``) for ``crs``, or its WKT, or None.

    Accepts an int EPSG code, ``"EPSG:nnnn"``, ``"epsg:nnnn"``, a WKT / PROJ
    string or a ``pyproj.CRS``.  A CRS that PROJ does not know (``EPSG:999999``)
    is an :class:`~meshcore.errors.InvalidInputError`, never written into a file.
    """
    if crs is None:
        return None
    if isinstance(crs, bool):
        raise InvalidInputError(f"crs: expected an EPSG code or a CRS string, got {crs!r}")
    if isinstance(crs, (int, np.integer)):
        s = f"EPSG:{int(crs)}"
    elif isinstance(crs, str):
        s = crs.strip()
        if not s or s.lower() in {"none", "local"}:
            return None
    elif getattr(crs, "to_wkt", None) is not None:
        s = crs.to_wkt()
    else:
        raise InvalidInputError(f"crs: expected an EPSG code or a CRS string, got {type(crs).__name__}")
    if s.upper() in _GEOGRAPHIC_ALIASES:
        return LONLAT
    if s.isdigit():
        s = f"EPSG:{s}"
    return _checked_crs(s)


@functools.lru_cache(maxsize=256)
def _checked_crs(s: str) -> str:
    """``s`` checked against the PROJ database: ``EPSG:n`` as given, anything else as authority or WKT."""
    epsg = s.upper().startswith("EPSG:") and s[5:].isdigit()
    try:
        _pyproj()
    except InvalidInputError:
        if epsg:  # without pyproj an EPSG code can only be taken on trust
            return f"EPSG:{s[5:]}"
        raise
    shown = s if len(s) <= 60 else s[:59] + "…"
    try:
        auth = proj_call(_authority, s, epsg)
    except Exception as exc:
        why = "no such code in the PROJ database" if epsg else " ".join(str(exc).split())[:120]
        raise InvalidInputError(f"crs: unknown CRS {shown!r} ({why})") from None
    if epsg:
        return f"EPSG:{int(s[5:])}"
    return auth


def _authority(s: str, epsg: bool) -> str:
    """``AUTH:code`` of the CRS ``s`` (its WKT when PROJ knows no authority for it; "" for an
    EPSG code, which is only checked); PROJ thread."""
    c = _pyproj().CRS.from_user_input(s)
    if epsg:
        return ""
    auth = c.to_authority(min_confidence=90)
    return f"{auth[0]}:{auth[1]}" if auth else c.to_wkt()


def transform(src: str, dst: str, x: Any, y: Any, where: str) -> tuple[np.ndarray, np.ndarray]:
    """Coordinates ``(x, y)`` in ``src`` → ``dst`` (x = east/lon first), or an error naming both."""

    def run():
        t = _pyproj().Transformer.from_crs(src, dst, always_xy=True)
        return t.transform(np.asarray(x, dtype=np.float64), np.asarray(y, dtype=np.float64))

    try:
        X, Y = proj_call(run)
    except InvalidInputError:
        raise
    except Exception as exc:
        raise InvalidInputError(
            f"{where}: cannot transform {src} to {dst} ({' '.join(str(exc).split())[:120]})"
        ) from None
    return np.asarray(X, dtype=np.float64), np.asarray(Y, dtype=np.float64)


def is_geographic(crs: str | None) -> bool:
    """True when ``crs`` is a geographic (degrees) CRS."""
    if crs is None:
        return False
    if crs.upper() in _GEOGRAPHIC_ALIASES:
        return True
    return bool(_crs_attribute(crs, lambda c: c.is_geographic))


def not_a_map(crs: str | None) -> str | None:
    """Why ``crs`` cannot hold a 2-D grid (geocentric x, y, z; a height), or None when it can."""
    if crs is None or crs.upper() in _GEOGRAPHIC_ALIASES:
        return None

    def why(c: Any) -> str | None:
        if c.is_geocentric:
            return "a geocentric CRS (x, y, z from the Earth's centre)"
        if c.is_vertical and not (c.is_projected or c.is_geographic):
            return "a vertical CRS (heights)"
        return None

    return _crs_attribute(crs, why)


def is_web_mercator(crs: str | None) -> bool:
    """True for Web ("Pseudo") Mercator (EPSG:3857, 900913 …), whose metres are true metres only at
    the equator: ``1 / cos(lat)`` of them to a metre (1.44 at 46°, cell areas 2.1 times too large)."""
    if crs is None or is_geographic(crs):
        return False

    def pseudo(c: Any) -> bool:
        op = c.coordinate_operation
        return op is not None and "pseudo mercator" in (op.method_name or "").lower()

    return bool(_crs_attribute(crs, pseudo))


def crs_wkt(crs: str | None) -> str | None:
    """WKT2 of ``crs`` (None for an unknown CRS)."""
    if crs is None:
        return None
    return _crs_attribute(crs, lambda c: c.to_wkt())


def crs_name(crs: str) -> str:
    """PROJ's name of ``crs`` (``"WGS 84 / UTM zone 32N"``)."""
    return _crs_attribute(crs, lambda c: c.name)


def crs_cf(crs: str) -> dict[str, Any]:
    """The CF grid-mapping attributes of ``crs`` (``pyproj.CRS.to_cf()``)."""
    return _crs_attribute(crs, lambda c: c.to_cf())


def _crs_attribute(crs: str, get):
    """``get(pyproj.CRS(crs))`` computed on the PROJ thread, or an error naming the CRS."""
    try:
        return proj_call(lambda: get(_pyproj().CRS.from_user_input(crs)))
    except InvalidInputError:
        raise
    except Exception as exc:
        raise InvalidInputError(f"crs: unknown CRS {crs[:60]!r} ({' '.join(str(exc).split())[:120]})") from None


def looks_lonlat(points: Any) -> bool:
    """Heuristic: do these unlabelled coordinates look like lon/lat degrees?

    True when every point lies in ``[-180, 180] × [-90, 90]``, the extent is
    at most 20° (a lake or river region, not a whole continent; measured across
    the antimeridian when that is shorter, :func:`lon_span`), the centre
    is more than 1° away from ``(0, 0)`` and the values carry at least three
    decimals (digitised degrees do; unit squares and other small model
    coordinates such as ``0 … 8`` or ``0.5, 1.25`` are not mistaken for degrees).
    """
    p = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    if p.size == 0 or not np.isfinite(p).all():
        return False
    lo, hi = p.min(axis=0), p.max(axis=0)
    if lo[0] < -180 or hi[0] > 180 or lo[1] < -90 or hi[1] > 90:
        return False
    lon_c, lon_w = lon_span(p[:, 0])
    if max(lon_w, hi[1] - lo[1]) > 20:
        return False
    if math.hypot(lon_c, 0.5 * (lo[1] + hi[1])) <= 1.0:
        return False
    frac = np.abs(p * 100 - np.round(p * 100))
    return bool((frac > 1e-6).any())


def check_lonlat(points: np.ndarray, *, where: str, swapped: str = "") -> None:
    """Raise :class:`ReadError` naming the first point outside lon/lat range.

    When the points are latitude, longitude instead (every first value within ±90, and read
    the other way round they look like degrees, :func:`looks_swapped`), the message says so,
    followed by ``swapped`` (what to change in the file: its header, its format's order).
    """
    p = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    bad = (np.abs(p[:, 0]) > 180) | (np.abs(p[:, 1]) > 90)
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        msg = f"{where}: point {k + 1} ({p[k, 0]:g}, {p[k, 1]:g}) is outside the lon/lat range [-180, 180] × [-90, 90]"
        if looks_swapped(p):
            msg = (
                f"{where}: point {k + 1} (read as lon {p[k, 0]:g}, lat {p[k, 1]:g}) is no longitude, latitude: the "
                f"values look like latitude, longitude (every longitude read within ±90, latitudes beyond){swapped}"
            )
        raise ReadError(msg)


def looks_swapped(points: Any) -> bool:
    """Degrees written latitude, longitude: out of the lon/lat range as written (a second value
    beyond ±90), and read the other way round they look like degrees (:func:`looks_lonlat`: in
    range and a lake's extent, so a mistyped latitude among lon, lat points is no swap)."""
    p = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    if p.size == 0 or not np.isfinite(p).all() or not (np.abs(p[:, 1]) > 90).any():
        return False
    return looks_lonlat(p[:, ::-1])


def utm_epsg(lon: float, lat: float) -> int:
    """EPSG code of the WGS84 UTM zone containing ``(lon, lat)``.

    Zones are 6° wide from −180°; 326zz north of the equator, 327zz south.
    The Norway (32V) and Svalbard (31X–37X) exceptions are applied.
    """
    if not (-180 <= lon <= 180 and -80 <= lat <= 84):
        raise InvalidInputError(f"no UTM zone for lon={lon:g}, lat={lat:g} (UTM covers 80°S–84°N)")
    zone = int((lon + 180) // 6) + 1
    zone = min(zone, 60)
    if 56 <= lat < 64 and 3 <= lon < 12:
        zone = 32
    if 72 <= lat < 84 and lon >= 0:
        if lon < 9:
            zone = 31
        elif lon < 21:
            zone = 33
        elif lon < 33:
            zone = 35
        elif lon < 42:
            zone = 37
    return (32600 if lat >= 0 else 32700) + zone


def auto_epsg(lon: float, lat: float) -> int:
    """EPSG code of the grid CRS ``crs="auto"`` picks for a lake centred at ``(lon, lat)``.

    The UTM zone (:func:`utm_epsg`) between 80°S and 84°N; beyond, where UTM stops, the
    Universal Polar Stereographic of that pole with easting, northing axes (EPSG:5041 north,
    5042 south), as the military grid reference system continues it.
    """
    if -180 <= lon <= 180 and lat > 84:
        return 5041
    if -180 <= lon <= 180 and lat < -80:
        return 5042
    return utm_epsg(lon, lat)


def _nice_origin(points: np.ndarray) -> tuple[float, float]:
    """Bounding-box centre rounded to a power of ten of the extent (0 when small)."""
    if len(points) == 0:
        return (0.0, 0.0)
    lo, hi = points.min(axis=0), points.max(axis=0)
    c = 0.5 * (lo + hi)
    size = float(math.hypot(*(hi - lo))) or 1.0
    if math.hypot(*c) <= 10 * size:
        return (0.0, 0.0)
    e = math.floor(math.log10(size))
    return (float(round(float(c[0]), -e)), float(round(float(c[1]), -e)))


@dataclass(frozen=True, slots=True)
class Frame:
    """Where local grid coordinates live: a CRS and a local origin.

    World coordinates are ``(x + origin[0], y + origin[1])`` in ``crs``.

    Parameters
    ----------
    crs : str or None
        Metric CRS of the world coordinates (``"EPSG:32632"``), None if unknown.
    origin : (float, float)
        Local origin in world coordinates.
    source_crs : str or None
        CRS the points were read in (``"EPSG:4326"`` for lon/lat files).
    """

    crs: str | None = None
    origin: tuple[float, float] = (0.0, 0.0)
    source_crs: str | None = None

    def to_world(self, x: Any, y: Any) -> tuple[np.ndarray, np.ndarray]:
        """Local → world (projected) coordinates."""
        return (np.asarray(x, dtype=np.float64) + self.origin[0], np.asarray(y, dtype=np.float64) + self.origin[1])

    def to_local(self, x: Any, y: Any) -> tuple[np.ndarray, np.ndarray]:
        """World (projected) → local coordinates."""
        return (np.asarray(x, dtype=np.float64) - self.origin[0], np.asarray(y, dtype=np.float64) - self.origin[1])

    def to_lonlat(self, x: Any, y: Any) -> tuple[np.ndarray, np.ndarray]:
        """Local coordinates → WGS84 longitude, latitude (degrees)."""
        if self.crs is None:
            raise InvalidInputError("cannot convert to lon/lat: the grid's CRS is unknown")
        X, Y = self.to_world(x, y)
        if is_geographic(self.crs):
            return X, Y
        return transform(self.crs, LONLAT, X, Y, "lon/lat")

    @property
    def wkt(self) -> str | None:
        return crs_wkt(self.crs)

    def as_dict(self) -> dict[str, Any]:
        d: dict[str, Any] = {"origin": [float(self.origin[0]), float(self.origin[1])]}
        if self.crs:
            d["crs"] = self.crs
        if self.source_crs:
            d["source_crs"] = self.source_crs
        return d


def as_frame(crs: Any = None, origin: Any = None) -> Frame:
    """Coerce ``crs`` (a Frame, CRS string/EPSG int or None) and ``origin`` to a Frame."""
    if isinstance(crs, Frame):
        if origin is None:
            return crs
        return Frame(crs.crs, (float(origin[0]), float(origin[1])), crs.source_crs)
    o = (0.0, 0.0) if origin is None else (float(origin[0]), float(origin[1]))
    return Frame(normalize_crs(crs), o)


def project(pointset: Any, crs: Any = "auto", *, origin: Any = "auto", source_crs: Any = None) -> tuple[Any, Frame]:
    """Project a :class:`~meshcore.io.PointSet` to local metric coordinates.

    Parameters
    ----------
    pointset : PointSet
        As returned by :func:`meshcore.io.read_points`.
    crs : "auto", int, str or None
        Target CRS.  ``"auto"``: lon/lat input (declared, or unlabelled and
        :func:`looks_lonlat`) goes to the UTM zone of its centroid (UPS
        beyond 80°S–84°N: :func:`auto_epsg`); projected
        input stays in its CRS; unknown non-geographic input is left as is.
        An EPSG code / CRS string projects to that CRS.  ``None``/``"none"``:
        no projection.
    origin : "auto", (x0, y0) or None
        Local origin subtracted after projecting (see module docstring);
        ``None`` means ``(0, 0)``.
    source_crs : optional
        Overrides the CRS the points were read in.

    Returns
    -------
    (PointSet, Frame)
        The points in local coordinates and the frame that maps them back.

    Examples
    --------
    >>> from meshcore.io import PointSet, Polyline
    >>> ps = PointSet((Polyline("a", [[8.5, 47.3], [8.6, 47.3], [8.6, 47.4]]),), "EPSG:4326")
    >>> local, frame = project(ps)
    >>> frame.crs, frame.origin
    ('EPSG:32632', (470000.0, 5240000.0))
    """
    import dataclasses

    src = normalize_crs(source_crs) if source_crs is not None else pointset.crs
    arrays = [pl.points for pl in pointset.polylines]
    names = [pl.name for pl in pointset.polylines]
    local, frame = project_arrays(arrays, crs, source_crs=src, origin=origin, where=pointset.source, names=names)
    polylines = [dataclasses.replace(pl, points=p) for pl, p in zip(pointset.polylines, local, strict=True)]
    return pointset.with_points(polylines, frame.crs), frame


def project_arrays(
    arrays: list[np.ndarray],
    crs: Any = "auto",
    *,
    source_crs: Any = None,
    origin: Any = "auto",
    where: str = "",
    names: list[str] | None = None,
) -> tuple[list[np.ndarray], Frame]:
    """Project ``(n, 2)`` point arrays together (the core of :func:`project`).

    ``source_crs`` is the CRS of the points (None: unknown; unlabelled lon/lat
    is recognised by :func:`looks_lonlat`).  Returns the local arrays and the
    :class:`Frame` that maps them back.
    """
    src = normalize_crs(source_crs) if source_crs is not None else None
    pts = np.vstack([np.asarray(a, dtype=np.float64).reshape(-1, 2) for a in arrays]) if arrays else np.zeros((0, 2))
    target_in = crs.strip().lower() if isinstance(crs, str) else crs
    if src is None and target_in not in (None, "none", "local") and looks_lonlat(pts):
        src = LONLAT
    target: str | None
    if target_in == "auto":
        if src is not None and (is_geographic(src) or is_web_mercator(src)):  # to true metres
            lon, lat = _lonlat_centroid(pts, src)
            target = f"EPSG:{auto_epsg(lon, lat)}"
        else:
            target = src
    elif target_in in (None, "none", "local"):
        target = src
    else:
        target = normalize_crs(crs)
        if src is None:
            raise InvalidInputError(
                f"{where}: cannot project to {target}: the points' CRS is unknown, the file does not say it (give "
                f"it with --source-crs, source_crs= in Python: --source-crs {target} if they are in it already)"
            )
    for c, role in ((src, "the points' CRS"), (target, "the target CRS")):
        why = not_a_map(c) if c is not None and c != LONLAT else None
        if why:
            raise InvalidInputError(f"{where or 'points'}: {role} {c} is {why}, not a map: give a projected CRS")
    if src is not None and is_geographic(src):
        check_lonlat(pts, where=where or "points")
    new = [np.asarray(a, dtype=np.float64).reshape(-1, 2) for a in arrays]
    if target is not None and src is not None and target != src:
        for k, a in enumerate(new):
            if len(a) == 0:
                continue
            X, Y = transform(src, target, a[:, 0], a[:, 1], where or "points")
            P = np.column_stack([X, Y]).astype(np.float64)
            if not np.isfinite(P).all():
                label = f"{names[k]}: " if names else ""
                raise InvalidInputError(f"{where}: {label}points cannot be projected to {target}")
            new[k] = P
    allp = np.vstack(new) if new else np.zeros((0, 2))
    if isinstance(origin, str) and origin == "auto":
        o = _nice_origin(allp)
    elif origin is None:
        o = (0.0, 0.0)
    else:
        o = (float(origin[0]), float(origin[1]))
    off = np.array(o)
    return [a - off for a in new], Frame(target, o, src)


def _lonlat_centroid(pts: np.ndarray, src: str) -> tuple[float, float]:
    if src != LONLAT:
        x, y = transform(src, LONLAT, pts[:, 0], pts[:, 1], "centroid")
        pts = np.column_stack([x, y])
    centre, _ = lon_span(pts[:, 0])
    return centre, float(0.5 * (pts[:, 1].min() + pts[:, 1].max()))


def lon_span(lon: Any) -> tuple[float, float]:
    """Centre and width in degrees of the shortest arc of longitudes holding ``lon``.

    An outline across the antimeridian (179.9° and −179.9°) spans 0.2°, not
    359.8°: its centre is ±180°, and the UTM zone of the naive centre (0°) would
    put it 180° from the zone's meridian, where the projection is meaningless.

    Examples
    --------
    >>> lon_span([10.0, 12.0])
    (11.0, 2.0)
    >>> c, w = lon_span([179.9, -179.9]); (round(abs(c), 6), round(w, 6))
    (180.0, 0.2)
    """
    a = np.asarray(lon, dtype=np.float64).ravel()
    lo, hi = float(a.min()), float(a.max())
    w = np.where(a < 0, a + 360.0, a)  # the same points seen from 0°–360°
    lo2, hi2 = float(w.min()), float(w.max())
    if hi2 - lo2 < hi - lo:
        c = 0.5 * (lo2 + hi2)
        return (c - 360.0 if c > 180.0 else c), hi2 - lo2
    return 0.5 * (lo + hi), hi - lo


# ------------------------------------------------------------ case files
def frame_from_table(table: Any) -> Frame | None:
    """The :class:`Frame` of a case file's top-level ``crs`` table (None without one).

    The table (written by ``meshcore import``) reads::

        crs = { crs = "EPSG:32632", origin = [480000.0, 5240000.0],
                source_crs = "EPSG:4326" }
    """
    if not isinstance(table, dict):
        return None
    o = table.get("origin", [0.0, 0.0])
    try:
        origin = (float(o[0]), float(o[1]))
    except (TypeError, ValueError, IndexError):
        raise InvalidInputError(f"case crs.origin must be [x0, y0], got {o!r}") from None
    if not all(math.isfinite(v) and abs(v) <= 1e100 for v in origin):
        raise InvalidInputError(f"case crs.origin must be finite numbers of at most 1e100, got {list(origin)}")
    return Frame(normalize_crs(table.get("crs")), origin, normalize_crs(table.get("source_crs")))


def frame_from_case(case: Any) -> Frame | None:
    """The :class:`Frame` stored in a :class:`meshcore.case.Case`'s ``crs`` table, or None."""
    return frame_from_table(getattr(case, "crs", None))
