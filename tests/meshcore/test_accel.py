"""Anderson mixing of the FAS cycles (meshcore.elliptic.accel): the formula, the safeguards, and
solves with it reaching the plain cycles' grid."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import meshcore
from meshcore import testing
from meshcore.elliptic import accel, multigrid
from meshcore.io.outline import guess_cells, guess_corners
from tests.meshcore.test_multigrid import _ring


# ------------------------------------------------------------------ the formula
def _linear_map(n: int, seed: int = 0):
    """``G(x) = M x + b`` with a symmetric contraction M (eigenvalues 0.1–0.95) and its fixed point."""
    rng = np.random.default_rng(seed)
    q, _ = np.linalg.qr(rng.standard_normal((n, n)))
    m = (q * np.linspace(0.1, 0.95, n)) @ q.T
    b = rng.standard_normal(n)
    return (lambda x: m @ x + b), np.linalg.solve(np.eye(n) - m, b)


def test_anderson_reaches_the_fixed_point_in_fewer_steps():
    g, xs = _linear_map(40)
    plain, n_plain = np.zeros(40), 0
    while np.abs(plain - xs).max() >= 1e-9 and n_plain < 1000:
        plain, n_plain = g(plain), n_plain + 1
    acc = accel.Anderson(40, depth=6)
    x, n_mixed = np.zeros(40), 0
    while np.abs(x - xs).max() >= 1e-9 and n_mixed < 1000:
        gx = g(x)
        mixed = acc.mix(x, gx)
        x, n_mixed = (gx if mixed is None else mixed.copy()), n_mixed + 1
    assert np.abs(x - xs).max() < 1e-9
    assert acc.mixed > 0 and n_mixed < n_plain / 2


def test_anderson_waits_for_min_pairs_and_drops_ill_conditioned_differences():
    acc = accel.Anderson(5, depth=3)
    x = np.arange(5.0)
    assert acc.mix(x, x + 1.0) is None  # no difference yet
    # the same step again: a zero difference (singular Gram matrix) gives no mixed iterate
    assert acc.mix(x, x + 1.0) is None
    assert acc.mixed == 0


# ------------------------------------------------------------------ the safeguards
def _primed_mixer(folds):
    """A mixer on one array that has started (a slow cycle) and holds enough differences."""
    a = np.zeros(6)
    mixer = accel.Mixer([a], folds, depth=3)
    g, _ = _linear_map(6, seed=1)
    history = [(0, 1.0), (1, 0.9), (2, 0.8)]  # slower than START_RATE: the mixing starts
    for _ in range(accel.MIN_PAIRS):
        mixer.before(history)
        a[...] = g(a)
        assert not mixer.after()
    mixer.before(history)
    a[...] = g(a)
    image = a.copy()
    assert mixer.after()  # the arrays hold the mixed iterate now
    assert not np.array_equal(a, image)
    return mixer, a, image


def test_a_mixed_iterate_that_raises_the_residual_is_replaced_by_the_cycles_image():
    mixer, a, image = _primed_mixer(lambda arrays: 0)
    assert not mixer.keep(2.0 * mixer.r_ref)
    np.testing.assert_array_equal(a, image)
    assert mixer.why[-1][0] == "residual" and mixer.acc is not None and mixer.acc.count == 0


def test_a_mixed_iterate_that_folds_more_cells_is_replaced_by_the_cycles_image():
    # the fold count of the image (a view of the mixer's copy) is 1, the mixed arrays' 3
    mixer, a, image = _primed_mixer(lambda arrays: 3 if arrays[0] is not None and np.shares_memory(arrays[0], a) else 1)
    assert not mixer.keep(0.5 * mixer.r_ref)
    np.testing.assert_array_equal(a, image)
    assert mixer.why[-1] == ("folds", 3, 1)


def test_a_better_mixed_iterate_is_kept():
    mixer, a, _ = _primed_mixer(lambda arrays: 0)
    mixed = a.copy()
    assert mixer.keep(0.5 * mixer.r_ref)
    np.testing.assert_array_equal(a, mixed)
    assert not mixer.why


def test_folded_cells_counts_cells_turned_against_the_majority():
    x, y = np.meshgrid(np.arange(6.0), np.arange(5.0), indexing="ij")
    assert accel.folded_cells(x, y) == 0
    assert accel.folded_cells(x[::-1].copy(), y) == 0  # orientation does not count
    y[2, 2] -= 4.0  # thrown below the bottom border: some of its cells fold
    n = accel.folded_cells(x, y)
    assert 0 < n <= 4
    # the same cells as corner ids of flat arrays (counter-clockwise)
    ids = np.arange(x.size).reshape(x.shape)
    cells = np.stack([ids[:-1, :-1], ids[1:, :-1], ids[1:, 1:], ids[:-1, 1:]], axis=-1).reshape(-1, 4)
    assert accel.folded_cells(x.ravel(), y.ravel(), cells) == n


# ------------------------------------------------------------------ solves
def _stretched(ni: int, nj: int, ratio: float = 1.05) -> meshcore.StructuredGrid:
    """Wavy bottom and top borders, cells stretched geometrically along ξ (line-smoothed)."""
    s = np.cumsum(np.r_[0.0, ratio ** np.arange(ni)])
    s /= s[-1]
    t = np.linspace(0.0, 1.0, nj + 1)
    bottom = np.column_stack([3 * s, 0.4 * np.sin(np.pi * s)])
    top = np.column_stack([3 * s, 1 + 0.6 * np.sin(2 * np.pi * s)])
    left = np.column_stack([0.1 * np.sin(np.pi * t), t])
    right = np.column_stack([3 + 0.3 * np.sin(np.pi * t), t])
    return meshcore.initial_grid(meshcore.prepare_borders(bottom, right, top, left))


def _ring_start() -> meshcore.StructuredGrid:
    """An annulus O-grid (periodic: curved, stretched radially) from a straight radial start."""
    X, Y = _ring(96, 48)
    t = np.linspace(0.0, 1.0, X.shape[1])
    return meshcore.StructuredGrid(
        X[:, :1] + (X[:, -1:] - X[:, :1]) * t, Y[:, :1] + (Y[:, -1:] - Y[:, :1]) * t, periodic=True
    )


def _lake(seed: int, nodes: int, shape=testing.channel_network) -> dict:
    """A generated shape's outer ring (a channel network's) as one block, as ``meshcore import``
    chooses it."""
    loop = np.asarray(shape(seed).exterior.coords)[:-1]
    corners = guess_corners(loop)
    ci, cj = guess_cells(loop, corners)
    s = math.sqrt(nodes / ((ci + 1) * (cj + 1)))
    return {"loop": loop, "corners": corners, "cells": (max(4, round(ci * s)), max(4, round(cj * s)))}


def _solve_both(monkeypatch, solve):
    """The grid of ``solve()`` with plain cycles and with mixing (and the mixer)."""
    monkeypatch.setattr(multigrid, "ACCEL", False)
    plain = solve()
    monkeypatch.setattr(multigrid, "ACCEL", True)
    mixed = solve()
    return plain, mixed, multigrid.last_run["accel"]


@pytest.mark.parametrize("case", ["stretched", "ring"])
def test_mixed_cycles_reach_the_plain_cycles_grid_on_model_problems(monkeypatch, case):
    # these converge at 0.05-0.3 per cycle: mix from the first cycle to exercise it
    monkeypatch.setattr(accel, "START_RATE", 0.0)
    monkeypatch.setattr(accel, "MIN_PAIRS", 1)
    g0 = _stretched(160, 40) if case == "stretched" else _ring_start()
    plain, mixed, mixer = _solve_both(
        monkeypatch, lambda: meshcore.solve(g0, method="multigrid", threads=1, tolerance=1e-10)
    )
    assert plain.converged and mixed.converged and mixed.info.message == "converged"
    assert mixer.acc is not None and mixer.acc.mixed > 0
    size = max(np.ptp(plain.x), np.ptp(plain.y))
    assert max(np.abs(mixed.x - plain.x).max(), np.abs(mixed.y - plain.y).max()) < 1e-8 * size
    if case == "ring":
        np.testing.assert_array_equal(mixed.x[-1], mixed.x[0])


def test_mixed_cycles_on_a_branched_lake_take_fewer_cycles_to_the_same_grid(monkeypatch):
    kw = _lake(1, 3000)
    plain, mixed, mixer = _solve_both(monkeypatch, lambda: meshcore.generate_block(**kw, threads=1, repair="off"))
    assert multigrid.last_run["lines"]
    assert plain.converged and mixed.converged and mixed.info.message == "converged"
    assert mixer.acc is not None and mixer.acc.mixed > 0
    assert mixed.iterations < plain.iterations
    # both within the solve tolerance of the tightly converged grid
    monkeypatch.setattr(multigrid, "ACCEL", False)
    tight = meshcore.generate_block(**kw, threads=1, repair="off", tolerance=1e-11)
    err_plain = max(np.abs(plain.x - tight.x).max(), np.abs(plain.y - tight.y).max())
    err_mixed = max(np.abs(mixed.x - tight.x).max(), np.abs(mixed.y - tight.y).max())
    assert err_mixed < 3 * err_plain + 1e-9 * max(np.ptp(tight.x), np.ptp(tight.y))
    assert meshcore.quality(mixed).n_folded == meshcore.quality(plain).n_folded


def test_the_fold_safeguard_rejects_in_a_solve_and_the_solve_converges(monkeypatch):
    # a generated network whose branches fold while the cycles converge: a mixed grid with more
    # folded cells than the cycle's own is rejected once, the solve goes on and converges
    kw = _lake(3, 3000)
    plain, mixed, mixer = _solve_both(monkeypatch, lambda: meshcore.generate_block(**kw, threads=1, repair="off"))
    assert any(w[0] == "folds" for w in mixer.why), mixer.why
    assert mixed.converged and mixed.info.message == "converged"
    assert meshcore.quality(mixed).n_folded == meshcore.quality(plain).n_folded


def test_point_smoothed_solves_that_may_go_on_with_lines_are_not_mixed(monkeypatch):
    # their stall is what hands them to the line smoother
    monkeypatch.setattr(multigrid, "ACCEL", True)
    monkeypatch.setattr(accel, "START_RATE", 0.0)
    g = meshcore.generate_block(**_lake(0, 6000, testing.lake_with_islands), threads=1, repair="off")
    assert g.converged and g.method == "multigrid" and not multigrid.last_run["lines"]
    assert multigrid.last_run["accel"] is None


def test_mixed_serial_and_two_threads_give_bit_identical_grids(monkeypatch):
    monkeypatch.setattr(multigrid, "ACCEL", True)
    kw = _lake(1, 12000)  # levels above PARALLEL_MIN_NODES run the parallel kernels
    a = meshcore.generate_block(**kw, threads=1, repair="off")
    mixer = multigrid.last_run["accel"]
    b = meshcore.generate_block(**kw, threads=2, repair="off")
    assert mixer is not None and mixer.acc is not None and mixer.acc.mixed > 0
    assert a.iterations == b.iterations
    assert np.array_equal(a.x, b.x) and np.array_equal(a.y, b.y)


def test_mixing_is_an_option_that_is_off_by_default():
    # see multigrid.ACCEL: the fold-free repair is sensitive to where in the tolerance its start lies
    assert multigrid.ACCEL is False


def test_multiblock_mixing_is_an_option_that_reaches_the_plain_cycles_grid(monkeypatch):
    # off by default (it did not pay on the multiblock cycles, see meshcore.multiblock.multigrid);
    # on, and mixing from the first cycle, the same grid within the solve tolerance
    from meshcore.case import case_topology, load_case
    from meshcore.multiblock import multigrid as mbmg
    from meshcore.multiblock import solve_multiblock

    assert mbmg.ACCEL is False
    topo = case_topology(
        load_case(Path(__file__).resolve().parents[2] / "resources/examples/shasta-multiblock-fine.toml")
    )
    plain = solve_multiblock(topo, threads=1, tolerance=1e-9)
    monkeypatch.setattr(mbmg, "ACCEL", True)
    monkeypatch.setattr(accel, "START_RATE", 0.0)
    monkeypatch.setattr(accel, "MIN_PAIRS", 1)
    mixed = solve_multiblock(topo, threads=1, tolerance=1e-9)
    mixer = mbmg.last_run["accel"]
    assert mixer is not None and mixer.acc is not None and mixer.acc.mixed > 0
    assert plain.info.converged and mixed.info.converged
    size = max(max(np.ptp(g.x), np.ptp(g.y)) for g in plain.grids)
    for a, b in zip(plain.grids, mixed.grids, strict=True):
        assert max(np.abs(a.x - b.x).max(), np.abs(a.y - b.y).max()) < 1e-6 * size
