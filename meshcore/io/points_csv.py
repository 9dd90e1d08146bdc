"""Delimited text point files: ``.csv``, ``.txt``, ``.xy``, ``.xyz``-less ``.dat``.

* delimiter sniffed among tab, ``;``, ``,``, ``|`` and white space (``;``
  files may use a decimal comma);
* comment lines start with ``#``, ``%``, ``//`` or ``!``; trailing ``#``
  comments are cut;
* an optional header names the columns: ``x``/``y``, ``easting``/``northing``
  or ``lon``/``lat`` (``longitude``, ``lng``, ``latitude`` …, in either
  order).  ``lon``/``lat`` headers make the CRS ``EPSG:4326`` and are checked
  against the lon/lat range; a ``name``/``id``/``part`` column groups rows into
  polylines; otherwise the first two numeric columns are x, y;
* several polylines are separated by blank lines or GMT-style ``> name`` lines.

A ring whose last point repeats the first is marked closed and the repeated
point dropped.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import numpy as np

from ..crs import LONLAT, check_lonlat, normalize_crs
from ..errors import ReadError
from ._base import PointSet, decode_text, make_polyline, read_bytes

__all__ = ["read_points_csv"]

_X_NAMES = {"x", "easting", "east", "e", "xcoord", "x_coord", "x_m", "xm"}
_Y_NAMES = {"y", "northing", "north", "n", "ycoord", "y_coord", "y_m", "ym"}
_LON_NAMES = {"lon", "long", "longitude", "lng", "lambda", "x_lon"}
_LAT_NAMES = {"lat", "latitude", "phi", "y_lat"}
_NAME_NAMES = {"name", "id", "part", "polyline", "line", "feature", "shape_id", "ring"}
_COMMENT = ("#", "%", "//", "!")
_NUM = re.compile(r"^[+-]?(\d+\.?\d*|\.\d+)([eEdD][+-]?\d+)?$")


def _is_number(tok: str) -> bool:
    return bool(_NUM.match(tok)) or tok.lower() in {"nan", "inf", "-inf", "+inf"}


def _clean_header(tok: str) -> str:
    t = tok.strip().strip('"').strip("'").strip().lower()
    t = re.sub(r"\s*[\(\[].*[\)\]]\s*$", "", t)  # "x (m)", "lon [deg]"
    return t.replace(" ", "_")


def _sniff(lines: list[str]) -> tuple[str | None, bool]:
    """Return (delimiter or None for white space, decimal_comma)."""
    sample = lines[:50]
    for d in ("\t", ";", "|"):
        if sample and all(d in ln for ln in sample):
            decimal_comma = (
                d == ";"
                and any(re.search(r"\d,\d", ln) for ln in sample)
                and not any(re.search(r"\d\.\d", ln) for ln in sample)
            )
            return d, decimal_comma
    if sample and all("," in ln for ln in sample):
        return ",", False
    return None, False


def _split(line: str, delim: str | None) -> list[str]:
    if delim is None:
        return line.split()
    return [t.strip().strip('"').strip("'") for t in line.split(delim)]


def read_points_csv(
    path: Path, *, columns: Any = None, crs: Any = None, closed: bool | None = None, **_: Any
) -> PointSet:
    """Read polylines from a delimited text file (see module docstring).

    Parameters
    ----------
    path : Path
    columns : (x, y), optional
        Column names (as in the header) or 0-based indices of x and y
        (or of lon and lat).
    crs : optional
        Declared CRS of the points (overrides what the header suggests).
    closed : bool, optional
        Force rings (True) or open polylines (False); default: closed when
        the last point repeats the first.
    """
    text = decode_text(path, read_bytes(path))
    raw = text.splitlines()
    # strip comments, remember line numbers (1-based)
    entries: list[tuple[int, str]] = []
    for k, ln in enumerate(raw, 1):
        s = ln.strip()
        if s.startswith(_COMMENT):
            entries.append((k, ""))
            continue
        if "#" in s:
            s = s[: s.index("#")].rstrip()
        entries.append((k, s))
    content = [s for _, s in entries if s and not s.startswith(">")]
    if not content:
        raise ReadError(f"{path}: no data lines (only comments or blank lines)")
    delim, decimal_comma = _sniff(content[1:] if len(content) > 1 else content)

    def tokens(s: str) -> list[str]:
        t = _split(s, delim)
        if decimal_comma:
            t = [v.replace(",", ".") for v in t]
        return t

    header: list[str] | None = None
    rows: list[tuple[int, list[str]]] = []
    segments: list[tuple[str | None, list[tuple[int, list[str]]]]] = [(None, rows)]
    for lineno, s in entries:
        if not s:
            if rows:
                rows = []
                segments.append((None, rows))
            continue
        if s.startswith(">"):
            rows = []
            segments.append((s[1:].strip() or None, rows))
            continue
        t = tokens(s)
        if (
            header is None
            and not any(r for _, r in segments)
            and not all(_is_number(v) for v in t if v)
            and not any(_is_number(v) for v in t[:2])
        ):
            header = [_clean_header(v) for v in t]
            continue
        rows.append((lineno, t))
    segments = [(nm, r) for nm, r in segments if r]
    if not segments:
        raise ReadError(f"{path}: no data rows after the header")

    # ------------------------------------------------------------ columns
    first_line, first = segments[0][1][0]
    width = len(first)
    lonlat = False
    name_col: int | None = None
    if columns is not None:
        try:
            cx, cy = columns
        except (TypeError, ValueError):
            raise ReadError(f"{path}: columns must be (x, y), got {columns!r}") from None
        ix, iy = (_col_index(c, header, path) for c in (cx, cy))
        if header is not None:
            lonlat = header[ix] in _LON_NAMES and header[iy] in _LAT_NAMES
    elif header is not None:
        ix = _find(header, _LON_NAMES)
        iy = _find(header, _LAT_NAMES)
        if ix is not None and iy is not None:
            lonlat = True
        else:
            ix, iy = _find(header, _X_NAMES), _find(header, _Y_NAMES)
        if ix is None or iy is None:
            numeric = [k for k, v in enumerate(first) if _is_number(v)]
            if len(numeric) < 2:
                raise ReadError(f"{path}: line {first_line}: no numeric x/y columns (header {header})")
            ix, iy = numeric[0], numeric[1]
        name_col = _find(header, _NAME_NAMES)
    else:
        numeric = [k for k, v in enumerate(first) if _is_number(v)]
        if len(numeric) < 2:
            raise ReadError(f"{path}: line {first_line}: no numeric columns (need at least two: x, y)")
        ix, iy = numeric[0], numeric[1]
    if ix == iy:
        raise ReadError(f"{path}: x and y are the same column ({ix})")

    # ------------------------------------------------------------- values
    polylines = []
    base = path.stem
    for seg_no, (seg_name, seg_rows) in enumerate(segments):
        groups: list[tuple[str | None, list[tuple[float, float]]]] = []
        for lineno, t in seg_rows:
            if len(t) != width:
                raise ReadError(
                    f"{path}: line {lineno}: mixed dimensions: {len(t)} values, but line {first_line} has {width}"
                )
            try:
                xv = float(t[ix].replace("d", "e").replace("D", "e"))
                yv = float(t[iy].replace("d", "e").replace("D", "e"))
            except (ValueError, IndexError):
                raise ReadError(
                    f"{path}: line {lineno}: not a number in column {ix + 1} or {iy + 1}: {' '.join(t)[:60]!r}"
                ) from None
            gname = t[name_col] if name_col is not None else None
            if not groups or groups[-1][0] != gname:
                groups.append((gname, []))
            groups[-1][1].append((xv, yv))
        for gname, pts in groups:
            name = (
                gname
                or seg_name
                or (base if len(segments) == 1 and len(groups) == 1 else f"{base} {len(polylines) + 1}")
            )
            arr = np.array(pts, dtype=np.float64)
            if len(arr) < 2:
                raise ReadError(f"{path}: polyline {name!r} has only {len(arr)} point")
            polylines.append(make_polyline(name, arr, closed=closed, where=str(path)))
        del seg_no
    declared = normalize_crs(crs) if crs is not None else (LONLAT if lonlat else None)
    if declared == LONLAT:
        for pl in polylines:
            check_lonlat(pl.points, where=f"{path}: {pl.name}")
    return PointSet(tuple(polylines), declared, str(path))


def _find(header: list[str], names: set[str]) -> int | None:
    for k, h in enumerate(header):
        if h in names:
            return k
    return None


def _col_index(c: Any, header: list[str] | None, path: Path) -> int:
    if isinstance(c, (int, np.integer)):
        return int(c)
    if isinstance(c, str) and c.isdigit():
        return int(c)
    if header is None:
        raise ReadError(f"{path}: column {c!r} given by name but the file has no header")
    key = _clean_header(str(c))
    if key not in header:
        raise ReadError(f"{path}: no column {c!r} in the header {header}")
    return header.index(key)
