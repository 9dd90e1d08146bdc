"""Bad input: every case gives one clear error naming the border, point or key."""

from __future__ import annotations

import numpy as np
import pytest

import meshcore
from meshcore import BorderMismatchError, BoundaryError, InvalidInputError, MeshcoreWarning
from tests.conftest import rectangle_borders

B, R, T, L = rectangle_borders(2.0, 1.0, 4, 2)


def gen(b=B, r=R, t=T, l=L, **kw):
    return meshcore.generate_block(b, r, t, l, **kw)


def test_too_few_points():
    with pytest.raises(InvalidInputError, match="top border: needs at least 2 points, got 1"):
        gen(t=T[:1])


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_non_finite_point_named(bad):
    r = R.copy()
    r[1, 1] = bad
    with pytest.raises(InvalidInputError, match=r"right border: point 2 is not finite") as exc:
        gen(r=r)
    assert f"({float(r[1, 0])!r}, {bad!r})" in str(exc.value)  # as a user writes them, not np.float64(nan)


def test_duplicate_consecutive_points_are_dropped_with_warning():
    b = np.insert(B, 2, B[2], axis=0)
    # counted from 1 for people (and the app's rows), from 0 for arrays and case files
    with pytest.warns(MeshcoreWarning, match=r"bottom border: dropped 1 duplicate .*: point 4 \(index 3\)"):
        g = gen(b=b, cells=(4, 2))
    assert g.converged


def test_zero_length_border():
    with pytest.raises(BoundaryError, match="left border: zero-length border"):
        gen(l=np.array([[0.0, 0.0], [0.0, 0.0]]), b=B, r=R, t=T)


def test_corners_that_do_not_meet():
    t = T + [0.0, 0.1]
    with pytest.raises(BoundaryError, match="corner mismatch: the start of the top border"):
        gen(t=t)


def test_reversed_border_is_reported():
    with pytest.raises(BoundaryError, match="corner mismatch"):
        gen(t=T[::-1])


def test_self_intersecting_boundary():
    t = np.array([[0.0, 1.0], [1.0, -0.5], [2.0, 1.0]])
    # points counted from 1 along each border, as every message counts them (was "segment 0–1")
    with pytest.raises(
        BoundaryError, match=r"intersects itself near .* the edge from point 2 to 3 of the bottom border crosses"
    ):
        gen(t=t, cells=(4, 2))


def test_opposite_count_mismatch_names_both():
    t = np.array([[0.0, 1.0], [1.0, 1.0], [2.0, 1.0]])
    with pytest.raises(BorderMismatchError, match="bottom border has 5 nodes but top border has 3"):
        gen(t=t)


@pytest.mark.parametrize("cells", [(0, 3), (3, -1), (2.5, 3)])
def test_cells_below_one(cells):
    with pytest.raises(InvalidInputError, match="cells"):
        gen(cells=cells)


@pytest.mark.parametrize("w", [(1.5, 0.5), (0.5, -0.1), (np.nan, 0.5)])
def test_weights_outside_unit_interval(w):
    with pytest.raises(InvalidInputError, match=r"weight p13_[xy] must be in \[0, 1\]"):
        gen(weights=w)


def test_loop_corner_errors():
    sq = np.array([[0, 0], [1, 0], [2, 0], [2, 1], [1, 1], [0, 1]], float)
    with pytest.raises(InvalidInputError, match=r"corner ne index 9 is out of range \(the loop has 6 points"):
        meshcore.generate_block(loop=sq, corners=[0, 2, 9, 5])
    with pytest.raises(BoundaryError, match="not in cyclic order"):
        meshcore.generate_block(loop=sq, corners=[0, 3, 2, 5])
    with pytest.raises(InvalidInputError, match="4 different points"):
        meshcore.generate_block(loop=sq, corners=[0, 2, 2, 5])


def test_loop_orientation_and_closing_point_are_accepted():
    sq = np.array([[0, 0], [1, 0], [2, 0], [2, 1], [1, 1], [0, 1]], float)
    g1 = meshcore.generate_block(loop=sq, corners=[0, 2, 3, 5])
    closed_cw = np.vstack([sq[::-1], sq[-1:]])  # clockwise and closed
    g2 = meshcore.generate_block(loop=closed_cw, corners=[5, 3, 2, 0])
    np.testing.assert_array_equal(g1.x, g2.x)
    np.testing.assert_array_equal(g1.y, g2.y)


def test_bad_distribution_spec_names_border():
    with pytest.raises(InvalidInputError, match="bottom border: unknown option"):
        gen(cells=(4, 2), borders={"bottom": {"distrib": "tanh"}})
    with pytest.raises(InvalidInputError, match="left border: first spacing"):
        gen(cells=(4, 4), borders={"left": {"distribution": "tanh", "first": 5.0}})


def test_unknown_solver_method():
    with pytest.raises(InvalidInputError, match="method must be one of"):
        gen(method="newton-krylov-magic")


def test_inputs_are_not_modified_and_read_only_inputs_work():
    b, r, t, l = (a.copy() for a in (B, R, T, L))
    l[0] += 1e-12  # within the corner tolerance: snapped, but only in meshcore's copy
    before = [a.copy() for a in (b, r, t, l)]
    for a in (b, r, t, l):
        a.setflags(write=False)
    g = meshcore.generate_block(b, r, t, l)
    assert g.converged
    for a, a0 in zip((b, r, t, l), before, strict=True):
        np.testing.assert_array_equal(a, a0)


_RING = np.c_[
    np.cos(np.linspace(0, 2 * np.pi, 30, endpoint=False)), np.sin(np.linspace(0, 2 * np.pi, 30, endpoint=False))
]


@pytest.mark.parametrize("corners", [[0.5, 7, 15, 22], {"a": 1}, [True, 7, 15, 22], ["0", 7, 15, 22], 5])
def test_corner_indices_are_whole_numbers_never_truncated(corners):
    """0.5 was silently read as corner 0, and a dict of corners was a bare ValueError."""
    with pytest.raises(InvalidInputError, match="corners must be"):
        meshcore.generate_block(loop=_RING, corners=corners, cells=(4, 4))


def test_corner_indices_written_as_floats_are_indices():
    a = meshcore.generate_block(loop=_RING, corners=[0, 7, 15, 22], cells=(4, 4))
    b = meshcore.generate_block(loop=_RING, corners=[0.0, 7.0, np.int64(15), -8.0], cells=(4, 4))
    np.testing.assert_array_equal(a.x, b.x)


def test_an_integer_beyond_any_float_is_one_clear_error():
    with pytest.raises(InvalidInputError, match="cannot read points as numbers"):
        meshcore.generate_block(loop=[[0, 0], [10**400, 0], [10, 10], [0, 10]], corners=[0, 1, 2, 3], cells=(3, 3))
