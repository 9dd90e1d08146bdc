"""Cell counts of blocks whose cells are given: the search (:mod:`meshcore.multiblock.countsearch`)
lists every solution and reaches HiGHS's optimum.

Oracles: every assignment in a box that meets the constraints (small systems) and the program
solved by HiGHS (``counts.SEARCH = False``) on random brick layouts: a rectangle cut again and
again along lattice lines (T-junctions where a cut ends on another), every lattice interval a
random number of cells, so the blocks' cells always have a solution; one block's cells changed by
``multiple`` leaves none.
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest

import meshcore.multiblock.counts as counts
from meshcore.errors import TopologyError
from meshcore.multiblock.counts import solve_counts
from meshcore.multiblock.countsearch import best_counts

from .test_counts_program import _objective


def bricks(seed: int, n_blocks: int, multiple: int):
    """A random brick layout: ``(targets, sides, block_cells, least)`` of :func:`solve_counts`.

    Blocks are lattice rectangles (a rectangle split at random interior lattice lines, a third
    of the pieces removed, so that kept sides have shore parts between their neighbours); every
    block side is cut into chains at the corners of the kept blocks that lie on it.  Lattice
    intervals get random cells (multiples of ``multiple``) and random real lengths; a chain's
    target is its length over a cell size near the mean, so the given cells are close to but not
    the targets, and a few shore chains get a ``least`` count."""
    rng = np.random.default_rng(seed)
    nx, ny = 4 + n_blocks, 4 + n_blocks
    rects = [(0, 0, nx, ny)]
    while len(rects) < n_blocks:
        i = int(rng.integers(len(rects)))
        x0, y0, x1, y1 = rects[i]
        horizontal = (y1 - y0 > x1 - x0) if rng.random() < 0.7 else rng.random() < 0.5
        if horizontal and y1 - y0 > 1:
            y = int(rng.integers(y0 + 1, y1))
            rects[i : i + 1] = [(x0, y0, x1, y), (x0, y, x1, y1)]
        elif not horizontal and x1 - x0 > 1:
            x = int(rng.integers(x0 + 1, x1))
            rects[i : i + 1] = [(x0, y0, x, y1), (x, y0, x1, y1)]
    drop = rng.permutation(len(rects))[: len(rects) // 3]  # water removed: shore parts on kept sides
    rects = [r for i, r in enumerate(rects) if i not in drop]
    cx = multiple * rng.integers(1, 6, nx)  # cells per lattice interval
    cy = multiple * rng.integers(1, 6, ny)
    wx, wy = rng.uniform(0.5, 2.0, nx), rng.uniform(0.5, 2.0, ny)  # lengths per interval
    corners = {(x, y) for x0, y0, x1, y1 in rects for x in (x0, x1) for y in (y0, y1)}
    index: dict[tuple, int] = {}
    targets: list[float] = []
    users: list[int] = []
    h = float(wx.sum() / cx.sum() + wy.sum() / cy.sum()) / 2

    def chains(a, b, fixed, along_x):
        on_line = [(x if along_x else y) for x, y in corners if (y if along_x else x) == fixed]
        cuts = sorted({a, b} | {p for p in on_line if a < p < b})
        out = []
        for p, q in itertools.pairwise(cuts):
            key = (along_x, fixed, p, q)
            if key not in index:
                index[key] = len(targets)
                targets.append(float((wx if along_x else wy)[p:q].sum()) / h)
                users.append(0)
            users[index[key]] += 1
            out.append(index[key])
        return out

    sides, cells = [], {}
    for bi, (x0, y0, x1, y1) in enumerate(rects):
        bottom, top = chains(x0, x1, y0, True), chains(x0, x1, y1, True)[::-1]
        left, right = chains(y0, y1, x0, False)[::-1], chains(y0, y1, x1, False)
        sides.append((bottom, right, top, left))
        cells[bi] = (int(cx[x0:x1].sum()), int(cy[y0:y1].sum()))
    t = np.round(np.array(targets), 3)
    least = np.where((np.array(users) == 1) & (rng.random(len(t)) < 0.2), t + 2.5 * multiple, 0.0)
    return t, sides, cells, least


def _searched(t, sides, cells, m, least=None, **kw):
    """:func:`best_counts` with the program's objective: (counts or None, every candidate row
    the objective saw)."""
    seen: list[np.ndarray] = []
    objective = counts.objective(t, sides, counts._jump_pairs(t, sides, least=float(m))[0], _short(least, m))

    def cost(rows):
        seen.extend(rows)
        return objective(rows)

    return best_counts(len(t), sides, multiple=m, min_cells=1, block_cells=cells, cost=cost, **kw), seen


def _short(least, m):
    return [] if least is None else [(c, float(v)) for c, v in enumerate(least) if v > m]


# a basin whose top side is shore, arm, shore, arm, shore (the Shasta examples' main block)
ARMS = [([0], [1], [2, 3, 4, 5, 6], [7]), ([3], [8], [9], [10]), ([5], [11], [12], [13])]


@pytest.mark.parametrize("seed", range(8))
def test_the_search_finds_the_best_of_every_count(seed):
    """A basin with two arms on its top side (three shore chains share what the arms leave):
    the searched counts are the best of every assignment of the shore chains, by the objective
    written out in ``test_counts_program`` (random targets, a ``least`` on odd seeds)."""
    rng = np.random.default_rng(seed)
    m = 1 + seed % 2
    ni, a1, a2 = m * int(rng.integers(8, 16)), m * int(rng.integers(1, 4)), m * int(rng.integers(1, 4))
    cells = {0: (ni, 3 * m), 1: (a1, 2 * m), 2: (a2, 4 * m)}
    t = np.round(rng.uniform(0.5, 1.5, 14) * [ni, 3 * m, 0, a1, 0, a2, 0, 3 * m, 2 * m, a1, 2 * m, 4 * m, a2, 4 * m], 3)
    t[[2, 4, 6]] = np.round(rng.uniform(0.5, 4.0, 3) * m, 3)
    least = np.zeros(14)
    if seed % 2:
        least[4] = t[4] + 2.5 * m
    kw = {"min_cells": 1, "multiple": m, "block_cells": cells, "least": least}
    got, seen = _searched(t, ARMS, cells, m, least)
    base = np.array([ni, 3 * m, 0, a1, 0, a2, 0, 3 * m, 2 * m, a1, 2 * m, 4 * m, a2, 4 * m])
    every = []
    for n2, n4 in itertools.product(range(m, ni + 1, m), repeat=2):
        n = base.copy()
        n[[2, 4, 6]] = n2, n4, ni - a1 - a2 - n2 - n4
        every.append(n)
    brute = _objective(t, ARMS, np.array(every), **kw)
    assert len(seen) == np.isfinite(brute).sum() > 1  # the search saw every solution, once
    assert _objective(t, ARMS, got, **kw)[0] == pytest.approx(brute.min(), abs=1e-9)
    assert np.array_equal(got, solve_counts(t, ARMS, **kw))


def test_the_search_reaches_the_programs_optimum(monkeypatch):
    """60 random brick layouts of 3-14 blocks: the searched counts meet every constraint and have
    the objective of HiGHS's counts (its optimum), on layouts with one solution and with several."""
    several = 0
    for seed in range(60):
        m = (1, 2, 4)[seed % 3]
        t, sides, cells, least = bricks(seed, 3 + seed % 12, m)
        kw = {"min_cells": 1, "multiple": m, "block_cells": cells, "least": least}
        found, seen = _searched(t, sides, cells, m, least)
        got = solve_counts(t, sides, **kw)
        monkeypatch.setattr(counts, "SEARCH", False)
        want = solve_counts(t, sides, **kw)
        monkeypatch.setattr(counts, "SEARCH", True)
        a, b = _objective(t, sides, got, **kw)[0], _objective(t, sides, want, **kw)[0]
        assert np.isfinite(a)
        assert a == pytest.approx(b, abs=1e-6), seed
        assert found is not None  # (below MAX_NODES)
        several += len(seen) > 1
        assert np.array_equal(found, got)
        assert np.array_equal(got, want), seed  # one optimum (counts.ALIKE, TIE_BREAK)
    assert several >= 10


def test_cells_that_do_not_fit_give_the_programs_error(monkeypatch):
    """Brick layouts with one block's cells changed by ``multiple``: the search finds counts
    exactly when HiGHS does (with the same objective), else both raise :class:`TopologyError`
    (and :func:`~meshcore.multiblock.chains.chain_topology`'s step-by-step count then says where)."""
    raised = 0
    for seed in range(24):
        m = (1, 2, 4)[seed % 3]
        t, sides, cells, _ = bricks(seed, 3 + seed % 6, m)
        for bi in range(len(sides)):
            ni, nj = cells[bi]
            changed = {**cells, bi: (ni + m, nj) if (seed + bi) % 2 else (ni, nj + m)}
            kw = {"min_cells": 1, "multiple": m, "block_cells": changed}
            out = []
            for search in (True, False):
                monkeypatch.setattr(counts, "SEARCH", search)
                try:
                    out.append(_objective(t, sides, solve_counts(t, sides, **kw), **kw)[0])
                except TopologyError as e:
                    assert "no integer cell counts" in str(e)
                    out.append(None)
            assert (out[0] is None) == (out[1] is None), (seed, bi)
            if out[0] is None:
                raised += 1
                with pytest.raises(TopologyError):  # the search's own answer, not HiGHS's
                    _searched(t, sides, changed, m)
            else:
                assert out[0] == pytest.approx(out[1], abs=1e-6)
    assert raised >= 20


def test_the_search_gives_up_where_it_does_not_apply():
    """A block without given cells, or a search beyond ``max_nodes``: None (HiGHS decides)."""
    t, sides, cells, _ = bricks(5, 8, 4)
    found, seen = _searched(t, sides, cells, 4)
    assert found is not None and len(seen) > 1
    partial = dict(list(cells.items())[1:])
    assert _searched(t, sides, partial, 4)[0] is None
    assert _searched(t, sides, cells, 4, max_nodes=1)[0] is None
    # one block with a T on its bottom: 10 cells shared by two chains, 9 ways (one group)
    sides1 = [([0, 1], [2], [3], [4])]
    t1 = np.array([3.0, 7.2, 4.0, 10.0, 4.0])
    found, seen = _searched(t1, sides1, {0: (10, 4)}, 1)
    assert sorted(int(r[0]) for r in seen) == list(range(1, 10))
    assert found.tolist() == [3, 7, 4, 10, 4]
    assert _searched(t1, sides1, {0: (10, 4)}, 1, max_nodes=5)[0] is None


def test_the_shasta_example_needs_no_highs(monkeypatch):
    """The 7-block example case's counts come from the search (HiGHS is not called) and are the
    program's."""
    from pathlib import Path

    from meshcore.case import load_case
    from meshcore.case.multiblock import _outline_topology

    case = load_case(Path(__file__).resolve().parents[2] / "resources/examples/shasta-multiblock-fine.toml")
    calls = []
    real = solve_counts

    def record(*a, **k):
        calls.append((a, k))
        return real(*a, **k)

    monkeypatch.setattr(counts, "solve_counts", record)

    def no_milp(*a, **k):
        raise AssertionError("HiGHS was called")

    import scipy.optimize

    monkeypatch.setattr(scipy.optimize, "milp", no_milp)
    _outline_topology(case)
    monkeypatch.undo()
    assert calls
    for a, k in calls:
        got = solve_counts(*a, **k)
        monkeypatch.setattr(counts, "SEARCH", False)
        assert np.array_equal(got, solve_counts(*a, **k))
        monkeypatch.setattr(counts, "SEARCH", True)
