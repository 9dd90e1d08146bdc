"""benchmarks/meshkernel_compare.py: grids reach MeshKernel and come back unchanged, the
orthogonalisation box moves only the sides asked for, and the interface measures agree with
meshcore.quality.  Skipped where the ``bench`` extra (meshkernel) is not installed."""

from __future__ import annotations

import importlib.util
import sys

import numpy as np
import pytest

from meshcore import StructuredGrid
from meshcore.multiblock import from_outline, solve_multiblock
from meshcore.quality import lake_metrics
from tests.conftest import ROOT


@pytest.fixture(scope="module")
def mc():
    spec = importlib.util.spec_from_file_location("meshkernel_compare", ROOT / "benchmarks" / "meshkernel_compare.py")
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod  # dataclasses look their module up there
    try:
        spec.loader.exec_module(mod)
        yield mod
    finally:
        sys.modules.pop(spec.name, None)


def _wavy(ni: int, nj: int) -> StructuredGrid:
    xi, eta = np.meshgrid(np.linspace(0, 1, ni + 1), np.linspace(0, 1, nj + 1), indexing="ij")
    x = 3.0 * xi + 0.4 * eta**2 + 0.05 * np.sin(7 * xi) * np.sin(3 * eta)
    y = eta + 0.2 * xi**2 + 0.03 * np.cos(5 * xi)
    return StructuredGrid(x + 5.0e5, y + 4.2e6)  # UTM-sized coordinates


def _two_blocks():
    ring = [[0, 0], [2, 0], [2, 1], [0, 1]]
    blocks = [
        {"name": "w", "corners": [[0, 0], [1, 0], [1, 1], [0, 1]], "cells": [6, 4]},
        {"name": "e", "corners": [[1, 0], [2, 0], [2, 1], [1, 1]], "cells": [6, 4]},
    ]
    return from_outline(ring, cuts=[[[1, 0], [1, 1]]], blocks=blocks).topology


def test_round_trip_is_exact_and_keeps_the_index_order(mc):
    pytest.importorskip("meshkernel")
    g = _wavy(9, 5)
    mk = mc.to_meshkernel(g)
    cg = mk.curvilineargrid_get()
    assert (cg.num_m, cg.num_n) == (10, 6)  # m along i, n along j
    back = mc.from_meshkernel(mk, g)
    assert np.array_equal(back.x, g.x) and np.array_equal(back.y, g.y)


@pytest.mark.parametrize("sliding", [(True, False, False, False), (False, False, True, True), (False,) * 4])
def test_only_the_sides_asked_for_move(mc, sliding):
    mkp = pytest.importorskip("meshkernel")
    g = _wavy(9, 6)
    out, _, _ = mc.orthogonalize_block(g, mkp.OrthogonalizationParameters(), sliding)
    sides = ((0, slice(1, -1)), (-1, slice(1, -1)), (slice(1, -1), 0), (slice(1, -1), -1))
    for s, sl in zip(sliding, sides, strict=True):
        moved = np.hypot(out.x[sl] - g.x[sl], out.y[sl] - g.y[sl])
        assert (moved.max() > 1e-6) == s
    corners = (0, -1)
    for i in corners:
        for j in corners:
            assert (out.x[i, j], out.y[i, j]) == (g.x[i, j], g.y[i, j])
    assert np.abs(out.x[1:-1, 1:-1] - g.x[1:-1, 1:-1]).max() > 1e-4  # the interior is orthogonalised


def test_shore_sides_of_two_blocks(mc):
    topo = _two_blocks()
    # (left, right, bottom, top): the cut is w's right side and e's left side
    assert mc.shore_sides(topo) == [(True, False, True, True), (False, True, True, True)]


def test_interface_measures(mc):
    topo = _two_blocks()
    grids = list(solve_multiblock(topo).grids)
    assert mc.interface_gap(topo, grids) == 0.0
    expected = np.sort(lake_metrics(grids).values("interface_ratio"))
    assert np.allclose(np.sort(mc.interface_ratios(topo, grids)), expected, rtol=1e-12)
    # pull one interface node of w sideways: the gap is the pull, the blocks no longer meet there
    x = np.array(grids[0].x)
    x[-1, 2] += 0.05
    grids[0] = grids[0].replaced(x=x)
    assert mc.interface_gap(topo, grids) == pytest.approx(0.05)
    assert mc.interface_ratios(topo, grids).max() > expected.max()
