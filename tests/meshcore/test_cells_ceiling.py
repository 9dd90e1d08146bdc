"""Layouts whose agreed cell counts give far more cells than asked (issue 12: 0.5–2 × area / h²).

A shore chain's ``least`` count (:func:`meshcore.multiblock.shorecells.least_cells`) costs
:data:`~meshcore.multiblock.counts.LEAST_WEIGHT` per missing cell, and raising a count carried
across a row of ``k`` blocks costs ``k`` per cell: with ``k < 4`` the program doubles the row.
Above :data:`~meshcore.layout.blocks.CELLS_CEILING` the counts are solved again with those
demands relaxed (:func:`meshcore.layout.blocks._under_ceiling`)."""

from __future__ import annotations

import numpy as np
import pytest

import meshcore.layout.blocks as blocks
from meshcore import testing
from meshcore.layout import auto_layout


def _ratio(poly, cells: int) -> float:
    lay = auto_layout(poly, target_cells=cells, multiple=4)
    return lay.n_cells / (poly.area / lay.cell_size**2)


@pytest.mark.slow
@pytest.mark.parametrize(
    "shape", [lambda: testing.headlands(502605, n=6), lambda: testing.dendritic(502701)], ids=["headlands", "dendritic"]
)
def test_a_layout_whose_least_counts_double_its_rows_gets_at_most_twice_the_cells(shape):
    """Before the ceiling: ``headlands(502605, n=6)`` 2.21 × and ``dendritic(502701)`` 2.53 × the
    cells asked at 3000 (shore chains asking up to :data:`~meshcore.multiblock.shorecells.MOST`
    × their cells, carried across rows of blocks); with it 1.82 × and 1.87 ×."""
    ratio = _ratio(shape(), 3000)
    assert 0.5 <= ratio <= 2.0, ratio


def _counted(pieces, h: float, ceiling: float):
    old = blocks.CELLS_CEILING
    blocks.CELLS_CEILING = ceiling
    try:
        return blocks._counts(blocks._line_work(pieces), pieces, h, 3, 4, None, True)
    finally:
        blocks.CELLS_CEILING = old


def _share(pieces, cells, h: float) -> float:
    from meshcore.boundary import signed_area

    return sum(a * b for a, b in cells) * h * h / sum(abs(signed_area(p.ring)) for p in pieces)


@pytest.mark.slow
@pytest.mark.parametrize(
    "shape",
    [
        lambda: testing.dendritic(990703),
        lambda: testing.headlands(990602, n=8),
        lambda: testing.dendritic(882703),
        lambda: testing.lake_with_islands(880300, n_islands=6, lobes=4),
        lambda: testing.channel_network(501002, n_branches=5),
    ],
    ids=["dendritic 990703", "headlands 990602", "dendritic 882703", "islands 880300", "net 501002"],
)
def test_counts_over_the_ceiling_come_closer_and_the_others_stay(shape):
    """On a generated layout's blocks: where the plain counts give more than
    :data:`~meshcore.layout.blocks.CELLS_CEILING` × the cells asked, counts that change come closer
    to the cells asked (and within 2 ×); under it, the same counts bit for bit.  On the chosen
    layouts' blocks: ``dendritic(990703)`` 2.02 → 1.84 ×, ``dendritic(882703)`` 2.62 → 1.72 ×,
    ``lake_with_islands(880300)`` 1.77 × (no relaxation comes closer: kept), the other two under it."""
    poly = shape()
    lay = auto_layout(poly, target_cells=3000, multiple=4)
    pieces, h = list(lay.pieces), lay.cell_size
    plain = _counted(pieces, h, float("inf"))
    now = _counted(pieces, h, blocks.CELLS_CEILING)
    before, after = _share(pieces, plain[0], h), _share(pieces, now[0], h)
    if before <= blocks.CELLS_CEILING:
        assert np.array_equal(plain[1], now[1])
    elif not np.array_equal(plain[1], now[1]):
        assert abs(np.log(after)) < abs(np.log(before)), (before, after)
        assert after <= 2.0, (before, after)
