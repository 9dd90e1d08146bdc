r"""A junction as a T: what a regular layout may use where the default layout uses a star.

**Off as the layout of every lake** (``LayoutOptions(tees=True)``, ``--layout-option tees``; regular
layouts only): measured mixed, see ``docs/lake-grids-journal.md`` (*Junctions of regular layouts as a
T*).  The regular layout choice reads the draw with tees as one more candidate
(:data:`meshcore.layout.TEE_DRAW`) and keeps it where its coarse grid is the most orthogonal.

Delft3D's domain decomposition couples no node where three blocks take a corner each
(:mod:`.frames`), so a regular layout has no star (:func:`~.split._star`).  Without one, a wide
junction is split by cuts from its reflex corners and along the shore's normals alone: long bent
pieces whose grid lines cross at 10–15° over much of the junction (held-out lakes g180632,
g180801 at 15 000 cells, ``--regular``).  A **T** is regular: a straight *through* cut joins two
of the junction's reflex corners, and a *stem* runs from a third reflex corner — or from the
opposite shore where it runs parallel to the through cut (a junction whose third side is an
island's flank has two reflex corners only) — to the through cut, meeting it at a right angle.
Round the foot of the stem the piece on the through side keeps a straight side (a half turn),
the two on the stem's sides take a right-angled corner each: ``2 m − c = 2·3 − 2 = 4`` quarter
turns, as four corners give.

The T stays local to the junction: the stem's foot lies in the junction's inscribed circle
(centre: the skeleton's junction, radius ``reach``: its distance to the shore) and every end
within :data:`_ARMS` × ``reach`` of the centre.  :func:`~.split.best_split` splits the T's pieces
on and keeps it when they cost less in all than the cheapest other split's (one step of
look-ahead: the T's own pieces are rarely four-sided).
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from .corners import SHARP, turning

__all__ = ["tee"]

#: The stem's foot keeps at least this many ``sigma`` from both ends of the through cut (a
#: foot at a reflex corner would be a node where a corner and two half sides meet).
_FOOT_GAP = 1.0


def _stems(ring: np.ndarray, reflex: list[int], sigma: float, center: np.ndarray, reach: float):
    """``(a, b, stem)`` vertex triples: a through cut from reflex ``a`` to reflex ``b`` and a stem
    from vertex ``stem`` — a third reflex corner, or (:data:`SHORE_STEMS`) a shore vertex where the
    shore runs parallel to the through cut within :data:`_PARALLEL`, so that the stem meets the
    shore at a right angle too — whose foot on the through cut lies within ``reach`` of ``center``
    and :data:`_FOOT_GAP` × ``sigma`` from its ends."""
    n = len(ring)
    tangent = np.roll(ring, -1, axis=0) - np.roll(ring, 1, axis=0)
    tangent /= np.maximum(np.hypot(*tangent.T), 1e-300)[:, None]
    for a, b in itertools.combinations(reflex, 2):
        d = ring[b] - ring[a]
        L = math.hypot(*d)
        if L == 0.0:
            continue
        u = (ring - ring[a]) @ d / (L * L)
        foot = ring[a] + u[:, None] * d
        gap = _FOOT_GAP * sigma / L
        ok = (u > gap) & (u < 1.0 - gap) & (np.hypot(*(foot - center).T) <= reach)
        ok[[a, b]] = False
        for v in reflex:
            if v not in (a, b) and ok[v]:
                yield a, b, v
        if not SHORE_STEMS:
            continue
        along = np.abs(tangent @ (d / L)) >= math.cos(math.radians(_PARALLEL))
        near = np.flatnonzero(ok & along & ~np.isin(np.arange(n), reflex))
        near = near[np.argsort(np.hypot(*(foot[near] - center).T))]
        taken: list[int] = []
        for v in near.tolist():  # the nearest to the junction, one per sigma of shore
            if all(np.hypot(*(ring[v] - ring[w])) > sigma for w in taken):
                taken.append(v)
                yield a, b, v
            if len(taken) >= 3:
                break


#: Stems from a shore vertex (not only a third reflex corner): a junction whose third side is
#: a smooth shore (an island's flank, a bay) has only two reflex corners.
SHORE_STEMS = True

#: A shore vertex carries a stem where its tangent is within this many degrees of the through
#: cut's direction (the stem meets the shore within as many degrees of a right angle).
_PARALLEL = 20.0


#: Every end of the T lies within this many times the junction's radius of its centre: a cut to
#: a corner farther away splits more than the junction.
_ARMS = 2.5


def tee(ring: np.ndarray, center: np.ndarray, sigma: float, min_width: float):
    """``(pieces, cuts, cost)`` of the cheapest admissible T of ``ring`` round the junction at
    ``center`` (pieces as ``(ring, ())``), or None when none fits."""
    from shapely.geometry import LineString, Point, Polygon

    from .split import _orient, _reflex_peaks, _segment, _sides, _valid, region_cost
    from .width import width as _width

    t = turning(ring, sigma)
    s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(ring, axis=0).T))])
    total = s[-1] + math.hypot(*(ring[0] - ring[-1]))
    reflex = sorted(_reflex_peaks(t, s, total, sigma)[:7])
    if len(reflex) < 2:
        return None
    poly = Polygon(ring)
    if not poly.contains(Point(center)):
        return None
    reach = poly.exterior.distance(Point(center))  # the junction's circle: the stem's foot lies in it
    room = poly.buffer(1e-9 * math.sqrt(poly.area))
    n = len(ring)
    best = None
    for a, b, stem in _stems(ring, reflex, sigma, center, reach):
        d = ring[b] - ring[a]
        foot = ring[a] + float((ring[stem] - ring[a]) @ d) / float(d @ d) * d
        combo = tuple(sorted((a, b, stem)))
        if max(math.hypot(*(ring[v] - center)) for v in combo) > _ARMS * reach:
            continue
        if not poly.contains(Point(foot)):
            continue
        if any(max(_sides(ring, s, total, v, foot, sigma)) > 180.0 + SHARP for v in combo):
            continue  # a cut that leaves a reflex bend on one side (see split._star)
        spokes = {v: _segment(foot, ring[v], sigma) for v in combo}
        if any(sp is None or not room.covers(LineString(sp)) for sp in spokes.values()):
            continue
        pieces = []
        for v0, v1 in zip(combo, combo[1:] + combo[:1], strict=True):
            arc = np.array([ring[(v0 + q) % n] for q in range((v1 - v0) % n + 1)])
            sp0, sp1 = spokes[v0], spokes[v1]
            pieces.append(_orient(np.array([*sp0[:-1], *arc, *sp1[-2:0:-1]])))
        if not all(_valid(p) for p in pieces) or min(_width(p) for p in pieces) < min_width:
            continue
        cost = sum(region_cost(p, sigma) for p in pieces)
        if best is None or cost < best[2]:
            through = np.vstack([spokes[a][::-1], spokes[b][1:]])
            best = ([(p, ()) for p in pieces], [through, spokes[stem]], cost)
    return best
