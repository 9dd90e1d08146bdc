r"""Grid sequencing: solve on a coarse copy of the layout, refine, solve again.

The orthogonal smoother is a Gauss–Seidel iteration: it removes local errors in a few sweeps
but needs thousands to move nodes along a 30-km shore.  Those slow, smooth errors are
resolved cheaply on a coarse grid — the same blocks with half (or a quarter of) the cells —
and carried to the fine grid by :func:`refine`, where a few sweeps remove what the
interpolation left.  Cell counts must be multiples of ``2**levels`` (the layout's integer
program arranges that).
"""

from __future__ import annotations

import numpy as np

from ..multiblock.topology import Block, Interface, MultiBlockTopology, Side
from .shore import arc_lengths, project_to_rings, ring_point

__all__ = ["coarsen_topology", "refine"]


def _refine_grid(x: np.ndarray) -> np.ndarray:
    """Bilinear refinement in index space: ``(n+1, m+1)`` nodes → ``(2n+1, 2m+1)``."""
    n, m = x.shape
    out = np.empty((2 * n - 1, 2 * m - 1))
    out[::2, ::2] = x
    out[1::2, ::2] = 0.5 * (x[:-1] + x[1:])
    out[::2, 1::2] = 0.5 * (x[:, :-1] + x[:, 1:])
    out[1::2, 1::2] = 0.25 * (x[:-1, :-1] + x[1:, :-1] + x[:-1, 1:] + x[1:, 1:])
    return out


def refine(grids) -> list:
    """Every block grid refined twice in each direction (interface nodes stay shared:
    the midpoint of a shared edge is computed the same way from either side)."""
    return [g.replaced(x=_refine_grid(g.x), y=_refine_grid(g.y)) for g in grids]


def coarsen_topology(topology: MultiBlockTopology, factor: int) -> MultiBlockTopology:
    """The topology with every block's borders sub-sampled by ``factor`` (cells divisible by it)."""
    blocks = []
    for b in topology.blocks:
        ni, nj = b.cells
        if ni % factor or nj % factor:
            raise ValueError(f"block {b.name!r}: cells {ni}×{nj} are not multiples of {factor}")
        bd = b.borders
        sub = type(bd)(
            bottom=bd.bottom[::factor].copy(),
            right=bd.right[::factor].copy(),
            top=bd.top[::factor].copy(),
            left=bd.left[::factor].copy(),
        )
        blocks.append(Block(b.name, sub, initial=b.initial, weights=b.weights, names=dict(b.names)))
    itfs = []
    for itf in topology.interfaces:
        sides = []
        for s in (itf.a, itf.b):
            if s.start % factor or s.stop % factor:
                raise ValueError(f"interface side {s.label} is not a multiple of {factor}")
            sides.append(Side(s.block, s.border, s.start // factor, s.stop // factor))
        itfs.append(Interface(sides[0], sides[1], itf.reversed))
    return MultiBlockTopology(tuple(blocks), tuple(itfs), check_geometry=False)


def refine_shore(grids, topology: MultiBlockTopology, rings: list[np.ndarray]) -> list:
    """After :func:`refine`, put every new shore node on the shore, halfway along it between
    its two neighbours (the straight midpoint would cut across every bay the coarse edge
    spanned, and the nearest shore point would be at its mouth); where that alone would make a
    cell non-convex, with the new nodes inwards of it carried along (:func:`_carried_to`)."""
    if not rings:
        return list(grids)
    m = topology.node_map
    per = [float(np.hypot(*(np.roll(r, -1, axis=0) - r).T).sum()) for r in rings]
    xs = [np.array(g.x) for g in grids]
    ys = [np.array(g.y) for g in grids]
    where, ends = [], []  # (block, index of the new node, its column inwards), its two neighbours
    for b, ids in enumerate(m.ids):
        n1, m1 = ids.shape
        for fixed_i, fixed_j in ((None, 0), (None, m1 - 1), (0, None), (n1 - 1, None)):
            count = n1 if fixed_i is None else m1
            for k in range(1, count - 1, 2):
                idx = [(t, fixed_j) if fixed_i is None else (fixed_i, t) for t in (k - 1, k, k + 1)]
                if all(m.boundary[ids[ij]] for ij in idx):
                    where.append((b, idx[1], _column(ids.shape, idx[1], fixed_i, fixed_j)))
                    ends.append([xs[b][idx[0]], ys[b][idx[0]], xs[b][idx[2]], ys[b][idx[2]]])
    if not where:
        return list(grids)
    ends_a = np.asarray(ends)
    n = len(ends_a)
    r12, s12, _ = project_to_rings(rings, np.vstack([ends_a[:, :2], ends_a[:, 2:]]))  # one tree for both ends
    ra, sa, rb, sb = r12[:n], s12[:n], r12[n:], s12[n:]
    cums = [arc_lengths(r) for r in rings]  # once per ring, not per node
    for (b, ij, col), r1, s1, r2, s2 in zip(where, ra, sa, rb, sb, strict=True):
        if r1 != r2:
            continue
        total = per[r1]
        d = (s2 - s1) % total
        if d > total / 2:  # the short way round
            d -= total
        # halfway along the shore, else elsewhere on the shore between the two (a sharp bend
        # of the shore between them can leave no convex cell at halfway), each with the new
        # nodes inwards of it carried along, else towards halfway
        at = ring_point(rings[r1], s1 + d * np.array([0.5, 0.35, 0.65, 0.2, 0.8, 0.1, 0.9]), cums[r1])
        if not any(_moved_to(xs[b], ys[b], ij, p) for p in at) and not any(
            _carried_to(xs[b], ys[b], ij, col, p) for p in at
        ):
            _move_if_valid(xs[b], ys[b], ij, at[0])
    return [g.replaced(x=x, y=y) for g, x, y in zip(grids, xs, ys, strict=True)]


def _convex_around(x: np.ndarray, y: np.ndarray, ij) -> bool:
    """True when every cell of the block that has node ``ij`` as a corner is convex."""
    i, j = ij
    n1, m1 = x.shape
    for ci in (i - 1, i):
        for cj in (j - 1, j):
            if not (0 <= ci < n1 - 1 and 0 <= cj < m1 - 1):
                continue
            px = [x[ci, cj], x[ci + 1, cj], x[ci + 1, cj + 1], x[ci, cj + 1]]
            py = [y[ci, cj], y[ci + 1, cj], y[ci + 1, cj + 1], y[ci, cj + 1]]
            for k in range(4):
                ax, ay = px[(k + 1) % 4] - px[k], py[(k + 1) % 4] - py[k]
                bx, by = px[(k + 3) % 4] - px[k], py[(k + 3) % 4] - py[k]
                if ax * by - ay * bx <= 0.0:
                    return False
    return True


def _moved_to(x: np.ndarray, y: np.ndarray, ij, p: np.ndarray) -> bool:
    """Move node ``ij`` to ``p`` if its cells stay convex there; True if it moved."""
    ox, oy = x[ij], y[ij]
    x[ij], y[ij] = p[0], p[1]
    if _convex_around(x, y, ij):
        return True
    x[ij], y[ij] = ox, oy
    return False


#: New nodes inwards of a new shore node that :func:`_carried_to` moves with it: the new
#: nodes of the coarse cell whose edge cut across the shore and of the next one (measured only
#: at this value, on generated lakes with islands: ``tests/meshcore/test_shore_fit.py``).
CARRY = 3


def _column(shape: tuple[int, int], ij, fixed_i, fixed_j) -> list[tuple[int, int]]:
    """Up to :data:`CARRY` nodes inwards of the new shore node ``ij`` along its grid line, short of
    the block's other borders (the line of a new node holds new nodes only: they were interpolated,
    not solved, and no other block shares them)."""
    n1, m1 = shape
    i, j = ij
    if fixed_i is None:
        step = 1 if fixed_j == 0 else -1
        return [(i, j + step * t) for t in range(1, CARRY + 1) if 0 < j + step * t < m1 - 1]
    step = 1 if fixed_i == 0 else -1
    return [(i + step * t, j) for t in range(1, CARRY + 1) if 0 < i + step * t < n1 - 1]


def _carried_to(x: np.ndarray, y: np.ndarray, ij, col: list, p: np.ndarray) -> bool:
    """Move node ``ij`` to ``p`` and the ``k`` nodes ``col`` inwards of it by a share of the same
    move that falls off along the line (``1 - t / (k + 1)`` for the ``t``-th); True if every
    cell around them stays convex, else nothing moves.  Where the coarse edge cut across a bulge of the shore the row
    inside is closer to the shore than the move, and moving the shore node alone folds a cell."""
    ox, oy = x[ij], y[ij]
    dx, dy = p[0] - ox, p[1] - oy
    nodes = [ij, *col]
    old = [(x[n], y[n]) for n in nodes]
    for t, n in enumerate(nodes):
        w = 1.0 - t / len(nodes)
        x[n], y[n] = old[t][0] + w * dx, old[t][1] + w * dy
    if all(_convex_around(x, y, n) for n in nodes):
        return True
    for n, (a, c) in zip(nodes, old, strict=True):
        x[n], y[n] = a, c
    return False


def _move_if_valid(x: np.ndarray, y: np.ndarray, ij, p: np.ndarray) -> None:
    """Move node ``ij`` to ``p``, or as far towards it as keeps its cells convex."""
    ox, oy = x[ij], y[ij]
    for f in (1.0, 0.5, 0.25):
        x[ij], y[ij] = ox + f * (p[0] - ox), oy + f * (p[1] - oy)
        if _convex_around(x, y, ij):
            return
    x[ij], y[ij] = ox, oy
