"""meshcore.multiblock.indexspace: the blocks of a layout in one (I, J) index space."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from meshcore.grid import StructuredGrid
from meshcore.multiblock.indexspace import EmbeddingError, embed


def quad(p00, p10, p11, p01, n: int, m: int) -> StructuredGrid:
    """A bilinear block of n × m cells with corners (i, j) = (0,0), (n,0), (n,m), (0,m)."""
    s, t = np.meshgrid(np.linspace(0, 1, n + 1), np.linspace(0, 1, m + 1), indexing="ij")
    c = [np.asarray(p, float) for p in (p00, p10, p11, p01)]
    xy = [(1 - s) * (1 - t) * c[0][d] + s * (1 - t) * c[1][d] + s * t * c[2][d] + (1 - s) * t * c[3][d] for d in (0, 1)]
    return StructuredGrid(xy[0].copy(), xy[1].copy())


def oriented(g: StructuredGrid, k: int) -> StructuredGrid:
    """One of the 8 index orientations of a block (k = 0 … 7; k ≥ 4 mirrored)."""
    x, y = g.x, g.y
    for _ in range(k % 4):
        x, y = x.T[::-1], y.T[::-1]
    if k >= 4:
        x, y = x[::-1], y[::-1]
    return StructuredGrid(x.copy(), y.copy())


def frame(hole_cells_bottom: int = 2, hole_cells_top: int = 2) -> list[StructuredGrid]:
    """Four blocks round a square hole [1, 2]²: bottom and top full width, left and right between."""
    nb, nt = hole_cells_bottom, hole_cells_top
    bottom = np.r_[np.linspace(0, 1, 3)[:-1], np.linspace(1, 2, nb + 1)[:-1], np.linspace(2, 3, 3)]
    top = np.r_[np.linspace(0, 1, 3)[:-1], np.linspace(1, 2, nt + 1)[:-1], np.linspace(2, 3, 3)]
    t = np.linspace(0, 1, 3)

    def strip(xs, y0, y1):
        X, T = np.meshgrid(xs, t, indexing="ij")
        return StructuredGrid(X.copy(), (y0 + (y1 - y0) * T).copy())

    left = quad((0, 1), (1, 1), (1, 2), (0, 2), 2, 2)
    right = quad((2, 1), (3, 1), (3, 2), (2, 2), 2, 2)
    return [strip(bottom, 0, 1), right, strip(top, 2, 3), left]


def check_nodes(space, blocks) -> None:
    """Every block node sits at its index node with its own coordinates; cells are the block's."""
    for k, (g, p) in enumerate(zip(blocks, space.placements, strict=True)):
        ii, jj = np.meshgrid(np.arange(g.shape[0]), np.arange(g.shape[1]), indexing="ij")
        gi, gj = p.apply(ii, jj)
        np.testing.assert_allclose(space.x[gi, gj], g.x, atol=1e-12)
        np.testing.assert_allclose(space.y[gi, gj], g.y, atol=1e-12)
        assert (space.owner[np.minimum(gi[:-1, :-1], gi[1:, 1:]), np.minimum(gj[:-1, :-1], gj[1:, 1:])] == k).all()
    assert int(space.water.sum()) == sum(g.cells[0] * g.cells[1] for g in blocks)


def cell_areas(space) -> np.ndarray:
    x, y = space.x, space.y
    ax, ay = x[1:, :-1] - x[:-1, :-1], y[1:, :-1] - y[:-1, :-1]
    bx, by = x[:-1, 1:] - x[:-1, :-1], y[:-1, 1:] - y[:-1, :-1]
    return (ax * by - ay * bx)[space.water]


@pytest.mark.parametrize("orients", [(0, 0, 0, 0), (1, 2, 3, 0), (5, 0, 6, 3), (4, 5, 6, 7)])
def test_four_blocks_any_orientation(orients):
    base = [
        quad((0, 0), (1, 0), (1, 1), (0, 1), 3, 2),
        quad((1, 0), (2.5, 0), (2.5, 1), (1, 1), 4, 2),
        quad((0, 1), (1, 1), (1, 2), (0, 2), 3, 5),
        quad((1, 1), (2.5, 1), (2.5, 2), (1, 2), 4, 5),
    ]
    blocks = [oriented(g, k) for g, k in zip(base, orients, strict=True)]
    space = embed(blocks, list("abcd"))
    assert space.shape == (8, 8)
    assert space.n_components == 1
    check_nodes(space, blocks)
    assert (cell_areas(space) > 0).all()  # right-handed whatever the blocks' own orientation


def test_ring_round_a_hole_closes():
    blocks = frame()
    for turns in itertools.product(range(8), repeat=2):
        bl = [oriented(blocks[0], turns[0]), blocks[1], oriented(blocks[2], turns[1]), blocks[3]]
        space = embed(bl, ["s", "e", "n", "w"])
        assert space.shape == (7, 7)
        check_nodes(space, bl)
        assert (space.owner[2:4, 2:4] == -1).all()  # the hole
        assert not space.active_nodes[3, 3]


def test_ring_whose_counts_do_not_add_up():
    with pytest.raises(EmbeddingError, match=r"cells away.*do not add up") as err:
        embed(frame(2, 4), ["s", "e", "n", "w"])
    assert "'" in str(err.value) and "near (" in str(err.value)


def test_three_block_corner_is_named():
    c = np.array([0.0, 0.0])
    p = [np.array([np.cos(a), np.sin(a)]) for a in np.radians(np.arange(0, 360, 60))]
    blocks = [quad(c, p[2 * k], p[2 * k + 1], p[(2 * k + 2) % 6], 3, 3) for k in range(3)]
    with pytest.raises(EmbeddingError, match="3 or 5 blocks"):
        embed(blocks, ["a", "b", "c"])


def test_a_slit_ring_folds_onto_itself():
    bottom, right, top, left = frame()
    # the left block pulled off the bottom block by a hair: no interface there, so the ring
    # unrolls and comes back onto the bottom block's index nodes at other places
    cut = StructuredGrid(left.x.copy(), np.where(np.isclose(left.y, 1.0), 1.01, left.y))
    with pytest.raises(EmbeddingError, match="folds back"):
        embed([bottom, right, top, cut], ["s", "e", "n", "w"])


def test_parts_side_by_side_and_one_block():
    a = quad((0, 0), (1, 0), (1, 1), (0, 1), 3, 2)
    b = quad((5, 5), (6, 5), (6, 7), (5, 7), 2, 4)
    space = embed([a, b], ["a", "b"], gap=2)
    assert space.n_components == 2 and space.shape == (3 + 1 + 2 + 2 + 1, 5)
    check_nodes(space, [a, b])
    assert not space.active_nodes[4:6].any()
    one = embed([oriented(a, 5)])
    assert one.shape in ((4, 3), (3, 4)) and (cell_areas(one) > 0).all()
