"""Point distributions and boundary curves."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from meshcore import InvalidInputError
from meshcore.curves import LinearSpline, SmoothCurve
from meshcore.distribution import distribute, tanh_one_sided, uniform, vinokur


def _check(u, n):
    assert len(u) == n + 1
    assert u[0] == 0.0 and u[-1] == 1.0
    assert np.all(np.diff(u) > 0)


@settings(max_examples=60, deadline=None)
@given(st.integers(1, 200))
def test_uniform(n):
    u = uniform(n)
    _check(u, n)
    np.testing.assert_allclose(np.diff(u), 1.0 / n)


@settings(max_examples=80, deadline=None)
@given(st.integers(2, 300), st.floats(0.02, 5.0), st.booleans())
def test_tanh_one_sided_exact_spacing(n, ratio, at_end):
    first = ratio / n  # from 2 % to 500 % of the uniform spacing
    assume(first < 0.95)
    try:
        u = tanh_one_sided(n, first, at_end=at_end)
    except InvalidInputError as exc:
        # only legitimately impossible requests may be refused
        assert "too large" in str(exc) or "too small" in str(exc)
        return
    _check(u, n)
    got = (1 - u[-2]) if at_end else u[1]
    assert got == pytest.approx(first, rel=1e-9)


@settings(max_examples=80, deadline=None)
@given(st.integers(3, 300), st.floats(0.05, 3.0), st.floats(0.05, 3.0))
def test_vinokur_exact_spacings(n, r0, r1):
    first, last = r0 / n, r1 / n
    assume(first + last < 0.9)
    try:
        u = vinokur(n, first, last)
    except InvalidInputError:
        # Only extreme requests (one end much larger than uniform) may be refused.
        assert max(r0, r1) > 1.5
        return
    _check(u, n)
    assert u[1] == pytest.approx(first, rel=1e-8)
    assert 1 - u[-2] == pytest.approx(last, rel=1e-8)


def test_distribute_dispatch_and_errors():
    _check(distribute(10, "vinokur", first=0.01, last=0.05), 10)
    _check(distribute(10, "tanh", last=0.01), 10)
    with pytest.raises(InvalidInputError, match="needs a first"):
        distribute(10, "tanh")
    with pytest.raises(InvalidInputError, match="distribution must be one of"):
        distribute(10, "cosine")
    with pytest.raises(InvalidInputError, match="cells must be >= 1"):
        distribute(0)


def test_linear_spline_is_paper_eq33():
    pts = np.array([[0.0, 0.0], [3.0, 0.0], [3.0, 4.0], [0.0, 4.0]])
    c = LinearSpline(pts)
    assert c.length == 10.0
    np.testing.assert_allclose(c.at(np.array([1.5, 3.0, 5.0, 8.5])), [[1.5, 0], [3, 0], [3, 2], [1.5, 4]])
    np.testing.assert_array_equal(c.at_fraction(np.array([0.0, 1.0])), pts[[0, -1]])


@pytest.mark.parametrize("kind", ["cubic", "catmull-rom"])
def test_smooth_curve_arc_length(kind):
    t = np.linspace(0, math.pi, 13)
    pts = np.column_stack([np.cos(t), np.sin(t)])
    c = SmoothCurve(pts, kind=kind)
    assert c.length == pytest.approx(math.pi, rel=2e-3)
    # passes through the input points
    for p in pts[1:-1]:
        s = np.linspace(0, c.length, 4001)
        assert np.min(np.hypot(*(c.at(s) - p).T)) < 2e-3
    # evaluation by arc length: equal steps give equal chord lengths on a circle
    q = c.at_fraction(np.linspace(0, 1, 9))
    chords = np.hypot(*np.diff(q, axis=0).T)
    assert np.ptp(chords) < 5e-3 * chords.mean()
    assert np.all(np.abs(np.hypot(q[:, 0], q[:, 1]) - 1) < 2e-3)


def test_snap_angle_keeps_sharp_vertices_as_nodes():
    import meshcore

    bottom = np.array([[0.0, 0], [10, 0]])
    top = np.array([[0.0, 4], [3.5, 4], [3.5, 2.5], [6.5, 2.5], [6.5, 4], [10, 4]])
    left = np.array([[0.0, 0], [0, 4]])
    right = np.array([[10.0, 0], [10, 4]])
    corners = top[1:-1]
    plain = meshcore.prepare_borders(bottom, right, top, left, cells=(15, 6))
    snapped = meshcore.prepare_borders(bottom, right, top, left, cells=(15, 6), snap_angle=30)

    def has(nodes, p):
        return np.min(np.hypot(*(nodes - p).T)) < 1e-12

    assert not all(has(plain.top, c) for c in corners)  # the paper's uniform re-sampling cuts corners
    assert all(has(snapped.top, c) for c in corners)
    assert np.all(np.diff(np.concatenate([[0], np.cumsum(np.hypot(*np.diff(snapped.top, axis=0).T))])) > 0)


def test_vinokur_extreme_request():
    # found by hypothesis: a first cell of 75 % of the border with 4 cells used to hit a math domain error
    u = vinokur(4, 0.75, 1 / 12)
    _check(u, 4)
    assert u[1] == pytest.approx(0.75, rel=1e-9) and 1 - u[-2] == pytest.approx(1 / 12, rel=1e-9)
