"""NumPy reference of :mod:`._kernels` (test oracle): point-Jacobi targets over the table."""

from __future__ import annotations

import numpy as np

__all__ = ["jacobi_targets", "line_sweep"]


def jacobi_targets(x, y, nodes, nbr, irr_nodes, irr_ptr, irr_ring):
    """Positions ``(tx, ty)`` one point-Jacobi update (ω = 1) would give every free node.

    Regular nodes: the 9-point Winslow stencil in the frame ``nbr = (E, W, N, S,
    NE, NW, SE, SW)``; irregular nodes: the mean of their ring of edge neighbours.
    Fixed nodes keep their position.
    """
    tx, ty = np.array(x, dtype=float), np.array(y, dtype=float)
    if len(nodes):
        e, w, n, s, ne, nw, se, sw = (nbr[:, k] for k in range(8))
        xxi, yxi = 0.5 * (x[e] - x[w]), 0.5 * (y[e] - y[w])
        xet, yet = 0.5 * (x[n] - x[s]), 0.5 * (y[n] - y[s])
        a = xet**2 + yet**2
        b = xxi * xet + yxi * yet
        g = xxi**2 + yxi**2
        den = 2.0 * (a + g)
        for src, dst in ((x, tx), (y, ty)):
            c = src[ne] - src[nw] - src[se] + src[sw]
            r = a * (src[e] + src[w]) + g * (src[n] + src[s]) - 0.5 * b * c
            dst[nodes] = np.where(den > 0, r / np.where(den > 0, den, 1.0), src[nodes])
    for k, p in enumerate(irr_nodes):
        ring = irr_ring[irr_ptr[k] : irr_ptr[k + 1]]
        tx[p] = x[ring].mean()
        ty[p] = y[ring].mean()
    return tx, ty


def line_sweep(x, y, fx, fy, nodes, nbr, rows, ptr, axis):
    """One line Gauss–Seidel sweep (reference of :func:`._kernels.line_sweep_rhs`, which takes the
    table rows ``rows`` gathered, ``nodes[rows], nbr[rows]``): line by line, the tridiagonal
    system with coefficients frozen at the current values, solved densely."""
    x, y = np.array(x, dtype=float), np.array(y, dtype=float)
    for L in range(len(ptr) - 1):
        ks = rows[ptr[L] : ptr[L + 1]]
        p = nodes[ks]
        tx, ty = jacobi_targets(x, y, nodes[ks], nbr[ks], np.zeros(0, int), np.zeros(1, int), np.zeros(0, int))
        e, w, n, s = (nbr[ks, k] for k in range(4))
        xxi, yxi = 0.5 * (x[e] - x[w]), 0.5 * (y[e] - y[w])
        xet, yet = 0.5 * (x[n] - x[s]), 0.5 * (y[n] - y[s])
        den = 2.0 * (xet**2 + yet**2 + xxi**2 + yxi**2)
        c = (xet**2 + yet**2) / den if axis[L] == 0 else (xxi**2 + yxi**2) / den
        lo, hi = (w, e) if axis[L] == 0 else (s, n)
        m = len(ks)
        A = np.eye(m) - np.diag(c[1:], -1) - np.diag(c[:-1], 1)
        for src, t, f in ((x, tx, fx), (y, ty, fy)):
            b = t[p] - c * (src[lo] + src[hi]) + (f[p] if len(f) else 0.0)
            b[0] += c[0] * src[lo[0]]
            b[-1] += c[-1] * src[hi[-1]]
            src[p] = np.linalg.solve(A, b)
    return x, y
