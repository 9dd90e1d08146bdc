r"""Multiblock topology: blocks, shared borders (parts) with orientation, corners.

A multiblock grid is a set of structured blocks (each in the convention of
:mod:`meshcore.grid`) glued along **interfaces**.  An interface joins a
contiguous part of one block's border to a part of another block's border::

    Interface(Side("main", "right", 4, 12), Side("arm", "left", 0, 8), reversed=False)

``Side(block, border, start, stop)`` names the nodes ``start … stop``
(inclusive) of a border, counted in the border's own direction (bottom/top
with increasing i, left/right with increasing j).  ``reversed=False`` pairs
``a[start + k]`` with ``b[start + k]``; ``reversed=True`` pairs it with
``b[stop − k]``.  With ``reversed=None`` the orientation is read from the
coordinates.  Both parts must carry the same number of cells.

Global node numbering
---------------------
Every block node gets an id; the ids of paired interface nodes are merged
(union–find), so a shared node — including a corner where 3, 4 or 5 blocks
meet — is stored once.  From the cells of all blocks (corners in
counter-clockwise order) the topology derives:

* **boundary nodes**: nodes on an edge used by one cell only (the outer
  boundary, e.g. a lake shore).  They are always fixed;
* **regular free nodes**: four cells around the node.  Their eight neighbours
  in a local (ξ, η) frame are read off the ring of cells, so an interface node
  gets the same 9-point stencil it would have inside one block;
* **irregular free nodes**: ``k ≠ 4`` cells around the node (a corner where
  3, 5, … blocks meet).  They get an explicit Laplacian update over the ring of
  their ``k`` edge neighbours (see :mod:`._kernels`).

Validation (:class:`~meshcore.errors.TopologyError`, one message per case,
naming blocks and borders): unknown blocks/borders, part ranges outside the
border, interfaces whose cell counts differ, parts whose nodes do not coincide,
an edge shared by more than two cells, blocks that overlap, blocks that touch
along a border no interface declares, and holes (gaps) between blocks.
"""

from __future__ import annotations

import math
from collections import defaultdict
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..boundary import Borders
from ..errors import TopologyError
from ..grid import BORDER_NAMES

__all__ = [
    "Block",
    "Corner",
    "Interface",
    "MultiBlockTopology",
    "NodeMap",
    "Side",
    "parse_side",
]


@dataclass(frozen=True, slots=True)
class Side:
    """Nodes ``start … stop`` (inclusive) of one border of one block."""

    block: str
    border: str
    start: int = 0
    stop: int = -1  # -1: the last node of the border

    @property
    def label(self) -> str:
        return f"{self.block}.{self.border}[{self.start}:{self.stop}]"

    def resolved(self, n_nodes: int) -> Side:
        """The side with ``stop = -1`` replaced by the last node index."""
        stop = n_nodes - 1 if self.stop == -1 else self.stop
        return Side(self.block, self.border, self.start, stop)


def parse_side(text: str | Side | Sequence[Any]) -> Side:
    """``"main.right"`` or ``"main.right[4:12]"`` (node indices, inclusive) → :class:`Side`."""
    if isinstance(text, Side):
        return text
    if not isinstance(text, str):
        try:
            block, border, *rng = text
            return Side(str(block), str(border), *(int(v) for v in rng))
        except (TypeError, ValueError):
            raise TopologyError(f"interface side must be 'block.border[start:stop]', got {text!r}") from None
    s = text.strip()
    rng: tuple[int, ...] = ()
    if s.endswith("]") and "[" in s:
        s, r = s[:-1].split("[", 1)
        try:
            a, b = r.split(":")
            rng = (int(a), int(b))
        except ValueError:
            raise TopologyError(f"interface side {text!r}: the node range must be [start:stop] with integers") from None
    if "." not in s:
        raise TopologyError(f"interface side {text!r} must be written 'block.border', e.g. 'main.right'")
    block, border = s.rsplit(".", 1)
    return Side(block, border, *rng)


@dataclass(frozen=True, slots=True)
class Interface:
    """Two border parts that share their nodes (see module docstring)."""

    a: Side
    b: Side
    reversed: bool | None = None

    @property
    def label(self) -> str:
        arrow = "reversed" if self.reversed else "same direction"
        return f"{self.a.label} ↔ {self.b.label} ({arrow})"


@dataclass(frozen=True, slots=True, eq=False)
class Block:
    """One block: a name, its four re-sampled borders and how to start its grid.

    Parameters
    ----------
    name : str
    borders : Borders
        Boundary nodes (opposite borders with equal counts).
    initial : {"weighted", "tfi"}
        Algebraic start grid.
    weights : (p13_x, p13_y)
        Weights of the paper's eq. 34 when ``initial == "weighted"``.
    """

    name: str
    borders: Borders
    initial: str = "tfi"
    weights: tuple[float, float] = (0.5, 0.5)
    names: dict = field(default_factory=dict)

    @property
    def cells(self) -> tuple[int, int]:
        return self.borders.check_counts()

    def border_nodes(self, border: str) -> np.ndarray:
        return self.borders[border]


@dataclass(frozen=True, slots=True)
class Corner:
    """A node shared by three or more blocks (or an irregular interior node)."""

    node: int
    point: tuple[float, float]
    blocks: tuple[str, ...]  # "name(i,j)" labels of the block corners/nodes meeting here
    valence: int  # number of cells around the node
    free: bool  # solved (interior) or fixed (on the outer boundary)

    @property
    def handling(self) -> str:
        if not self.free:
            return "fixed (on the outer boundary)"
        if self.valence == 4:
            return "regular 9-point stencil from the ring of 4 cells"
        return f"irregular: Laplacian update over its {self.valence} edge neighbours"


@dataclass(frozen=True, slots=True, eq=False)
class NodeMap:
    """Global node numbering and the solver tables of a topology."""

    n_nodes: int
    ids: tuple[np.ndarray, ...]  # per block, (ni+1, nj+1) global ids
    boundary: np.ndarray  # bool (n_nodes,): on the outer boundary (fixed)
    shared: np.ndarray  # bool (n_nodes,): in more than one block
    nodes: np.ndarray  # int64 (m,): free regular nodes in sweep order (block interiors first)
    nbr: np.ndarray  # int64 (m, 8): E, W, N, S, NE, NW, SE, SW
    irr_nodes: np.ndarray
    irr_ptr: np.ndarray
    irr_ring: np.ndarray
    corners: tuple[Corner, ...]
    cells: np.ndarray  # int64 (n_cells, 4) CCW corner ids
    cell_block: np.ndarray  # int32 (n_cells,): block index of each cell
    n_interior: int = 0  # nodes[:n_interior] are block-interior nodes, the rest lie on borders


def _union_find(n: int) -> tuple[np.ndarray, Any, Any]:
    parent = np.arange(n)

    def find(a: int) -> int:
        root = a
        while parent[root] != root:
            root = parent[root]
        while parent[a] != root:
            parent[a], a = root, parent[a]
        return int(root)

    def union(a: int, b: int) -> None:
        ra, rb = find(a), find(b)
        if ra != rb:
            if ra < rb:
                parent[rb] = ra
            else:
                parent[ra] = rb

    return parent, find, union


def _border_index(shape: tuple[int, int], border: str) -> tuple[np.ndarray, np.ndarray]:
    """(i, j) index arrays of a border's nodes in its own direction."""
    n1, m1 = shape
    if border == "bottom":
        return np.arange(n1), np.zeros(n1, dtype=int)
    if border == "top":
        return np.arange(n1), np.full(n1, m1 - 1)
    if border == "left":
        return np.zeros(m1, dtype=int), np.arange(m1)
    return np.full(m1, n1 - 1), np.arange(m1)


@dataclass(frozen=True, slots=True, eq=False)
class MultiBlockTopology:
    """Blocks and the interfaces that glue them (validated on construction).

    Parameters
    ----------
    blocks : sequence of Block
    interfaces : sequence of Interface
        Sides may use ``stop = -1`` and ``reversed = None``; the stored
        interfaces are resolved (explicit ranges and orientation).
    check_geometry : bool
        Run the shapely checks (overlaps, undeclared contacts, holes).
    """

    blocks: tuple[Block, ...]
    interfaces: tuple[Interface, ...] = ()
    check_geometry: bool = True
    _map: list = field(default_factory=list, repr=False)

    def __post_init__(self) -> None:
        blocks = tuple(self.blocks)
        if not blocks:
            raise TopologyError("a multiblock topology needs at least one block")
        names = [b.name for b in blocks]
        dup = sorted({n for n in names if names.count(n) > 1})
        if dup:
            raise TopologyError(f"block names must be unique; repeated: {', '.join(dup)}")
        for b in blocks:
            try:
                _ = b.cells
            except Exception as exc:  # BorderMismatchError → name the block
                raise TopologyError(f"block {b.name!r}: {exc}") from None
        object.__setattr__(self, "blocks", blocks)
        by_name = {b.name: b for b in blocks}
        size = self.size
        resolved = []
        for itf in self.interfaces:
            resolved.append(self._resolve(itf, by_name, size))
        object.__setattr__(self, "interfaces", tuple(resolved))
        self._check_overlapping_parts()
        if self.check_geometry:
            self._check_geometry()
        self._map.append(self._build_map())

    # ------------------------------------------------------------ basics
    @property
    def size(self) -> float:
        allp = np.vstack([b.borders.loop() for b in self.blocks])
        return float(math.hypot(*(allp.max(axis=0) - allp.min(axis=0))))

    def block(self, name: str) -> Block:
        for b in self.blocks:
            if b.name == name:
                return b
        raise TopologyError(f"no block named {name!r}; blocks: {', '.join(b.name for b in self.blocks)}")

    def index(self, name: str) -> int:
        return [b.name for b in self.blocks].index(name)

    @property
    def node_map(self) -> NodeMap:
        return self._map[0]

    # -------------------------------------------------------- validation
    @staticmethod
    def _resolve(itf: Interface, by_name: dict[str, Block], size: float) -> Interface:
        sides = []
        for s in (itf.a, itf.b):
            if s.block not in by_name:
                raise TopologyError(
                    f"interface {itf.a.block}.{itf.a.border} ↔ {itf.b.block}.{itf.b.border}: "
                    f"no block named {s.block!r} (blocks: {', '.join(by_name)})"
                )
            if s.border not in BORDER_NAMES:
                raise TopologyError(
                    f"interface side {s.block}.{s.border}: border must be one of {', '.join(BORDER_NAMES)}"
                )
            n = len(by_name[s.block].borders[s.border])
            r = s.resolved(n)
            if not (0 <= r.start < r.stop <= n - 1):
                raise TopologyError(
                    f"interface side {r.label}: node range must satisfy 0 ≤ start < stop ≤ {n - 1} "
                    f"(border {s.block}.{s.border} has {n} nodes)"
                )
            sides.append(r)
        a, b = sides
        if a.block == b.block and a.border == b.border:
            raise TopologyError(f"interface {a.label} ↔ {b.label} joins a border to itself")
        ca, cb = a.stop - a.start, b.stop - b.start
        if ca != cb:
            raise TopologyError(
                f"interface {a.label} ↔ {b.label}: cell counts differ ({ca} cells on "
                f"{a.block}.{a.border} but {cb} on {b.block}.{b.border}); shared borders must "
                f"carry the same number of nodes"
            )
        pa = by_name[a.block].borders[a.border][a.start : a.stop + 1]
        pb = by_name[b.block].borders[b.border][b.start : b.stop + 1]
        tol = 1e-7 * size
        gap_f = np.hypot(*(pa - pb).T)
        gap_r = np.hypot(*(pa - pb[::-1]).T)
        rev = itf.reversed
        if rev is None:
            rev = bool(gap_r.max() < gap_f.max())
        gap = gap_r if rev else gap_f
        if gap.max() > tol:
            k = int(np.argmax(gap))
            raise TopologyError(
                f"interface {a.label} ↔ {b.label}: the nodes do not coincide "
                f"({'reversed' if rev else 'same direction'}); node {a.start + k} of "
                f"{a.block}.{a.border} at ({pa[k, 0]:.6g}, {pa[k, 1]:.6g}) is {gap[k]:.3g} "
                f"away from "
                f"its partner (check the node ranges and the orientation)"
            )
        return Interface(a, b, rev)

    def _check_overlapping_parts(self) -> None:
        used: dict[tuple[str, str], list[Side]] = defaultdict(list)
        for itf in self.interfaces:
            for s in (itf.a, itf.b):
                for o in used[(s.block, s.border)]:
                    if s.start < o.stop and o.start < s.stop:
                        raise TopologyError(
                            f"border {s.block}.{s.border}: parts {o.label} and {s.label} overlap; "
                            f"each border node range may join only one interface"
                        )
                used[(s.block, s.border)].append(s)

    def _check_geometry(self) -> None:
        import shapely
        from shapely.geometry import LineString, Polygon

        size = self.size
        polys = {}
        for b in self.blocks:
            poly = Polygon(b.borders.loop())
            if not poly.is_valid:
                raise TopologyError(
                    f"block {b.name!r}: its four borders cross each other ({shapely.is_valid_reason(poly)})"
                )
            polys[b.name] = poly
        declared: dict[frozenset, float] = defaultdict(float)
        for itf in self.interfaces:
            pa = self.block(itf.a.block).borders[itf.a.border][itf.a.start : itf.a.stop + 1]
            declared[frozenset((itf.a.block, itf.b.block))] += LineString(pa).length
        names = list(polys)
        for ia, na in enumerate(names):
            for nb in names[ia + 1 :]:
                pa, pb = polys[na], polys[nb]
                if not pa.intersects(pb):
                    continue
                inter = pa.intersection(pb)
                amin = min(pa.area, pb.area)
                if inter.area > 1e-6 * amin:
                    c = inter.representative_point()
                    raise TopologyError(
                        f"blocks {na!r} and {nb!r} overlap (shared area {inter.area:.4g}, "
                        f"{100 * inter.area / amin:.2g}% of the smaller one, near "
                        f"({c.x:.6g}, {c.y:.6g}))"
                    )
                contact = pa.boundary.intersection(pb.boundary).length
                have = declared.get(frozenset((na, nb)), 0.0)
                if contact > have + 1e-6 * size:
                    raise TopologyError(
                        f"blocks {na!r} and {nb!r} touch along a length of {contact:.4g} but "
                        f"interfaces join only {have:.4g} of it: declare the shared border part "
                        f"(e.g. {na}.<border> ↔ {nb}.<border>) or the grid has a slit there"
                    )
        union = shapely.union_all(list(polys.values()))
        geoms = getattr(union, "geoms", [union])
        for g in geoms:
            for hole in g.interiors:
                hp = Polygon(hole)
                if hp.area <= 1e-9 * size * size:
                    continue
                around = [n for n, p in polys.items() if p.boundary.distance(hp) <= 1e-7 * size]
                c = hp.representative_point()
                raise TopologyError(
                    f"gap between blocks {', '.join(repr(n) for n in around)}: a hole of area "
                    f"{hp.area:.4g} near ({c.x:.6g}, {c.y:.6g}) is covered by no block"
                )

    # ------------------------------------------------------ numbering
    def _build_map(self) -> NodeMap:
        shapes = [(b.cells[0] + 1, b.cells[1] + 1) for b in self.blocks]
        offsets = np.cumsum([0] + [a * c for a, c in shapes])
        local = [offsets[k] + np.arange(a * c).reshape(a, c) for k, (a, c) in enumerate(shapes)]
        _, find, union = _union_find(int(offsets[-1]))
        idx = {b.name: k for k, b in enumerate(self.blocks)}
        for itf in self.interfaces:
            ka, kb = idx[itf.a.block], idx[itf.b.block]
            ia, ja = _border_index(shapes[ka], itf.a.border)
            ib, jb = _border_index(shapes[kb], itf.b.border)
            ga = local[ka][ia, ja][itf.a.start : itf.a.stop + 1]
            gb = local[kb][ib, jb][itf.b.start : itf.b.stop + 1]
            if itf.reversed:
                gb = gb[::-1]
            for u, v in zip(ga.tolist(), gb.tolist(), strict=True):
                union(u, v)
        roots = np.array([find(k) for k in range(int(offsets[-1]))])
        uniq, compact = np.unique(roots, return_inverse=True)
        n_nodes = len(uniq)
        ids = tuple(compact[loc].reshape(loc.shape) for loc in local)
        for k, g in enumerate(ids):
            if len(np.unique(g)) != g.size:
                raise TopologyError(
                    f"block {self.blocks[k].name!r}: interfaces glue two nodes of the same block "
                    f"together (a border is joined to itself or to a neighbour's border twice)"
                )
        # cells, CCW: (i,j) (i+1,j) (i+1,j+1) (i,j+1)
        cells = np.vstack(
            [np.stack([g[:-1, :-1], g[1:, :-1], g[1:, 1:], g[:-1, 1:]], axis=-1).reshape(-1, 4) for g in ids]
        ).astype(np.int64)
        cell_block = np.concatenate([np.full((a - 1) * (c - 1), k, dtype=np.int32) for k, (a, c) in enumerate(shapes)])
        # edges: count cells per undirected edge
        e0 = cells.reshape(-1)
        e1 = np.roll(cells, -1, axis=1).reshape(-1)
        key = np.minimum(e0, e1) * n_nodes + np.maximum(e0, e1)
        ukey, inv, cnt = np.unique(key, return_inverse=True, return_counts=True)
        if (cnt > 2).any():
            bad = int(ukey[np.argmax(cnt > 2)])
            u, v = divmod(bad, n_nodes)
            hit = np.flatnonzero(key == bad)
            blocks = sorted({self.blocks[cell_block[c // 4]].name for c in hit})
            raise TopologyError(
                f"an edge is shared by more than two cells (blocks {', '.join(blocks)}): "
                f"interfaces of these blocks overlap"
            )
        # directed-edge check: a shared edge must be walked in opposite directions
        dkey = e0 * n_nodes + e1
        _, dcnt = np.unique(dkey, return_counts=True)
        if (dcnt > 1).any():
            raise TopologyError(
                "two blocks meet with opposite orientations (a mirrored block): every block must "
                "run bottom → right → top → left counter-clockwise"
            )
        on_bnd_edge = cnt[inv] == 1
        boundary = np.zeros(n_nodes, dtype=bool)
        boundary[e0[on_bnd_edge]] = True
        boundary[e1[on_bnd_edge]] = True
        count = np.bincount(cells.reshape(-1), minlength=n_nodes)  # cells per node
        occ = np.bincount(np.concatenate([np.unique(g) for g in ids]), minlength=n_nodes)
        shared = occ > 1

        # --- regular interior nodes of each block: direct frame
        nodes_l, nbr_l = [], []
        for g in ids:
            if g.shape[0] < 3 or g.shape[1] < 3:
                continue
            c = g[1:-1, 1:-1].ravel()
            nb = np.stack(
                [
                    g[2:, 1:-1],
                    g[:-2, 1:-1],
                    g[1:-1, 2:],
                    g[1:-1, :-2],
                    g[2:, 2:],
                    g[:-2, 2:],
                    g[2:, :-2],
                    g[:-2, :-2],
                ],
                axis=-1,
            ).reshape(-1, 8)
            nodes_l.append(c)
            nbr_l.append(nb)
        # --- free nodes on block borders: frame from the ring of cells
        border_free = np.flatnonzero(~boundary & shared)
        inc = defaultdict(list)
        sel = np.isin(cells, border_free)
        for cidx, pos in zip(*np.nonzero(sel), strict=True):
            inc[int(cells[cidx, pos])].append((int(cidx), int(pos)))
        reg_n, reg_nb, irr_n, irr_ptr, irr_ring = [], [], [], [0], []
        corners = []
        for n in border_free.tolist():
            lst = inc[n]
            nxt = {}
            for cidx, pos in lst:
                c = cells[cidx]
                e_next, diag, e_prev = (int(c[(pos + k) % 4]) for k in (1, 2, 3))
                nxt[e_next] = (e_next, diag, e_prev)
            ring = []
            cur = next(iter(nxt.values()))
            for _ in range(len(lst)):
                ring.append(cur)
                cur = nxt.get(cur[2])
                if cur is None:
                    break
            if len(ring) != len(lst) or cur != ring[0]:
                raise TopologyError(
                    f"the cells around node {self._node_label(n, ids)} do not close into a ring: "
                    f"interfaces there are inconsistent"
                )
            if len(ring) == 4:
                e = [r[0] for r in ring]
                d = [r[1] for r in ring]
                # E, W, N, S, NE, NW, SE, SW  with E=e0, N=e1, W=e2, S=e3
                reg_n.append(n)
                reg_nb.append([e[0], e[2], e[1], e[3], d[0], d[1], d[3], d[2]])
            else:
                irr_n.append(n)
                irr_ring.extend(r[0] for r in ring)
                irr_ptr.append(len(irr_ring))
        # corner records: nodes in ≥ 3 blocks, or irregular
        for n in np.flatnonzero(occ >= 3).tolist() + [m for m in irr_n if occ[m] < 3]:
            corners.append(
                Corner(
                    node=n,
                    point=self._node_xy(n, ids),
                    blocks=self._node_owners(n, ids),
                    valence=int(count[n]),
                    free=not bool(boundary[n]),
                )
            )
        n_interior = int(sum(len(c) for c in nodes_l))
        if reg_n:
            nodes_l.append(np.array(reg_n, dtype=np.int64))
            nbr_l.append(np.array(reg_nb, dtype=np.int64))
        nodes = np.concatenate(nodes_l).astype(np.int64) if nodes_l else np.zeros(0, np.int64)
        nbr = np.vstack(nbr_l).astype(np.int64) if nbr_l else np.zeros((0, 8), np.int64)
        return NodeMap(
            n_nodes=n_nodes,
            ids=ids,
            boundary=boundary,
            shared=shared,
            nodes=np.ascontiguousarray(nodes),
            nbr=np.ascontiguousarray(nbr),
            irr_nodes=np.array(irr_n, dtype=np.int64),
            irr_ptr=np.array(irr_ptr, dtype=np.int64),
            irr_ring=np.array(irr_ring, dtype=np.int64),
            corners=tuple(sorted(corners, key=lambda c: c.node)),
            cells=cells,
            cell_block=cell_block,
            n_interior=n_interior,
        )

    def _node_owners(self, n: int, ids: Iterable[np.ndarray]) -> tuple[str, ...]:
        out = []
        for b, g in zip(self.blocks, ids, strict=True):
            for i, j in np.argwhere(g == n):
                out.append(f"{b.name}({int(i)},{int(j)})")
        return tuple(out)

    def _node_label(self, n: int, ids: Iterable[np.ndarray]) -> str:
        return " = ".join(self._node_owners(n, ids))

    def _node_xy(self, n: int, ids: Iterable[np.ndarray]) -> tuple[float, float]:
        for b, g in zip(self.blocks, ids, strict=True):
            hit = np.argwhere(g == n)
            if len(hit):
                i, j = hit[0]
                ni, nj = b.cells
                for border, (bi, bj) in (
                    ("bottom", (i, 0)),
                    ("top", (i, nj)),
                    ("left", (0, j)),
                    ("right", (ni, j)),
                ):
                    if (i, j) == (bi, bj):
                        p = b.borders[border][i if border in ("bottom", "top") else j]
                        return (float(p[0]), float(p[1]))
        return (math.nan, math.nan)

    # --------------------------------------------------------- report
    def connectivity_report(self) -> str:
        """Human-readable connectivity: blocks, interfaces (orientation, node ranges), corners."""
        lines = ["Blocks:"]
        for b in self.blocks:
            ni, nj = b.cells
            lines.append(f"  {b.name}: {ni} × {nj} cells ({(ni + 1) * (nj + 1)} nodes)")
        lines.append("Interfaces (node ranges inclusive, in each border's own direction):")
        if not self.interfaces:
            lines.append("  (none)")
        for k, itf in enumerate(self.interfaces):
            a, b = itf.a, itf.b
            orient = "opposite directions" if itf.reversed else "same direction"
            lines.append(
                f"  {k}: {a.block}.{a.border} nodes {a.start}…{a.stop}  ↔  "
                f"{b.block}.{b.border} nodes {b.start}…{b.stop}  "
                f"({a.stop - a.start} cells, {orient})"
            )
        m = self.node_map
        lines.append("Multi-block corners:")
        if not m.corners:
            lines.append("  (none)")
        for c in m.corners:
            lines.append(
                f"  node {c.node} at ({c.point[0]:.6g}, {c.point[1]:.6g}): {len(c.blocks)} block "
                f"nodes [{', '.join(c.blocks)}], {c.valence} cells around; {c.handling}"
            )
        lines.append(
            f"Nodes: {m.n_nodes} unique ({int(m.boundary.sum())} on the outer boundary, "
            f"{len(m.nodes)} regular free, {len(m.irr_nodes)} irregular free)"
        )
        return "\n".join(lines)
