r"""The blocks of a multiblock grid placed in ONE ``(I, J)`` index space.

A single-domain model grid (a Delft3D ``.grd`` with inactive points, EFDC's
``cell.inp``) is one logical rectangle of nodes, some of them inactive.  A
multiblock grid fits in one when every block can be given an offset and one of
the 8 orientations of its index space (quarter turns, mirrored or not) so that

* blocks that share an interface are neighbours in ``(I, J)`` and their shared
  nodes fall on the same index node;
* no two blocks claim the same cell, and a node two blocks reach lies at one
  place (blocks that are apart in the water are apart in the index space);
* every cycle of blocks closes: the blocks round an island come back to the
  same offset and orientation.

:func:`embed` finds the placement by a breadth-first walk over the blocks
through their interfaces.  The interfaces are the runs of border nodes that two
blocks share (:func:`meshcore.io.delft3d_dd.find_couplings`: whole or partial
borders, so T-junctions are fine).  Crossing an interface fixes the neighbour's
placement: its border's direction goes where the first block's border goes (or
the opposite way for a reversed run) and its inside lies on the far side of the
line, so the 2 × 2 matrix ``R_b`` is ``[s R_a t_a, −R_a n_a] · [t_b, n_b]ᵀ``
(``t`` a border's direction, ``n`` its inward normal in the block's own index
space, ``s = −1`` for a reversed run) and the offset makes the first shared
node coincide.

Where it cannot — a corner where 3 or 5 blocks meet inside the water (4 cells
round every inner index node), a ring of blocks round an island whose index
directions come back turned or whose cell counts do not add up, or a layout
whose arms fold back onto each other in index space — :class:`EmbeddingError`
names the blocks and the interface.  The regular layouts (``meshcore mesh
--regular``, made for Delft3D domain decomposition) have no 3- or 5-block
corners; docs/lake-grids.md says how often they embed.

Blocks that share no interface (water in several parts) are placed side by
side along ``I``, ``gap`` inactive node columns apart.  The result is oriented
so that the index space is right-handed (``J`` to the left of ``I``), as both
Delft3D and EFDC expect.

Example
-------
>>> import numpy as np
>>> from meshcore.grid import StructuredGrid
>>> xs = np.linspace(0, 1, 3)
>>> a = StructuredGrid(*np.meshgrid(xs, xs, indexing="ij"))
>>> b = StructuredGrid(*np.meshgrid(xs + 1, xs, indexing="ij")).transposed()  # turned a quarter
>>> space = embed([a, b], ["a", "b"])
>>> space.shape, int((space.owner >= 0).sum())
((5, 3), 8)
>>> bool(np.allclose(space.x[:, 0], [0, 0.5, 1, 1.5, 2]))
True
"""

from __future__ import annotations

from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..errors import TopologyError
from ..grid import StructuredGrid

__all__ = ["EmbeddingError", "IndexSpace", "Placement", "embed", "from_mask"]

#: Nodes closer than this fraction of the domain's size are one node.
RTOL = 1e-7


class EmbeddingError(TopologyError):
    """The blocks cannot be placed in one index space; the message names the blocks."""


@dataclass(frozen=True, slots=True)
class Placement:
    """Block node ``(i, j)`` sits at index node ``R @ (i, j) + offset``."""

    rotation: tuple[tuple[int, int], tuple[int, int]]
    offset: tuple[int, int]

    def apply(self, i: np.ndarray, j: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        (a, b), (c, d) = self.rotation
        return a * i + b * j + self.offset[0], c * i + d * j + self.offset[1]

    @property
    def mirrored(self) -> bool:
        (a, b), (c, d) = self.rotation
        return a * d - b * c < 0


@dataclass(frozen=True, slots=True, eq=False)
class IndexSpace:
    """The merged grid: node coordinates (NaN where no block has a node) and cell owners.

    ``x, y`` have shape ``shape`` (index nodes); ``owner[I, J]`` is the block of
    cell ``(I, J)`` (nodes ``I…I+1``, ``J…J+1``), −1 for a cell no block has
    (land, or the water round which a ring of blocks closes).
    """

    x: np.ndarray
    y: np.ndarray
    owner: np.ndarray
    placements: tuple[Placement, ...]
    names: tuple[str, ...]
    n_components: int

    @property
    def shape(self) -> tuple[int, int]:
        return self.x.shape  # type: ignore[return-value]

    @property
    def active_nodes(self) -> np.ndarray:
        return np.isfinite(self.x)

    @property
    def water(self) -> np.ndarray:
        """Cells that belong to a block."""
        return self.owner >= 0

    def block(self, k: int) -> StructuredGrid:
        """Block ``k`` as a grid in its own index directions (the inverse of its placement)."""
        cells = np.argwhere(self.owner == k)
        if not len(cells):
            raise ValueError(f"block {k} has no cells in the index space")
        p = self.placements[k]
        R = np.array(p.rotation)
        box = np.array(cells.max(axis=0) - cells.min(axis=0) + 1)  # cells along I, J
        ni, nj = (int(v) for v in np.abs(R.T) @ box)
        ii, jj = np.meshgrid(np.arange(ni + 1), np.arange(nj + 1), indexing="ij")
        gi, gj = p.apply(ii, jj)
        return StructuredGrid(self.x[gi, gj], self.y[gi, gj], names={"block": self.names[k]})

    def blocks(self) -> list[StructuredGrid]:
        """Every block (:meth:`block`), in order."""
        return [self.block(k) for k in range(len(self.placements))]


_BORDER = {  # direction t, inward normal n, node of index k on a (ni, nj)-cell block
    "bottom": ((1, 0), (0, 1), lambda k, ni, nj: (k, 0)),
    "top": ((1, 0), (0, -1), lambda k, ni, nj: (k, nj)),
    "left": ((0, 1), (1, 0), lambda k, ni, nj: (0, k)),
    "right": ((0, 1), (-1, 0), lambda k, ni, nj: (ni, k)),
}


def _neighbour(pa: Placement, ga: StructuredGrid, gb: StructuredGrid, c) -> Placement:
    """The placement of block ``c.b`` that coupling ``c`` implies from ``pa`` (block ``c.a``)."""
    ra = np.array(pa.rotation)
    ta, na, pos_a = _BORDER[c.border_a]
    tb, nb, pos_b = _BORDER[c.border_b]
    s = -1 if c.reversed else 1
    m = np.column_stack([s * (ra @ ta), -(ra @ na)])
    rb = m @ np.array([tb, nb]).astype(int)  # [t_b n_b]^-1 = [t_b n_b]^T: rows t_b, n_b
    node_a = np.array(pos_a(c.start_a, *ga.cells))
    node_b = np.array(pos_b(c.stop_b if c.reversed else c.start_b, *gb.cells))
    off = ra @ node_a + np.array(pa.offset) - rb @ node_b
    rot = ((int(rb[0, 0]), int(rb[0, 1])), (int(rb[1, 0]), int(rb[1, 1])))
    return Placement(rot, (int(off[0]), int(off[1])))


def _where(g: StructuredGrid, border: str, k: int) -> str:
    p = g.border(border)[k]
    return f"({p[0]:.8g}, {p[1]:.8g})"


def _place(blocks, names, couplings) -> tuple[list[Placement], list[int]]:
    """BFS over the couplings; every block's placement and its component number."""
    adj: dict[int, list] = {k: [] for k in range(len(blocks))}
    for c in couplings:
        adj[c.a].append(c)
        adj[c.b].append(_swapped(c))
    place: list[Placement | None] = [None] * len(blocks)
    comp = [-1] * len(blocks)
    n_comp = 0
    for root in range(len(blocks)):
        if place[root] is not None:
            continue
        place[root] = Placement(((1, 0), (0, 1)), (0, 0))
        comp[root] = n_comp
        queue = deque([root])
        while queue:
            k = queue.popleft()
            pk = place[k]
            assert pk is not None
            for c in adj[k]:
                want = _neighbour(pk, blocks[c.a], blocks[c.b], c)
                have = place[c.b]
                if have is None:
                    place[c.b], comp[c.b] = want, n_comp
                    queue.append(c.b)
                elif have != want:
                    raise EmbeddingError(_mismatch(blocks, names, c, have, want))
        n_comp += 1
    return [p for p in place if p is not None], comp


def _swapped(c):
    """The coupling seen from its second block."""
    return type(c)(c.b, c.border_b, c.start_b, c.stop_b, c.a, c.border_a, c.start_a, c.stop_a, c.reversed)


def _mismatch(blocks, names, c, have: Placement, want: Placement) -> str:
    where = _where(blocks[c.a], c.border_a, (c.start_a + c.stop_a) // 2)
    head = f"the blocks do not fit one index space: {names[c.a]}.{c.border_a} ↔ {names[c.b]}.{c.border_b} near {where} "
    if have.rotation != want.rotation:
        return head + (
            f"turns block {names[c.b]!r} unlike the way round (a corner where 3 or 5 blocks meet, or a ring "
            f"round an island whose index directions come back turned)"
        )
    d = np.array(want.offset) - np.array(have.offset)
    return head + (
        f"puts block {names[c.b]!r} {abs(int(d[0])) + abs(int(d[1]))} cells away from the way round (a ring of "
        f"blocks round an island whose cell counts do not add up)"
    )


def _normalised(placements: list[Placement], blocks, comp: list[int], gap: int) -> list[Placement]:
    """Each component shifted to start at 0 and laid side by side along I, ``gap`` node columns apart."""
    lo: dict[int, np.ndarray] = {}
    hi: dict[int, np.ndarray] = {}
    for p, g, k in zip(placements, blocks, comp, strict=True):
        ni, nj = g.cells
        ci, cj = p.apply(np.array([0, ni, 0, ni]), np.array([0, 0, nj, nj]))
        a, b = np.array([ci.min(), cj.min()]), np.array([ci.max(), cj.max()])
        lo[k] = np.minimum(lo.get(k, a), a)
        hi[k] = np.maximum(hi.get(k, b), b)
    start, shift = 0, {}
    for k in sorted(lo):
        shift[k] = np.array([start, 0]) - lo[k]
        start += int(hi[k][0] - lo[k][0]) + 1 + gap
    return [
        Placement(p.rotation, (p.offset[0] + int(shift[k][0]), p.offset[1] + int(shift[k][1])))
        for p, k in zip(placements, comp, strict=True)
    ]


def _right_handed(placements: list[Placement], blocks) -> list[Placement]:
    """Mirror J when the first block's cells turn clockwise in the index space."""
    g, p = blocks[0], placements[0]
    jac = np.sign((g.x[1, 0] - g.x[0, 0]) * (g.y[0, 1] - g.y[0, 0]) - (g.x[0, 1] - g.x[0, 0]) * (g.y[1, 0] - g.y[0, 0]))
    if jac * (-1 if p.mirrored else 1) >= 0:
        return placements
    return [
        Placement((q.rotation[0], (-q.rotation[1][0], -q.rotation[1][1])), (q.offset[0], -q.offset[1]))
        for q in placements
    ]


def _fill(blocks, names, placements, shape, tol) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    x = np.full(shape, np.nan)
    y = np.full(shape, np.nan)
    node_owner = np.full(shape, -1)
    owner = np.full((shape[0] - 1, shape[1] - 1), -1)
    for k, (g, p) in enumerate(zip(blocks, placements, strict=True)):
        ii, jj = np.meshgrid(np.arange(g.shape[0]), np.arange(g.shape[1]), indexing="ij")
        gi, gj = p.apply(ii, jj)
        seen = node_owner[gi, gj] >= 0
        bad = seen & ((np.abs(x[gi, gj] - g.x) > tol) | (np.abs(y[gi, gj] - g.y) > tol))
        if bad.any():
            i, j = (int(v) for v in np.argwhere(bad)[0])
            other = names[int(node_owner[gi[i, j], gj[i, j]])]
            raise EmbeddingError(
                f"the blocks do not fit one index space: {other!r} and {names[k]!r} reach index node "
                f"({int(gi[i, j])}, {int(gj[i, j])}) at two places (near ({g.x[i, j]:.8g}, {g.y[i, j]:.8g})): "
                f"the layout folds back onto itself in index space"
            )
        x[gi, gj], y[gi, gj] = g.x, g.y
        node_owner[gi, gj] = np.where(seen, node_owner[gi, gj], k)
        ci = np.minimum(gi[:-1, :-1], gi[1:, 1:])
        cj = np.minimum(gj[:-1, :-1], gj[1:, 1:])
        taken = owner[ci, cj] >= 0
        if taken.any():
            i, j = (int(v) for v in np.argwhere(taken)[0])
            raise EmbeddingError(
                f"the blocks do not fit one index space: {names[int(owner[ci[i, j], cj[i, j]])]!r} and {names[k]!r} "
                f"claim index cell ({int(ci[i, j])}, {int(cj[i, j])}) (near ({g.x[i, j]:.8g}, {g.y[i, j]:.8g})): "
                f"the layout folds back onto itself in index space"
            )
        owner[ci, cj] = k
    return x, y, owner


def embed(blocks: Sequence[StructuredGrid], names: Sequence[str] | None = None, *, gap: int = 2) -> IndexSpace:
    """Place ``blocks`` in one index space (see module docstring).

    Raises
    ------
    EmbeddingError
        Naming the interface or the two blocks where the placement fails.
    """
    from ..io.delft3d_dd import find_couplings

    blocks = list(blocks)
    names = tuple(names) if names is not None else tuple(f"block{k + 1}" for k in range(len(blocks)))
    if not blocks:
        raise EmbeddingError("no blocks to place in an index space")
    pts = np.concatenate([np.column_stack([g.x.ravel(), g.y.ravel()]) for g in blocks])
    if not np.isfinite(pts).all():
        raise EmbeddingError("a block has a non-finite coordinate")
    tol = RTOL * max(float(np.hypot(*np.ptp(pts, axis=0))), np.finfo(float).tiny)
    couplings = find_couplings(blocks) if len(blocks) > 1 else []
    placements, comp = _place(blocks, names, couplings)
    placements = _right_handed(placements, blocks)
    placements = _normalised(placements, blocks, comp, gap)
    size = np.zeros(2, int)
    for p, g in zip(placements, blocks, strict=True):
        ci, cj = p.apply(np.array([0, g.cells[0]]), np.array([0, g.cells[1]]))
        size = np.maximum(size, [ci.max() + 1, cj.max() + 1])
    x, y, owner = _fill(blocks, names, placements, (int(size[0]), int(size[1])), tol)
    return IndexSpace(x, y, owner, tuple(placements), names, max(comp) + 1)


def from_mask(x: np.ndarray, y: np.ndarray, water: np.ndarray, *, prefix: str = "block") -> IndexSpace:
    """A merged grid read back (nodes ``x, y``, NaN where inactive; its water cells ``water``) as an
    :class:`IndexSpace` of rectangular blocks: the inverse of :func:`embed` for a file that keeps no
    blocks (a Delft3D single-domain ``.grd``, EFDC's ``cell.inp``).

    The water cells are cut into rectangles row by row, each as wide as its run of water and as
    tall as the run stays water: blocks that share borders, with T-junctions where runs end.  Every
    corner of a water cell must be an active node (``ValueError`` otherwise).
    """
    x = np.asarray(x, float)
    y = np.asarray(y, float)
    water = np.asarray(water, bool)
    if water.shape != (x.shape[0] - 1, x.shape[1] - 1) or x.shape != y.shape:
        raise ValueError(f"{water.shape} cells do not fit {x.shape} nodes")
    act = np.isfinite(x) & np.isfinite(y)
    corners = act[:-1, :-1] & act[1:, :-1] & act[1:, 1:] & act[:-1, 1:]
    if (water & ~corners).any():
        i, j = (int(v) for v in np.argwhere(water & ~corners)[0])
        raise ValueError(f"water cell ({i}, {j}) has an inactive corner")
    owner = np.full(water.shape, -1)
    placements: list[Placement] = []
    free = water.copy()
    for J in range(water.shape[1]):
        row = np.r_[False, free[:, J], False].astype(np.int8)
        starts = np.flatnonzero(np.diff(row) == 1)
        stops = np.flatnonzero(np.diff(row) == -1)
        for i0, i1 in zip(starts, stops, strict=True):
            j1 = J + 1
            while j1 < water.shape[1] and free[i0:i1, j1].all():
                j1 += 1
            k = len(placements)
            owner[i0:i1, J:j1] = k
            free[i0:i1, J:j1] = False
            placements.append(Placement(((1, 0), (0, 1)), (int(i0), int(J))))
    from scipy import ndimage

    n_components = int(ndimage.label(water)[1])
    names = tuple(f"{prefix}{k + 1}" for k in range(len(placements)))
    return IndexSpace(np.where(act, x, np.nan), np.where(act, y, np.nan), owner, tuple(placements), names, n_components)
