r"""The paper's iteration, as a Python script of the paper's time would write it.

Point-Jacobi iteration of eq. 30 (errata applied, P = Q = 0, Δξ = Δη = 1),
vectorised over the whole interior with NumPy slices:

.. math::

    φ_P^{new} = \frac{α(φ_E + φ_W) + γ(φ_N + φ_S)
                - \tfrac{β}{2}(φ_{NE} - φ_{NW} - φ_{SE} + φ_{SW})}{2(α + γ)}

with α, β, γ from central differences of the current iterate.  It stops with
the benchmark's common criterion: the largest point-Jacobi displacement
(which is exactly this iteration's update) ≤ tol·L.

:func:`count_sweeps` runs the *same* iteration compiled with numba, only to
count sweeps on grids where the NumPy run would take too long (it is used to
calibrate the extrapolation, never timed as the paper's method).
"""

from __future__ import annotations

import time

import numpy as np
from numba import njit


def jacobi_sweep(x: np.ndarray, y: np.ndarray) -> float:
    """One vectorised Jacobi sweep in place; returns the largest displacement."""
    xc, yc = x[1:-1, 1:-1], y[1:-1, 1:-1]
    xe, xw, xn, xs = x[2:, 1:-1], x[:-2, 1:-1], x[1:-1, 2:], x[1:-1, :-2]
    ye, yw, yn, ys = y[2:, 1:-1], y[:-2, 1:-1], y[1:-1, 2:], y[1:-1, :-2]
    x_xi, y_xi = 0.5 * (xe - xw), 0.5 * (ye - yw)
    x_eta, y_eta = 0.5 * (xn - xs), 0.5 * (yn - ys)
    alpha = x_eta**2 + y_eta**2
    beta = x_xi * x_eta + y_xi * y_eta
    gamma = x_xi**2 + y_xi**2
    cx = x[2:, 2:] - x[:-2, 2:] - x[2:, :-2] + x[:-2, :-2]
    cy = y[2:, 2:] - y[:-2, 2:] - y[2:, :-2] + y[:-2, :-2]
    den = 2.0 * (alpha + gamma)
    xnew = (alpha * (xe + xw) + gamma * (xn + xs) - 0.5 * beta * cx) / den
    ynew = (alpha * (ye + yw) + gamma * (yn + ys) - 0.5 * beta * cy) / den
    d = float(np.sqrt(np.max((xnew - xc) ** 2 + (ynew - yc) ** 2)))
    x[1:-1, 1:-1] = xnew
    y[1:-1, 1:-1] = ynew
    return d


def solve(x0: np.ndarray, y0: np.ndarray, tol_abs: float, *, max_seconds: float = np.inf, max_sweeps: int = 10_000_000):
    """Iterate until the displacement ≤ ``tol_abs``; returns (x, y, sweeps, seconds, done)."""
    x, y = x0.copy(), y0.copy()
    t0 = time.perf_counter()
    for k in range(1, max_sweeps + 1):
        d = jacobi_sweep(x, y)
        if d <= tol_abs:
            # the displacement belongs to the iterate before this sweep
            return x, y, k - 1, time.perf_counter() - t0, True
        if time.perf_counter() - t0 > max_seconds:
            return x, y, k, time.perf_counter() - t0, False
    return x, y, max_sweeps, time.perf_counter() - t0, False


@njit(cache=True)
def _count(x, y, tol_abs, max_sweeps):  # pragma: no cover - compiled
    ni1, nj1 = x.shape
    xn = x.copy()
    yn = y.copy()
    for k in range(1, max_sweeps + 1):
        dmax = 0.0
        for i in range(1, ni1 - 1):
            for j in range(1, nj1 - 1):
                xe, xw, xnn, xs = x[i + 1, j], x[i - 1, j], x[i, j + 1], x[i, j - 1]
                ye, yw, yn_, ys = y[i + 1, j], y[i - 1, j], y[i, j + 1], y[i, j - 1]
                x_xi, y_xi = 0.5 * (xe - xw), 0.5 * (ye - yw)
                x_eta, y_eta = 0.5 * (xnn - xs), 0.5 * (yn_ - ys)
                a = x_eta * x_eta + y_eta * y_eta
                b = x_xi * x_eta + y_xi * y_eta
                g = x_xi * x_xi + y_xi * y_xi
                cx = x[i + 1, j + 1] - x[i - 1, j + 1] - x[i + 1, j - 1] + x[i - 1, j - 1]
                cy = y[i + 1, j + 1] - y[i - 1, j + 1] - y[i + 1, j - 1] + y[i - 1, j - 1]
                den = 2.0 * (a + g)
                vx = (a * (xe + xw) + g * (xnn + xs) - 0.5 * b * cx) / den
                vy = (a * (ye + yw) + g * (yn_ + ys) - 0.5 * b * cy) / den
                d = (vx - x[i, j]) ** 2 + (vy - y[i, j]) ** 2
                if d > dmax:
                    dmax = d
                xn[i, j] = vx
                yn[i, j] = vy
        if np.sqrt(dmax) <= tol_abs:
            return k - 1
        x, xn = xn, x
        y, yn = yn, y
    return -1


def count_sweeps(x0, y0, tol_abs: float, max_sweeps: int = 2_000_000) -> int:
    """Sweeps the paper's Jacobi iteration needs (numba, same arithmetic); −1 = over the cap."""
    x = np.ascontiguousarray(x0, dtype=np.float64).copy()
    y = np.ascontiguousarray(y0, dtype=np.float64).copy()
    return int(_count(x, y, float(tol_abs), max_sweeps))
