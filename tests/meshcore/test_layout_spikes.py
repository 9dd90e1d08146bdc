"""A piece with a spike of no width: a cut that runs along a straight shore before it leaves it.

`dendritic(955700)` at 15 000 cells: a cut started on the shore and ran along it for 0.3 cells;
the piece beside it went out along the cut and straight back (its own vertex on its own edge),
:func:`meshcore.layout.blocks.conform` inserted that vertex a second time, and every scale's
layout was refused as self-intersecting — the user got no grid.
"""

from __future__ import annotations

import numpy as np
import pytest
from shapely.geometry import Polygon

from meshcore import testing
from meshcore.layout import auto_layout
from meshcore.layout.blocks import conform
from meshcore.layout.build import _despiked


def _spiked() -> np.ndarray:
    """A ring that runs from (1, 1) to (0.4, 0.4), out to (0.7, 0.7) and straight back past
    (0.4, 0.4) to (0, 0): a spike of no width (off by 1e-12, as the layout's was)."""
    return np.array([(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.4, 0.4 + 1e-12), (0.7, 0.7)])


def test_a_ring_that_turns_straight_back_loses_its_spike():
    r = _spiked()
    assert Polygon(r).is_valid  # shapely reads the spike of no width as valid ...
    assert not Polygon(conform([r], 1e-9)[0]).is_valid  # ... conform puts (0.4,0.4) in twice
    d = _despiked(r)
    assert len(d) == 4 and Polygon(d).is_valid
    assert Polygon(d).area == pytest.approx(Polygon(r).area)
    assert Polygon(conform([d], 1e-9)[0]).is_valid
    # a ring without such a vertex is returned as it is, a sharp but open tip included
    sq = np.array([(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.5, 0.001), (0.0, 1.0)])
    assert np.array_equal(_despiked(sq), sq)


@pytest.mark.slow
def test_the_dendritic_reservoir_gets_a_layout():
    poly = testing.dendritic(955700)
    lay = auto_layout(poly, target_cells=15000, multiple=4)  # main: "a block ... came out self-intersecting"
    assert all(Polygon(pc.ring).is_valid for pc in lay.pieces)
    area = sum(Polygon(pc.ring).area for pc in lay.pieces)
    assert area == pytest.approx(lay.polygon.area, rel=1e-6)
