"""The level plan of the one-block multigrid (:mod:`.multigrid`): which directions to coarsen.

Each direction is coarsened (vertex-centred, :func:`._mg_kernels.transfer_tables`) while it has
at least :data:`MIN_COARSEN_CELLS` cells; where cells are clearly longer one way only the other
direction is coarsened (:func:`coarsening`); coarsening stops before a level that would fold or
whose scaled control sources lose monotonicity (:func:`_plan`).  :func:`anisotropic` tells the
solver to smooth by alternating lines from the start.  :class:`_Level` is one level's storage.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import _mg_control as C
from . import _mg_kernels as K
from . import _mg_wake as W

__all__ = ["MIN_COARSEN_CELLS", "anisotropic", "coarsening", "hierarchy"]

#: A direction is coarsened while it has at least this many cells.
MIN_COARSEN_CELLS = 4
#: A periodic ξ direction is not coarsened below this many cells.
MIN_PERIODIC_CELLS = 8
#: Cells longer than this times their height in one direction: coarsen only the other.
SEMI_ASPECT = 1.7
#: Coarsening stops at a level with more folded cells (fraction) than FOLD_GROWTH × its
#: parent's plus MAX_NEW_FOLDED (see _plan).
MAX_NEW_FOLDED, FOLD_GROWTH = 0.02, 2.0
#: Non-periodic grids whose sampled cells have an aspect beyond LINE_ASPECT (either way) in
#: more than LINE_FRACTION of the cells are smoothed by alternating zebra lines (see
#: :func:`_alt_lines`) from the start; others start with point smoothing and go on with
#: lines if that stalls or diverges.  Measured on generated one-block shapes (~24 000
#: nodes): channel networks, a spiral, a Y junction have 8–81 % of their cells beyond 3:1
#: and all stalled with point smoothing; discs, blobs and lakes with islands have ~2 % (the
#: corner cells) and converge in 5–17 point cycles, each a quarter of a line cycle.
LINE_ASPECT, LINE_FRACTION = 3.0, 0.1


def _stride(x: np.ndarray) -> int:
    """Sampling stride of the aspect estimate (about 64 samples per direction)."""
    return max(1, max(x.shape) // 64)


def coarsening(cells: tuple[int, int], aspect: float, periodic: bool = False) -> tuple[bool, bool]:
    """Which directions to coarsen: both, or only the strongly coupled one.

    Point Gauss–Seidel smooths only along the direction of strong coupling,
    which is the direction of the *shorter* cell side.  With cells longer than
    ``SEMI_ASPECT`` × their height in ξ only η is coarsened (and vice versa),
    which brings the coarse cells back towards aspect 1.  A periodic ξ
    direction keeps at least :data:`MIN_PERIODIC_CELLS` cells (a ring of
    three cells is a triangle: its coarse problem says nothing useful).
    """
    ci = cells[0] >= (2 * MIN_PERIODIC_CELLS if periodic else MIN_COARSEN_CELLS)
    cj = cells[1] >= MIN_COARSEN_CELLS
    if ci and cj:
        if aspect > SEMI_ASPECT:
            ci = False
        elif aspect < 1.0 / SEMI_ASPECT:
            cj = False
    return ci, cj


def anisotropic(x: np.ndarray, y: np.ndarray) -> bool:
    """True if more than ``LINE_FRACTION`` of the (sampled) cells have an aspect beyond
    ``LINE_ASPECT`` either way (first ξ side / first η side, as :func:`K.cell_stats`;
    :func:`K.far_fraction`, whose NumPy reference is in the tests)."""
    return bool(K.far_fraction(x, y, _stride(x), LINE_ASPECT**2) > LINE_FRACTION)


def _plan(x: np.ndarray, y: np.ndarray, periodic: bool = False, norm: tuple | None = None, wake: int = 0) -> list:
    """The coarsenings of the grid ``(x, y)``: ``(ci, cj, tables_i, tables_j)`` per level.

    Each direction is coarsened as :func:`coarsening` says; a coarse level
    (injected nodes) must still represent the shape: a level with (many) more
    folded cells than its parent, a ring cut into two cells say, is a
    degenerate grid whose FAS correction is noise, so coarsening stops
    before it.  "More" allows ``FOLD_GROWTH`` = 2 × the parent's fraction: a
    fold band of the (start) grid one cell wide is one coarse cell wide, twice
    the fraction of the cells, without being new (the algebraic start grid of
    a branched lake folds 3–10 % of its cells, which the Winslow solve
    removes; counted as new, coarsening stopped at a 32 × 369 level on one and
    at the finest on another, which then ran plain SOR).  With normalised control sources ``norm = (φ, ψ)`` it also
    stops before a level whose scaled sources lose monotonicity
    (:func:`._mg_control.coarse_ok`).  A C-grid wake cut of ``wake`` cells stays
    nested (:func:`._mg_wake.coarsen_xi_ok`).
    """
    out = []
    pos_i = np.arange(x.shape[0])
    pos_j = np.arange(x.shape[1])
    stats = K.cell_stats(x, y, _stride(x))  # (log aspect, folded fraction)
    while True:
        ci, cj = coarsening((x.shape[0] - 1, x.shape[1] - 1), float(np.exp(stats[0])), periodic)
        if wake and ci and not W.coarsen_xi_ok(x.shape[0] - 1, wake):
            ci = False
        if not (ci or cj):
            return out
        tab_i = _tables(pos_i, ci, periodic)
        tab_j = _tables(pos_j, cj, False)
        xc = np.empty((tab_i[6].size, tab_j[6].size))
        yc = np.empty(xc.shape)
        K.sample(x, tab_i[0], tab_i[1], tab_j[0], tab_j[1], xc)
        K.sample(y, tab_i[0], tab_i[1], tab_j[0], tab_j[1], yc)
        cstats = K.cell_stats(xc, yc, _stride(xc))
        if not cstats[1] <= FOLD_GROWTH * stats[1] + MAX_NEW_FOLDED:
            return out
        if norm is not None:
            norm = _coarse_norm(norm, tab_i[0], tab_i[1], tab_j[0], tab_j[1], xc.shape, clip=False)
            if not C.coarse_ok(*norm):
                return out
        out.append((ci, cj, tab_i, tab_j))
        if ci:
            wake //= 2
        stats = cstats
        x, y = xc, yc
        pos_i, pos_j = tab_i[6], tab_j[6]


def _coarse_norm(norm: tuple, si, swi, sj, swj, shape: tuple, clip: bool = True) -> tuple:
    """Normalised sources ``(φ, ψ)`` sampled to a coarse level and scaled by its coarsening
    factors (``φ → aφ``, ``ψ → bψ``); clipped to ``±PECLET_MAX`` if ``clip``."""
    out = []
    for arr, fac in zip(norm, _factors(norm[0].shape, shape), strict=True):
        c = np.empty(shape)
        K.sample(arr, si, swi, sj, swj, c)
        c *= fac
        if clip:
            np.clip(c, -C.PECLET_MAX, C.PECLET_MAX, out=c)
        out.append(c)
    return tuple(out)


def _factors(fine: tuple, coarse: tuple) -> tuple[float, float]:
    """Coarsening factors ``(a, b)``: fine cells per coarse cell in ξ and η."""
    return (fine[0] - 1) / (coarse[0] - 1), (fine[1] - 1) / (coarse[1] - 1)


def hierarchy(x: np.ndarray, y: np.ndarray, periodic: bool = False) -> list[tuple[int, int]]:
    """Cell counts ``(ni, nj)`` of every level for the grid ``(x, y)``, finest first."""
    out = [(x.shape[0] - 1, x.shape[1] - 1)]
    for _, _, tab_i, tab_j in _plan(x, y, periodic):
        out.append((tab_i[6].size - 1, tab_j[6].size - 1))
    return out


@dataclass(slots=True)
class _Level:
    x: np.ndarray
    y: np.ndarray
    fx: np.ndarray
    fy: np.ndarray
    p: np.ndarray
    q: np.ndarray
    rx: np.ndarray | None = None  # defect (fine shape) / coarse-correction scratch
    ry: np.ndarray | None = None
    par: bool = False
    lines: bool = False  # smoothed by alternating zebra lines (_alt_lines)
    # transfer to the next coarser level
    si: np.ndarray | None = None
    swi: np.ndarray | None = None
    sj: np.ndarray | None = None
    swj: np.ndarray | None = None
    ri: np.ndarray | None = None
    rwi: np.ndarray | None = None
    rj: np.ndarray | None = None
    rwj: np.ndarray | None = None
    li: np.ndarray | None = None
    wli: np.ndarray | None = None
    lj: np.ndarray | None = None
    wlj: np.ndarray | None = None
    scale: float = 1.0
    pscale: float = 1.0
    qscale: float = 1.0
    # C-grid wake cut (see _mg_wake): its cells on this level, the cut defects
    wake: int = 0
    rcx: np.ndarray | None = None
    rcy: np.ndarray | None = None


_TABLES: dict = {}


def _tables(pos: np.ndarray, coarsen: bool, periodic: bool):
    """:func:`K.transfer_tables`, memoised (they depend on the sizes only; read-only)."""
    key = (pos.tobytes(), coarsen, periodic)
    tab = _TABLES.get(key)
    if tab is None:
        if len(_TABLES) > 256:
            _TABLES.clear()
        tab = K.transfer_tables(pos, coarsen, periodic)
        for a in tab:
            a.flags.writeable = False
        _TABLES[key] = tab
    return tab
