"""The one-block multigrid on skewed cells (issue 15): grid lines that cross at a small angle.

The branched lakes as one block converge at 0.77–0.82 per cycle because 30–46 % of their nodes
have grid lines crossing at ``ρ = |cos θ| > 0.9`` and the slowest modes of the cycle sit there
(``benchmarks/skew_rates.py``, whose model problem these tests use).  A parallelogram's affine
grid is the exact Winslow solution: these tests check that both smoothers converge to it by
multigrid, and guard the rate per cycle (measured at 64 × 64 cells: lines 0.04 at ρ = 0, 0.67 at
ρ = 0.95; points 0.06 and 0.75).
"""

from __future__ import annotations

import numpy as np
import pytest

import meshcore
from meshcore.elliptic import multigrid
from tests.conftest import benchmark_module

B = benchmark_module("skew_rates")
N = 64


def _solve(monkeypatch, start, lines: bool, tol: float):
    monkeypatch.setattr(multigrid, "anisotropic", lambda x, y: lines)
    g = meshcore.solve(start, threads=1, method="multigrid", tolerance=tol)
    assert multigrid.last_run["lines"] is lines
    return g


@pytest.mark.parametrize("lines", [False, True])
@pytest.mark.parametrize("rho", [0.9, 0.98])
def test_a_skewed_grid_converges_by_multigrid_to_the_affine_grid(monkeypatch, rho, lines):
    x, y, start = B.parallelogram(rho, N)
    g = _solve(monkeypatch, start, lines, 1e-10)
    assert g.converged and "SOR" not in g.info.message
    # 1e-8–4e-8 measured: the error sits far above the residual on skewed cells
    assert np.hypot(g.x - x, g.y - y).max() < 1e-6


@pytest.mark.parametrize(
    ("lines", "rho", "most"), [(True, 0.0, 0.2), (True, 0.95, 0.75), (False, 0.0, 0.2), (False, 0.95, 0.8)]
)
def test_rate_per_cycle_on_a_skewed_model_problem(monkeypatch, lines, rho, most):
    *_, start = B.parallelogram(rho, N)
    g = _solve(monkeypatch, start, lines, 1e-12)
    assert g.converged
    assert B.tail_rate(g) < most
