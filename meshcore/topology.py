r"""Single-block topologies with a cut: O-grids (periodic ξ) and C-grids (wake cut).

Grid convention (:mod:`meshcore.grid`): i along ξ, j along η, positive Jacobian
:math:`x_ξ y_η − x_η y_ξ > 0`.  For an **O-grid** between two closed curves the
ξ direction runs *clockwise* around the inner curve and η outwards (i around,
j out: clockwise gives :math:`x_ξ × x_η > 0`); the left and right borders are the
same radial cut, which the periodic solver treats as interior (the seam).

A **C-grid** wraps a body with a trailing edge: the bottom border runs along the
lower side of the wake cut towards the trailing edge, around the body
(lower surface, leading edge, upper surface) and back out along the upper side
of the cut, so bottom nodes ``k`` and ``ni − k`` (``k < wake``) coincide.  Pass
``ControlSpec(wake=wake)`` to solve the cut nodes as interior nodes (see
:mod:`meshcore.control`); otherwise the cut stays where it was put.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from ._validation import (
    check_allocation,
    check_grid_size,
    max_nodes,
    validate_count,
    validate_points,
    validate_positive,
)
from .algebraic import algebraic_grid
from .boundary import Borders, signed_area
from .distribution import distribute
from .errors import BoundaryError, InvalidInputError
from .grid import StructuredGrid

__all__ = ["CGrid", "cgrid", "closed_curve_nodes", "ogrid", "ogrid_borders", "radial_nodes"]


def _closed(points: Any, name: str) -> np.ndarray:
    p = validate_points(points, name=name, min_points=3)
    size = float(np.ptp(p, axis=0).max())
    if np.hypot(*(p[0] - p[-1])) <= 1e-12 * size:
        p = p[:-1]
    if len(p) < 3:
        raise InvalidInputError(f"{name}: a closed curve needs ≥ 3 distinct points")
    return p


def closed_curve_nodes(
    points: Any, n: int, *, start: Any = None, clockwise: bool = True, name: str = "curve"
) -> np.ndarray:
    """``n + 1`` nodes uniformly in arc length around a closed polyline.

    The walk starts at the vertex nearest ``start`` (default: the first point),
    runs clockwise (or counter-clockwise) and ends back at the start, so node
    ``n`` repeats node ``0``.
    """
    p = _closed(points, name)
    n = validate_count(n, name=f"{name} cells")
    check_allocation(n, max_nodes(), what=f"{name} cells", env="MESHCORE_MAX_NODES")
    if (signed_area(p) < 0) != clockwise:
        p = p[::-1]
    k0 = 0 if start is None else int(np.argmin(np.hypot(*(p - np.asarray(start, float)).T)))
    p = np.roll(p, -k0, axis=0)
    q = np.vstack([p, p[:1]])
    s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(q, axis=0).T))])
    t = np.linspace(0.0, s[-1], n + 1)
    out = np.column_stack([np.interp(t, s, q[:, 0]), np.interp(t, s, q[:, 1])])
    out[-1] = out[0]
    return out


def radial_nodes(a: Any, b: Any, n: int, *, first: float | None = None, last: float | None = None) -> np.ndarray:
    """``n + 1`` nodes on the segment a → b, clustered by ``first``/``last`` spacing."""
    a = np.asarray(a, float)
    b = np.asarray(b, float)
    L = float(np.hypot(*(b - a)))
    if L == 0:
        raise BoundaryError("the cut joins two coincident points")
    if first is None and last is None:
        u = distribute(n, "uniform")
    elif last is None:
        u = distribute(n, "tanh", first=first / L)
    elif first is None:
        u = 1.0 - distribute(n, "tanh", first=last / L)[::-1]
    else:
        u = distribute(n, "vinokur", first=first / L, last=last / L)
    return a[None] + u[:, None] * (b - a)[None]


def ogrid_borders(
    inner: Any,
    outer: Any,
    cells: tuple[int, int],
    *,
    first: float | None = None,
    last: float | None = None,
    start: Any = None,
) -> Borders:
    """Periodic borders of an O-grid between two closed curves.

    Parameters
    ----------
    inner, outer : (k, 2) array_like
        Closed polylines (any orientation, first point optionally repeated);
        ``inner`` must lie inside ``outer``.
    cells : (ni, nj)
        Cells around and across.
    first, last : float, optional
        Cell spacing of the cut at the inner / outer curve (clustering).
    start : (2,), optional
        Where the cut meets the inner curve (default: its first point); the
        cut goes straight to the nearest outer node.
    """
    ni, nj = (validate_count(c, name=nm) for c, nm in zip(cells, ("cells ξ", "cells η"), strict=True))
    check_grid_size(ni, nj, what="cells")
    bottom = closed_curve_nodes(inner, ni, start=start, name="inner curve")
    # the cut leaves the inner curve along the ray from its centroid (no twist)
    po = _closed(outer, "outer curve")
    c = _closed(inner, "inner curve").mean(axis=0)
    d = bottom[0] - c
    ang = np.arctan2(*(po - c).T[::-1]) - math.atan2(d[1], d[0])
    k = int(np.argmin(np.abs(np.angle(np.exp(1j * ang)))))
    top = closed_curve_nodes(po, ni, start=po[k], name="outer curve")
    cut = radial_nodes(bottom[0], top[0], nj, first=first, last=last)
    from shapely.geometry import Polygon

    if not Polygon(_closed(outer, "outer")).contains(Polygon(_closed(inner, "inner"))):
        raise BoundaryError("O-grid: the inner curve must lie inside the outer curve")
    return Borders(bottom=bottom, right=cut.copy(), top=top, left=cut, periodic=True)


def ogrid(
    inner: Any,
    outer: Any,
    cells: tuple[int, int],
    *,
    first: float | None = None,
    last: float | None = None,
    start: Any = None,
    initial: str = "tfi",
) -> StructuredGrid:
    """Algebraic start grid of an O-grid (solve it with :func:`meshcore.solve`)."""
    b = ogrid_borders(inner, outer, cells, first=first, last=last, start=start)
    return algebraic_grid(b, initial)


@dataclass(frozen=True, slots=True, eq=False)
class CGrid:
    """A C-grid start grid and what the solver needs to know about its cut.

    Attributes
    ----------
    grid : StructuredGrid
        Algebraic start grid (TFI).
    wake : int
        Cells of the wake cut on each side: bottom nodes ``k`` and
        ``ni − k`` coincide for ``k ≤ wake``.
    body : tuple[int, int]
        Node range ``[wake, ni − wake]`` of the body on the bottom border.
    """

    grid: StructuredGrid
    wake: int
    body: tuple[int, int]


def cgrid(
    body: Any,
    *,
    cells_wake: int,
    cells_normal: int,
    wake_length: float = 5.0,
    radius: float = 5.0,
    first: float | None = None,
    wake_first: float | None = None,
) -> CGrid:
    """C-grid start grid around an open-trailing-edge-free body.

    Parameters
    ----------
    body : (k, 2) array_like
        Body nodes from the trailing edge along the **lower** surface to the
        leading edge and back along the upper surface to the trailing edge
        (first = last = trailing edge, the clockwise walk); these become the
        body's bottom nodes as given.
    cells_wake : int
        Cells along the wake cut (each side).
    cells_normal : int
        Cells from the body/cut to the far field (η).
    wake_length, radius : float
        Wake cut length behind the trailing edge and far-field radius (model units).
    first : float, optional
        First cell height at the body (clusters the outflow borders).
    wake_first : float, optional
        First wake-cut spacing at the trailing edge (default: the body's last
        panel length).
    """
    b = validate_points(body, name="body", min_points=5)
    if np.hypot(*(b[0] - b[-1])) > 1e-12 * float(np.ptp(b, axis=0).max()):
        raise BoundaryError("C-grid body: first and last node must both be the trailing edge")
    if signed_area(b[:-1]) > 0:
        raise BoundaryError("C-grid body must run clockwise (trailing edge → lower → leading edge → upper)")
    nw = validate_count(cells_wake, name="cells_wake")
    nj = validate_count(cells_normal, name="cells_normal")
    validate_positive(wake_length, name="wake_length")
    validate_positive(radius, name="radius")
    te = b[0]
    if wake_first is None:
        wake_first = 0.5 * (np.hypot(*(b[1] - b[0])) + np.hypot(*(b[-1] - b[-2])))
    u = distribute(nw, "tanh", first=min(wake_first / wake_length, 0.5 / nw))
    wx = te[0] + wake_length * u  # TE → far
    lower = np.column_stack([wx[::-1], np.full(nw + 1, te[1])])
    upper = np.column_stack([wx, np.full(nw + 1, te[1])])
    bottom = np.vstack([lower[:-1], b[:-1], upper])
    nb = len(b) - 1
    ni = 2 * nw + nb
    # top: a semicircle around the front, uniform in angle, and straight lines
    # above/below the wake whose first spacing matches the arc's
    cx, cy = te[0], te[1]
    th = -0.5 * math.pi - math.pi * np.linspace(0.0, 1.0, nb + 1)
    arc = np.column_stack([cx + radius * np.cos(th), cy + radius * np.sin(th)])
    h = min(math.pi * radius / nb, 0.9 * wake_length / nw)
    line = radial_nodes((cx, 0.0), (cx + wake_length, 0.0), nw, first=h)[:, 0]
    top_low = np.column_stack([line[::-1], np.full(nw + 1, cy - radius)])
    top_up = np.column_stack([line, np.full(nw + 1, cy + radius)])
    top = np.vstack([top_low[:-1], arc[:-1], top_up])
    left = radial_nodes(bottom[0], top[0], nj, first=first)
    right = radial_nodes(bottom[-1], top[-1], nj, first=first)
    assert len(bottom) == len(top) == ni + 1
    borders = Borders(bottom=bottom, right=right, top=top, left=left)
    g = algebraic_grid(borders, "tfi")
    return CGrid(grid=g, wake=nw, body=(nw, nw + nb))


def body_spec(first: float, cgrid_or_none: CGrid | None = None, **kw: Any) -> Mapping[str, Any]:
    """Convenience: ``borders={"bottom": {...}}`` control entry for a body wall."""
    d = {"spacing": first, "angle": 90.0, **kw}
    if cgrid_or_none is not None:
        d["start"], d["stop"] = cgrid_or_none.body[0] + 1, cgrid_or_none.body[1]
    return {"bottom": d}
