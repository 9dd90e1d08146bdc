r"""The Winslow/TTM stencil at one node: the single place the discrete equations are written.

At an interior node P with neighbours E, W, N, S and NE, NW, SE, SW (Δξ = Δη = 1;
paper eq. 30 with the errata in docs/errata.md):

.. math::

    x_ξ = (x_E − x_W)/2,\quad x_η = (x_N − x_S)/2 \quad(\text{same for } y)

    α = x_η^2 + y_η^2,\quad β = x_ξ x_η + y_ξ y_η,\quad γ = x_ξ^2 + y_ξ^2,
    \quad D = x_ξ y_η − x_η y_ξ \;(= 1/J \text{ of the paper})

    2(α + γ) φ_P = α(φ_E + φ_W) + γ(φ_N + φ_S)
                   − \tfrac{β}{2}(φ_{NE} − φ_{NW} − φ_{SE} + φ_{SW})
                   + D^2 (P φ_ξ + Q φ_η)

for φ ∈ {x, y}.  :func:`winslow` returns the right-hand side ``(s_x, s_y)`` (P = Q = 0;
:func:`with_sources` adds the source terms) and the diagonal ``den = 2(α + γ)``
from the neighbours' values; every numba kernel
(SOR and multigrid relaxation, defects, residuals, the multiblock tables)
loads its neighbours its own way and calls it, so they all evaluate the same
expression in the same order (bit-identical results across kernels).  The
coefficients α, β, γ and D do not involve φ_P, so the equation is linear in
φ_P: a point update ``φ_P ← s/den`` solves it exactly.
"""

from __future__ import annotations

from numba import njit

__all__ = ["neighbours", "winslow", "winslow_at", "with_sources"]

# inline="always": every kernel gets the arithmetic in its own loop (LLVM then
# vectorises the row kernels as before); arguments are scalars or arrays that are only
# read, which keeps the inlined code free of reference counting.


@njit(cache=True, nogil=True, inline="always")
def winslow(xe, xw, xn, xs, xne, xnw, xse, xsw, ye, yw, yn, ys, yne, ynw, yse, ysw):  # pragma: no cover
    """``(s_x, s_y, den, x_ξ, y_ξ, x_η, y_η)`` at a node from its eight neighbours' values.

    ``s`` is the right-hand side with P = Q = 0 (see :func:`with_sources`), ``den = 2(α + γ)``.
    """
    xxi = 0.5 * (xe - xw)
    yxi = 0.5 * (ye - yw)
    xet = 0.5 * (xn - xs)
    yet = 0.5 * (yn - ys)
    a = xet * xet + yet * yet
    b = xxi * xet + yxi * yet
    g = xxi * xxi + yxi * yxi
    den = 2.0 * (a + g)
    cx = xne - xnw - xse + xsw
    cy = yne - ynw - yse + ysw
    sx = a * (xe + xw) + g * (xn + xs) - 0.5 * b * cx
    sy = a * (ye + yw) + g * (yn + ys) - 0.5 * b * cy
    return sx, sy, den, xxi, yxi, xet, yet


@njit(cache=True, nogil=True, inline="always")
def with_sources(sx, sy, xxi, yxi, xet, yet, pp, qq):  # pragma: no cover - compiled
    """``(s_x, s_y)`` plus the source terms ``D² (P φ_ξ + Q φ_η)`` (P = ``pp``, Q = ``qq``)."""
    d = xxi * yet - xet * yxi
    d2 = d * d
    return sx + d2 * (pp * xxi + qq * xet), sy + d2 * (pp * yxi + qq * yet)


@njit(cache=True, nogil=True, inline="always")
def neighbours(x, i, iw, ie, j):  # pragma: no cover - compiled
    """``x`` at the E, W, N, S, NE, NW, SE, SW neighbours of node ``(i, j)``."""
    return x[ie, j], x[iw, j], x[i, j + 1], x[i, j - 1], x[ie, j + 1], x[iw, j + 1], x[ie, j - 1], x[iw, j - 1]


@njit(cache=True, nogil=True, inline="always")
def winslow_at(x, y, i, iw, ie, j):  # pragma: no cover - compiled
    """:func:`winslow` at node ``(i, j)`` of node arrays (``iw, ie``: the rows of its ξ
    neighbours, which wrap around on periodic grids)."""
    xe, xw, xn, xs, xne, xnw, xse, xsw = neighbours(x, i, iw, ie, j)
    ye, yw, yn, ys, yne, ynw, yse, ysw = neighbours(y, i, iw, ie, j)
    return winslow(xe, xw, xn, xs, xne, xnw, xse, xsw, ye, yw, yn, ys, yne, ynw, yse, ysw)
