"""The star of a junction region (:func:`meshcore.layout.split._star`): spokes that leave no
reflex side at the reflex corner they end on."""

from __future__ import annotations

import math

import numpy as np
import pytest

from meshcore import testing
from meshcore.layout import auto_layout, split
from meshcore.layout.corners import SHARP


def _sides(ring: np.ndarray, v: int, toward: np.ndarray, sigma: float) -> tuple[float, float]:
    """The angles (degrees) of the water at vertex ``v`` of a CCW ring either side of a line
    from ``v`` toward ``toward``, the shore's directions read ``sigma`` along it either way."""
    s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(ring, axis=0).T))])
    total = s[-1] + math.hypot(*(ring[0] - ring[-1]))
    xs = np.concatenate([s, [total]])
    closed = np.vstack([ring, ring[:1]])

    def at(q):
        q %= total
        return np.array([np.interp(q, xs, closed[:, 0]), np.interp(q, xs, closed[:, 1])])

    def deg(u):
        return math.degrees(math.atan2(u[1], u[0]))

    ahead, back, d = at(s[v] + sigma) - ring[v], at(s[v] - sigma) - ring[v], toward - ring[v]
    return (deg(d) - deg(ahead)) % 360.0, (deg(back) - deg(d)) % 360.0


def _spoke_sides(monkeypatch, poly, cells: int) -> list[tuple[float, float]]:
    """The water angles either side of the end of every spoke of every star the layout drew."""
    seen: list[tuple[float, float]] = []
    star = split._star

    def recording(ring, center, sigma, min_width):
        out = star(ring, center, sigma, min_width)
        if out is None:
            return out
        for sp in out[1]:
            d = np.hypot(*(ring - sp[-1]).T)
            v = int(np.argmin(d))
            if d[v] == 0.0 and np.array_equal(sp[0], center):  # a spoke to a reflex vertex
                seen.append(_sides(ring, v, sp[-2], sigma))
        return out

    monkeypatch.setattr(split, "_star", recording)
    auto_layout(poly, target_cells=cells, multiple=4)
    return seen


@pytest.mark.parametrize(
    "make",
    [
        # lobed lakes with many islands: junction zones wide enough to see far island tips
        lambda: testing.lake_with_islands(3, n_islands=9, lobes=7),
        lambda: testing.lake_with_islands(21, n_islands=7, lobes=5),
        lambda: testing.lake_with_islands(34, n_islands=8, lobes=6),
        lambda: testing.channel_network(5, n_branches=7),
        lambda: testing.channel_network(11, n_branches=4, width=(1.0, 3.0), roughness=0.15),
    ],
)
def test_star_spokes_leave_no_reflex_side(monkeypatch, make):
    """Every spoke splits the reflex angle it ends at into two of at most 180° (+ SHARP)."""
    sides = _spoke_sides(monkeypatch, make(), 6000)
    assert sides  # the shapes have stars
    assert max(max(a) for a in sides) <= 180.0 + SHARP + 1e-6


def test_an_island_tip_seen_across_a_junction_gets_no_spoke():
    """A lake with nine islands at 4000 cells: its star had a spoke to a far island tip that
    left a reflex angle on one side (a second cut then ended there) and a sliver on the other;
    cells were 21 times apart across a cut beside it.  Without such spokes 3.95."""
    from meshcore.lakegrid import mesh_outline
    from meshcore.quality.interfaces import interface_pairs

    mb = mesh_outline(testing.lake_with_islands(3, n_islands=9, lobes=7), target_cells=4000)
    assert interface_pairs(mb.grids)["ratio"].max() <= 6.0
