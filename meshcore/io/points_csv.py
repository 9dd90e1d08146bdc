"""Delimited text point files: ``.csv``, ``.txt``, ``.xy``, ``.xyz``-less ``.dat``.

* delimiter sniffed among tab, ``;``, ``,``, ``|`` and white space (``;``
  files may use a decimal comma);
* comment lines start with ``#``, ``%``, ``//`` or ``!``; trailing ``#``
  comments are cut;
* degrees, minutes, seconds (``46°6'30.5"N``, ``N 46° 6.5'``, ``46 6 30.5 N``) are
  lon/lat (``EPSG:4326``), a hemisphere letter telling latitude from longitude;
* an optional header names the columns: ``x``/``y``, ``easting``/``northing``
  or ``lon``/``lat`` (``longitude``, ``lng``, ``latitude`` …, in either
  order).  ``lon``/``lat`` headers make the CRS ``EPSG:4326`` and are checked
  against the lon/lat range; a ``name``/``id``/``part`` column groups rows into
  polylines (unless it changes on every row: then it numbers the points);
  otherwise the first two numeric columns are x, y;
* several polylines are separated by blank lines or GMT-style ``> name`` lines
  (runs that only blank lines separate and that close together, none by itself, or
  join end to start with no gap longer than their longest step, are one ring cut by
  stray blank lines).

A ring whose last point repeats the first is marked closed and the repeated
point dropped.
"""

from __future__ import annotations

import re
import warnings
from array import array
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np

from .._validation import check_allocation, max_points
from ..crs import LONLAT, check_lonlat, normalize_crs
from ..errors import ReadError
from ._base import PointSet, decode_text, make_polyline, read_bytes

__all__ = ["read_points_csv"]

# English, and the names of German (Rechtswert/Hochwert, Länge/Breite), French, Spanish, Italian,
# Dutch exports: columns in the other order are read the right way round
_X_NAMES = {"x", "easting", "east", "e", "xcoord", "x_coord", "x_m", "xm", "utm_e", "utm_x", "rechtswert", "rechts"}
_Y_NAMES = {"y", "northing", "north", "n", "ycoord", "y_coord", "y_m", "ym", "utm_n", "utm_y", "hochwert", "hoch"}
_LON_NAMES = {
    "lon", "long", "longitude", "lng", "lambda", "x_lon", "länge", "laenge", "längengrad", "geogr_länge",
    "longitud", "longitudine", "lengtegraad", "lon_dd", "long_dd",
}  # fmt: skip
_LAT_NAMES = {
    "lat", "latitude", "phi", "y_lat", "breite", "breitengrad", "geogr_breite", "latitud", "latitudine",
    "breedtegraad", "lat_dd",
}  # fmt: skip
_NAME_NAMES = {"name", "id", "part", "polyline", "line", "feature", "shape_id", "ring"}
_COMMENT = ("#", "%", "//", "!")
_NUM = re.compile(r"^[+-]?(\d+\.?\d*|\.\d+)([eEdD][+-]?\d+)?$")


def _is_number(tok: str) -> bool:
    return bool(_NUM.match(tok)) or tok.lower() in {"nan", "inf", "-inf", "+inf"}


# degrees, minutes, seconds: 46°6'0.5"N, N 46° 6.25', -46°6'0", 46 6 0.5 N (a hemisphere letter or a
# degree sign is needed: three plain numbers are three columns)
_DMS = re.compile(
    r"""^(?P<h1>[NSEW])?\s*(?P<sign>[+-])?(?P<d>\d+(?:\.\d+)?)\s*(?P<deg>[°º˚d]|\s)\s*"""
    r"""(?:(?P<m>\d+(?:\.\d+)?)\s*(?:['′’m]|\s)?\s*)?(?:(?P<s>\d+(?:\.\d+)?)\s*(?:["″”s]|''|′′)?\s*)?"""
    r"""(?P<h2>[NSEW])?$""",
    re.IGNORECASE,
)


def _dms(tok: str) -> tuple[float, str] | None:
    """``(degrees, "lat" | "lon" | "")`` of a degrees-minutes-seconds token, or None."""
    m = _DMS.match(tok.strip())
    if m is None:
        return None
    h = (m["h1"] or m["h2"] or "").upper()
    if (m["h1"] and m["h2"]) or (not h and m["deg"].isspace()) or (h and m["sign"]):
        return None
    d, mi, se = float(m["d"]), float(m["m"] or 0), float(m["s"] or 0)
    if mi >= 60 or se >= 60 or (m["s"] and m["m"] is None):
        return None
    v = d + mi / 60 + se / 3600
    sign = -1.0 if h in ("S", "W") or m["sign"] == "-" else 1.0
    return sign * v, {"N": "lat", "S": "lat", "E": "lon", "W": "lon"}.get(h, "")


def _is_coord(tok: str) -> bool:
    return _is_number(tok) or _dms(tok) is not None


def _clean_header(tok: str) -> str:
    t = tok.strip().strip('"').strip("'").strip().lower()
    t = re.sub(r"\s*[\(\[].*[\)\]]\s*$", "", t)  # "x (m)", "lon [deg]"
    return t.replace(" ", "_")


def _show(s: str, limit: int = 40) -> str:
    """A short, printable rendering of file text for messages."""
    t = "".join(c if c.isprintable() else "?" for c in s.strip())
    return repr(t if len(t) <= limit else t[: limit - 1] + "…")


_DELIMS = ("\t", ";", "|", ",")


def _sniff(sample: list[str]) -> tuple[str | None, bool]:
    """Return (delimiter or None for white space, decimal_comma).

    The delimiter is the one found on most sample lines (at least half of
    them), so one stray character on a later line is reported on that line
    instead of changing how the whole file is read.
    """
    best, best_n = None, 0
    for d in _DELIMS:
        n = sum(d in ln for ln in sample)
        if n > best_n:
            best, best_n = d, n
    if best is None or 2 * best_n < len(sample):
        return None, False
    decimal_comma = (
        best == ";"
        and any(re.search(r"\d,\d", ln) for ln in sample)
        and not any(re.search(r"\d\.\d", ln) for ln in sample)
    )
    return best, decimal_comma


def _split(line: str, delim: str | None) -> list[str]:
    if delim is None:
        return line.split()
    if '"' in line and len(delim) == 1:  # a quoted value may hold the delimiter: "1,234.5" is one value
        import csv

        return [t.strip().strip("'") for t in next(csv.reader([line], delimiter=delim, skipinitialspace=True))]
    return [t.strip().strip('"').strip("'") for t in line.split(delim)]


def _lines(text: str) -> Iterator[tuple[int, str]]:
    """``(line number, content)``: comments cut, white space stripped; one pass, no copies of the text."""
    if "\n" not in text and "\r" in text:
        text = text.replace("\r", "\n")  # old Mac line ends
    start, n, lineno = 0, len(text), 0
    while start < n:
        end = text.find("\n", start)
        if end < 0:
            end = n
        lineno += 1
        s = text[start:end].strip()
        start = end + 1
        if s.startswith(_COMMENT):
            yield lineno, ""
            continue
        if "#" in s:
            s = s[: s.index("#")].rstrip()
        yield lineno, s


class _Layout:
    """How the rows of one file are read: delimiter, header, x/y (and name) columns."""

    def __init__(self, path: Path, text: str, columns: Any) -> None:
        sample: list[tuple[int, str]] = []
        for lineno, s in _lines(text):
            if s and not s.startswith(">"):
                sample.append((lineno, s))
                if len(sample) > 50:
                    break
        if not sample:
            raise ReadError(f"{path}: no data lines (only comments or blank lines)")
        body = [s for _, s in sample[1:]] or [sample[0][1]]
        self.delim, self.decimal_comma = _sniff(body)
        first_no, first = sample[0]
        t = self.tokens(first)
        self.header: list[str] | None = None
        self.header_line = 0
        if not all(_is_coord(v) for v in t if v) and not any(_is_coord(v) for v in t[:2]):
            self.header = [_clean_header(v) for v in t]
            self.header_line = first_no
            if len(sample) < 2:
                raise ReadError(f"{path}: no data rows after the header")
            first_no, first = sample[1]
            t = self.tokens(first)
        self.first_line, self.width = first_no, len(t)
        self.lonlat = False
        self.dms = False  # a value was read in degrees, minutes, seconds: lon/lat
        self.name_col: int | None = None
        self.more_numeric: list[int] = []
        self.ix, self.iy = self._columns(path, columns, t)
        if self.ix == self.iy:
            raise ReadError(f"{path}: x and y are the same column ({self.ix})")
        if max(self.ix, self.iy) >= self.width:
            raise ReadError(
                f"{path}: line {self.first_line}: column {max(self.ix, self.iy) + 1} asked for, "
                f"but the line has {self.width} values"
            )

    def tokens(self, s: str) -> list[str]:
        t = _split(s, self.delim)
        if self.decimal_comma:
            t = [v.replace(",", ".") for v in t]
        return t

    def _columns(self, path: Path, columns: Any, first: list[str]) -> tuple[int, int]:
        header = self.header
        if columns is not None:
            try:
                cx, cy = columns
            except (TypeError, ValueError):
                raise ReadError(f"{path}: columns must be (x, y), got {columns!r}") from None
            ix, iy = (_col_index(c, header, path) for c in (cx, cy))
            if header is not None and max(ix, iy) < len(header):
                self.lonlat = header[ix] in _LON_NAMES and header[iy] in _LAT_NAMES
            return ix, iy
        if header is not None:
            self.name_col = _find(header, _NAME_NAMES)
            ix, iy = _find(header, _LON_NAMES), _find(header, _LAT_NAMES)
            if ix is not None and iy is not None:
                self.lonlat = True
                return ix, iy
            ix, iy = _find(header, _X_NAMES), _find(header, _Y_NAMES)
            if ix is not None and iy is not None:
                return ix, iy
        numeric = [k for k, v in enumerate(first) if _is_coord(v)]
        if len(numeric) < 2:
            what = "no numeric x/y columns" if header is not None else "no numeric columns (need at least two: x, y)"
            sep = {None: "white space", "\t": "tabs"}.get(self.delim, repr(self.delim))
            raise ReadError(
                f"{path}: line {self.first_line}: {what}: {_show(' '.join(first))} split at {sep} "
                f"has {len(numeric)} number(s)"
                + (f" (the header {_show(' '.join(header))} names no x/y or lon/lat columns)" if header else "")
            )
        self.more_numeric = numeric[2:] if header is None else []  # x, y of "n x y": a point number first
        return numeric[0], numeric[1]


_CHUNK = 1 << 18  # characters per block of the one-pass parser (its temporaries stay ~ 4 MB)


def _plain_block(chunk: str, delim: str | None, width: int) -> np.ndarray | None:
    """The numbers of ``chunk`` as (rows, width) when every line holds exactly ``width`` values
    split by ``delim`` (or by blanks), else None: a line of another width never shifts the
    columns of the lines after it."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            vals = np.fromstring(chunk.replace(delim, " ") if delim else chunk, dtype=np.float64, sep=" ")
    except (ValueError, DeprecationWarning):
        return None
    rows = chunk.count("\n") + 1
    if vals.size != rows * width:
        return None
    lut = np.zeros(256, dtype=np.int8)  # 0 part of a number, 1 blank, 2 delimiter, 3 line end
    lut[[ord(c) for c in " \t\v\f"]] = 1
    if delim:
        lut[ord(delim)] = 2
    lut[ord("\n")] = 3
    cls = lut[np.frombuffer(chunk.encode("ascii"), dtype=np.uint8)]
    value = np.zeros(len(cls) + 2, dtype=bool)
    value[1:-1] = cls == 0
    edge = np.flatnonzero(value[1:] != value[:-1])
    starts, ends = edge[0::2], edge[1::2]  # one run of number characters per value
    if len(starts) != vals.size or starts[0] != 0 or ends[-1] != len(cls):
        return None
    line_end = (np.arange(1, vals.size) % width == 0).astype(np.intp)  # between value k-1 and k
    wanted = [(3, line_end)] + ([(2, 1 - line_end)] if delim else [])  # no delimiter bytes without one
    for c, want in wanted:
        seen = np.cumsum(cls == c, dtype=np.int32)  # line ends / delimiters up to each character
        if not np.array_equal(seen[starts[1:] - 1] - seen[ends[:-1] - 1], want):
            return None
    return vals.reshape(rows, width)


def _fast_points(text: str, lay: _Layout) -> np.ndarray | None:
    """Every row in one C pass (block by block), when the file is one plain block of numbers
    after its header (no comments, segments, names, quotes, blank lines or lines of another
    width); None otherwise (then the line loop runs, and names the line of any problem)."""
    if lay.name_col is not None or lay.decimal_comma:
        return None
    start = 0
    for _ in range(lay.header_line):  # skip the header line (and anything before it)
        start = text.find("\n", start) + 1
        if start == 0:
            return None
    body = text[start:].replace("\r\n", "\n").replace("\r", "\n").strip()
    if not body or not body.isascii() or any(c in body for c in "#>%!\"'/") or "\n\n" in body:
        return None
    blocks, a = [], 0
    while a < len(body):
        b = body.find("\n", a + _CHUNK)
        b = len(body) if b < 0 else b
        block = _plain_block(body[a:b].strip(" \t"), lay.delim, lay.width)
        if block is None:
            return None
        blocks.append(block[:, [lay.ix, lay.iy]])
        a = b + 1
    return np.concatenate(blocks)


def _rows(path: Path, text: str, lay: _Layout) -> tuple[np.ndarray, list[tuple[int, str | None, str | None, int]]]:
    """All points, and ``(first point, group name, segment name, line)`` of each polyline's run."""
    fast = _fast_points(text, lay)
    if fast is not None:
        return fast, [(0, None, None, lay.first_line)]
    xs, ys = array("d"), array("d")
    groups: list[tuple[int, str | None, str | None, int]] = []
    seg_name: str | None = None
    new_segment = True
    sep = {None: "white space", "\t": "tabs"}.get(lay.delim, repr(lay.delim))
    ix, iy, nc, width = lay.ix, lay.iy, lay.name_col, lay.width
    for lineno, s in _lines(text):
        if not s:
            new_segment = True
            continue
        if s.startswith(">"):
            seg_name, new_segment = s[1:].strip() or None, True
            continue
        if lineno == lay.header_line:
            continue
        t = lay.tokens(s)
        if len(t) != width:
            raise ReadError(
                f"{path}: line {lineno}: mixed dimensions: {len(t)} values separated by {sep}, but line "
                f"{lay.first_line} has {width}: {_show(s)}"
            )
        try:
            x, y = float(t[ix].replace("d", "e").replace("D", "e")), float(t[iy].replace("d", "e").replace("D", "e"))
        except ValueError:
            x, y = _dms_pair(path, lineno, s, t[ix], t[iy], (ix, iy))
            lay.dms = True
        xs.append(x)
        ys.append(y)
        gname = t[nc] if nc is not None else None
        if new_segment or gname != groups[-1][1]:
            groups.append((len(xs) - 1, gname, seg_name, lineno))
            new_segment = False
    pts = np.column_stack([np.frombuffer(xs, dtype=np.float64), np.frombuffer(ys, dtype=np.float64)])
    return pts, groups


def _dms_pair(path: Path, lineno: int, s: str, tx: str, ty: str, cols: tuple[int, int]) -> tuple[float, float]:
    """Longitude, latitude of a line whose x/y are degrees-minutes-seconds (N/S marks a latitude)."""
    a, b = (_dms(tx) if not _is_number(tx) else (float(tx), "")), (_dms(ty) if not _is_number(ty) else (float(ty), ""))
    if a is None or b is None:
        bad = cols[0] if a is None else cols[1]
        raise ReadError(
            f"{path}: line {lineno}: not a number in column {bad + 1} (nor degrees, minutes, seconds "
            f"such as 46°6'30.5\"N): {_show(s, 60)}"
        )
    if a[1] == "lat" or b[1] == "lon":
        a, b = b, a
    if a[1] == "lat" or b[1] == "lon":
        raise ReadError(f"{path}: line {lineno}: two latitudes or two longitudes: {_show(s, 60)}")
    return a[0], b[0]


def read_points_csv(
    path: Path, *, columns: Any = None, crs: Any = None, closed: bool | None = None, **_: Any
) -> PointSet:
    """Read polylines from a delimited text file (see module docstring).

    Linear in the file, about 16 bytes per point beyond the text itself (a
    plain block of numbers is parsed in one C pass, anything else line by
    line); the number of lines is checked against
    :func:`~meshcore._validation.max_points` before parsing.

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
    data = read_bytes(path)
    check_allocation(
        data.count(b"\n") + 1, max_points(), what=f"{path}: lines", env="MESHCORE_MAX_POINTS", error=ReadError
    )
    text = decode_text(path, data)
    del data
    lay = _Layout(path, text, columns)
    pts, groups = _rows(path, text, lay)
    if lay.name_col is not None and len(groups) == len(pts) > 2:
        # a name on every row that changes on every row is a point number ("id,lon,lat",
        # "fid,x,y"), not the name of polylines of one point each
        lay.name_col = None
        pts, groups = _rows(path, text, lay)
    if lay.more_numeric and len(pts) > 2 and np.all(np.diff(pts[:, 0]) == 1.0):
        # no header, and the first column counts the rows 1, 2, 3 … (a point number, "n lon lat"): no
        # ring has x rising by one at every point; x, y are the next two (was: the number read as x)
        lay.ix, lay.iy = lay.iy, lay.more_numeric[0]
        pts, groups = _rows(path, text, lay)
    if not groups:
        raise ReadError(f"{path}: no data rows after the header")
    groups = _one_ring_split_by_blank_lines(pts, groups)
    base = path.stem
    polylines = []
    ends = [g[0] for g in groups[1:]] + [len(pts)]
    for (start, gname, sname, lineno), end in zip(groups, ends, strict=True):
        name = gname or sname or (base if len(groups) == 1 else f"{base} {len(polylines) + 1}")
        if end - start < 2:
            if len(groups) == 1:  # the whole file (was: "(a blank line starts a new polyline)" with none in it)
                raise ReadError(f"{path}: only 1 point (line {lineno}); an outline needs 3 or more")
            raise ReadError(
                f"{path}: polyline {name!r} (line {lineno}) has only {end - start} point"
                + (" (a blank line starts a new polyline)" if gname is None and sname is None else "")
            )
        polylines.append(make_polyline(name, pts[start:end], closed=closed, where=str(path)))
    declared = normalize_crs(crs) if crs is not None else (LONLAT if lay.lonlat or lay.dms else None)
    if declared == LONLAT:
        for pl in polylines:
            check_lonlat(pl.points, where=f"{path}: {pl.name}", swapped=_swap_hint(lay))
    meta: dict = {"xy_columns": (lay.ix, lay.iy)}
    if lay.header is not None and max(lay.ix, lay.iy) < len(lay.header):  # the names the x, y columns have
        meta["columns"] = (lay.header[lay.ix], lay.header[lay.iy], lay.ix, lay.iy)
    return PointSet(tuple(polylines), declared, str(path), meta)


def _swap_hint(lay: _Layout) -> str:
    """What to change when a lon/lat file holds latitude, longitude: its header, or the columns."""
    if lay.header is None or max(lay.ix, lay.iy) >= len(lay.header):
        return f"; if so, give the columns in the other order ({lay.iy}, {lay.ix} from 0)"
    names = list(lay.header)
    x, y = names[lay.ix], names[lay.iy]
    names[lay.ix], names[lay.iy] = y, x
    sep = lay.delim if lay.delim and lay.delim != "\t" else ("\t" if lay.delim else " ")
    return (
        f"; the header (line {lay.header_line}) names column {lay.ix + 1} {x!r} and column {lay.iy + 1} {y!r}: "
        f"if column {lay.ix + 1} holds latitudes, write the header {sep.join(names)!r}"
    )


def _one_ring_split_by_blank_lines(
    pts: np.ndarray, groups: list[tuple[int, str | None, str | None, int]]
) -> list[tuple[int, str | None, str | None, int]]:
    """The runs of one ring that stray blank lines cut into pieces, joined again.

    Runs that blank lines alone separate (no names), none a ring by itself, whose last point
    closes on the first run's first point: one ring.  Read apart, the first piece was a ring of
    its own (a CSV ring may omit its closing point) and the rest lines dropped as touching it.
    A ring written without its closing point, cut so, is one ring too when every run has two
    points or more and every gap (from a run's last point to the next run's first, and from the
    last point back to the first) is no longer than the longest step inside the runs: read
    apart, the largest piece was the shore and the rest dropped with a note, the lake cut short.
    """
    if len(groups) < 2 or any(g[1] is not None or g[2] is not None for g in groups):
        return groups
    ends = [g[0] for g in groups[1:]] + [len(pts)]
    if any(np.array_equal(pts[g[0]], pts[e - 1]) for g, e in zip(groups, ends, strict=True)):
        return groups
    if np.array_equal(pts[0], pts[-1]):
        return groups[:1]
    if any(e - g[0] < 2 for g, e in zip(groups, ends, strict=True)):
        return groups
    step = max(float(np.hypot(*np.diff(pts[g[0] : e], axis=0).T).max()) for g, e in zip(groups, ends, strict=True))
    gaps = pts[[g[0] for g in groups[1:]] + [0]] - pts[[e - 1 for e in ends]]
    return groups[:1] if float(np.hypot(*gaps.T).max()) <= step else groups


def _find(header: list[str], names: set[str]) -> int | None:
    for k, h in enumerate(header):
        if h in names:
            return k
    return None


def _col_index(c: Any, header: list[str] | None, path: Path) -> int:
    if isinstance(c, (int, np.integer)) and not isinstance(c, bool):
        if int(c) < 0:
            raise ReadError(f"{path}: column index {int(c)} is negative (columns count from 0)")
        return int(c)
    if isinstance(c, str) and c.isdigit():
        return int(c)
    if header is None:
        raise ReadError(f"{path}: column {c!r} given by name but the file has no header")
    key = _clean_header(str(c))
    if key not in header:
        raise ReadError(f"{path}: no column {c!r} in the header {_show(' '.join(header))}")
    return header.index(key)
