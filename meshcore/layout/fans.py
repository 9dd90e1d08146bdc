r"""Pieces that would fan: a split for a piece whose four sides span far less than its water.

The greedy split (:func:`~.split.best_split`) stops when no single cut lowers the corner cost.
Its cost sees corners and sharp bends; a piece whose corners bunch on one part of its boundary
costs little more than a good one, yet its grid fans out from two short sides across the whole
piece.  Two measures of the piece with its chosen corners: the bulge ``R``
(:func:`~.corners.bulge_ratio`: the area over the product of the mean lengths of its two pairs
of opposite sides; a rectangle 1, a disc with four corners a quarter apart 1.27) and the ratio
of opposite sides.  On generated lakes the folded ones had ``R`` of 5–6 — a round lobe behind
a narrow neck and the strip of water beside it as one block 4 cells across and 184 along
(`headlands(791603, n=9)`, 43 folded cells), a needle island's far side run round by one block
side (`small_islands(760001, n_islands=10)`, the island lost) — or ``R`` 1.65 with both pairs of
opposite sides 11–12× apart: a round basin whose corners bunched by a thin peninsula, its cells
fanning out from there across the lake (`small_islands(745801, n_islands=4, peninsulas=4,
widths=(0.5, 3.0))`, 429 folded cells).  No single cut pays there because each piece of any one
cut still needs cuts of its own.  :func:`unfan` splits such a piece with one step of
look-ahead: every admissible split, its pieces split greedily again, the cheapest result in
which no piece fans.  Other pieces are left as the greedy split made them (one step of
look-ahead everywhere helped some lakes and hurt others: ``docs/lake-grids-journal.md``).
"""

from __future__ import annotations

import contextlib
import contextvars
import math

import numpy as np

from .memo import watching

__all__ = [
    "BULGING",
    "FAN_AREA",
    "FAN_BULGE",
    "FAN_PAIRS",
    "bulges",
    "fans",
    "noted_unsplit",
    "tapers",
    "unfan",
    "watching_unsplit",
    "wraps",
]

#: A piece whose chosen corners give :func:`~.corners.bulge_ratio` at least this fans.  On the
#: 73 generated shapes of `fresh_sweep.py` base 791000 (both sets) every piece was below 2.6
#: but in two headlands lakes (5.1; 5.3, the 43 folded cells above).
FAN_BULGE = 3.0

#: ... and a piece with ``R`` above :data:`BULGING` whose two pairs of opposite sides both
#: differ by at least this factor (its cells differ in area by the square of it).  Base 791000:
#: every piece below 7.2 but a sliver of ``R`` 0.01 (15).
FAN_PAIRS = 8.0
BULGING = 1.2

#: ... or whose two ratios of opposite sides multiply to at least this (its cells differ in area
#: by about the product: a polar fan whose short sides are unequally short).
#: `round_lake(955400, kind='blob', n_islands=5)` at 15 000 cells: the east lobe as one block from a
#: small island's side, ``R`` 1.24, sides 6.0× and 8.1× apart (49), 1 299 nodes beyond 3°; on the
#: 72 generated shapes of `fresh_sweep.py` base 946000 (both sets) every other piece of ``R`` ≥ 1.2
#: had a product below 20.
FAN_AREA = 32.0

#: ... and a piece one of whose sides runs back on itself — measured along the line between its
#: corners — by more than this share of that line's length and by more than :data:`BACK_CELLS`
#: cells beyond what its opposite side does: the side goes round a tip of land into a pocket of
#: water and out again (a peninsula the block wraps), and the grid lines from the opposite side
#: crowd into the tip (a channel that winds, or a spiral, winds both sides alike).
WRAP_BACK = 0.5
BACK_CELLS = 3.0


def _pairs(ring: np.ndarray, corners) -> tuple[float, float]:
    """The two ratios of opposite sides between ``corners``, the smaller first."""
    from .corners import _arclength_closed

    s, total = _arclength_closed(ring)
    c = sorted(corners)
    L = [max((s[c[(k + 1) % 4]] - s[c[k]]) % total, 1e-300) for k in range(4)]
    a, b = max(L[0], L[2]) / min(L[0], L[2]), max(L[1], L[3]) / min(L[1], L[3])
    return min(a, b), max(a, b)


def fans(ring: np.ndarray, sigma: float, forced=(), tapered: bool = False) -> bool:
    """True when ``ring`` as one block (its corners by :func:`~.corners.choose_corners`) fans
    (``tapered``: or :func:`tapers`)."""
    got = _bulge(ring, sigma, forced)
    if got is None:
        return False
    corners, R = got
    if R >= FAN_BULGE:
        return True
    lo, hi = _pairs(ring, corners)
    return (R >= BULGING and (lo >= FAN_PAIRS or lo * hi >= FAN_AREA)) or (tapered and lo * hi >= FAN_AREA)


def tapers(ring: np.ndarray, sigma: float, forced=()) -> bool:
    """True when ``ring`` as one block (its corners by :func:`~.corners.choose_corners`) is a wedge
    whose two ratios of opposite sides multiply to :data:`FAN_AREA` or more, whatever its bulge (its
    cells differ in area by about the product): what default layouts split with
    ``LayoutOptions(tapers=True)`` (:func:`~.build._unfanned`)."""
    got = _bulge(ring, sigma, forced)
    if got is None:
        return False
    lo, hi = _pairs(ring, got[0])
    return lo * hi >= FAN_AREA


def bulges(ring: np.ndarray, sigma: float, forced=()) -> bool:
    """True when ``ring`` as one block (its corners by :func:`~.corners.choose_corners`) has
    :func:`~.corners.bulge_ratio` at least :data:`FAN_BULGE`: what regular layouts split with
    ``LayoutOptions(bulges=True)`` (:func:`~.build._unfanned`)."""
    got = _bulge(ring, sigma, forced)
    return got is not None and got[1] >= FAN_BULGE


def _bulge(ring: np.ndarray, sigma: float, forced=()) -> tuple[list, float] | None:
    """``(corners, bulge ratio)`` of ``ring`` as one block, or None where it has no corners."""
    from .corners import bulge_ratio
    from .split import corners_of, forced_indices

    corners, cost = corners_of(ring, sigma, forced_indices(ring, forced))
    if corners is None or not math.isfinite(cost):
        return None
    return corners, bulge_ratio(ring, corners)


def wraps(ring: np.ndarray, sigma: float, forced=()) -> bool:
    """True when ``ring`` as one block (its corners by :func:`~.corners.choose_corners`) has a
    side that runs round a tip of land and back (:data:`WRAP_BACK`).  Such a piece is split
    only where :func:`unfan`'s split costs less than the piece (:func:`~.build._unfanned`): the
    greedy split keeps it because no single cut pays, yet one cut and the splits after it may;
    where they do not, the block is a C round a thin peninsula, which grids well."""
    from .split import corners_of, forced_indices

    corners, cost = corners_of(ring, sigma, forced_indices(ring, forced))
    if corners is None or not math.isfinite(cost):
        return False
    return _wraps(ring, corners, sigma)


def _wraps(ring: np.ndarray, corners, sigma: float) -> bool:
    """True when a side between two of ``corners`` runs back on itself further than its
    opposite side does (:data:`WRAP_BACK`)."""
    h = sigma / 1.5  # (the layout's sigma: 1.5 cells)
    c = sorted(int(i) for i in corners)
    if len(c) != 4:
        return False
    n = len(ring)
    sides = [ring[(c[k] + np.arange((c[(k + 1) % 4] - c[k]) % n + 1)) % n] for k in range(4)]
    for k in range(4):
        chord = sides[k][-1] - sides[k][0]
        length = math.hypot(*chord)
        if length == 0:
            continue
        u = chord / length
        extra = _back(sides[k] @ u) - _back(sides[(k + 2) % 4][::-1] @ u)
        if extra > max(WRAP_BACK * length, BACK_CELLS * h):
            return True
    return False


def _back(q: np.ndarray) -> float:
    """How far the positions ``q`` along a line fall back from the furthest reached before."""
    return float(np.max(np.maximum.accumulate(q) - q))


def unfan(
    ring: np.ndarray, *, sigma: float, min_width: float, center=None, depth: int = 3, wrapped: bool = False, **kw
):
    """``(pieces, cuts)`` of a split of a fanning piece ``ring`` in which no piece fans, or None.

    Every admissible split of :func:`~.split._options` (and the shore-normal cuts from evenly
    spaced points of the last resort) is followed by the greedy split of its pieces
    (``depth`` − 1 levels); the cheapest result without a fanning piece (``wrapped``: nor one
    with a side round a tip, :func:`wraps`) is returned.
    ``kw``: ``regular``, ``normal``, ``thin`` of :func:`~.split.best_split`; ``tapered``: a piece
    that tapers (:func:`tapers`) counts as fanning.
    """
    from .split import _cut_options, _normal_cuts, _options, best_split

    regular, normal, thin = kw.get("regular", False), kw.get("normal", True), kw.get("thin", False)
    tapered = kw.get("tapered", False)
    options = _options(ring, sigma, min_width, center, (), regular, normal, thin)
    if normal:
        options += _cut_options(_normal_cuts(ring, sigma, even=True), sigma, min_width)
    # the options in order of their own cost (their pieces unsplit), so that a cheap result is found
    # early and the look-ahead of options that cannot beat it stops; the result is the option of
    # least total cost, the first in ``options`` among equals, as in that order
    best = None
    for k in sorted(range(len(options)), key=lambda i: options[i][2]):
        pieces, cuts, _ = options[k]
        out_p, out_c, total = [], list(cuts), 0.0
        for pc, fc in pieces:
            if best is not None and (total > best[2] or (total == best[2] and k > best[3])):
                break  # (costs ≥ 0: this option cannot come before the best)
            pp, cc, c = best_split(
                pc,
                sigma=sigma,
                min_width=min_width,
                depth=depth - 1,
                forced=fc,
                regular=regular,
                normal=normal,
                thin=thin,
            )
            out_p += pp
            out_c += cc
            total += c
        else:
            if any(not len(f) and (fans(p, sigma, tapered=tapered) or (wrapped and wraps(p, sigma))) for p, f in out_p):
                continue
            if best is None or total < best[2] or (total == best[2] and k < best[3]):
                best = (out_p, out_c, total, k)
    return None if best is None else best[:2]


_unsplit: contextvars.ContextVar[list | None] = contextvars.ContextVar("unsplit", default=None)


@contextlib.contextmanager
def watching_unsplit():
    """Yields a list to which a layout drawn within this context adds ``"bulge"`` where a regular
    draw without ``LayoutOptions(bulges=True)`` kept a piece that bulges (:func:`bulges`) and
    ``"taper"`` where a default draw without ``LayoutOptions(tapers=True)`` kept a piece that tapers
    (:func:`tapers`; :func:`noted_unsplit`).  Where none is noted, the draw with that option makes
    the same layout, so the layout choice does not make it (:data:`~meshcore.layout.BULGE_DRAW`,
    :data:`~meshcore.layout.TAPER_DRAW`)."""
    with watching(_unsplit) as box:
        yield box


def noted_unsplit(kind: str) -> None:
    """Within :func:`watching_unsplit`: note that the draw kept a piece of ``kind`` (``"bulge"``,
    ``"taper"``) unsplit."""
    box = _unsplit.get()
    if box is not None:
        box.append(kind)
