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
    c = loop - loop.mean(axis=0)
    return float(np.sum(c[:, 0] * np.roll(c[:, 1], -1) - np.roll(c[:, 0], -1) * c[:, 1])) > 0


def guess_corners(loop: Any) -> tuple[int, int, int, int]:
    """Four corner indices ``(sw, se, ne, nw)`` on a closed loop (see module docstring)."""
    p = np.asarray(loop, dtype=np.float64)
    if len(p) > 2 and np.array_equal(p[0], p[-1]):
        p = p[:-1]
    n = len(p)
    if n < 4:
        raise InvalidInputError(f"a loop needs at least 4 points for 4 corners, got {n}")
    c = p - p.mean(axis=0)
    w, vec = np.linalg.eigh(c.T @ c)
    u_ax = vec[:, np.argmax(w)]
    v_ax = np.array([-u_ax[1], u_ax[0]])
    u, v = c @ u_ax, c @ v_ax
    cand = [int(np.argmax(-u - v)), int(np.argmax(u - v)), int(np.argmax(u + v)),
            int(np.argmax(-u + v))]
    ccw = _ccw(p)

    def ok(cs: list[int]) -> bool:
        if len(set(cs)) != 4:
            return False
        rel = [((k - cs[0]) if ccw else (cs[0] - k)) % n for k in cs]
        return rel[0] < rel[1] < rel[2] < rel[3]

    if ok(cand):
        return tuple(cand)  # type: ignore[return-value]
    seg = np.hypot(*np.diff(np.vstack([p, p[:1]]), axis=0).T)
    total = float(np.sum(seg))
    s = np.concatenate([[0.0], np.cumsum(seg)])[:-1]
    rel_s = (s - s[cand[0]]) % total
    idx = [int(np.argmin(np.abs(rel_s - q * total))) for q in (0.0, 0.25, 0.5, 0.75)]
    if not ccw:
        idx = [idx[0], idx[3], idx[2], idx[1]]
    if len(set(idx)) != 4:
        raise InvalidInputError("cannot place four distinct corners on this loop; give --corners")
    return tuple(idx)  # type: ignore[return-value]


def guess_cells(loop: Any, corners: tuple[int, int, int, int], *, ni: int = 40) -> tuple[int, int]:
    """Cell counts ``(ni, nj)`` with ``nj/ni`` ≈ (mean of left/right length) /
    (mean of bottom/top length), so cells are roughly square."""
    p = np.asarray(loop, dtype=np.float64)
    n = len(p)
    seg = np.hypot(*np.diff(np.vstack([p, p[:1]]), axis=0).T)

    ccw = _ccw(p)

    def length(a: int, b: int) -> float:
        k, tot = a, 0.0
        while k != b:
            tot += seg[k] if ccw else seg[(k - 1) % n]
            k = (k + 1) % n if ccw else (k - 1) % n
        return tot

    sw, se, ne, nw = corners
    bt = 0.5 * (length(sw, se) + length(ne, nw))
    lr = 0.5 * (length(se, ne) + length(nw, sw))
    nj = max(2, round(ni * lr / bt)) if bt > 0 else ni
    return (ni, int(nj))
