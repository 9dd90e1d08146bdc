"""Boundaries and their four borders: validation, splitting, re-sampling.

A block boundary is given either as four open polylines ``bottom, right, top,
left`` in the orientation of :mod:`meshcore.grid`, or as one closed loop of
points plus four corner indices ``(sw, se, ne, nw)``.

Policies (documented once, here):

* **Duplicate consecutive points** are dropped with a :class:`MeshcoreWarning`
  naming the border and the point index; a border left with fewer than two
  distinct points is an error (zero-length border).
* **Corners** of adjacent borders must meet to ``1e-9`` of the boundary size;
  they are then snapped to be bit-identical.
* **Loops** may be given clockwise or counter-clockwise and with or without the
  first point repeated at the end; corners ``(sw, se, ne, nw)`` must appear in
  that cyclic order when walking the loop counter-clockwise.
* **Self-intersection** of the boundary is an error naming both segments
  (border and point indices) and the crossing location.  Two opposite borders
  that coincide exactly (a *cut*, as in the paper's doubly-connected case) are
  allowed.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from ._validation import (
    check_extent,
    check_grid_size,
    validate_choice,
    validate_count,
    validate_indices,
    validate_points,
    validate_positive,
)
from .curves import CURVE_KINDS, make_curve
from .distribution import DISTRIBUTIONS, distribute
from .errors import BorderMismatchError, BoundaryError, InvalidInputError, MeshcoreWarning
from .grid import BORDER_NAMES

__all__ = [
    "BorderSpec",
    "Borders",
    "borders_from_loop",
    "borders_from_polylines",
    "check_self_intersection",
    "signed_area",
]


def check_encloses_area(points: np.ndarray, *, name: str) -> float:
    """The signed area of a closed loop; refuse a loop whose points lie on a line (no area at all).

    A loop that crosses itself so that its areas cancel is not refused here
    (the self-intersection check names the crossing).
    """
    p = np.asarray(points, dtype=np.float64)
    sv = np.linalg.svd(p - p.mean(axis=0), compute_uv=False) if len(p) >= 2 else np.zeros(1)
    if len(sv) < 2 or not sv[1] > 1e-12 * sv[0]:
        raise BoundaryError(f"{name}: the outline encloses no area (its points lie on a line)")
    return signed_area(p)


def signed_area(points: np.ndarray) -> float:
    """Signed area of a closed polygon (positive when counter-clockwise).

    Computed about the first vertex and in units of the polygon's extent, so
    the sign does not depend on where the polygon lies (a 1e-3 circle at
    (1e5, 1e5)) or on its scale (a loop scaled by 1e-300).  The value is
    the area times the square of the extent; it underflows to 0 only below
    the scales meshcore refuses anyway (:func:`~meshcore._validation.check_extent`).
    """
    p = np.asarray(points, dtype=np.float64)
    if len(p) < 3:
        return 0.0
    d = p - p[0]
    s = float(np.abs(d).max())
    if not s > 0 or not math.isfinite(s):
        return 0.0
    d = d / s
    x, y = d[:, 0], d[:, 1]
    a = 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))
    area = a * s * s
    return area if area != 0 or a == 0 else math.copysign(math.ulp(0.0), a)  # keep the sign of an underflow


@dataclass(frozen=True, slots=True)
class BorderSpec:
    """How one border is re-sampled.

    Parameters
    ----------
    distribution : {"uniform", "tanh", "vinokur"}
        Point distribution along the arc length.
    first, last : float, optional
        Absolute first / last cell spacing (model units) for clustering.
    name : str, optional
        A boundary-condition name (inlet, outlet, wall, shore …) that exporters carry.
    """

    distribution: str = "uniform"
    first: float | None = None
    last: float | None = None
    name: str | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "distribution", validate_choice(self.distribution, DISTRIBUTIONS, name="distribution"))
        for nm in ("first", "last"):
            object.__setattr__(self, nm, validate_positive(getattr(self, nm), name=f"{nm} spacing", allow_none=True))
        if self.distribution != "uniform" and self.first is None and self.last is None:
            raise InvalidInputError(f"distribution {self.distribution!r} needs 'first' and/or 'last' spacing")

    @classmethod
    def coerce(cls, value: Any, *, border: str) -> BorderSpec:
        if value is None:
            return cls()
        if isinstance(value, BorderSpec):
            return value
        if isinstance(value, str):
            return cls(distribution=value)
        if isinstance(value, Mapping):
            valid = {"distribution", "first", "last", "name"}
            unknown = set(value) - valid
            if unknown:
                raise InvalidInputError(f"{border} border: unknown option(s) {sorted(unknown)}; valid: {sorted(valid)}")
            try:
                return cls(**dict(value))
            except InvalidInputError as exc:
                raise InvalidInputError(f"{border} border: {exc}") from None
        raise InvalidInputError(f"{border} border: expected a distribution spec, got {value!r}")


def _which(indices) -> str:
    """Points named for everyone: ``point 4 (index 3)``, ``points 4, 9 (indices 3, 8)``.

    People (and the app's point rows) count points from 1; case files and arrays index them
    from 0: a message names both.  At most five, then ``…``.
    """
    k = [int(i) for i in indices]
    more = " …" if len(k) > 5 else ""
    k = k[:5]
    one = len(k) == 1
    return (
        f"point{'' if one else 's'} {', '.join(str(i + 1) for i in k)}{more} "
        f"({'index' if one else 'indices'} {', '.join(str(i) for i in k)}{more})"
    )


def _drop_duplicates(p: np.ndarray, *, name: str, tol: float) -> np.ndarray:
    seg = np.hypot(np.diff(p[:, 0]), np.diff(p[:, 1]))
    dup = np.flatnonzero(seg <= tol)
    if dup.size == len(seg):
        raise BoundaryError(f"{name}: zero-length border (all points coincide)")
    if dup.size:
        warnings.warn(
            f"{name}: dropped {dup.size} duplicate consecutive point(s): {_which(dup + 1)}",
            MeshcoreWarning,
            stacklevel=3,
        )
        keep = np.ones(len(p), dtype=bool)
        keep[dup + 1] = False
        # keep the last point (a corner) rather than its duplicate predecessor
        if not keep[-1]:
            keep[-1] = True
            keep[dup[-1]] = False
        p = p[keep]
    if len(p) < 2:
        raise BoundaryError(f"{name}: zero-length border (all points coincide)")
    return p


@dataclass(frozen=True, slots=True, eq=False)
class Borders:
    """Four border polylines in the grid convention (bottom, right, top, left)."""

    bottom: np.ndarray
    right: np.ndarray
    top: np.ndarray
    left: np.ndarray
    periodic: bool = False

    def __getitem__(self, name: str) -> np.ndarray:
        return getattr(self, name)

    def items(self):
        return [(n, getattr(self, n)) for n in BORDER_NAMES]

    @property
    def counts(self) -> dict[str, int]:
        return {n: len(getattr(self, n)) for n in BORDER_NAMES}

    @property
    def size(self) -> float:
        allp = np.vstack([self.bottom, self.right, self.top, self.left])
        return float(math.hypot(*(allp.max(axis=0) - allp.min(axis=0))))

    def loop(self) -> np.ndarray:
        """The closed boundary walk bottom → right → top⁻¹ → left⁻¹ (no repeated point)."""
        return np.vstack([self.bottom[:-1], self.right[:-1], self.top[::-1][:-1], self.left[::-1][:-1]])

    def check_counts(self) -> tuple[int, int]:
        """Return ``(ni, nj)`` cells or raise :class:`BorderMismatchError`."""
        c = self.counts
        if c["bottom"] != c["top"]:
            raise BorderMismatchError(
                f"bottom border has {c['bottom']} nodes but top border has {c['top']}; "
                f"opposite borders need equal counts (change one of them or give cells=)"
            )
        if c["left"] != c["right"]:
            raise BorderMismatchError(
                f"left border has {c['left']} nodes but right border has {c['right']}; "
                f"opposite borders need equal counts (change one of them or give cells=)"
            )
        return c["bottom"] - 1, c["left"] - 1

    def resampled(
        self,
        cells: tuple[int, int],
        *,
        specs: Mapping[str, Any] | None = None,
        curve: str = "linear",
        snap_angle: float | None = None,
    ) -> Borders:
        """Re-sample each border on its curve with ``cells = (ni, nj)``.

        ``specs`` maps border names to :class:`BorderSpec` (or dicts); spacings
        are absolute lengths and are converted to fractions of each border.
        ``snap_angle``: input vertices where a linear border turns by more than
        this many degrees (the corners of a cutout, say) receive a node
        exactly — the nearest re-sampled node moves onto them — so the grid
        keeps the drawn geometry; ``None`` (default) keeps the pure
        distribution, as in the paper.
        """
        ni = validate_count(cells[0], name="cells ξ (ni)")
        nj = validate_count(cells[1], name="cells η (nj)")
        check_grid_size(ni, nj, what="cells")  # before a node is allocated
        curve = validate_choice(curve, CURVE_KINDS, name="curve")
        specs = dict(specs or {})
        unknown = set(specs) - set(BORDER_NAMES)
        if unknown:
            raise InvalidInputError(f"unknown border name(s) {sorted(unknown)}; valid: {list(BORDER_NAMES)}")
        out = {}
        for name in BORDER_NAMES:
            n = ni if name in ("bottom", "top") else nj
            spec = BorderSpec.coerce(specs.get(name), border=name)
            c = make_curve(getattr(self, name), curve)
            first = None if spec.first is None else spec.first / c.length
            last = None if spec.last is None else spec.last / c.length
            try:
                u = distribute(n, spec.distribution, first=first, last=last)
            except InvalidInputError as exc:
                raise InvalidInputError(f"{name} border: {exc}") from None
            if snap_angle is not None and curve == "linear":
                u = _snap_to_vertices(getattr(self, name), u, snap_angle)
            pts = c.at_fraction(u)
            out[name] = pts
        if self.periodic:
            out["right"] = out["left"].copy()
        # Snap corners so that shared corners are bit-identical.
        b, r, t, l = out["bottom"], out["right"], out["top"], out["left"]
        l[0] = b[0]
        r[0] = b[-1]
        l[-1] = t[0]
        r[-1] = t[-1]
        return Borders(periodic=self.periodic, **out)


def _snap_to_vertices(p: np.ndarray, u: np.ndarray, angle: float) -> np.ndarray:
    """Move the nearest interior fraction onto each sharp vertex of polyline ``p``."""
    if len(p) < 3 or len(u) < 3:
        return u
    d = np.diff(p, axis=0)
    seg = np.hypot(d[:, 0], d[:, 1])
    s = np.concatenate([[0.0], np.cumsum(seg)]) / seg.sum()
    a0 = np.arctan2(d[:-1, 1], d[:-1, 0])
    a1 = np.arctan2(d[1:, 1], d[1:, 0])
    turn = np.degrees(np.abs((a1 - a0 + np.pi) % (2 * np.pi) - np.pi))
    u = u.copy()
    taken = np.zeros(len(u), dtype=bool)
    taken[0] = taken[-1] = True
    for k in np.argsort(-turn):  # sharpest first
        if turn[k] < angle:
            break
        sv = s[k + 1]
        ok = [m for m in range(1, len(u) - 1) if not taken[m] and u[m - 1] < sv < u[m + 1]]
        if ok:
            m = min(ok, key=lambda m: abs(u[m] - sv))
            u[m] = sv
            taken[m] = True
    return u


def _segment_table(parts: list[tuple[str, np.ndarray]]):
    rows = []
    for name, p in parts:
        for k in range(len(p) - 1):
            rows.append((name, k, p[k], p[k + 1]))
    return rows


def check_self_intersection(
    parts: list[tuple[str, np.ndarray]], *, allow_coincident: tuple[tuple[str, str], ...] = ()
) -> None:
    """Raise :class:`BoundaryError` if the chained polylines cross themselves.

    ``parts`` are consecutive open polylines forming a closed loop (end of one
    = start of the next).  Pairs in ``allow_coincident`` may overlap (a cut).
    """
    from shapely import STRtree, intersection, linestrings

    rows = _segment_table(parts)
    if len(rows) < 3:
        return
    coords = np.array([[r[2], r[3]] for r in rows])
    segs = linestrings(coords)
    tree = STRtree(segs)
    left_idx, right_idx = tree.query(segs, predicate="intersects")
    n = len(rows)
    allowed = {frozenset(p) for p in allow_coincident}
    for a, b in zip(left_idx, right_idx, strict=True):
        if a >= b:
            continue
        if b == a + 1 or (a == 0 and b == n - 1):
            # neighbours share an end point; they may only touch there
            inter = intersection(segs[a], segs[b])
            if inter.geom_type == "Point" or inter.is_empty:
                continue
        na, ka = rows[a][0], rows[a][1]
        nb, kb = rows[b][0], rows[b][1]
        if na != nb and frozenset((na, nb)) in allowed:
            continue
        inter = intersection(segs[a], segs[b])
        if inter.is_empty:
            continue
        if allowed and inter.geom_type == "Point":
            # with a cut the loop touches itself at the cut's end points (corners)
            ends_a = {tuple(rows[a][2]), tuple(rows[a][3])}
            ends_b = {tuple(rows[b][2]), tuple(rows[b][3])}
            if ends_a & ends_b:
                continue
        c = inter.centroid
        raise BoundaryError(
            f"boundary intersects itself near ({c.x:.6g}, {c.y:.6g}): the edge from point {ka + 1} to {ka + 2} "
            f"of the {na} border crosses the edge from point {kb + 1} to {kb + 2} of the {nb} border"
        )


def borders_from_polylines(
    bottom: Any,
    right: Any,
    top: Any,
    left: Any,
    *,
    check_intersections: bool = True,
    periodic: bool = False,
    where: str = "",
) -> Borders:
    """Validate four border polylines given in the grid convention.

    ``periodic=True`` declares the ξ direction periodic (an O-grid): left and
    right must coincide and their interior nodes are then solved, not fixed.

    Raises
    ------
    InvalidInputError
        Too few points, NaN/inf.
    BoundaryError
        Zero-length border, corners that do not meet, self-intersection.
    """
    prefix = f"{where}: " if where else ""
    raw = {}
    for name, pts in zip(BORDER_NAMES, (bottom, right, top, left), strict=True):
        # a private copy: corners are snapped in place below, never in the caller's arrays
        raw[name] = validate_points(pts, name=f"{prefix}{name} border", min_points=2).copy()
    allp = np.vstack(list(raw.values()))
    size = check_extent(allp, name=f"{prefix}boundary points")
    tol = 1e-9 * size
    for name in BORDER_NAMES:
        raw[name] = _drop_duplicates(raw[name], name=f"{prefix}{name} border", tol=tol)
    b, r, t, l = raw["bottom"], raw["right"], raw["top"], raw["left"]
    checks = [
        ("bottom", "start", b[0], "left", "start", l[0]),
        ("bottom", "end", b[-1], "right", "start", r[0]),
        ("top", "start", t[0], "left", "end", l[-1]),
        ("top", "end", t[-1], "right", "end", r[-1]),
    ]
    for n1, e1, p1, n2, e2, p2 in checks:
        d = float(np.hypot(*(p1 - p2)))
        if d > 1e-9 * size:
            raise BoundaryError(
                f"{prefix}corner mismatch: the {e1} of the {n1} border ({p1[0]:.6g}, {p1[1]:.6g}) "
                f"and the {e2} of the {n2} border ({p2[0]:.6g}, {p2[1]:.6g}) are {d:.3g} apart; "
                f"borders must share their corners (check the border orientation: bottom/top run "
                f"left→right, left/right run bottom→top)"
            )
    # snap corners
    l[0] = b[0]
    r[0] = b[-1]
    l[-1] = t[0]
    r[-1] = t[-1]
    # A cut: left and right coincide (the paper's doubly-connected case).  It
    # is held fixed like any border unless the caller asks for periodic=True.
    is_cut = bool(l.shape == r.shape and np.allclose(l, r, atol=tol, rtol=0))
    if periodic and not is_cut:
        raise BoundaryError(
            f"{prefix}periodic=True needs the left and right borders to coincide (the seam of an "
            f"O-grid); they differ by up to {float(np.abs(l - r).max()) if l.shape == r.shape else float('nan'):.3g}"
        )
    if is_cut:
        r = l.copy()
    borders = Borders(bottom=b, right=r, top=t, left=l, periodic=bool(periodic))
    if check_intersections:
        allow = (("left", "right"),) if is_cut else ()
        try:
            check_self_intersection(
                [("bottom", b), ("right", r), ("top", t[::-1]), ("left", l[::-1])],
                allow_coincident=allow,
            )
        except BoundaryError as exc:
            raise BoundaryError(f"{prefix}{exc}") from None
        if not is_cut and check_encloses_area(borders.loop(), name=f"{prefix}borders") <= 0:
            raise BoundaryError(
                f"{prefix}the borders run clockwise (bottom → right → top → left must go "
                f"counter-clockwise): reverse their order or swap left/right"
            )
    return borders


def borders_from_loop(
    points: Any,
    corners: Any,
    *,
    check_intersections: bool = True,
    where: str = "",
) -> Borders:
    """Split a closed loop of points at four corners ``(sw, se, ne, nw)``.

    The loop may run either way and may repeat its first point at the end;
    corner indices refer to the points as given.

    Examples
    --------
    >>> sq = [[0, 0], [1, 0], [2, 0], [2, 1], [1, 1], [0, 1]]
    >>> b = borders_from_loop(sq, [0, 2, 3, 5])
    >>> b.bottom.tolist(), b.left.tolist()
    ([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]], [[0.0, 0.0], [0.0, 1.0]])
    """
    prefix = f"{where}: " if where else ""
    p = validate_points(points, name=f"{prefix}boundary points", min_points=4)
    n_given = len(p)
    size = check_extent(p, name=f"{prefix}boundary points")
    closed_repeat = bool(np.hypot(*(p[0] - p[-1])) <= 1e-12 * size)
    if isinstance(corners, str):
        raise InvalidInputError(f"{prefix}corners must be 4 integer point indices, got {corners!r}")
    c = list(validate_indices(corners, name=f"{prefix}corners"))
    if len(c) != 4:
        raise InvalidInputError(f"{prefix}corners must be 4 point indices (sw, se, ne, nw), got {len(c)}")
    n = n_given - 1 if closed_repeat else n_given
    for k, ci in enumerate(c):
        if not (-n <= ci < n_given):
            raise InvalidInputError(
                f"{prefix}corner {('sw', 'se', 'ne', 'nw')[k]} index {ci} is out of range "
                f"(the loop has {n} points, indices 0…{n - 1})"
            )
    c = [ci % n for ci in c]
    if len(set(c)) != 4:
        raise InvalidInputError(f"{prefix}corner indices must be 4 different points, got {c}")
    loop = p[:n].copy()
    # duplicates (cyclic)
    seg = np.hypot(*(np.roll(loop, -1, axis=0) - loop).T)
    dup = np.flatnonzero(seg <= 1e-9 * size)
    if dup.size:
        drop = (dup + 1) % n
        bad = [k for k in drop if k in c]
        if bad:
            raise BoundaryError(
                f"{prefix}the corner on {_which(bad[:1])} duplicates its predecessor; pick the first of the two"
            )
        warnings.warn(
            f"{prefix}boundary: dropped {dup.size} duplicate consecutive point(s): {_which(drop)}",
            MeshcoreWarning,
            stacklevel=2,
        )
        keep = np.ones(n, dtype=bool)
        keep[drop] = False
        newidx = np.cumsum(keep) - 1
        c = [int(newidx[ci]) for ci in c]
        loop = loop[keep]
        n = len(loop)
    if check_encloses_area(loop, name=f"{prefix}boundary points") < 0:
        loop = loop[::-1].copy()
        c = [n - 1 - ci for ci in c]
    # the corners must be in cyclic CCW order sw → se → ne → nw
    rel = [(ci - c[0]) % n for ci in c]
    if not (rel[0] < rel[1] < rel[2] < rel[3]):
        raise BoundaryError(
            f"{prefix}corners {list(corners)} are not in cyclic order: walking the boundary "
            f"counter-clockwise they must come as sw, se, ne, nw"
        )

    def walk(a: int, b: int) -> np.ndarray:
        idx = [(a + k) % n for k in range((b - a) % n + 1)]
        return loop[idx].copy()

    bottom = walk(c[0], c[1])
    right = walk(c[1], c[2])
    top = walk(c[2], c[3])[::-1].copy()
    left = walk(c[3], c[0])[::-1].copy()
    return borders_from_polylines(bottom, right, top, left, check_intersections=check_intersections, where=where)
