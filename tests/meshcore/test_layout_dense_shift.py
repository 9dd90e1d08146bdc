"""The layout on dense shores (simplified first, within 0.05 cells) and on shifted outlines."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely

from meshcore import testing
from meshcore.layout import auto_layout
from meshcore.layout.shore import DENSE_TOLERANCE, without_dense_vertices


def _vertices(poly) -> int:
    return len(poly.exterior.coords) - 1 + sum(len(r.coords) - 1 for r in poly.interiors)


def _h(poly, cells: int = 1500) -> float:
    return math.sqrt(poly.area / cells)


def _resampled(poly, step: float, jitter: float = 0.0, seed: int = 0):
    """Every ring at points ``step`` apart along it, each moved by up to ``jitter`` (a traced shore)."""
    rng = np.random.default_rng(seed)

    def ring(r):
        line = shapely.LineString(r.coords)
        s = np.linspace(0.0, line.length, max(4, round(line.length / step)), endpoint=False)
        p = shapely.get_coordinates(shapely.line_interpolate_point(line, s))
        return p + rng.uniform(-jitter, jitter, p.shape)

    return shapely.Polygon(ring(poly.exterior), [ring(r) for r in poly.interiors])


DENSE_CASES = [
    testing.lake_with_islands(0),
    testing.lake_with_islands(2, n_islands=4),
    testing.channel_network(3, n_branches=5),
    testing.round_lake(1),
]


@pytest.mark.parametrize("k", range(len(DENSE_CASES)))
def test_a_dense_shore_is_simplified_within_the_tolerance(k):
    poly = DENSE_CASES[k]
    h = _h(poly)
    dense = _resampled(poly, h / 12, jitter=0.01 * h, seed=k)  # traced: vertices off the line
    assert dense.is_valid
    out, notes = without_dense_vertices(dense, h)
    assert out.is_valid and len(out.interiors) == len(poly.interiors)
    assert _vertices(out) < _vertices(dense) / 4
    assert out.hausdorff_distance(dense) <= DENSE_TOLERANCE * h * (1 + 1e-9)
    assert len(notes) == 1 and f"{_vertices(dense)} to {_vertices(out)} vertices" in notes[0]
    assert out.exterior.is_ccw


@pytest.mark.parametrize("k", range(len(DENSE_CASES)))
def test_a_shore_sampled_at_the_cell_size_is_left_as_it_is(k):
    h = _h(DENSE_CASES[k])
    poly = _resampled(DENSE_CASES[k], h)
    out, notes = without_dense_vertices(poly, h)
    assert out is poly and notes == []


def test_the_layout_of_a_dense_shore_follows_it_within_the_tolerance():
    poly = testing.channel_network(3, n_branches=5)
    h = _h(poly)
    dense = _resampled(poly, h / 12)
    lay = auto_layout(dense, cell_size=h)
    assert any("simplified" in n for n in lay.notes)
    assert lay.polygon.hausdorff_distance(dense) <= DENSE_TOLERANCE * h * (1 + 1e-9)
    assert _vertices(lay.polygon) < _vertices(dense) / 4
    total = sum(shapely.Polygon(p.ring).area for p in lay.pieces)
    assert total == pytest.approx(lay.polygon.area, rel=1e-6)
