"""Hit-testing and drawing helpers for the canvas (pure NumPy, no Qt; tested).

Everything here works in model coordinates; tolerances are given in model
units by the caller (the canvas converts a few screen pixels to model units).
"""

from __future__ import annotations

import math

import numpy as np

from meshcore.plot import line_alpha  # the level of detail of the canvas and of meshcore's figures

__all__ = [
    "border_polylines",
    "cell_at",
    "cell_centres",
    "compose_similarity",
    "corner_advice",
    "fit_image",
    "grid_lines",
    "image_bounds",
    "label_levels",
    "line_alpha",
    "marker_size",
    "nearest_point",
    "nearest_segment",
    "points_in_box",
    "similarity_from_pairs",
    "snap",
    "typical_cell_size",
    "typical_spacing",
    "union_bounds",
]


def nearest_point(points: np.ndarray, xy, tol: float) -> int | None:
    """Index of the point closest to ``xy`` if it is within ``tol``, else None."""
    if len(points) == 0:
        return None
    d = np.hypot(points[:, 0] - xy[0], points[:, 1] - xy[1])
    k = int(np.argmin(d))
    return k if d[k] <= tol else None


def nearest_segment(points: np.ndarray, xy, tol: float, *, closed: bool = True):
    """The segment ``(k, k+1)`` nearest to ``xy`` within ``tol``.

    Returns ``(k, t, foot)``: segment start index, the parameter ``t ∈ [0, 1]``
    of the foot of the perpendicular and the foot point, or None.  With
    ``closed`` the segment from the last point back to the first counts too.
    """
    n = len(points)
    if n < 2:
        return None
    a = points
    b = np.roll(points, -1, axis=0)
    if not closed:
        a, b = a[:-1], b[:-1]
    ab = b - a
    L2 = np.einsum("ij,ij->i", ab, ab)
    p = np.asarray(xy, float)
    with np.errstate(invalid="ignore", divide="ignore"):
        t = np.clip(np.einsum("ij,ij->i", p - a, ab) / np.where(L2 > 0, L2, 1.0), 0.0, 1.0)
    foot = a + t[:, None] * ab
    d = np.hypot(foot[:, 0] - p[0], foot[:, 1] - p[1])
    k = int(np.argmin(d))
    if d[k] > tol:
        return None
    return k, float(t[k]), (float(foot[k, 0]), float(foot[k, 1]))


def points_in_box(points: np.ndarray, x0: float, y0: float, x1: float, y1: float) -> np.ndarray:
    """Indices of points inside the axis-aligned box spanned by two corners."""
    if len(points) == 0:
        return np.zeros(0, dtype=int)
    xa, xb = sorted((x0, x1))
    ya, yb = sorted((y0, y1))
    m = (points[:, 0] >= xa) & (points[:, 0] <= xb) & (points[:, 1] >= ya) & (points[:, 1] <= yb)
    return np.flatnonzero(m)


def snap(xy, points: np.ndarray, tol: float, *, exclude=()) -> tuple[float, float]:
    """Snap ``xy`` onto the nearest point (other than ``exclude``) within ``tol``."""
    if len(points):
        d = np.hypot(points[:, 0] - xy[0], points[:, 1] - xy[1])
        for k in exclude:
            if 0 <= k < len(d):
                d[k] = np.inf
        k = int(np.argmin(d))
        if d[k] <= tol:
            return float(points[k, 0]), float(points[k, 1])
    return float(xy[0]), float(xy[1])


def corner_advice(points: np.ndarray, corners) -> list[str]:
    """What is wrong with corners on reflex vertices, and where to move them.

    One sentence per problem corner (from :func:`meshcore.corners.corner_problems`),
    with points numbered from 1 like the rows of a point file.
    """
    from meshcore.corners import corner_problems

    out = []
    for prob in corner_problems(np.asarray(points, float), corners):
        s = (
            f"corner {prob.corner.upper()} is on point {prob.index + 1}, a reflex vertex "
            f"(interior angle {prob.angle:.0f}° ≥ 180°): its corner cell cannot be convex; "
            f"move corner {prob.corner.upper()} to a convex vertex"
        )
        if prob.suggestion is not None:
            s += f", e.g. point {prob.suggestion + 1}"
        out.append(s)
    return out


def _signed_area(p: np.ndarray) -> float:
    x, y = p[:, 0], p[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


def grid_lines(x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """All grid lines as one NaN-separated polyline (for ``connect="finite"``).

    The i-lines (constant i, varying j) and then the j-lines, each followed by
    a NaN.  Returns flat ``(X, Y)`` of length ``ni1·(nj1+1) + nj1·(ni1+1)``.
    """
    ni1, nj1 = x.shape
    a = np.empty((ni1, nj1 + 1))
    a[:, :-1] = x
    a[:, -1] = np.nan
    b = np.empty((nj1, ni1 + 1))
    b[:, :-1] = x.T
    b[:, -1] = np.nan
    c = np.empty((ni1, nj1 + 1))
    c[:, :-1] = y
    c[:, -1] = np.nan
    d = np.empty((nj1, ni1 + 1))
    d[:, :-1] = y.T
    d[:, -1] = np.nan
    return np.concatenate([a.ravel(), b.ravel()]), np.concatenate([c.ravel(), d.ravel()])


def edge_pairs(shapes) -> np.ndarray:
    """Every cell edge of grids of node ``shapes`` once, as start/end indices of their nodes, all grids'
    nodes (each raveled, C order) in one array one after another; for ``connect="pairs"``.

    Per grid the edges along j (``(i, j)–(i, j+1)``) and then along i (``(i, j)–(i+1, j)``): indexing
    the nodes with it (one NumPy gather) is the segments of :func:`grid_segments`, ten times faster
    than building them grid by grid (Como, 16 blocks: 1.5 -> 0.15 ms per frame of a drag).
    """
    out, offset = [], 0
    for ni, nj in shapes:
        n = np.arange(ni * nj, dtype=np.intp).reshape(ni, nj) + offset
        out.append(np.stack([n[:, :-1], n[:, 1:]], axis=-1).ravel())
        out.append(np.stack([n[:-1, :], n[1:, :]], axis=-1).ravel())
        offset += ni * nj
    return np.concatenate(out) if out else np.zeros(0, dtype=np.intp)


def lattice(n: int, step: int, start: int = 0) -> np.ndarray:
    """Every ``step``-th index of ``start … start + n - 1``, the last one always.

    >>> lattice(7, 3).tolist(), lattice(4, 1, start=2).tolist()
    ([0, 3, 6], [2, 3, 4, 5])
    >>> lattice(8, 3).tolist()
    [0, 3, 6, 7]
    """
    idx = np.arange(0, n, max(1, int(step)))
    if idx[-1] != n - 1:
        idx = np.append(idx, n - 1)
    return idx + start


def drawn_lines(shapes, max_cells: int, windows: dict | None = None) -> list[tuple[int, np.ndarray, np.ndarray]]:
    """The grid lines a frame draws of grids of node ``shapes``: ``(grid, rows, columns)`` node indices.

    Every line when the grids have at most ``max_cells`` cells; more: every ``s``-th line of each grid
    (its borders always, through every node), ``s`` the smallest step that keeps them within
    ``max_cells`` (on screen such cells are a pixel or less: the lines drawn are the grid's shape).
    ``windows``: ``{grid: (i0, i1, j0, j1)}``, the node boxes in view, drawn besides at the step their
    cells allow (every line when they have at most ``max_cells``): zoomed in, every cell there.

    >>> [(k, len(i), len(j)) for k, i, j in drawn_lines([(11, 11)], 100)]
    [(0, 11, 11)]
    >>> [(k, len(i), len(j)) for k, i, j in drawn_lines([(101, 101)], 100)]
    [(0, 11, 11), (0, 1, 101), (0, 1, 101), (0, 101, 1), (0, 101, 1)]
    >>> [(k, int(i[0]), int(i[-1]), len(i)) for k, i, j in drawn_lines([(101, 101)], 100, {0: (20, 30, 40, 50)})][-1]
    (0, 20, 30, 11)
    """
    total = sum((ni - 1) * (nj - 1) for ni, nj in shapes)
    if total <= max_cells:
        return [(k, np.arange(ni), np.arange(nj)) for k, (ni, nj) in enumerate(shapes)]
    step = int(np.ceil(np.sqrt(total / max_cells)))
    out = [(k, lattice(ni, step), lattice(nj, step)) for k, (ni, nj) in enumerate(shapes)]
    for k, (ni, nj) in enumerate(shapes):  # the borders through every node (a shore is where one looks)
        rows, cols = np.arange(ni), np.arange(nj)
        out += [
            (k, np.array([0]), cols),
            (k, np.array([ni - 1]), cols),
            (k, rows, np.array([0])),
            (k, rows, np.array([nj - 1])),
        ]
    if windows:
        cells = sum((i1 - i0) * (j1 - j0) for i0, i1, j0, j1 in windows.values())
        fine = max(1, int(np.ceil(np.sqrt(cells / max_cells))))
        if fine < step:
            for k, (i0, i1, j0, j1) in sorted(windows.items()):
                out.append((k, lattice(i1 - i0 + 1, fine, i0), lattice(j1 - j0 + 1, fine, j0)))
    return out


def coarse_cells(x, y, values, step: int, *, low: bool = False) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The cells of a grid (nodes ``x``, ``y``; a value per cell) merged ``step`` × ``step`` for colouring:
    the nodes of every ``step``-th line (:func:`lattice`, the borders kept) and per merged cell the largest
    of its cells' values (``low``: the smallest): the worst of a quality measure stays seen; NaN where
    all are NaN.

    >>> v = np.arange(16.0).reshape(4, 4); v[1, 2] = np.nan
    >>> xc, yc, vc = coarse_cells(*np.meshgrid(np.arange(5.0), np.arange(5.0), indexing="ij"), v, 2)
    >>> xc.shape, vc.tolist()
    ((3, 3), [[5.0, 7.0], [13.0, 15.0]])
    >>> coarse_cells(xc, yc, vc, 2, low=True)[2].tolist()
    [[5.0]]
    """
    ni, nj = np.shape(x)
    ii, jj = lattice(ni, step), lattice(nj, step)
    sign = -1.0 if low else 1.0
    v = sign * np.asarray(values, float)
    v = np.where(np.isnan(v), -np.inf, v)
    v = np.maximum.reduceat(np.maximum.reduceat(v, ii[:-1], axis=0), jj[:-1], axis=1)
    v[np.isneginf(v)] = np.nan
    return np.asarray(x)[np.ix_(ii, jj)], np.asarray(y)[np.ix_(ii, jj)], sign * v


def in_view(grids, lines, rect) -> dict[int, tuple[int, int, int, int]]:
    """``{grid: (i0, i1, j0, j1)}``: the node boxes of ``grids`` in ``rect`` ``(x0, y0, x1, y1)``, found on
    the lines drawn (``lines`` of :func:`drawn_lines`, one coarse lattice per grid first) and widened
    by one of their steps; a grid wholly in view is left out (its coarse lines are all there is to see)."""
    x0, y0, x1, y1 = rect
    out = {}
    for k, ii, jj in lines[: len(grids)]:
        g = grids[k]
        x, y = np.asarray(g.x)[np.ix_(ii, jj)], np.asarray(g.y)[np.ix_(ii, jj)]
        inside = (x >= x0) & (x <= x1) & (y >= y0) & (y <= y1)
        if not inside.any() or inside.all():
            continue
        a, b = np.nonzero(inside.any(axis=1))[0][[0, -1]]
        c, d = np.nonzero(inside.any(axis=0))[0][[0, -1]]
        a, c = max(a - 1, 0), max(c - 1, 0)
        b, d = min(b + 1, len(ii) - 1), min(d + 1, len(jj) - 1)
        out[k] = (int(ii[a]), int(ii[b]), int(jj[c]), int(jj[d]))
    return out


def grid_segments(x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Every cell edge of a grid once, as start/end pairs (for ``connect="pairs"``).

    The edges along j (``(i, j)–(i, j+1)``) and then along i (``(i, j)–(i+1, j)``); returns
    flat ``(X, Y)`` of length ``2·(ni1·(nj1−1) + (ni1−1)·nj1)``.  Drawn as line segments,
    they paint faster than the polylines of :func:`grid_lines` and need no NaN checks.
    """
    x = np.asarray(x, float)
    y = np.asarray(y, float)
    pairs = edge_pairs([x.shape])
    return x.ravel()[pairs], y.ravel()[pairs]


def border_polylines(points: np.ndarray, corners) -> dict[str, np.ndarray]:
    """The four borders of a loop in the grid convention, for drawing.

    Like :func:`meshcore.borders_from_loop` (bottom/top run sw→se / nw→ne,
    left/right run sw→nw / se→ne, walking the loop counter-clockwise) but it
    never raises: it is used while the user edits.
    """
    p = np.asarray(points, float)
    n = len(p)
    step = 1 if _signed_area(p) >= 0 else -1

    def walk(a: int, b: int) -> np.ndarray:
        m = ((b - a) * step) % n
        return p[[(a + step * s) % n for s in range(m + 1)]]

    sw, se, ne, nw = (int(c) for c in corners)
    return {
        "bottom": walk(sw, se),
        "right": walk(se, ne),
        "top": walk(ne, nw)[::-1],
        "left": walk(nw, sw)[::-1],
    }


def similarity_from_pairs(uv0, xy0, uv1, xy1) -> tuple[float, float, float, float]:
    """Similarity map ``(a, b, tx, ty)`` taking image points uv0→xy0 and uv1→xy1.

    ``x = a·u − b·v + tx``, ``y = b·u + a·v + ty`` (rotation + uniform scale +
    translation), i.e. complex multiplication ``z = (a + ib)·w + t``.
    """
    w0, w1 = complex(*uv0), complex(*uv1)
    z0, z1 = complex(*xy0), complex(*xy1)
    if w1 == w0:
        raise ValueError("the two calibration points must be different pixels")
    m = (z1 - z0) / (w1 - w0)
    t = z0 - m * w0
    return (m.real, m.imag, t.real, t.imag)


def compose_similarity(transform, shown, true) -> tuple[float, float, float, float]:
    """The transform that moves two ``shown`` model points onto their ``true`` positions.

    ``transform`` (``(a, b, tx, ty)``, see :func:`similarity_from_pairs`) places
    an image in the model; the image currently shows two features at the
    model points ``shown[0]`` and ``shown[1]`` whose real coordinates are
    ``true[0]`` and ``true[1]``.  The result is the correction composed with
    ``transform``: the image drawn with it shows the features at ``true``.

    Raises
    ------
    ValueError
        When the two shown points coincide.
    """
    a, b, tx, ty = similarity_from_pairs(shown[0], true[0], shown[1], true[1])
    m_s, t_s = complex(a, b), complex(tx, ty)
    a0, b0, tx0, ty0 = transform
    m, t = m_s * complex(a0, b0), m_s * complex(tx0, ty0) + t_s
    return (m.real, m.imag, t.real, t.imag)


def fit_image(width: int, height: int, bounds) -> tuple[float, float, float, float]:
    """A similarity transform putting a ``width`` × ``height`` pixel image over ``bounds``.

    The image keeps its aspect ratio and covers the box ``(x0, y0, x1, y1)``
    with its lower-left corner at ``(x0, y0)``; without bounds it is drawn at
    one model unit per pixel from the origin.
    """
    if bounds is None:
        return (1.0, 0.0, 0.0, 0.0)
    x0, y0, x1, y1 = bounds
    s = max((x1 - x0) / max(width, 1), (y1 - y0) / max(height, 1))
    return (s if s > 0 else 1.0, 0.0, float(x0), float(y0))


def image_bounds(width: int, height: int, transform) -> tuple[float, float, float, float]:
    """The model-coordinate bounding box of a ``width`` × ``height`` image placed by ``transform``."""
    corners = [_apply(transform, u, v) for u, v in ((0, 0), (width, 0), (width, height), (0, height))]
    xs, ys = [z.real for z in corners], [z.imag for z in corners]
    return (min(xs), min(ys), max(xs), max(ys))


def _apply(transform, u: float, v: float) -> complex:
    a, b, tx, ty = transform
    return complex(a, b) * complex(u, v) + complex(tx, ty)


def union_bounds(*boxes) -> tuple[float, float, float, float] | None:
    """The box around every ``(x0, y0, x1, y1)`` given (Nones skipped; None if there is none)."""
    bb = [b for b in boxes if b is not None]
    if not bb:
        return None
    a = np.asarray(bb, float)
    return (float(a[:, 0].min()), float(a[:, 1].min()), float(a[:, 2].max()), float(a[:, 3].max()))


def typical_cell_size(grids, sample: int = 20_000) -> float:
    """The median length of the grid lines' segments (model units; 0 without grids).

    At most about ``sample`` segments of each grid are measured (a regular
    subset of the rows), so this stays cheap for large grids.
    """
    lengths = []
    for g in grids:
        x, y = np.asarray(g.x), np.asarray(g.y)
        step = max(1, int(x.size // max(sample, 1)))
        xs, ys = x[::step], y[::step]
        if xs.shape[1] > 1:
            lengths.append(np.hypot(np.diff(xs, axis=1), np.diff(ys, axis=1)).ravel())
        if x.shape[0] > 1:
            lengths.append(np.hypot(x[1::step] - x[:-1:step], y[1::step] - y[:-1:step]).ravel())
    if not lengths:
        return 0.0
    a = np.concatenate(lengths)
    a = a[np.isfinite(a)]
    return float(np.median(a)) if a.size else 0.0


def marker_size(spacing_pixels: float, full: float, *, least: float = 3.0) -> float:
    """Symbol size (pixels) of markers ``spacing_pixels`` apart on screen (level of detail).

    ``full`` when they are at least ``1.5 × full`` apart (a gap of half a symbol between them),
    else two thirds of the spacing, so neighbours never merge into one blob; 0 (hidden) when that
    is below ``least`` pixels: a zoomed-out shore of thousands of points is its line, not a
    black band.  A non-finite spacing (one marker) gives ``full``.
    """
    if not math.isfinite(spacing_pixels) or spacing_pixels >= 1.5 * full:
        return float(full)
    size = spacing_pixels / 1.5
    return float(size) if size >= least else 0.0


def typical_spacing(points: np.ndarray, *, along: bool = False) -> float:
    """The median distance from each point to its nearest other point (inf for fewer than two).

    ``along``: the points are a polyline's, in order: the median distance between consecutive
    distinct points instead (linear time: the canvas measures a dragged outline every frame).
    """
    p = np.asarray(points, float).reshape(-1, 2)
    if along:
        d = np.hypot(*np.diff(p, axis=0).T)
        d = d[d > 0]
        return float(np.median(d)) if len(d) else math.inf
    p = np.unique(p, axis=0)
    if len(p) < 2:
        return math.inf
    from scipy.spatial import cKDTree

    d, _ = cKDTree(p).query(p, k=2)
    return float(np.median(d[:, 1]))


def label_levels(at: np.ndarray, half: np.ndarray, fits: np.ndarray, order, taken=None) -> np.ndarray:
    """Level of detail of labels: which text each label shows, so that none overlaps another.

    ``at`` (n, 2) are the labels' centres, ``half`` (n, L, 2) the half width and height of each of
    a label's L texts (most detailed first, in model units: their screen size times the pixel size),
    ``fits`` (n, L) whether that text lies inside the label's own region (a block) on screen.
    Labels are placed in ``order`` (most important first); each shows its most detailed text that
    fits and overlaps no label already placed, nor a box of ``taken`` ((m, 4): x0, y0, x1, y1 of
    other labels drawn there).  Returns the text index per label, −1 for hidden.
    """
    at = np.asarray(at, float).reshape(-1, 2)
    half = np.asarray(half, float).reshape(len(at), -1, 2)
    fits = np.asarray(fits, bool).reshape(half.shape[:2])
    out = np.full(len(at), -1, dtype=int)
    placed = np.zeros((0, 4)) if taken is None else np.asarray(taken, float).reshape(-1, 4)  # the labels shown
    for k in order:
        for lev in range(half.shape[1]):
            if not fits[k, lev]:
                continue
            x0, y0 = at[k] - half[k, lev]
            x1, y1 = at[k] + half[k, lev]
            hit = (placed[:, 0] < x1) & (x0 < placed[:, 2]) & (placed[:, 1] < y1) & (y0 < placed[:, 3])
            if not hit.any():
                out[k] = lev
                placed = np.vstack([placed, [x0, y0, x1, y1]])
                break
    return out


def cell_centres(x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Centres (mean of the four nodes) of the cells of a grid, shape ``(ni, nj)``."""
    cx = 0.25 * (x[:-1, :-1] + x[1:, :-1] + x[1:, 1:] + x[:-1, 1:])
    cy = 0.25 * (y[:-1, :-1] + y[1:, :-1] + y[1:, 1:] + y[:-1, 1:])
    return cx, cy


def cell_at(x: np.ndarray, y: np.ndarray, px: float, py: float, centres=None) -> tuple[int, int] | None:
    """The cell ``(i, j)`` whose centre is nearest to ``(px, py)``, or None when the point is
    farther from that centre than the cell's diagonal (outside the grid).

    ``centres`` may pass the result of :func:`cell_centres` (cached by the caller).
    """
    cx, cy = centres if centres is not None else cell_centres(x, y)
    if cx.size == 0:
        return None
    d = np.hypot(cx - px, cy - py)
    i, j = np.unravel_index(int(np.argmin(d)), d.shape)
    size = math.hypot(x[i + 1, j + 1] - x[i, j], y[i + 1, j + 1] - y[i, j])
    if d[i, j] > size:
        return None
    return int(i), int(j)


def polyline_length(p: np.ndarray) -> float:
    if len(p) < 2:
        return 0.0
    d = np.diff(p, axis=0)
    return float(np.hypot(d[:, 0], d[:, 1]).sum())


def arrow_at_middle(p: np.ndarray) -> tuple[float, float, float] | None:
    """Position and angle (degrees, math convention) half-way along a polyline."""
    if len(p) < 2:
        return None
    d = np.diff(p, axis=0)
    s = np.concatenate([[0.0], np.cumsum(np.hypot(d[:, 0], d[:, 1]))])
    if s[-1] <= 0:
        return None
    h = 0.5 * s[-1]
    k = int(min(np.searchsorted(s, h) - 1, len(d) - 1))
    k = max(k, 0)
    t = (h - s[k]) / max(s[k + 1] - s[k], 1e-300)
    pt = p[k] + t * d[k]
    return float(pt[0]), float(pt[1]), math.degrees(math.atan2(d[k, 1], d[k, 0]))
