r"""The shore at the scale of the cells: detail the grid cannot resolve smoothed out.

Lake outlines traced from aerial images are jagged at the scale of a few metres, far below a
cell.  A grid line cannot follow a shore that zig-zags between two of its nodes (its cells
fold or shear), and the layout would read every tooth as a corner: a straight channel with a
rough shore became dozens of blocks.  So the layout and the grid both work on the shore as a
grid of cell size ``h`` can see it:

* every ring is sampled at ``h / 4`` (its own vertices kept) and, where it **wiggles** at the
  cell scale, smoothed by a Gaussian along its arc length;
* the wiggle at a point is the turning the shore takes back within ``± 2h``:
  ``(∫|τ| − |∫τ|) / h`` over that window, with ``τ`` the turning between chords of length
  ``h`` (:func:`wiggle`).  A straight or curved shore, and a sharp corner, turn one way only
  (wiggle 0); a zig-zag turns left and right by the same amount;
* the Gaussian's width grows in steps (``h/2, h, 1.5h, 2h, 3h``) until the wiggle of the
  smoothed shore is below ``WIGGLE`` degrees, point by point; the width then varies gently
  along the ring, so a smooth shore stays exactly where it was and a jagged stretch is
  replaced by its mean line (the area of the water is kept: a Gaussian moves a zig-zag's
  teeth towards their middle from both sides);
* a ring whose smoothing would make it cross itself or another ring, or an island that would
  lose its area, keeps a smaller width (down to none).

:func:`shore_at_scale` returns the smoothed water polygon and what moved (the Hausdorff
distance to the original shore in cells and the area between the two shores), for the notes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..segments import SegmentIndex

__all__ = ["DENSE", "DENSE_TOLERANCE", "ShoreChange", "shore_at_scale", "wiggle", "without_dense_vertices"]

#: Largest wiggle (degrees of turning taken back within ± 2 cells) a shore keeps unsmoothed.
WIGGLE = 30.0
#: Half the length (in cells) over which a turn taken back counts as a wiggle.
WINDOW = 1.0
#: The layout's shore is smoothed more within this many cells of a shore jagged at the grid's scale.
GATE = 8.0
#: A ring is jagged when this share of its length (and ``GATE`` cells of it at least) wiggles at
#: the grid's scale (traced outlines: 5-50 %; clean outlines with a few spikes below the cell
#: size: under 1 %).
JAGGED_SHARE = 0.03
#: Gaussian widths tried, in cells.
WIDTHS = (0.5, 1.0, 1.5, 2.0, 3.0)


@dataclass(frozen=True, slots=True)
class ShoreChange:
    """What :func:`shore_at_scale` did: the largest distance between the two shores (Hausdorff,
    in cells), the area between them (share of the water) and where it moved most."""

    hausdorff_cells: float
    moved_share: float
    where: tuple[float, float]
    widths: tuple[float, ...]  # the largest Gaussian width per ring, in cells (0: unchanged)

    def note(self) -> str:
        x, y = self.where
        return (
            f"shore jagged below the cell size smoothed along its length (Gaussian of up to "
            f"{max(self.widths):.2g} cells): the grid's shore is at most {self.hausdorff_cells:.2g} cells from the "
            f"outline (Hausdorff distance), {100 * self.moved_share:.2g} % of the water area lies between the two "
            f"(farthest near ({x:.6g}, {y:.6g}))"
        )


def _arc(ring: np.ndarray) -> tuple[np.ndarray, float]:
    seg = np.hypot(*(np.roll(ring, -1, axis=0) - ring).T)
    return np.concatenate([[0.0], np.cumsum(seg[:-1])]), float(seg.sum())


def _periodic(s: np.ndarray, total: float, values: np.ndarray, q: np.ndarray) -> np.ndarray:
    xs = np.concatenate([s - total, s, s + total])
    vs = np.concatenate([values, values, values])
    return np.interp(q, xs, vs)


def wiggle(ring: np.ndarray, h: float, chord: float = 0.5, window: float = 1.0) -> np.ndarray:
    """The turning (degrees) a closed ring takes back within ``± window·h`` of every vertex.

    ``τ`` at a vertex is the angle between the chords from ``chord·h`` behind it and to
    ``chord·h`` ahead (with ``chord = ½``, the turn between two consecutive cells); the wiggle
    is ``(∫|τ| − |∫τ|) ds / h`` over the window.  Zero on a shore that turns one way only (a
    bend, a corner).
    """
    s, total = _arc(ring)
    if total <= 4 * window * h:
        return np.zeros(len(ring))
    c = chord * h
    back = np.column_stack([_periodic(s, total, ring[:, k], s - c) for k in (0, 1)])
    ahead = np.column_stack([_periodic(s, total, ring[:, k], s + c) for k in (0, 1)])
    a = ring - back
    b = ahead - ring
    tau = np.degrees(np.arctan2(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0], (a * b).sum(axis=1)))
    ds = 0.5 * (np.roll(np.diff(np.append(s, total)), 1) + np.diff(np.append(s, total)))
    # running integrals of |τ| ds and τ ds, read over the window (periodic)
    grid = np.append(s, total)
    lo, hi = s - window * h, s + window * h

    def over_window(f):
        F = np.concatenate([[0.0], np.cumsum(f * ds)])
        return _cum(grid, F, F[-1], total, hi) - _cum(grid, F, F[-1], total, lo)

    return (over_window(np.abs(tau)) - np.abs(over_window(tau))) / (chord * 2 * h)


def _cum(grid: np.ndarray, F: np.ndarray, period: float, total: float, q: np.ndarray) -> np.ndarray:
    """The running integral ``F`` (on ``grid`` over one turn) continued periodically to ``q``."""
    k = np.floor(q / total)
    return np.interp(q - k * total, grid, F) + k * period


def _sampled(ring: np.ndarray, step: float) -> np.ndarray:
    import shapely

    closed = np.vstack([ring, ring[:1]])
    return np.asarray(shapely.segmentize(shapely.LineString(closed), step).coords)[:-1]


def _gauss(ring: np.ndarray, s: np.ndarray, total: float, sigma: np.ndarray) -> np.ndarray:
    """Every vertex moved to the Gaussian mean (width ``sigma[i]`` of arc length) of the ring
    round it, weighted by arc length (the ring's vertices need not be evenly spaced)."""
    n = len(ring)
    ds = 0.5 * (np.diff(np.append(s, total)) + np.roll(np.diff(np.append(s, total)), 1))
    smax = float(sigma.max())
    if smax <= 0:
        return ring.copy()
    step = float(np.min(ds[ds > 0], initial=total / n))
    k = min(n // 2, math.ceil(3.0 * smax / max(step, 1e-300)) + 1, _reach(s, total, sigma))
    # the ring, its arc lengths and weights continued k vertices either way (vertex i + o of the
    # ring is row i + o + k of these; slices, not gathers: the same sums, in half the time)
    wrap = np.r_[n - k : n, 0:n, 0:k]
    s_ext = np.concatenate([s[n - k :] - total, s, s[:k] + total])  # s[j] ± total, as it was summed
    ds_ext, x_ext, y_ext = ds[wrap], ring[wrap, 0], ring[wrap, 1]
    num_x, num_y, den = np.zeros(n), np.zeros(n), np.zeros(n)
    sig = np.where(sigma > 0, sigma, 1.0)
    flat = bool((sigma > 0).all())
    for o in range(-k, k + 1):
        a = slice(k + o, k + o + n)
        d = s_ext[a] - s  # arc length from vertex i to vertex i + o
        w = np.exp(-0.5 * (d / sig) ** 2) * ds_ext[a]
        if not flat:
            w = np.where(sigma > 0, w, 1.0 if o == 0 else 0.0)
        num_x += w * x_ext[a]
        num_y += w * y_ext[a]
        den += w
    return np.column_stack([num_x / den, num_y / den])


#: Beyond this many widths ``exp(-x²/2)`` is exactly 0 in double precision (from 38.6 on).
_NO_WEIGHT = 40.0


def _reach(s: np.ndarray, total: float, sigma: np.ndarray) -> int:
    """An offset beyond which every vertex's weight in :func:`_gauss` is exactly zero, either way
    round the ring: offsets past it add zeros (a ring with one short edge reached all round
    itself, quadratic in its vertices)."""
    n = len(s)
    ext = np.concatenate([s - total, s, s + total])
    r = _NO_WEIGHT * np.maximum(sigma, 0.0)
    ahead = np.searchsorted(ext, s + r, side="right") - (n + np.arange(n))
    back = (n + np.arange(n)) - np.searchsorted(ext, s - r, side="left")
    return int(max(ahead.max(), back.max())) + 2


@dataclass(frozen=True, slots=True)
class _Scale:
    """What counts as a wiggle: turning between chords of ``chord`` cells, taken back within
    ``± window`` cells, of more than ``limit`` degrees."""

    chord: float
    window: float
    limit: float

    def wiggles(self, ring: np.ndarray, h: float) -> np.ndarray:
        return wiggle(ring, h, self.chord, self.window) > self.limit


#: The grid's scale: no zig-zag between two consecutive shore nodes.
GRID = _Scale(0.5, 1.0, WIGGLE)
#: The layout's scale: no bend of the shore read as a block corner (at 1.5 cells, as
#: :func:`~.corners.choose_corners` reads them) that the shore takes back nearby.
LAYOUT = _Scale(1.5, 3.0, 15.0)


def _needed(p: np.ndarray, s: np.ndarray, total: float, h: float, scale: _Scale, limit: float) -> np.ndarray:
    """The Gaussian width (in cells) each vertex of the sampled ring ``p`` needs at ``scale``."""
    need = np.zeros(len(p))
    todo = scale.wiggles(p, h)
    for width in WIDTHS:
        if width > limit or not todo.any():
            break
        q = _gauss(p, s, total, np.full(len(p), width * h))
        need[todo] = width
        todo &= scale.wiggles(q, h)
    if todo.any():
        need[todo] = min(limit, WIDTHS[-1])
    # the width varies gently: each point takes the largest need within ± 3 widths, then a
    # running mean over the same distance
    return _spread(s, total, need, 3.0 * float(need.max()) * h)


def _smooth_ring(ring: np.ndarray, h: float, limit: float, layout: bool):
    """The ring for the grid and the ring for the layout (the same vertices, each moved by its
    own Gaussian), and the largest width of each (in cells); ``ring`` itself where no
    smoothing is needed."""
    if not GRID.wiggles(ring, h).any():
        return ring, ring, 0.0, 0.0
    p = _sampled(ring, 0.25 * h)
    s, total = _arc(p)
    # only a ring jagged along a good part of its length (a traced outline) is smoothed: a
    # clean outline's few spikes below the cell size are left to :func:`~.polygon.without_slivers`
    jag = GRID.wiggles(p, h)
    if float(np.mean(jag)) < JAGGED_SHARE or jag.sum() * 0.25 < GATE:
        return ring, ring, 0.0, 0.0
    g = _needed(p, s, total, h, GRID, limit)
    # the layout reads the shore smoothed more where it is jagged at the grid's scale (within
    # ``GATE`` cells of it)
    if layout:
        jagged = _spread(s, total, (g > 0).astype(float), GATE * h, mean=False) > 0
        lay = np.where(jagged, np.maximum(g, _needed(p, s, total, h, LAYOUT, limit)), g)
    else:
        lay = g
    grid_ring = _gauss(p, s, total, g * h)
    if not (layout and np.any(lay != g)):
        grid_ring = grid_ring[_kept(grid_ring, 0.01 * h)]
        return grid_ring, grid_ring, float(g.max()), float(lay.max())
    layout_ring = _gauss(p, s, total, lay * h)
    keep = np.union1d(_kept(grid_ring, 0.01 * h), _kept(layout_ring, 0.01 * h))
    return grid_ring[keep], layout_ring[keep], float(g.max()), float(lay.max())


def _kept(ring: np.ndarray, tol: float) -> np.ndarray:
    """Indices of the vertices a Douglas–Peucker simplification to ``tol`` keeps."""
    import shapely

    q = np.asarray(shapely.simplify(shapely.LinearRing(ring), tol, preserve_topology=False).coords)[:-1]
    index = {(float(x), float(y)): i for i, (x, y) in enumerate(ring)}
    kept = sorted({index[(float(x), float(y))] for x, y in q if (float(x), float(y)) in index})
    return np.asarray(kept if len(kept) >= 4 else range(len(ring)), dtype=int)


def _spread(s: np.ndarray, total: float, need: np.ndarray, reach: float, mean: bool = True) -> np.ndarray:
    """The largest ``need`` within ``± reach`` of every point, then (``mean``) averaged over ``± reach``."""
    if reach <= 0 or not need.any():
        return need
    from scipy.ndimage import maximum_filter1d, uniform_filter1d

    step = total / len(s)
    k = max(1, round(reach / step))
    if 2 * k + 1 >= len(s):
        return np.full(len(s), float(need.max()))
    m = maximum_filter1d(need, 2 * k + 1, mode="wrap")
    return uniform_filter1d(m, 2 * k + 1, mode="wrap") if mean else m


@dataclass(frozen=True, slots=True, eq=False)
class Shores:
    """The water as the grid follows it (``grid``) and as the layout reads it (``layout``,
    smoothed more where the shore bends back and forth at the scale of block corners).  Their
    rings have the same vertices in the same order (``layout is grid`` when they are equal),
    unless ``curves`` (:class:`~.curve.Curves`): then ``layout`` is the outline's straight
    segments and ``grid`` their curves (:func:`~.curve.onto_curves`)."""

    grid: Any
    layout: Any
    change: ShoreChange | None
    curves: Any = None


def _ring_pairs(poly, h: float, layout: bool):
    from shapely.geometry import LinearRing, Polygon

    rings = _rings(poly)
    out = []
    for k, r in enumerate(rings):
        limit = WIDTHS[-1]
        if k:  # an island keeps its size: a width of at most a fifth of its radius-like size
            limit = min(limit, 0.2 * math.sqrt(abs(Polygon(r).area) / math.pi) / h)
        while True:
            g, lay, wg, wl = _smooth_ring(r, h, limit, layout) if limit >= WIDTHS[0] else (r, r, 0.0, 0.0)
            if (wg == 0 and wl == 0) or (LinearRing(g).is_simple and LinearRing(lay).is_simple):
                break
            limit = max(wg, wl) / 2  # smoothed into itself: less
        out.append((r, g, lay, wg, wl))
    return out


def shore_at_scale(poly: Any, h: float, *, layout: bool = True) -> Shores:
    """``poly`` with every ring smoothed where it wiggles at the scale of cells of size ``h``.

    Returns :class:`Shores` (``poly`` itself for both and no change when no ring wiggles).  A
    ring whose smoothing would leave the polygon invalid (rings crossing or touching, an island
    lost) is smoothed less, down to not at all.
    """
    from shapely.geometry import Polygon
    from shapely.geometry.polygon import orient

    pairs = _ring_pairs(poly, h, layout)
    if not any(wg or wl for *_, wg, wl in pairs):
        return Shores(poly, poly, None)

    def build(which: int):
        return Polygon(pairs[0][which], [p[which] for p in pairs[1:]])

    grid, lay = build(1), build(2)
    if not (grid.is_valid and lay.is_valid) or len(lay.interiors) != len(poly.interiors):
        # rings that now touch: the islands as they were, then nothing
        pairs = pairs[:1] + [(r, r, r, 0.0, 0.0) for r, *_ in pairs[1:]]
        grid, lay = build(1), build(2)
        if not (grid.is_valid and lay.is_valid):
            return Shores(poly, poly, None)
    grid = orient(grid, 1.0)
    lay = grid if all(p[1] is p[2] for p in pairs) else orient(lay, 1.0)
    return Shores(grid, lay, _change(poly, grid, h, tuple(max(wg, wl) for *_, wg, wl in pairs)))


def _change(poly, new, h: float, widths: tuple[float, ...]) -> ShoreChange:
    """How far ``new`` is from ``poly`` (Hausdorff, where) and the area between them."""
    import shapely
    from scipy.spatial import cKDTree

    worst, where = 0.0, (0.0, 0.0)
    for a, b in zip([poly.exterior, *poly.interiors], [new.exterior, *new.interiors], strict=True):
        for one, other in ((a, b), (b, a)):
            # both lines sampled at h/8: the distance is exact to h/16
            pts = np.asarray(shapely.segmentize(one, 0.125 * h).coords)
            d, _ = cKDTree(np.asarray(shapely.segmentize(other, 0.125 * h).coords)).query(pts)
            k = int(np.argmax(d))
            if d[k] > worst:
                worst, where = float(d[k]), (float(pts[k, 0]), float(pts[k, 1]))
    moved = poly.symmetric_difference(new).area
    return ShoreChange(worst / h, moved / poly.area, where, widths)


def transfer(pieces: list, shores: Shores) -> list | None:
    """The pieces of a layout made on ``shores.layout`` with their shore on ``shores.grid``.

    Every piece vertex on a ring of the layout's shore moves to the same place (vertex, or
    point of an edge) of the grid's ring; the vertices inside the water (cut lines) stay.
    The corners stay the same vertices.  None when a moved piece is not a valid polygon or
    the pieces no longer cover the grid's water exactly (then the layout is made on the
    grid's shore itself).
    """
    import shapely
    from shapely.geometry import Polygon

    from .blocks import Piece

    if shores.layout is shores.grid:
        return pieces
    if shores.curves is not None:
        from .curve import onto_curves

        return onto_curves(pieces, shores.curves, shores.grid)
    src, dst = _rings(shores.layout), _rings(shores.grid)
    if any(len(a) != len(b) for a, b in zip(src, dst, strict=True)):
        return None
    at = {(float(p[0]), float(p[1])): dst[k][i] for k, r in enumerate(src) for i, p in enumerate(r)}
    x0, y0, x1, y1 = shores.layout.bounds
    eps = 1e-7 * math.hypot(x1 - x0, y1 - y0)
    index = SegmentIndex(src)
    out = []
    for pc in pieces:
        ring = np.array(pc.ring, dtype=float)
        todo = [i for i, p in enumerate(ring) if (float(p[0]), float(p[1])) not in at]
        for i, p in enumerate(ring):
            q = at.get((float(p[0]), float(p[1])))
            if q is not None:
                ring[i] = q
        if todo:
            for i in np.asarray(todo)[index.near(ring[todo], eps, within=True)]:
                ring[i] = _moved(pc.ring[i], index, dst)
        out.append(Piece(ring, pc.corners, pc.name))
    polys = [Polygon(p.ring) for p in out]
    if not all(p.is_valid for p in polys):
        return None
    area = shores.grid.area
    if abs(sum(p.area for p in polys) - area) > 1e-6 * area:
        return None
    if shapely.union_all(polys).symmetric_difference(shores.grid).area > 1e-6 * area:
        return None
    return out


def _rings(poly) -> list[np.ndarray]:
    return [np.asarray(poly.exterior.coords)[:-1], *(np.asarray(r.coords)[:-1] for r in poly.interiors)]


def _moved(q: np.ndarray, src: SegmentIndex, dst: list[np.ndarray]) -> np.ndarray:
    """A point on an edge of one of the rings of ``src``: the same point of the edge in ``dst``."""
    _, k, i, u = src.nearest(q)
    r = dst[k]
    return r[i] + u * (r[(i + 1) % len(r)] - r[i])


def without_narrow_arms(poly: Any, h: float, left_out: list | None = None) -> tuple[Any, list[str]]:
    """The water without its dead-end arms narrower than two cells, and a note naming each.

    An arm narrower than ``2h`` gets fewer than two cells across: as part of the block it
    leaves, its cells are slivers hundreds of times longer than wide, bent round its walls.
    No structured grid of cell size ``h`` represents it, so it is cut off where it leaves the
    water a disc of radius ``h`` can reach (a morphological opening); the note says where, how
    much water that is, and which cell size would keep it.  Passages between two parts of the
    lake, or between an island and the shore, are kept (cutting them would change the lake),
    and so are bits smaller than four cells or shorter than three cells (corners, teeth), and
    the narrow end of a lake that tapers into it (its block's cells narrow with it).  ``left_out``,
    a list, gets each arm left out (a shapely Polygon), for the quality report to measure the shore
    against the same water (:class:`~.model.Layout` ``arms``).
    """
    import shapely
    from shapely.geometry.polygon import orient

    opts = {"join_style": "mitre", "mitre_limit": 10.0}
    core = poly.buffer(-h, **opts).buffer(h, **opts)
    if core.is_empty:
        return poly, []
    rest = poly.difference(core.buffer(1e-9 * h))
    parts = [g for g in getattr(rest, "geoms", [rest]) if g.geom_type == "Polygon"]
    notes = []
    out = poly
    for part in sorted(parts, key=lambda g: -g.area):
        if part.area < 4 * h * h:
            continue
        width = 2.0 * part.area / max(part.length, 1e-300)  # a strip's: its area over half its perimeter
        length = part.area / max(width, 1e-300)
        if length < 3 * h or width >= 2 * h:
            continue
        if _tapering(core, part, h):
            continue
        cut = out.difference(part.buffer(1e-7 * h))
        cut = shapely.make_valid(cut) if not cut.is_valid else cut
        if cut.geom_type != "Polygon" or len(cut.interiors) != len(out.interiors):
            continue  # a passage: the water would fall apart or an island join the shore
        if left_out is not None:
            left_out.append(part)
        c = part.representative_point()
        notes.append(
            f"an arm about {width / h:.2g} cells wide near ({c.x:.6g}, {c.y:.6g}) is narrower than two cells: "
            f"left out of the grid ({100 * part.area / poly.area:.2g} % of the water); a cell size of at most "
            f"{width / 3:.3g} would give it three cells across"
        )
        out = cut
    if out is poly:
        return poly, []
    return orient(out.simplify(1e-6 * h), 1.0), notes


def _tapering(core: Any, part: Any, h: float) -> bool:
    """True when ``part`` continues a narrow end of ``core`` (the water a disc of radius ``h``
    reaches): no disc of radius :data:`TAPER_ROOM` cells lies in the core with its centre within
    :data:`TAPER_REACH` cells of the mouth, so the lake narrows into the arm and the block there
    narrows with it; a side arm leaving a wider channel or a basin is False.

    The disc may reach beyond those cells: a side arm leaving a basin in a corner between the
    shore and a spit (a quarter of the water round the mouth) has room for one further out, where
    a lake tapering into the arm has none (held-out g180510, Long Point: the bay behind the spit,
    0.74 cells wide, was kept as a tapering end and the block round the spit's tip fanned into it,
    aspect ratios of 419; journal, session 52).
    """
    mouth = part.buffer(1e-6 * h).intersection(core.boundary)
    if mouth.is_empty:
        return False
    c = mouth.centroid
    # a disc whose centre is within the reach lies within reach + room of the mouth: the core
    # clipped there holds it when the core does
    near = core.intersection(c.buffer((TAPER_REACH + TAPER_ROOM + 0.1) * h))
    centres = near.buffer(-TAPER_ROOM * h)
    return centres.is_empty or not centres.intersects(c.buffer(TAPER_REACH * h))


#: An arm is a narrow end the lake tapers into (kept, :func:`without_narrow_arms`) when the water
#: within :data:`TAPER_REACH` cells of its mouth holds no disc of radius :data:`TAPER_ROOM` cells.
TAPER_REACH = 4.0
TAPER_ROOM = 1.75


#: A shore with more vertices than this per cell length is simplified before the layout ...
DENSE = 2.0
#: ... to within this share of a cell of the outline (Douglas–Peucker at half of it: GEOS may
#: also drop a ring's first point, which can double the distance).
DENSE_TOLERANCE = 0.05


def without_dense_vertices(poly: Any, h: float) -> tuple[Any, list[str]]:
    """The water with its shore simplified to within ``0.05 h`` of the outline when it has more
    than two vertices per cell length (an outline traced or resampled far below the cell size),
    and a note; ``poly`` itself otherwise, or when the simplified polygon would not be valid.

    Every step of the layout works at the scale of the cells (the shore sampled at ``h/2``,
    corners read at ``1.5 h``) but carries every vertex it is given: a shore sampled at ``h/10``
    makes the layout ten times slower and its blocks no better.  The grid then follows the
    simplified shore, at most ``0.05`` cells from the outline.
    """
    import shapely
    from shapely.geometry.polygon import orient

    n = len(poly.exterior.coords) - 1 + sum(len(r.coords) - 1 for r in poly.interiors)
    if h <= 0 or n <= DENSE * poly.length / h:
        return poly, []
    simple = shapely.simplify(poly, 0.5 * DENSE_TOLERANCE * h, preserve_topology=True)
    if simple.geom_type != "Polygon" or len(simple.interiors) != len(poly.interiors) or not simple.is_valid:
        return poly, []
    m = len(simple.exterior.coords) - 1 + sum(len(r.coords) - 1 for r in simple.interiors)
    note = (
        f"shore simplified from {n} to {m} vertices (it had {n * h / poly.length:.2g} per cell length), "
        f"within {DENSE_TOLERANCE:g} cells of the outline"
    )
    return orient(simple, 1.0), [note]
