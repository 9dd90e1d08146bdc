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
and — what the cells across a cut line see — every pair of spacings that meet (two chains in
a row along a block side; the two blocks beside a shared chain, across it) pays for the
cells by which one density exceeds :data:`JUMP` times the other (:func:`_jump_pairs`), and
:data:`STEEP_WEIGHT` more per cell beyond :data:`STEEP` times, a chain shorter than ``multiple``
cells measured against the ``multiple`` cells it cannot go below:
without it, a block side made of a short cut and a long shore could get 28 cells on the cut
and 4 on the shore (a Y junction's star), a tenfold jump no smoother removes, and a 1.6-cell shore
piece beside a 29-cell cut took 32 cells where the cut had 12 (the block fanned into the piece);
with :func:`scipy.optimize.milp` (HiGHS).  Each block side's constraint couples only the
chains around it, so the programs are small (tens to hundreds of unknowns); with every
``|.|`` term's convex hull written in (:data:`HULL_CUTS`) a hundred blocks take about a second.
Optionally every count is a multiple of ``multiple`` (2**k lets a multigrid coarsen k times).
When every block's cells are given, most chains are forced and the few solutions are searched
instead (:mod:`.countsearch`, :data:`SEARCH`).
Among otherwise equally good counts, the spacings that meet are made alike and each cell earns a
hair (:data:`ALIKE`, :data:`TIE_BREAK`), so that the optimum is one count vector whatever HiGHS's
search meets first.
"""

from __future__ import annotations

import itertools
from collections import defaultdict
from collections.abc import Sequence

import numpy as np

from ..errors import TopologyError

__all__ = ["ALIKE", "TIE_BREAK", "objective", "solve_counts", "tie_weights"]

#: Spacings that meet (two chains in a row along a block side, two blocks across their
#: interface) may differ by this factor before the program pays for it ...
JUMP = 1.5
#: ... and it pays this much per cell of the excess (a deviation from the cell size costs 1).
JUMP_WEIGHT = 1.0
#: Beyond this factor a jump pays :data:`STEEP_WEIGHT` more per cell of the excess over it: a
#: side whose chains' spacings differ tenfold fans its block into the dense chain, which costs
#: more than the cells an arm or the block's other side gives up to avoid it.  Held-out lake
#: g180632 at 10 000 cells: its cut and shore piece 12 + 32 → 20 + 8 cells, nodes within 3°
#: 69 → 83 %.
#: OFF by default (0.0; 8.0 with :data:`SHORT_JUMPS` measured on session 15's landed tree against
#: off): fresh_sweep base 791000, shapes with ≥ 90 % of nodes within 3°: 42 → 43 of 45
#: (15 000 cells), 40 → 44 (10 000), 23 → 24 of 27 (``--more``); geometric mean of the largest
#: interface ratio 3.02 → 2.98, 2.65 → 2.49, 5.31 → 4.41; held-out set 3 (20 real lakes with
#: islands) at 10 000 cells: g180632 69 → 83 %, g180936 77 → 91 %, g180713 80 → 87 %.  Worse:
#: every interface ratio ≤ 2 in 16 → 13 (base 791000, 15 000 cells), ``islands 791302`` at 10 000
#: cells 84.5 → 74.0 %, held-out g181126 90 → 85 % and g180775's shore 0.23 → 1.57 cells; some
#: layouts get fewer cells (``lake_with_islands(740300)`` 10 208 → 7 264 at 10 000 asked).  Before
#: the island-cover weight (:data:`LAND_WEIGHT`) it also took ``lake_with_islands(18)``'s coarsest
#: level 2.45 cells off the shore; with it, ``lake_with_islands(6)`` (tests/meshcore/
#: test_layout_folds.py) falls to 73.5 % of nodes within 3° (the test asks 80 %).  Why they lost,
#: and the cost now paid along block sides only: :data:`STEEP_ACROSS`, docs/lake-grids-journal.md
#: ("Crowded shore pieces"); still off: the largest interface ratio and a few lakes get worse.
STEEP = 3.0
STEEP_WEIGHT = 0.0
#: Cost per cell by which a chain falls short of its ``least`` count: above every other
#: term (1 per cell of a block's deviation, of a jump), so a shore chain gets the cells that
#: keep the coarse levels in the water unless that needs four times as many elsewhere.  On 40
#: generated lakes with islands and bays and 6 others, 4 instead of 2 brought the largest
#: distance of a node outside the water from 2.3 to 1.3 cells at the same cell count.
LEAST_WEIGHT = 4.0
#: The same cost where the chain's coarse chords would cross an island (its block wraps an
#: island's convex side, :func:`~.shorecells.over_island`): there a shortfall puts the coarse
#: grid over the island, refinement does not bring it back, and the island is lost (the layout
#: of ``lake_with_islands(263303, n_islands=9, lobes=7)`` left a 2.4-long side round an island,
#: 26 cells long and 20 least, with 4: one coarse edge, shoreline distance 16 cells).  Near a
#: hard bound: only a shortfall that costs 16 cells elsewhere per cell stays.
LAND_WEIGHT = 16.0
#: (Both pay :data:`STEEP_WEIGHT` more when it is on, so a shortfall still costs more than a cell of
#: a steep jump: with 4 against 8, held-out g180775 at 10 000 cells gave a shore chain's cells to a
#: jump and its grid left the shore by 1.57 cells, 0.23 with 12.)
#: HiGHS's wall-clock limit, seconds: a guard against a hang, not a budget.  The counts must
#: not depend on how busy the machine is: with a 20 s limit a layout of ~90 blocks (2.4 s of
#: CPU) stopped at a worse incumbent on a loaded machine and came out with other blocks.
TIME_LIMIT = 600.0
#: Add to every ``|N − T|`` term (``N`` a sum of counts, all multiples of ``m``) the line through
#: its two integer points around ``T`` (and the same for the ``least`` shortfall): the convex hull
#: of the term's integer points.  Valid for every integer count, so the program has the same
#: solutions and optimum, but its LP relaxation no longer spreads fractional counts to make every
#: term zero.  HiGHS otherwise finds these cuts itself, round by round at the root: on generated
#: channel networks of 44/84/124 blocks 0.54/1.27/8.7 s of CPU without them, 0.13/0.51/1.35 s
#: with them, the same counts.  False: the plain program (the tests' oracle).
HULL_CUTS = True
#: With every block's cells given (a case's blocks), search the solutions (:mod:`.countsearch`)
#: for the least :func:`objective` when there are few, instead of HiGHS (the same optimum, and
#: mostly the same counts where several are as good).  False: always HiGHS (the tests' oracle).
SEARCH = True
#: Pay for jumps next to chains shorter than ``multiple`` cells too, measured against the fewest
#: cells they can have (``multiple``).  False: such chains were exempt, and a 1.6-cell shore piece
#: beside a 12-cell cut on one block side could take 32 cells (a 48x jump, the block fanning into it).
#: Measured again alone in session 32 (:data:`STEEP_WEIGHT` off), for the crowded tiny shore pieces
#: of lakes of 40–110 blocks (held-out g180713 at 15 000 cells: 36 cells on 3.9 cells of shore beside
#: a 43-cell cut with 12): mixed, still off — the counts are a new draw and interface ratios move
#: both ways (docs/lake-grids-journal.md, "Tiny chains pay for their jumps").
SHORT_JUMPS = False
#: With :data:`STEEP_WEIGHT` on, pairs across a shared chain (two blocks' counts crossing it) pay it
#: too; False: only two chains in a row along a block side, where a block fans into the dense one.
#: Across, it shrank whole blocks: ``lake_with_islands(791302, n_islands=8, lobes=6)`` at 10 000
#: cells 8864 → 7776 cells (a 4.9 × 37.6 block 16 → 8 cells wide, its shore below its ``least``),
#: nodes within 3° 84.5 % off → 74.0 % (along only: 86.7 %); ``lake_with_islands(6)`` at 15 000
#: 83.9 → 73.5 % (along only: 80.5 %).  Against the cost across too, on fresh_sweep bases 768000
#: and 776000 (15 000 and 10 000 cells): within-3° means 98.37/97.75 → 98.32/97.79 (768000), the
#: shore distance of ``rough net 768204`` 0.79 → 0.19 cells.
STEEP_ACROSS = False


#: Equally good counts are common: a T-junction can slide along a block side over a few multiples
#: while both of its chains stay above (or below) their targets, and ``|n − t|`` adds up alike;
#: two sides' T-junctions can slide together.  HiGHS then returns whichever optimum its search meets
#: first, which its random seed, version or platform can change (held-out set 29 at 10 000 cells:
#: with ``random_seed`` 0–3, 12 of 131 programs gave two different optima, on 5 of 28 lakes; an
#: install with another scipy would get other grids).  So every pair of spacings that meet (the
#: pairs of :data:`JUMP`) also pays this per cell of their difference, however small (``JUMP`` = 1
#: at a thousandth of the weight): among otherwise equally good counts the cells along a side are
#: spread alike, a T-junction placed where its two chains' spacings agree ...
ALIKE = 1e-3
#: ... and every cell earns this (times ``1 + t / (10 max(t))``, ``t`` its chain's target,
#: :func:`tie_weights`): a hair more cells is better, a hair more on a longer chain, so that chains
#: of different lengths differ in weight and the optimum is one count vector unless the layout has
#: chains of exactly one length (a symmetric shape).  With both, each of those 131 programs had one
#: optimum for every seed.
TIE_BREAK = 1e-3


def tie_weights(t: np.ndarray) -> np.ndarray:
    """Per chain (``t``: the chains' targets), the cost of one of its cells that breaks ties
    (negative: more cells are a hair better, :data:`TIE_BREAK`)."""
    t = np.asarray(t, dtype=float)
    top = float(t.max()) if len(t) else 0.0
    return -TIE_BREAK * (1.0 + 0.1 * t / top) if top > 0 else np.full(len(t), -TIE_BREAK)


def _block_targets(t: np.ndarray, sides) -> np.ndarray:
    """Each block's wanted count per direction, order ``(b0 ξ, b0 η, b1 ξ, …)``: the mean of its
    two opposite sides' targets."""
    out = np.empty(2 * len(sides))
    for bi, (bottom, right, top, left) in enumerate(sides):
        for d, (a, b) in enumerate(((bottom, top), (left, right))):
            out[2 * bi + d] = 0.5 * (t[list(a)].sum() + t[list(b)].sum())
    return out


def _block_weights(t: np.ndarray, sides, area: bool = False) -> np.ndarray:
    """Weight of each block's ``|N − T|`` term per direction, order ``(b0 ξ, b0 η, b1 ξ, …)``: 1
    each, or with ``area`` in proportion to the block's cells in the other direction (its share
    of the grid whose cell size that count sets; ``T_other / mean T_other``, mean weight 1).

    Weighed alike, blocks in series (one count across them all) let a small block at a tapering
    end decide the count for the widest basin: a 10:1 ellipse got 0.47 × the asked cells, a lens
    with sharp ends 0.13 × (held-out GSHHG lakes of that shape 0.43 × and 0.47 ×).  Weighed by
    area on every layout, two of 27 generated hard shapes got folded cells (fresh_sweep ``--more``
    953000), so the layout asks for it only when the plain counts miss the cells by far
    (:data:`meshcore.layout.blocks.CELLS_FLOOR`)."""
    nb = len(sides)
    if not area or not nb:
        return np.ones(2 * nb)
    other = _block_targets(t, sides).reshape(-1, 2)[:, ::-1].reshape(-1)  # cells in the other direction
    other = np.maximum(other, 1e-9)
    return other / other.mean()


def _jump_pairs(
    t: np.ndarray, sides, least: float = 1.0
) -> tuple[list[tuple[list[int], float, list[int], float]], list[bool]]:
    """Pairs of cell densities (chains, target cells) whose ratio should stay near 1, and per pair
    whether it lies along a block side (the first kind below) or across a shared chain.

    * two chains in a row on one block side (they meet at a T-junction or where a cut ends on
      the side): the spacing along the side jumps there;
    * the two blocks beside a shared chain, across it: each block's count in the direction
      crossing the chain against the mean of that direction's two sides — the cells on the two
      sides of a cut line are as long, across it, as these say.
    """
    out: list[tuple[list[int], float, list[int], float]] = []
    across: dict[int, list[tuple[list[int], float]]] = {}
    short = np.maximum(t, least)  # a chain under ``least`` cells: as dense as its fewest cells make it
    for bottom, right, top, left in sides:
        for side in (bottom, right, top, left):
            for c1, c2 in itertools.pairwise(side):
                if SHORT_JUMPS:
                    out.append(([c1], float(short[c1]), [c2], float(short[c2])))
                elif t[c1] >= least and t[c2] >= least:
                    out.append(([c1], float(t[c1]), [c2], float(t[c2])))
        cross = {
            0: (list(left), 0.5 * (t[list(left)].sum() + t[list(right)].sum())),
            1: (list(bottom), 0.5 * (t[list(bottom)].sum() + t[list(top)].sum())),
        }
        for d, pair in enumerate(((bottom, top), (left, right))):
            for side in pair:
                for c in side:
                    across.setdefault(int(c), []).append(cross[d])
    along = [True] * len(out)
    for users in across.values():
        if len(users) == 2 and min(users[0][1], users[1][1]) >= least:
            (a, ta), (b, tb) = users
            out.append((a, float(ta), b, float(tb)))
            along.append(False)
    return out, along


def objective(
    t: np.ndarray,
    sides,
    jumps: list[tuple[list[int], float, list[int], float]],
    short,
    weights=None,
    steep_w=None,
    area_weights: bool = False,
):
    """The program's objective as a function of integer counts (rows: candidates that meet its
    constraints; returns one cost per row): each ``|.|`` and excess term of :func:`solve_counts`
    at its value, with ``jumps`` from :func:`_jump_pairs` and ``short`` the ``(chain, least)``
    pairs (``weights``: the cost per missing cell of each, default :data:`LEAST_WEIGHT`; ``steep_w``:
    each pair's :data:`STEEP_WEIGHT`, default that for every pair).  For
    :mod:`.countsearch`, which minimises it; the sums over chains are sparse matrices made once
    (a layout of 37 blocks: ~300 pairs; dense, a layout of 250 blocks spent a second on its zeros)."""
    from scipy.sparse import csr_array

    nc, nb, npair = len(t), len(sides), len(jumps)
    mean = _block_targets(t, sides)  # a block's count in each direction
    rows: list[int] = []
    cols: list[int] = []
    for bi, (bottom, _, _, left) in enumerate(sides):
        for d, a in enumerate((bottom, left)):
            rows += [2 * bi + d] * len(a)
            cols += [int(c) for c in a]
    across = csr_array((np.ones(len(rows)), (rows, cols)), shape=(2 * nb, nc))  # duplicates add up
    w = np.zeros(npair)
    d1: tuple[list[float], list[int], list[int]] = ([], [], [])
    d2: tuple[list[float], list[int], list[int]] = ([], [], [])
    for p, (ca, ta, cb, tb) in enumerate(jumps):
        for (v, r, c), chains, tt in ((d1, ca, ta), (d2, cb, tb)):
            v += [1.0 / tt] * len(chains)
            r += [p] * len(chains)
            c += [int(x) for x in chains]
        w[p] = min(ta, tb)
    dens1 = csr_array((d1[0], (d1[1], d1[2])), shape=(npair, nc))  # densities that meet
    dens2 = csr_array((d2[0], (d2[1], d2[2])), shape=(npair, nc))
    held = np.array([c for c, _ in short], dtype=int)
    want = np.array([v for _, v in short], dtype=float)
    per = np.full(len(short), LEAST_WEIGHT) if weights is None else np.asarray(weights, dtype=float)
    bw = _block_weights(t, sides, area_weights)
    tie = tie_weights(t)

    def cost(n: np.ndarray) -> np.ndarray:
        n = np.atleast_2d(n).astype(float)
        x1, x2 = (dens1 @ n.T).T, (dens2 @ n.T).T
        excess = np.maximum(0.0, w * np.maximum(x1 - JUMP * x2, x2 - JUMP * x1))
        steep = np.maximum(0.0, w * np.maximum(x1 - STEEP * x2, x2 - STEEP * x1))
        return (
            n @ tie
            + 0.25 * np.abs(n - t).sum(axis=1)
            + (bw * np.abs((across @ n.T).T - mean)).sum(axis=1)
            + JUMP_WEIGHT * excess.sum(axis=1)
            + ALIKE * (w * np.abs(x1 - x2)).sum(axis=1)
            + (steep * (STEEP_WEIGHT if steep_w is None else steep_w)).sum(axis=1)
            + (per * np.maximum(0.0, want - n[:, held])).sum(axis=1)
        )

    return cost


def solve_counts(
    targets: Sequence[float] | np.ndarray,
    sides: Sequence[Sequence[Sequence[int]]],
    *,
    min_cells: int = 3,
    multiple: int = 1,
    fixed: dict[int, int] | None = None,
    block_cells: dict[int, tuple[int, int]] | None = None,
    best: bool = True,
    least: Sequence[float] | np.ndarray | None = None,
    least_weight: Sequence[float] | np.ndarray | None = None,
    equal: np.ndarray | None = None,
    area_weights: bool = False,
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
    best : bool
        False: any counts that satisfy the constraints, not the closest (whether counts
        exist at all; a hundred times faster on layouts of a hundred blocks).
    least : sequence of float, optional
        Per chain, the count below which it pays :data:`LEAST_WEIGHT` per missing cell (a
        shore chain that the coarse levels would cut across, :mod:`.shorecells`); a soft
        bound, so counts fixed by the user still have a solution.
    least_weight : sequence of float, optional
        Per chain, that cost per missing cell instead (:data:`LAND_WEIGHT` where the coarse
        chords would cross an island, :func:`~.shorecells.least_weights`).
    equal : (m, chains) array, optional
        Rows ``A`` with ``A @ counts = 0`` required as well: the rings of
        :func:`~.closure.closure_rows` (one index space).
    area_weights : bool
        Each block's count in a direction weighs by its cells in the other
        (:func:`_block_weights`); False: every block alike.

    Raises
    ------
    TopologyError
        When no integer solution exists (e.g. fixed counts that contradict each other).
    """
    from .countsearch import best_counts

    t = np.asarray(targets, dtype=float)
    n = len(t)
    nb = len(sides)
    m = int(multiple)
    jumps, along = _jump_pairs(t, sides, least=float(max(m, 1)))
    steep_w = np.array([STEEP_WEIGHT if STEEP_ACROSS or a else 0.0 for a in along])
    short = [] if least is None else [(c, float(v)) for c, v in enumerate(least) if v > m]
    weights = np.array(
        [LEAST_WEIGHT if least_weight is None else float(least_weight[c]) for c, _ in short], dtype=float
    )
    weights += STEEP_WEIGHT  # a shortfall stays above every other term: a steep jump's cell costs JUMP + STEEP
    for given in (fixed or {}).values():
        if given % m:
            raise TopologyError(f"a fixed count {given} is not a multiple of {m}")
    if equal is not None and not len(equal):
        equal = None
    if SEARCH and block_cells and len(block_cells) == nb and equal is None:  # few solutions: the best of them, no HiGHS
        search_cost = (
            objective(t, sides, jumps, short, weights, steep_w, area_weights)
            if best
            else (lambda counts: np.zeros(len(counts)))
        )
        found = best_counts(
            n, sides, multiple=m, min_cells=min_cells, block_cells=block_cells, cost=search_cost, fixed=fixed
        )
        if found is not None:
            return found
    from scipy.optimize import LinearConstraint, milp

    # unknowns: k_c (n_c = m k_c); e_c ≥ |n_c − t_c| per chain; f_bd ≥ |N_bd − T_bd| per block and
    # direction, with N_bd the count across the block in that direction and T_bd the mean of its
    # two opposite sides' targets: every block's cells close to the asked size in both directions
    # (so neighbours' cells are alike across interfaces), chains close to theirs within a side;
    # g_p ≥ 0 per pair of spacings that meet (see _jump_pairs), the cells by which one exceeds
    # JUMP times the other
    # h_q ≥ 0 per chain with a ``least`` count, the cells it falls short of it
    nj, ns = len(jumps), len(short)
    paid = {int(p): k for k, p in enumerate(np.flatnonzero(steep_w))}  # ... and s_p ≥ 0 per pair that pays
    nst = len(paid)  # for the cells beyond STEEP times (STEEP_WEIGHT, STEEP_ACROSS)
    nv = 2 * n + 2 * nb + nj + ns + nst + nj  # (last: q_p ≥ |difference| of each pair, ALIKE)
    cost = np.concatenate(
        [
            m * tie_weights(t),
            np.full(n, 0.25),
            _block_weights(t, sides, area_weights),
            np.full(len(jumps), JUMP_WEIGHT),
            weights,
            steep_w[steep_w > 0],
            np.full(nj, ALIKE),
        ]
    )
    rows: list[dict[int, float]] = []  # sparse: {unknown: coefficient} per row
    lo: list[float] = []
    hi: list[float] = []

    def row() -> dict[int, float]:
        return defaultdict(float)

    def add(r: dict[int, float], low: float, high: float) -> None:
        rows.append(r)
        lo.append(low)
        hi.append(high)

    def absdev(dev_index: int, chains, target: float) -> None:
        for sign in (1.0, -1.0):  # dev ± Σ m k ≥ ± target
            r = row()
            r[dev_index] = 1.0
            for c in chains:
                r[c] += sign * m
            add(r, sign * target, np.inf)
        lo_k, frac = divmod(target / m, 1.0)
        if HULL_CUTS and best and frac > 0.0:  # dev ≥ m (frac + (1 − 2 frac)(Σ k − lo_k)): the hull
            r = row()
            r[dev_index] = 1.0
            for c in chains:
                r[c] -= m * (1.0 - 2.0 * frac)
            add(r, m * (frac - (1.0 - 2.0 * frac) * lo_k), np.inf)

    for c in range(n):
        absdev(n + c, [c], t[c])
    wanted = _block_targets(t, sides)
    for bi, (bottom, right, top, left) in enumerate(sides):
        for d, (a, b) in enumerate(((bottom, top), (left, right))):
            r = row()
            for c in a:
                r[c] += m
            for c in b:
                r[c] -= m
            add(r, 0.0, 0.0)
            absdev(2 * n + 2 * bi + d, list(a), wanted[2 * bi + d])
        for side in (bottom, right, top, left):
            r = row()
            for c in side:
                r[c] += m
            add(r, float(min_cells), np.inf)
        if block_cells and bi in block_cells:
            for side, want in ((bottom, block_cells[bi][0]), (left, block_cells[bi][1])):
                r = row()
                for c in side:
                    r[c] += m
                add(r, float(want), float(want))
    for a in () if equal is None else equal:  # Σ a_c n_c = 0, i.e. Σ a_c k_c = 0
        add({int(c): float(a[c]) for c in np.flatnonzero(a)}, 0.0, 0.0)
    for p, (ca, ta, cb, tb) in enumerate(jumps):
        w = min(ta, tb)
        for (c1, t1), (c2, t2) in (((ca, ta), (cb, tb)), ((cb, tb), (ca, ta))):
            # g ≥ w (N1/T1 − JUMP N2/T2), q ≥ w (N1/T1 − N2/T2), and for a pair that pays,
            # s ≥ w (N1/T1 − STEEP N2/T2)
            excess = [(2 * n + 2 * nb + p, JUMP), (2 * n + 2 * nb + nj + ns + nst + p, 1.0)]
            if p in paid:
                excess.append((2 * n + 2 * nb + nj + ns + paid[p], STEEP))
            for var, factor in excess:
                r = row()
                r[var] = 1.0
                for c in c1:
                    r[c] -= w * m / t1
                for c in c2:
                    r[c] += factor * w * m / t2
                add(r, 0.0, np.inf)
    for q, (c, v) in enumerate(short):
        r = row()  # h ≥ least − n_c
        r[2 * n + 2 * nb + len(jumps) + q] = 1.0
        r[c] = m
        add(r, v, np.inf)
        lo_k, frac = divmod(v / m, 1.0)
        if HULL_CUTS and best and frac > 0.0:  # h ≥ m frac (lo_k + 1 − k): the hull of the integer points
            r = row()
            r[2 * n + 2 * nb + len(jumps) + q] = 1.0
            r[c] = m * frac
            add(r, m * frac * (lo_k + 1.0), np.inf)
    lb = np.concatenate([np.ones(n), np.zeros(nv - n)])
    ub = np.full(nv, np.inf)
    for c, v in (fixed or {}).items():
        lb[c] = ub[c] = v // m
    from scipy.optimize import Bounds
    from scipy.sparse import csr_array

    matrix = csr_array(
        (
            [v for r in rows for v in r.values()],
            ([i for i, r in enumerate(rows) for _ in r], [j for r in rows for j in r]),
        ),
        shape=(len(rows), nv),
    )
    res = milp(
        cost if best else np.zeros(nv),
        constraints=LinearConstraint(matrix, lo, hi),
        integrality=np.concatenate([np.ones(n), np.zeros(nv - n)]),
        bounds=Bounds(lb, ub),
        options={"time_limit": TIME_LIMIT, "mip_rel_gap": 0.0},
    )
    if res.x is None or res.status not in (0, 1):
        raise TopologyError(f"no integer cell counts satisfy the block sides ({res.message})")
    return (np.rint(res.x[:n]).astype(int) * m).astype(int)
