"""The guarded spacing smoother (``meshcore.orthogonal.spacing``): graded lines are kept,
jumps along lines are spread, borders and the cells at interfaces stay, no guard is broken."""

from __future__ import annotations

import numpy as np

from meshcore.grid import StructuredGrid
from meshcore.orthogonal.spacing import SIN3, _node_cos, smooth_block, smooth_spacing
from meshcore.quality.interfaces import signed_area
from meshcore.quality.lake import _smoothness


def _block(xs: np.ndarray, ys: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    return np.meshgrid(xs, ys, indexing="ij")


def _bad_pairs(x: np.ndarray, y: np.ndarray, limit: float = 1.2) -> int:
    sxi, seta = _smoothness(x, y, False)
    return int(np.nansum(sxi > limit) + np.nansum(seta > limit))


def test_graded_lines_are_a_fixed_point() -> None:
    xs = np.concatenate([[0.0], np.cumsum(1.3 ** np.arange(12))])  # every pair 1.3
    x, y = _block(xs, np.linspace(0.0, 10.0, 11))
    x2, y2, moved = smooth_block(x, y)
    assert moved == 0
    assert np.array_equal(x2, x) and np.array_equal(y2, y)


def test_a_jump_is_spread_within_the_guards() -> None:
    # a bent block (annular sector) whose radial spacing jumps 1 → 1.8 halfway
    r = np.concatenate([10.0 + np.arange(11.0), 20.0 + 1.8 * np.arange(1, 11)])
    t = np.linspace(0.0, 0.8, 25)
    rr, tt = np.meshgrid(r, t, indexing="ij")
    x, y = rr * np.cos(tt), rr * np.sin(tt)
    before = _bad_pairs(x, y)
    cos0 = _node_cos(x, y)
    side = np.zeros(x.shape, dtype=bool)
    side[1:-1, 0] = side[1:-1, -1] = True  # the two straight sides: a shore the nodes slide on
    x2, y2, moved = smooth_block(x, y, slide=side)
    assert moved > 0
    assert _bad_pairs(x2, y2) < before
    ang = np.arctan2(y2, x2)
    np.testing.assert_allclose(ang[:, 0], 0.0, atol=1e-12)  # slid along the sides, not off them
    np.testing.assert_allclose(ang[:, -1], 0.8, atol=1e-12)
    cos1 = _node_cos(x2, y2)
    assert not np.any((cos0 <= 0.02) & (cos1 > 0.02))
    assert not np.any((cos0 <= SIN3) & (cos1 > SIN3))
    assert np.all(signed_area(x2, y2) > 0)
    for a, b in ((x, x2), (y, y2)):  # the ends of the radial lines stay
        assert np.array_equal(a[0], b[0]) and np.array_equal(a[-1], b[-1])


def test_cells_at_an_interface_keep_their_area() -> None:
    # two blocks of an annular sector meeting on the arc r = 20; the outer one's radial spacing
    # jumps 1 → 1.8 at r = 23, its straight sides are shore
    t = np.linspace(0.0, 0.8, 25)
    radii = (10.0 + np.arange(11.0), np.concatenate([20.0 + np.arange(4.0), 23.0 + 1.8 * np.arange(1, 11)]))
    grids = []
    for r in radii:
        rr, tt = np.meshgrid(r, t, indexing="ij")
        grids.append(StructuredGrid(rr * np.cos(tt), rr * np.sin(tt)))
    out, moved = smooth_spacing(grids, shore_slide=True)
    assert moved > 0
    x0, y0 = np.asarray(grids[1].x), np.asarray(grids[1].y)
    x1, y1 = np.asarray(out[1].x), np.asarray(out[1].y)
    assert _bad_pairs(x1, y1) < _bad_pairs(x0, y0)
    a0, a1 = signed_area(x0, y0), signed_area(x1, y1)
    np.testing.assert_array_equal(a0[0], a1[0])  # the cells along the interface
    np.testing.assert_array_equal(np.asarray(out[0].x), np.asarray(grids[0].x))  # nothing to do there
    assert not np.allclose(a0, a1)
