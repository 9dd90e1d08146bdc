r"""A cut that passes close by a land tip, bent through the tip (session 35).

A block whose side runs round the tip of a land tongue while the cut opposite passes within a
few cells of that tip (a C-shaped piece pinched at the tip) cannot be split from the tip by
:mod:`.tipcuts`: either piece would be under three cells wide there.  Its grid fans out of the tip
across the whole block (held-out g180700 at 10 000 cells: a 24 × 24 junction block with 494 of
its 529 nodes beyond 3°, the cut 1.9 cells from the tongue's tip).  :func:`pinched` bends such a
cut through the tip instead: the cut between the piece and its neighbour runs straight to the tip
and on, so the piece is split in two at the tip (each with a corner there, the tongue's flank on
one side and the cut on the other) and the neighbour's side passes the tip (a T-junction).  Applied
in the layout choice's tip draw (:mod:`.tipcuts`), so the coarse grid judges it.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = [
    "NECK",
    "NECK_CELLS",
    "PINCH",
    "PINCH_CELLS",
    "WATER_SCALE",
    "Water",
    "necked_lines",
    "pinch_candidates",
    "pinched",
]

#: Bend cuts through land tips in the tip draw.  Session 35, with
#: :data:`~.choice.TIP_RATIO_SLACK` 0.01, against the layouts without (the layout choice scanned
#: on every development set, the changed lakes' grids run in full): at 10 000 cells 4 of 337 lake
#: layouts changed — g180700 91.5 → 96.2 % of nodes within 3° (edge pairs 94.1 → 96.2 %: every
#: hard target), g182833 94.2 → 95.2 %, g183013 99.81 → 99.96 % (by the slack alone), g181254
#: +0.01 — at 15 000 cells 1 of 341 (g181392 by the slack: 99.96 → 99.97 %, its largest interface
#: ratio 1.14 → 1.46), 1 of 71 generated shapes (+0.07 points); no fold, no hard target lost; held-out
#: set 22 (seen after the scan) the same grids at 10 000 and 15 000 cells (journal).
PINCH = True

#: A cut passing within this many cell sizes of a side's tip is bent through it.
PINCH_CELLS = 3.0


#: Bend cuts through a piece's *neck* too: where the land comes within :data:`NECK_CELLS` of a cut
#: across the piece at a shore point that is no tip by :func:`~.tipcuts._tip` (a blunt tongue whose
#: bend, read at half the piece's width, is under its 60°), away from the cut's ends (session 44:
#: held-out g182250, a chord across a bay grazing a tongue at 0.06 cells, one block wrapped round it).
NECK = True

#: A neck: the land this many cell sizes or less from a cut across the piece.
NECK_CELLS = 1.0


#: The water's turning at a point on the shore is read this many cell sizes along it.
WATER_SCALE = 3.0


class Water:
    """The water's turning (degrees, negative where the water's angle is reflex: a land tip) at
    the points of its shore, read at :data:`WATER_SCALE` cells (``poly``: the water polygon, ``h``:
    the cell size of the layout's geometry)."""

    def __init__(self, poly, h: float) -> None:
        import shapely
        from scipy.spatial import cKDTree

        from .corners import turning

        xy, tt = [], []
        for k, r in enumerate((poly.exterior, *poly.interiors)):
            ring = shapely.LinearRing(r)
            if ring.is_ccw != (k == 0):  # the water on the left of every ring
                ring = shapely.LinearRing(list(ring.coords)[::-1])
            pts = np.asarray(shapely.segmentize(ring, 0.25 * h).coords)[:-1]
            xy.append(pts)
            tt.append(turning(pts, WATER_SCALE * h))
        self.points = np.vstack(xy)
        self.turn = np.concatenate(tt)
        self.tree = cKDTree(self.points)
        self.tol = 1e-6 * math.sqrt(max(poly.area, 1e-300))

    def at(self, pts: np.ndarray) -> np.ndarray:
        """The water's turning at ``pts`` (nan at points not on its shore)."""
        d, k = self.tree.query(np.asarray(pts, float).reshape(-1, 2))
        return np.where(d <= self.tol, self.turn[k], np.nan)


def _key(p) -> tuple[float, float]:
    return (float(p[0]), float(p[1]))


def _shared_run(a: np.ndarray, b: np.ndarray) -> list[int] | None:
    """The indices in ``a`` of its one contiguous run of vertices shared with ``b`` (in ``a``'s
    order, both ends included, at least two), or None."""
    kb = {_key(p) for p in b}
    on = np.array([_key(p) in kb for p in a])
    if on.sum() < 2 or on.all():
        return None
    n = len(a)
    start = next(i for i in range(n) if on[i] and not on[i - 1])
    run = [start]
    while on[(run[-1] + 1) % n]:
        run.append((run[-1] + 1) % n)
    return run if len(run) == int(on.sum()) else None


def _sampled(p: np.ndarray, q: np.ndarray, step: float) -> np.ndarray:
    """The points strictly between ``p`` and ``q`` every ``step`` or less."""
    m = max(1, math.ceil(math.hypot(*(q - p)) / step))
    t = np.arange(1, m)[:, None] / m
    return (1 - t) * p + t * q


def _pinch_one(rings: list[np.ndarray], forced: list, i: int, sigma: float, min_width: float, water, uses):
    """The rings with piece ``i``'s far cut bent through its side's tip, or None."""
    import shapely

    from .split import _orient, _too_narrow, _valid
    from .tipcuts import _tip
    from .width import inscribed

    a = rings[i]
    if len(forced[i]):
        return None
    tip = _tip(a, sigma)
    if tip is not None:
        v = tip[0]
        if np.isnan(water.at(a[v])[0]):
            return None  # not on the shore
    else:
        bumps = np.flatnonzero(water.at(a) < 0.0) if NECK else np.empty(0, dtype=np.intp)
        if not len(bumps):
            return None  # no tip, no land bump to be a neck
    reach = PINCH_CELLS * sigma / 1.5
    best = None
    box = np.r_[a.min(axis=0) - reach, a.max(axis=0) + reach]
    runs = []
    for j, b in enumerate(rings):
        if j == i or len(forced[j]):
            continue
        if (b.max(axis=0) < box[:2]).any() or (b.min(axis=0) > box[2:]).any():
            continue
        run = _shared_run(a, b)
        if run is not None and len(run) >= 2:
            runs.append((j, run))
    if tip is not None:
        for j, run in runs:
            if v in run:
                continue
            d = shapely.LineString(a[run]).distance(shapely.Point(a[v]))
            if d <= reach and (best is None or d < best[0]):
                best = (d, j, run)
    else:
        best, v = _neck(a, bumps, runs, NECK_CELLS * sigma / 1.5, min_width)
    if best is None:
        return None
    T = a[v]
    _, j, run = best
    inner = [_key(a[k]) for k in run[1:-1]]
    if any(uses().get(p, 0) > 2 for p in inner):  # a third piece's corner on the cut (a T): leave it
        return None
    p0, p1 = a[run[0]], a[run[-1]]
    if min(math.hypot(*(p0 - T)), math.hypot(*(p1 - T))) < min_width:
        return None
    n = len(a)
    # a: ... p0 (run) p1 ... v ... ; a1 = v .. p0 then p0 → T, a2 = p1 .. v then T → p1
    idx_v_to_p0 = [(v + k) % n for k in range((run[0] - v) % n + 1)]
    idx_p1_to_v = [(run[-1] + k) % n for k in range((v - run[-1]) % n + 1)]
    s0, s1 = _sampled(p0, T, sigma), _sampled(T, p1, sigma)  # (each made once: both sides share its points)
    a1 = np.vstack([a[idx_v_to_p0], s0])
    a2 = np.vstack([a[idx_p1_to_v], s1])
    b = rings[j]
    rb = _shared_run(b, a)
    if rb is None or _key(b[rb[0]]) != _key(p1) or _key(b[rb[-1]]) != _key(p0):
        return None
    m = len(b)
    rest = [(rb[-1] + k) % m for k in range((rb[0] - rb[-1]) % m + 1)]  # p0 … p1 round b's other side
    b2 = np.vstack([b[rest], s1[::-1], T[None, :], s0[::-1]])
    new = [_orient(a1), _orient(a2), _orient(b2)]
    polys = [shapely.polygons(r) for r in new]
    if not all(_valid(r, p) for r, p in zip(new, polys, strict=True)):
        return None
    whole = shapely.union(shapely.polygons(a), shapely.polygons(b))
    if abs(sum(p.area for p in polys) - whole.area) > 1e-9 * whole.area:
        return None
    # a piece pinched at a tip is compact (a triangle-like bay, whose 2A/P is its inscribed
    # circle's radius): a disc ``min_width`` across must fit in it
    if any(
        _too_narrow(r, min_width, False, p) and inscribed(r, 0.02 * min_width) < min_width
        for r, p in zip(new, polys, strict=True)
    ):
        return None
    out = [r for k, r in enumerate(rings) if k not in (i, j)] + new
    fo = [f for k, f in enumerate(forced) if k not in (i, j)] + [(), (), ()]
    return out, fo


def _nearest_bump(pts: np.ndarray, line: np.ndarray, min_width: float) -> tuple[float, int]:
    """``(distance, index)`` of the point of ``pts`` (land bumps on the shore) nearest to the cut
    ``line`` among those at least ``min_width`` from both its ends; ``(inf, -1)`` if none is."""
    import shapely

    far = (np.hypot(*(pts - line[0]).T) >= min_width) & (np.hypot(*(pts - line[-1]).T) >= min_width)
    if not far.any():
        return math.inf, -1
    d = np.full(len(pts), np.inf)
    d[far] = shapely.distance(shapely.points(pts[far]), shapely.LineString(line))
    k = int(np.argmin(d))
    return float(d[k]), k


def _neck(a: np.ndarray, bumps: np.ndarray, runs: list, reach: float, min_width: float):
    """``((distance, j, run), vertex)`` of the vertex of ``a`` among ``bumps`` (its shore vertices
    where the water turns right: land bumps) nearest to a cut ``run`` shared with piece ``j``
    (``runs``), off the run, at most ``reach`` from it and at least ``min_width`` from both its
    ends: the piece's neck; ``(None, -1)`` if there is none."""
    best, v = None, -1
    for j, run in runs:
        off = bumps[~np.isin(bumps, run)]
        d, k = _nearest_bump(a[off], a[run], min_width)
        if d <= reach and (best is None or d < best[0]):
            best, v = (d, j, run), int(off[k])
    return best, v


def _counted(rings: list[np.ndarray]):
    """:func:`_uses` of ``rings`` as a function that counts them when first called (most pieces
    have no tip to bend a cut through: their count is not read)."""
    import functools

    return functools.cache(lambda: _uses(rings))


def _uses(rings: list[np.ndarray]) -> dict:
    """How many of ``rings`` have each vertex (keyed as :func:`_key`)."""
    uses: dict = {}
    for r in rings:
        for p in {_key(p) for p in r}:
            uses[p] = uses.get(p, 0) + 1
    return uses


def pinched(rings: list[np.ndarray], forced: list, water, sigma: float, min_width: float):
    """``rings`` and ``forced`` (the welded pieces of a layout and their forced corners) with every
    cut that passes within :data:`PINCH_CELLS` of the tip a piece's side runs round bent through
    that tip (see the module), where the pieces stay valid and at least ``min_width`` wide."""
    rings, forced = list(rings), list(forced)
    i, left = 0, 4 * len(rings)
    uses = _counted(rings)  # (counted again only when the rings change)
    while i < len(rings) and left > 0:
        left -= 1
        got = _pinch_one(rings, forced, i, sigma, min_width, water, uses)
        if got is None:
            i += 1
            continue
        rings, forced = got  # (the new pieces at the end: each looked at again)
        uses = _counted(rings)
    return rings, forced


def pinch_candidates(rings: list[np.ndarray], forced: list, water, sigma: float, min_width: float) -> bool:
    """Whether :func:`pinched` would bend any cut of these pieces."""
    uses = _counted(rings)
    return any(_pinch_one(rings, forced, i, sigma, min_width, water, uses) is not None for i in range(len(rings)))


def necked_lines(lines: list[np.ndarray], water, h: float, min_width: float) -> list[np.ndarray]:
    """``lines`` (the chords, each from shore to shore) with every one that comes within
    :data:`NECK_CELLS` of the land away from its ends (at least ``min_width`` from both, where the
    water turns right: a land bump) split in two at the land's nearest shore point (``water``: a
    :class:`Water` of the water polygon sampled every ``h`` or finer).  For layouts that do not
    :func:`pinched` their pieces (regular ones): the piece beyond such a chord would hold two
    channels joined by a neck under a cell wide."""
    out: list[np.ndarray] = []
    pts = water.points[water.turn < 0.0]
    for line in lines:
        d, k = _nearest_bump(pts, np.asarray(line, float), min_width) if len(pts) else (math.inf, -1)
        if d > NECK_CELLS * h:
            out.append(line)
            continue
        out += [np.vstack([line[0], pts[k]]), np.vstack([pts[k], line[-1]])]
    return out
