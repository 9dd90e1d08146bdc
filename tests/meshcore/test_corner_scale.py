"""Corners of a piece about as large as the corner scale (:data:`meshcore.layout.corners.TURN_SHARE`)."""

from __future__ import annotations

import numpy as np
import pytest

from meshcore.layout import corners

# a block in a neck one cell wide between two round islands (generated ``headlands(951100, n=6)`` at
# 15 000 cells, cell size 0.152): its two short sides are the islands' shores, 0.13 long
_NECK = np.array(
    [
        [4.591, 1.802], [4.471, 1.803], [4.352, 1.805], [4.232, 1.807], [4.235, 1.75], [4.231, 1.676],
        [4.35, 1.673], [4.469, 1.671], [4.589, 1.668], [4.588, 1.676], [4.586, 1.734], [4.59, 1.792],
    ]
)  # fmt: skip


@pytest.mark.parametrize("sigma", [0.228, 0.285, 0.5])
@pytest.mark.parametrize("choose", [corners.choose_corners, corners.choose_corners_numpy])
def test_a_piece_as_large_as_the_corner_scale_keeps_its_four_real_corners(monkeypatch, choose, sigma):
    got, _ = choose(_NECK, sigma)
    assert got == (0, 3, 5, 8)  # the cut ends, not the flat middle of a short shore side
    monkeypatch.setattr(corners, "TURN_SHARE", 0.0)  # read at the scale as given
    old, _ = choose(_NECK, sigma)
    if sigma > 0.25:
        assert 4 in old  # (the flat vertex between the two corners of the left side)


def test_large_pieces_are_read_at_the_scale_given():
    # a 40 x 10 rectangle sampled every 0.5: its perimeter is far above ten times the scale
    xs = np.arange(0.0, 40.0, 0.5)
    ys = np.arange(0.0, 10.0, 0.5)
    ring = np.vstack(
        [np.c_[xs, 0 * xs], np.c_[0 * ys + 40, ys], np.c_[xs[::-1] + 0.5, 0 * xs + 10], np.c_[0 * ys, ys[::-1] + 0.5]]
    )
    d = np.diff(ring, axis=0, append=ring[:1])
    total = np.hypot(d[:, 0], d[:, 1]).sum()
    assert corners._capped(1.5, total) == 1.5
    assert corners._capped(100.0, total) == pytest.approx(0.1 * 100.0)


@pytest.mark.slow
def test_the_neck_between_two_islands_leaves_no_bad_cell():
    # the whole lake: one non-convex cell and an interface ratio of 3.3 with the corner read at scale
    from meshcore import testing
    from meshcore.lakegrid import mesh_outline
    from meshcore.quality import lake_metrics

    poly = testing.headlands(951100, n=6)
    s = lake_metrics(mesh_outline(poly, target_cells=10_000), polygon=poly).summary()
    assert s["folded_cells"] == 0
    assert s["max_interface_ratio"] <= 2.0
