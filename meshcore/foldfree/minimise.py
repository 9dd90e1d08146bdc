"""The barrier minimisation: untangling with a shrinking ε, then nonlinear SOR; on patches that grow."""

from __future__ import annotations

import math

import numpy as np

from . import _kernels, _sweep
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
    _, dmin = _kernels.patch_stats(x, y, cells, 0.0, exempt)
    if dmin <= 0.0:
        eps_floor = 1e-12 * _median_area(x, y, cells)
        eps = max(math.sqrt(0.04 * dmin * dmin), eps_floor)
        dmin, sweeps = _sweep.untangle(x, y, nodes, cells, exempt, eps, eps_floor, tol, inner, max_outer, periodic)
        if dmin <= 0.0:
            return False, sweeps
    sweeps += _sweep.barrier_sweeps(x, y, nodes, tol, max_sweeps, omega, periodic)
    _, dmin = _kernels.patch_stats(x, y, cells, 0.0, exempt)
    return dmin > 0.0, sweeps


def _components(mask: np.ndarray, periodic: bool) -> list[np.ndarray]:
    """The 8-connected components of ``mask`` (boolean masks), joined across the seam if ``periodic``."""
    from scipy import ndimage

    lab, n = ndimage.label(mask, structure=np.ones((3, 3), dtype=bool))
    if periodic and n > 1:  # column ni − 1 touches column 0: join labels that meet there
        parent = list(range(n + 1))

        def root(a: int) -> int:
            while parent[a] != a:
                parent[a] = parent[parent[a]]
                a = parent[a]
            return a

        nj = mask.shape[1]
        for j in range(nj):
            a = lab[-1, j]
            if not a:
                continue
            for dj in (-1, 0, 1):
                if 0 <= j + dj < nj and lab[0, j + dj]:
                    parent[root(int(lab[0, j + dj]))] = root(int(a))
        lab = np.array([root(k) for k in range(n + 1)])[lab]
    return [lab == k for k in np.unique(lab[lab > 0])]


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
    max_radius: int | None = None,
    give_up_early: bool = False,
) -> tuple[bool, int, int]:
    """Barrier minimisation on patches around ``bad``, each connected patch on its own.

    The patch of radius ``r`` (cells) around the bad cells falls apart into
    connected pieces; each is minimised with every node outside it fixed.
    A piece that ends valid keeps its nodes; a failed piece gets its nodes
    back and its bad cells try again with ``2 r``, until the piece covers
    more than ``max_fraction`` of the cells (the whole block is always
    allowed when ``max_fraction ≥ 1``) or ``r`` would pass ``max_radius``.  So a fold that cannot be repaired
    locally no longer makes every other one grow with it, and the cost
    follows the size of the pieces, not of the block.  Returns
    ``(ok, free nodes, sweeps)``; on failure the repaired pieces stay.
    ``give_up_early``: return ``ok = False`` as soon as the failure is certain (a piece given up,
    or failed at the last radius), the other pieces untried (for a caller that then discards the
    grid).
    """
    ni, nj = bad.shape
    r = max(1, int(radius))
    total = 0
    nfree = 0
    todo = bad.copy()
    given_up = np.zeros_like(bad)
    while todo.any() and (max_radius is None or r <= max_radius):
        whole = r >= max(ni, nj)
        mask = np.ones_like(bad) if whole else _dilate(todo, r, periodic)
        failed = np.zeros_like(bad)
        last = whole or (max_radius is not None and 2 * r > max_radius)
        pieces = [mask] if whole else _components(mask, periodic)
        if give_up_early and last:  # the widest piece first: the likeliest to fail, which ends the call
            pieces.sort(key=lambda m: -int(m.sum()))
        for piece in pieces:
            if max_fraction < 1.0 and piece.sum() > max_fraction * piece.size:
                given_up |= piece & todo
                if give_up_early:
                    return False, nfree, total
                continue
            nodes = _nodes_of(piece, periodic)
            if nodes.size == 0:
                given_up |= piece & todo
                if give_up_early:
                    return False, nfree, total
                continue
            cells = _touched_cells(nodes, (ni, nj), periodic)
            h = _median_edge(x, y, cells)
            xs, ys = x[nodes[:, 0], nodes[:, 1]].copy(), y[nodes[:, 0], nodes[:, 1]].copy()
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
            nfree += len(nodes)
            if not ok:  # the piece's nodes go back (seam copies too)
                x[nodes[:, 0], nodes[:, 1]], y[nodes[:, 0], nodes[:, 1]] = xs, ys
                if periodic:
                    x[-1, :], y[-1, :] = x[0, :], y[0, :]
                failed |= piece
                if give_up_early and last:
                    return False, nfree, total
        if whole:
            given_up |= failed
        todo = invalid_cells(x, y, ex_bits) & ~given_up
        r *= 2
    return not invalid_cells(x, y, ex_bits).any(), nfree, total
