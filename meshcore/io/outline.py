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

from ..cellratio import cell_ratio
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
    """Cell counts whose cells are near square: ``ni : nj`` is the ratio at which the Winslow grid's
    median cell is square (:func:`meshcore.cellratio.cell_ratio`).

    The ratio of the mean lengths of opposite borders, the guess before, counts every arm that a
    border traces in and out (a branched lake's bottom and top borders): cells came out three to
    four times longer across than along, too few rows to follow the arms.  On a rectangle both
    are its side ratio.  Where the ratio is not defined (a loop that crosses itself), the border
    lengths.

    By default the cells are :func:`meshcore.cellsize.default_cell_size` of the area inside the
    loop (``sqrt(area / 10 000)``, what ``meshcore mesh`` chooses), or ``cell_size``: ``ni · nj``
    is the area over the cell size squared.  With ``total``: about ``total`` cells along the
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
    ratio = cell_ratio(p, (sw, se, ne, nw))
    if not (ratio > 0 and math.isfinite(ratio)):
        lxi = 0.5 * (length(sw, se) + length(ne, nw))
        leta = 0.5 * (length(se, ne) + length(nw, sw))
        ratio = lxi / leta if lxi > 0 and leta > 0 else math.nan
    if total is not None:
        if not (ratio > 0 and math.isfinite(ratio)):
            return (total, total)
        if ratio >= 1:
            return (total, max(minimum, round(total / ratio)))
        return (max(minimum, round(total * ratio)), total)
    from ..boundary import signed_area
    from ..cellsize import DEFAULT_CELLS, default_cell_size

    area = abs(signed_area(p))
    h = float(cell_size) if cell_size is not None else default_cell_size(area)
    cells = area / h**2 if h > 0 else math.nan
    if not (cells > 0 and math.isfinite(cells) and ratio > 0 and math.isfinite(ratio)):
        side = max(minimum, round(math.sqrt(DEFAULT_CELLS)))
        return (side, side)
    ni, nj = max(minimum, round(math.sqrt(cells * ratio))), max(minimum, round(math.sqrt(cells / ratio)))
    shrink = math.sqrt(max_nodes() / ((ni + 1) * (nj + 1)))
    if shrink < 1.0:
        ni, nj = max(minimum, math.floor(ni * shrink) - 1), max(minimum, math.floor(nj * shrink) - 1)
    return (ni, nj)
