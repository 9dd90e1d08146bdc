r"""Pieces whose side runs round a land tip or past a headland: split from the tip.

A channel that turns round a land tongue (a U-turn), or a basin block whose side passes a
headland into the pocket behind it, is often left whole by the greedy split
(:func:`~.split.best_split`): its corner cost reads the shore's turning at 1.5 cells, where a
rounded tip or a headland turns by 30–60° at any one vertex, so the side pays a few mild bends and
any cut from the tip costs more in corners than it saves.  The grid sees the whole turn at the
scale of the block: the lines from the opposite side crowd into the tip or the pocket, and most of
the block's nodes end beyond 3° (held-out lakes of 40–100 blocks: a few such blocks hold a large
share of a lake's bad nodes).

:func:`tip_split` reads the piece's boundary again at half its width (twice its area over its
perimeter, as :func:`~.split._normal_cuts` reads bays) and, where a side's reflex bend there turns
by :data:`TIP_TURN` or more (a tip, no corner of the piece within 1.5 cells), cuts from the vertex
where it turns most: straight on along either flank (read at that scale), along the bisector of the
tip, or at right angles onto the far side, each admissible cut's pieces split greedily again, the
cheapest result in which no piece fans or wraps.  Such a split is not judged by the corner cost
(which is what kept the piece whole): the layout with these splits is one more candidate of the
layout choice (:mod:`.choice`), which keeps it only where its coarse grid is clearly more orthogonal.
"""

from __future__ import annotations

import contextlib
import contextvars
import math

import numpy as np

from .memo import copied, digest, remembered, watching

__all__ = [
    "TIP_SCALE",
    "TIP_TURN",
    "noted_pinch",
    "noted_tips",
    "splits",
    "splitting_tips",
    "tip_split",
    "tips_split",
    "untipped",
    "watching_tips",
]

#: The boundary is read at this share of the piece's width (at least the corners' scale).
TIP_SCALE = 0.5

#: A side's reflex bend at that scale turning by at least this (degrees) is a tip to cut from.
TIP_TURN = 60.0

_on: contextvars.ContextVar[bool] = contextvars.ContextVar("tips_split", default=False)


@contextlib.contextmanager
def splitting_tips():
    """Layouts drawn within this context split the pieces round land tips (:func:`untipped`)."""
    token = _on.set(True)
    try:
        yield
    finally:
        _on.reset(token)


def tips_split() -> bool:
    """True within :func:`splitting_tips`."""
    return _on.get()


_seen: contextvars.ContextVar[list | None] = contextvars.ContextVar("tips_seen", default=None)


@contextlib.contextmanager
def watching_tips():
    """Yields a list to which a layout drawn within this context (not within
    :func:`splitting_tips`) adds every piece :func:`untipped` would look at that has a tip
    (:func:`_tip`), with the arguments :func:`untipped` would split it with (:func:`noted_tips`).
    Where none of them splits (:func:`splits`), the same draw within :func:`splitting_tips` makes
    the same layout, so the layout choice's tip draw (:func:`~meshcore.layout.choice.chosen`) is
    skipped."""
    with watching(_seen) as box:
        yield box


def noted_tips(pieces: list, sigma: float, min_width: float, normal: bool, thin: bool) -> None:
    """Within :func:`watching_tips`: note the pieces of ``pieces`` (``(ring, forced)``, as
    :func:`untipped` takes them, with its other arguments) without forced corners that have a tip."""
    box = _seen.get()
    if box is not None:
        box += [
            (np.array(r), sigma, min_width, normal, thin)
            for r, fc in pieces
            if not len(fc) and _tip(r, sigma) is not None
        ]


def noted_pinch() -> None:
    """Within :func:`watching_tips`: note that the tip draw would bend a cut through a land tip
    (:mod:`.pinch`)."""
    box = _seen.get()
    if box is not None:
        box.append(None)


def splits(noted: list) -> bool:
    """Whether :func:`tip_split` splits any of the pieces ``noted`` (:func:`watching_tips`), or a
    cut is bent through a tip there (:func:`noted_pinch`)."""
    return any(args is None or _kept_split(*args) is not None for args in noted)


def _kept_split(ring: np.ndarray, sigma: float, min_width: float, normal: bool, thin: bool):
    """:func:`tip_split`, remembered within :func:`~.memo.remembering` (keyed by a 128-bit digest
    of the ring and the arguments): :func:`splits` asks before the tip draw, which asks again
    (copies are returned: callers own what they get)."""
    key = ("tip", digest(ring), np.shape(ring), float(sigma), float(min_width), normal, thin)
    got = remembered(key, lambda: tip_split(ring, sigma=sigma, min_width=min_width, normal=normal, thin=thin))
    return None if got is None else copied(got)


def _tip(ring: np.ndarray, sigma: float) -> tuple[int, float] | None:
    """``(vertex, scale)`` of the sharpest reflex bend of a side of ``ring`` at its own scale
    (:data:`TIP_SCALE`, :data:`TIP_TURN`; no corner within ``sigma``), or None."""
    from .corners import _arclength_closed, turning
    from .split import corners_of
    from .width import width

    corners, cost = corners_of(ring, sigma)
    if corners is None or not math.isfinite(cost):
        return None
    arc = _arclength_closed(ring)
    s, total = arc
    big = max(sigma, TIP_SCALE * width(ring))
    tb = turning(ring, big, arc)
    d = np.abs(s[None, :] - s[list(corners)][:, None])
    near = (np.minimum(d, total - d) < sigma).any(axis=0)
    side = np.where(near, np.inf, tb)
    v = int(np.argmin(side))
    return (v, big) if side[v] <= -TIP_TURN else None


def _cuts_from(ring: np.ndarray, v: int, big: float):
    """Candidate cuts ``(piece_a, piece_b, segment)`` from vertex ``v``: on along either flank
    (read ``big`` along the ring), along the tip's bisector, and square onto the far side."""
    from .corners import _arclength_closed, _edges
    from .split import _point_along, _ray_to_boundary, _split_ring

    s, total = _arclength_closed(ring)
    e = _edges(ring)
    back = _point_along(ring, s, total, s[v] - big)
    ahead = _point_along(ring, s, total, s[v] + big)
    dirs = [ring[v] - back, ring[v] - ahead]
    u = ahead - back
    dirs.append(np.array([-u[1], u[0]]))  # the inward normal of the chord across the tip
    # square onto the far side: the feet of the perpendiculars from v inside edges, nearest first
    L2 = np.maximum((e * e).sum(axis=1), 1e-300)
    w = ((ring[v] - ring) * e).sum(axis=1) / L2
    n = len(ring)
    feet = [
        (float(np.hypot(*(ring[k] + w[k] * e[k] - ring[v]))), k)
        for k in range(n)
        if 1e-9 < w[k] < 1 - 1e-9 and min((k - v) % n, (v - k) % n) > 1
    ]
    for _, k in sorted(feet)[:4]:
        dirs.append(ring[k] + w[k] * e[k] - ring[v])
    out = []
    for d in dirs:
        nd = math.hypot(*d)
        hit = _ray_to_boundary(ring, v, d / nd, e) if nd > 0 else None
        res = None if hit is None else _split_ring(ring, v, *hit)
        if res is not None:
            out.append((res[0], res[1], np.array([ring[v], res[2]])))
    return out


def tip_split(
    ring: np.ndarray,
    *,
    sigma: float,
    min_width: float,
    normal: bool = True,
    thin: bool = False,
):
    """``(pieces, cuts)`` of ``ring`` split from the tip its side runs round (see the module), or
    None (no such tip, or no admissible cut from it whose pieces, split greedily again, neither fan
    nor wrap)."""
    import shapely

    from .fans import fans, wraps
    from .split import _cut_options, best_split

    poly = shapely.Polygon(ring)
    room = poly.buffer(1e-9 * math.sqrt(poly.area))
    tip = _tip(ring, sigma)
    if tip is None:
        return None
    cuts = [c for c in _cuts_from(ring, *tip) if room.covers(shapely.LineString(c[2]))]
    best = None
    for pieces, segs, _ in _cut_options(cuts, sigma, min_width, thin):
        out_p, out_c, total = [], list(segs), 0.0
        for pc, fc in pieces:
            pp, cc, c = best_split(pc, sigma=sigma, min_width=min_width, depth=2, forced=fc, normal=normal, thin=thin)
            out_p += pp
            out_c += cc
            total += c
        if any(not len(f) and (fans(p, sigma) or wraps(p, sigma)) for p, f in out_p):
            continue
        if best is None or total < best[2]:
            best = (out_p, out_c, total)
    return None if best is None else best[:2]


def untipped(pieces: list, cuts: list, sigma: float, min_width: float, normal: bool, thin: bool):
    """``pieces`` (``(ring, forced)``) and ``cuts`` with every piece round a land tip split from
    it (:func:`tip_split`; pieces with forced corners as they are)."""
    out: list = []
    for ring, fc in pieces:
        got = None if len(fc) else _kept_split(ring, sigma, min_width, normal, thin)
        out += [(ring, fc)] if got is None else got[0]
        cuts = cuts if got is None else [*cuts, *got[1]]
    return out, cuts
