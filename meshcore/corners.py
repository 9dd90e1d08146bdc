r"""Automatic choice of the four block corners on a closed boundary loop.

A single structured block over a closed outline (a lake shoreline) needs four
corner points ``(sw, se, ne, nw)`` that split the loop into the borders
bottom, right, top and left.  :func:`choose_corners` picks them from the
outline alone:

``"bbox"`` (default)
    The principal axes of the outline (eigenvectors of the second-moment
    tensor of the boundary, each vertex weighted by half its two adjacent
    edge lengths) define a rotated bounding box; ``s`` runs along the long
    axis, ``t = ẑ × s``.  Each corner is the loop vertex nearest the
    matching box corner (``sw = (s_min, t_min)``, ``se = (s_max, t_min)``,
    ``ne = (s_max, t_max)``, ``nw = (s_min, t_max)``).  A pick that lands on
    a reflex vertex (interior angle ≥ 180°) is replaced by the nearest
    *convex* vertex, so the corner cell can be convex.
``"hull"``
    The support vertices of the outline in the four box-diagonal directions
    ``(±w, ±h)``.  Support vertices are convex-hull vertices, hence never
    reflex, and they appear along the loop in the same cyclic order as their
    directions, so they are always a valid (sw, se, ne, nw).

``"outline"``
    For shorelines and rivers: a long, narrow, curved outline
    (``4·area / perimeter² < 0.12``, i.e. width ≲ length / 8, filling less
    than 70 % of its principal box) gets two corners beside each tip — the
    first vertices, walking both ways from the extreme vertices along the long
    axis, at least half a mean width (``area / half-perimeter``) of arc away —
    so the tips become the short left/right borders; any other outline gets
    the ``"bbox"`` corners.

All methods fall back to ``"hull"`` when their picks coincide or are not in
counter-clockwise cyclic order, and then to convex vertices near the quarter
points of the perimeter measured from the ``sw`` pick.  ``upright=True``
renames the corners (a cyclic shift, the same grid up to a renaming of the
borders) so that SW → SE points most nearly along +x: "bottom" stays at the
bottom of the screen.

:func:`meshcore.io.outline.guess_corners` (``meshcore import``) and the app
both use ``method="outline", upright=True``.

A corner on a reflex vertex makes its corner cell non-convex whatever the
interior nodes do (the corner Jacobian of that cell depends on the three
boundary nodes only).  :func:`corner_problems` finds such corners and names
the one to move.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ._validation import check_extent, validate_choice, validate_points
from .errors import BoundaryError

__all__ = ["CORNER_NAMES", "CornerProblem", "choose_corners", "corner_problems", "interior_angles"]

#: Corner names in the order of the ``corners=`` argument.
CORNER_NAMES: tuple[str, ...] = ("sw", "se", "ne", "nw")


def _loop(points: Any, name: str) -> tuple[np.ndarray, int]:
    p = validate_points(points, name=name, min_points=4)
    n = len(p)
    size = check_extent(p, name=name)
    if math.hypot(*(p[0] - p[-1])) <= 1e-12 * size:
        n -= 1
    return p[:n], n


def _signed_area(p: np.ndarray) -> float:
    from .boundary import signed_area  # translation- and scale-invariant sign

    return signed_area(p)


def interior_angles(points: Any) -> np.ndarray:
    """Interior angle (degrees, in (0, 360)) at every vertex of a closed loop.

    The loop may run either way; angles are measured on the side of the
    enclosed region.  A vertex with angle > 180° is *reflex*.
    """
    p, _ = _loop(points, "boundary points")
    return _angles(p)


def _angles(p: np.ndarray) -> np.ndarray:
    """Interior angles of the loop ``p`` exactly as given (no closing point dropped: a loop whose
    last point repeats its first after a run of repeated points keeps its length)."""
    flip = _signed_area(p) < 0
    if flip:  # measure on the counter-clockwise loop (no recursion: rounding cannot ping-pong)
        p = p[::-1]
    d_in = p - np.roll(p, 1, axis=0)
    d_out = np.roll(p, -1, axis=0) - p
    turn = np.arctan2(
        d_in[:, 0] * d_out[:, 1] - d_in[:, 1] * d_out[:, 0],
        (d_in * d_out).sum(axis=1),
    )
    ang = 180.0 - np.degrees(turn)
    return ang[::-1].copy() if flip else ang


def _angles_of_distinct(p: np.ndarray) -> np.ndarray:
    """:func:`_angles` with each run of repeated consecutive points measured as one point (every
    copy gets its angle): a zero-length edge has no direction, and :func:`_angles` would give
    its ends 180°, a "reflex" corner where a user clicked a point twice.  Repeats are the
    points :func:`meshcore.boundary.borders_from_loop` drops (within 1e-9 of the loop's size)."""
    size = check_extent(p, name="boundary points")
    first = np.hypot(*(p - np.roll(p, 1, axis=0)).T) > 1e-9 * size  # not a repeat of its predecessor
    if first.all() or first.sum() < 3:
        return _angles(p)
    run = np.cumsum(first) - 1  # -1 (the last run) for repeats of the last point that wrap round
    return _angles(p[first])[run]


def _principal_frame(p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Centre and rotation (rows = long axis s, short axis t) of the outline."""
    seg = np.hypot(*(np.roll(p, -1, axis=0) - p).T)
    w = 0.5 * (seg + np.roll(seg, 1))
    c = (w[:, None] * p).sum(axis=0) / w.sum()
    d = p - c
    m = (w[:, None, None] * d[:, :, None] * d[:, None, :]).sum(axis=0)
    vals, vecs = np.linalg.eigh(m)
    s = vecs[:, int(np.argmax(vals))]
    if s[0] < 0 or (s[0] == 0 and s[1] < 0):
        s = -s
    t = np.array([-s[1], s[0]])
    return c, np.vstack([s, t])


def _cyclic_ok(c: list[int], n: int) -> bool:
    if len(set(c)) != 4:
        return False
    rel = [(ci - c[0]) % n for ci in c]
    return rel[0] < rel[1] < rel[2] < rel[3]


def choose_corners(points: Any, *, method: str = "bbox", upright: bool = False) -> tuple[int, int, int, int]:
    """Pick four corner indices ``(sw, se, ne, nw)`` on a closed loop.

    Parameters
    ----------
    points : (n, 2) array_like
        The loop, either orientation, optionally closed (first point repeated).
    method : {"bbox", "hull", "outline"}
        See the module docstring.
    upright : bool
        Rename the corners so that SW → SE points most nearly along +x.

    Returns
    -------
    tuple of int
        Indices into ``points`` in the order expected by
        ``borders_from_loop(points, corners)`` / ``generate_block(loop=, corners=)``.

    Examples
    --------
    >>> sq = [[0, 0], [1, 0], [2, 0], [2, 1], [1, 1], [0, 1]]
    >>> choose_corners(sq)
    (0, 2, 3, 5)
    """
    method = validate_choice(method, ("bbox", "hull", "outline"), name="corner method")
    p, n = _loop(points, "boundary points")
    from .boundary import check_encloses_area  # points on a line: one clear error, not a NaN box

    ccw = check_encloses_area(p, name="boundary points") >= 0
    q = p if ccw else p[::-1]
    c0, rot = _principal_frame(q)
    st = (q - c0) @ rot.T
    picks: list[int] = []
    if method == "outline" and _elongated(q, st):
        picks = _tip_corners(q, st[:, 0])  # [] when the tips give no four corners: the box
    if not picks and method in ("bbox", "outline"):
        picks = _box_corners(q, st)
    if not _cyclic_ok(picks, n):
        picks = _hull_corners(st)
        if not _cyclic_ok(picks, n):
            picks = _by_arc_length(q, picks[0])
        if not _cyclic_ok(picks, n):
            raise BoundaryError(
                "could not find four distinct corners in counter-clockwise order on the "
                f"loop of {n} points (picked {picks}); give corners= explicitly"
            )
    if upright:
        picks = _upright(q, picks)
    if not ccw:
        picks = [n - 1 - k for k in picks]
    return tuple(int(k) for k in picks)  # type: ignore[return-value]


def _box(st: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    lo, hi = st.min(axis=0), st.max(axis=0)
    return np.array([[lo[0], lo[1]], [hi[0], lo[1]], [hi[0], hi[1]], [lo[0], hi[1]]]), lo, hi


def _box_corners(q: np.ndarray, st: np.ndarray) -> list[int]:
    """The vertices nearest the principal box's corners (the nearest convex one for a reflex pick)."""
    box, _, _ = _box(st)
    convex = _angles(q) < 180.0 - 1e-9
    picks = []
    for b in box:
        d2 = ((st - b) ** 2).sum(axis=1)
        k = int(np.argmin(d2))
        if not convex[k] and convex.any():
            k = int(np.argmin(np.where(convex, d2, np.inf)))
        picks.append(k)
    return picks


def _hull_corners(st: np.ndarray) -> list[int]:
    """The support vertices in the four box-diagonal directions (hull vertices, never reflex)."""
    box, lo, hi = _box(st)
    half = 0.5 * (hi - lo)
    half = np.where(half > 0, half, 1.0)
    picks = []
    for b in box:
        direction = (b - 0.5 * (lo + hi)) / half**2
        proj = st @ direction
        # ties (a straight hull edge): take the vertex nearest the box corner
        cand = np.flatnonzero(proj >= proj.max() - 1e-12 * max(1.0, abs(proj.max())))
        picks.append(int(cand[np.argmin(((st[cand] - b) ** 2).sum(axis=1))]))
    return picks


def _elongated(q: np.ndarray, st: np.ndarray) -> bool:
    """Long, narrow and curved: ``4·area / perimeter² < 0.12`` and filling < 70 % of the box."""
    area = abs(_signed_area(q))
    perimeter = float(np.hypot(*(np.roll(q, -1, axis=0) - q).T).sum())
    extent = st.max(axis=0) - st.min(axis=0)
    fill = area / max(float(extent[0] * extent[1]), 1e-300)
    return 4.0 * area / max(perimeter**2, 1e-300) < 0.12 and fill < 0.7


def _tip_corners(q: np.ndarray, u: np.ndarray) -> list[int]:
    """Two corners beside each tip of a long loop (counter-clockwise ``q``; ``u``: long-axis coordinate)."""
    n = len(q)
    seg = np.hypot(*(np.roll(q, -1, axis=0) - q).T)
    width = 2.0 * abs(_signed_area(q)) / seg.sum()
    a, b = int(np.argmin(u)), int(np.argmax(u))

    def walk(tip: int, step: int) -> int:
        """The first vertex at least half a mean width of arc away from the tip."""
        arc, k = 0.0, tip
        for _ in range(n // 4):
            nxt = (k + step) % n
            arc += float(np.hypot(*(q[nxt] - q[k])))
            k = nxt
            if arc >= 0.5 * width:
                break
        return k

    c = [walk(a, 1), walk(b, -1), walk(b, 1), walk(a, -1)]  # sw, se, ne, nw walking CCW
    if not _cyclic_ok(c, n):
        return []
    ang = _angles(q)
    for prob in corner_problems(q, c):  # off reflex vertices, keeping the order
        if prob.suggestion is not None:
            trial = c.copy()
            trial[CORNER_NAMES.index(prob.corner)] = prob.suggestion
            if _cyclic_ok(trial, n) and ang[prob.suggestion] < 180.0:
                c = trial
    return c


def _upright(q: np.ndarray, c: list[int]) -> list[int]:
    """Rotate the corner roles so that SW → SE points most nearly along +x."""
    best, best_cos = 0, -2.0
    for k in range(4):
        d = q[c[(k + 1) % 4]] - q[c[k]]
        cos = float(d[0] / max(math.hypot(*d), 1e-300))
        if cos > best_cos + 1e-12:
            best, best_cos = k, cos
    return [c[(best + j) % 4] for j in range(4)]


def _by_arc_length(q: np.ndarray, start: int) -> list[int]:
    """Four vertices near the quarter points of the perimeter from ``start`` (convex preferred)."""
    n = len(q)
    order = [(start + k) % n for k in range(n)]
    seg = np.hypot(*(np.roll(q, -1, axis=0) - q).T)
    s = np.concatenate([[0.0], np.cumsum(seg[order][:-1])])
    per = float(seg.sum())
    convex = _angles(q)[order] < 180.0
    picks = [0]
    for k in (1, 2, 3):
        lo = picks[-1] + 1
        hi = n - (3 - k)  # leave room for the remaining corners
        cand = np.arange(lo, hi)
        if cand.size == 0:
            return []
        good = cand[convex[cand]] if convex[cand].any() else cand
        picks.append(int(good[np.argmin(np.abs(s[good] - k * per / 4))]))
    return [order[k] for k in picks]


@dataclass(frozen=True, slots=True)
class CornerProblem:
    """A block corner on a reflex boundary vertex (its corner cell cannot be convex)."""

    corner: str
    index: int
    point: tuple[float, float]
    angle: float
    suggestion: int | None

    @property
    def message(self) -> str:
        s = (
            f"corner {self.corner} (point {self.index} at "
            f"({self.point[0]:.6g}, {self.point[1]:.6g})) "
            f"is a reflex vertex (interior angle {self.angle:.1f}° ≥ 180°): its corner cell cannot "
            f"be convex; move corner {self.corner} to a convex vertex"
        )
        if self.suggestion is not None:
            s += f", e.g. point {self.suggestion}"
        return s


def corner_problems(points: Any, corners: Any) -> list[CornerProblem]:
    """Corners (``sw, se, ne, nw`` indices into ``points``) that sit on reflex vertices."""
    p, n = _loop(points, "boundary points")
    ang = _angles_of_distinct(p)
    convex = np.flatnonzero(ang < 180.0)
    out = []
    for name, k in zip(CORNER_NAMES, corners, strict=True):
        k = int(k) % n
        if ang[k] >= 180.0:
            sug = None
            if convex.size:
                sug = int(convex[np.argmin(np.hypot(*(p[convex] - p[k]).T))])
            out.append(CornerProblem(name, k, (float(p[k, 0]), float(p[k, 1])), float(ang[k]), sug))
    return out
