"""A region's first split chosen by the cost of its pieces split on (``look``,
:data:`meshcore.layout.split.LOOKAHEAD`), and the layout choice's draw with it
(``LayoutOptions(lookahead=True)``, :data:`meshcore.layout.LOOK_DRAW`)."""

from __future__ import annotations

import numpy as np
import pytest
import shapely

from meshcore import testing
from meshcore.layout import LayoutOptions, auto_layout
from meshcore.layout.split import LOOKAHEAD, best_split, region_cost


def _region(poly, cells: int = 1500):
    """The whole water of ``poly`` as one region (CCW ring sampled at h/2), its cell size and a
    centre for a star."""
    h = float(np.sqrt(poly.area / cells))
    ring = np.asarray(shapely.segmentize(poly, h / 2).exterior.coords)[:-1]
    if not shapely.LinearRing(ring).is_ccw:
        ring = ring[::-1].copy()
    return ring, h, np.asarray(poly.representative_point().coords[0])


def _split(poly, look: int):
    ring, h, centre = _region(poly)
    return best_split(ring, sigma=1.5 * h, min_width=3 * h, center=centre, look=look)


_SHAPES = [testing.channel_network(s, n_branches=5) for s in range(4)]
_SHAPES += [testing.round_lake(s, kind="arms") for s in range(5)]


@pytest.mark.parametrize("poly", _SHAPES)
def test_looking_ahead_never_splits_a_region_into_costlier_pieces(poly):
    greedy, ahead = _split(poly, 1), _split(poly, LOOKAHEAD)
    assert ahead[2] <= greedy[2]
    # the cost returned is the pieces' own (nothing is lost on the way)
    ring, h, _ = _region(poly)
    own = sum(region_cost(p, 1.5 * h, forced=f) for p, f in ahead[0])
    assert own == pytest.approx(ahead[2])
    # and the pieces tile the region
    whole = shapely.Polygon(ring)
    union = shapely.union_all([shapely.Polygon(p) for p, _ in ahead[0]])
    assert abs(union.area - whole.area) <= 1e-6 * whole.area


def test_looking_ahead_finds_cheaper_pieces_than_the_cheapest_first_cut():
    # a channel network whose cheapest first cut leaves a piece that splits on badly: with the next
    # cheapest cuts split on, 143 000 → 103 000 (corner cost, every piece's)
    poly = testing.channel_network(0, n_branches=5)
    greedy, ahead = _split(poly, 1), _split(poly, LOOKAHEAD)
    assert ahead[2] < 0.9 * greedy[2]


def test_the_option_draws_a_valid_layout_and_the_default_draw_is_the_greedy_one():
    poly = testing.channel_network(0, n_branches=5)
    looked = auto_layout(poly, target_cells=3000, multiple=4, options=LayoutOptions(lookahead=True))
    greedy = auto_layout(poly, target_cells=3000, multiple=4)
    assert looked.blocks != greedy.blocks
    for lay in (looked, greedy):
        union = shapely.union_all([shapely.Polygon(p.ring) for p in lay.pieces])
        assert abs(union.area - lay.polygon.area) <= 1e-6 * lay.polygon.area
        lay.topology()  # a valid case: counts that agree, blocks that close
    assert str(LayoutOptions(lookahead=True)) == "lookahead"


def _scored(blocks, dev: float, ratio: float):
    from types import SimpleNamespace

    return SimpleNamespace(multiple=4, blocks=blocks, reading=(dev, ratio))


def test_the_choice_draws_it_only_where_the_layout_kept_reads_far_off_90():
    from meshcore.layout import choice

    # every other scale draws the first layout again (nothing else read): the far draw alone
    for dev0, tried in ((0.9 * choice.WIDE_DEV, False), (2.0 * choice.WIDE_DEV, True)):
        first = _scored("first", dev0, 2.0)
        looked = _scored("looked", 0.5 * dev0, 2.0)
        calls: list[float] = []
        got = choice.chosen(
            first,
            lambda s, f=first: f,
            lambda la: la.reading,
            far=[lambda s, lk=looked, c=calls: c.append(s) or lk],
        )
        assert calls == ([1.0] if tried else [])  # at the scale chosen
        assert (got is looked) is tried
    # a layout of more than WIDE_MAX_BLOCKS blocks: not drawn (each draw costs its blocks' time)
    many = _scored(tuple(range(choice.WIDE_MAX_BLOCKS + 1)), 2.0 * choice.WIDE_DEV, 2.0)
    calls = []
    got = choice.chosen(many, lambda s: many, lambda la: la.reading, far=[lambda s: calls.append(s) or looked])
    assert got is many and not calls
    # kept by the rule of the other draws at the chosen scale: the margin, the ratio guard
    first = _scored("first", 2.0 * choice.WIDE_DEV, 2.0)
    for looked, taken in (
        (_scored("close", (1 - 0.5 * choice.MARGIN) * 2.0 * choice.WIDE_DEV, 2.0), False),
        (_scored("steep", 0.5 * choice.WIDE_DEV, 2.0 * (1 + 2 * choice.TIP_RATIO_SLACK)), False),
        (_scored("fine", 0.5 * choice.WIDE_DEV, 2.0), True),
    ):
        got = choice.chosen(first, lambda s: first, lambda la: la.reading, far=[lambda s, lk=looked: lk])
        assert (got is looked) is taken, looked.blocks
