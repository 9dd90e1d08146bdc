"""Metrics and quality: exact values on affine maps, invariances, fold detection."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import meshcore
from meshcore.quality import cell_quality
from tests.conftest import annulus_sector

INVARIANT = ["jacobian_ratio", "orthogonality", "skewness", "aspect_ratio", "size_ratio"]


def test_metrics_of_an_affine_map_are_exact():
    xi, eta = np.meshgrid(np.arange(6.0), np.arange(4.0), indexing="ij")
    x, y = 2.0 * xi + 0.5 * eta, 0.25 * xi + 1.5 * eta
    m = meshcore.metrics(meshcore.StructuredGrid(x, y))
    np.testing.assert_allclose(m.x_xi, 2.0)
    np.testing.assert_allclose(m.x_eta, 0.5)
    np.testing.assert_allclose(m.y_xi, 0.25)
    np.testing.assert_allclose(m.y_eta, 1.5)
    np.testing.assert_allclose(m.jacobian, 2.0 * 1.5 - 0.5 * 0.25)
    np.testing.assert_allclose(m.alpha, 0.5**2 + 1.5**2)
    np.testing.assert_allclose(m.beta, 2.0 * 0.5 + 0.25 * 1.5)
    np.testing.assert_allclose(m.gamma, 4.0 + 0.0625)
    # inverse metrics: [[xi_x, xi_y], [eta_x, eta_y]] is the inverse of [[x_xi, x_eta], [y_xi, y_eta]]
    inv = np.linalg.inv(np.array([[2.0, 0.5], [0.25, 1.5]]))
    np.testing.assert_allclose(m.xi_x, inv[0, 0])
    np.testing.assert_allclose(m.xi_y, inv[0, 1])
    np.testing.assert_allclose(m.eta_x, inv[1, 0])
    np.testing.assert_allclose(m.eta_y, inv[1, 1])


def test_metrics_second_order_including_borders():
    errs = []
    for n in (8, 16, 32):
        X, Y = annulus_sector(n, n)
        m = meshcore.metrics(meshcore.StructuredGrid(X, Y))
        # exact: x = exp(a + b ξ) cos(c η) ... with ξ, η node indices
        r0, r1, th1 = 1.0, 3.0, math.pi / 2
        b, d = math.log(r1 / r0) / n, th1 / n
        R = np.hypot(X, Y)
        exact_j = b * d * R**2
        errs.append(np.max(np.abs(m.jacobian - exact_j) / exact_j))
    assert math.log2(errs[0] / errs[1]) > 1.8 and math.log2(errs[1] / errs[2]) > 1.8


def test_rectangle_quality_is_ideal():
    xi, eta = np.meshgrid(np.linspace(0, 4, 9), np.linspace(0, 1, 5), indexing="ij")
    r = meshcore.quality(meshcore.StructuredGrid(xi, eta))
    assert r.n_folded == 0 and r.n_nonconvex == 0 and r.ok
    assert r.max_orthogonality == pytest.approx(0, abs=1e-12)
    assert r.max_skewness == pytest.approx(0, abs=1e-12)
    assert r.max_aspect_ratio == pytest.approx(2.0)
    assert r.max_size_ratio == pytest.approx(1.0)
    assert r.min_jacobian_ratio == pytest.approx(1.0)
    assert "folded cells" in str(r)


def test_folded_and_nonconvex_cells_are_found():
    xi, eta = np.meshgrid(np.arange(5.0), np.arange(5.0), indexing="ij")
    x, y = xi.copy(), eta.copy()
    x[2, 2] = 4.5  # pushes node (2,2) far past its neighbour (3,2): cells (2,1),(2,2) fold
    r = meshcore.quality(meshcore.StructuredGrid(x, y))
    assert r.n_folded >= 1
    assert {tuple(c) for c in r.folded} <= {tuple(c) for c in r.nonconvex}
    x2, y2 = xi.copy(), eta.copy()
    x2[2, 2], y2[2, 2] = 2.9, 2.9  # a dart: non-convex but positive area
    r2 = meshcore.quality(meshcore.StructuredGrid(x2, y2))
    assert r2.n_folded == 0 and r2.n_nonconvex >= 1


@settings(max_examples=40, deadline=None)
@given(
    st.floats(-100, 100),
    st.floats(-100, 100),
    st.floats(0, 2 * math.pi),
    st.floats(1e-3, 1e3),
    st.integers(0, 1000),
)
def test_quality_invariant_under_similarity(dx, dy, angle, scale, seed):
    rng = np.random.default_rng(seed)
    X, Y = annulus_sector(7, 5)
    X = X + 0.03 * rng.standard_normal(X.shape)
    Y = Y + 0.03 * rng.standard_normal(Y.shape)
    g = meshcore.StructuredGrid(X, Y)
    h = g.rotated(angle).scaled(scale).translated(dx, dy)
    a, b = cell_quality(g), cell_quality(h)
    for k in INVARIANT:
        np.testing.assert_allclose(a[k], b[k], rtol=1e-7, atol=1e-7, err_msg=k)
    np.testing.assert_allclose(b["area"], a["area"] * scale**2, rtol=1e-7, atol=1e-9 * scale**2)


def test_coverage_of_a_grid_with_a_collapsed_cell_sticking_out():
    """A collapsed cell made valid is a line; where it sticks out of the other cells the union
    is a GeometryCollection whose boundary is empty: the shore distance crashed (argmax of an
    empty sequence, seen on a generated lake's badly folded grid).  Now: the polygons only."""
    from types import SimpleNamespace

    from shapely.geometry import Polygon

    from meshcore.grid import StructuredGrid
    from meshcore.quality.coverage import coverage

    # cells 0, 1: a square and a triangle over [0, 2] × [0, 1]; cell 2: the segment (2, 0)–(4, 0)
    x = np.array([[0.0, 0.0], [1.0, 1.0], [2.0, 2.0], [3.0, 4.0]])
    y = np.array([[0.0, 1.0], [0.0, 1.0], [0.0, 0.0], [0.0, 0.0]])
    g = StructuredGrid(x, y)
    water = Polygon([(0, 0), (2, 0), (2, 1), (0, 1)])
    c = coverage([g], [SimpleNamespace(folded=np.array([[False], [False], [True]]))], water, cell_size=1.0)
    assert c.grid_area == pytest.approx(1.5)  # the square and the triangle; the line adds nothing
    assert c.hausdorff == pytest.approx(math.sqrt(0.5))  # the triangle's slope misses (2, 1) by √½
