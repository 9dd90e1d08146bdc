"""NumPy reference of the corner-triangle energy and its gradient (test oracle).

Vectorised over all cells; see :mod:`meshcore.foldfree._kernels` for the maths.
"""

from __future__ import annotations

import numpy as np


def _corners(x: np.ndarray, y: np.ndarray):
    return [
        (x[:-1, :-1], y[:-1, :-1]),
        (x[1:, :-1], y[1:, :-1]),
        (x[1:, 1:], y[1:, 1:]),
        (x[:-1, 1:], y[:-1, 1:]),
    ]


def chi(d: np.ndarray, eps: float) -> np.ndarray:
    """``χ(D, ε) = (D + sqrt(ε² + D²)) / 2`` (``max(D, 0)`` for ε = 0)."""
    if eps == 0.0:
        return np.maximum(d, 0.0)
    return 0.5 * (d + np.sqrt(eps * eps + d * d))


def energy(x: np.ndarray, y: np.ndarray, eps: float) -> float:
    """``E = Σ_cells Σ_corners F / χ(D, ε)`` over the whole grid."""
    c = _corners(x, y)
    e = 0.0
    for m in range(4):
        (px, py), (ax, ay), (bx, by) = c[m], c[(m + 1) % 4], c[(m + 3) % 4]
        ux, uy, vx, vy = ax - px, ay - py, bx - px, by - py
        d = ux * vy - uy * vx
        ch = chi(d, eps)
        with np.errstate(divide="ignore"):
            f = np.where(ch > 0, (ux**2 + uy**2 + vx**2 + vy**2) / np.where(ch > 0, ch, 1.0), np.inf)
        e += float(f.sum())
    return e


def gradient(x: np.ndarray, y: np.ndarray, eps: float) -> tuple[np.ndarray, np.ndarray]:
    """``∂E/∂x, ∂E/∂y`` at every node (boundary nodes included)."""
    c = _corners(x, y)
    gx = np.zeros_like(x)
    gy = np.zeros_like(y)
    sl = [
        (slice(None, -1), slice(None, -1)),
        (slice(1, None), slice(None, -1)),
        (slice(1, None), slice(1, None)),
        (slice(None, -1), slice(1, None)),
    ]
    for m in range(4):
        (px, py), (ax, ay), (bx, by) = c[m], c[(m + 1) % 4], c[(m + 3) % 4]
        ux, uy, vx, vy = ax - px, ay - py, bx - px, by - py
        d = ux * vy - uy * vx
        f2 = ux**2 + uy**2 + vx**2 + vy**2
        if eps == 0.0:
            ch, c1 = d, np.ones_like(d)
        else:
            s = np.sqrt(eps * eps + d * d)
            ch = 0.5 * (d + s)
            c1 = ch / s
        k = f2 * c1 / ch**2
        # df/du, df/dv
        gux = 2 * ux / ch - k * vy
        guy = 2 * uy / ch + k * vx
        gvx = 2 * vx / ch + k * uy
        gvy = 2 * vy / ch - k * ux
        ia, ib = sl[(m + 1) % 4], sl[(m + 3) % 4]
        gx[sl[m]] -= gux + gvx
        gy[sl[m]] -= guy + gvy
        gx[ia] += gux
        gy[ia] += guy
        gx[ib] += gvx
        gy[ib] += gvy
    return gx, gy
