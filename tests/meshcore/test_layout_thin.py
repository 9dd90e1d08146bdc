"""Arms 2–4 cells wide (``auto_layout(..., options=LayoutOptions(thin_arms=True))``): a cut from a reflex corner may
leave blocks two cells across (:data:`meshcore.layout.width.THIN_ACROSS`), so that no block's
side runs round the corner of a junction or bend of such arms (its cells fan out from it)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from meshcore import testing
from meshcore.layout import LayoutOptions, auto_layout, width
from meshcore.layout.corners import turning


def _wrapped(lay, limit: float) -> int:
    """Blocks whose boundary turns into the water by more than ``limit`` degrees (at the
    corners' scale, 1.5 cells) somewhere farther than that scale from any of their corners."""
    sigma = 1.5 * lay.cell_size
    n = 0
    for pc in lay.pieces:
        t = turning(pc.ring, sigma)
        away = np.ones(len(t), bool)
        for c in pc.corners:
            away &= np.hypot(*(pc.ring - pc.ring[c]).T) > sigma
        n += bool(away.any() and t[away].min() < -limit)
    return n


def _tee(w_main: float, w_side: float, angle: float, h: float):
    """A straight arm ``w_main`` cells wide and 30 long with a side arm ``w_side`` wide and 14
    long leaving its middle at ``angle`` degrees."""
    import shapely
    from shapely.geometry import LineString

    a = math.radians(angle)
    main = LineString([(0, 0), (30 * h, 0)]).buffer(0.5 * w_main * h, cap_style="flat")
    end = (15 * h + 14 * h * math.cos(a), 14 * h * math.sin(a))
    side = LineString([(15 * h, 0), end]).buffer(0.5 * w_side * h, cap_style="flat")
    return shapely.union_all([main, side])


@pytest.mark.parametrize(
    ("w_main", "w_side", "angle"), [(3.5, 3.0, 60), (3.2, 3.2, 90), (4.0, 2.6, 45), (3.0, 3.0, 120)]
)
def test_junction_of_thin_arms_is_split(w_main, w_side, angle):
    h = 0.1
    poly = _tee(w_main, w_side, angle, h)
    lay = auto_layout(poly, cell_size=h, options=LayoutOptions(thin_arms=True))
    assert _wrapped(lay, 60.0) == 0
    assert all(min(b.cells) >= 3 for b in lay.blocks)
    # without it, no cut is admissible there and a block wraps the junction's reflex corner
    assert _wrapped(auto_layout(poly, cell_size=h), 60.0) >= 1


def test_too_narrow_reads_the_inscribed_disc():
    h = 1.0
    square = np.array([[0, 0], [2.5, 0], [2.5, 2.5], [0, 2.5]], float)  # 2A/P = 1.25 cells
    strip = np.array([[0, 0], [20, 0], [20, 1.5], [0, 1.5]], float)  # 2A/P 1.4, 1.5 across
    assert width.too_narrow(square, 3 * h) and width.too_narrow(strip, 3 * h)
    assert not width.too_narrow(square, 3 * h, thin=True)
    assert width.too_narrow(strip, 3 * h, thin=True)


def test_dendritic_reservoirs_fewer_blocks_round_reflex_corners():
    """Generated dendritic reservoirs (seeds nobody tuned to) at 15 000 cells: blocks that wrap a
    reflex bend of more than 90° 21 → 9."""
    off = on = 0
    for seed in (761001, 761002, 761003):
        poly = testing.dendritic(seed)
        off += _wrapped(auto_layout(poly, target_cells=15000, multiple=4), 90.0)
        on += _wrapped(auto_layout(poly, target_cells=15000, multiple=4, options=LayoutOptions(thin_arms=True)), 90.0)
    assert on <= 0.6 * off
