r"""The ratio of cell counts ``ni : nj`` at which a one-block grid's cells are square on median.

A Winslow grid is the inverse of a harmonic map: in the limit of many cells its lines are the
level lines of the harmonic functions ``ξ`` and ``η`` (``Δξ = Δη = 0``) whose boundary values
are the borders' node positions — ``ξ`` = 0 on the left border, 1 on the right, the arc-length
fraction along the bottom and top borders (their nodes' uniform distribution); ``η`` likewise
across.  The map onto the unit square is one-to-one (Radó–Kneser–Choquet), and a cell at a point
has sides ``1 / (ni |∇ξ|)`` along and ``1 / (nj |∇η|)`` across.  Its aspect is 1 where
``ni / nj = |∇η| / |∇ξ|``; the ratio returned is that of the median cell: the median of
``log(|∇η| / |∇ξ|)`` weighted by the cells each piece of the region holds
(``|∇ξ × ∇η|`` times its area).  On a rectangle ``a × b`` (``ξ = x / a``, ``η = y / b``) it is
``a / b``.

The ratio of the borders' mean lengths is that too on a rectangle, but not where a shore winds:
the bottom and top borders of a branched lake trace every arm in and out, and the grid's middle
lines, crossing each arm's mouth once, are shorter — with the border ratio its cells came out
three to four times longer across than along (rows too few to follow the arms: folds).

``ξ`` and ``η`` are solved with linear finite elements on shapely's constrained Delaunay
triangulation of the outline, refined by midpoint subdivision (boundary data exact: linear
along each shore edge).
"""

from __future__ import annotations

import math
import warnings
from typing import Any

import numpy as np

__all__ = ["cell_ratio"]

#: Subdivisions of the triangulation (each ×4 triangles), fewer where the triangles would pass
#: :data:`MAX_TRIANGLES`.  On 24 generated one-block shapes (``meshcore.testing``: channel
#: networks, lakes with arms, outer rings of lakes with islands, jagged Y junctions, a spiral, a
#: disc) the ratio changes by at most a few per cent from 2 to 3 subdivisions: below what
#: rounding the counts sees.  Cost at the cap: sparse solves of ~8 000 unknowns, ~20 ms.
LEVELS = 2
MAX_TRIANGLES = 16_000


def _subdivide(t: np.ndarray, p: np.ndarray, value: np.ndarray, shore: set[tuple[int, int]]):
    """Every triangle into four by its edge midpoints.  A midpoint of a shore edge takes the mean
    of its ends' boundary values (rows of ``value``; linear along the edge); interior midpoints
    are free (``nan``)."""
    e = np.sort(np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]]), axis=1)
    edges, inv = np.unique(e, axis=0, return_inverse=True)
    mid = len(p) + inv.reshape(3, -1).T
    on_shore = np.array([(int(a), int(b)) in shore for a, b in edges], dtype=bool)
    vm = np.where(on_shore[:, None], 0.5 * (value[edges[:, 0]] + value[edges[:, 1]]), np.nan)
    new_shore = set()
    for k in np.flatnonzero(on_shore):  # midpoints are numbered after every old node
        a, b, m = int(edges[k, 0]), int(edges[k, 1]), len(p) + int(k)
        new_shore |= {(a, m), (b, m)}
    a, b, c = t.T
    ab, bc, ca = mid.T
    t = np.vstack([np.c_[a, ab, ca], np.c_[ab, b, bc], np.c_[ca, bc, c], np.c_[ab, bc, ca]])
    p = np.vstack([p, 0.5 * (p[edges[:, 0]] + p[edges[:, 1]])])
    return t, p, np.vstack([value, vm]), new_shore


def _harmonic_gradients(t: np.ndarray, p: np.ndarray, value: np.ndarray):
    """Linear elements: the harmonic functions with the boundary values ``value`` (columns; ``nan``
    rows free), returned as their gradient on each triangle ``(m, 2, columns)`` and the triangles'
    areas."""
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla

    x, y = p[t, 0], p[t, 1]
    b = np.c_[y[:, 1] - y[:, 2], y[:, 2] - y[:, 0], y[:, 0] - y[:, 1]]
    c = np.c_[x[:, 2] - x[:, 1], x[:, 0] - x[:, 2], x[:, 1] - x[:, 0]]
    area2 = b[:, 0] * c[:, 1] - b[:, 1] * c[:, 0]  # > 0: counter-clockwise
    k = (b[:, :, None] * b[:, None, :] + c[:, :, None] * c[:, None, :]) / (2.0 * area2[:, None, None])
    n = len(p)
    a = sp.csr_matrix((k.ravel(), (np.repeat(t, 3, axis=1).ravel(), np.tile(t, (1, 3)).ravel())), shape=(n, n))
    fixed = ~np.isnan(value[:, 0])
    free = np.flatnonzero(~fixed)
    u = np.where(fixed[:, None], value, 0.0)
    if free.size:
        rhs = -(a[free][:, np.flatnonzero(fixed)] @ u[fixed])
        u[free] = spla.spsolve(a[free][:, free].tocsc(), rhs).reshape(len(free), -1)
    ut = u[t]  # (m, 3, columns)
    grad = np.stack([(b[:, :, None] * ut).sum(1), (c[:, :, None] * ut).sum(1)], axis=1) / area2[:, None, None]
    return grad, 0.5 * area2


#: Points of one border the ratio's triangulation takes (every k-th beyond): a shore of 10⁶ points
#: took 69 s in the constrained Delaunay triangulation (``meshcore import``), the ratio only guides
#: the cell counts.
MAX_BORDER_POINTS = 4000


def _thinned(line: np.ndarray) -> np.ndarray:
    """Every k-th point of a border (its two ends kept) so that at most about :data:`MAX_BORDER_POINTS` remain."""
    step = -(-len(line) // MAX_BORDER_POINTS)
    return line if step <= 1 else np.vstack([line[:-1:step], line[-1:]])


def cell_ratio(loop: Any, corners: Any) -> float:
    """``ni / nj`` at which the Winslow grid of the region inside ``loop`` with corners
    ``(sw, se, ne, nw)`` has cells square on median (see the module docstring).

    ``nan`` where it is not defined: corners that do not split the loop into four borders, a
    loop that crosses itself.

    >>> sq = [[0, 0], [1, 0], [2, 0], [3, 0], [3, 1], [2, 1], [1, 1], [0, 1]]
    >>> round(cell_ratio(sq, (0, 3, 4, 7)), 9)
    3.0
    """
    import shapely

    from .boundary import borders_from_loop
    from .errors import MeshcoreError

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            bd = borders_from_loop(loop, corners, check_intersections=False)
    except MeshcoreError:
        return math.nan

    def fraction(line: np.ndarray) -> np.ndarray:
        s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(line, axis=0).T))])
        return s / s[-1]

    bottom, right, top, left = (
        _thinned(np.asarray(b, dtype=np.float64)) for b in (bd.bottom, bd.right, bd.top, bd.left)
    )
    # the ring sw → se → ne → nw (counter-clockwise); columns ξ, η
    parts = [
        (bottom, np.c_[fraction(bottom), np.zeros(len(bottom))]),
        (right, np.c_[np.ones(len(right)), fraction(right)]),
        (top[::-1], np.c_[fraction(top)[::-1], np.ones(len(top))]),
        (left[::-1], np.c_[np.zeros(len(left)), fraction(left)[::-1]]),
    ]
    ring = np.vstack([pts[:-1] for pts, _ in parts])
    value = np.vstack([v[:-1] for _, v in parts])
    poly = shapely.Polygon(ring)
    if not poly.is_valid:
        return math.nan
    tri = shapely.get_coordinates(shapely.constrained_delaunay_triangles(poly).geoms).reshape(-1, 4, 2)[:, :3]
    index = {(float(x), float(y)): k for k, (x, y) in enumerate(ring)}
    if len(index) != len(ring) or len(tri) == 0:
        return math.nan
    try:
        t = np.array([[index[(float(x), float(y))] for x, y in tk] for tk in tri], dtype=np.int64)
    except KeyError:  # a vertex not on the ring: not a triangulation of these points
        return math.nan
    p = ring
    x, y = p[t, 0], p[t, 1]
    cw = (x[:, 1] - x[:, 0]) * (y[:, 2] - y[:, 0]) - (x[:, 2] - x[:, 0]) * (y[:, 1] - y[:, 0]) < 0
    t[cw] = t[cw][:, ::-1]
    n = len(ring)
    shore = {(min(k, (k + 1) % n), max(k, (k + 1) % n)) for k in range(n)}
    for _ in range(LEVELS):
        if 4 * len(t) > MAX_TRIANGLES:
            break
        t, p, value, shore = _subdivide(t, p, value, shore)
    grad, area = _harmonic_gradients(t, p, value)
    gxi, geta = np.hypot(*grad[:, :, 0].T), np.hypot(*grad[:, :, 1].T)
    cells = np.abs(grad[:, 0, 0] * grad[:, 1, 1] - grad[:, 1, 0] * grad[:, 0, 1]) * area
    ok = (gxi > 0) & (geta > 0) & (cells > 0)
    if not ok.any():
        return math.nan
    r = np.log(geta[ok] / gxi[ok])
    order = np.argsort(r)
    w = np.cumsum(cells[ok][order])
    return float(np.exp(r[order][np.searchsorted(w, 0.5 * w[-1])]))
