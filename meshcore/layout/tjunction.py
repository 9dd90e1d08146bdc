r"""When cell counts cannot agree: carry T-junctions across their blocks.

A T-junction — the end of a neighbour's side in the middle of a block's side — couples the
counts of the chains on either side of it.  Round an island such couplings can contradict
each other (``a + e = a`` with ``e ≥ 1``): no integer counts exist.  The cure is the one of
quad layouts ("motorcycle" lines): continue the T across its block, straight to the opposite
side, splitting the block in two.  A layout without T-junctions always has counts (every
block's opposite sides are single chains, and chains equal along a sheet of blocks can all
take the same count), so :func:`extend_t_junctions` is applied, round after round, only
while the counts are infeasible.
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from ..pointindex import point_key, point_keys
from .blocks import Piece, _chains_of

__all__ = ["extend_t_junctions", "t_junctions"]


def t_junctions(pieces: list[Piece]) -> list[tuple[int, int]]:
    """``(piece, vertex)`` of every break between chains inside a block side."""
    side_chains, _chain_pts, _ = _chains_of(pieces)
    out = []
    for pi, pc in enumerate(pieces):
        pos = {k: i for i, k in enumerate(point_keys(pc.ring))}
        corners = {point_key(pc.ring[c]) for c in pc.corners}
        for side in ("bottom", "right", "top", "left"):
            keys = side_chains[(pi, side)]
            for a, b in itertools.pairwise(keys):
                shared = {a[0], a[-1]} & {b[0], b[-1]}
                for p in shared:
                    if p not in corners:
                        out.append((pi, pos[p]))
    return sorted(set(out))


def _arc(ring: np.ndarray, a: int, b: int) -> np.ndarray:
    n = len(ring)
    return np.array([ring[(a + t) % n] for t in range((b - a) % n + 1)])


def _at_fraction(line: np.ndarray, f: float):
    s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(line, axis=0).T))])
    u = f * s[-1]
    k = min(int(np.searchsorted(s, u, side="right")) - 1, len(line) - 2)
    t = (u - s[k]) / max(s[k + 1] - s[k], 1e-300)
    return k, t, line[k] + t * (line[k + 1] - line[k])


def _split(pc: Piece, v: int, wide: float = 0.0):
    """Split ``pc`` by a straight cut from its vertex ``v`` across to the opposite side (at the
    same fraction of it; ``wide``: the cut's far end at least this far along the opposite side
    from its corner nearer ``v``, where that side is long enough: a strip as wide at both ends)."""
    from shapely.geometry import LineString, Polygon

    r, c = pc.ring, list(pc.corners)
    n = len(r)
    side = next(k for k in range(4) if 0 < (v - c[k]) % n < (c[(k + 1) % 4] - c[k]) % n)
    this = _arc(r, c[side], c[(side + 1) % 4])
    s_this = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(this, axis=0).T))])
    f = s_this[(v - c[side]) % n] / s_this[-1]
    opp_a, opp_b = c[(side + 2) % 4], c[(side + 3) % 4]
    opp = _arc(r, opp_a, opp_b)  # runs the other way: fraction 1 − f
    u = 1.0 - f
    if wide > 0.0:
        L_opp = float(np.hypot(*np.diff(opp, axis=0).T).sum())
        if 2.0 * wide < L_opp:  # the fraction from the nearer corner, at least wide / L_opp
            u = max(u, wide / L_opp) if f >= 0.5 else min(u, 1.0 - wide / L_opp)
    k, t, q = _at_fraction(opp, u)
    poly = Polygon(r)
    room = poly.buffer(1e-9 * math.sqrt(poly.area))
    cut = np.array([r[v], q])
    if not room.covers(LineString(cut)):
        # a curved block: the transfinite-interpolation line of the block instead
        left = _arc(r, c[(side + 3) % 4], c[side])[::-1]  # from this side's start, across
        right = _arc(r, c[(side + 1) % 4], c[(side + 2) % 4])  # from this side's end, across
        eta = np.linspace(0.0, 1.0, 12)[1:-1]
        pts = [r[v]]
        for e in eta:
            pl = _at_fraction(left, e)[2]
            pr = _at_fraction(right, e)[2]
            lin = (1 - e) * r[v] + e * q
            edge_mix = (1 - f) * (pl - ((1 - e) * left[0] + e * left[-1])) + f * (
                pr - ((1 - e) * right[0] + e * right[-1])
            )
            pts.append(lin + edge_mix)
        pts.append(q)
        cut = np.array(pts)
        if not room.covers(LineString(cut)) or not LineString(cut).is_simple:
            return None
    # insert q into the ring
    j = (opp_a + k) % n
    if t <= 1e-9:
        qi, ring = j, r
    elif t >= 1 - 1e-9:
        qi, ring = (j + 1) % n, r
    else:
        ring = np.insert(r, j + 1, q, axis=0)
        qi = j + 1
        c = [ci + 1 if ci > j else ci for ci in c]
        v = v + 1 if v > j else v
    inner = cut[1:-1]
    a_ring = np.vstack([_arc(ring, v, qi), inner[::-1]]) if len(inner) else _arc(ring, v, qi)
    b_ring = np.vstack([_arc(ring, qi, v), inner]) if len(inner) else _arc(ring, qi, v)
    pieces = []
    for sub, cs in (
        (a_ring, [ring[v], ring[c[(side + 1) % 4]], ring[c[(side + 2) % 4]], ring[qi]]),
        (b_ring, [ring[qi], ring[c[(side + 3) % 4]], ring[c[side]], ring[v]]),
    ):
        idx = sorted(int(np.argmin(np.hypot(*(sub - p).T))) for p in cs)
        if len(set(idx)) != 4:
            return None
        pieces.append(Piece(sub, tuple(idx), pc.name))
    return pieces, cut


def extend_t_junctions(pieces: list[Piece], todo=None):
    """One round: every T-junction (``todo``, :func:`t_junctions` of the pieces if not given)
    continued across its block.  Returns new pieces and cuts."""
    if todo is None:
        todo = t_junctions(pieces)
    by_piece: dict[int, int] = {}
    for pi, v in todo:
        by_piece.setdefault(pi, v)  # one split per block and round (its indices change)
    out, cuts = [], []
    for pi, pc in enumerate(pieces):
        if pi in by_piece:
            res = _split(pc, by_piece[pi])
            if res is not None:
                new, cut = res
                out += new
                cuts.append(cut)
                continue
        out.append(pc)
    return out, cuts
