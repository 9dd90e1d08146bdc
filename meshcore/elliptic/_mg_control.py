r"""Multigrid with a control-function updater (wall control, Thomas–Middlecoff): the pieces.

A control updater (:class:`meshcore.control.ControlSources`) writes the kernel
sources as ``P = (α/D²)·φ``, ``Q = (γ/D²)·ψ`` from *normalised* sources φ, ψ
(index units) and the metric of the grid at the time of the update.  Frozen
over a whole cycle that is unstable: the term ``D²(P x_ξ + Q x_η)`` then grows
with the square of the cell size, so a cell next to a wall that the coarse-grid
correction enlarges is pushed further (measured on the NACA 0012 O-grid: even
plain Gauss–Seidel diverges when the sources are refreshed only every 16
sweeps).  Three things make the FAS cycle work there:

* **Sources follow the grid.**  φ, ψ are taken from ``P, Q`` once per update
  (:func:`normalised`) and every level re-applies them with its *current*
  metric before it relaxes (:func:`apply`); on the coarse levels φ, ψ are
  sampled and scaled by the coarsening factors (``φ → aφ``).  At convergence
  the grid no longer moves, so the fine ``P, Q`` are the updater's.
* **Coarse levels keep a monotone source discretisation.**  Central
  differences of ``φ x_ξ`` stay diagonally dominant for ``|φ| ≤ 2`` (a cell
  Péclet number); φ doubles per coarsening of a geometrically stretched
  direction (ψ ≈ 0.19 at the NACA wall: 0.38, 0.76, 1.5, …).  Coarsening
  stops before a level whose φ or ψ exceed :data:`PECLET_MAX` at more than
  1 % of its nodes (:func:`coarse_ok`), and coarse φ, ψ are clipped to it.
* **A coarse-grid correction never collapses a cell.**  Interpolated in the
  index, a correction of a few first-cell heights inverts the thin cells next
  to a wall; :func:`safe_step` halves the correction until no cell loses more
  than :data:`MAX_AREA_LOSS` of its (signed) area.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ..control.geometry import scale_factors

__all__ = [
    "MAX_AREA_LOSS",
    "PECLET_BULK",
    "PECLET_MAX",
    "apply",
    "apply_reference",
    "cell_areas",
    "coarse_ok",
    "normalised",
    "safe_step",
]

#: Normalised coarse sources are bounded by this (cell Péclet number; central differences
#: of the source term stay diagonally dominant below 2).
PECLET_MAX = 1.0
#: A coarse level is used only while at most this fraction of its nodes exceed PECLET_MAX.
PECLET_FRACTION = 0.01
#: ... and while the median of its normalised sources stays below this (see coarse_ok:
#: the coarse cells reproduce the fine stretching within ~4 % there).
PECLET_BULK = 0.75
#: A damped coarse-grid correction lets no cell keep less than (1 − this) of its area.
MAX_AREA_LOSS = 0.75
#: At most this many halvings of a coarse-grid correction (then it is dropped).
MAX_HALVINGS = 10


def normalised(x, y, p, q, periodic: bool) -> tuple[np.ndarray, np.ndarray]:
    """The normalised sources ``(φ, ψ)`` behind the kernel sources ``P, Q`` on the grid ``(x, y)``."""
    with np.errstate(all="ignore"):
        fa, fg = scale_factors(x, y, periodic)
        ph = np.where(fa > 0, p / fa, 0.0)
        qh = np.where(fg > 0, q / fg, 0.0)
    return np.nan_to_num(ph, posinf=0.0, neginf=0.0), np.nan_to_num(qh, posinf=0.0, neginf=0.0)


def apply_reference(x, y, ph, qh, periodic: bool, p: np.ndarray, q: np.ndarray) -> None:
    """``p, q ← (α/D², γ/D²)·(φ, ψ)`` with the metric of the grid ``(x, y)`` now (NumPy;
    the oracle of :func:`apply`)."""
    fa, fg = scale_factors(x, y, periodic)
    np.multiply(fa, ph, out=p)
    np.multiply(fg, qh, out=q)


@njit(cache=True, nogil=True)
def apply(x, y, ph, qh, periodic, p, q):  # pragma: no cover - compiled
    """:func:`apply_reference` at the interior nodes (and the periodic seam), compiled.

    Border nodes keep their values: no kernel reads P, Q there.
    """
    ni1, nj1 = x.shape
    ni = ni1 - 1
    i0 = 0 if periodic else 1
    for i in range(i0, ni):
        iw = i - 1 if i > 0 else ni - 1
        ie = i + 1
        for j in range(1, nj1 - 1):
            xx = 0.5 * (x[ie, j] - x[iw, j])
            yx = 0.5 * (y[ie, j] - y[iw, j])
            xe = 0.5 * (x[i, j + 1] - x[i, j - 1])
            ye = 0.5 * (y[i, j + 1] - y[i, j - 1])
            a = xe * xe + ye * ye
            g = xx * xx + yx * yx
            d = xx * ye - xe * yx
            d2 = max(max(d * d, 1e-3 * a * g), 1e-300)
            p[i, j] = a / d2 * ph[i, j]
            q[i, j] = g / d2 * qh[i, j]
    if periodic:
        for j in range(1, nj1 - 1):
            p[ni, j] = p[0, j]
            q[ni, j] = q[0, j]


def coarse_ok(ph: np.ndarray, qh: np.ndarray) -> bool:
    """Whether a coarse level with normalised sources ``(φ, ψ)`` represents the fine source term.

    Only the rows ``j = 1 … nj − 1`` count: no kernel reads P, Q on the bottom and top
    borders, where the wall control's tangential source can be large (counted, they
    stopped a wall-controlled C-grid of 128 × 24 cells before its first coarse level).
    Two bounds, on ``s = max(|φ|, |ψ|)`` per node:

    * *spikes*: at most :data:`PECLET_FRACTION` of the nodes have ``s > PECLET_MAX``
      (monotone source term; those few are clipped);
    * *bulk*: the median ``s`` is at most :data:`PECLET_BULK`.  Central differences make a
      source ``s`` grow a coordinate by ``g(s) = (1 + s/2)/(1 − s/2)`` per cell; a coarse
      cell standing for ``a`` fine cells of source ``s/a`` should grow it by
      ``g(s/a)^a``.  The two differ by 1.5 % (of the logarithm) at ``s = 0.5``, 4 % at
      0.75, 8–9 % at 0.96: a level whose sources sit near the limit *everywhere* (a
      geometric wall stretching scales ψ uniformly: ψ ≈ 0.96 on every node of the
      33 × 7 level of an ellipse O-grid of 64 × 24 cells) misrepresents the stretching
      on the whole level, and its FAS correction overshoots (measured: solved more
      accurately it oscillated, solved by 100 sweeps it diverged; without it the cycle
      converged in 53 cycles).  A few spikes are local and harmless.
    """
    s = np.maximum(np.abs(ph[:, 1:-1]), np.abs(qh[:, 1:-1]))
    if s.size == 0:
        return True
    over = np.count_nonzero(s > PECLET_MAX)
    return bool(over <= PECLET_FRACTION * s.size and np.median(s) <= PECLET_BULK)


def cell_areas(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Twice the signed area of every cell (cross product of its diagonals)."""
    return (x[1:, 1:] - x[:-1, :-1]) * (y[:-1, 1:] - y[1:, :-1]) - (x[:-1, 1:] - x[1:, :-1]) * (y[1:, 1:] - y[:-1, :-1])


def safe_step(x: np.ndarray, y: np.ndarray, x0: np.ndarray, y0: np.ndarray) -> float:
    """Damp the step ``(x, y) − (x0, y0)`` in place so that no cell of positive area keeps
    less than ``1 − MAX_AREA_LOSS`` of it; returns the factor used (0: the step is dropped,
    so is a step to non-finite coordinates: a coarse level that blew up)."""
    with np.errstate(all="ignore"):
        return _safe_step(x, y, x0, y0)


def _safe_step(x, y, x0, y0) -> float:
    a0 = cell_areas(x0, y0)
    dx, dy = x - x0, y - y0
    floor = (1.0 - MAX_AREA_LOSS) * a0
    pos = a0 > 0
    theta = 1.0
    for _ in range(MAX_HALVINGS + 1):
        a1 = cell_areas(x, y)
        if np.isfinite(a1).all() and not np.any(pos & (a1 < floor)):
            return theta
        theta *= 0.5
        np.multiply(dx, theta, out=x)
        x += x0
        np.multiply(dy, theta, out=y)
        y += y0
    x[...] = x0
    y[...] = y0
    return 0.0
