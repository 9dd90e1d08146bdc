"""Small validators used at the public edge; every message names the argument.

Limits
------
What an input may make meshcore allocate is checked *before* allocating, with
an error that says what the request would need:

* :func:`max_nodes` — nodes of one grid (generated, or read from a file):
  ``2**24`` (16 777 216, a 4097 × 4097 grid), ``MESHCORE_MAX_NODES`` overrides;
* :func:`max_points` — points (or lines) of one point file: 5 000 000,
  ``MESHCORE_MAX_POINTS`` overrides;
* :func:`max_bytes` — bytes of one input file, and bytes one compressed array
  may inflate to: 512 MiB, ``MESHCORE_MAX_BYTES`` overrides;
* :data:`MAX_COORDINATE` — coordinates must be finite and at most ``1e100``
  in magnitude (squares and products of them stay finite).
"""

from __future__ import annotations

import enum
import math
import os
from collections.abc import Iterable
from typing import Any

import numpy as np

from .errors import BoundaryError, InvalidInputError

__all__ = [
    "MAX_COORDINATE",
    "MIN_EXTENT",
    "check_allocation",
    "check_extent",
    "check_grid_size",
    "max_bytes",
    "max_nodes",
    "max_points",
    "validate_choice",
    "validate_count",
    "validate_fraction",
    "validate_indices",
    "validate_points",
    "validate_positive",
]


#: Largest coordinate magnitude accepted (its square, and products of two, stay finite).
MAX_COORDINATE = 1e100

#: Smallest extent of a boundary (cubes of cell sizes must stay above the float64 underflow).
MIN_EXTENT = 1e-100

#: Bytes per node a solve needs at most (coordinates, solver work arrays, quality and output arrays).
BYTES_PER_NODE = 200


def _env_limit(name: str, default: int) -> int:
    raw = os.environ.get(name, "").strip()
    if not raw:
        return default
    try:
        v = int(raw.replace("_", ""))
    except ValueError:
        raise InvalidInputError(f"environment variable {name} must be a positive integer, got {raw!r}") from None
    if v < 1:
        raise InvalidInputError(f"environment variable {name} must be a positive integer, got {raw!r}")
    return v


def max_nodes() -> int:
    """Largest number of nodes in one grid (``MESHCORE_MAX_NODES``, default ``2**24``)."""
    return _env_limit("MESHCORE_MAX_NODES", 2**24)


def max_points() -> int:
    """Largest number of points (or text lines) in one point file (``MESHCORE_MAX_POINTS``, default 5 000 000)."""
    return _env_limit("MESHCORE_MAX_POINTS", 5_000_000)


def max_bytes() -> int:
    """Largest input file, and largest inflated array, in bytes (``MESHCORE_MAX_BYTES``, default 512 MiB)."""
    return _env_limit("MESHCORE_MAX_BYTES", 512 * 2**20)


def _size(nbytes: int) -> str:
    for unit, f in (("TB", 1e12), ("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if nbytes >= f:
            return f"{nbytes / f:.3g} {unit}"
    return f"{nbytes} bytes"


def check_allocation(
    count: int, limit: int, *, what: str, env: str, error: type[Exception] = InvalidInputError
) -> None:
    """Raise ``error`` when ``count`` (of ``what``) exceeds ``limit`` (raised by the variable ``env``)."""
    if int(count) > int(limit):
        raise error(f"{what}: {int(count):,} is more than the limit of {int(limit):,} (set {env} to raise it)")


def read_file_bytes(path: Any, *, error: type[Exception], limit: int | None = None) -> bytes:
    """The bytes of the regular file ``path``, refusing (``error``) more than ``limit`` bytes
    (default :func:`max_bytes`) — by its size before reading, and while reading (a file that
    grows) — and a device, pipe or socket, which could be read for ever (``/dev/zero``, a fifo).
    A missing file or a directory raises ``FileNotFoundError`` / ``IsADirectoryError``."""
    import stat

    st = os.stat(path)
    if stat.S_ISDIR(st.st_mode):
        raise IsADirectoryError(21, "Is a directory", str(path))
    if not stat.S_ISREG(st.st_mode):
        raise error(f"{path}: not a regular file (a device, pipe or socket): give the path of a file")
    cap = max_bytes() if limit is None else int(limit)
    if limit is None:
        check_allocation(st.st_size, cap, what=f"{path}: file size in bytes", env="MESHCORE_MAX_BYTES", error=error)
    elif st.st_size > cap:
        raise error(f"{path}: file is {st.st_size:,} bytes, more than the limit of {cap:,}")
    with open(path, "rb") as fh:
        data = fh.read(min(cap, st.st_size) + 1)  # read(n) reserves n bytes: the size it has, not the cap
        if len(data) > st.st_size:  # a file that grows while it is read (or a /proc file of size 0)
            parts, n = [data], len(data)
            while n <= cap and (chunk := fh.read(1 << 20)):
                parts.append(chunk)
                n += len(chunk)
            data = b"".join(parts)
    if len(data) > cap:
        raise error(f"{path}: the file grew beyond the limit of {cap:,} bytes while it was read")
    return data


def check_grid_size(
    n_i: Any, n_j: Any, *, what: str = "grid", error: type[Exception] = InvalidInputError, nodes: bool = False
) -> None:
    """Refuse a grid of ``n_i × n_j`` cells (``nodes=True``: nodes) above :func:`max_nodes`.

    Works on Python integers, so absurd counts (``2**63 - 1``) give the same
    clear message instead of an overflow.
    """
    a, b = int(n_i), int(n_j)
    ni, nj = (a, b) if nodes else (a + 1, b + 1)
    n = ni * nj
    limit = max_nodes()
    if n > limit:
        shown = f"{a} × {b} {'nodes' if nodes else 'cells'}"
        raise error(
            f"{what}: {shown} make {n:,} nodes (about {_size(n * BYTES_PER_NODE)} of memory to solve); "
            f"the limit is {limit:,} nodes (set MESHCORE_MAX_NODES to raise it)"
        )


def validate_points(points: Any, *, name: str, min_points: int = 2, where: str = "") -> np.ndarray:
    """Return ``points`` as a C-contiguous float64 ``(n, 2)`` array or raise.

    Parameters
    ----------
    points : array_like
        ``(n, 2)`` coordinates.
    name : str
        Name used in error messages, e.g. ``"bottom border"``.
    min_points : int
        Minimum number of points.
    where : str
        Optional location prefix (a file name) for messages.
    """
    prefix = f"{where}: " if where else ""
    try:
        arr = np.asarray(points, dtype=np.float64)
    except (TypeError, ValueError, OverflowError) as exc:  # OverflowError: an int beyond any float
        raise InvalidInputError(f"{prefix}{name}: cannot read points as numbers ({exc})") from None
    if arr.ndim != 2 or arr.shape[1] != 2:
        raise InvalidInputError(f"{prefix}{name}: expected an (n, 2) array of x, y points, got shape {arr.shape}")
    if arr.shape[0] < min_points:
        raise InvalidInputError(f"{prefix}{name}: needs at least {min_points} points, got {arr.shape[0]}")
    bad = ~np.isfinite(arr).all(axis=1)
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        raise InvalidInputError(
            f"{prefix}{name}: point {k + 1} is not finite ({float(arr[k, 0])!r}, {float(arr[k, 1])!r})"
            + (f" and {int(bad.sum()) - 1} more" if bad.sum() > 1 else "")
        )
    huge = (np.abs(arr) > MAX_COORDINATE).any(axis=1)
    if huge.any():
        k = int(np.flatnonzero(huge)[0])
        raise InvalidInputError(
            f"{prefix}{name}: point {k + 1} ({arr[k, 0]:.6g}, {arr[k, 1]:.6g}) is beyond ±{MAX_COORDINATE:g}; "
            f"scale the coordinates (or move them to a local origin)"
        )
    return np.ascontiguousarray(arr)


def check_extent(points: np.ndarray, *, name: str) -> float:
    """The extent (bounding-box diagonal) of ``points``; refuse a boundary too small to grid.

    Too small is below :data:`MIN_EXTENT`, or below 1e-12 of the largest
    coordinate (then float64 resolves fewer than four digits across it).
    """
    p = np.asarray(points, dtype=np.float64)
    size = float(np.hypot(*(p.max(axis=0) - p.min(axis=0))))
    big = float(np.abs(p).max())
    if size == 0:
        raise BoundaryError(f"{name}: all points coincide")
    if size < MIN_EXTENT:
        raise BoundaryError(f"{name}: the points span only {size:.3g} (less than {MIN_EXTENT:g}); scale them up")
    if size <= 1e-12 * big:
        raise BoundaryError(
            f"{name}: the points span only {size:.3g} at coordinates up to {big:.3g}, too little to grid in "
            f"double precision; move them to a local origin (subtract a point near them)"
        )
    return size


def validate_count(value: Any, *, name: str, minimum: int = 1) -> int:
    """Return ``value`` as an int ``>= minimum`` or raise."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        if isinstance(value, (float, np.floating)) and float(value).is_integer():
            value = int(value)
        else:
            raise InvalidInputError(f"{name} must be an integer, got {value!r}")
    if value < minimum:
        raise InvalidInputError(f"{name} must be >= {minimum}, got {value}")
    return int(value)


def validate_indices(values: Any, *, name: str) -> tuple[int, ...]:
    """Return point indices as ints (negative ones count from the end) or raise.

    A whole number written as a float (``3.0``, from a JSON or TOML file) is an
    index; ``2.5``, ``True``, ``"3"`` or something that is not a sequence is an
    error, never silently truncated.
    """
    try:
        items = list(values)
    except TypeError:
        raise InvalidInputError(f"{name} must be integer point indices, got {values!r}") from None
    for v in items:
        whole = isinstance(v, (float, np.floating)) and float(v).is_integer()
        if not whole and (isinstance(v, (bool, np.bool_)) or not isinstance(v, (int, np.integer))):
            raise InvalidInputError(f"{name} must be integer point indices, got {v!r} in {values!r}")
    return tuple(int(v) for v in items)


def validate_fraction(value: Any, *, name: str) -> float:
    """Return ``value`` as a float in [0, 1] or raise."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InvalidInputError(f"{name} must be a number in [0, 1], got {value!r}") from None
    if not (0.0 <= v <= 1.0) or math.isnan(v):
        raise InvalidInputError(f"{name} must be in [0, 1], got {v}")
    return v


def validate_positive(value: Any, *, name: str, allow_none: bool = False) -> float | None:
    """Return ``value`` as a finite float > 0 (or None when allowed) or raise."""
    if value is None and allow_none:
        return None
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InvalidInputError(f"{name} must be a positive number, got {value!r}") from None
    if not math.isfinite(v) or v <= 0:
        raise InvalidInputError(f"{name} must be a positive finite number, got {v}")
    return v


def validate_choice(value: Any, choices: Iterable[str] | type[enum.Enum], *, name: str) -> str:
    """Return ``value`` if it is one of ``choices`` (case-insensitive) or raise listing them."""
    if isinstance(choices, type) and issubclass(choices, enum.Enum):
        options = [str(m.value) for m in choices]
    else:
        options = [str(c) for c in choices]
    if isinstance(value, enum.Enum):
        value = value.value
    if isinstance(value, str) and value.lower() in options:
        return value.lower()
    raise InvalidInputError(f"{name} must be one of {', '.join(map(repr, options))}; got {value!r}")
