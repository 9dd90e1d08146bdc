"""Vectorised NumPy reference of the elliptic kernels: the test oracle.

``sweep4`` applies exactly the same 4-colour SOR sweep as
:func:`meshcore.elliptic._kernels.sweep4` — within one colour every update is
independent, so a colour is one vectorised Jacobi update of a strided slice.
``jacobi_update`` is the plain point-Jacobi map of eq. 30 (the paper-style
iteration) and ``jacobi_residual`` the shared stopping measure.
"""

from __future__ import annotations

import numpy as np

__all__ = ["jacobi_residual", "jacobi_update", "sweep4"]


def _targets(x, y, p, q, I, J, periodic):
    ni1 = x.shape[0]
    IW = I - 1
    if periodic:
        IW = np.where(IW < 0, ni1 - 2, IW)
    IE = I + 1
    xe, xw, xn, xs = x[IE, J], x[IW, J], x[I, J + 1], x[I, J - 1]
    ye, yw, yn, ys = y[IE, J], y[IW, J], y[I, J + 1], y[I, J - 1]
    xxi, yxi = 0.5 * (xe - xw), 0.5 * (ye - yw)
    xet, yet = 0.5 * (xn - xs), 0.5 * (yn - ys)
    a = xet * xet + yet * yet
    b = xxi * xet + yxi * yet
    g = xxi * xxi + yxi * yxi
    den = 2.0 * (a + g)
    cx = x[IE, J + 1] - x[IW, J + 1] - x[IE, J - 1] + x[IW, J - 1]
    cy = y[IE, J + 1] - y[IW, J + 1] - y[IE, J - 1] + y[IW, J - 1]
    rx = a * (xe + xw) + g * (xn + xs) - 0.5 * b * cx
    ry = a * (ye + yw) + g * (yn + ys) - 0.5 * b * cy
    if p is not None and p.size:
        d = xxi * yet - xet * yxi
        d2 = d * d
        rx = rx + d2 * (p[I, J] * xxi + q[I, J] * xet)
        ry = ry + d2 * (p[I, J] * yxi + q[I, J] * yet)
    ok = den > 0
    safe = np.where(ok, den, 1.0)
    tx = np.where(ok, rx / safe, x[I, J])
    ty = np.where(ok, ry / safe, y[I, J])
    return tx, ty


def sweep4(x, y, p=None, q=None, omega=1.0, periodic=False) -> float:
    """In-place 4-colour SOR sweep; returns the largest update length."""
    ni1, nj1 = x.shape
    i0 = 0 if periodic else 1
    dmax = 0.0
    for ci in range(2):
        for cj in range(2):
            start_i = i0 + ((ci - i0) % 2)
            ii = np.arange(start_i, ni1 - 1, 2)
            jj = np.arange(1 + cj, nj1 - 1, 2)
            if ii.size == 0 or jj.size == 0:
                if periodic:
                    x[-1, :], y[-1, :] = x[0, :], y[0, :]
                continue
            I, J = np.meshgrid(ii, jj, indexing="ij")
            tx, ty = _targets(x, y, p, q, I, J, periodic)
            dx = omega * (tx - x[I, J])
            dy = omega * (ty - y[I, J])
            x[I, J] += dx
            y[I, J] += dy
            dmax = max(dmax, float(np.max(dx * dx + dy * dy)))
            if periodic:
                x[-1, :], y[-1, :] = x[0, :], y[0, :]
    return float(np.sqrt(dmax))


def jacobi_update(x, y, p=None, q=None, periodic=False) -> tuple[np.ndarray, np.ndarray]:
    """Return the point-Jacobi targets of eq. 30 for all interior nodes (new arrays)."""
    ni1, nj1 = x.shape
    i0 = 0 if periodic else 1
    I, J = np.meshgrid(np.arange(i0, ni1 - 1), np.arange(1, nj1 - 1), indexing="ij")
    tx, ty = _targets(x, y, p, q, I, J, periodic)
    nx, ny = x.copy(), y.copy()
    nx[I, J], ny[I, J] = tx, ty
    if periodic:
        nx[-1, :], ny[-1, :] = nx[0, :], ny[0, :]
    return nx, ny


def jacobi_residual(x, y, p=None, q=None, periodic=False) -> float:
    """Largest displacement of one point-Jacobi update (the stopping measure)."""
    nx, ny = jacobi_update(x, y, p, q, periodic)
    return float(np.sqrt(np.max((nx - x) ** 2 + (ny - y) ** 2)))
