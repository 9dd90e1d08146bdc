r"""Elliptic grid generation (Thompson–Thames–Mastin / Winslow with sources P, Q).

Symbols used throughout:

* ``xi, eta`` (ξ, η): computational coordinates, Δξ = Δη = 1;
* ``alpha, beta, gamma``: metric coefficients α = x_η² + y_η², β = x_ξ x_η + y_ξ y_η,
  γ = x_ξ² + y_ξ²;
* ``D = x_ξ y_η − x_η y_ξ``: the Jacobian determinant (the paper's 1/J);
* ``p, q``: control functions P, Q;
* ``omega``: the SOR relaxation factor.

Equations (paper eqs. 25/26, errata applied):
α x_ξξ − 2β x_ξη + γ x_ηη + D² (P x_ξ + Q x_η) = 0, same for y.
"""

from . import multigrid as _multigrid  # noqa: F401  (registers "multigrid")
from .solver import (
    METHODS,
    EllipticConfig,
    SolverProgress,
    default_tolerance,
    iterate,
    register_method,
    residual,
    solve,
)

__all__ = [
    "METHODS",
    "EllipticConfig",
    "SolverProgress",
    "default_tolerance",
    "iterate",
    "register_method",
    "residual",
    "solve",
    "warmup",
]


def warmup() -> None:
    """Compile (or load from cache) the kernels on a tiny grid."""
    import numpy as np

    from . import _kernels

    x, y = np.meshgrid(np.arange(5.0), np.arange(5.0), indexing="ij")
    x, y = np.ascontiguousarray(x), np.ascontiguousarray(y)
    e = np.zeros((0, 0))
    _kernels.sweep4(x, y, e, e, 1.0, False)
    _kernels.jacobi_residual(x, y, e, e, False)
