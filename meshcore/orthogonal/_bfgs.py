"""A dense BFGS whose inverse-Hessian update costs O(n²) a step (scipy's ``BFGS`` forms it with two
matrix products, O(n³): on the run patches of :mod:`.equalize`, a few hundred unknowns, that
product was nearly all of the step's CPU); the update itself compiled (``_update``: as NumPy outer
products it still took 58 % of the step's CPU on Taal, session 29)."""

from __future__ import annotations

import warnings
from collections.abc import Callable

import numpy as np
from numba import njit
from scipy.optimize import line_search

__all__ = ["bfgs"]


def bfgs(
    fun: Callable[[np.ndarray], tuple[float, np.ndarray]], x0: np.ndarray, *, maxiter: int, gtol: float = 1e-5
) -> np.ndarray:
    """The minimizer ``fun`` (value and gradient) reaches from ``x0``: BFGS with a Wolfe line search,
    stopped after ``maxiter`` steps, when the gradient's largest component is below ``gtol`` or
    when no step of the line search is found (the last point is returned)."""
    x = np.asarray(x0, float).copy()
    cache: dict[bytes, tuple[float, np.ndarray]] = {}

    def fg(v: np.ndarray) -> tuple[float, np.ndarray]:
        key = v.tobytes()
        if key not in cache:
            cache.clear()
            cache[key] = fun(v)
        return cache[key]

    f, g = fg(x)
    H = np.eye(len(x))
    old_old: float = float(f + np.linalg.norm(g) / 2)
    for _ in range(maxiter):
        if np.abs(g).max() < gtol:
            break
        p = -H @ g
        with warnings.catch_warnings():  # "did not converge": answered by the Armijo steps below
            warnings.simplefilter("ignore")
            alpha, _, _, f_new, old_old, g_new = line_search(
                lambda v: fg(v)[0], lambda v: fg(v)[1], x, p, g, f, old_old, amax=1e100
            )
        if alpha is None:  # Wolfe failed (e.g. a trial point folded a cell: value 1e6, no gradient)
            alpha, f_new, g_new = _backtrack(fg, x, p, f, float(g @ p))
            if alpha is None:
                break
        s = alpha * p
        x = x + s
        f_old, f = f, float(f_new)
        old_old = f_old
        g_new = fg(x)[1] if g_new is None else g_new
        y = g_new - g
        g = g_new
        sy = float(s @ y)
        if sy <= 1e-300:
            continue
        Hy = H @ y
        _update(H, s, Hy, (sy + float(y @ Hy)) / sy**2, sy)
    return x


@njit(cache=True, nogil=True)
def _update(H, s, Hy, c, sy):
    """``H += c·s sᵀ − (Hy sᵀ + s Hyᵀ) / sy`` in one pass over the upper triangle, mirrored: each
    entry the same operations in the same order as the NumPy expression (the same bits), which
    made three n × n temporaries and took most of the run patches' CPU (Taal: 0.85 s a patch)."""
    n = len(s)
    for i in range(n):
        for j in range(i, n):
            v = H[i, j] + (c * (s[i] * s[j]) - (Hy[i] * s[j] + s[i] * Hy[j]) / sy)
            H[i, j] = v
            H[j, i] = v


def _backtrack(fg, x: np.ndarray, p: np.ndarray, f: float, slope: float):
    """An Armijo step along ``p`` from 1 halved up to 40 times: ``(alpha, f, g)`` or Nones."""
    if slope >= 0:
        return None, None, None
    alpha = 1.0
    for _ in range(40):
        fn, gn = fg(x + alpha * p)
        if fn <= f + 1e-4 * alpha * slope:
            return alpha, fn, gn
        alpha *= 0.5
    return None, None, None
