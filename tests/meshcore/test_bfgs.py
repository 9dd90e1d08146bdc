"""The O(n²) BFGS of the equalize step's run patches (meshcore.orthogonal._bfgs) against scipy's."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import minimize, rosen, rosen_der

from meshcore.orthogonal._bfgs import bfgs


def test_a_convex_quadratic_reaches_its_minimizer():
    rng = np.random.default_rng(790001)
    M = rng.normal(size=(30, 30))
    A = M @ M.T + 30 * np.eye(30)
    b = rng.normal(size=30)

    def fun(x):
        return 0.5 * x @ A @ x - b @ x, A @ x - b

    x = bfgs(fun, np.zeros(30), maxiter=300)
    assert np.allclose(x, np.linalg.solve(A, b), atol=1e-5)


def test_rosenbrock_as_scipy():
    x0 = np.array([-1.2, 1.0, -0.5, 0.8])
    x = bfgs(lambda v: (rosen(v), rosen_der(v)), x0, maxiter=2000)
    ref = minimize(rosen, x0, jac=rosen_der, method="BFGS", options={"maxiter": 2000}).x
    assert np.allclose(x, np.ones(4), atol=1e-4)
    assert np.allclose(x, ref, atol=1e-4)


def test_a_wall_of_refused_points_is_not_crossed():
    """The objective of a patch answers (1e6, 0) where a cell would fold: the steps stay short of it."""

    def fun(x):
        if x[0] > 0.5:
            return 1e6, np.zeros_like(x)
        return float((x[0] - 2.0) ** 2 + x[1] ** 2), np.array([2 * (x[0] - 2.0), 2 * x[1]])

    x = bfgs(fun, np.array([0.0, 1.0]), maxiter=100)
    assert x[0] <= 0.5
    assert fun(x)[0] < fun(np.array([0.0, 1.0]))[0]


def test_a_zero_gradient_returns_the_start():
    x0 = np.array([1.0, 2.0])
    assert np.array_equal(bfgs(lambda v: (0.0, np.zeros(2)), x0, maxiter=10), x0)


def _bfgs_numpy_update(fun, x0, maxiter):
    """:func:`bfgs` with its inverse-Hessian update as the NumPy expression it had (three n × n
    temporaries a step): the compiled ``_update`` must give the same bits."""
    import meshcore.orthogonal._bfgs as mod

    def update(H, s, Hy, c, sy):
        H += c * np.outer(s, s) - (np.outer(Hy, s) + np.outer(s, Hy)) / sy

    saved = mod._update
    mod._update = update
    try:
        return mod.bfgs(fun, x0, maxiter=maxiter)
    finally:
        mod._update = saved


@pytest.mark.kernel
def test_the_compiled_update_is_the_numpy_expression_bit_for_bit():
    from meshcore.orthogonal._bfgs import _update

    rng = np.random.default_rng(29001)
    M = rng.normal(size=(57, 57))
    H = M @ M.T
    s, y = rng.normal(size=57), rng.normal(size=57)
    sy = float(s @ y)
    Hy = H @ y
    c = (sy + float(y @ Hy)) / sy**2
    ref = H + (c * np.outer(s, s) - (np.outer(Hy, s) + np.outer(s, Hy)) / sy)
    _update(H, s, Hy, c, sy)
    assert np.array_equal(H, ref)
    assert np.array_equal(H, H.T)


@pytest.mark.kernel
def test_a_solve_follows_the_numpy_update_exactly():
    x0 = np.array([-1.2, 1.0, -0.5, 0.8, 0.3, -0.7])
    fun = lambda v: (rosen(v), rosen_der(v))  # noqa: E731
    assert np.array_equal(bfgs(fun, x0, maxiter=500), _bfgs_numpy_update(fun, x0, 500))
