r"""Among layouts drawn at neighbouring scales, the one whose coarsest grid is most orthogonal.

A large jagged basin is split greedily (:mod:`.split`): which star, spokes and cuts win depends
on where the chords fall and on the scale at which corners are read, all multiples of the cell
size, so a slightly other cell size gives another layout and, on lakes of 60–90 blocks, grids
from 65 to 93 % of nodes within 3° (held-out g180632 between 8 000 and 20 000 cells).  The
blocks' side ratios, corner angles and cell aspects hardly told the good layouts from the bad
(Spearman +0.1 to +0.2 within a lake; docs/lake-grids-journal.md), the coarsest level of the
orthogonal solve (cells of ``multiple`` × the size, 0.1–0.3 s) does: the mean deviation from
90° of its block-interior nodes ranks the final grids of the same lake (+0.76, −0.96 on g180632).

:func:`chosen` draws the layout again at :data:`SCALES` × the cell size (the geometry only:
the cells keep the asked size, as :data:`~meshcore.layout.LAYOUT_SCALES`), solves the coarsest
level of each layout that differs, and keeps the one with the smallest deviation if that is
:data:`MARGIN` below the first's and its interface ratio there (the 99th percentile of the coarse
cell pairs', :data:`meshcore.lakegrid.READING_PERCENTILE`) is no larger (up to
:data:`RATIO_SLACK`) or at most ``ratio_ok`` (:data:`meshcore.layout.DEFAULT_RATIO` and
:data:`~meshcore.layout.REGULAR_RATIO`: 2.5); else the layout at the cell size itself.  Where
every one of those reads far off 90° (:data:`WIDE_DEV`), the layout is drawn at the wider
:data:`WIDE_SCALES` as well.  A default layout whose blocks
average fewer than :data:`SMALL_BLOCK_CELLS` cells can also be drawn at :data:`COARSE_SCALES` (off) × the
cell size — fewer, larger blocks whose lines are long enough to grade their cells (edge pairs
≤ 1.2, issue 12's lakes of 70–100 blocks at 10 000 cells) — and there the coarse ratio may also
be up to :data:`SMALL_RATIO_OK`, which the final grid's equalize step brings under 2.  Layouts of more than
:data:`MAX_BLOCKS` blocks are kept as drawn (each other scale costs a layout: Saimaa's takes 10 s).

The mean deviation does not see a collapsed cell (a block side wrapped round a land tip squeezes
a row of cells to nothing), the coarse grid's shortest edge does: a chosen layout whose coarse grid
has one (:data:`COLLAPSED`) gives way to the least deviating layout read whose grid has none, if
that one deviates at most :data:`COLLAPSE_WEIGHT` × as much.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Sequence

from ..errors import MeshcoreError
from .model import Layout

__all__ = [
    "COLLAPSED",
    "COLLAPSE_MARGIN",
    "COLLAPSE_WEIGHT",
    "MARGIN",
    "MAX_BLOCKS",
    "RATIO_SLACK",
    "SCALES",
    "WIDE_DEV",
    "WIDE_MAX_BLOCKS",
    "WIDE_RATIO",
    "WIDE_SCALES",
    "chosen",
]

#: The other scales (× the cell size) the layout is drawn at, in the order tried.
SCALES = (1.07, 0.93)

#: When the best of those layouts' coarse grids still deviates from 90° by more than
#: :data:`WIDE_DEV` degrees on average (the target for the final grid's mean, issue 12), the layout
#: is also drawn at these scales.  The draws of 1, 1.07 and 0.93 × the cell size often share the same
#: fault (a strip between a cut and the shore, a block wrapped round a junction); a wider scale moves
#: the cuts and corners enough to lose it.  Session 38, held-out set 25 at 10 000 cells: regular
#: layouts 23 → 26 of 28 lakes meeting every hard target (g182733 74.3 → 95.5 % of nodes within 3°,
#: g181108 88.0 → 95.9 %), default ones 24 → 27 (g180663 91.1 → 96.8 %, g180899 89.4 → 95.1 %);
#: generated ``fresh_sweep.py --base 430000`` 44 → 45 of 45 (islands 430306 72.6 → 95.5 %).  Of 21
#: layouts taken from the wide round, 0.8 gave 9, 0.87 and 1.25 5 each, 1.15 none (dropped).  The
#: whole comparison in ``docs/lake-grids-journal.md`` (session 38).
WIDE_SCALES = (0.87, 1.25, 0.8)
WIDE_DEV = 3.0

#: ... for layouts of at most this many blocks: a draw of a lake's layout costs ~25 ms of CPU a
#: block (Kivu's 90 blocks 1.7–3.6 s), and four wide draws took Kivu at 15 000 cells from 12.7 to
#: 23.2 s of CPU (81.8 → 88.8 % within 3°), over issue 12's 20 s.
WIDE_MAX_BLOCKS = 80

#: ... and a layout of those wider scales is kept also when its coarse interface ratio is up to
#: this (where the nearby ones allow :data:`meshcore.layout.DEFAULT_RATIO` or
#: :data:`~meshcore.layout.REGULAR_RATIO`, 2.5): its coarse grid is far off 90° while the final
#: grid's equalize step brings its interfaces under 2 (set 25: the wide layouts kept read coarse
#: ratios of 2.7–3.4 and ended at 1.52–2.00; session 26's coarse 5.6 and 12.7 ended at 5.9 and 8.8).
WIDE_RATIO = 3.5

#: Another scale's layout is kept only if its coarse grid's mean deviation is below ``1 - MARGIN``
#: of the first's: differences of a few percent did not rank the final grids (generated islands
#: 1020303: 7.17° against 7.30°, final 92.1 against 93.6 % within 3°).
MARGIN = 0.1

#: Layouts whose blocks average fewer cells than this (at most 16 × 16: lines too short to grade
#: their cells smoothly, issue 12's many-block lakes at 10 000 cells) are also drawn at
#: :data:`COARSE_SCALES` × the cell size: fewer, larger blocks at the same cell size.
SMALL_BLOCK_CELLS = 256

#: The coarser scales drawn for layouts of small blocks (:data:`SMALL_BLOCK_CELLS`).  OFF by
#: default (empty): ``(1.3, 1.6)`` measured on sets 13–20 (session 34, docs/lake-grids-journal.md
#: "Many-block lakes drawn coarser"): within 3° up on most lakes of 55–105 blocks at 10 000
#: cells (g180779 78.5 → 91.0 %, g180759 every hard target), edge pairs ≤ 1.2 still under 95 % on
#: most, and two lakes lost a target (g180875 its pairs, g180780 its shore distance).
COARSE_SCALES: tuple[float, ...] = ()

#: For a layout of small blocks another draw may also read a coarse interface ratio above the
#: first's up to this (as regular layouts, :data:`meshcore.layout.REGULAR_RATIO`).
SMALL_RATIO_OK = 2.5

#: A layout of more blocks than this is not drawn again (the time: a layout each).
MAX_BLOCKS = 150

#: How much (a share) another scale's coarse interface ratio may exceed the first's and
#: still count as no larger: the same interface, left as it was by the other scale, reads a few
#: parts in 10 000 apart on the two coarse grids (held-out g180759 at 10 000 cells: 2.45358 and
#: 2.45377), and the strict test threw away a layout whose coarse deviation was 29 % lower (final
#: grid 93.1 → 97.8 % of nodes within 3°, edge pairs ≤ 1.2 94.98 → 96.72 %).
RATIO_SLACK = 1e-3

#: :data:`RATIO_SLACK` for the draws at the chosen scale (``again``).  The tip draw changes the
#: layout only round a few land tips, where a new cut end can lift the lake's 99th percentile of
#: the coarse pairs by a hair (held-out g180700 at 10 000 cells with
#: :data:`~meshcore.layout.pinch.PINCH`: 1.936 → 1.945, +0.5 %, the coarse deviation 36 % lower;
#: final grid 91.5 → 96.2 % within 3°).  Session 35 measured 0.01 (journal); an absolute guard
#: tried first (up to 2.0) took tip draws of small lakes whose coarse ratio rose 3–17 % for grids
#: already 99.9 % within 3°, final ratios up to 1.71.
TIP_RATIO_SLACK = 0.01


#: A coarse grid whose shortest edge is under this share of its mean cell size has a collapsed
#: cell: a block side wrapped round a land tip, a corner on a spike, squeezes a row of cells to
#: nothing there, and the final grid keeps it.  The mean deviation does not see it.  Held-out sets
#: 25–29 (main, 279 grids at 10 000 and 15 000 cells): the chosen layout's shortest coarse edge
#: against its final grid's, both in their mean cell sizes, Spearman +0.91; of the 10 under 0.03, 8
#: ended under 0.05 (an explicit model's time step ÷ 20).  Swapped at 0.02 / 0.03 / 0.05 (with
#: :data:`COLLAPSE_WEIGHT`): the swaps between 0.02 and 0.03 gained (g180780 at 15 000 cells: an
#: edge of 0.003 → 0.058 cells, 90.7 → 94.4 % within 3°), the one between 0.03 and 0.05 lost
#: (g180726 at 10 000: 88.3 → 82.0 %, its final edge 0.0002 → 0.005).
COLLAPSED = 0.03

#: A chosen layout whose coarse grid collapses gives way to the best-reading layout read on the way
#: whose coarse grid does not, if that one deviates at most this many times as much (and passed
#: its round's ratio guard).  1.5 took a layout that read 1.4 × the deviation and ended 12 points
#: less within 3° (held-out g180615 at 10 000 cells, 90.0 → 77.4 %).  Weighing the collapse in
#: every comparison instead (× 1.5 below 0.05 cells) lost land-tip draws: a wide draw whose collapse
#: its tip draw removes (g181108 at 10 000 cells: 94.2 → 91.7 % within 3°), generated dendritic
#: lakes (journal, session 42).
COLLAPSE_WEIGHT = 1.25

#: Where the layout kept so far has a collapsed coarse cell (:data:`COLLAPSED`), a draw at its scale
#: with the pieces round land tips or those that taper split (``again``: :mod:`.tipcuts`,
#: :func:`~.fans.tapers`) is kept when it reads this much below it, not :data:`MARGIN`: such a draw
#: changes the layout only round the tips and necks that squeeze a row of cells to nothing (the
#: fault the collapse names), and a final grid keeps the collapse of the layout it is made from.
#: Held-out g180780 (set 38) at 10 000 cells: a passage chord 0.5 cells from a tongue's tip, every
#: draw's coarse grid collapsing; its tip draw read 4.8 % lower and ended 83.7 → 88.1 % of nodes
#: within 3°, its shortest edge 0.0008 → 0.116 cells (journal, session 51).
COLLAPSE_MARGIN = 0.03


def chosen(
    first: Layout,
    at_scale: Callable[[float], Layout],
    reading: Callable[[Layout], tuple[float, ...]],
    more: Sequence[Callable[[], Layout]] = (),
    ratio_ok: float = 0.0,
    again: Sequence[Callable[[float], Layout]] = (),
    coarse: bool = False,
    far: Sequence[Callable[[float], Layout]] = (),
) -> Layout:
    """``first`` (the layout at the cell size) or the layout ``at_scale(s)``, ``s`` in
    :data:`SCALES` (then each of ``more()``, other draws: a regular layout with more cuts from its
    islands, :func:`~meshcore.layout.auto_layout`), whose coarse grid deviates least from 90° on
    average, if that is at most ``1 - MARGIN`` of ``first``'s and its coarse interface ratio
    is no larger than ``first``'s up to :data:`RATIO_SLACK` (``reading``: those two numbers of a
    layout's coarse grid and, optionally, its shortest edge,
    :func:`meshcore.lakegrid.coarse_reading`).  A scale whose layout or coarse solve fails is
    passed over; so is every other scale when ``first``'s coarse solve fails.
    ``again``: other draws at a scale (the pieces round land tips split, :mod:`.tipcuts`; the
    pieces that taper split, :func:`~.fans.tapers`), each drawn in turn at the chosen scale and
    kept when its coarse deviation is :data:`MARGIN` below the layout chosen so far and its coarse
    interface ratio no larger than ``first``'s (up to :data:`TIP_RATIO_SLACK`, or ``ratio_ok``);
    :data:`COLLAPSE_MARGIN` below it where the layout kept so far has a collapsed coarse cell.
    ``coarse``: a layout of small blocks (:data:`SMALL_BLOCK_CELLS`) is also drawn at
    :data:`COARSE_SCALES`, and ``ratio_ok`` is at least :data:`SMALL_RATIO_OK` for it (default
    layouts; regular ones close their frames at other scales by moving corners).  When the best
    of all these still reads more than :data:`WIDE_DEV` degrees (and ``first`` has at most
    :data:`WIDE_MAX_BLOCKS` blocks), the layout is drawn at
    :data:`WIDE_SCALES` too, one of them kept when it reads :data:`MARGIN` below that best with a
    coarse ratio up to :data:`WIDE_RATIO`.  Last, a chosen layout whose coarse grid has a collapsed
    cell (:data:`COLLAPSED`) gives way to the least deviating layout read whose grid has none, if that
    deviates at most :data:`COLLAPSE_WEIGHT` × as much.  ``far``: draws at the chosen scale as
    ``again``, tried after those only when the layout kept so far reads more than :data:`WIDE_DEV` (and
    ``first`` has at most :data:`WIDE_MAX_BLOCKS` blocks)."""
    if first.multiple < 4 or len(first.blocks) > MAX_BLOCKS:
        return first
    try:
        got0 = reading(first)
    except MeshcoreError:
        return first
    dev0, ratio0 = got0[:2]
    if dev0 == float("inf"):  # no interior node to read
        return first
    seen = [first.blocks]
    read = [(first, dev0, _shortest(got0))]  # (layout, deviation, shortest edge) of each admissible reading
    scales: tuple[float, ...] = SCALES
    if (
        coarse
        and COARSE_SCALES
        and sum(b.cells[0] * b.cells[1] for b in first.blocks) < SMALL_BLOCK_CELLS * len(first.blocks)
    ):
        scales = SCALES + COARSE_SCALES
        ratio_ok = max(ratio_ok, SMALL_RATIO_OK)

    def best_of(draws, taken, score: float, guard: float):
        """``taken`` (layout, scale, reading) or the draw reading least below ``score`` whose coarse
        ratio is no larger than the first's (up to the slack) or at most ``guard``."""
        for scale, draw in draws:
            try:
                lay = draw()
                if lay.blocks in seen:
                    continue
                seen.append(lay.blocks)
                got = reading(lay)
            except MeshcoreError:
                continue
            dev, ratio = got[:2]
            if ratio <= max(ratio0 * (1.0 + RATIO_SLACK), guard):
                read.append((lay, dev, _shortest(got)))
                if dev < score:
                    taken, score = (lay, scale, dev), dev
        return taken

    nearby = [(s, functools.partial(at_scale, s)) for s in scales] + [(None, d) for d in more]
    best, best_scale, best_dev = best_of(nearby, (first, 1.0, dev0), (1.0 - MARGIN) * dev0, ratio_ok)
    if best_dev > WIDE_DEV and len(first.blocks) <= WIDE_MAX_BLOCKS:  # every nearby draw far from 90°
        wide = [(s, functools.partial(at_scale, s)) for s in WIDE_SCALES]
        best, best_scale, best_dev = best_of(
            wide, (best, best_scale, best_dev), (1.0 - MARGIN) * best_dev, max(ratio_ok, WIDE_RATIO)
        )

    def redrawn(draws, best: Layout, best_dev: float, local: bool = False) -> tuple[Layout, float]:
        """The chosen scale again, drawn otherwise: ``(best, best_dev)`` or the draw kept instead
        (``local``: draws that change the layout round tips and tapers only, :data:`COLLAPSE_MARGIN`)."""
        margin = COLLAPSE_MARGIN if local and _collapses(best, read) else MARGIN
        for redraw in draws if best_scale is not None else ():
            try:
                lay = redraw(best_scale)
                if lay.blocks in seen:
                    continue
                seen.append(lay.blocks)
                got = reading(lay)
            except MeshcoreError:
                continue
            dev, ratio = got[:2]
            if ratio <= max(ratio0 * (1.0 + TIP_RATIO_SLACK), ratio_ok):
                read.append((lay, dev, _shortest(got)))
                if dev < (1.0 - margin) * best_dev:
                    best, best_dev = lay, dev
        return best, best_dev

    best, best_dev = redrawn(again, best, best_dev, local=True)
    if best_dev > WIDE_DEV and len(first.blocks) <= WIDE_MAX_BLOCKS:  # (each draw costs its blocks' time)
        best, best_dev = redrawn(far, best, best_dev)
    return _uncollapsed(best, best_dev, read)


def _shortest(got: Sequence[float]) -> float | None:
    """The shortest edge of a reading ``(deviation, ratio[, shortest edge])`` (None without)."""
    return float(got[2]) if len(got) > 2 else None


def _collapses(lay: Layout, read: list) -> bool:
    """True when the reading of ``lay`` in ``read`` (``(layout, deviation, shortest edge)``) has a
    collapsed coarse cell (:data:`COLLAPSED`); False without a shortest edge."""
    e = next((e for la, _, e in read if la is lay), None)
    return e is not None and e < COLLAPSED


def _uncollapsed(best: Layout, dev: float, read: list) -> Layout:
    """``best`` (reading ``dev``), or where its coarse grid collapses (:data:`COLLAPSED`) the layout
    of ``read`` (``(layout, deviation, shortest edge)``) whose coarse grid does not and that deviates
    least, if at most :data:`COLLAPSE_WEIGHT` × ``dev`` (readings without a shortest edge: ``best``)."""
    if not _collapses(best, read):
        return best
    whole = [(d, k) for k, (_, d, e) in enumerate(read) if e is not None and e >= COLLAPSED]
    if not whole:
        return best
    d, k = min(whole)
    return read[k][0] if d <= COLLAPSE_WEIGHT * dev else best
