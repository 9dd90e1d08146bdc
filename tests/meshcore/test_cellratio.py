"""The one-block cell counts: ``ni : nj`` at which the Winslow grid's median cell is square."""

from __future__ import annotations

import math

import numpy as np
import pytest

import meshcore
from meshcore import testing
from meshcore.cellratio import cell_ratio
from meshcore.io.outline import guess_cells, guess_corners
from tests.conftest import one_block_kwargs


def _rectangle(a: float, b: float, seed: int) -> tuple[np.ndarray, tuple[int, int, int, int]]:
    """An ``a × b`` rectangle's loop with unevenly spaced points on each side (clockwise for odd
    seeds) and its corners."""
    rng = np.random.default_rng(seed)

    def side(p, q, k):
        s = np.sort(rng.uniform(0.0, 1.0, k))
        return np.asarray(p) + np.outer(np.concatenate([[0.0], s]), np.subtract(q, p))

    parts = [side((0, 0), (a, 0), 7), side((a, 0), (a, b), 3), side((a, b), (0, b), 9), side((0, b), (0, 0), 4)]
    loop = np.vstack(parts)
    corners = np.cumsum([0] + [len(p) for p in parts[:3]])
    if seed % 2:
        loop, corners = loop[::-1], len(loop) - 1 - corners  # the same corners, indices of the reversed loop
    return loop, tuple(int(c) for c in corners)


def _median_log_aspect(g) -> float:
    """Median over the cells of log(ξ side / η side) (each the mean of the cell's two sides)."""
    x, y = g.x, g.y
    lxi = 0.5 * (np.hypot(*np.diff([x[:, :-1], y[:, :-1]], axis=1)) + np.hypot(*np.diff([x[:, 1:], y[:, 1:]], axis=1)))
    leta = 0.5 * (np.hypot(*np.diff([x[:-1], y[:-1]], axis=2)) + np.hypot(*np.diff([x[1:], y[1:]], axis=2)))
    return float(np.median(np.log(lxi / leta)))


@pytest.mark.parametrize("a,b,seed", [(10.0, 1.0, 0), (3.0, 7.0, 1), (1.0, 1.0, 2), (250.0, 4.0, 3), (5.0, 2.0, 4)])
def test_a_rectangle_keeps_its_side_ratio(a, b, seed):
    loop, corners = _rectangle(a, b, seed)
    assert cell_ratio(loop, corners) == pytest.approx(a / b, rel=1e-9)
    h = math.sqrt(a * b / 10_000)
    assert guess_cells(loop, corners) == (max(8, round(a / h)), max(8, round(b / h)))
    assert guess_cells(loop, corners, cell_size=a / 40) == (40, max(8, round(40 * b / a)))


def test_the_ratio_is_a_property_of_the_shape():
    loop = np.asarray(testing.channel_network(1).exterior.coords)[:-1]
    corners = guess_corners(loop)
    r = cell_ratio(loop, corners)
    c, s = math.cos(0.7), math.sin(0.7)
    moved = 3.5 * loop @ np.array([[c, s], [-s, c]]) + [1e5, -2e4]
    assert cell_ratio(moved, corners) == pytest.approx(r, rel=1e-6)
    sw, se, ne, nw = corners  # the same block turned by a quarter: ξ and η exchanged
    assert cell_ratio(loop, (se, ne, nw, sw)) == pytest.approx(1.0 / r, rel=0.05)


def test_undefined_where_the_loop_crosses_itself():
    bow = np.array([[0.0, 0.0], [2.0, 0.0], [0.0, 1.0], [2.0, 1.0]])  # a bow tie
    assert math.isnan(cell_ratio(bow, (0, 1, 2, 3)))


SHAPES = {
    "network-1": lambda: testing.channel_network(1),
    "network-4": lambda: testing.channel_network(4),
    "rough-network-10": lambda: testing.channel_network(10, roughness=0.15),
    "jagged-y": lambda: testing.jagged_cells(testing.y_junction(), 1.4, seed=0),
    "arms-1": lambda: testing.round_lake(1, kind="arms"),
    "spiral": lambda: testing.spiral(),
}


@pytest.mark.parametrize("name", sorted(SHAPES))
def test_the_guess_gives_near_square_cells(name):
    # the ratio of the borders' lengths gave cells 2–17 times longer across than along on these
    # (median log aspect -0.6 … -2.8): the bottom and top borders trace every arm in and out
    kw = one_block_kwargs(SHAPES[name](), 6000)
    g = meshcore.generate_block(**kw, repair="off", threads=1)
    assert abs(_median_log_aspect(g)) < math.log(1.4)


@pytest.mark.parametrize("name", ["spiral", "network-8"])
def test_the_default_call_is_fold_free(name):
    # with the ratio of the borders' lengths (438×13 and 26×226 cells at this size) the repair
    # left 1373 and 4 bad cells: rows too few for the arms and turns
    shape = {"spiral": testing.spiral, "network-8": lambda: testing.channel_network(8)}[name]()
    g = meshcore.generate_block(**one_block_kwargs(shape, 6000), threads=1)
    assert g.converged  # the repair reports a grid it could not make valid as not converged
    assert meshcore.quality(g).n_folded == 0
