"""numba kernel of the multiblock start grids (:mod:`.start`; functions only).

A lake layout has tens of blocks, and :func:`meshcore.algebraic.tfi` costs ~50 NumPy calls
per block (0.3–0.5 ms each; the start grids were 9–14 ms of every solve of a ~15 000-cell
layout, re-solves included).  :func:`tfi_fill` evaluates the same expressions node by node, in
the same order, so the grids are identical (test oracle: :func:`meshcore.algebraic.tfi`).
"""

from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["tfi_fill"]


@njit(cache=True, nogil=True)
def _arc_fraction(x, y, out):  # pragma: no cover - compiled
    """Normalised arc length along the points ``(x[k], y[k])`` (uniform when the length is 0;
    :func:`meshcore.algebraic._arc_fraction`)."""
    n = x.shape[0]
    out[0] = 0.0
    for k in range(1, n):
        out[k] = out[k - 1] + np.hypot(x[k] - x[k - 1], y[k] - y[k - 1])  # C hypot, as NumPy (not Python's math.hypot)
    total = out[n - 1]
    if total > 0:
        for k in range(n):
            out[k] = out[k] / total
    else:  # as np.linspace(0, 1, n)
        step = 1.0 / (n - 1)
        for k in range(n):
            out[k] = k * step
        out[n - 1] = 1.0


@njit(cache=True, nogil=True)
def tfi_fill(x, y):  # pragma: no cover - compiled
    """Fill the interior of ``x, y`` (borders set) by linear transfinite interpolation with
    arc-length blending (:func:`meshcore.algebraic.tfi`, in place)."""
    n1, m1 = x.shape
    sb, st = np.empty(n1), np.empty(n1)
    tl, tr = np.empty(m1), np.empty(m1)
    _arc_fraction(x[:, 0], y[:, 0], sb)
    _arc_fraction(x[:, m1 - 1], y[:, m1 - 1], st)
    _arc_fraction(x[0, :], y[0, :], tl)
    _arc_fraction(x[n1 - 1, :], y[n1 - 1, :], tr)
    for arr in (x, y):
        c00, cn0, c0m, cnm = arr[0, 0], arr[n1 - 1, 0], arr[0, m1 - 1], arr[n1 - 1, m1 - 1]
        for i in range(1, n1 - 1):
            for j in range(1, m1 - 1):
                den = 1.0 - (st[i] - sb[i]) * (tr[j] - tl[j])
                s = (sb[i] + (st[i] - sb[i]) * tl[j]) / den
                t = (tl[j] + (tr[j] - tl[j]) * sb[i]) / den
                arr[i, j] = (
                    (1 - s) * arr[0, j]
                    + s * arr[n1 - 1, j]
                    + (1 - t) * arr[i, 0]
                    + t * arr[i, m1 - 1]
                    - ((1 - s) * (1 - t) * c00 + s * (1 - t) * cn0 + (1 - s) * t * c0m + s * t * cnm)
                )
