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
:data:`RATIO_SLACK`; else the layout at the cell size itself).  Layouts of more than
:data:`MAX_BLOCKS` blocks are kept as drawn (each other scale costs a layout: Saimaa's takes 10 s).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

from ..errors import MeshcoreError
from .model import Layout

__all__ = ["MARGIN", "MAX_BLOCKS", "RATIO_SLACK", "SCALES", "chosen"]

#: The other scales (× the cell size) the layout is drawn at, in the order tried.
SCALES = (1.07, 0.93)

#: Another scale's layout is kept only if its coarse grid's mean deviation is below ``1 - MARGIN``
#: of the first's: differences of a few percent did not rank the final grids (generated islands
#: 1020303: 7.17° against 7.30°, final 92.1 against 93.6 % within 3°).
MARGIN = 0.1

#: A layout of more blocks than this is not drawn again (the time: a layout each).
MAX_BLOCKS = 150

#: How much (a share) another scale's coarse interface ratio may exceed the first's and
#: still count as no larger: the same interface, left as it was by the other scale, reads a few
#: parts in 10 000 apart on the two coarse grids (held-out g180759 at 10 000 cells: 2.45358 and
#: 2.45377), and the strict test threw away a layout whose coarse deviation was 29 % lower (final
#: grid 93.1 → 97.8 % of nodes within 3°, edge pairs ≤ 1.2 94.98 → 96.72 %).
RATIO_SLACK = 1e-3


def chosen(
    first: Layout,
    at_scale: Callable[[float], Layout],
    reading: Callable[[Layout], tuple[float, float]],
    more: Sequence[Callable[[], Layout]] = (),
    ratio_ok: float = 0.0,
    tips: Callable[[float], Layout] | None = None,
) -> Layout:
    """``first`` (the layout at the cell size) or the layout ``at_scale(s)``, ``s`` in
    :data:`SCALES` (then each of ``more()``, other draws: a regular layout with more cuts from its
    islands, :func:`~meshcore.layout.auto_layout`), whose coarse grid deviates least from 90° on
    average, if that is at most ``1 - MARGIN`` of ``first``'s and its coarse interface ratio
    is no larger than ``first``'s up to :data:`RATIO_SLACK` (``reading``: those two numbers of a
    layout's coarse grid, :func:`meshcore.lakegrid.coarse_reading`).  A scale whose layout or
    coarse solve fails is passed over; so is every other scale when ``first``'s coarse solve fails.
    ``tips``: the layout at a scale with its pieces round land tips split (:mod:`.tipcuts`),
    drawn at the chosen scale and kept when its coarse deviation is :data:`MARGIN` below the
    chosen layout's and its coarse interface ratio no larger than ``first``'s."""
    if first.multiple < 4 or len(first.blocks) > MAX_BLOCKS:
        return first
    try:
        dev0, ratio0 = reading(first)
    except MeshcoreError:
        return first
    if dev0 == float("inf"):  # no interior node to read
        return first
    best, score = first, (1.0 - MARGIN) * dev0
    seen = [first.blocks]
    best_scale: float | None = 1.0
    best_dev = dev0
    draws: list[tuple[float | None, Callable[[], Layout]]] = [(s, lambda s=s: at_scale(s)) for s in SCALES]
    draws += [(None, d) for d in more]
    for scale, draw in draws:
        try:
            lay = draw()
            if lay.blocks in seen:
                continue
            seen.append(lay.blocks)
            dev, ratio = reading(lay)
        except MeshcoreError:
            continue
        if dev < score and ratio <= max(ratio0 * (1.0 + RATIO_SLACK), ratio_ok):
            best, score, best_scale, best_dev = lay, dev, scale, dev
    if tips is not None and best_scale is not None:  # the chosen scale again, pieces round land tips split
        try:
            lay = tips(best_scale)
            if lay.blocks not in seen:
                dev, ratio = reading(lay)
                if dev < (1.0 - MARGIN) * best_dev and ratio <= ratio0 * (1.0 + RATIO_SLACK):
                    best = lay
        except MeshcoreError:
            pass
    return best
