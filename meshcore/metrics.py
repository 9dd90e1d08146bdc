r"""Transformation metrics at every node (second order, one-sided at borders).

For a grid ``x(ξ, η), y(ξ, η)`` with Δξ = Δη = 1:

* ``x_xi, x_eta, y_xi, y_eta`` — central differences inside, second-order
  one-sided differences on the borders (``numpy.gradient(edge_order=2)``);
  across the seam of a periodic (O-grid) direction, central differences.
* ``jacobian`` — ``D = x_ξ y_η − x_η y_ξ`` (the paper's ``1/J``);
* ``alpha = x_η² + y_η²``, ``beta = x_ξ x_η + y_ξ y_η``, ``gamma = x_ξ² + y_ξ²``;
* inverse metrics ``xi_x = y_η/D``, ``xi_y = −x_η/D``, ``eta_x = −y_ξ/D``,
  ``eta_y = x_ξ/D`` (NaN where D = 0).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .grid import StructuredGrid

__all__ = ["METRIC_FIELDS", "Metrics", "metrics"]

METRIC_FIELDS = (
    "x_xi",
    "x_eta",
    "y_xi",
    "y_eta",
    "jacobian",
    "alpha",
    "beta",
    "gamma",
    "xi_x",
    "xi_y",
    "eta_x",
    "eta_y",
)


@dataclass(frozen=True, slots=True, eq=False)
class Metrics:
    """Node metrics of a grid; every field is an array of the node shape."""

    x_xi: np.ndarray
    x_eta: np.ndarray
    y_xi: np.ndarray
    y_eta: np.ndarray
    jacobian: np.ndarray
    alpha: np.ndarray
    beta: np.ndarray
    gamma: np.ndarray
    xi_x: np.ndarray
    xi_y: np.ndarray
    eta_x: np.ndarray
    eta_y: np.ndarray

    def as_dict(self) -> dict[str, np.ndarray]:
        return {k: getattr(self, k) for k in METRIC_FIELDS}


def _d_xi(a: np.ndarray, periodic: bool) -> np.ndarray:
    if a.shape[0] < 3:
        return np.repeat(np.diff(a, axis=0), 2, axis=0)
    if periodic:
        core = a[:-1]
        d = 0.5 * (np.roll(core, -1, axis=0) - np.roll(core, 1, axis=0))
        return np.vstack([d, d[:1]])
    return np.gradient(a, axis=0, edge_order=2)


def _d_eta(a: np.ndarray) -> np.ndarray:
    if a.shape[1] < 3:
        return np.repeat(np.diff(a, axis=1), 2, axis=1)
    return np.gradient(a, axis=1, edge_order=2)


def metrics(grid: StructuredGrid) -> Metrics:
    """Compute the node metrics of ``grid``.

    Examples
    --------
    >>> import numpy as np
    >>> from meshcore import StructuredGrid
    >>> xi, eta = np.meshgrid(np.arange(4.0), np.arange(3.0), indexing="ij")
    >>> m = metrics(StructuredGrid(2 * xi, eta))
    >>> float(m.jacobian.min()), float(m.xi_x.max())
    (2.0, 0.5)
    """
    x, y = grid.x, grid.y
    x_xi, y_xi = _d_xi(x, grid.periodic), _d_xi(y, grid.periodic)
    x_eta, y_eta = _d_eta(x), _d_eta(y)
    d = x_xi * y_eta - x_eta * y_xi
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = np.where(d != 0, 1.0 / np.where(d != 0, d, 1.0), np.nan)
    return Metrics(
        x_xi=x_xi,
        x_eta=x_eta,
        y_xi=y_xi,
        y_eta=y_eta,
        jacobian=d,
        alpha=x_eta**2 + y_eta**2,
        beta=x_xi * x_eta + y_xi * y_eta,
        gamma=x_xi**2 + y_xi**2,
        xi_x=y_eta * inv,
        xi_y=-x_eta * inv,
        eta_x=-y_xi * inv,
        eta_y=x_xi * inv,
    )
