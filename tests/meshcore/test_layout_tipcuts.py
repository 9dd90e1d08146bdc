"""Pieces whose side runs round a land tip, split from the tip (meshcore.layout.tipcuts) as a
candidate of the layout choice (docs/lake-grids-journal.md, session 33)."""

import math

import numpy as np
import pytest
from shapely.geometry import Point, Polygon, box

from meshcore import testing
from meshcore.layout.split import _orient
from meshcore.layout.tipcuts import tip_split


def _u_turn(tip_radius: float = 0.5) -> np.ndarray:
    """A basin 10 × 6 with a tongue of land 1 wide from its south shore, rounded at its tip (5, 4):
    the water turns round the tip (a U-turn), as one CCW ring."""
    tongue = box(5 - tip_radius, 0, 5 + tip_radius, 3.5).union(Point(5, 3.5).buffer(tip_radius, 16))
    water = box(0, 0, 10, 6).difference(tongue)
    return _orient(np.asarray(water.exterior.coords)[:-1])


def test_a_piece_round_a_rounded_tip_is_split_from_the_tip():
    ring = _u_turn()
    got = tip_split(ring, sigma=0.15, min_width=0.3)
    assert got is not None
    pieces, cuts = got
    # a cut starts (or ends) at the tip's rounded end
    assert any(min(math.dist(c[0], (5, 4)), math.dist(c[-1], (5, 4))) < 0.55 for c in cuts)
    # the pieces tile the piece
    assert sum(Polygon(p).area for p, _ in pieces) == pytest.approx(Polygon(ring).area, rel=1e-9)
    assert all(Polygon(p).is_valid for p, _ in pieces)


def test_a_piece_without_a_tip_is_left_alone():
    ring = _orient(np.asarray(box(0, 0, 10, 3).exterior.coords)[:-1])
    assert tip_split(ring, sigma=0.15, min_width=0.3) is None


@pytest.mark.slow
def test_headlands_grid_gains_where_the_choice_takes_the_tip_splits(monkeypatch):
    """`headlands(4)` at 6 000 cells: the layout choice takes the chosen scale's layout with the
    pieces round land tips split (its coarse grid 10 % more orthogonal); main's grid had 78.7 % of
    its nodes within 3° (a basin block round a headland's tip), this one 86.2 %.  The tip draw at
    the nearby scales only: with the wide scales (session 38) the choice takes the tip draw at
    0.8 × the cell size (coarse 8.45° against 12.1°), 82.1 % within 3° (journal)."""
    import meshcore.layout as lay
    from meshcore.cellsize import default_cell_size
    from meshcore.lakegrid import mesh_outline
    from meshcore.layout import choice
    from meshcore.quality import lake_metrics

    monkeypatch.setattr(choice, "WIDE_SCALES", ())
    poly = testing.headlands(4)
    mb = mesh_outline(poly, target_cells=6000)
    s = lake_metrics(mb, polygon=poly, cell_size=default_cell_size(poly.area, 6000)).summary()
    assert s["folded_cells"] == 0
    assert s["pct_nodes_within_3deg"] >= 84.0
    assert lay.TIP_DRAW
