r"""Cut lines across the channels: chords placed along the skeleton's branches.

A **chord** is a straight segment across a channel, from shore to shore, at right angles to
the branch of the skeleton it crosses (so, where the banks are parallel, at right angles to
both banks: the block corners it makes are right angles).  Along every branch chords are
placed

* where the branch leaves a **junction**: just outside the junction's inscribed circle (the
  chord's own circle touches the junction's), so the junction zone holds the meeting of the
  arms and nothing more;
* before a **tip**: about one channel width before the end of the water, so the tip zone is
  about square;
* in between, at most ``spacing`` channel widths apart (long arms become chains of blocks,
  each only gently curved).

A chord that would leave the water, cross another chord or land too close to one is dropped;
the zones then simply grow.  Everything is measured in local channel widths, so the same
rules serve a 100-m creek and a 10-km reservoir arm.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .skeleton import Branch, Skeleton

__all__ = ["Chord", "place_chords"]

#: chords at the arms' mouths (``mouths=True``): only at junctions of at most this many arms,
#: for arms at most this many ``min_length`` wide, this many arm half-widths past the mouth
MOUTH_MAX_DEGREE = 4
MOUTH_MAX_WIDTH = 3.5
MOUTH_MARGIN = 0.05

#: A chord end this many cells (``min_length / 2``) or less from an outline vertex where the
#: shore turns by :data:`SNAP_TURN` degrees or more goes onto that vertex.  A ray hit a hair
#: from a corner of a few-point outline (0.02 m down a side of a hand-drawn polygon, 2e-4 cells)
#: left a block a side piece far shorter than a cell that turns as much as the corner: a cell
#: edge of 6e-5 cells and a fan of four cells there.  Only a hair: ends within half a cell were
#: moved on many generated lakes (0.01-0.5 cells from a vertex), each move reshuffled the layout
#: downstream, and the reshuffles were mixed (``dendritic 998803``: 2 folded cells).
SNAP = 0.01
SNAP_TURN = 30.0


@dataclass(frozen=True, slots=True, eq=False)
class Chord:
    """A cut across branch ``branch`` at arc length ``s``: ``points`` (2, 2), shore to shore."""

    branch: int
    s: float
    points: np.ndarray
    kind: str  # "junction" | "mouth" | "tip" | "middle" | "ring" | "passage"


def _arclength(p: np.ndarray) -> np.ndarray:
    return np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(p, axis=0).T))])


def _at(s_all: np.ndarray, values: np.ndarray, s: float) -> np.ndarray:
    if values.ndim == 1:
        return np.interp(s, s_all, values)
    return np.array([np.interp(s, s_all, values[:, k]) for k in range(values.shape[1])])


def _tangent(br: Branch, s_all: np.ndarray, s: float, window: float) -> np.ndarray:
    """Unit tangent of the branch at ``s``, averaged over ``± window`` (smooths Voronoi zig-zag)."""
    a = _at(s_all, br.points, max(0.0, s - window))
    b = _at(s_all, br.points, min(s_all[-1], s + window))
    t = b - a
    n = math.hypot(*t)
    if n == 0.0:
        t = br.points[-1] - br.points[0]
        n = math.hypot(*t) or 1.0
    return t / n


def _candidates(poly, room, br: Branch, s_all: np.ndarray, step: float, min_length: float):
    """Chords normal to the branch at regularly spaced arc lengths, with their bank angles.

    Returns ``(s, segments (m, 2, 2), error (m,))``: ``error`` is the larger deviation (degrees)
    from a right angle where the chord meets the two banks; ``inf`` where no chord exists
    (the normal misses the facing bank, leaves the water, or is far longer than the width).
    """
    import shapely

    L = s_all[-1]
    m = max(2, math.ceil(L / step) + 1)
    s = np.linspace(0.0, L, m)
    c = np.column_stack([np.interp(s, s_all, br.points[:, 0]), np.interp(s, s_all, br.points[:, 1])])
    r = np.interp(s, s_all, br.radius)
    win = np.maximum(r, 1e-12)
    a = np.column_stack([np.interp(np.maximum(s - win, 0), s_all, br.points[:, k]) for k in (0, 1)])
    b = np.column_stack([np.interp(np.minimum(s + win, L), s_all, br.points[:, k]) for k in (0, 1)])
    t = b - a
    t /= np.maximum(np.hypot(*t.T), 1e-300)[:, None]
    n = np.column_stack([-t[:, 1], t[:, 0]])
    rings = [np.asarray(poly.exterior.coords), *(np.asarray(h.coords) for h in poly.interiors)]
    seg_a = np.vstack([rg[:-1] for rg in rings])
    seg_b = np.vstack([rg[1:] for rg in rings])

    ends = np.full((m, 2, 2), np.nan)
    err = np.zeros(m)
    for side, sign in ((1, 1.0), (0, -1.0)):
        p, q = _local_hits(c, sign * n, seg_a, seg_b, 4.0 * r)
        ends[:, side] = p
        tb = q / np.maximum(np.hypot(*q.T), 1e-300)[:, None]
        dev = np.degrees(np.arcsin(np.clip(np.abs((tb * n).sum(axis=1)), 0.0, 1.0)))
        err = np.where(np.isfinite(p[:, 0]), np.maximum(err, dev), np.inf)
    length = np.hypot(*(ends[:, 1] - ends[:, 0]).T)
    bad = ~np.isfinite(length) | (length > 6.0 * r) | (length < 1.0 * r) | (length < min_length)
    err[bad] = np.inf
    ok = np.flatnonzero(np.isfinite(err))
    if len(ok):
        lines = shapely.linestrings(ends[ok])
        inside = shapely.covers(room, lines)  # the prepared room first: fast on dense shores
        err[ok[~inside]] = np.inf
    return s, ends, err


def _local_hits(c, d, seg_a, seg_b, reach, group: int = 48):
    """:func:`_ray_hits` for consecutive groups of rays, each against the shore within reach."""
    hit = np.full((len(c), 2), np.nan)
    tan = np.full((len(c), 2), np.nan)
    smin, smax = np.minimum(seg_a, seg_b), np.maximum(seg_a, seg_b)
    for lo in range(0, len(c), group):
        sl = slice(lo, lo + group)
        rr = float(reach[sl].max())
        a, b = c[sl].min(axis=0) - rr, c[sl].max(axis=0) + rr
        near = ~((smax[:, 0] < a[0]) | (smin[:, 0] > b[0]) | (smax[:, 1] < a[1]) | (smin[:, 1] > b[1]))
        if near.any():
            hit[sl], tan[sl] = _ray_hits(c[sl], d[sl], seg_a[near], seg_b[near], reach[sl])
    return hit, tan


def _ray_hits(c, d, seg_a, seg_b, reach):
    """First crossing of the rays ``c + t d`` (0 < t ≤ reach) with the shore segments.

    Returns the hit points (nan where none) and the tangent of the segment hit.
    """
    e = seg_b - seg_a  # (k, 2)
    # solve c + t d = a + u e  for every ray × segment (chunked to bound memory)
    m = len(c)
    hit = np.full((m, 2), np.nan)
    tan = np.full((m, 2), np.nan)
    chunk = max(1, 2_000_000 // max(len(e), 1))
    for lo in range(0, m, chunk):
        cc, dd, rr = c[lo : lo + chunk, None, :], d[lo : lo + chunk, None, :], reach[lo : lo + chunk, None]
        den = dd[..., 0] * e[None, :, 1] - dd[..., 1] * e[None, :, 0]
        w = seg_a[None] - cc
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (w[..., 0] * e[None, :, 1] - w[..., 1] * e[None, :, 0]) / den
            u = (w[..., 0] * dd[..., 1] - w[..., 1] * dd[..., 0]) / den
        good = (np.abs(den) > 1e-300) & (t > 0) & (t <= rr) & (u >= 0) & (u <= 1)
        t = np.where(good, t, np.inf)
        k = np.argmin(t, axis=1)
        tk = t[np.arange(len(k)), k]
        found = np.isfinite(tk)
        idx = np.arange(lo, lo + len(k))[found]
        hit[idx] = c[idx] + tk[found, None] * d[idx]
        tan[idx] = e[k[found]]
    return hit, tan


def _end_offset(
    sk: Skeleton, br: Branch, s_all: np.ndarray, end: int, degree: np.ndarray, min_length: float, mouths: bool = False
) -> tuple[float, bool]:
    """Arc length from the branch's end ``end`` (0: start, 1: finish) to its first chord, and
    whether that chord is at the arm's mouth (``mouths``, see :func:`place_chords`)."""
    node = br.a if end == 0 else br.b
    P = br.points if end == 0 else br.points[::-1]
    R = br.radius if end == 0 else br.radius[::-1]
    s_loc = _arclength(P)
    dist = np.hypot(*(P - sk.nodes[node]).T)
    # junction: outside its inscribed circle (the chord's circle touches it);
    # tip: about one channel width before the end of the water
    need = sk.node_radius[node] + R
    if degree[node] < 3:
        need = np.maximum(need, np.maximum(2.0 * R, min_length))
    ok = np.flatnonzero(dist >= need)
    if not len(ok):
        return math.inf, False
    r_arm, r_node = float(R[ok[0]]), float(sk.node_radius[node])
    if mouths and 3 <= degree[node] <= MOUTH_MAX_DEGREE and 2.0 * r_arm <= MOUTH_MAX_WIDTH * min_length:
        # the arm's mouth: where a chord as wide as the arm ends on the junction's inscribed
        # circle, which touches the shore at the reflex corners between the arms
        d = math.sqrt(max(r_node * r_node - r_arm * r_arm, 0.0)) + MOUTH_MARGIN * r_arm
        at = np.flatnonzero(dist >= d)
        if len(at) and at[0] < ok[0]:
            return float(s_loc[at[0]]), True
    return float(s_loc[ok[0]]), False


def _pick(s: np.ndarray, err: np.ndarray, u_of_s: np.ndarray, target: float, window: float, limit: float):
    """Index of the best candidate within ``window`` widths of ``target`` (None if none is good)."""
    near = np.abs(u_of_s - target) <= window
    score = np.where(near & (err <= limit), err + 5.0 * np.abs(u_of_s - target), np.inf)
    k = int(np.argmin(score))
    return k if np.isfinite(score[k]) else None


def place_chords(
    poly, sk: Skeleton, *, min_length: float, spacing: float = 4.0, max_angle: float = 30.0, mouths: bool = False
) -> list[Chord]:
    """Chords along every branch of ``sk`` (see the module docstring).

    ``min_length`` is the shortest chord (a block needs a few cells across), ``spacing`` the
    largest distance between consecutive chords, in channel widths; ``max_angle`` the largest
    deviation from a right angle where a chord meets a bank.  A tip zone is kept at least
    ``min_length`` long.  ``mouths``: at a junction of three or four arms at most
    ``MOUTH_MAX_WIDTH · min_length`` wide, an arm's junction chord lies at its mouth, where a
    chord as wide as the arm ends on the junction's inscribed circle (through the reflex shore
    corners between the arms); two such chords may meet there.  Off by default: measured mixed
    (docs/lake-grids-journal.md).
    """
    import shapely
    from shapely.geometry import LineString

    degree = sk.degree()
    chords: list[Chord] = []
    room = poly.buffer(1e-9 * math.sqrt(poly.area))  # the water, a hair wider (cuts end on the shore)
    shapely.prepare(room)
    corners = _sharp_vertices(poly, SNAP_TURN)
    tips = _land_tips(poly, 0.75 * min_length) if AVOID_TIPS else np.zeros((0, 2))
    for k, br in enumerate(sk.branches):
        s_all = _arclength(br.points)
        L = s_all[-1]
        if L <= 0:
            continue
        step = 0.25 * float(np.min(br.radius[br.radius > 0], initial=L))
        s, ends, err = _candidates(poly, room, br, s_all, step, min_length)
        err = _grazing(ends, err, tips, 0.5 * min_length)
        w = 2.0 * np.maximum(br.radius, 1e-12)
        u_all = np.concatenate([[0.0], np.cumsum(np.diff(s_all) / (0.5 * (w[1:] + w[:-1])))])
        u = np.interp(s, s_all, u_all)
        picks: list[tuple[int, str]] = []
        cycle = br.a == br.b and degree[br.a] == 2  # an island ring with nothing attached
        if cycle:
            n = max(4, math.ceil(u[-1] / spacing))
            for j in range(n):
                i = _pick(s, err, u, u[-1] * (j + 0.5) / n, 0.5 * u[-1] / n, max_angle)
                if i is not None:
                    picks.append((i, "ring"))
        else:
            e0, m0 = _end_offset(sk, br, s_all, 0, degree, min_length, mouths)
            e1, m1 = _end_offset(sk, br, s_all, 1, degree, min_length, mouths)
            s0, s1 = e0, L - e1
            u0, u1 = np.interp(s0, s_all, u_all), np.interp(s1, s_all, u_all)
            if s1 - s0 > 0 and u1 - u0 >= 0.5:
                n_mid = max(0, math.ceil((u1 - u0) / spacing) - 1)
                targets = [(u0, _end_kind(degree[br.a], m0)), (u1, _end_kind(degree[br.b], m1))]
                targets += [(u0 + (u1 - u0) * (j + 1) / (n_mid + 1), "middle") for j in range(n_mid)]
                for tu, kind in targets:
                    lo = 0.0 if kind != "middle" else 0.25 * spacing
                    win = 0.5 if kind == "middle" else 0.35
                    i = _pick(s, err, u, tu, win + lo, max_angle)
                    if i is not None:
                        picks.append((i, kind))
            elif (degree[br.a] >= 3) != (degree[br.b] >= 3):
                # an arm too short for a chord at each end: one chord that gives its tip a
                # block of its own (the junction zone is smaller for it)
                tip_end = 1 if degree[br.a] >= 3 else 0
                s_tip = s1 if tip_end == 1 else s0
                s_tip = min(max(s_tip, 0.25 * L), 0.75 * L)
                target = 0.5 * (u0 + u1) if s1 > s0 else float(np.interp(s_tip, s_all, u_all))
                i = _pick(s, err, u, target, 0.5, max_angle)
                if i is not None:
                    picks.append((i, "junction"))
            loop = br.a == br.b
            need = 2 if loop else (1 if degree[br.a] >= 3 and degree[br.b] >= 3 else 0)
            if len(picks) < need:
                # junction to junction (or a loop round an island) with no room for end
                # chords: chords at the narrowest good places separate the junction zones
                r = np.interp(s, s_all, br.radius)
                score = np.where(err <= max_angle, r * (1.0 + err / 90.0), np.inf)
                picks = []
                for _ in range(need):
                    i = int(np.argmin(score))
                    if not np.isfinite(score[i]):
                        break
                    picks.append((i, "passage"))
                    score[np.abs(s - s[i]) < L / 3.0] = np.inf
        for i, kind in picks:
            chords.append(Chord(k, float(s[i]), _snapped(ends[i], corners, room, 0.5 * SNAP * min_length), kind))
    # drop chords that cross or crowd an earlier one (junction and tip chords first).  Two
    # chords crowd each other when they come closer than a quarter of the SHORTER one: the
    # zone between them is at most as wide as that chord's channel.  (A quarter of the chord
    # being placed dropped the long chord across a wide lobe whose end came near a narrow
    # arm's chord at a blunt notch: the lobe then went into the junction's block, one side
    # wrapped round the whole lobe, and the grid left the shore by 1.6 cells.)
    order = {"passage": 0, "mouth": 1, "junction": 1, "tip": 2, "ring": 3, "middle": 4}
    chords.sort(key=lambda c: order[c.kind])
    kept: list[Chord] = []
    lines: list = []
    for c in chords:
        ls = LineString(c.points)
        if any(_clash(c, ls, k, o) for k, o in zip(kept, lines, strict=True)):
            continue
        kept.append(c)
        lines.append(ls)
    return kept


def _sharp_vertices(poly, turn: float) -> np.ndarray:
    """The vertices (m, 2) of ``poly``'s rings where the shore turns by ``turn`` degrees or more."""
    from .corners import raw_turning

    out = []
    for ring in (poly.exterior, *poly.interiors):
        r = np.asarray(ring.coords)[:-1]
        out.append(r[np.abs(raw_turning(r)) >= turn])
    return np.vstack(out) if out else np.empty((0, 2))


def _snapped(ends: np.ndarray, corners: np.ndarray, room, tol: float) -> np.ndarray:
    """The chord ``ends`` (2, 2) with each end within ``tol`` of a sharp vertex (``corners``)
    moved onto the nearest one, when the chord stays in the water (``room``)."""
    import shapely

    out = ends.copy()
    if not len(corners):
        return out
    for e in range(2):
        d = np.hypot(*(corners - ends[e]).T)
        j = int(np.argmin(d))
        if 0.0 < d[j] <= tol:
            moved = out.copy()
            moved[e] = corners[j]
            if shapely.covers(room, shapely.linestrings(moved)):
                out = moved
    return out


#: Chords that pass close by a land tip (:data:`TIP_TURN`, :data:`TIP_GAP`) are not taken (off:
#: measured mixed).  Saimaa at 10 000 cells: 1 folded cell -> 0, mean deviation 10.09 -> 9.95°;
#: Lake of the Woods 4.12 -> 1.90°; fresh_sweep base 861400 (15 000 cells): 11 of 45 change, none
#: folded either way, within 3° islands 861705 99.3 -> 90.5 %, 861704 89.4 -> 85.6 %, 861703
#: 72.3 -> 73.7 %, round arms 861805 91.7 -> 93.2 %, every interface ratio <= 2 on 39 -> 37;
#: ``--more`` 861400: >= 90 % within 3° 19 -> 21 of 27 (dendritic 862101 85.1 -> 94.9 %, headlands
#: 862003 84.4 -> 81.4 %) (docs/lake-grids-journal.md, "Chords beside land tips").
AVOID_TIPS = False
#: A shore vertex where the water turns right by more than this (degrees, read over 1.5 cells as
#: block corners are) is a land tip a chord must not pass close by.
TIP_TURN = 80.0
#: ... closer than this (cells), unless it ends there: the block beyond wraps round the tip in a
#: sliver whose side bends by the tip's turn (Saimaa at 10 000 cells: a chord 0.87 cells from a
#: tip turning 90°, a non-convex cell from the coarsest level on that no repair removed).
TIP_GAP = 1.0


def _land_tips(poly, sigma: float) -> np.ndarray:
    """The shore vertices turning right (into the water) by more than :data:`TIP_TURN` at scale
    ``sigma``: the peaks, one a stretch of arc of ``sigma``."""
    from .corners import _arclength_closed, _sharp_peaks, turning

    out = []
    for ring in [np.asarray(poly.exterior.coords)[:-1], *(np.asarray(h.coords)[:-1] for h in poly.interiors)]:
        if len(ring) < 4:
            continue
        arc = _arclength_closed(ring)
        t = turning(ring, sigma, arc)
        out += [ring[i] for i in _sharp_peaks(-t, arc[0], arc[1], sigma, TIP_TURN)]
    return np.asarray(out, dtype=float).reshape(-1, 2)


def _grazing(ends: np.ndarray, err: np.ndarray, tips: np.ndarray, h: float) -> np.ndarray:
    """``err`` with the chords (``ends``) that pass within :data:`TIP_GAP` cells of a land tip
    without ending near it made unusable (``inf``)."""
    ok = np.flatnonzero(np.isfinite(err))
    if not len(ok) or not len(tips):
        return err
    from ..segments import feet

    err = err.copy()
    for i in ok:
        a, b = ends[i, 0], ends[i, 1]
        dist, _ = feet(np.repeat(a[None], len(tips), 0), np.repeat(b[None], len(tips), 0), tips)
        off_ends = np.minimum(np.hypot(*(tips - a).T), np.hypot(*(tips - b).T)) > 0.5 * h
        if np.any((dist < TIP_GAP * h) & off_ends):
            err[i] = np.inf
    return err


def _clash(c: Chord, ls, k: Chord, o) -> bool:
    """Whether chord ``c`` (line ``ls``) crosses or crowds the kept chord ``k`` (line ``o``);
    two mouth chords may meet at the reflex corner between their arms."""
    if c.kind == "mouth" and k.kind == "mouth":
        return bool(ls.crosses(o))
    return bool(ls.distance(o) < 0.25 * min(ls.length, o.length))


def _end_kind(deg: int, mouth: bool = False) -> str:
    return "tip" if deg < 3 else ("mouth" if mouth else "junction")
