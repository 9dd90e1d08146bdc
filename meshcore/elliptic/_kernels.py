r"""numba kernels for the elliptic grid equations (functions only, no state).

Discrete equations (paper eq. 30 with the errata in docs/errata.md, written once in
:func:`._stencil.winslow`), at an interior node P with neighbours
E = (i+1, j), W = (i−1, j), N = (i, j+1), S = (i, j−1) and Δξ = Δη = 1:

.. math::

    x_ξ = (x_E − x_W)/2,\quad x_η = (x_N − x_S)/2 \quad(\text{same for } y)

    α = x_η^2 + y_η^2,\quad β = x_ξ x_η + y_ξ y_η,\quad γ = x_ξ^2 + y_ξ^2,
    \quad D = x_ξ y_η − x_η y_ξ \;(= 1/J \text{ of the paper})

    2(α + γ) φ_P = α(φ_E + φ_W) + γ(φ_N + φ_S)
                   − \tfrac{β}{2}(φ_{NE} − φ_{NW} − φ_{SE} + φ_{SW})
                   + D^2 (P φ_ξ + Q φ_η)

for φ ∈ {x, y}.  A Gauss–Seidel/SOR sweep applies
``φ_P ← φ_P + ω (φ_P^* − φ_P)`` with the coefficients evaluated from the
current iterate at P.

Ordering: **4-colour** (2×2 parity of (i, j)).  Nodes of one colour never
appear in each other's 9-point stencils, so each colour is a Jacobi update of
a disjoint set: the serial and ``parallel=True`` compilations of the same
function give bit-identical results (red–black would race on the diagonal
neighbours).  Within a colour the loops are free of loop-carried
dependencies and vectorise.

Periodic ξ (O-grids): column ``ni`` repeats column ``0``; the W neighbour of
column 0 is column ``ni − 1`` and after each colour column ``ni`` is refreshed.

``p`` and ``q`` are arrays of the grid's shape, or empty arrays for P = Q = 0.
"""

from __future__ import annotations

import numba
import numpy as np
from numba import njit, prange

from ._compile import parallel, serial
from ._stencil import winslow_at, with_sources

__all__ = ["jacobi_residual", "sweep4", "sweep4_parallel"]


def _sweep4(x, y, p, q, omega, periodic):  # pragma: no cover - compiled
    ni1, nj1 = x.shape
    use_pq = p.size > 0
    imax = ni1 - 1  # exclusive upper bound of updated i (non-periodic: 1..ni-1)
    i0 = 0 if periodic else 1
    dmax = 0.0
    for ci in range(2):
        for cj in range(2):
            # i values of this colour: i0 + ci', stepping 2, where parity(i) == ci
            start_i = i0 + ((ci - i0) % 2)
            n_rows = (imax - start_i + 1) // 2
            row_max = np.zeros(max(n_rows, 0))
            for k in prange(n_rows):
                i = start_i + 2 * k
                iw = i - 1
                if iw < 0:
                    iw = ni1 - 2
                ie = i + 1
                rmax = 0.0
                for j in range(1 + cj, nj1 - 1, 2):
                    rx, ry, den, xxi, yxi, xet, yet = winslow_at(x, y, i, iw, ie, j)
                    if use_pq:
                        rx, ry = with_sources(rx, ry, xxi, yxi, xet, yet, p[i, j], q[i, j])
                    if den <= 0.0:
                        continue
                    dx = omega * (rx / den - x[i, j])
                    dy = omega * (ry / den - y[i, j])
                    x[i, j] += dx
                    y[i, j] += dy
                    m = dx * dx + dy * dy
                    if m > rmax:
                        rmax = m
                row_max[k] = rmax
            for k in range(n_rows):
                if row_max[k] > dmax:
                    dmax = row_max[k]
            if periodic:
                for j in range(nj1):
                    x[ni1 - 1, j] = x[0, j]
                    y[ni1 - 1, j] = y[0, j]
    return np.sqrt(dmax)


sweep4 = serial(_sweep4)
sweep4_parallel = parallel(_sweep4)


@njit(cache=True, nogil=True)
def jacobi_residual(x, y, p, q, periodic):  # pragma: no cover - compiled
    """Largest displacement one point-Jacobi update (ω = 1) would make.

    This is the stopping measure shared by every solver: it is zero exactly at
    a solution of the discrete equations, and it is a length, so it is
    compared with ``tolerance × L`` (L = bounding-box diagonal).
    """
    ni1, nj1 = x.shape
    use_pq = p.size > 0
    i0 = 0 if periodic else 1
    dmax = 0.0
    for i in range(i0, ni1 - 1):
        iw = i - 1
        if iw < 0:
            iw = ni1 - 2
        ie = i + 1
        for j in range(1, nj1 - 1):
            rx, ry, den, xxi, yxi, xet, yet = winslow_at(x, y, i, iw, ie, j)
            if use_pq:
                rx, ry = with_sources(rx, ry, xxi, yxi, xet, yet, p[i, j], q[i, j])
            if not den > 0.0:
                if den != den:
                    return np.inf
                continue
            dx = rx / den - x[i, j]
            dy = ry / den - y[i, j]
            m = dx * dx + dy * dy
            if m > dmax:
                dmax = m
            elif m != m:  # NaN anywhere means "not converged", never a silent pass
                return np.inf
    return np.sqrt(dmax)


def threading_layer() -> str:
    """The numba threading layer in use (for benchmark reports)."""
    try:
        return numba.threading_layer()
    except ValueError:
        return "not initialised"
