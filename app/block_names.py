"""Block names that stay with their blocks across a layout edit (no Qt).

:func:`meshcore.layout.layout_from_cuts` names a layout's blocks ``b0, b1, …`` in the order it
finds its regions, so a cut added or deleted anywhere renamed blocks it never touched (the
modeller's ``b3`` became ``b2``, ``b5`` became ``b9``).  :func:`names_kept` gives the edited layout
the names of the layout before it:

* a block with the corners of a block before is that block: it keeps its name;
* a block the edit made (parted or joined) takes the name of the changed block before it overlaps
  most, when no bigger part of that block took it already (a block cut in two: its bigger part
  keeps the name); the others get new names after the highest number in use;
* the blocks are listed by name (``b2`` before ``b10``), as the Lake panel shows them.
"""

from __future__ import annotations

import dataclasses
import re
from typing import Any

import numpy as np

__all__ = ["names_kept"]


def _key(name: str) -> tuple:
    """``b2`` before ``b10``: the name's text and number parts, numbers as numbers."""
    return tuple((0, int(t), "") if t.isdigit() else (1, 0, t) for t in re.findall(r"\d+|\D+", name))


def _corners_key(corners: Any, tol: float) -> tuple:
    return tuple(np.round(np.asarray(corners, float).ravel() / tol).astype(np.int64).tolist())


def _polygon(ring: Any) -> Any:
    """A block's region as a valid shapely polygon (a ring that touches itself made valid)."""
    import shapely
    from shapely.geometry import Polygon

    poly = Polygon(np.asarray(ring, float))
    return poly if poly.is_valid else shapely.make_valid(poly)


def _fresh(used: set[str]) -> str:
    nums = [int(m.group(1)) for n in used if (m := re.fullmatch(r"b(\d+)", n))]
    name = f"b{max(nums, default=-1) + 1}"
    used.add(name)
    return name


def names_kept(before: Any, after: Any) -> Any:
    """``after`` (a :class:`meshcore.layout.Layout` made by editing ``before``) with the block names
    of ``before`` where the blocks are the same (see the module's text), its blocks in name order."""
    tol = 1e-6 * float(before.cell_size)
    old = {_corners_key(b.corners, tol): b.name for b in before.blocks}
    names: list[str | None] = [old.get(_corners_key(b.corners, tol)) for b in after.blocks]
    used = {n for n in names if n is not None}
    gone = [(b.name, _polygon(p.ring)) for p, b in zip(before.pieces, before.blocks, strict=True) if b.name not in used]
    new = [k for k, n in enumerate(names) if n is None]
    claims = []  # (overlap area, block k of after, name of a changed block of before)
    for k in new:
        poly = _polygon(after.pieces[k].ring)
        for name, was in gone:
            area = poly.intersection(was).area
            if area > 0:
                claims.append((area, k, name))
    for _area, k, name in sorted(claims, key=lambda c: -c[0]):  # the biggest overlap takes the name
        if names[k] is None and name not in used:
            names[k] = name
            used.add(name)
    used |= {b.name for b in before.blocks}  # a name that went is not given to another block
    final = [n if n is not None else _fresh(used) for n in names]
    if final == [b.name for b in after.blocks]:
        return after
    order = sorted(range(len(final)), key=lambda k: _key(final[k]))
    pieces = tuple(dataclasses.replace(after.pieces[k], name=final[k]) for k in order)
    blocks = tuple(dataclasses.replace(after.blocks[k], name=final[k]) for k in order)
    return dataclasses.replace(after, pieces=pieces, blocks=blocks)
