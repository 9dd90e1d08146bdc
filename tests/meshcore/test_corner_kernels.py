"""The compiled corner choice (:mod:`meshcore.layout._corner_kernels`) against its NumPy reference
(:func:`meshcore.layout.corners.choose_corners_numpy`): the same corners and the same cost to the
last bit, on random rings and on every piece a real layout costs — a layout's greedy splits
compare these costs, so a last-bit difference could change which split wins."""

from __future__ import annotations

import math

import numpy as np
import pytest

import meshcore.layout.split as split
from meshcore import testing
from meshcore.layout import _corner_kernels as kernels
from meshcore.layout import auto_layout, corners
from meshcore.layout.corners import choose_corners, choose_corners_numpy

pytestmark = pytest.mark.kernel  # (test_kernels_interpreted.py runs them with the JIT off too)


def _same(ring, sigma, forced=()):
    want = choose_corners_numpy(ring, sigma, forced=forced)
    have = choose_corners(ring, sigma, forced=forced)
    assert have[0] == want[0]
    assert have[1] == want[1] or (math.isinf(want[1]) and math.isinf(have[1])), (have[1], want[1])
    return have


@pytest.mark.parametrize("n", [1, 2, 7, 8, 9, 15, 16, 17, 127, 128, 129, 255, 256, 257, 1000, 1031])
def test_the_sum_is_numpys_pairwise_sum(n):
    rng = np.random.default_rng(n)
    for _ in range(20):
        a = rng.standard_normal(n) * 10.0 ** rng.uniform(-6, 6, n)
        assert kernels._sum(a) == a.sum()  # bit for bit, not approximately
        assert kernels._sum(a) == np.add.reduce(a)


def test_the_kernels_read_the_same_sharp_limit():
    assert kernels.SHARP == corners.SHARP


@pytest.mark.parametrize("seed", range(6))
def test_random_rings_get_the_references_corners_and_cost(seed):
    rng = np.random.default_rng(400 + seed)
    for k in range(150):
        n = int(rng.integers(4, 90))
        ang = np.sort(rng.uniform(0.0, 2.0 * np.pi, n))
        r = np.abs(1.0 + 0.4 * rng.standard_normal(n) * (k % 3))  # round, wavy, jagged
        ring = np.stack([r * np.cos(ang), r * np.sin(ang)], axis=1) * 10.0 ** rng.uniform(-2, 5)
        sigma = float(rng.uniform(0.01, 1.5)) * float(np.ptp(ring[:, 0]))
        forced = rng.choice(n, size=int(rng.integers(0, min(n, 6))), replace=False).tolist() if k % 2 else ()
        _same(ring, sigma, forced)


def test_degenerate_rings():
    square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    assert _same(square, 0.1)[0] == (0, 1, 2, 3)
    assert choose_corners(square[:3], 0.1) == (None, math.inf)  # fewer than four vertices
    doubled = np.repeat(square, 2, axis=0)  # zero-length edges
    _same(doubled, 0.1)
    _same(doubled, 0.1, forced=[1, 3])
    line = np.stack([np.linspace(0, 1, 12), np.zeros(12)], axis=1)  # no turning anywhere
    _same(np.concatenate([line, line[::-1][1:-1]]), 0.05)
    t = np.linspace(0.0, 2.0 * np.pi, 40, endpoint=False)  # an oval: every corner on a smooth stretch
    _same(np.stack([3.0 * np.cos(t), np.sin(t)], axis=1), 0.2)
    _same(square, 0.1, forced=[0, 1, 2, 3])


def test_every_piece_a_layout_costs(monkeypatch):
    # the rings the greedy splits of a lake with islands actually cost (with their forced corners)
    seen = []
    orig = split.choose_corners

    def spy(ring, sigma, *, forced=()):
        seen.append((np.array(ring), float(sigma), list(forced)))
        return orig(ring, sigma, forced=forced)

    monkeypatch.setattr(split, "choose_corners", spy)
    auto_layout(testing.lake_with_islands(451, n_islands=2), target_cells=1500)
    assert len(seen) > 100
    for ring, sigma, forced in seen:
        _same(ring, sigma, forced)
