"""What a case file holds: :class:`Case` and its multiblock sections (frozen, no I/O)."""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .._validation import validate_count
from ..errors import InvalidInputError
from ..multiblock.outline import BlockOutline
from ..multiblock.solver import MODES
from ..spec import BlockSpec, SolverSpec

__all__ = [
    "CASE_MODES",
    "OUTLINE_CRS",
    "START_CHOICES",
    "Case",
    "InterfaceEntry",
    "LakeSection",
    "MultiblockSection",
    "OutlineSection",
    "outline_point",
]

#: ``[multiblock] mode``: the multiblock solver's modes, and ``orthogonal`` (an ``[outline]`` case
#: solved by :func:`meshcore.lakegrid.iterate_layout`: shore nodes slide, grid lines orthogonal).
CASE_MODES = (*MODES, "orthogonal")
#: ``[multiblock] start``: smooth mode starts from the algebraic grids or the frozen solution.
START_CHOICES = ("algebraic", "frozen")
#: ``crs`` of an outline: no projection, local equirectangular, UTM of the centroid (pyproj);
#: any other value is a target CRS for pyproj (``"EPSG:32610"``, ``32610``).
OUTLINE_CRS = ("xy", "none", "lonlat", "utm", "auto")


@dataclass(frozen=True, slots=True)
class MultiblockSection:
    """``[multiblock]``: how the blocks are solved together.

    ``mode``: ``"smooth"`` (interfaces solved), ``"frozen"`` (the paper:
    interfaces fixed) or ``"orthogonal"`` (an ``[outline]`` case: orthogonal lake grid, shore
    nodes sliding); ``start``: smooth mode starts from the ``"algebraic"``
    grids or from the ``"frozen"`` solution.
    """

    mode: str = "smooth"
    start: str = "algebraic"

    def __post_init__(self) -> None:
        if self.mode not in CASE_MODES:
            raise InvalidInputError(f"mode must be one of {', '.join(CASE_MODES)}, got {self.mode!r}")
        if self.start not in START_CHOICES:
            raise InvalidInputError(f"start must be frozen or algebraic, got {self.start!r}")


@dataclass(frozen=True, slots=True)
class InterfaceEntry:
    """``[[interfaces]]``: two block sides glued together.

    ``a``, ``b``: ``"block.border"``, optionally with a node range
    (``"main.top[4:12]"``); ``reversed``: orientation (None = from the coordinates).
    """

    a: str
    b: str
    reversed: bool | None = None

    def __post_init__(self) -> None:
        if self.reversed is not None and not isinstance(self.reversed, bool):
            raise InvalidInputError("reversed must be true or false")


def outline_point(v: Any) -> int | tuple[float, float]:
    if isinstance(v, (int, np.integer)) and not isinstance(v, bool):
        return int(v)
    if (
        isinstance(v, (list, tuple, np.ndarray))
        and len(v) == 2
        and all(isinstance(e, (int, float, np.number)) and not isinstance(e, bool) for e in v)
    ):
        return (float(v[0]), float(v[1]))
    raise InvalidInputError(f"expected an outline point index or an [x, y] pair, got {v!r}")


@dataclass(frozen=True, slots=True, eq=False)
class OutlineSection:
    """``[outline]``: one closed outline split by cut lines into ``[[outline.blocks]]``.

    ``points`` is a point-file name (relative to the case file) or ``(n, 2)``
    points; cut and corner points are outline indices or ``(x, y)`` pairs.  ``holes``: islands,
    inline rings of ``(x, y)`` points (cuts may end on them); ``cell_size``: the cell size the
    layout was made for (shares a side's cells among its parts; the orthogonal mode's shore
    sampling); ``single``: the cells of a side's parts also close every ring of blocks in one index
    space (a layout made for a Delft3D single domain or EFDC).  See
    :func:`meshcore.multiblock.from_outline` and ``crs`` in :data:`OUTLINE_CRS`.
    """

    points: str | np.ndarray
    cuts: tuple[tuple[int | tuple[float, float], ...], ...]
    blocks: tuple[BlockOutline, ...]
    crs: str | int = "auto"
    origin: tuple[float, float] | None = None
    snap: float | None = None
    multiple: int = 1
    holes: tuple[np.ndarray, ...] = ()
    cell_size: float | None = None
    single: bool = False

    def __post_init__(self) -> None:
        put = object.__setattr__
        if not isinstance(self.single, bool):
            raise InvalidInputError(f"single must be true or false, got {self.single!r}")
        holes = []
        for k, h in enumerate(self.holes):
            a = np.array(h, dtype=np.float64)
            if a.ndim != 2 or a.shape[1] != 2 or len(a) < 3:
                raise InvalidInputError(f"holes[{k}]: expected a ring of at least 3 [x, y] pairs, got shape {a.shape}")
            a.setflags(write=False)
            holes.append(a)
        put(self, "holes", tuple(holes))
        if self.cell_size is not None:
            size = float(self.cell_size)
            if not (np.isfinite(size) and size > 0):
                raise InvalidInputError(f"cell_size must be a positive number, got {self.cell_size!r}")
            put(self, "cell_size", size)
        if not isinstance(self.points, str):
            a = np.array(self.points, dtype=np.float64)
            if a.ndim != 2 or a.shape[1] != 2:
                raise InvalidInputError(f"points: expected a list of [x, y] pairs, got shape {a.shape}")
            a.setflags(write=False)
            put(self, "points", a)
        if isinstance(self.crs, bool) or not isinstance(self.crs, (str, int)):
            raise InvalidInputError(f"crs must be a string or an EPSG code, got {self.crs!r}")
        if isinstance(self.crs, str):
            crs = self.crs.strip()
            put(self, "crs", crs.lower() if crs.lower() in OUTLINE_CRS else crs)
        if not isinstance(self.cuts, (list, tuple)):
            raise InvalidInputError("cuts must be a list of polylines")
        cuts: list[tuple[int | tuple[float, float], ...]] = []
        for k, c in enumerate(self.cuts):
            if not isinstance(c, (list, tuple)) or len(c) < 2:
                raise InvalidInputError(f"cut {k} must list at least two points")
            try:
                cuts.append(tuple(outline_point(v) for v in c))
            except InvalidInputError as exc:
                raise InvalidInputError(f"cut {k}: {exc}") from None
        put(self, "cuts", tuple(cuts))
        if not isinstance(self.blocks, (list, tuple)) or not self.blocks:
            raise InvalidInputError("needs [[outline.blocks]] tables")
        put(self, "blocks", tuple(self.blocks))
        if self.origin is not None:
            put(self, "origin", (float(self.origin[0]), float(self.origin[1])))
        if self.snap is not None:
            put(self, "snap", float(self.snap))
        if isinstance(self.multiple, bool) or not isinstance(self.multiple, int) or self.multiple < 1:
            raise InvalidInputError("multiple must be a positive integer")
        validate_count(self.multiple, name="multiple")

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, OutlineSection):
            return NotImplemented
        same_points = (
            self.points == other.points
            if isinstance(self.points, str) or isinstance(other.points, str)
            else np.array_equal(self.points, other.points)
        )
        same_holes = len(self.holes) == len(other.holes) and all(
            np.array_equal(a, b) for a, b in zip(self.holes, other.holes, strict=True)
        )
        return (
            same_points
            and same_holes
            and all(
                getattr(self, f.name) == getattr(other, f.name)
                for f in dataclasses.fields(self)
                if f.name not in ("points", "holes")
            )
        )

    __hash__ = None  # type: ignore[assignment]


def _ring(points: Any, where: str) -> np.ndarray:
    a = np.array(points, dtype=np.float64)
    if a.ndim != 2 or a.shape[1] != 2 or len(a) < 3:
        raise InvalidInputError(f"{where}: expected a ring of at least 3 [x, y] pairs, got shape {a.shape}")
    if not np.isfinite(a).all():
        raise InvalidInputError(f"{where}: a coordinate is not a finite number")
    a.setflags(write=False)
    return a


@dataclass(frozen=True, slots=True, eq=False)
class LakeSection:
    """``[lake]``: the water a case was made from, as imported, and how to lay it out again.

    ``shore`` and ``islands`` are rings of ``[x, y]`` in the case's coordinates, as the outline
    file gave them (an ``[outline]`` case's own shore carries every vertex its blocks put on it;
    a one-block case has no islands at all); ``cell_size`` (None: the automatic size),
    ``regular`` and ``single`` are the layout settings (``meshcore mesh --cell-size``,
    ``--regular``, a layout for one index space).  ``notes`` and ``details`` are what the layout
    changed in the water (an island left out, a shore smoothed; :attr:`meshcore.layout.Layout.notes`):
    the case's blocks cannot tell them again.  Written by the app's *Save project*, so that a
    reopened lake is the one imported; ``meshcore generate`` grids the blocks and does not read it.
    """

    shore: np.ndarray
    islands: tuple[np.ndarray, ...] = ()
    cell_size: float | None = None
    regular: bool = False
    single: bool = False
    notes: tuple[str, ...] = ()
    details: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        put = object.__setattr__
        put(self, "shore", _ring(self.shore, "shore"))
        put(self, "islands", tuple(_ring(h, f"islands[{k}]") for k, h in enumerate(self.islands)))
        if self.cell_size is not None:
            size = float(self.cell_size)
            if not (np.isfinite(size) and size > 0):
                raise InvalidInputError(f"cell_size must be a positive number, got {self.cell_size!r}")
            put(self, "cell_size", size)
        for name in ("regular", "single"):
            if not isinstance(getattr(self, name), bool):
                raise InvalidInputError(f"{name} must be true or false, got {getattr(self, name)!r}")
        for name in ("notes", "details"):
            texts = getattr(self, name)
            if isinstance(texts, str) or not all(isinstance(t, str) for t in texts):
                raise InvalidInputError(f"{name} must be a list of strings, got {texts!r}")
            put(self, name, tuple(texts))

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, LakeSection):
            return NotImplemented
        return (
            np.array_equal(self.shore, other.shore)
            and len(self.islands) == len(other.islands)
            and all(np.array_equal(a, b) for a, b in zip(self.islands, other.islands, strict=True))
            and (self.cell_size, self.regular, self.single) == (other.cell_size, other.regular, other.single)
            and (self.notes, self.details) == (other.notes, other.details)
        )

    __hash__ = None  # type: ignore[assignment]


@dataclass(frozen=True, eq=False)
class Case:
    """A whole case: blocks, solver settings and the optional multiblock sections.

    ``crs`` is the top-level ``crs`` table (``crs``, ``origin``, ``source_crs``,
    ``source``; :func:`meshcore.crs.frame_from_case`).  A case is *multiblock*
    when it has a ``[multiblock]`` table, ``[[interfaces]]`` or an ``[outline]``.  ``lake``: the
    water the case was made from (:class:`LakeSection`; not read by the generator).
    """

    blocks: tuple[BlockSpec, ...] = ()
    title: str = ""
    description: str = ""
    solver: SolverSpec = field(default_factory=SolverSpec)
    crs: Mapping[str, Any] | None = None
    multiblock: MultiblockSection | None = None
    interfaces: tuple[InterfaceEntry, ...] = ()
    outline: OutlineSection | None = None
    lake: LakeSection | None = None
    path: Path | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "blocks", tuple(self.blocks))
        object.__setattr__(self, "interfaces", tuple(self.interfaces))
        if self.crs is not None:
            object.__setattr__(self, "crs", dict(self.crs))

    @property
    def is_multiblock(self) -> bool:
        """True when the blocks are solved together (``[multiblock]``, ``[[interfaces]]``, ``[outline]``)."""
        return self.multiblock is not None or bool(self.interfaces) or self.outline is not None

    @property
    def settings(self) -> MultiblockSection:
        """The ``[multiblock]`` settings (defaults when the table is absent)."""
        return self.multiblock or MultiblockSection()

    @property
    def repair(self) -> str:
        """``solver.repair``."""
        return self.solver.repair

    @property
    def source(self) -> str:
        """The case file's name for messages (``<case>`` when it was not read from a file)."""
        return str(self.path) if self.path else "<case>"

    def replaced(self, **changes: Any) -> Case:
        return dataclasses.replace(self, **changes)
