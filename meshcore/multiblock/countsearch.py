"""Cell counts for blocks whose cells are given: a short search instead of HiGHS.

A case's blocks say their cells (``cells = [ni, nj]``), so every block side must add up to a
known count.  Most chains are then forced: a chain that is a whole side has the side's count, and
the last unknown chain of a side has what the side's other chains leave.  Only sides with two or
more chains (a T-junction, a cut ending on a side) leave a choice: on the Shasta examples three
shore chains on one side share 24 (or 48) cells.  :func:`best_counts` settles the forced chains,
splits the open sides into groups that share no unknown chain and searches each group depth-first
(settling the forced chains after every choice), keeping the group's counts of least cost.

Each group can be chosen on its own because the program's objective (:func:`~.counts.objective`)
is then a sum of terms that each vary with one group's chains only: a block's count across it and
a side's total are given, two chains in a row on an open side are in its group, and the other
terms are per chain.  So the search visits the sum of the groups' solutions, not their product
(on 36 generated layouts 2–790 solutions in all, where the product reached 27 720), and gives
the program's optimum without HiGHS, whose branch and bound took 11 ms on the 28 chains of the
Shasta examples (and a new process spends longer than that importing :mod:`scipy.optimize`).
When the blocks' cells are not all given (the layout's program chooses them) or the search
grows beyond :data:`MAX_NODES`, it gives up and the program is solved by HiGHS.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable, Mapping, Sequence

import numpy as np

from ..errors import TopologyError

__all__ = ["MAX_NODES", "best_counts"]

#: Most search nodes (partial counts) visited before the search gives up.  A node costs 10–25 µs
#: (its settling and the objective of its solutions), HiGHS 4–20 ms on the programs that reach
#: it (generated layouts of 5–37 blocks, load 9): the bound keeps the search's worst case near
#: one HiGHS solve (the layout nearest it, 790 solutions: 21 ms against HiGHS's 13).
MAX_NODES = 1000

Eq = tuple[list[tuple[int, int]], int]  # (chain, coefficient) terms, the units they add up to


class _TooMany(Exception):
    pass


def _settle(value: list[int], eqs: Sequence[Eq]) -> bool:
    """Give every chain that is the last unknown of a side its count (in place, until none is
    left); False when a side cannot add up (a count below 1 or not a whole number of units)."""
    changed = True
    while changed:
        changed = False
        for terms, want in eqs:
            rest, least, free = want, 0, None
            for c, a in terms:
                if value[c]:
                    rest -= a * value[c]
                else:
                    least += a
                    free = (c, a) if free is None else (-1, 0)
            if free is None:
                if rest:
                    return False
            elif free[0] >= 0:
                v, r = divmod(rest, free[1])
                if r or v < 1:
                    return False
                value[free[0]] = v
                changed = True
            elif rest < least:
                return False
    return True


def _groups(value: list[int], eqs: Sequence[Eq]) -> list[list[Eq]]:
    """The open sides (some chain unknown) in groups that share no unknown chain."""
    parent: dict[int, int] = {}

    def root(c: int) -> int:
        while parent.setdefault(c, c) != c:
            c = parent[c]
        return c

    open_eqs = [eq for eq in eqs if any(not value[c] for c, _ in eq[0])]
    for terms, _ in open_eqs:
        free = [c for c, _ in terms if not value[c]]
        for c in free[1:]:
            parent[root(c)] = root(free[0])
    out: dict[int, list[Eq]] = {}
    for eq in open_eqs:
        out.setdefault(root(next(c for c, _ in eq[0] if not value[c])), []).append(eq)
    return list(out.values())


def _search(value: list[int], eqs: Sequence[Eq], budget: list[int]) -> list[list[int]]:
    """Every completion of ``value`` on the chains of ``eqs`` (depth first, smallest counts first),
    ``budget[0]`` nodes at most (then :class:`_TooMany`)."""
    out: list[list[int]] = []
    stack = [value]
    while stack:
        value = stack.pop()
        budget[0] -= 1
        if budget[0] < 0:
            raise _TooMany
        if not _settle(value, eqs):
            continue
        pick = next(((terms, want) for terms, want in eqs if any(not value[c] for c, _ in terms)), None)
        if pick is None:
            out.append(value)
            continue
        terms, want = pick
        unknown = [(c, a) for c, a in terms if not value[c]]
        rest = want - sum(a * value[c] for c, a in terms if value[c])
        (c, a), others = unknown[0], sum(a for _, a in unknown[1:])
        for v in range((rest - others) // a, 0, -1):  # popped smallest first
            child = value.copy()
            child[c] = v
            stack.append(child)
    return out


def _least(counts: np.ndarray, cost: Callable[[np.ndarray], np.ndarray]) -> int:
    """The first row (in the search's order: smaller counts on a side's first chains first) whose
    cost is within 1e-9 of the least: equally good counts are common (two chains on a side whose
    |n − t| add up alike), the program takes any, and this order gave HiGHS's choice on 38 of 39
    programs (the Shasta examples, 36 of generated layouts; the L² distance to the targets: 35)."""
    c = cost(counts)
    return int(np.flatnonzero(c <= c.min() + 1e-9)[0])


def best_counts(
    n_chains: int,
    sides: Sequence[Sequence[Sequence[int]]],
    *,
    multiple: int,
    min_cells: int,
    block_cells: Mapping[int, tuple[int, int]] | None,
    cost: Callable[[np.ndarray], np.ndarray],
    fixed: Mapping[int, int] | None = None,
    max_nodes: int = MAX_NODES,
) -> np.ndarray | None:
    """The count per chain (multiples of ``multiple``) of least ``cost`` with which every block
    side adds up to its block's given cells.

    ``cost`` maps counts (rows: candidates, one column per chain) to a cost per row and must
    separate as :func:`~.counts.objective` does (see the module's docstring).  None when the search
    does not apply or gives up: a block without given cells, a chain on no block side, a fixed
    count below ``multiple``, or more than ``max_nodes`` nodes.  ``sides``, ``min_cells``,
    ``block_cells`` and ``fixed`` as in :func:`~.counts.solve_counts` (a fixed count is a
    multiple of ``multiple``).

    Raises
    ------
    TopologyError
        When no counts fit (the program would have no solution).
    """
    m = int(multiple)
    if not block_cells or any(bi not in block_cells for bi in range(len(sides))):
        return None
    none = TopologyError("no integer cell counts satisfy the block sides (their given cells leave none)")
    eqs: list[Eq] = []
    for bi, (bottom, right, top, left) in enumerate(sides):
        ni, nj = block_cells[bi]
        for side, want in ((bottom, ni), (top, ni), (left, nj), (right, nj)):
            if want < min_cells or want % m:
                raise none
            eqs.append((list(Counter(int(c) for c in side).items()), int(want) // m))
    if len({c for terms, _ in eqs for c, _ in terms}) < n_chains:
        return None
    value = [0] * n_chains  # 0: not known yet (every count is ≥ 1 unit)
    for c, v in (fixed or {}).items():
        if v < m:
            return None
        value[c] = int(v) // m
    if not _settle(value, eqs):
        raise none
    budget = [max_nodes]
    try:
        for group in _groups(value, eqs):
            found = _search(value, group, budget)
            if not found:
                raise none
            value = found[_least(m * np.array(found), cost)] if len(found) > 1 else found[0]
    except _TooMany:
        return None
    return m * np.array(value, dtype=int)
