r"""Elliptic grid generation (Thompson–Thames–Mastin / Winslow with sources P, Q).

Symbols used throughout:

* ``xi, eta`` (ξ, η): computational coordinates, Δξ = Δη = 1;
* ``alpha, beta, gamma``: metric coefficients α = x_η² + y_η², β = x_ξ x_η + y_ξ y_η,
  γ = x_ξ² + y_ξ²;
* ``D = x_ξ y_η − x_η y_ξ``: the Jacobian determinant (the paper's 1/J);
* ``p, q``: control functions P, Q;
* ``omega``: the SOR relaxation factor.

Equations (paper eqs. 25/26, errata applied: docs/errata.md):
α x_ξξ − 2β x_ξη + γ x_ηη + D² (P x_ξ + Q x_η) = 0, same for y.
"""

from . import multigrid as _multigrid  # registers "multigrid"
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


def warmup(*, multigrid: bool = True, parallel: bool = True) -> None:
    """Compile (or load from the numba cache) the solver kernels on tiny grids.

    ``multigrid`` also runs a small multigrid solve (every serial multigrid
    kernel), ``parallel`` calls the ``parallel=True`` kernels that the
    default ``threads=0`` uses on large grids.  Meant for a background thread
    at start-up, so that the first real solve pays no one-time cost.
    """
    import numpy as np

    from . import _kernels, _mg_kernels
    from .solver import solve

    x, y = np.meshgrid(np.arange(5.0), np.arange(5.0), indexing="ij")
    x, y = np.ascontiguousarray(x), np.ascontiguousarray(y)
    e = np.zeros((0, 0))
    _kernels.sweep4(x, y, e, e, 1.0, False)
    _kernels.jacobi_residual(x, y, e, e, False)
    if multigrid:
        from ..grid import StructuredGrid

        s = np.linspace(0.0, 1.0, 33)
        X, Y = np.meshgrid(s, s, indexing="ij")
        X = X + 0.05 * np.sin(np.pi * X) * np.sin(np.pi * Y)
        solve(StructuredGrid(X, Y), method="multigrid", threads=1)
        # cells long one way at one corner and the other way at the other: line smoothing
        t = np.linspace(0.0, 1.0, 17)
        X, Y = np.meshgrid(t * t, 1.0 - (1.0 - t) ** 2, indexing="ij")
        solve(StructuredGrid(X + 0.1 * Y * Y, Y), method="multigrid", threads=1)
        from . import _mg_wake  # the C-grid wake cut (x, y copies: the rows of a 5×5 square)

        r = np.zeros(5)
        _mg_wake.cut_defect(x.copy(), y.copy(), e, e, 2, r, r.copy())
        _mg_wake.relax_cut(x.copy(), y.copy(), e, e, 2, 1)
    if parallel:
        _kernels.sweep4_parallel(x, y, e, e, 1.0, False)
        r = np.zeros_like(x)
        _mg_kernels.smooth_parallel(x, y, r, r, e, e, False, 1)
        from . import _mg_lines

        _mg_lines.smooth_lines_parallel(x.copy(), y.copy(), r, r, e, e, 0, 1)
        tab = _multigrid._tables(np.arange(5.0), True, False)  # read-only, as in a solve
        xc = np.zeros((tab[6].size, tab[6].size))
        _mg_kernels.defect_parallel(x, y, e, e, e, e, False, r.copy(), r.copy())
        _mg_kernels.defect_restrict_parallel(
            x, y, e, e, e, e, tab[2], tab[3], tab[2], tab[3], 1.0, xc, xc.copy(), _mg_kernels.ROW_CHUNKS
        )
        _mg_kernels.restrict_parallel(r, r, tab[2], tab[3], tab[2], tab[3], 1.0, xc, xc.copy())
        _mg_kernels.add_operator_parallel(xc, xc.copy(), e, e, False, xc.copy(), xc.copy())
        _mg_kernels.prolong_correct_parallel(
            x,
            y,
            xc,
            xc.copy(),
            xc.copy(),
            xc.copy(),
            tab[0],
            tab[1],
            tab[0],
            tab[1],
            tab[4],
            tab[4],
            tab[5],
            tab[5],
            False,
        )
