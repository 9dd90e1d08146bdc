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
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..boundary import Borders
from ..errors import TopologyError
from ..grid import BORDER_NAMES
from .nodemap import Corner, NodeMap, build_node_map

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
    _size: list = field(default_factory=list, repr=False)  # [size], computed once (blocks are frozen)

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
        self._map.append(build_node_map(self.blocks, self.interfaces))

    # ------------------------------------------------------------ basics
    @property
    def size(self) -> float:
        """The diagonal of the bounding box of all blocks (the stopping rule's length)."""
        if not self._size:
            allp = np.vstack([b.borders.loop() for b in self.blocks])
            self._size.append(float(math.hypot(*(allp.max(axis=0) - allp.min(axis=0)))))
        return self._size[0]

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
        union = shapely.union_all(list(polys.values()))
        # Σ areas − area of the union ≥ the overlap of any two blocks: when it is below the
        # threshold of the smallest block, no pair can exceed its own (skips the intersections)
        areas = [p.area for p in polys.values()]
        overlap_free = sum(areas) - union.area <= 1e-6 * min(areas)
        for ia, na in enumerate(names):
            for nb in names[ia + 1 :]:
                pa, pb = polys[na], polys[nb]
                if not pa.intersects(pb):
                    continue
                amin = min(pa.area, pb.area)
                inter = None if overlap_free else pa.intersection(pb)
                if inter is not None and inter.area > 1e-6 * amin:
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
