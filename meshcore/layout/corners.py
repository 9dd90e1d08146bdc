r"""Four corners for a region: where its boundary turns, measured at the scale of its cells.

A block is four-sided: walking round it counter-clockwise the boundary turns by 360° in all,
ideally 90° at each of its four corners and not at all in between.  For any region (a simple
polygon) we choose the four corner vertices from the **cumulative turning** ``θ(s)``: the
corners are where ``θ`` first reaches ``φ + 45° + 90° k`` (k = 0 … 3).  A rectangle's corners
are found for every phase ``φ``; a rounded end is split evenly (its corners at 45° and 135° of
its turn); the phase with the smallest cost is kept.

The **cost** of a choice is what the grid pays for it: ``Σ (t − 90)²`` over the corners,
``Σ t²`` over the other vertices whose turning is large (sharp bends left inside a side), with
``t`` the turning at a vertex measured over a window of ``± sigma`` of arc length (so jagged
shores are read at the scale of the cells, not of their vertices), plus a term for opposite
sides of different lengths (:func:`side_cost`): the same number of cells on both.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["bulge_ratio", "choose_corners", "choose_corners_numpy", "corner_cost", "raw_turning", "set_cost", "turning"]

#: A vertex turning more than this (degrees, at scale) counts as a sharp feature.
SHARP = 30.0


def _edges(ring: np.ndarray) -> np.ndarray:
    """``ring[i + 1] - ring[i]`` for every vertex of a closed ring (the last back to the first);
    what ``np.roll(ring, -1, axis=0) - ring`` gives, without its cost (these functions run for
    every candidate piece of a layout: thousands of small rings)."""
    ring = np.asarray(ring)
    d = np.empty_like(ring)
    np.subtract(ring[1:], ring[:-1], out=d[:-1])
    np.subtract(ring[:1], ring[-1:], out=d[-1:])
    return d


def _arclength_closed(ring: np.ndarray, d: np.ndarray | None = None) -> tuple[np.ndarray, float]:
    """Arc length at every vertex of a closed ring and its perimeter (``d``: its :func:`_edges`)."""
    d = _edges(ring) if d is None else d
    seg = np.hypot(d[:, 0], d[:, 1])
    s = np.concatenate([[0.0], np.cumsum(seg[:-1])])
    return s, float(seg.sum())


def turning(ring: np.ndarray, sigma: float, arc: tuple[np.ndarray, float] | None = None) -> np.ndarray:
    """Turning angle (degrees, left = positive) at every vertex of a closed ring, at scale.

    The direction before a vertex is that of the chord from the point ``sigma`` behind it
    (along the ring) to the vertex, after it the chord to the point ``sigma`` ahead.
    ``arc``: the ring's :func:`_arclength_closed`, if made already.
    """
    ring = np.asarray(ring, dtype=float)
    s, total = _arclength_closed(ring) if arc is None else arc
    sigma = min(sigma, 0.25 * total)
    xs = np.concatenate([s - total, s, s + total])
    n = len(s)
    # the points sigma behind and ahead of every vertex, in one interpolation per coordinate
    q = np.concatenate([s - sigma, s + sigma])
    x = np.interp(q, xs, np.concatenate([ring[:, 0], ring[:, 0], ring[:, 0]]))
    y = np.interp(q, xs, np.concatenate([ring[:, 1], ring[:, 1], ring[:, 1]]))
    a = np.empty((n, 2))
    b = np.empty((n, 2))
    np.subtract(ring[:, 0], x[:n], out=a[:, 0])  # ring - back
    np.subtract(ring[:, 1], y[:n], out=a[:, 1])
    np.subtract(x[n:], ring[:, 0], out=b[:, 0])  # ahead - ring
    np.subtract(y[n:], ring[:, 1], out=b[:, 1])
    ang = np.degrees(np.arctan2(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0], (a * b).sum(axis=1)))
    return ang


def raw_turning(ring: np.ndarray, d: np.ndarray | None = None) -> np.ndarray:
    """Turning angle (degrees) at every vertex between its two edges (``d``: :func:`_edges`)."""
    b = _edges(ring) if d is None else d
    a = np.concatenate([b[-1:], b[:-1]])
    return np.degrees(np.arctan2(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0], (a * b).sum(axis=1)))


def corner_cost(t: np.ndarray, corners, near=None) -> float:
    """Cost of taking ``corners`` (indices) as the corners, given turning ``t`` at every vertex.

    ``(t − 90)²`` per corner, made steeper below 60° of turning (an angle above 120°): an
    orthogonal grid squeezes its cells to nothing at a block corner on a nearly straight shore,
    which is far worse than the angle alone says.  ``near`` (a mask) marks the vertices that
    are close to a corner: they are not counted as bends of the sides.
    """
    mask = np.zeros(len(t), dtype=bool)
    mask[list(corners)] = True
    tc = t[mask]
    flat = 1.0 + 2.0 * np.clip(60.0 - tc, 0.0, 60.0) / 60.0
    # vertices within the window of a corner see part of its turn: not a bend of their own
    side = t[~(mask | near)] if near is not None else t[~mask]
    return float(((tc - 90.0) ** 2 * flat).sum() + (side[np.abs(side) > SHARP] ** 2).sum())


#: Cost of opposite sides whose lengths differ by a factor e (a block whose sides differ a lot
#: squeezes its cells on one side and stretches them on the other); 2× costs about as much as
#: a corner 30° off.
SIDE_WEIGHT = 2000.0


def side_cost(s: np.ndarray, total: float, corners) -> float:
    """``SIDE_WEIGHT × (log² (bottom/top) + log² (left/right))`` for corners at arc lengths."""
    c = sorted(corners)
    pos = [s[i] for i in c]
    L = [(pos[(k + 1) % 4] - pos[k]) % total for k in range(4)]
    if min(L) <= 0:
        return math.inf
    return SIDE_WEIGHT * (math.log(L[0] / L[2]) ** 2 + math.log(L[1] / L[3]) ** 2)


def bulge_ratio(ring: np.ndarray, corners, arc: tuple[np.ndarray, float] | None = None) -> float:
    """``R``: the area of ``ring`` over the product of the mean lengths of its two pairs of
    opposite sides between ``corners`` (1 for a rectangle, an annular sector or a straight or
    bent strip; 1.27 for a disc with four corners a quarter apart).

    Four corners bunched together on one part of a round region give ``R ≫ 1``: its cells
    fan out from two short sides across the whole basin, although every corner may be a right
    angle and no side bends sharply.  ``arc``: the ring's :func:`_arclength_closed`, if made already.
    """
    s, total = _arclength_closed(ring) if arc is None else arc
    pos = [s[i] for i in sorted(corners)]
    L = [(pos[(k + 1) % 4] - pos[k]) % total for k in range(4)]
    x, y = ring[:, 0], ring[:, 1]
    x1, y1 = np.concatenate([x[1:], x[:1]]), np.concatenate([y[1:], y[:1]])  # np.roll(·, -1)
    area = 0.5 * abs(float(np.dot(x, y1) - np.dot(y, x1)))
    return area / max(0.25 * (L[0] + L[2]) * (L[1] + L[3]), 1e-300)


def bulge_cost(ring: np.ndarray, corners, arc: tuple[np.ndarray, float] | None = None) -> float:
    """``SIDE_WEIGHT × log² R`` for a region that holds more water than its sides span
    (:func:`bulge_ratio` ``R > 1``); nothing for ``R ≤ 1``."""
    R = bulge_ratio(ring, corners, arc)
    return SIDE_WEIGHT * math.log(R) ** 2 if R > 1.0 else 0.0


def _sharp_peaks(
    t: np.ndarray, s: np.ndarray, total: float, sigma: float, limit: float, most: int | None = None
) -> list[int]:
    """Vertices turning more than ``limit`` that are the largest within ``± sigma`` of arc length,
    the most turning first (``most``: only the first that many)."""
    order = np.argsort(-t)
    tl, sl = t.tolist(), s.tolist()  # Python floats: the same numbers, without NumPy's per-scalar cost
    taken: list[int] = []
    at: list[float] = []
    for i in order.tolist():
        if tl[i] < limit:
            break
        si = sl[i]
        for q in at:
            d = abs(si - q)
            if not min(d, total - d) > sigma:
                break
        else:
            taken.append(i)
            at.append(si)
            if most is not None and len(taken) >= most:
                break
    return taken


def _smooth_corners(raw: np.ndarray, a: int, b: int, m: int) -> list[int]:
    """``m`` corners on the stretch of vertices strictly between ``a`` and ``b`` (cyclic), at the
    quantiles ``(k + ½) / m`` of its total turning (a rounded end gets its corners at 45° and
    135° of a 180° turn)."""
    n = len(raw)
    idx = ((a + np.arange(1, (b - a) % n if (b - a) % n else n)) % n).tolist()
    if len(idx) < m:
        return []
    cum = np.cumsum(np.maximum(raw[idx], 0.0))
    total = cum[-1] if len(cum) else 0.0
    out = []
    for k in range(m):
        level = (k + 0.5) / m * total
        j = int(np.searchsorted(cum, level)) if total > 0 else int((k + 0.5) / m * len(idx))
        j = min(max(j, 0), len(idx) - 1)
        while idx[j] in out and j + 1 < len(idx):
            j += 1
        out.append(idx[j])
    return out


def _where_it_bends(raw: np.ndarray, s: np.ndarray, total: float, i: int, reach: float) -> int:
    """The vertex within ``reach`` (arc length) of a sharp corner ``i`` where the boundary itself
    turns most, if it turns more there than at ``i`` and by more than :data:`SHARP`: read at
    scale, the vertices beside a cut's end turn almost as much as the end, but a block corner
    one vertex off it has a straight or reflex angle in the grid (its corner cell cannot be
    convex)."""
    d = np.abs(s - s[i])
    # the first vertex of the largest turn among those within reach (i is one of them)
    j = int(np.argmax(np.where(np.minimum(d, total - d) <= reach, raw, -np.inf)))
    return j if raw[j] > max(raw[i], SHARP) else i


def _where_they_bend(raw: np.ndarray, s: np.ndarray, total: float, picks: list[int], reach: float) -> list[int]:
    """:func:`_where_it_bends` of every vertex of ``picks``, in one pass (the same numbers)."""
    if not picks:
        return []
    d = np.abs(s[None, :] - s[picks][:, None])
    j = np.argmax(np.where(np.minimum(d, total - d) <= reach, raw[None, :], -np.inf), axis=1).tolist()
    return [jk if raw[jk] > max(raw[i], SHARP) else i for i, jk in zip(picks, j, strict=True)]


#: The turning is read at no more than this share of a ring's perimeter: a piece about as large as
#: the corner scale (a block in a neck one cell wide between two islands) read at that scale turns
#: ~130° at most of its vertices, and its fourth corner went to a flat vertex of a short shore side
#: (its corner cell non-convex).  The share the sharp peaks' spacing has (:func:`choose_corners_numpy`).
TURN_SHARE = 0.1


def _capped(sigma: float, total: float) -> float:
    """``sigma``, or :data:`TURN_SHARE` of the perimeter ``total`` where that is smaller."""
    return float(sigma) if TURN_SHARE <= 0 else float(min(sigma, TURN_SHARE * total))


def choose_corners(ring: np.ndarray, sigma: float, *, forced=()):
    """The four corner indices (increasing, counter-clockwise) of a CCW ring, and their cost.

    Sharp corners (turning ≥ 45° at scale ``sigma``, at most one within ``± sigma``) are
    taken first, the most turning first; ``forced`` vertices always count as sharp.  Missing
    corners are placed on the smooth convex stretches in between, in proportion to how much
    each stretch turns, at the quantiles of its turning.  Returns ``(None, inf)`` when the ring
    has fewer than four vertices.

    The work runs in the compiled kernels of :mod:`._corner_kernels`; :func:`choose_corners_numpy`
    is the same in NumPy, the reference they are tested against (the same corners and cost, bit
    for bit).
    """
    from . import _corner_kernels as kernels

    n = len(ring)
    if n < 4:
        return None, math.inf
    ring = np.ascontiguousarray(ring, dtype=float)
    s, total, at_scale, between = kernels.ring_terms(ring, float(sigma))
    if _capped(sigma, total) < sigma:  # a piece about as large as the scale (TURN_SHARE): read again
        sigma = _capped(sigma, total)
        s, total, at_scale, between = kernels.ring_terms(ring, sigma)
    t = np.degrees(np.arctan2(at_scale[0], at_scale[1]))  # (NumPy's arctan2: the reference's bits)
    raw = np.degrees(np.arctan2(between[0], between[1]))
    forced = sorted({int(f) for f in forced})
    tt = t.copy()
    tt[forced] = 1e9  # forced first
    mask = np.zeros(n, dtype=np.bool_)
    mask[forced] = True
    picks, corner_term = kernels.choose(s, total, t, raw, np.argsort(-tt), mask, float(sigma))
    arc = (s, total)
    if len(picks) != 4:  # (rare: the reference's last resort)
        return _fourth_resort(ring, sigma, picks.tolist(), t, arc)
    picks = tuple(int(p) for p in picks)
    return picks, corner_term + side_cost(s, total, picks) + bulge_cost(ring, picks, arc)


def _fourth_resort(ring: np.ndarray, sigma: float, picks: list[int], t: np.ndarray, arc) -> tuple:
    """The corners of :func:`choose_corners` when its steps found other than four: the most turning
    vertices not among ``picks`` fill them up."""
    order = [int(i) for i in np.argsort(-t) if int(i) not in picks]
    picks = sorted(set(picks + order[: 4 - len(picks)]))[:4]
    if len(picks) != 4:
        return None, math.inf
    return tuple(picks), set_cost(ring, sigma, picks, t=t, arc=arc)


def choose_corners_numpy(ring: np.ndarray, sigma: float, *, forced=()):
    """:func:`choose_corners` in NumPy: the reference of its compiled kernels."""
    n = len(ring)
    if n < 4:
        return None, math.inf
    d = _edges(ring)
    arc = _arclength_closed(ring, d)
    s, total = arc
    sigma = _capped(sigma, total)
    t = turning(ring, sigma, arc)
    raw = raw_turning(ring, d)
    forced = sorted({int(f) for f in forced})
    tt = t.copy()
    tt[forced] = 1e9  # forced first
    picks = _sharp_peaks(tt, s, total, min(sigma, 0.1 * total), 45.0, most=4)
    moved = _where_they_bend(raw, s, total, picks, 0.5 * sigma)
    picks = [p if p in forced else m for p, m in zip(picks, moved, strict=True)]
    if len(picks) < 4:
        picks = sorted(picks)
        missing = 4 - len(picks)
        if not picks:
            # a smooth oval: corners at the quantiles of the whole turn
            picks = _smooth_corners(raw, 0, 0, 4)
        else:
            stretches = [(a, b) for a, b in zip(picks, picks[1:] + picks[:1], strict=True)]
            turn = np.array([np.maximum(raw[(a + np.arange(1, (b - a) % n or n)) % n], 0).sum() for a, b in stretches])
            share = np.zeros(len(stretches), dtype=int)
            for _ in range(missing):  # largest remaining turn per corner gets the next one
                share[int(np.argmax(turn / (share + 1)))] += 1
            extra = []
            for (a, b), m in zip(stretches, share, strict=True):
                if m:
                    extra += _smooth_corners(raw, a, b, int(m))
            picks = picks + extra
    picks = sorted(set(picks))
    if len(picks) != 4:
        return _fourth_resort(ring, sigma, picks, t, arc)
    return tuple(picks), set_cost(ring, sigma, picks, t=t, arc=arc)


def set_cost(
    ring: np.ndarray, sigma: float, picks, *, t: np.ndarray | None = None, arc: tuple[np.ndarray, float] | None = None
) -> float:
    """The cost of the four corners ``picks`` (increasing indices) of a CCW ring: the corners'
    turning (:func:`corner_cost`), opposite sides' lengths (:func:`side_cost`) and the bulge
    (:func:`bulge_cost`); ``t``: :func:`turning` of the ring at ``sigma``, ``arc``: its
    :func:`_arclength_closed`, if made already."""
    arc = _arclength_closed(ring) if arc is None else arc
    t = turning(ring, sigma, arc) if t is None else t
    s, total = arc
    d = np.abs(s[None, :] - s[list(picks)][:, None])
    near = (np.minimum(d, total - d) < sigma).any(axis=0)
    return corner_cost(t, picks, near) + side_cost(s, total, picks) + bulge_cost(ring, picks, arc)


#: A corner turning at least this (degrees, at scale) is a wedge's tip: the end of an arm that
#: tapers to a point (an angle of 60° or less).
WEDGE_TURN = 120.0

#: ... whose block gets two corners along the shore either side of the tip, as far from it as
#: makes the end side between them this wide (× ``sigma`` / 1.5: cells), at least a cell from the tip.
WEDGE_END = 1.0

#: ... and only in a piece at most this many cells wide (twice its area over its perimeter): the
#: end of an arm.  The tip of a wide bay (`headlands(762600)`, a basin block round it) folded a
#: cell on its curved side with two corners there.
WEDGE_WIDTH = 4.0


#: The least turning (degrees, between its two edges, towards the water) of a shore vertex that
#: takes a block corner moved there (a wedge's end, :func:`wedge_corners`; a corner that closes a
#: regular layout's frames, :mod:`.frames`): at a vertex of a straight edge the block's corner
#: cell has an angle of 180° (a triangle; :data:`~meshcore.quality.cells.STRAIGHT_SINE`),
#: whatever the shore does a fraction of a cell further on.
OWN_TURN = 1.0


#: ... and each of the two corners goes to the nearest vertex turning by :data:`OWN_TURN` or
#: more within this fraction of that distance of it, if there is one.
WEDGE_SLACK = 0.5


def wedge_corners(ring: np.ndarray, corners, sigma: float, *, shore: np.ndarray, forced=()):
    """``corners`` of a CCW ring with a wedge's tip among them split in two (or ``corners``).

    A piece ending in a wedge (an arm tapering to a point, its tip turning ≥ :data:`WEDGE_TURN`
    at ``sigma``) has three sharp corners, the tip and the two ends of the chord across the arm;
    :func:`choose_corners` puts the fourth on a side, and the block's cells fan out from the
    tip across the whole wedge.  Here the fourth (the weakest corner, turning under
    :data:`SHARP` · 2, or one of two corners within a quarter of ``sigma``; not ``forced``) is
    dropped and the tip is replaced by the two vertices far enough along the shore either side
    of it to span :data:`WEDGE_END` cells: the tip lies inside a short end side, the grid lines
    run along the wedge and converge on it (a polar grid).  Each of the two goes to the nearest
    vertex turning by :data:`OWN_TURN` or more within :data:`WEDGE_SLACK` of that distance: at
    a vertex of a straight flank the corner cell is a triangle with a 180° angle (on straight
    flanks there is none, and the corners are put there all the same: left, see
    docs/lake-grids-journal.md).
    ``shore`` marks the ring's vertices on the shore: the tip and the end side must be shore (a
    star's centre turns as much inside the water).
    """
    c = [int(i) for i in corners]
    forced = {int(f) for f in forced}
    arc = _arclength_closed(ring)
    s, total = arc
    t = turning(ring, sigma, arc)
    tip = max(c, key=lambda i: t[i])
    if t[tip] < WEDGE_TURN or tip in forced or not shore[tip]:
        return tuple(c)
    h = sigma / 1.5
    x, y = ring[:, 0], ring[:, 1]
    area = 0.5 * abs(float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))))
    if 2.0 * area / total > WEDGE_WIDTH * h:
        return tuple(c)
    # the fourth corner: the weakest, or one of two corners a vertex apart (a chord's end
    # read twice), the one not forced
    gap = [min(abs(s[i] - s[j]), total - abs(s[i] - s[j])) for i, j in zip(c, c[1:] + c[:1], strict=True)]
    k = int(np.argmin(gap))
    twin = [i for i in (c[k], c[(k + 1) % 4]) if i != tip and i not in forced]
    if gap[k] < 0.25 * sigma and twin:
        weak = twin[0]
    else:
        weak = min((i for i in c if i != tip), key=lambda i: t[i])
        if t[weak] >= 2 * SHARP or weak in forced:
            return tuple(c)
    d = h * max(1.0, WEDGE_END / (2.0 * math.sin(math.radians(max(180.0 - t[tip], 5.0)) / 2.0)))
    raw = raw_turning(ring)

    def placed(along: np.ndarray) -> int:  # the vertex nearest d from the tip, one that turns if any
        near = np.abs(along - d)
        ok = np.flatnonzero((near <= WEDGE_SLACK * d) & (raw >= OWN_TURN))
        return int(ok[np.argmin(near[ok])]) if len(ok) else int(np.argmin(near))

    ia, ib = placed((s[tip] - s) % total), placed((s - s[tip]) % total)
    new = sorted({ia, ib} | (set(c) - {tip, weak}))
    n = len(ring)
    # both within the tip's own sides: no other corner between them (round the tip)
    if len(new) != 4 or any(0 < (k - ia) % n < (ib - ia) % n for k in new if k not in (ia, ib)):
        return tuple(c)
    if not 0 < (tip - ia) % n < (ib - ia) % n or not shore[(ia + np.arange((ib - ia) % n + 1)) % n].all():
        return tuple(c)
    return tuple(new)
