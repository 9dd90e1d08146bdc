"""The editable project: immutable state and pure edit functions (no Qt).

A :class:`Project` is a frozen snapshot of everything the user edits: the
blocks (boundary points, corners, cells, weights, initial method, per-border
distributions), the solver settings, cut lines, the background image and the
coordinate reference.  Every edit is a pure function ``Project -> Project``
(``with_point_added``, ``with_points_moved`` …); undo commands store the
states before and after and swap them, so undo restores the *exact* previous
state.

Blocks come in two forms, both accepted by :func:`meshcore.generate_block`:

* a closed **loop** of points plus four corner indices ``(sw, se, ne, nw)``
  (``Block.points`` / ``Block.corners``) — the form the editing tools work on;
* four **border polylines** (``Block.boundary``), as read from a case file
  whose borders are given explicitly (e.g. the paper's doubly-connected case
  where left and right coincide).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from meshcore import BORDER_NAMES, BlockSpec, BorderSpec, MeshcoreError, SolverSpec
from meshcore.io.outline import guess_cells, guess_corners

__all__ = [
    "Background",
    "Block",
    "Project",
    "SolverSettings",
    "frozen_points",
]

#: The solver part of a project: meshcore's :class:`~meshcore.SolverSpec` itself.
SolverSettings = SolverSpec


def frozen_points(points: Any) -> np.ndarray:
    """An ``(n, 2)`` float64 read-only copy of ``points`` (``(0, 2)`` for none)."""
    a = np.array(points if points is not None and len(points) else np.zeros((0, 2)), dtype=np.float64)
    a = a.reshape(-1, 2).copy()
    a.setflags(write=False)
    return a


def _eq_arrays(a: np.ndarray | None, b: np.ndarray | None) -> bool:
    if a is None or b is None:
        return a is b
    return a.shape == b.shape and bool(np.array_equal(a, b))


@dataclass(frozen=True, slots=True, eq=False)
class Block(BlockSpec):
    """One block of the project: a :class:`meshcore.BlockSpec` plus the drawing state.

    ``points`` is the closed loop (first point not repeated) when ``closed``;
    while the user is still drawing it is an open polyline.  ``corners`` are
    four indices into ``points`` (sw, se, ne, nw) or None.  ``boundary``
    (four polylines) replaces points/corners for blocks given by borders.
    ``cells=None`` keeps the given points as the boundary nodes.
    """

    cells: tuple[int, int] | None = (32, 16)
    closed: bool = False

    @classmethod
    def of(cls, spec: BlockSpec, **changes: Any) -> Block:
        """The editable block of a :class:`meshcore.BlockSpec` (a loop is closed, its repeated point dropped)."""
        kw = {f.name: getattr(spec, f.name) for f in dataclasses.fields(BlockSpec)}
        pts = np.asarray(spec.points)
        if len(pts) > 3 and np.allclose(pts[0], pts[-1]):
            kw["points"] = pts[:-1]
            if isinstance(spec.corners, tuple):
                kw["corners"] = tuple(int(c) % (len(pts) - 1) for c in spec.corners)
        kw["closed"] = len(pts) > 0
        return cls(**(kw | changes))

    # ------------------------------------------------------------ queries
    @property
    def ready(self) -> bool:
        """True when the block has a full boundary and can be generated."""
        if self.boundary is not None:
            return True
        return self.closed and self.corners is not None and len(self.points) >= 4

    def node_count(self, border: str) -> int:
        ni, nj = self.cell_counts or (0, 0)
        return (ni if border in ("bottom", "top") else nj) + 1


@dataclass(frozen=True, slots=True, eq=False)
class Background:
    """A background image placed in model coordinates.

    ``transform`` = ``(a, b, tx, ty)`` of the similarity map
    ``x = a·u − b·v + tx, y = b·u + a·v + ty`` from image pixels ``(u, v)``
    (u to the right, v *upwards* from the bottom row) to model coordinates.
    """

    path: str
    transform: tuple[float, float, float, float] = (1.0, 0.0, 0.0, 0.0)

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Background) and (self.path, self.transform) == (other.path, other.transform)

    __hash__ = None  # type: ignore[assignment]


@dataclass(frozen=True, slots=True, eq=False)
class Project:
    """Everything the user edits (immutable; edits return new projects)."""

    blocks: tuple[Block, ...] = (Block(name="block"),)
    solver: SolverSpec = field(default_factory=SolverSpec)
    cut_lines: tuple[np.ndarray, ...] = ()
    background: Background | None = None
    crs: str = ""  # metric CRS of the world coordinates, e.g. "EPSG:32632"
    origin: tuple[float, float] = (0.0, 0.0)  # local origin: world = local + origin
    source_crs: str = ""  # CRS the points were read in ("EPSG:4326" for lon/lat)
    title: str = ""
    #: a multiblock case (meshcore.case.Case with [multiblock]/[outline]/[[interfaces]]):
    #: its blocks are shown and solved together by meshcore.multiblock; not editable in the app
    multiblock: Any = None
    #: a lake (:class:`app.lake.Lake`): shore, islands, cell size and the block layout; with a
    #: layout the blocks are the layout's, solved together as one orthogonal grid
    lake: Any = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "blocks", tuple(self.blocks))
        object.__setattr__(self, "cut_lines", tuple(frozen_points(c) for c in self.cut_lines))

    def replaced(self, **kw: Any) -> Project:
        return dataclasses.replace(self, **kw)

    @property
    def layout(self) -> Any:
        """The lake's block layout (a :class:`meshcore.layout.Layout`), or None."""
        return self.lake.layout if self.lake is not None else None

    def with_block(self, index: int, block: Block) -> Project:
        blocks = list(self.blocks)
        blocks[index] = block
        return self.replaced(blocks=tuple(blocks))

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Project):
            return NotImplemented
        return (
            self.blocks == other.blocks
            and self.solver == other.solver
            and len(self.cut_lines) == len(other.cut_lines)
            and all(_eq_arrays(a, b) for a, b in zip(self.cut_lines, other.cut_lines, strict=True))
            and self.background == other.background
            and self.crs == other.crs
            and self.title == other.title
            and (self.lake is other.lake or self.lake == other.lake)
        )

    __hash__ = None  # type: ignore[assignment]

    def bounds(self) -> tuple[float, float, float, float] | None:
        """Bounding box of all points (None when empty)."""
        pts = [b.points for b in self.blocks if len(b.points)]
        pts += [np.vstack(b.boundary) for b in self.blocks if b.boundary is not None]
        if self.lake is not None:
            pts.append(self.lake.outline)
        if not pts:
            return None
        a = np.vstack(pts)
        return (float(a[:, 0].min()), float(a[:, 1].min()), float(a[:, 0].max()), float(a[:, 1].max()))


# ------------------------------------------------------------------ edits on a block
def with_point_added(block: Block, xy: tuple[float, float]) -> Block:
    """Append a point to an open (being drawn) block."""
    return block.replaced(points=np.vstack([block.points, np.asarray(xy, float).reshape(1, 2)]))


def with_loop_closed(block: Block) -> Block:
    """Close the drawn polyline (needs ≥ 3 points); drops a repeated last point."""
    p = block.points
    if len(p) >= 2 and np.allclose(p[0], p[-1]):
        p = p[:-1]
    if len(p) < 3:
        return block
    return block.replaced(points=p, closed=True)


def with_points_moved(block: Block, indices: Any, delta: tuple[float, float]) -> Block:
    """Move the points ``indices`` by ``delta``."""
    p = np.array(block.points)
    idx = np.asarray(list(indices), dtype=int)
    p[idx] += np.asarray(delta, float)
    return block.replaced(points=p)


def with_point_set(block: Block, index: int, xy: tuple[float, float]) -> Block:
    """Put point ``index`` at ``xy``."""
    p = np.array(block.points)
    p[int(index)] = xy
    return block.replaced(points=p)


def with_points_set(block: Block, indices: Any, positions: Any) -> Block:
    """Put the points ``indices`` at ``positions`` (``(k, 2)``)."""
    p = np.array(block.points)
    p[np.asarray(list(indices), dtype=int)] = np.asarray(positions, float).reshape(-1, 2)
    return block.replaced(points=p)


def with_point_inserted(block: Block, after: int, xy: tuple[float, float]) -> Block:
    """Insert a point after index ``after`` (on segment after → after+1); corners follow."""
    p = np.insert(np.array(block.points), after + 1, np.asarray(xy, float), axis=0)
    corners = None
    if block.corners is not None:
        corners = tuple(c + 1 if c > after else c for c in block.corners)
    return block.replaced(points=p, corners=corners)


def with_points_deleted(block: Block, indices: Any) -> Block:
    """Delete points; corners on deleted points are cleared, others re-indexed."""
    idx = sorted({int(i) for i in indices})
    if not idx:
        return block
    keep = np.ones(len(block.points), dtype=bool)
    keep[idx] = False
    p = block.points[keep]
    corners = None
    if block.corners is not None and not any(c in idx for c in block.corners):
        newidx = np.cumsum(keep) - 1
        corners = tuple(int(newidx[c]) for c in block.corners)
    closed = block.closed and len(p) >= 3
    return block.replaced(points=p, corners=corners, closed=closed)


def with_corners(block: Block, corners: Any) -> Block:
    return block.replaced(corners=None if corners is None else tuple(int(c) for c in corners))


def with_border_spec(block: Block, border: str, spec: BorderSpec) -> Block:
    if border not in BORDER_NAMES:
        raise ValueError(f"unknown border {border!r}")
    d = dict(block.borders)
    d[border] = spec
    return block.replaced(borders=tuple(d.items()))


def boundary_to_loop(block: Block) -> Block:
    """Turn a four-polyline block into loop + corners (for editing), when possible."""
    if block.boundary is None:
        return block
    b, r, t, l = block.boundary
    loop = np.vstack([b[:-1], r[:-1], t[::-1][:-1], l[::-1][:-1]])
    nb, nr, nt = len(b) - 1, len(r) - 1, len(t) - 1
    corners = (0, nb, nb + nr, nb + nr + nt)
    return block.replaced(points=loop, closed=True, corners=corners, boundary=None)


def next_block_name(project: Project) -> str:
    names = {b.name for b in project.blocks}
    k = len(project.blocks) + 1
    while f"block{k}" in names:
        k += 1
    return f"block{k}"


def default_cells(
    points: np.ndarray, corners: tuple[int, int, int, int], total: int = 40, minimum: int = 2
) -> tuple[int, int]:
    """Cell counts whose Winslow grid has square cells on median (:func:`meshcore.io.outline.guess_cells`).

    About ``total`` cells along the longer direction, at least ``minimum`` along either.
    """
    return guess_cells(points, corners, total=total, minimum=minimum)


def block_from_points(points: Any, name: str, *, total: int | None = None, minimum: int = 8) -> Block:
    """A closed block from imported boundary points, with the corners and cells ``meshcore import`` chooses
    (cells of ``meshcore mesh``'s default size, about 10 000 of them; ``total``: about that many along
    the longer direction instead).

    (:func:`meshcore.io.outline.guess_corners`, :func:`~meshcore.io.outline.guess_cells`):
    the same point file gives the same grid in the app and on the command line.
    """
    try:
        corners = guess_corners(points)
    except MeshcoreError:
        return Block(name=name, points=points, closed=True)
    cells = guess_cells(points, corners, total=total, minimum=minimum)
    return Block(name=name, points=points, closed=True, corners=corners, cells=cells)
