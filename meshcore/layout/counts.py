r"""Integer cell counts that agree everywhere: a small mixed-integer program.

Every block side is a run of **chains** (pieces of line between break points: block corners
and the ends of shared parts).  A chain is shared by the one or two blocks beside it, so its
count ``n_c`` is one unknown.  A block needs equal counts on opposite sides:

.. math::  \sum_{c \in \text{bottom}} n_c = \sum_{c \in \text{top}} n_c, \qquad
           \sum_{c \in \text{left}} n_c = \sum_{c \in \text{right}} n_c .

We look for integers ``n_c ≥ 1`` (every side ≥ ``min_cells``) closest to the wanted counts
``L_c / h`` (``L_c`` the chain's length, ``h`` the cell size) in the weighted L¹ sense
``Σ |n_c − L_c/h|``
with :func:`scipy.optimize.milp` (HiGHS).  Each block side's constraint couples only the
chains around it, so the programs are tiny (tens to hundreds of unknowns) and solve in
milliseconds.  Optionally every count is a multiple of ``multiple`` (2**k lets a multigrid
coarsen k times).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..errors import TopologyError

__all__ = ["solve_counts"]


def solve_counts(
    targets: Sequence[float],
    sides: Sequence[tuple[Sequence[int], Sequence[int], Sequence[int], Sequence[int]]],
    *,
    min_cells: int = 3,
    multiple: int = 1,
    fixed: dict[int, int] | None = None,
) -> np.ndarray:
    """Integer counts per chain.

    Parameters
    ----------
    targets : sequence of float
        Wanted (real) cell count of every chain.
    sides : sequence of (bottom, right, top, left)
        Per block, the chain indices of each side.
    min_cells : int
        Smallest count of a whole block side.
    multiple : int
        Every chain count is a multiple of this.
    fixed : dict, optional
        Chains whose count is given (e.g. typed by the user).

    Raises
    ------
    TopologyError
        When no integer solution exists (e.g. fixed counts that contradict each other).
    """
    from scipy.optimize import LinearConstraint, milp

    t = np.asarray(targets, dtype=float)
    n = len(t)
    m = int(multiple)
    # unknowns: k_c (n_c = m k_c), e_c ≥ |m k_c − t_c| and the shortfall u_c ≥ t_c / 3 − m k_c
    # (a chain with far fewer cells than its length asks for would cut across the water it
    # should follow: below a third of it, a missing cell costs double)
    nv = 3 * n
    w = np.ones(n)
    # a tiny premium on larger counts breaks ties (opposite sides of different lengths) towards
    # cells no larger than asked for
    cost = np.concatenate([np.full(n, -1e-3 * m), w, 2.0 * w])
    rows, lo, hi = [], [], []

    def row() -> np.ndarray:
        return np.zeros(nv)

    for c in range(n):  # e_c − m k_c ≥ −t_c ;  e_c + m k_c ≥ t_c ;  u_c + m k_c ≥ t_c / 3
        r = row()
        r[n + c], r[c] = 1.0, -m
        rows.append(r), lo.append(-t[c]), hi.append(np.inf)
        r = row()
        r[n + c], r[c] = 1.0, m
        rows.append(r), lo.append(t[c]), hi.append(np.inf)
        r = row()
        r[2 * n + c], r[c] = 1.0, m
        rows.append(r), lo.append(t[c] / 3.0), hi.append(np.inf)
    for bottom, right, top, left in sides:
        for a, b in ((bottom, top), (left, right)):
            r = row()
            for c in a:
                r[c] += m
            for c in b:
                r[c] -= m
            rows.append(r), lo.append(0.0), hi.append(0.0)
        for side in (bottom, right, top, left):
            r = row()
            for c in side:
                r[c] += m
            rows.append(r), lo.append(float(min_cells)), hi.append(np.inf)
    lb = np.concatenate([np.ones(n), np.zeros(2 * n)])
    ub = np.full(nv, np.inf)
    for c, v in (fixed or {}).items():
        if v % m:
            raise TopologyError(f"a fixed count {v} is not a multiple of {m}")
        lb[c] = ub[c] = v // m
    from scipy.optimize import Bounds

    res = milp(
        cost,
        constraints=LinearConstraint(np.array(rows), lo, hi),
        integrality=np.concatenate([np.ones(n), np.zeros(2 * n)]),
        bounds=Bounds(lb, ub),
        options={"time_limit": 20.0, "mip_rel_gap": 0.0},
    )
    if res.x is None or res.status not in (0, 1):
        raise TopologyError(f"no integer cell counts satisfy the block sides ({res.message})")
    return (np.rint(res.x[:n]).astype(int) * m).astype(int)
