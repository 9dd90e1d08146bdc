r"""Blocks split at a crowded tip: a short piece of shore in a block side becomes a side of its own.

Where a cut ends on the shore and a block's side passes its end — the side runs along the cut
and on along a short piece of shore (a flat island end, a blunt peninsula end) up to the block's
corner — that side is two chains: the cut, whose count a ring of other blocks may fix, and the
short piece, which then takes the rest of what the side's opposite asks for.  On held-out
g180782 the 36-cell cut got 4 cells and the 3.9-cell island end 60: ~60 grid lines fanning into
the end (journal: *Fans into island tips*, *Crowded shore pieces*).

Here, where the counts do crowd such a side (the piece's cells per length :data:`TIP_JUMP` or
more times the cut's), the passing block is split by a straight cut from the cut's end across
to its opposite side (:func:`~.tjunction._split`, the "motorcycle" line of a T-junction): both
blocks get a corner there, the short piece and the strip beyond it are a block of their own,
and its count no longer follows the cut's.  The new block is at least as wide at its far end
as the piece is long.  A split is kept only when both blocks are valid with angles of at least
:data:`LEAST_ANGLE` at the new cut's ends, no chain it makes (the piece, the far end's pieces of
the opposite side) is shorter than half the least count's length (:data:`MIN_SHARE`), and the
layout can still be counted.

OFF by default (:data:`SPLIT`; journal *Blocks split at crowded tips*).
"""

from __future__ import annotations

import numpy as np

from .blocks import Piece, _chains_of, block_counts, conform
from .corners import raw_turning

__all__ = ["counted_with_tip_splits"]

#: Split passing blocks at crowded tips (:func:`counted_with_tip_splits`).  OFF: on, a generated
#: channel network's shore leaves the grid by 0.502 cells (``test_shore_tips``, a 7-cell piece at a
#: 4.2× jump); measured in the journal (*Blocks split at crowded tips*, session 24).
SPLIT = False

#: The spacing jump (cells per length of the shore piece against the cut's) from which a
#: side counts as crowded (as :data:`~.tipends.TIP_JUMP`).
TIP_JUMP = 4.0

#: Every chain the split makes (the shore piece, the new cut's far end's pieces of the opposite
#: side) must be at least this share of the least count's length (``max(3, multiple)`` cells): a
#: chain holds at least that many cells, and shorter its cells would be over 2× finer than those
#: of the blocks round it (an interface ratio above 2 instead of the fan; islands 981301: a
#: 1.2-cell piece split off made a strip 4 cells across, its neighbour's cells 4.9× as large).
MIN_SHARE = 0.5
#: The longest shore piece (cells) split off: a longer one is a side in its own right already.
MAX_PIECE = 8.0

#: The least angle (degrees) of either new block at the new cut's two ends.
LEAST_ANGLE = 45.0

#: Splits made at most (each one recounts the layout).
ROUNDS = 6


def _angles(ring: np.ndarray) -> np.ndarray:
    return 180.0 - raw_turning(ring)


def crowded(pieces: list[Piece], h: float, multiple: int):
    """The cells of every piece, and ``(jump, piece, vertex, length of the shore piece)`` of every
    place where a block side passes a cut's end onto a piece of shore that its counts crowd
    (largest jump first)."""
    from ..pointindex import point_key
    from .tipends import cut_beside_shore

    cells, places = cut_beside_shore(pieces, h, multiple)
    least = MIN_SHARE * max(3, multiple)
    out = []
    pos_of: dict[int, dict] = {}
    for pi, (l_cut, s_cut, at), (l_shore, s_shore, _) in places:
        if not least * h <= l_shore <= MAX_PIECE * h or l_cut <= l_shore:
            continue
        jump = s_cut / s_shore
        if jump < TIP_JUMP:
            continue
        if pi not in pos_of:
            pos_of[pi] = {point_key(p): i for i, p in enumerate(pieces[pi].ring)}
        pos = pos_of[pi]
        out += [(float(jump), pi, pos[k], float(l_shore)) for k in at if k in pos]
    out.sort(key=lambda t: -t[0])
    return cells, out


def _split(pieces: list[Piece], pi: int, v: int, piece: float, shortest: float) -> list[Piece] | None:
    """``pieces`` with piece ``pi`` split from its vertex ``v`` across, the new block at least as
    wide at its far end as the shore ``piece`` is long (None: not a sound split; ``shortest``: the
    least length of a chain the split makes at the new cut's far end)."""
    from shapely.geometry import Polygon

    from .tjunction import _split as across

    got = across(pieces[pi], v, wide=piece)
    if got is None:
        return None
    new, cut = got
    ends = (cut[0], cut[-1])
    for pc in new:
        if not Polygon(pc.ring).is_valid:
            return None
        ang = _angles(pc.ring)
        for e in ends:
            i = np.flatnonzero((pc.ring == e).all(axis=1))
            if len(i) and ang[int(i[0])] < LEAST_ANGLE:
                return None
    rings = [p.ring for p in pieces[:pi]] + [p.ring for p in new] + [p.ring for p in pieces[pi + 1 :]]
    olds = pieces[:pi] + new + pieces[pi + 1 :]
    size = float(np.hypot(*np.ptp(np.vstack(rings), axis=0)))
    out = []
    for k, (r, p) in enumerate(zip(conform(rings, 1e-9 * size), olds, strict=True)):
        i0, i1, i2, i3 = sorted(int(np.argmin(np.hypot(*(r - p.ring[c]).T))) for c in p.corners)
        if len({i0, i1, i2, i3}) != 4:
            return None
        out.append(Piece(r, (i0, i1, i2, i3), f"b{k}"))
    # no new chain at the new cut's far end shorter than the shore piece may be (:data:`MIN_SHARE`):
    # an end that falls just beside a corner or another cut's end makes a sliver chain
    from ..pointindex import point_key

    _, old_pts, _ = _chains_of(pieces)
    _, new_pts, _ = _chains_of(out)
    far = point_key(cut[-1])
    for key, p in new_pts.items():
        ends = (point_key(p[0]), point_key(p[-1]))
        if key not in old_pts and far in ends and float(np.hypot(*np.diff(p, axis=0).T).sum()) < shortest:
            return None
    return out


def counted_with_tip_splits(pieces: list[Piece], h: float, *, multiple: int = 1):
    """``(pieces, cells)``: the cells of every piece (:func:`~.blocks.block_counts`), and where
    a block side's counts crowd a short piece of shore beside a cut, the block split there
    (see the module) and the layout counted again; only with :data:`SPLIT`."""
    from ..errors import TopologyError

    if not SPLIT:
        return pieces, block_counts(pieces, h, multiple=multiple)
    cells, todo = crowded(pieces, h, multiple)
    for _ in range(ROUNDS):
        for _jump, pi, v, piece in todo:
            new = _split(pieces, pi, v, piece, MIN_SHARE * max(3, multiple) * h)
            if new is None:
                continue
            try:
                more, again = crowded(new, h, multiple)
            except TopologyError:
                continue
            pieces, cells, todo = new, more, again
            break
        else:
            break
    return pieces, cells
