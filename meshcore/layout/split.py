r"""Splitting a region that is not four-sided: cuts from reflex corners, or a star.

A region whose boundary has more than four sharp turns (a junction of arms, an L, a bay)
cannot be one block.  Two kinds of split are tried and the cheapest result is kept (cost:
:func:`~.corners.choose_corners`, summed over the pieces):

* **motorcycle cuts** — from a reflex corner (the shore turns right, into the water) a straight
  cut continues one of the two shore lines that meet there, until it meets the other side of
  the region; where it lands near another reflex corner it ends there.  This is how a T
  junction becomes a through channel plus a side arm, an L two rectangles, an X a cross;
* **a star** — from one interior point (the skeleton's junction) a straight spoke to each of
  three to five reflex corners.  This is the symmetric Y: three blocks meeting at a point of
  valence three.

Splits are applied greedily (the best cut first, then the pieces again) while they lower the
cost; a piece narrower than ``min_width`` is never made.
"""

from __future__ import annotations

import hashlib
import itertools
import math

import numpy as np

from .corners import SHARP, _edges, choose_corners, turning
from .width import THIN_CUT
from .width import too_narrow as _too_narrow
from .width import width as _width

__all__ = ["best_split", "corners_of", "region_cost"]


def region_cost(ring: np.ndarray, sigma: float, forced=()) -> float:
    """The corner cost of ``ring`` (``forced``: points that must be corners).

    Remembered for the last :data:`_COSTS_KEPT` rings (:func:`corners_of`): a split's pieces are
    costed among its options and again as the regions split on, and the same cut comes back among
    the options of the pieces of other cuts (a sixth of the calls on held-out lakes)."""
    return corners_of(ring, sigma, forced_indices(ring, forced))[1]


def corners_of(ring: np.ndarray, sigma: float, forced=()) -> tuple:
    """:func:`~.corners.choose_corners` ``(corners, cost)`` of ``ring`` with the vertex indices
    ``forced``, remembered for the last :data:`_COSTS_KEPT` rings (keyed by a 128-bit digest of
    the ring, ``sigma`` and ``forced``): the splits cost the same rings again and again, and
    :func:`~.fans.fans`, :func:`~.fans.wraps` and the final corners read the rings they costed."""
    fi = tuple(int(i) for i in forced)
    data = np.ascontiguousarray(ring, dtype=float).tobytes()
    key = (hashlib.blake2b(data, digest_size=16).digest(), len(data), float(sigma), fi)
    got = _costs.get(key)
    if got is None:
        got = choose_corners(ring, sigma, forced=list(fi))
        if len(_costs) >= _COSTS_KEPT:
            _costs.clear()
        _costs[key] = got
    return got


#: How many rings' corners and costs :func:`corners_of` remembers (then it starts again; a layout
#: of 75 blocks costs ~2 000 rings at each scale; keyed by a 128-bit digest of the ring, not the ring).
_COSTS_KEPT = 20_000
_costs: dict[tuple, tuple] = {}


def forced_indices(ring: np.ndarray, points) -> list[int]:
    """Indices of the ring vertices equal to ``points``."""
    if not len(points):
        return []
    keys = {(float(p[0]), float(p[1])) for p in points}
    return [i for i, q in enumerate(ring) if (float(q[0]), float(q[1])) in keys]


def _ray_to_boundary(ring: np.ndarray, v: int, d: np.ndarray, e: np.ndarray | None = None):
    """First crossing of the ray from vertex ``v`` along ``d`` with the ring's other edges
    (``e``: the ring's edges, :func:`~.corners._edges`, if made already)."""
    n = len(ring)
    c = ring[v]
    a = ring
    e = _edges(ring) if e is None else e  # np.roll(ring, -1, axis=0) - ring
    den = d[0] * e[:, 1] - d[1] * e[:, 0]
    w = a - c
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (w[:, 0] * e[:, 1] - w[:, 1] * e[:, 0]) / den
        u = (w[:, 0] * d[1] - w[:, 1] * d[0]) / den
    ok = (np.abs(den) > 1e-300) & (t > 1e-9) & (u >= 0) & (u <= 1)
    ok[v] = False
    ok[(v - 1) % n] = False
    if not ok.any():
        return None
    t = np.where(ok, t, np.inf)
    k = int(np.argmin(t))
    return k, float(u[k]), c + t[k] * d


def _split_ring(ring: np.ndarray, i: int, k: int, u: float, q: np.ndarray):
    """Split a ring by the segment from vertex ``i`` to point ``q`` on edge ``k`` (at ``u``)."""
    n = len(ring)
    # insert q after vertex k (unless it is a vertex)
    if u <= 1e-9:
        j = k
        r = ring
    elif u >= 1 - 1e-9:
        j = (k + 1) % n
        r = ring
    else:
        r = np.concatenate([ring[: k + 1], np.reshape(q, (1, 2)), ring[k + 1 :]])  # np.insert(ring, k + 1, q, axis=0)
        j = k + 1
        if i > k:
            i += 1
    m = len(r)
    if i == j:
        return None
    a = r[(i + np.arange((j - i) % m + 1)) % m]
    b = r[(j + np.arange((i - j) % m + 1)) % m]
    if len(a) < 3 or len(b) < 3:
        return None
    return a, b, r[j].copy()


def _snap_to_reflex(ring: np.ndarray, t: np.ndarray, k: int, u: float, q: np.ndarray, tol: float):
    """Move a cut's end ``q`` onto a reflex vertex within ``tol`` of it, if there is one."""
    n = len(ring)
    cand = [j for j in (k, (k + 1) % n) if t[j] < -SHARP]
    d = [(math.hypot(*(ring[j] - q)), j) for j in cand]
    d = [x for x in d if x[0] <= tol]
    if not d:
        return k, u, q
    _, j = min(d)
    return j, 0.0, ring[j].copy()


def _motorcycle_cuts(ring: np.ndarray, sigma: float):
    """Candidate cuts ``(piece_a, piece_b, segment)`` from every reflex vertex, both directions."""
    t = turning(ring, sigma)
    w = _width(ring)
    e = _edges(ring)
    out = []
    s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(ring, axis=0).T))])
    total = s[-1] + math.hypot(*(ring[0] - ring[-1]))
    table = _along_table(ring, s, total)
    for v in _reflex_peaks(t, s, total, sigma):
        back = _point_along(ring, s, total, s[v] - sigma, table)
        ahead = _point_along(ring, s, total, s[v] + sigma, table)
        for d in (ring[v] - back, ring[v] - ahead):
            nd = math.hypot(*d)
            if nd == 0:
                continue
            hit = _ray_to_boundary(ring, v, d / nd, e)
            if hit is None:
                continue
            k, u, q = hit
            k, u, q = _snap_to_reflex(ring, t, k, u, q, 0.5 * w)
            res = _split_ring(ring, v, k, u, q)
            if res is None:
                continue
            a, b, q = res
            out.append((a, b, np.array([ring[v], q])))
    return out


def _normal_cuts(ring: np.ndarray, sigma: float, *, even: bool = False, count: int = 32):
    """Candidate cuts ``(piece_a, piece_b, segment)`` along the inward normal of the shore.

    A smooth bay between two lobes of a round lake turns too gently to be a reflex corner at
    the cells' scale, and a round basin has no reflex corner at all, yet neither can be one
    block.  A cut along the normal of a smooth shore leaves a right angle on both of its sides
    there (across a disc it is a diameter: right angles at both ends).  Candidates start at
    the concave bends at the region's own scale (half its width), or with ``even`` at
    ``count`` points evenly spaced round it (:func:`best_split` tries those only when nothing
    else pays: in channel junctions they also won by a little, where the motorcycle cut from
    the junction's corner makes the better grid); sharp reflex corners are left to
    :func:`_motorcycle_cuts`.
    """
    w = _width(ring)
    big = max(sigma, 0.5 * w)
    tb = turning(ring, big)
    s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(ring, axis=0).T))])
    total = s[-1] + math.hypot(*(ring[0] - ring[-1]))
    t = turning(ring, sigma)
    e = _edges(ring)
    starts = [] if even else _reflex_peaks(tb, s, total, big, limit=-20.0)
    if even:
        at = np.minimum(np.searchsorted(s, np.linspace(0.0, total, count, endpoint=False)), len(ring) - 1)
        starts = sorted({int(v) for v in at})
    table = _along_table(ring, s, total)
    out = []
    for v in starts:
        if abs(t[v]) > SHARP:
            continue  # a corner: a cut from it makes no right angles (reflex: motorcycle cuts)
        back = _point_along(ring, s, total, s[v] - sigma, table)
        ahead = _point_along(ring, s, total, s[v] + sigma, table)
        d = ahead - back
        nd = math.hypot(*d)
        if nd == 0:
            continue
        hit = _ray_to_boundary(ring, v, np.array([-d[1], d[0]]) / nd, e)
        if hit is None:
            continue
        res = _split_ring(ring, v, *hit)
        if res is not None:
            out.append((res[0], res[1], np.array([ring[v], res[2]])))
    return out


def _reflex_peaks(t: np.ndarray, s: np.ndarray, total: float, sigma: float, limit: float = -45.0) -> list[int]:
    """Reflex vertices (turning < ``limit`` at scale), the sharpest within ``± sigma`` only."""
    tl, sl = t.tolist(), s.tolist()  # Python floats: the same numbers, without NumPy's per-scalar cost
    taken: list[int] = []
    at: list[float] = []
    for i in np.argsort(t).tolist():
        if tl[i] >= limit:
            break
        si = sl[i]
        if all(min(abs(si - q), total - abs(si - q)) > sigma for q in at):
            taken.append(i)
            at.append(si)
    return taken


def _point_along(ring, s, total, at, table=None):
    """The point at arc length ``at`` (cyclic) along ``ring`` (``s``: arc length at its vertices,
    ``total``: its perimeter; ``table``: :func:`_along_table` of these, if made already)."""
    at = at % total
    xs, x, y = _along_table(ring, s, total) if table is None else table
    return np.array([np.interp(at, xs, x), np.interp(at, xs, y)])


def _along_table(ring, s, total):
    """``(arc lengths, x, y)`` of ``ring`` closed (its first vertex again at ``total``)."""
    xs = np.concatenate([s, [total]])
    return xs, np.concatenate([ring[:, 0], ring[:1, 0]]), np.concatenate([ring[:, 1], ring[:1, 1]])


def _valid(r: np.ndarray, poly=None) -> bool:
    """True if ``r`` is a valid polygon (``poly``: ``shapely.polygons(r)``, if made already)."""
    import shapely

    return len(r) >= 3 and bool(shapely.is_valid(shapely.polygons(r) if poly is None else poly))


def _orient(r: np.ndarray) -> np.ndarray:
    x, y = r[:, 0], r[:, 1]
    x1, y1 = np.concatenate([x[1:], x[:1]]), np.concatenate([y[1:], y[:1]])  # np.roll(·, -1)
    a = 0.5 * (np.dot(x, y1) - np.dot(y, x1))
    return r if a > 0 else r[::-1].copy()


def best_split(
    ring: np.ndarray,
    *,
    sigma: float,
    min_width: float,
    center=None,
    depth: int = 4,
    forced=(),
    regular: bool = False,
    normal: bool = True,
    thin: bool = False,
    tee=None,
    look: int = 1,
):
    """Pieces and cuts (segments) of a greedy split of ``ring`` (maybe none).

    Returns ``(pieces, cuts, cost)`` with ``pieces`` a list of ``(ring, corners)``: a CCW ring
    and the points that must be among its corners (a butterfly's), usually none.  The cut (or
    star, or butterfly) whose pieces are cheapest is applied if it lowers the cost, then the
    pieces are split again, at most ``depth`` levels deep.  When nothing pays, cuts along the
    shore's normal from evenly spaced points are tried as a last resort (a round basin has no
    corner to cut from).  ``regular``: no star and no butterfly, so no node where three or five
    blocks meet (Delft3D's domain decomposition couples grid lines of the same direction only).
    ``normal=False``: no cuts along the shore's normal (the splits of earlier versions).
    ``thin``: motorcycle cuts may leave pieces two cells across (:data:`.width.THIN_ACROSS`).
    ``tee`` (where ``center`` is given): a function ``(ring, center, sigma, min_width)`` giving one
    more split, :func:`.tee.tee` in regular layouts with ``LayoutOptions(tees=True)``, kept when its
    pieces, split on, cost less than those of the cheapest other split.  ``look``: the first split is
    the one of its ``look`` cheapest options whose pieces, split on, cost least (:data:`LOOKAHEAD`).
    """
    base = region_cost(ring, sigma, forced)
    if depth <= 0 or base <= _GOOD:
        return [(ring, tuple(forced))], [], base
    # only an option cheaper than base - _GOOD is applied: cuts that cost more are not costed in full
    # (unless the first split looks ahead: then the LOOKAHEAD cheapest are needed)
    ahead = max(int(look), 1)
    options = _options(
        ring, sigma, min_width, center, forced, regular, normal, thin, bound=None if ahead > 1 else base - _GOOD
    )
    best = min(options, key=lambda o: o[2]) if options else None
    if (best is None or best[2] >= base - _GOOD) and normal and not len(forced):
        # last resort (a round basin): cuts along the shore's normal from evenly spaced points
        bound = base - _GOOD if best is None else min(best[2], base - _GOOD)
        more = _cut_options(_normal_cuts(ring, sigma, even=True), sigma, min_width, bound=bound)
        best = min(more + options, key=lambda o: o[2]) if more else best
        options = more + options
    t = (
        tee(ring, np.asarray(center, float), sigma, min_width)
        if tee and center is not None and not len(forced)
        else None
    )
    if (best is None or best[2] >= base - _GOOD) and (t is None or t[2] >= base - _GOOD):
        return [(ring, tuple(forced))], [], base
    kw = {
        "sigma": sigma,
        "min_width": min_width,
        "depth": depth - 1,
        "regular": regular,
        "normal": normal,
        "thin": thin,
    }
    out = _split_on(best, **kw) if best is not None and best[2] < base - _GOOD else None
    if out is not None and ahead > 1:  # the next cheapest splits, split on: the least in all
        others = sorted((o for o in options if o is not best), key=lambda o: o[2])
        for o in others[: ahead - 1]:
            if o[2] >= base - _GOOD:
                break
            alt = _split_on(o, **kw)
            if alt[2] < out[2]:
                out = alt
    if t is not None and t[2] < base - _GOOD:  # a T where its pieces, split on, cost less in all
        alt = _split_on(t, **kw)
        if out is None or alt[2] < out[2]:
            out = alt
    assert out is not None
    return out


def _split_on(option, **kw):
    """``(pieces, cuts, cost)`` of ``option`` with every piece split again by :func:`best_split`."""
    pieces, cuts, _ = option
    out_p, out_c, total = [], list(cuts), 0.0
    for pc, fc in pieces:
        pp, cc, c = best_split(pc, forced=fc, **kw)
        out_p += pp
        out_c += cc
        total += c
    return out_p, out_c, total


def _cut_options(cuts, sigma: float, min_width: float, thin: bool = False, bound: float | None = None) -> list:
    """``(pieces, cuts, cost)`` of the admissible single cuts among ``cuts`` (``thin``:
    :data:`.width.THIN_ACROSS` for cuts at most :data:`.width.THIN_CUT` × ``min_width`` long).

    With ``bound`` (the cost of the cheapest option found before, or inf) only the options that
    may be the cheapest of a split's options (the first of the cheapest wins): a cut whose first
    piece alone costs more than ``bound`` or than an earlier cut here is left out without costing
    its second piece (costs are sums of non-negative terms, so its pieces cost more in all)."""
    import shapely

    out = []
    for a, b, seg in cuts:
        a, b = _orient(a), _orient(b)
        here = thin and math.hypot(*(seg[-1] - seg[0])) <= THIN_CUT * min_width
        pa = shapely.polygons(a)  # each piece's polygon made once for its width and validity
        if _too_narrow(a, min_width, here, pa):
            continue
        pb = shapely.polygons(b)
        if _too_narrow(b, min_width, here, pb) or not (_valid(a, pa) and _valid(b, pb)):
            continue
        ca = region_cost(a, sigma)
        if bound is not None and ca > bound:
            continue
        cost = ca + region_cost(b, sigma)
        out.append(([(a, ()), (b, ())], [seg], cost))
        if bound is not None and cost < bound:
            bound = cost
    return out


def _options(ring, sigma, min_width, center, forced, regular, normal, thin=False, *, bound: float | None = None):
    """Every admissible split of ``ring``: motorcycle cuts (``thin``: :data:`.width.THIN_ACROSS`),
    normal cuts from its bays, the star from ``center``, the butterfly (none for a piece with
    ``forced`` corners).  With ``bound``: of the cuts only those that may be the first cheapest
    option and cost at most ``bound`` (:func:`_cut_options`)."""
    if len(forced):
        return []
    options = _cut_options(_motorcycle_cuts(ring, sigma), sigma, min_width, thin, bound=bound)
    if bound is not None:
        bound = min([bound] + [o[2] for o in options])
    options += _cut_options(_normal_cuts(ring, sigma) if normal else [], sigma, min_width, bound=bound)
    if center is not None and not regular:
        star = _star(ring, np.asarray(center, float), sigma, min_width)
        if star is not None:
            options.append(([(p, ()) for p in star[0]], star[1], star[2]))
    fly = None if regular else _butterfly(ring, sigma, min_width)
    if fly is not None:
        options.append(fly)
    return options


#: The first split of a region is chosen among its this many cheapest options by the cost of their
#: pieces split on (greedily), not by their own: a cut that leaves a bay on one piece may lead to
#: cheaper pieces than the cut whose two pieces cost least as they are.  1: the cheapest as it is.
LOOKAHEAD = 3

#: A region whose corner cost is below this (four corners within ~20° of a right angle, no
#: sharp bend left on a side) is not split further.
_GOOD = 4 * 20.0**2


def _star(ring: np.ndarray, center: np.ndarray, sigma: float, min_width: float):
    """Straight spokes from ``center`` to 3–5 reflex vertices: the cheapest admissible star.

    Spokes are straight segments (sampled every ``sigma``): the grid solves move interface
    nodes along and across cut lines and straighten a curved spoke anyway.  Spokes that reached
    their corner along the continued shore (quadratic Béziers, earlier versions) gave one piece
    a small angle there in the layout which the solves opened to 150–180° (a fan of cells in its
    corner): generated Y junctions had cells 2.5× apart across the spoke's shore end.

    A straight spoke halves the reflex angle, so a piece between two spokes is a pentagon (the
    centre, two halved reflex corners, the two corners of its arm's opening); such a piece
    gets a spoke of its own from the centre to its far side (:func:`_far_spoke`) when that
    pays.  Without it the piece was split again by a cut from one of the evenly spaced shore
    points of the last resort (:func:`best_split`), unevenly: a symmetric Y in 8 or 9 blocks
    of different counts.  A symmetric junction gets a symmetric star.

    A spoke must split its reflex corner into two angles of at most 180° (+ :data:`SHARP`, a
    bend the corners do not count as sharp), so that no piece keeps a reflex bend at its end.
    A spoke to a far reflex vertex, typically the sharp tip of an island or a peninsula seen
    from across a wide junction, can arrive almost along one of its shores: one side of it a
    sliver (16° on a generated lake), the other still reflex (299°), which a second cut from
    the same vertex then splits; the grid fans out from that vertex (cells 47× apart across
    the cut on a generated lake with islands, 4× without such spokes).  The spokes of channel
    junctions mostly leave 90–180° on each side; the tolerance keeps those of 190–200° (a
    junction that lost them went from 2.9 to 6.8).
    """
    from shapely.geometry import LineString, Point, Polygon

    t = turning(ring, sigma)
    s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(ring, axis=0).T))])
    total = s[-1] + math.hypot(*(ring[0] - ring[-1]))
    reflex = sorted(_reflex_peaks(t, s, total, sigma)[:7])
    poly = Polygon(ring)
    if not poly.contains(Point(center)):
        return None
    room = poly.buffer(1e-9 * math.sqrt(poly.area))
    spoke_of = {}
    for v in reflex:
        sp = _segment(center, ring[v], sigma)
        if sp is None or max(_sides(ring, s, total, v, center, sigma)) > 180.0 + SHARP:
            continue  # (a spoke that leaves a reflex side: see above)
        if room.covers(LineString(sp)):
            spoke_of[v] = sp
    reflex = [v for v in reflex if v in spoke_of]
    best = None
    n = len(ring)
    for k in (3, 4, 5):
        for combo in itertools.combinations(reflex, k):
            spokes = [LineString(spoke_of[v]) for v in combo]
            if any(spokes[i].crosses(spokes[j]) for i in range(k) for j in range(i + 1, k)):
                continue
            pieces, extra, cost = [], [], 0.0
            for v0, v1 in zip(combo, combo[1:] + combo[:1], strict=True):
                arc = np.array([ring[(v0 + q) % n] for q in range((v1 - v0) % n + 1)])
                sub, sp, c = _far_spoke(spoke_of[v0], arc, spoke_of[v1], sigma, min_width)
                pieces += sub
                extra += sp
                cost += c
                if best is not None and cost >= best[2]:  # (costs ≥ 0: this star costs no less)
                    break
            if best is not None and cost >= best[2]:
                continue
            if min(_width(p) for p in pieces) < min_width:
                continue
            if not all(Polygon(p).is_valid for p in pieces):
                continue
            if best is None or cost < best[2]:
                best = (pieces, [spoke_of[v] for v in combo] + extra, cost)
    return best


def _sides(ring: np.ndarray, s: np.ndarray, total: float, v: int, center: np.ndarray, sigma: float):
    """The water angles (degrees) either side of a straight spoke from ``center`` to vertex ``v``:
    from the shore ahead of ``v`` round to the spoke, and from the spoke round to the shore behind
    (their sum is the reflex angle at ``v``), the shore read ``sigma`` along it as in
    :func:`~.corners.turning` (``s``: arc length at the vertices, ``total``: the perimeter)."""
    ahead = _point_along(ring, s, total, s[v] + sigma) - ring[v]
    back = _point_along(ring, s, total, s[v] - sigma) - ring[v]
    d = center - ring[v]

    def deg(u):
        return math.degrees(math.atan2(u[1], u[0]))

    return (deg(d) - deg(ahead)) % 360.0, (deg(back) - deg(d)) % 360.0


def _segment(a: np.ndarray, b: np.ndarray, sigma: float):
    """The straight segment from ``a`` to ``b`` sampled every ``sigma`` or less (None if a = b)."""
    d = math.hypot(*(b - a))
    if d == 0:
        return None
    tt = np.linspace(0.0, 1.0, max(3, int(np.ceil(d / sigma)) + 2))[:, None]
    sp = (1 - tt) * a + tt * b
    sp[0], sp[-1] = a, b
    return sp


def _far_spoke(sp0: np.ndarray, arc: np.ndarray, sp1: np.ndarray, sigma: float, min_width: float):
    """The star piece between spokes ``sp0`` and ``sp1`` (both from the centre), maybe split in two.

    ``arc`` runs counter-clockwise from the end of ``sp0`` to the end of ``sp1``.  The extra
    spoke runs from the centre to a point of the arc where it meets the arc at a right angle (the
    foot of the perpendicular inside an edge, or a vertex where the feet on both of its edges
    fall: across an arm's opening, its middle), at least ``min_width`` from both ends of the arc
    along it; the four such points nearest the centre are tried.  It is kept when it lowers the
    piece's corner cost at all (not by the margin :data:`_GOOD` of :func:`best_split`: the pieces
    of one symmetric junction, drawn between chords placed on a sampled skeleton, differ by more
    than that margin in cost, and some were split, some not).  Returns ``(pieces, extra spokes, cost)``.
    """
    import shapely
    from shapely.geometry import LineString, Polygon

    c = sp0[0]
    whole = _orient(np.array([*sp0[:-1], *arc, *sp1[-2:0:-1]]))
    cost = region_cost(whole, sigma)
    if cost <= _GOOD:
        return [whole], [], cost
    a, b = arc[:-1], arc[1:]
    e = b - a
    L = np.maximum(np.hypot(*e.T), 1e-300)
    u = ((c - a) * e).sum(axis=1) / (L * L)
    s = np.concatenate([[0.0], np.cumsum(L)])
    eps = 1e-9
    # (edge k, head, the point): the foot inside edge k, or a vertex j where the feet on both of
    # its edges fall onto it (the nearest point of the arc to the centre there)
    inside = [int(k) for k in np.flatnonzero((u > eps) & (u < 1 - eps))]
    cand = [(k, arc[: k + 1], a[k] + u[k] * e[k], s[k] + u[k] * L[k]) for k in inside]
    cand += [(j, arc[:j], arc[j], s[j]) for j in range(1, len(arc) - 1) if u[j - 1] >= 1 - eps and u[j] <= eps]
    cand = [x for x in cand if min_width <= x[3] <= s[-1] - min_width]
    cand.sort(key=lambda x: math.hypot(*(x[2] - c)))
    best: tuple[list[np.ndarray], list[np.ndarray], float] = ([whole], [], cost)
    piece = Polygon(whole).buffer(1e-9 * math.sqrt(Polygon(whole).area))
    for k, head, q, _ in cand[:4]:
        sp = _segment(c, q, sigma)
        if sp is None or not piece.covers(LineString(sp)):
            continue
        tail = arc[k + 1 :]
        p0 = _orient(np.array([*sp0[:-1], *head, q, *sp[-2:0:-1]]))
        p1 = _orient(np.array([*sp[:-1], q, *tail, *sp1[-2:0:-1]]))
        q0, q1 = shapely.polygons(p0), shapely.polygons(p1)
        if min(_width(p0, q0), _width(p1, q1)) < min_width or not (_valid(p0, q0) and _valid(p1, q1)):
            continue
        c0 = region_cost(p0, sigma)
        if c0 >= best[2]:  # (costs ≥ 0: the two cost no less)
            continue
        split = c0 + region_cost(p1, sigma)
        if split < best[2]:
            best = ([p0, p1], [sp], split)
    return best


def _butterfly(ring: np.ndarray, sigma: float, min_width: float):
    """An inner rectangle and four pieces round it (the "butterfly" or O-grid of a basin).

    A wide basin whose shore has no right-angled corners would get its four block corners on a
    smooth shore, where an orthogonal grid squeezes its cells to nothing.  Here the shore has
    no corner at all: the rectangle sits at the basin's widest point, along its principal axes,
    and from each of its corners a spoke runs to the nearest shore point in its quadrant (so it
    meets the shore at a right angle).
    """
    from shapely.geometry import LineString, Point, Polygon
    from shapely.ops import polylabel

    poly = Polygon(ring)
    if not poly.is_valid:
        return None
    c = np.asarray(polylabel(poly, tolerance=0.05 * math.sqrt(poly.area)).coords[0])
    r = poly.exterior.distance(Point(c))
    if r < 1.5 * min_width:
        return None
    P = ring - c
    _, v = np.linalg.eigh(P.T @ P)
    axes = v[:, ::-1].T  # major axis first
    ext = [np.abs(P @ a).max() for a in axes]
    half = [0.45 * r * min(2.0, ext[0] / max(ext[1], 1e-300)) ** 0.5, 0.45 * r]
    corners = [c + sx * half[0] * axes[0] + sy * half[1] * axes[1] for sx, sy in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
    inner = np.array(corners)
    if not poly.contains(Polygon(inner)):
        return None
    boundary = np.vstack([ring, ring[:1]])
    room = poly.buffer(1e-9 * math.sqrt(poly.area))
    spokes, ends = [], []
    for q in inner:
        d = q - c
        # the nearest shore point within ±40° of the diagonal
        vec = ring - q
        ang = np.degrees(np.arccos(np.clip((vec @ d) / np.maximum(np.hypot(*vec.T) * math.hypot(*d), 1e-300), -1, 1)))
        ok = np.flatnonzero(ang <= 40.0)
        if not len(ok):
            return None
        k = int(ok[np.argmin(np.hypot(*vec[ok].T))])
        seg = np.array([q, ring[k]])
        if not room.covers(LineString(seg)):
            return None
        spokes.append(seg)
        ends.append(k)
    if len(set(ends)) != 4 or (ends != sorted(ends) and not _cyclic(ends)):
        return None
    pieces = [(_orient(inner.copy()), tuple(inner))]
    for j in range(4):
        a, b = ends[j], ends[(j + 1) % 4]
        arc = [ring[(a + t) % len(ring)] for t in range((b - a) % len(ring) + 1)]
        corners = (inner[j], ring[a], ring[b], inner[(j + 1) % 4])
        pieces.append((_orient(np.array([inner[j], *arc, inner[(j + 1) % 4]])), corners))
    del boundary
    if not all(Polygon(pc).is_valid for pc, _ in pieces) or min(_width(pc) for pc, _ in pieces) < min_width:
        return None
    sides = [np.array([inner[j], inner[(j + 1) % 4]]) for j in range(4)]
    # the rectangle's corners are nodes where three blocks meet: the smoother gives each cell
    # about 120° there (the interfaces move), not the 90° / 135° of the drawing
    cost = sum(region_cost(pc, sigma, fc) for pc, fc in pieces)
    cost -= sum(_corner_term(pc, sigma, inner) for pc, _ in pieces[1:])
    cost += 8 * (120.0 - 90.0) ** 2
    return pieces, spokes + sides, cost


def _corner_term(ring: np.ndarray, sigma: float, points) -> float:
    """The part of the corner cost that the vertices at ``points`` contribute as corners."""
    from .corners import corner_cost

    idx = forced_indices(ring, points)
    t = turning(ring, sigma)[idx]
    return corner_cost(t, range(len(idx)))


def _cyclic(idx: list[int]) -> bool:
    """True when the indices increase round the ring from their smallest (any rotation)."""
    k = idx.index(min(idx))
    rot = idx[k:] + idx[:k]
    return rot == sorted(rot)
