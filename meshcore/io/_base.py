"""Shared pieces of the readers and writers: point sets, atomic writes, errors.

Every reader raises :class:`~meshcore.errors.ReadError` naming the file and the
line or feature; every writer writes to a temporary file in the target's
directory and renames it over the target (``os.replace``), so a failed write
leaves nothing behind.
"""

from __future__ import annotations

import contextlib
import re
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .._validation import MAX_COORDINATE, check_grid_size, read_file_bytes
from ..errors import MeshcoreError, ReadError, WriteError
from ..grid import BORDER_NAMES, StructuredGrid
from ._atomic import (  # noqa: F401 - re-exported: the writers import them from here
    STALE_AGE,
    atomic_path,
    atomic_paths,
    clean_stale_temporaries,
    one_line,
    temp_prefix,
)
from ._connectivity import (  # noqa: F401 - re-exported
    Interface,
    border_ij,
    check_interface,
    coerce_interfaces,
    find_interfaces,
)

__all__ = [
    "PointSet",
    "Polyline",
    "as_blocks",
    "atomic_path",
    "border_names",
    "read_guard",
]


@dataclass(frozen=True, slots=True, eq=False)
class Polyline:
    """One named polyline read from a point file.

    Parameters
    ----------
    name : str
        Feature / placemark / layer name, or ``"<file stem>"`` / ``"line k"``.
    points : (n, 2) ndarray
        Coordinates in the file's CRS (lon, lat for geographic files).
    closed : bool
        True for rings (polygons, closed polylines).  The repeated closing
        point is dropped: ``points[-1] != points[0]``.
    orientation : {"ccw", "cw", "", "point", "points"}
        For rings, the orientation as given in the file (sign of the shoelace
        area in the file's axes); ``""`` for open polylines; ``"point"`` for one
        point placemark and ``"points"`` for a run of them joined in file order.
    """

    name: str
    points: np.ndarray
    closed: bool = False
    orientation: str = ""

    def __post_init__(self) -> None:
        p = np.array(self.points, dtype=np.float64, order="C", copy=True)
        if p.ndim != 2 or p.shape[1] != 2:
            raise ValueError(f"polyline {self.name!r}: points must be (n, 2), got {p.shape}")
        p.setflags(write=False)
        object.__setattr__(self, "points", p)

    def __len__(self) -> int:
        return len(self.points)

    def __repr__(self) -> str:
        kind = f"ring ({self.orientation})" if self.closed else "open"
        return f"Polyline({self.name!r}, {len(self.points)} points, {kind})"


@dataclass(frozen=True, slots=True, eq=False)
class PointSet:
    """Named polylines read from one file, with their coordinate reference system.

    Parameters
    ----------
    polylines : tuple of Polyline
    crs : str or None
        ``"EPSG:4326"`` for lon/lat files (KML, GeoJSON, CSV with lon/lat
        columns), another authority string or WKT when the file declares one
        (shapefile ``.prj``, legacy GeoJSON ``crs``), ``None`` when unknown.
    source : str
        The file it came from.
    """

    polylines: tuple[Polyline, ...]
    crs: str | None = None
    source: str = ""
    meta: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        object.__setattr__(self, "polylines", tuple(self.polylines))

    def __len__(self) -> int:
        return len(self.polylines)

    def __iter__(self) -> Iterator[Polyline]:
        return iter(self.polylines)

    def __getitem__(self, k: int | str) -> Polyline:
        if isinstance(k, str):
            for pl in self.polylines:
                if pl.name == k:
                    return pl
            raise KeyError(f"{self.source}: no polyline named {k!r}")
        return self.polylines[k]

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(pl.name for pl in self.polylines)

    def all_points(self) -> np.ndarray:
        """All vertices stacked as one ``(N, 2)`` array."""
        if not self.polylines:
            return np.zeros((0, 2))
        return np.vstack([pl.points for pl in self.polylines])

    def with_points(self, polylines: Sequence[Polyline], crs: str | None) -> PointSet:
        return PointSet(tuple(polylines), crs, self.source, dict(self.meta))


def make_polyline(name: str, pts: np.ndarray, *, closed: bool | None = None, where: str = "") -> Polyline:
    """Build a :class:`Polyline`, detecting a repeated closing point.

    ``closed=None`` means: closed when the last point repeats the first.
    The repeated point is dropped and the orientation of the ring recorded.
    """
    p = np.asarray(pts, dtype=np.float64)
    if p.ndim != 2 or p.shape[1] != 2:
        raise ReadError(f"{where}: {name}: expected x, y pairs, got shape {p.shape}")
    if not np.isfinite(p).all():
        k = int(np.flatnonzero(~np.isfinite(p).all(axis=1))[0])
        raise ReadError(f"{where}: {name}: point {k + 1} is not a finite number")
    repeated = len(p) > 2 and bool(np.array_equal(p[0], p[-1]))
    if closed is None:
        closed = repeated
    if repeated:
        p = p[:-1]
    orientation = ""
    if closed and len(p) >= 3:
        c = p - p.mean(axis=0)
        a = 0.5 * float(np.sum(c[:, 0] * np.roll(c[:, 1], -1) - np.roll(c[:, 0], -1) * c[:, 1]))
        orientation = "ccw" if a > 0 else "cw" if a < 0 else ""
    return Polyline(name, p, closed=bool(closed), orientation=orientation)


def merge_point_runs(polylines: Sequence[Polyline], name: str, where: str) -> list[Polyline]:
    """Consecutive single-point features (points picked by hand) joined into one polyline
    named ``name`` (a run of one point is dropped); other polylines pass through in order."""
    merged: list[Polyline] = []
    run: list[np.ndarray] = []
    for pl in [*polylines, None]:
        if pl is not None and pl.orientation == "point":
            run.append(pl.points)
            continue
        if run:
            pts = np.vstack(run)
            if len(pts) >= 2:
                line = make_polyline(name, pts, where=where)
                if not line.closed:  # marked: single points joined in file order, not a line drawn
                    object.__setattr__(line, "orientation", "points")
                merged.append(line)
            run = []
        if pl is not None:
            merged.append(pl)
    return merged


# ----------------------------------------------------------------- reading
@contextlib.contextmanager
def read_guard(path: Any, what: str = "file") -> Iterator[None]:
    """Turn any unexpected failure while parsing ``path`` into a ReadError.

    Explicit checks raise well-worded :class:`ReadError` themselves; this guard
    is the safety net that keeps library exceptions (``struct.error``,
    ``UnicodeDecodeError``, a third-party parser's own errors …) from escaping.
    """
    try:
        yield
    except ReadError as exc:
        msg = str(exc)
        if "\n" in msg or "\r" in msg or len(msg) > 400:
            raise ReadError(one_line(msg)) from exc
        raise
    except FileNotFoundError:
        raise ReadError(f"{path}: no such file") from None
    except IsADirectoryError:
        raise ReadError(f"{path}: is a directory, not a {what}") from None
    except PermissionError:
        raise ReadError(f"{path}: permission denied") from None
    except MeshcoreError as exc:
        raise ReadError(one_line(f"{path}: {exc}")) from exc
    except RecursionError:
        raise ReadError(f"{path}: nesting too deep, not a valid {what}") from None
    except Exception as exc:  # the safety net (see docstring)
        msg = one_line(str(exc)) if str(exc) else type(exc).__name__
        raise ReadError(one_line(f"{path}: not a valid {what} ({type(exc).__name__}: {msg})")) from exc


def parse_xml(data: bytes, where: str, *, kind: str):
    """Parse XML with :mod:`defusedxml` (DTDs, entities and external references refused).

    ``kind`` names the format in messages (``"KML"``, ``"VTK"``).
    """
    try:
        from defusedxml import DTDForbidden, EntitiesForbidden, ExternalReferenceForbidden
        from defusedxml.ElementTree import ParseError, fromstring
    except ImportError as exc:  # pragma: no cover - defusedxml is a dependency
        raise ReadError(f"{where}: reading {kind} files needs defusedxml (pip install defusedxml)") from exc
    if not data.strip():
        raise ReadError(f"{where}: file is empty")
    try:
        return fromstring(data, forbid_dtd=True, forbid_entities=True, forbid_external=True)
    except (DTDForbidden, EntitiesForbidden, ExternalReferenceForbidden) as exc:
        raise ReadError(
            f"{where}: refused: the XML declares a DTD or entities ({type(exc).__name__}); {kind} files never need them"
        ) from None
    except ParseError as exc:
        latin1 = _latin1_as_utf8(data)
        if latin1 is not None:  # Latin-1 text saved without a declaration saying so (XML's default is UTF-8)
            try:
                return fromstring(latin1, forbid_dtd=True, forbid_entities=True, forbid_external=True)
            except ParseError:
                pass
        line = getattr(exc, "position", (None,))[0]
        raise ReadError(one_line(f"{where}: line {line}: not well-formed XML ({exc})")) from None


def _latin1_as_utf8(data: bytes) -> bytes | None:
    """``data`` re-encoded from Latin-1 to UTF-8 when it is not UTF-8 and its XML declaration names
    no encoding or UTF-8 (a name edited in an 8-bit editor: 'ä' as one byte); None otherwise (the
    parse error stands)."""
    decl = data[:200].lstrip(b"\xef\xbb\xbf").lstrip().split(b"?>", 1)[0].lower()
    if decl.startswith(b"<?xml") and b"encoding" in decl and not re.search(rb"encoding\s*=\s*[\"']utf-?8[\"']", decl):
        return None
    try:
        data.decode("utf-8")
    except UnicodeDecodeError:
        return data.decode("latin-1").encode("utf-8")
    return None


def read_bytes(path: Path, *, limit: int | None = None) -> bytes:
    """Read a whole regular file, refusing one larger than ``limit`` (default :func:`max_bytes`)
    and devices or pipes (see :func:`~meshcore._validation.read_file_bytes`)."""
    return read_file_bytes(path, error=ReadError, limit=limit)


def check_nodes(shape: Sequence[int], path: Any, what: str = "grid") -> None:
    """Refuse (ReadError) a grid whose node count exceeds :func:`max_nodes`, before allocating it."""
    ni, nj = (int(v) for v in shape[:2])
    if ni < 2 or nj < 2:
        raise ReadError(f"{path}: {what} has {ni} × {nj} nodes, at least 2 × 2 are needed")
    check_grid_size(ni, nj, what=f"{path}: {what}", error=ReadError, nodes=True)


def grid_from_world(
    X: Any, Y: Any, origin: Sequence[float], path: Any, what: str = "grid", names: dict | None = None
) -> StructuredGrid:
    """A grid in local coordinates (world − origin), refusing non-finite or huge values.

    Every grid reader builds its grids here, so a NaN, an infinity or a
    coordinate beyond :data:`~meshcore._validation.MAX_COORDINATE` (in the file
    or in its origin) is a :class:`ReadError` naming the node, never a grid.
    """
    X = np.asarray(X, dtype=np.float64)
    Y = np.asarray(Y, dtype=np.float64)
    if X.ndim != 2 or X.shape != Y.shape:
        raise ReadError(f"{path}: {what}: coordinates are not two 2-D arrays of one shape ({X.shape}, {Y.shape})")
    check_nodes(X.shape, path, what)
    o = np.asarray(origin, dtype=np.float64).reshape(-1)
    if o.size != 2 or not np.isfinite(o).all() or (np.abs(o) > MAX_COORDINATE).any():
        raise ReadError(f"{path}: the local origin {o.tolist()} is not two finite numbers")
    for axis, A in (("x", X), ("y", Y)):
        bad = ~np.isfinite(A) | (np.abs(A) > MAX_COORDINATE)
        if bad.any():
            i, j = (int(v) for v in np.argwhere(bad)[0])
            kind = "not finite" if not np.isfinite(A[i, j]) else f"beyond ±{MAX_COORDINATE:g}"
            raise ReadError(
                f"{path}: {what}: {axis} of node (i={i}, j={j}) is {kind} ({float(A[i, j])!r})"
                + (f", {int(bad.sum()) - 1} more such values" if bad.sum() > 1 else "")
            )
    return StructuredGrid(X - o[0], Y - o[1], names=dict(names or {}))


def decode_text(path: Path, data: bytes) -> str:
    """Decode text: UTF-16 (with a byte-order mark, or plain ASCII-range UTF-16), else UTF-8
    (with or without BOM), falling back to Latin-1."""
    if not data.strip():
        raise ReadError(f"{path}: file is empty")
    head = data[:4096]
    encoding = None
    if head[:2] in (b"\xff\xfe", b"\xfe\xff"):
        encoding = "utf-16"
    elif len(head) >= 4 and b"\x00" in head:
        even, odd = head[0::2], head[1::2]
        if not odd.strip(b"\x00") and b"\x00" not in even:
            encoding = "utf-16-le"
        elif not even.strip(b"\x00") and b"\x00" not in odd:
            encoding = "utf-16-be"
        else:
            k = head.index(b"\x00")
            raise ReadError(
                f"{path}: not a text file: NUL byte at offset {k} (binary data, or a text encoding other "
                f"than UTF-8, Latin-1 or UTF-16)"
            )
    if encoding is not None:
        try:
            text = data.decode(encoding)
        except UnicodeDecodeError as exc:
            raise ReadError(f"{path}: the text encoding looks like UTF-16 but byte {exc.start} is not") from None
        if not text.strip():
            raise ReadError(f"{path}: file is empty")
        return text.lstrip("\ufeff")
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError:
        return data.decode("latin-1")


def as_blocks(obj: Any) -> tuple[StructuredGrid, ...]:
    """Normalise a grid, a sequence of grids or a multiblock object to a tuple of grids."""
    if isinstance(obj, StructuredGrid):
        return (obj,)
    blocks = getattr(obj, "blocks", None)
    if blocks is not None and not isinstance(obj, (list, tuple)):
        obj = blocks
    if isinstance(obj, (list, tuple)) and obj:
        out = []
        for k, b in enumerate(obj):
            g = getattr(b, "grid", b)
            if not isinstance(g, StructuredGrid):
                raise WriteError(f"block {k} is a {type(b).__name__}, not a StructuredGrid")
            out.append(g)
        return tuple(out)
    raise WriteError(f"expected a StructuredGrid, a list of them or a multiblock object, got {type(obj).__name__}")


def block_names(obj: Any, n: int) -> tuple[str, ...]:
    """Block names of a multiblock object (``blocks[k].name``) or ``block1…``."""
    names = []
    seq = getattr(obj, "blocks", obj) if not isinstance(obj, StructuredGrid) else (obj,)
    for k in range(n):
        name = None
        with contextlib.suppress(Exception):
            name = getattr(seq[k], "name", None) or seq[k].names.get("block")
        names.append(str(name) if name else f"block{k + 1}")
    # unique
    seen: dict[str, int] = {}
    for k, nm in enumerate(names):
        if nm in seen:
            names[k] = f"{nm}_{k + 1}"
        seen[names[k]] = k
    return tuple(names)


def border_names(grid: StructuredGrid) -> dict[str, str]:
    """Border → marker name, defaulting to the convention's names (``bottom`` …)."""
    out = {}
    for b in BORDER_NAMES:
        nm = grid.names.get(b) if grid.names else None
        out[b] = str(nm) if nm else b
    return out


def border_index(grid_shape: tuple[int, int], border: str) -> tuple[slice | int, slice | int]:
    """Index of a border's nodes into the node arrays."""
    return {
        "bottom": (slice(None), 0),
        "top": (slice(None), -1),
        "left": (0, slice(None)),
        "right": (-1, slice(None)),
    }[border]


@dataclass(frozen=True, slots=True, eq=False)
class GridSet:
    """Grids read from (or about to be written to) a file.

    Parameters
    ----------
    blocks : tuple of StructuredGrid
        In *local* coordinates (world minus ``frame.origin``).
    frame : Frame
        CRS and local origin (see :mod:`meshcore.crs`).
    block_names : tuple of str
    connectivity : tuple of Interface
        1-to-1 block interfaces (:func:`meshcore.io.find_interfaces`).
    source : str
    """

    blocks: tuple[StructuredGrid, ...]
    frame: Any = None
    block_names: tuple[str, ...] = ()
    connectivity: tuple[Any, ...] = ()
    source: str = ""

    def __post_init__(self) -> None:
        from ..crs import Frame

        object.__setattr__(self, "blocks", tuple(self.blocks))
        if self.frame is None:
            object.__setattr__(self, "frame", Frame())
        if not self.block_names:
            object.__setattr__(self, "block_names", tuple(f"block{k + 1}" for k in range(len(self.blocks))))

    def __len__(self) -> int:
        return len(self.blocks)

    def world(self, k: int) -> tuple[np.ndarray, np.ndarray]:
        """World coordinates of block ``k`` (local + origin)."""
        g = self.blocks[k]
        return self.frame.to_world(g.x, g.y)
