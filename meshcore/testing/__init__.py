"""Synthetic water bodies for tests and benchmarks: the hard cases real shorelines bring.

Every function returns a :class:`shapely.Polygon` (outer shore counter-clockwise, islands as
interior rings) in metres-like units, deterministic for a given ``seed``.  They exist so that
the automatic layout and the lake grids are tested on many shapes nobody tuned anything to:

* :func:`channel_network` — a random tree of channel segments buffered to a width (branched
  reservoirs, Y and T junctions, zig-zags), optionally with jagged shores;
* :func:`jagged_cells` — any of them with shores jagged at the scale of the cells (the
  outlines traced from aerial images);
* :func:`lake_with_islands` — a lobed lake with islands, some close to the shore;
* :func:`archipelago` — a round lake with many polygonal islands a few cells across, some in
  narrow passages between each other and the shore;
* :func:`island_clusters` — a round lake whose islands lie in clusters, gaps 0.3–5 cells
  between them and to the shore (the skerries of Finnish and Canadian lakes);
* :func:`small_islands` — islands from a third of a cell to five cells across, thin, bent,
  near the shore and each other;
* :func:`spiral` — a channel wound round more than once;
* :func:`headlands` — a basin whose shore has rounded headlands and bays of many sizes, some
  with islands off their tips (the shores of rift and drowned-valley lakes);
* :func:`dendritic` — a reservoir behind a dam: a main valley whose side valleys branch again,
  narrowing with each order down to arms under two cells wide, long thin ridges between them;
* :func:`narrow_arms` — a reservoir of many arms 3–6 cells wide meeting 3 or 4 at a junction
  at varied angles, the last ones tapering to wedges;
* :func:`meander`, :func:`meander_bars`, :func:`confluence`, :func:`estuary` — rivers: a
  sine-generated meandering reach (loops nearly cut off), the same with mid-channel bars, two
  meandering rivers joining, an estuary funnel with side creeks (:mod:`meshcore.testing.rivers`);
* :func:`resampled` — any of them with its shore sampled densely (10 000+ points) or coarsely
  (20 points): the same water as an outline from another source;
* :func:`y_junction`, :func:`straight_channel`, :func:`rectangle_with_hole` — the textbook cases.

>>> from meshcore.testing import channel_network
>>> p = channel_network(3, n_branches=5)
>>> p.is_valid and p.area > 0
True
"""

from __future__ import annotations

import math

import numpy as np

from ._shapes import _clean, _lobed_disc, _placed
from .archipelago import archipelago, island_clusters
from .narrow import narrow_arms
from .rivers import confluence, estuary, meander, meander_bars

__all__ = [
    "archipelago",
    "channel_network",
    "confluence",
    "dendritic",
    "estuary",
    "headlands",
    "island_clusters",
    "jagged",
    "jagged_cells",
    "lake_with_islands",
    "meander",
    "meander_bars",
    "narrow_arms",
    "rectangle_with_hole",
    "resampled",
    "small_islands",
    "spiral",
    "straight_channel",
    "y_junction",
]


def straight_channel(length: float = 10.0, width: float = 1.0):
    """A rectangle ``length × width`` (the simplest channel: one block)."""
    from shapely.geometry import box

    return _clean(box(0.0, 0.0, length, width))


def rectangle_with_hole(width: float = 6.0, height: float = 4.0, hole: float = 1.5):
    """A rectangle with a square island of side ``hole`` in its middle."""
    from shapely.geometry import Polygon, box

    outer = box(0.0, 0.0, width, height)
    cx, cy, h = width / 2, height / 2, hole / 2
    island = box(cx - h, cy - h, cx + h, cy + h)
    return _clean(Polygon(outer.exterior, [island.exterior]))


def y_junction(arm: float = 6.0, width: float = 1.0, angle0: float = 90.0, resolution: int = 8):
    """Three arms of equal length and width at 120° from the origin (symmetric under rotations).

    The outline is built from one arm rotated three times, so rotating the input by 120°
    maps the vertex set onto itself (up to rounding).
    """
    import shapely
    from shapely import affinity
    from shapely.geometry import LineString

    base = LineString([(0.0, 0.0), (arm, 0.0)]).buffer(width / 2, cap_style="flat", quad_segs=resolution)
    arms = [affinity.rotate(base, angle0 + 120.0 * k, origin=(0.0, 0.0)) for k in range(3)]
    return _clean(shapely.union_all(arms).simplify(1e-9 * arm))


def jagged(poly, amplitude: float, seed: int = 0, spacing: float | None = None, *, raw: bool = False):
    """Shores made rough: every ring densified to ``spacing`` and moved by ±``amplitude`` along its normal
    (``raw``: independent uniform offsets per point; otherwise each offset averaged with its
    neighbours' by weights ¼, ½, ¼)."""
    from shapely.geometry import Polygon

    rng = np.random.default_rng(seed)
    spacing = spacing or 2.0 * amplitude

    def rough(ring, sign):
        p = np.asarray(ring.coords)[:-1]
        seg = np.roll(p, -1, axis=0) - p
        n = np.maximum(1, np.ceil(np.hypot(*seg.T) / spacing).astype(int))
        pts = np.vstack([p[k] + np.outer(np.arange(n[k]) / n[k], seg[k]) for k in range(len(p))])
        t = np.roll(pts, -1, axis=0) - np.roll(pts, 1, axis=0)
        nrm = np.column_stack([t[:, 1], -t[:, 0]]) / np.maximum(np.hypot(*t.T), 1e-300)[:, None]
        noise = rng.uniform(-1.0, 1.0, len(pts))
        if not raw:
            noise = 0.5 * noise + 0.25 * (np.roll(noise, 1) + np.roll(noise, -1))
        return pts + sign * amplitude * noise[:, None] * nrm

    outer = rough(poly.exterior, 1.0)
    holes = [rough(h, 1.0) for h in poly.interiors]
    return _clean(Polygon(outer, holes))


def jagged_cells(poly, cells: float, seed: int = 0, *, target_cells: int = 10_000, spacing: float = 0.86):
    """A shore jagged at the scale of the grid, as traced from aerial images: every ring
    densified to ``spacing`` cells and each point moved along the normal by an independent
    uniform offset of at most ``± cells / 2`` cells (``cells`` from tooth to tooth), the cell
    size being that of ``target_cells`` cells over the water, ``sqrt(area / target_cells)``.

    >>> from meshcore.testing import jagged_cells, straight_channel
    >>> jagged_cells(straight_channel(50.0, 1.0), 1.4, seed=2).is_valid
    True
    """
    h = math.sqrt(poly.area / target_cells)
    return jagged(poly, 0.5 * cells * h, seed=seed, spacing=spacing * h, raw=True)


def channel_network(
    seed: int,
    *,
    n_branches: int = 6,
    width: tuple[float, float] = (0.6, 1.4),
    length: tuple[float, float] = (3.0, 8.0),
    bend: float = 35.0,
    roughness: float = 0.0,
):
    """A random tree of channels (a dendritic reservoir): buffered random segments.

    Each branch starts at a random point of the tree, leaves at a random angle and bends by
    up to ``bend`` degrees per segment; widths and lengths are drawn from the ranges.  The
    union may close loops around land (islands).  ``roughness`` > 0 makes the shores jagged
    with that amplitude (a fraction of the narrowest width).
    """
    import shapely
    from shapely.geometry import LineString

    rng = np.random.default_rng(seed)
    pieces = []
    nodes = [np.zeros(2)]
    heading = rng.uniform(0, 2 * math.pi)
    for _b in range(n_branches):
        start = nodes[rng.integers(len(nodes))]
        ang = heading if not pieces else rng.uniform(0, 2 * math.pi)
        L = rng.uniform(*length)
        w = rng.uniform(*width)
        n_seg = int(rng.integers(2, 5))
        pts = [start]
        for _s in range(n_seg):
            ang += math.radians(rng.uniform(-bend, bend))
            pts.append(pts[-1] + (L / n_seg) * np.array([math.cos(ang), math.sin(ang)]))
        nodes.extend(pts[1:])
        pieces.append(LineString(pts).buffer(w / 2, quad_segs=6))
    poly = _clean(shapely.union_all(pieces), min_hole_area=0.05 * width[0] ** 2)
    if roughness > 0:
        poly = jagged(poly, roughness * width[0], seed=seed, spacing=0.5 * width[0])
    return poly


def lake_with_islands(seed: int, *, radius: float = 10.0, lobes: int = 5, n_islands: int = 3, near_shore: bool = True):
    """A lobed lake (radius ``radius``) with ``n_islands`` islands; with ``near_shore`` one sits
    within a few percent of the radius from the shore."""
    from shapely.geometry import Polygon

    rng = np.random.default_rng(seed)
    outer = _lobed_disc(rng, radius, 240, range(2, 2 + lobes), 0.35)
    holes = []
    inner = outer.buffer(-0.12 * radius)
    tries = 0
    while len(holes) < n_islands and tries < 500:
        tries += 1
        c = rng.uniform(-radius, radius, 2)
        size = rng.uniform(0.05, 0.15) * radius
        if near_shore and not holes:
            # first island: close to the shore (a narrow passage)
            edge = outer.exterior.interpolate(rng.uniform(0, outer.exterior.length))
            cen = np.array(outer.centroid.coords[0])
            d = np.array(edge.coords[0]) - cen
            c = cen + d * (1 - (size + 0.04 * radius) / np.hypot(*d))
        k = int(rng.integers(5, 9))
        a = np.sort(rng.uniform(0, 2 * math.pi, k))
        rr = size * rng.uniform(0.6, 1.0, k)
        isl = Polygon(c + np.column_stack([rr * np.cos(a), rr * np.sin(a)]))
        if not isl.is_valid or not outer.buffer(-0.02 * radius).contains(isl):
            continue
        if any(isl.distance(Polygon(h)) < 0.05 * radius for h in holes):
            continue
        if not near_shore and not inner.contains(isl):
            continue
        holes.append(np.asarray(isl.exterior.coords))
    return _clean(Polygon(outer.exterior, holes))


def spiral(turns: float = 1.5, width: float = 1.0, gap: float = 1.5):
    """A channel of ``width`` wound ``turns`` times round its centre, walls ``gap`` apart."""
    from shapely.geometry import LineString

    pitch = width + gap
    t = np.linspace(0.0, turns * 2 * math.pi, int(120 * turns) + 2)
    r = pitch * (1.0 + t / (2 * math.pi))
    line = LineString(np.column_stack([r * np.cos(t), r * np.sin(t)]))
    return _clean(line.buffer(width / 2, cap_style="flat", quad_segs=4))


def round_lake(seed: int, *, radius: float = 10.0, kind: str = "blob", n_islands: int | None = None):
    """A round water body with 1–4 random islands, of one of four kinds.

    ``kind``: ``"disc"`` (a circle), ``"blob"`` (a smoothly lobed circle), ``"ring"`` (a disc
    with one large island: a ring of water of random width) or ``"arms"`` (a blob with two or
    three arms narrower than a tenth of the radius).  Islands are smooth random blobs of 4–25 %
    of the radius, some within a few percent of the radius from the shore or from each other.
    """
    from shapely.geometry import LineString, Point, Polygon

    rng = np.random.default_rng(seed)
    outer = _lobed_disc(rng, radius, 360, range(2, 6) if kind not in ("disc", "ring") else (), 0.25)
    if kind == "arms":
        arms = []
        for _ in range(int(rng.integers(2, 4))):
            a = rng.uniform(0, 2 * math.pi)
            d = np.array([math.cos(a), math.sin(a)])
            bend = np.array([-d[1], d[0]]) * rng.uniform(-0.3, 0.3) * radius
            line = LineString([0.0 * d, 1.3 * radius * d + 0.5 * bend, 1.7 * radius * d + bend])  # from the centre
            arms.append(line.buffer(rng.uniform(0.04, 0.1) * radius, quad_segs=4))
        import shapely

        outer = shapely.union_all([outer, *arms])
        outer = Polygon(outer.exterior)
    holes: list[Polygon] = []
    if kind == "ring":
        inner_r = rng.uniform(0.3, 0.7) * radius
        off = rng.uniform(-1, 1, 2) * 0.15 * (radius - inner_r)
        holes.append(Point(*off).buffer(inner_r, quad_segs=32))
        n_islands = 1 if n_islands is None else n_islands
    want = int(rng.integers(1, 5)) if n_islands is None else n_islands
    body = outer.buffer(-0.03 * radius)
    tries = 0
    while len(holes) < want and tries < 1000:
        tries += 1
        size = rng.uniform(0.04, 0.25) * radius
        c = rng.uniform(-radius, radius, 2)
        ang = np.linspace(0, 2 * math.pi, 48, endpoint=False)
        rr = np.ones_like(ang)
        for k in range(2, 4):
            rr += rng.uniform(0.0, 0.25) * np.cos(k * ang + rng.uniform(0, 2 * math.pi))
        rr *= size / rr.max()
        isl = Polygon(c + np.column_stack([rr * np.cos(ang), rr * np.sin(ang)]))
        if not isl.is_valid or not body.contains(isl):
            continue
        if any(isl.distance(h) < 0.03 * radius for h in holes):
            continue
        holes.append(isl)
    return _clean(Polygon(outer.exterior, [h.exterior for h in holes]))


def small_islands(
    seed: int,
    *,
    cell_size: float = 0.25,
    n_islands: int = 6,
    widths: tuple[float, float] = (0.3, 5.0),
    radius: float = 10.0,
    peninsulas: int = 0,
):
    """A lobed lake with ``n_islands`` small islands ``widths`` cells across (log-uniform).

    The islands are of three kinds, chosen at random: ``blob`` (an ellipse up to twice as long
    as wide), ``needle`` (a capsule 3–10 times as long as wide) and ``hairpin`` (a spike
    tapering from its width to a sharp tip over 3–8 widths).  A third of them lie 0.3–3 cells
    from the shore, a third as far from the island before them, the rest anywhere.  For the
    question what a grid of cell size ``cell_size`` does with an island it can or cannot go
    round (mesh with ``cell_size=cell_size``).  ``peninsulas``: as many spikes of land of the
    same widths reaching 3–10 widths into the water from the shore (the same question for the
    outer shore), made before the islands.
    """
    from shapely import affinity
    from shapely.geometry import LineString, Point, Polygon

    rng = np.random.default_rng(seed)
    h = float(cell_size)
    outer = _lobed_disc(rng, radius, 240, range(2, 6), 0.25)
    for _ in range(peninsulas):
        w = h * math.exp(rng.uniform(math.log(widths[0]), math.log(widths[1])))
        p = np.asarray(outer.exterior.interpolate(rng.uniform(0, outer.exterior.length)).coords[0])
        inward = -p / max(np.hypot(*p), 1e-9)
        turn = rng.uniform(-0.5, 0.5)  # not quite towards the centre
        d = np.array(
            [
                inward[0] * math.cos(turn) - inward[1] * math.sin(turn),
                inward[0] * math.sin(turn) + inward[1] * math.cos(turn),
            ]
        )
        length = w * rng.uniform(3.0, 10.0)
        spike = LineString([p - 2.0 * w * d, p + length * d]).buffer(0.5 * w, quad_segs=4)
        cut = outer.difference(spike)
        parts = [g for g in getattr(cut, "geoms", [cut]) if g.geom_type == "Polygon"]
        outer = Polygon(max(parts, key=lambda g: g.area).exterior)
    body = outer.buffer(-0.3 * h)
    holes: list[Polygon] = []
    tries = 0
    while len(holes) < n_islands and tries < 2000:
        tries += 1
        w = h * math.exp(rng.uniform(math.log(widths[0]), math.log(widths[1])))
        kind = ("blob", "needle", "hairpin")[int(rng.integers(0, 3))]
        if kind == "blob":
            isl = affinity.scale(Point(0, 0).buffer(0.5 * w, quad_segs=8), rng.uniform(1.0, 2.0), 1.0)
        elif kind == "needle":
            length = w * rng.uniform(3.0, 10.0)
            isl = LineString([(-0.5 * length, 0), (0.5 * length, 0)]).buffer(0.5 * w, quad_segs=4)
        else:
            length = w * rng.uniform(3.0, 8.0)
            bow = rng.uniform(-0.3, 0.3) * length  # a bent spike
            xs = np.linspace(0.0, length, 12)
            half = 0.5 * w * (1.0 - xs / length) ** 0.7
            mid = bow * (xs / length) ** 2
            pts = np.vstack([np.column_stack([xs, mid + half]), np.column_stack([xs[::-1], (mid - half)[::-1]])[1:]])
            isl = Point(0, 0).buffer(0.5 * w, quad_segs=4).union(Polygon(pts))
        isl = _placed(rng, isl, outer, body, holes, radius, h=h, gaps=(0.3, 3.0), shore=2.0 * w, near=(1.0, w))
        if isl is not None and not any(isl.distance(o) < 0.3 * h for o in holes):
            holes.append(isl)
    return _clean(Polygon(outer.exterior, [g.exterior for g in holes]))


def headlands(seed: int, *, radius: float = 10.0, n: int = 8, islands: int = 3):
    """A round basin whose shore has ``n`` rounded headlands and bays: ridges of land with round
    tips, 4–15 % of the radius wide, reaching 15–45 % of the radius into the water from random
    places of the shore, and as many round bays of 10–30 % of the radius pushed out of it; up to
    ``islands`` round islands off the headlands' tips (4–12 % of the radius, a few percent of it
    from the tip).  The water then turns 180° round every tip: cut lines there must not fan.
    """
    import shapely
    from shapely.geometry import LineString, Point, Polygon

    rng = np.random.default_rng(seed)
    water = _lobed_disc(rng, radius, 360, range(2, 5), 0.15)
    for _ in range(n):  # bays first: pushed out of the basin
        a = rng.uniform(0, 2 * math.pi)
        rb = rng.uniform(0.1, 0.3) * radius
        p = np.asarray(
            water.exterior.interpolate(
                water.exterior.project(Point(radius * math.cos(a), radius * math.sin(a)))
            ).coords[0]
        )
        water = shapely.union_all(
            [water, Point(*(p * (1 + 0.5 * rb / max(np.hypot(*p), 1e-9)))).buffer(rb, quad_segs=16)]
        )
        water = Polygon(max(getattr(water, "geoms", [water]), key=lambda g: g.area).exterior)
    tips = []
    for _ in range(n):  # headlands: ridges of land with round tips
        w = rng.uniform(0.04, 0.15) * radius
        p = np.asarray(water.exterior.interpolate(rng.uniform(0, water.exterior.length)).coords[0])
        inward = -p / max(np.hypot(*p), 1e-9)
        turn = rng.uniform(-0.7, 0.7)
        d = np.array(
            [
                inward[0] * math.cos(turn) - inward[1] * math.sin(turn),
                inward[0] * math.sin(turn) + inward[1] * math.cos(turn),
            ]
        )
        length = rng.uniform(0.15, 0.45) * radius
        ridge = LineString([p - 2.0 * w * d, p + length * d]).buffer(0.5 * w, quad_segs=16)
        cut = water.difference(ridge)
        parts = [g for g in getattr(cut, "geoms", [cut]) if g.geom_type == "Polygon"]
        water = Polygon(max(parts, key=lambda g: g.area).exterior)
        tips.append((p + length * d, d, w))
    body = water.buffer(-0.02 * radius)
    holes: list[Polygon] = []
    for tip, d, w in tips[: 2 * islands]:
        if len(holes) >= islands:
            break
        size = rng.uniform(0.04, 0.12) * radius
        c = tip + d * (0.5 * w + rng.uniform(0.02, 0.08) * radius + size)
        isl = Point(*c).buffer(size, quad_segs=12)
        if body.contains(isl) and all(isl.distance(o) > 0.03 * radius for o in holes):
            holes.append(isl)
    return _clean(Polygon(water.exterior, [g.exterior for g in holes]))


def dendritic(seed: int, *, orders: int = 4, width: float = 2.0, length: float = 24.0, narrow: float = 0.06):
    """A dendritic reservoir: a main valley ``width`` wide and ``length`` long whose side valleys
    (2–4 per valley, leaving at 30–80° from either bank) branch again for ``orders`` orders, each
    order 0.35–0.6 times as wide and 0.3–0.5 times as long as its parent, every valley tapering
    to 60 % of its width at its head and meandering a little.  With the defaults the last order
    is 0.09–0.43 wide, and 60 % of that at its head (``narrow``: a floor): at 15 000 cells
    (h ≈ 0.07) many arms are under two cells wide; the land between neighbouring side valleys
    is a long thin ridge.
    """
    import shapely
    from shapely.geometry import LineString

    rng = np.random.default_rng(seed)
    pieces = []

    def valley(start: np.ndarray, heading: float, w: float, L: float, order: int) -> None:
        n_seg = 6
        pts = [start]
        ang = heading
        for _ in range(n_seg):
            ang += math.radians(rng.uniform(-15.0, 15.0))
            pts.append(pts[-1] + (L / n_seg) * np.array([math.cos(ang), math.sin(ang)]))
        line = LineString(pts)
        # a tapering valley: buffered pieces of decreasing width
        for k in range(n_seg):
            wk = max(narrow, w * (1.0 - 0.4 * (k + 0.5) / n_seg))
            pieces.append(LineString(pts[k : k + 2]).buffer(0.5 * wk, quad_segs=6))
        if order >= orders:
            return
        for _ in range(int(rng.integers(2, 5))):
            f = rng.uniform(0.15, 0.85)
            q = np.asarray(line.interpolate(f, normalized=True).coords[0])
            k = min(int(f * n_seg), n_seg - 1)
            seg = np.subtract(pts[k + 1], pts[k])
            base = math.atan2(seg[1], seg[0])
            side = 1.0 if rng.uniform() < 0.5 else -1.0
            valley(
                q,
                base + side * math.radians(rng.uniform(30.0, 80.0)),
                w * rng.uniform(0.35, 0.6),
                L * rng.uniform(0.3, 0.5),
                order + 1,
            )

    valley(np.zeros(2), rng.uniform(0, 2 * math.pi), width, length, 1)
    water = shapely.union_all(pieces).buffer(0.02 * narrow, quad_segs=2).buffer(-0.02 * narrow, quad_segs=2)
    return _clean(water, min_hole_area=(2 * width) ** 2)


def resampled(poly, points: int | None = None, *, spacing: float | None = None):
    """``poly`` with every ring sampled anew: ``points`` points on the outer shore at equal arc
    length (islands in proportion to their length, at least 8 each), or one every ``spacing``.
    Dense (10 000+ points: an outline from a survey) or coarse (20 points: a sketch); coarse
    sampling cuts corners, so the water changes a little, as it does between two sources.
    """
    from shapely.geometry import Polygon

    L0 = poly.exterior.length
    step = spacing if spacing is not None else L0 / float(points or 1000)

    def ring(r, least: int) -> np.ndarray:
        n = max(least, round(r.length / step))
        return np.asarray([r.interpolate(f, normalized=True).coords[0] for f in np.arange(n) / n])

    outer = ring(poly.exterior, 4)
    holes = [ring(h, 8) for h in poly.interiors]
    return _clean(Polygon(outer, [h for h in holes if Polygon(h).is_valid]))
