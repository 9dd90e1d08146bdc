"""The cell-count program (:func:`meshcore.multiblock.counts.solve_counts`) reaches its optimum.

Oracles: every integer count in a box, evaluated by the objective written out here (small
layouts), and the plain program without the hull rows (generated layouts of many blocks).
"""

from __future__ import annotations

import numpy as np
import pytest

import meshcore.multiblock.counts as counts
from meshcore import testing
from meshcore.layout import auto_layout
from meshcore.multiblock.counts import solve_counts


def _objective(
    t, sides, n, *, min_cells=3, multiple=1, least=None, least_weight=None, block_cells=None, fixed=None, best=True
):
    """The program's objective at integer counts ``n`` (rows: candidates), ``inf`` where a
    constraint fails: the docstring's terms, each written out per candidate."""
    t = np.asarray(t, float)
    n = np.atleast_2d(n).astype(float)
    m = multiple
    ok = np.all(n % m == 0, axis=1) & np.all(n >= m, axis=1)
    for c, v in (fixed or {}).items():
        ok &= n[:, c] == v
    obj = -1e-3 * n.sum(axis=1) + 0.25 * np.abs(n - t).sum(axis=1)
    for bi, (bottom, right, top, left) in enumerate(sides):
        for a, b in ((bottom, top), (left, right)):
            na, nb = n[:, list(a)].sum(axis=1), n[:, list(b)].sum(axis=1)
            ok &= na == nb
            obj += np.abs(na - 0.5 * (t[list(a)].sum() + t[list(b)].sum()))
        for side in (bottom, right, top, left):
            ok &= n[:, list(side)].sum(axis=1) >= min_cells
        if block_cells and bi in block_cells:
            ok &= n[:, list(bottom)].sum(axis=1) == block_cells[bi][0]
            ok &= n[:, list(left)].sum(axis=1) == block_cells[bi][1]
    for ca, ta, cb, tb in counts._jump_pairs(t, sides, least=float(m)):
        w = min(ta, tb)
        d1, d2 = n[:, ca].sum(axis=1) / ta, n[:, cb].sum(axis=1) / tb
        excess = np.maximum(w * (d1 - counts.JUMP * d2), w * (d2 - counts.JUMP * d1))
        obj += counts.JUMP_WEIGHT * np.maximum(0.0, excess)
    if least is not None:
        for c, v in enumerate(least):
            if v > m:
                w = counts.LEAST_WEIGHT if least_weight is None else least_weight[c]
                obj += w * np.maximum(0.0, v - n[:, c])
    return np.where(ok, obj, np.inf)


# small layouts (chains per block side: bottom, right, top, left)
LAYOUTS = {
    "T on one side": [([0, 1], [2], [3], [4])],
    "two blocks in a row": [([0], [1], [2], [3]), ([4], [5], [6], [1])],
    "Y star": [([0], [3], [1], [2]), ([5], [6], [7], [4, 0])],
}


def _box(sides, nc: int, values) -> np.ndarray:
    """Every assignment of ``values`` to the chains that meets the blocks' equalities (a
    depth-first search, each equality checked once its last chain has a count)."""
    eqs = [(list(a), list(b)) for bottom, right, top, left in sides for a, b in ((bottom, top), (left, right))]
    due = {d: [e for e in eqs if max(e[0] + e[1]) == d] for d in range(nc)}
    out = []

    def extend(n: list[int]) -> None:
        if len(n) == nc:
            out.append(list(n))
            return
        for v in values:
            n.append(v)
            if all(sum(n[c] for c in a) == sum(n[c] for c in b) for a, b in due[len(n) - 1]):
                extend(n)
            n.pop()

    extend([])
    return np.array(out)


@pytest.mark.parametrize("name", list(LAYOUTS))
@pytest.mark.parametrize("seed", range(6))
def test_counts_are_the_best_of_every_count_in_a_box(name, seed, request):
    """Random targets (with a ``least`` count on one chain, a multiple of 2 on odd seeds; from
    seed 4 on, a ``least_weight`` of its own on every chain): the counts meet every constraint
    and no integer counts in a box around them do better."""
    sides = LAYOUTS[name]
    nc = 1 + max(c for block in sides for side in block for c in side)
    rng = np.random.default_rng(seed)
    m = 1 + seed % 2
    t = np.round(rng.uniform(1.0, 5.5, nc) * m, 3)
    least = np.zeros(nc)
    least[seed % nc] = round(float(t[seed % nc]) + 1.7 * m, 3)
    kw = {"min_cells": 2, "multiple": m, "least": least}
    if seed >= 4:
        kw["least_weight"] = np.round(rng.uniform(1.0, 20.0, nc), 3)
    if (name, seed) == ("T on one side", 5):
        # HiGHS (scipy 1.17.1) ends at 20.23, "optimal"; 19.90 with presolve off (also with the
        # plain LEAST_WEIGHT at 8 or more): a presolve miss, not the program
        request.applymarker(pytest.mark.xfail(strict=True, reason="HiGHS presolve stops short"))
    n = solve_counts(t, sides, **kw)
    top = 13 * m
    assert np.all(n < top), "the optimum must lie in the box for the box to be an oracle"
    box = _box(sides, nc, range(m, top, m))
    brute = _objective(t, sides, box, **kw)
    got = _objective(t, sides, n, **kw)[0]
    assert np.isfinite(got)
    assert got == pytest.approx(brute.min(), abs=1e-9)


def _programs(shape, monkeypatch) -> list[tuple]:
    """The arguments of every program a layout of ``shape`` solves."""
    calls = []
    real = counts.solve_counts

    def record(targets, sides, **kw):
        calls.append((np.array(targets, float), [tuple(list(s) for s in b) for b in sides], kw))
        return real(targets, sides, **kw)

    monkeypatch.setattr(counts, "solve_counts", record)
    monkeypatch.setattr("meshcore.layout.blocks.solve_counts", record)
    auto_layout(shape, target_cells=6000, multiple=4)
    monkeypatch.undo()
    return [c for c in calls if c[2].get("best", True)]


@pytest.mark.parametrize(
    "shape",
    [
        pytest.param(lambda: testing.channel_network(1, n_branches=25), id="channels"),
        pytest.param(lambda: testing.lake_with_islands(2, n_islands=10), id="islands"),
    ],
)
def test_many_blocks_reach_the_plain_programs_optimum(shape, monkeypatch):
    """Layouts of tens of blocks: the program with the hull rows ends at the objective of the
    program without them (HiGHS solves both to optimality), every constraint met."""
    programs = _programs(shape(), monkeypatch)
    assert programs and max(len(p[1]) for p in programs) >= 20
    for t, sides, kw in programs:
        n = solve_counts(t, sides, **kw)
        monkeypatch.setattr(counts, "HULL_CUTS", False)
        plain = solve_counts(t, sides, **kw)
        monkeypatch.setattr(counts, "HULL_CUTS", True)
        got, want = _objective(t, sides, n, **kw)[0], _objective(t, sides, plain, **kw)[0]
        assert np.isfinite(got)
        assert got == pytest.approx(want, abs=1e-6)
