"""The barrier minimisation: untangling with a shrinking ε, then nonlinear SOR; on patches that grow."""

from __future__ import annotations

import math

import numpy as np

from . import _kernels
from .cells import _dilate, _median_area, _median_edge, _nodes_of, _touched_cells, invalid_cells

__all__ = ["minimise", "patches"]

#: Most sweeps per ε in the untangling stage (fewer when the energy stalls); one is fastest
#: on lakes, slots and C shapes (measured 1–40); the whole-block last resort uses 20.
_INNER = 1


def minimise(
    x: np.ndarray,
    y: np.ndarray,
    nodes: np.ndarray,
    cells: np.ndarray,
    exempt: np.ndarray,
    *,
    tol: float,
    max_sweeps: int,
    max_outer: int = 500,
    inner: int | None = None,
    omega: float = 1.9,
    periodic: bool = False,
) -> tuple[bool, int]:
    """Untangle (if needed) then minimise the barrier energy over ``nodes`` in place.

    Returns ``(valid, sweeps)``.
    """
    inner = _INNER if inner is None else inner
    sweeps = 0
    step = np.inf
    _, dmin = _kernels.patch_stats(x, y, cells, 0.0, exempt)
    if dmin <= 0.0:
        eps_floor = 1e-12 * _median_area(x, y, cells)
        eps = max(math.sqrt(0.04 * dmin * dmin), eps_floor)
        e_prev, _ = _kernels.patch_stats(x, y, cells, eps, exempt)
        for _outer in range(max_outer):
            # minimise at this ε until the energy stalls (≤ inner sweeps)
            e_in = e_prev
            for _ in range(inner):
                d = _kernels.sweep(x, y, nodes, eps, step, 1.0, periodic)
                sweeps += 1
                e, dmin = _kernels.patch_stats(x, y, cells, eps, exempt)
                if d <= tol or dmin > 0.0 or e_in - e <= 1e-3 * e:
                    break
                e_in = e
            if dmin > 0.0:
                break
            sigma = max(1.0 - e / e_prev, 0.1)
            chi = 0.5 * (dmin + math.sqrt(eps * eps + dmin * dmin))
            mu = (1.0 - sigma) * chi
            eps = 2.0 * math.sqrt(mu * (mu - dmin)) if dmin < mu else eps_floor
            eps = max(eps, eps_floor)
            if eps < 1e-4 * abs(dmin):
                break  # stagnated: ε has vanished next to the worst inverted corner
            e_prev, _ = _kernels.patch_stats(x, y, cells, eps, exempt)
        if dmin <= 0.0:
            return False, sweeps
    for _ in range(max_sweeps):
        d = _kernels.sweep(x, y, nodes, 0.0, step, omega, periodic)
        sweeps += 1
        if d <= tol:
            break
    _, dmin = _kernels.patch_stats(x, y, cells, 0.0, exempt)
    return dmin > 0.0, sweeps


def patches(
    x: np.ndarray,
    y: np.ndarray,
    bad: np.ndarray,
    ex_bits: np.ndarray,
    *,
    radius: int,
    max_fraction: float,
    tolerance: float,
    max_sweeps: int,
    inner: int | None = None,
    periodic: bool = False,
) -> tuple[bool, int, int]:
    """Barrier minimisation on patches around ``bad``; the radius doubles on failure.

    Stops when the patch covers more than ``max_fraction`` of the cells (the
    whole block is always allowed when ``max_fraction ≥ 1``).  On failure the
    nodes are left as they were.  Returns ``(ok, free nodes, sweeps)``.
    """
    ni, nj = bad.shape
    r = max(1, int(radius))
    total = 0
    nfree = 0
    while True:
        patch = _dilate(bad, r, periodic) if r < max(ni, nj) else np.ones_like(bad)
        if patch.mean() > max_fraction and max_fraction < 1.0:
            return False, nfree, total
        nodes = _nodes_of(patch, periodic)
        if nodes.size == 0:
            return False, 0, total
        cells = _touched_cells(nodes, (ni, nj), periodic)
        h = _median_edge(x, y, cells)
        xs, ys = x.copy(), y.copy()
        ok, sw = minimise(
            x,
            y,
            nodes,
            cells,
            ex_bits,
            tol=tolerance * h,
            max_sweeps=max_sweeps,
            inner=inner,
            periodic=periodic,
        )
        total += sw
        nfree = len(nodes)
        if ok:
            bad_now = invalid_cells(x, y, ex_bits)
            if not bad_now.any():
                return True, nfree, total
            bad = bad | bad_now
        x[...], y[...] = xs, ys
        if patch.all():
            return False, nfree, total
        r *= 2
