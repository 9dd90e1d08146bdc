"""NumPy reference of :mod:`._kernels` (test oracle): the orthogonal update, vectorised."""

from __future__ import annotations

import numpy as np

__all__ = ["fan_targets", "ortho_targets"]


def blend(smooth: float, h1: np.ndarray, h2: np.ndarray, lo, hi: float, floor: float = 0.0) -> np.ndarray:
    """The share of the symmetric weights along a grid line whose two edges at the node are
    ``h1, h2``: ``smooth`` up to the ratio ``lo`` (per node, or one for all), rising linearly to 1
    at ``hi`` — or, if more, from where the shorter edge is under ``floor`` to 1 at half of it."""
    r = np.maximum(h1, h2) / np.minimum(h1, h2)
    lo = np.broadcast_to(np.asarray(lo, dtype=float), r.shape)
    with np.errstate(invalid="ignore"):  # (an infinite lo: no blend, whatever the quotient)
        t = np.where(r <= lo, 0.0, np.clip((r - lo) / (hi - lo), 0.0, 1.0))
    if floor > 0.0:
        t = np.maximum(t, np.clip(2.0 * (floor - np.minimum(h1, h2)) / floor, 0.0, 1.0))
    return smooth + (1.0 - smooth) * t


def ortho_targets(
    x: np.ndarray,
    y: np.ndarray,
    nodes: np.ndarray,
    nbr: np.ndarray,
    smooth: float,
    lo=np.inf,
    hi: float = np.inf,
    lo_y=None,
    floor: float = 0.0,
):
    """Where one point-Jacobi step of the Ryskin–Leal update moves every regular node.

    ``nbr`` holds ``E, W, N, S, NE, NW, SE, SW`` per node; ``lo`` the size blend's start along
    each node's e–w line and ``lo_y`` (default ``lo``) along its n–s line (one for all, or per
    node); ``floor`` the edge length under which the blend rises too.  See :mod:`._kernels` for
    the formula; here every length is one vectorised ``hypot``.
    """
    e, w, n, s, ne, nw, se, sw = (nbr[:, k] for k in range(8))
    p = nodes

    def d(a, b):
        return np.hypot(x[b] - x[a], y[b] - y[a])

    he, hw, hn, hs = d(p, e), d(w, p), d(p, n), d(s, p)
    eta_e = 0.25 * (hn + hs + d(e, ne) + d(se, e))
    eta_w = 0.25 * (hn + hs + d(w, nw) + d(sw, w))
    xi_n = 0.25 * (he + hw + d(n, ne) + d(nw, n))
    xi_s = 0.25 * (he + hw + d(s, se) + d(sw, s))
    a = np.stack([eta_e / he, eta_w / hw, xi_n / hn, xi_s / hs])
    mean = np.stack([(a[0] + a[1]) / 2, (a[0] + a[1]) / 2, (a[2] + a[3]) / 2, (a[2] + a[3]) / 2])
    sx = blend(smooth, he, hw, lo, hi, floor)
    sy = blend(smooth, hn, hs, lo if lo_y is None else lo_y, hi, floor)
    a = a + np.stack([sx, sx, sy, sy]) * (mean - a)
    den = a.sum(axis=0)
    tx = (a[0] * x[e] + a[1] * x[w] + a[2] * x[n] + a[3] * x[s]) / den
    ty = (a[0] * y[e] + a[1] * y[w] + a[2] * y[n] + a[3] * y[s]) / den
    return tx, ty


def fan_targets(x, y, ends, fptr, fan, corner, least: float, slack: float, lo: float):
    """Where :func:`._kernels.hold_fans` puts the nodes of the lines leaving each cut end, all
    from the same old positions and without the fold guard: ``(nodes, tx, ty)`` of the lines it
    moves."""
    nodes, tx, ty = [], [], []
    for k, c in enumerate(ends):
        f = fan[fptr[k] : fptr[k + 1]]
        cor = corner[fptr[k] : fptr[k + 1] - 1]
        v = np.column_stack([x[f] - x[c], y[f] - y[c]])
        m = len(f) - 1
        w = float(np.mod(np.arctan2(v[-1, 1], v[-1, 0]) - np.arctan2(v[0, 1], v[0, 0]), 2 * np.pi)) or 2 * np.pi
        if w < least:
            continue
        nc = int(cor.sum())
        ac = aside = w / m
        if 0 < nc < m:
            ac = min(np.pi / 2, 0.5 * w / nc)
            aside = (w - nc * ac) / (m - nc)
        tau = np.cumsum(np.where(cor, ac, aside))[:-1]  # line q after cells 0 .. q-1
        phi = np.mod(np.arctan2(v[1:-1, 1], v[1:-1, 0]) - np.arctan2(v[0, 1], v[0, 0]), 2 * np.pi)
        r = np.hypot(*v[1:-1].T)
        short = np.sqrt(np.hypot(*v[0]) * np.hypot(*v[-1])) / lo
        band = slack * w / m
        off = phi - tau
        move = (np.abs(off) > band) | (r < short)
        new = np.arctan2(v[0, 1], v[0, 0]) + tau + np.clip(off, -band, band)
        r = np.maximum(r, short)
        nodes.extend(f[1:-1][move])
        tx.extend((x[c] + r * np.cos(new))[move])
        ty.extend((y[c] + r * np.sin(new))[move])
    return np.asarray(nodes, dtype=np.int64), np.asarray(tx), np.asarray(ty)
