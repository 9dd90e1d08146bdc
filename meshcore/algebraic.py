r"""Algebraic grids: the paper's weighted average (eq. 34) and transfinite interpolation.

Both fill the interior of a block from its four re-sampled borders; boundary
nodes are copied from the borders unchanged.

Weighted average (paper eqs. 34a/b, with the errata in docs/errata.md)::

    x_ij = p13_x (x_0j + i Δxξ_j) + (1 − p13_x) (x_i0 + j Δxη_i)
    Δxξ_j = (x_Nj − x_0j) / N      (straight line between left and right of row j)
    Δxη_i = (x_iM − x_i0) / M      (straight line between bottom and top of column i)

and the same for y with ``p13_y``.  ``weights = (p13_x, p13_y)`` is the weight of
the left/right (Γ1Γ3) interpolation; the paper's ``p24 = 1 − p13``.

TFI is the linear transfinite interpolation (Gordon–Hall) with arc-length
blending parameters (Soni), so clustered borders propagate into the interior;
with uniformly spaced straight borders it is classic TFI and reproduces any
bilinear map exactly.
"""

from __future__ import annotations

import numpy as np

from ._validation import validate_choice, validate_fraction
from .boundary import Borders
from .grid import StructuredGrid

__all__ = ["INITIAL_METHODS", "algebraic_grid", "border_frame", "tfi", "weighted_average"]

INITIAL_METHODS = ("weighted", "tfi")


def border_frame(borders: Borders) -> tuple[np.ndarray, np.ndarray]:
    """``(x, y)`` node arrays of a block with the border nodes set (the interior uninitialised)."""
    ni, nj = borders.check_counts()
    x = np.empty((ni + 1, nj + 1))
    y = np.empty((ni + 1, nj + 1))
    for arr, k in ((x, 0), (y, 1)):
        arr[:, 0] = borders.bottom[:, k]
        arr[:, -1] = borders.top[:, k]
        arr[0, :] = borders.left[:, k]
        arr[-1, :] = borders.right[:, k]
    return x, y


def weighted_average(borders: Borders, weights: tuple[float, float] = (0.5, 0.5)) -> StructuredGrid:
    """The paper's algebraic grid (eq. 34) with ``weights = (p13_x, p13_y)``."""
    px = validate_fraction(weights[0], name="weight p13_x")
    py = validate_fraction(weights[1], name="weight p13_y")
    x, y = border_frame(borders)
    ni, nj = x.shape[0] - 1, x.shape[1] - 1
    i = np.arange(ni + 1)[:, None] / ni
    j = np.arange(nj + 1)[None, :] / nj
    for arr, p in ((x, px), (y, py)):
        lr = arr[0:1, :] + i * (arr[-1:, :] - arr[0:1, :])  # left → right along row j
        bt = arr[:, 0:1] + j * (arr[:, -1:] - arr[:, 0:1])  # bottom → top along column i
        arr[1:-1, 1:-1] = (p * lr + (1.0 - p) * bt)[1:-1, 1:-1]
    return StructuredGrid(x, y, periodic=borders.periodic)


def _arc_fraction(p: np.ndarray) -> np.ndarray:
    s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(p, axis=0).T))])
    return s / s[-1] if s[-1] > 0 else np.linspace(0, 1, len(p))


def tfi(borders: Borders) -> StructuredGrid:
    """Linear transfinite interpolation with arc-length blending (Soni)."""
    x, y = border_frame(borders)
    sb = _arc_fraction(borders.bottom)[:, None]
    st = _arc_fraction(borders.top)[:, None]
    tl = _arc_fraction(borders.left)[None, :]
    tr = _arc_fraction(borders.right)[None, :]
    den = 1.0 - (st - sb) * (tr - tl)
    s = (sb + (st - sb) * tl) / den
    t = (tl + (tr - tl) * sb) / den
    for arr in (x, y):
        left, right = arr[0:1, :], arr[-1:, :]
        bot, top = arr[:, 0:1], arr[:, -1:]
        c00, cn0, c0m, cnm = arr[0, 0], arr[-1, 0], arr[0, -1], arr[-1, -1]
        full = (
            (1 - s) * left
            + s * right
            + (1 - t) * bot
            + t * top
            - ((1 - s) * (1 - t) * c00 + s * (1 - t) * cn0 + (1 - s) * t * c0m + s * t * cnm)
        )
        arr[1:-1, 1:-1] = full[1:-1, 1:-1]
    return StructuredGrid(x, y, periodic=borders.periodic)


def algebraic_grid(
    borders: Borders, method: str = "weighted", *, weights: tuple[float, float] = (0.5, 0.5)
) -> StructuredGrid:
    """Initial grid by ``method`` (``weighted`` = paper eq. 34, or ``tfi``)."""
    method = validate_choice(method, INITIAL_METHODS, name="initial")
    if method == "tfi":
        return tfi(borders)
    return weighted_average(borders, weights)
