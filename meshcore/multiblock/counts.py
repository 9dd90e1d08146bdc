r"""Integer cell counts that agree everywhere: a small mixed-integer program.

Every block side is a run of **chains** (pieces of line between break points: block corners
and the ends of shared parts).  A chain is shared by the one or two blocks beside it, so its
count ``n_c`` is one unknown.  A block needs equal counts on opposite sides:

.. math::  \sum_{c \in \text{bottom}} n_c = \sum_{c \in \text{top}} n_c, \qquad
           \sum_{c \in \text{left}} n_c = \sum_{c \in \text{right}} n_c .

We look for integers ``n_c ≥ 1`` (every side ≥ ``min_cells``) closest to the wanted counts
in the L¹ sense: first every block's count in each direction against the mean of its two
opposite sides' lengths over ``h`` (cells of the asked size in both directions, so
neighbouring blocks' cells are alike across their interface), then — with a quarter of the
weight — every chain against ``L_c / h`` (``L_c`` its length), which shares a side's cells
among the chains of a T-junction,
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
    targets: Sequence[float] | np.ndarray,
    sides: Sequence[Sequence[Sequence[int]]],
    *,
    min_cells: int = 3,
    multiple: int = 1,
    fixed: dict[int, int] | None = None,
    block_cells: dict[int, tuple[int, int]] | None = None,
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
    block_cells : dict, optional
        Blocks whose cells ``(ni, nj)`` are given: their bottom (and top) chains add up to
        ``ni``, their left (and right) chains to ``nj``.  With every block given, the program
        only shares each side's cells among its chains (closest to ``targets``).

    Raises
    ------
    TopologyError
        When no integer solution exists (e.g. fixed counts that contradict each other).
    """
    from scipy.optimize import LinearConstraint, milp

    t = np.asarray(targets, dtype=float)
    n = len(t)
    nb = len(sides)
    m = int(multiple)
    # unknowns: k_c (n_c = m k_c); e_c ≥ |n_c − t_c| per chain; f_bd ≥ |N_bd − T_bd| per block and
    # direction, with N_bd the count across the block in that direction and T_bd the mean of its
    # two opposite sides' targets: every block's cells close to the asked size in both directions
    # (so neighbours' cells are alike across interfaces), chains close to theirs within a side
    nv = 2 * n + 2 * nb
    cost = np.concatenate([np.full(n, -1e-3 * m), np.full(n, 0.25), np.ones(2 * nb)])
    rows, lo, hi = [], [], []

    def row() -> np.ndarray:
        return np.zeros(nv)

    def absdev(dev_index: int, chains, target: float) -> None:
        for sign in (1.0, -1.0):  # dev ± Σ m k ≥ ± target
            r = row()
            r[dev_index] = 1.0
            for c in chains:
                r[c] += sign * m
            rows.append(r), lo.append(sign * target), hi.append(np.inf)

    for c in range(n):
        absdev(n + c, [c], t[c])
    for bi, (bottom, right, top, left) in enumerate(sides):
        for d, (a, b) in enumerate(((bottom, top), (left, right))):
            r = row()
            for c in a:
                r[c] += m
            for c in b:
                r[c] -= m
            rows.append(r), lo.append(0.0), hi.append(0.0)
            absdev(2 * n + 2 * bi + d, list(a), 0.5 * (t[list(a)].sum() + t[list(b)].sum()))
        for side in (bottom, right, top, left):
            r = row()
            for c in side:
                r[c] += m
            rows.append(r), lo.append(float(min_cells)), hi.append(np.inf)
        if block_cells and bi in block_cells:
            for side, want in ((bottom, block_cells[bi][0]), (left, block_cells[bi][1])):
                r = row()
                for c in side:
                    r[c] += m
                rows.append(r), lo.append(float(want)), hi.append(float(want))
    lb = np.concatenate([np.ones(n), np.zeros(n + 2 * nb)])
    ub = np.full(nv, np.inf)
    for c, v in (fixed or {}).items():
        if v % m:
            raise TopologyError(f"a fixed count {v} is not a multiple of {m}")
        lb[c] = ub[c] = v // m
    from scipy.optimize import Bounds

    res = milp(
        cost,
        constraints=LinearConstraint(np.array(rows), lo, hi),
        integrality=np.concatenate([np.ones(n), np.zeros(n + 2 * nb)]),
        bounds=Bounds(lb, ub),
        options={"time_limit": 20.0, "mip_rel_gap": 0.0},
    )
    if res.x is None or res.status not in (0, 1):
        raise TopologyError(f"no integer cell counts satisfy the block sides ({res.message})")
    return (np.rint(res.x[:n]).astype(int) * m).astype(int)
