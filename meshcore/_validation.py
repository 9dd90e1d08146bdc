"""Small validators used at the public edge; every message names the argument."""

from __future__ import annotations

import enum
import math
from collections.abc import Iterable
from typing import Any

import numpy as np

from .errors import InvalidInputError

__all__ = [
    "validate_choice",
    "validate_count",
    "validate_fraction",
    "validate_points",
    "validate_positive",
]


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
    except (TypeError, ValueError) as exc:
        raise InvalidInputError(f"{prefix}{name}: cannot read points as numbers ({exc})") from None
    if arr.ndim != 2 or arr.shape[1] != 2:
        raise InvalidInputError(f"{prefix}{name}: expected an (n, 2) array of x, y points, got shape {arr.shape}")
    if arr.shape[0] < min_points:
        raise InvalidInputError(f"{prefix}{name}: needs at least {min_points} points, got {arr.shape[0]}")
    bad = ~np.isfinite(arr).all(axis=1)
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        raise InvalidInputError(
            f"{prefix}{name}: point {k} is not finite ({arr[k, 0]!r}, {arr[k, 1]!r})"
            + (f" and {int(bad.sum()) - 1} more" if bad.sum() > 1 else "")
        )
    return np.ascontiguousarray(arr)


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
