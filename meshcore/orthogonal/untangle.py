r"""Untangling across interfaces: make the cells at cut ends convex by moving interface nodes.

The fold-free repair of :mod:`meshcore.foldfree` works on one block with its borders fixed.  A
cell at a block's corner whose corner node is a cut line's end on the shore cannot be repaired
that way: its other corners are a shore node, an interface node and an interior node.  Where a
cut leaves a reflex shore corner, the coarse start solve (Winslow over all blocks as one grid)
can move the cut's first interface nodes so that one of the two angles at the corner opens
beyond 180°, although the layout drew both below it.  The orthogonal smoother keeps valid cells
valid and lets invalid ones only improve, but does not seek that: such a cell stayed non-convex
through every level (one cell in 4 of 45 generated lakes of fresh seeds at 15 000 cells).

:func:`untangle`, for every non-convex cell:

1. if one of its corners is a cut's end on the shore (a shore node of three or more cells) and
   ``layout`` grids are given (the blocks' algebraic grids: their borders are the layout's cut
   lines), puts the interface nodes within :data:`HOPS` edges of that end back towards the
   layout's line — fully at the end, blending into the solved position further along — and
   repairs the blocks then invalid with their borders fixed (:func:`meshcore.foldfree.repair`);
2. given the shore rings, slides each block corner or cut end on the shore whose angle in a bad
   cell only shore nodes make (a block corner on a notch of a rough shore, where the water turns
   beyond 180°: its one cell of that block is non-convex whatever the free nodes do) along the
   shore to the nearest place where every cell around it is convex (:func:`_slide_shore_nodes`;
   after step 3, any block corner or cut end of a cell it left bad, then step 3 again);
3. then moves, one at a time, each free node (not on the shore) of each cell still bad: to the
   nearest of a few candidate positions around it (rings of 16 points at ¼, ½ and 1 of its mean
   edge length, the mean of its edge neighbours) where every cell around it is convex with a
   margin; where there is none, to the candidate that raises the smallest corner Jacobian most
   without making another cell around it bad, and its free neighbours get their turn next round.

Nodes of cells that are convex are not moved by steps 2 and 3; a grid without bad cells comes back as
it is.
"""

from __future__ import annotations

import numpy as np

__all__ = ["bad_cells", "untangle"]

#: A corner Jacobian counts as convex above this share of the mean area of the node's cells (the
#: orthogonal smoother's guard floor is a thousandth; a margin above it lets its sweeps move the
#: node again).
MARGIN = 0.02
#: Rounds of single-node moves (each over the free nodes of the cells still bad, then their
#: neighbours).
ROUNDS = 12
#: Candidate positions of a node: rings at these multiples of its mean edge length, 16 points each.
RADII = (0.25, 0.5, 1.0)
#: Interface nodes put back on the layout's cut line near a cut end: those within this many edges
#: of it (weight of the solved position ``(d - 1) / HOPS`` at ``d`` edges).
HOPS = 3


_NEXT, _PREV = np.array([1, 2, 3, 0]), np.array([3, 0, 1, 2])  # np.roll(·, -1) and np.roll(·, 1) along a row


def _corner_jacobians(X, Y, cells) -> np.ndarray:
    """``(n, 4)`` corner Jacobians of the CCW cells ``cells`` (ids into X, Y)."""
    px, py = X[cells], Y[cells]
    nx, ny = px[:, _NEXT], py[:, _NEXT]  # (called tens of thousands of times on a few cells:
    mx, my = px[:, _PREV], py[:, _PREV]  # np.roll's own cost was most of it)
    return (nx - px) * (my - py) - (ny - py) * (mx - px)


def bad_cells(X, Y, cells) -> np.ndarray:
    """Indices of cells with a corner Jacobian ``≤ 0`` (folded or non-convex)."""
    return np.flatnonzero((_corner_jacobians(X, Y, cells) <= 0).any(axis=1))


def _score(X, Y, cells, around, area: float | None = None) -> tuple[int, float]:
    """``(-bad, worst)`` of the cells ``around``: how many are bad (negated), and their smallest
    corner Jacobian over ``area`` (a corner Jacobian of a parallelogram is its area; default:
    the cells' mean absolute area).  Larger is better, compared as a tuple.

    Compare the candidate positions of a node with one fixed ``area`` (:func:`_star_area`): with
    the cells' own mean absolute area a node taken far out of its star made its cells huge
    slivers whose worst corner over their mean area came out *better*, and each round of moves
    went a mean edge length further (``headlands(745600, n=6)`` at 15 000 cells: a block 686 611
    long in a lake 20 across, 25 folded cells)."""
    j = _corner_jacobians(X, Y, cells[around])
    if area is None:
        area = float(np.abs(j.sum(axis=1) / 4).mean())
    return -int((j <= 0).any(axis=1).sum()), float(j.min() / max(area, 1e-300))


def _star_area(X, Y, cells, around) -> float:
    """Mean signed area of the cells ``around`` a free node: the area of the polygon of their
    other corners over their number, whatever the node's position (:func:`_score`'s scale)."""
    j = _corner_jacobians(X, Y, cells[around])
    return abs(float(j.sum())) / 4 / max(len(around), 1)


class _Mesh:
    """The node arrays of a multiblock grid and the incidence tables :func:`untangle` needs."""

    def __init__(self, topology, grids):
        from .driver import _assemble

        m = self.m = topology.node_map
        self.cells = m.cells.astype(np.int64)
        self.X, self.Y = _assemble(grids, m)
        flat = self.cells.reshape(-1)
        order = np.argsort(flat, kind="stable")
        self.cnt = np.bincount(flat, minlength=m.n_nodes)
        self.ptr = np.concatenate([[0], np.cumsum(self.cnt)])
        self.rows = order // 4  # node n's cells: rows[ptr[n]:ptr[n + 1]] of `cells`
        # edge neighbours of every node, ascending (CSR: nbr[nptr[n]:nptr[n + 1]])
        n_all = np.int64(m.n_nodes)
        u, v = flat, np.roll(self.cells, -1, axis=1).reshape(-1)
        a, b = np.divmod(np.unique(np.minimum(u, v) * n_all + np.maximum(u, v)), n_all)
        src, dst = np.concatenate([a, b]), np.concatenate([b, a])
        order = np.lexsort((dst, src))
        self.nbr = dst[order]
        self.nptr = np.concatenate([[0], np.cumsum(np.bincount(src, minlength=m.n_nodes))])

    def nbrs(self, n: int) -> list[int]:
        """The nodes one edge from node ``n``, ascending."""
        return [int(v) for v in self.nbr[self.nptr[n] : self.nptr[n + 1]]]

    def around(self, n: int) -> np.ndarray:
        return self.rows[self.ptr[n] : self.ptr[n + 1]]

    def grids(self, grids) -> list:
        return [g.replaced(x=self.X[ids], y=self.Y[ids]) for g, ids in zip(grids, self.m.ids, strict=True)]


def _restore_cut_ends(mesh: _Mesh, grids, layout, bad) -> tuple[list, int]:
    """Step 1 of :func:`untangle`; returns the grids and how many nodes moved."""
    from ..foldfree import invalid_cells, repair
    from .driver import _assemble

    m = mesh.m
    LX, LY = _assemble(layout, m)
    ends = {int(n) for n in mesh.cells[bad].reshape(-1) if m.boundary[n] and mesh.cnt[n] >= 3}
    moved = 0
    for end in sorted(ends):
        # the interface nodes near the end, by edges along shared nodes (the cut lines)
        dist = {end: 0}
        front = [end]
        for d in range(1, HOPS + 1):
            nxt = []
            for u in front:
                for v in mesh.nbrs(u):
                    if v not in dist and m.shared[v] and not m.boundary[v]:
                        dist[v] = d
                        nxt.append(v)
            front = nxt
        for v, d in dist.items():
            if d:
                w = (d - 1) / HOPS
                mesh.X[v] = LX[v] + w * (mesh.X[v] - LX[v])
                mesh.Y[v] = LY[v] + w * (mesh.Y[v] - LY[v])
                moved += 1
    if not moved:
        return list(grids), 0
    out = []
    for g in mesh.grids(grids):
        if invalid_cells(np.asarray(g.x, dtype=float), np.asarray(g.y, dtype=float)).any():
            g = repair(g, strict=False).grid
        out.append(g)
    return out, moved


def _move_nodes(mesh: _Mesh) -> int:
    """Step 3 of :func:`untangle`: single-node moves; returns how many were made."""
    m, X, Y, cells = mesh.m, mesh.X, mesh.Y, mesh.cells
    ang = np.linspace(0.0, 2 * np.pi, 16, endpoint=False)
    ring = np.column_stack([np.cos(ang), np.sin(ang)])
    moved = 0
    todo: set[int] = set()
    for _ in range(ROUNDS):
        bad = bad_cells(X, Y, cells)
        if not len(bad):
            break
        nodes = {int(n) for n in cells[bad].reshape(-1) if not m.boundary[n]} | todo
        todo = set()
        for n in sorted(nodes):
            around = mesh.around(n)
            area = _star_area(X, Y, cells, around)
            now = _score(X, Y, cells, around, area)
            nb = mesh.nbrs(n)
            if (now[0] == 0 and now[1] > MARGIN) or not nb:
                continue
            p = np.array([X[n], Y[n]])
            q = np.column_stack([X[nb], Y[nb]])
            length = float(np.hypot(*(q - p).T).mean())
            cand = [q.mean(axis=0)] + [p + r * length * ring[k] for r in RADII for k in range(len(ring))]
            best, best_p, ok = now, None, []
            for c in cand:
                X[n], Y[n] = c
                s = _score(X, Y, cells, around, area)
                if s[0] == 0 and s[1] > MARGIN:
                    ok.append((float(np.hypot(*(c - p))), c))
                if s > best:
                    best, best_p = s, c
            if ok:
                X[n], Y[n] = min(ok, key=lambda t: t[0])[1]
                moved += 1
            elif best_p is not None:
                X[n], Y[n] = best_p
                moved += 1
                todo |= {v for v in nb if not m.boundary[v]}
            else:
                X[n], Y[n] = p
    return moved


#: How far (times its mean edge length) :func:`_slide_shore_nodes` looks along the shore, either way.
SLIDE = 1.5


def _slide_shore_nodes(mesh: _Mesh, rings, only_fixed: bool = True) -> int:
    """Step 2 of :func:`untangle`: every block corner or cut end on the shore (a shore node of one,
    three or more cells) whose angle in a bad cell is made by shore nodes only (its two neighbours
    in the cell are on the shore too) moved along its shore ring to the
    nearest place (within :data:`SLIDE` of its mean edge length either way) where every cell
    around it is convex; returns how many moved.  A block corner or a cut end the layout put on a
    notch of a rough shore, where the water turns beyond 180°, leaves its one cell of that block
    non-convex, and no move of the free nodes can mend that: the other corners of the cell would
    have to go onto land.  ``only_fixed`` False: every block corner or cut end of a bad cell
    (after step 3, for the cells it left bad)."""
    from .shore import arc_lengths, project_to_rings, ring_point

    m, X, Y, cells = mesh.m, mesh.X, mesh.Y, mesh.cells
    bad = cells[bad_cells(X, Y, cells)]
    j = _corner_jacobians(X, Y, bad)
    b = m.boundary[bad]
    # corners whose angle only shore nodes make: the node and its two neighbours in the cell
    fixed = (j <= 0) & b & np.roll(b, 1, axis=1) & np.roll(b, -1, axis=1) if only_fixed else b
    # block corners and cut ends only (the shore sweep holds them; a node along a block's side
    # slides in the sweeps and has free neighbours inwards): slid along a one-cell-wide coarse
    # block's sides they changed the whole block (``dendritic(911700)``: 0 -> 5 folded cells)
    nodes = sorted({int(n) for n in bad[fixed] if mesh.cnt[n] != 2})
    if not nodes or not rings:
        return 0
    r_of, s_of, _ = project_to_rings(rings, np.column_stack([X[nodes], Y[nodes]]))
    steps = np.linspace(-SLIDE, SLIDE, 30 * int(SLIDE) + 1)
    steps = steps[np.argsort(np.abs(steps), kind="stable")][1:]  # nearest first, not 0
    moved = 0
    for n, r, s in zip(nodes, r_of, s_of, strict=True):
        around = mesh.around(n)
        if _score(X, Y, cells, around)[0] == 0:
            continue
        nb = mesh.nbrs(n)
        p = np.array([X[n], Y[n]])
        length = float(np.hypot(X[nb] - p[0], Y[nb] - p[1]).mean())
        for c in ring_point(rings[int(r)], s + length * steps, arc_lengths(rings[int(r)])):
            X[n], Y[n] = c
            if _score(X, Y, cells, around)[0] == 0:
                moved += 1
                break
        else:
            X[n], Y[n] = p
    return moved


def untangle(topology, grids, layout=None, rings=None) -> tuple[list, int]:
    """``(grids, moved)``: ``grids`` (one per block of ``topology``) with the free nodes around
    their non-convex cells moved until those cells are convex, where the steps of the module
    docstring can; ``layout``: the blocks' algebraic grids (their borders are the layout's lines).
    ``moved`` counts the node moves made.  Shore nodes move only when ``rings`` (the shore rings)
    are given, along them (step 2)."""
    from .driver import _assemble

    X, Y = _assemble(grids, topology.node_map)
    if not len(bad_cells(X, Y, topology.node_map.cells)):  # the usual case: no tables needed
        return list(grids), 0
    mesh = _Mesh(topology, grids)
    bad = bad_cells(mesh.X, mesh.Y, mesh.cells)
    moved = 0
    if layout is not None:
        grids, moved = _restore_cut_ends(mesh, grids, layout, bad)
        mesh = _Mesh(topology, grids)
    if rings:
        moved += _slide_shore_nodes(mesh, rings)
    moved += _move_nodes(mesh)
    if rings and len(bad_cells(mesh.X, mesh.Y, mesh.cells)):
        n = _slide_shore_nodes(mesh, rings, only_fixed=False)
        moved += n + (_move_nodes(mesh) if n else 0)
    return mesh.grids(grids), moved
