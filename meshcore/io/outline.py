r"""From a point file's outline to a block boundary: pick the loop and four corners.

A lake shoreline is one closed ring; a structured block needs four corners
``(sw, se, ne, nw)`` on it.  :func:`guess_corners` picks them in the frame of
the outline's principal axes ``(u, v)`` (u along the longest extent): the
points extreme in the four diagonal directions ``−u−v, +u−v, +u+v, −u+v``.
For an elongated lake this puts two corners at each end, so the long sides
become bottom and top.  If those four are not distinct or not in
counter-clockwise order, corners at quarter arc lengths are used instead.
"""

from __future__ import annotations

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
    """Four corner indices ``(sw, se, ne, nw)`` on a closed loop.

    The same choice as :func:`meshcore.corners.choose_corners` (vertices nearest the
    corners of the principal-axis bounding box, moved off reflex vertices).
    """
    from ..corners import choose_corners

    return choose_corners(loop)


def guess_cells(loop: Any, corners: tuple[int, int, int, int], *, ni: int = 40) -> tuple[int, int]:
    """Cell counts ``(ni, nj)`` with ``nj/ni`` ≈ (mean of left/right length) /
    (mean of bottom/top length), so cells are roughly square."""
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
    bt = 0.5 * (length(sw, se) + length(ne, nw))
    lr = 0.5 * (length(se, ne) + length(nw, sw))
    nj = max(2, round(ni * lr / bt)) if bt > 0 else ni
    return (ni, int(nj))
