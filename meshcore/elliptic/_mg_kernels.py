r"""numba kernels of the nonlinear multigrid (FAS) solver, by concern (functions only).

* :mod:`._stencil` — the Winslow/TTM equations at one node (every kernel calls it);
* :mod:`._mg_relax` — point Gauss–Seidel relaxation (4-colour order, border bands);
* :mod:`._mg_defect` — defects, the fused defect restriction, the FAS coarse right-hand side;
* :mod:`._mg_transfer` — ``R̂`` (sampling), full-weighting restriction, prolongation, tables;
* :mod:`._mg_fused` — whole coarse V-cycles and the full-multigrid start in one call.

Operator.  At an interior node the discrete Winslow/TTM equations (eq. 30,
errata applied, Δξ = Δη = 1) are written as

.. math::

    N(u)_P = 2(α + γ)\, φ_P - \big[α(φ_E + φ_W) + γ(φ_N + φ_S)
             - \tfrac{β}{2}(φ_{NE} - φ_{NW} - φ_{SE} + φ_{SW})
             + D^2 (P φ_ξ + Q φ_η)\big] = f_P,\qquad φ ∈ \{x, y\},

``N = −(α φ_ξξ − 2β φ_ξη + γ φ_ηη + D²(P φ_ξ + Q φ_η))``, ``f = 0`` on the finest level
and the FAS right-hand side on coarse levels.  This module re-exports the kernels the
driver (:mod:`.multigrid`) uses.
"""

from __future__ import annotations

from ._compile import ROW_CHUNKS
from ._mg_defect import (
    RING,
    add_operator,
    add_operator_parallel,
    defect,
    defect_parallel,
    defect_restrict,
    defect_restrict_parallel,
)
from ._mg_fused import (
    M_FX,
    M_FY,
    M_LI,
    M_LJ,
    M_N0,
    M_N1,
    M_P,
    M_PQ,
    M_Q,
    M_RI,
    M_RJ,
    M_RWI,
    M_RWJ,
    M_RX,
    M_RY,
    M_SI,
    M_SJ,
    M_SWI,
    M_SWJ,
    M_WI,
    M_WJ,
    M_WLI,
    M_WLJ,
    M_X,
    M_Y,
    META_COLS,
    fmg_start,
    vcycle,
)
from ._mg_relax import TRANSPOSE_MAX_WIDTH, VECTOR_ROW, smooth, smooth_band, smooth_parallel
from ._mg_transfer import (
    RW,
    cell_stats,
    coarse_positions,
    far_fraction,
    prolong_correct,
    prolong_correct_parallel,
    restrict,
    restrict_parallel,
    sample,
    transfer_tables,
)

__all__ = [
    "META_COLS",
    "RING",
    "ROW_CHUNKS",
    "RW",
    "TRANSPOSE_MAX_WIDTH",
    "VECTOR_ROW",
    "add_operator",
    "add_operator_parallel",
    "cell_stats",
    "far_fraction",
    "coarse_positions",
    "defect",
    "defect_parallel",
    "defect_restrict",
    "defect_restrict_parallel",
    "fmg_start",
    "prolong_correct",
    "prolong_correct_parallel",
    "restrict",
    "restrict_parallel",
    "sample",
    "smooth",
    "smooth_band",
    "smooth_parallel",
    "transfer_tables",
    "vcycle",
] + [
    "M_FX", "M_FY", "M_LI", "M_LJ", "M_N0", "M_N1", "M_P", "M_PQ", "M_Q", "M_RI", "M_RJ", "M_RWI",
    "M_RWJ", "M_RX", "M_RY", "M_SI", "M_SJ", "M_SWI", "M_SWJ", "M_WI", "M_WJ", "M_WLI", "M_WLJ",
    "M_X", "M_Y",
]  # fmt: skip
