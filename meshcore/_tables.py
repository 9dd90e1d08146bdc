"""Mappings (case-file tables, keyword dicts) → frozen dataclasses: one helper for all.

:func:`from_table` reads the valid keys from :func:`dataclasses.fields`, so a
new field is a new key with nothing else to update.  Keys may be written with
``-`` or ``_`` (``thomas-middlecoff``).  Every message names the place
(``where``), the key and the valid keys.

>>> from dataclasses import dataclass
>>> @dataclass(frozen=True)
... class Pen:
...     width: float = 1.0
...     colour: str = "black"
>>> from_table(Pen, {"width": 2}, where="[pen]")
Pen(width=2, colour='black')
>>> from_table(Pen, {"colour": "red", "size": 3}, where="[pen]")
Traceback (most recent call last):
...
meshcore.errors.InvalidInputError: [pen]: unknown key 'size'; valid keys: colour, width
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Collection, Mapping
from typing import Any, TypeVar

from .errors import InvalidInputError

__all__ = ["check_keys", "from_table", "table_keys"]

T = TypeVar("T")


def table_keys(cls: type, *, exclude: Collection[str] = ()) -> set[str]:
    """The keys a table for ``cls`` may hold: its ``__init__`` fields minus ``exclude``."""
    return {f.name for f in dataclasses.fields(cls) if f.init and f.name not in exclude}


def check_keys(
    table: Any, valid: Collection[str], where: str, *, error: type[InvalidInputError] = InvalidInputError
) -> dict[str, Any]:
    """``table`` as a dict with ``-`` in keys read as ``_``; raises naming an unknown key."""
    if not isinstance(table, Mapping):
        raise error(f"{where}: expected a table, got {table!r}")
    out = {}
    for key, value in table.items():
        name = str(key).replace("-", "_")
        if name not in valid:
            raise error(f"{where}: unknown key {key!r}; valid keys: {', '.join(sorted(valid))}")
        out[name] = value
    return out


def from_table(
    cls: type[T],
    table: Any,
    *,
    where: str,
    error: type[InvalidInputError] = InvalidInputError,
    convert: Mapping[str, Callable[[Any, str], Any]] | None = None,
    exclude: Collection[str] = (),
    ignore: Collection[str] = (),
    required: Collection[str] = (),
    **given: Any,
) -> T:
    """Build the dataclass ``cls`` from a mapping.

    Parameters
    ----------
    cls : dataclass type
        The target; its ``__post_init__`` validates the values.
    table : mapping
        Keys are field names (``-`` allowed for ``_``).
    where : str
        Location prefix of every message (file, table, block).
    error : InvalidInputError subclass
        The exception raised (e.g. :class:`~meshcore.errors.CaseFileError`).
    convert : mapping of field name to ``fn(value, where) -> value``, optional
        Per-key conversion before construction (may raise ``error``).
    exclude : collection of str
        Fields that a table may not set.
    ignore : collection of str
        Keys that are valid but handled by the caller (skipped here).
    required : collection of str
        Keys that must be present.
    **given
        Field values decided by the caller.
    """
    valid = table_keys(cls, exclude=exclude) | set(ignore)
    kw = check_keys(table, valid, where, error=error)
    missing = [k for k in required if k not in kw]
    if missing:
        raise error(f"{where}: missing key {missing[0]!r}")
    for k in ignore:
        kw.pop(k, None)
    for name, fn in (convert or {}).items():
        if name in kw:
            kw[name] = fn(kw[name], f"{where}: {name}")
    try:
        return cls(**(kw | given))
    except (InvalidInputError, TypeError) as exc:
        raise error(f"{where}: {exc}") from None
