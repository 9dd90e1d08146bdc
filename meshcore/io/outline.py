r"""From a point file's outline to a block boundary: pick the loop and four corners.

A lake shoreline is one closed ring; a structured block needs four corners
``(sw, se, ne, nw)`` on it and cell counts.  :func:`guess_corners` and
:func:`guess_cells` are the one choice that ``meshcore import`` and the app
both make, so a point file gives the same grid in both.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..errors import InvalidInputError

__all__ = ["guess_cells", "guess_corners", "outline_loop"]


def outline_loop(pointset: Any, name: str | None = None) -> np.ndarray:
    """The boundary loop: the named polyline, else the longest ring, else the longest line."""
    pls = list(pointset.polylines)
    if not pls:
        raise InvalidInputError(f"{pointset.source}: no polylines")
    if name is not None:
        return pointset[name].points
    rings = [p for p in pls if p.closed]
    pick = max(rings or pls, key=len)
    return pick.points


def _ccw(loop: np.ndarray) -> bool:
    from ..boundary import signed_area

    return signed_area(loop) > 0


def guess_corners(loop: Any) -> tuple[int, int, int, int]:
    """Four corner indices ``(sw, se, ne, nw)`` on a closed loop: the choice of ``meshcore import`` and the app.

    :func:`meshcore.corners.choose_corners` with ``method="outline"`` (tip caps
    for long narrow outlines, else the principal box) and ``upright=True``.
    """
    from ..corners import choose_corners

    return choose_corners(loop, method="outline", upright=True)


def guess_cells(
    loop: Any,
    corners: tuple[int, int, int, int],
    *,
    cell_size: float | None = None,
    total: int | None = None,
    minimum: int = 8,
) -> tuple[int, int]:
    """Cell counts proportional to the mean lengths of opposite borders, cells roughly square.

    By default the cells are :func:`meshcore.cellsize.default_cell_size` of the area inside the
    loop (``sqrt(area / 10 000)``, what ``meshcore mesh`` chooses), or ``cell_size``: each count
    is a border's mean length over the cell size.  With ``total``: about ``total`` cells along the
    longer direction instead.  At least ``minimum`` along either; a grid past the node limit
    (:func:`meshcore._validation.max_nodes`) is scaled down to it, keeping the proportions.
    """
    from .._validation import max_nodes

    p = np.asarray(loop, dtype=np.float64)
    n = len(p)
    seg = np.hypot(*np.diff(np.vstack([p, p[:1]]), axis=0).T)
    ccw = _ccw(p)

    def length(a: int, b: int) -> float:
        k, tot = a, 0.0
        for _ in range(n):  # at most once around the loop
            if k == b:
                break
            tot += seg[k] if ccw else seg[(k - 1) % n]
            k = (k + 1) % n if ccw else (k - 1) % n
        return tot

    try:
        sw, se, ne, nw = (int(c) % n for c in corners)
    except (TypeError, ValueError):
        raise InvalidInputError(f"corners must be 4 integer point indices, got {corners!r}") from None
    lxi = 0.5 * (length(sw, se) + length(ne, nw))
    leta = 0.5 * (length(se, ne) + length(nw, sw))
    if total is not None:
        if lxi <= 0 or leta <= 0 or not math.isfinite(lxi / leta):
            return (total, total)
        if lxi >= leta:
            return (total, max(minimum, round(total * leta / lxi)))
        return (max(minimum, round(total * lxi / leta)), total)
    from ..boundary import signed_area
    from ..cellsize import DEFAULT_CELLS, default_cell_size

    h = float(cell_size) if cell_size is not None else default_cell_size(abs(signed_area(p)))
    if not (h > 0 and math.isfinite(lxi / h) and math.isfinite(leta / h)):
        side = max(minimum, round(math.sqrt(DEFAULT_CELLS)))
        return (side, side)
    ni, nj = max(minimum, round(lxi / h)), max(minimum, round(leta / h))
    shrink = math.sqrt(max_nodes() / ((ni + 1) * (nj + 1)))
    if shrink < 1.0:
        ni, nj = max(minimum, math.floor(ni * shrink) - 1), max(minimum, math.floor(nj * shrink) - 1)
    return (ni, nj)
