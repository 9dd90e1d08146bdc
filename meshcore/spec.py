"""What to generate and how: :class:`BlockSpec` (one block) and :class:`SolverSpec` (the solve).

Both are frozen.  The same two objects serve :func:`meshcore.generate_block`,
:func:`meshcore.run_block`, case files (:mod:`meshcore.case`), the command line
and the app (whose editable block *is* a :class:`BlockSpec`).

A block's boundary is given in one of two forms:

* a closed loop ``points`` plus four corner indices ``corners = (sw, se, ne, nw)``
  (or ``corners="auto"``: :func:`meshcore.corners.choose_corners`);
* four border polylines ``boundary = (bottom, right, top, left)`` in the
  orientation of :mod:`meshcore.grid`.

Examples
--------
>>> from meshcore import BlockSpec, SolverSpec, generate_block
>>> spec = BlockSpec(points=[[0, 0], [2, 0], [2, 1], [0, 1]], corners=(0, 1, 2, 3), cells=(4, 2))
>>> spec.cell_counts, SolverSpec(repair="strict").config().method
((4, 2), 'auto')
>>> generate_block(spec).shape
(5, 3)
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ._validation import validate_choice, validate_count, validate_indices, validate_points
from .boundary import BorderSpec, signed_area
from .elliptic import EllipticConfig
from .errors import InvalidInputError
from .grid import BORDER_NAMES

__all__ = ["REPAIR_CHOICES", "BlockSpec", "SolverSpec"]

#: ``SolverSpec.repair``: fold-free repair of invalid cells after the solve.
REPAIR_CHOICES = ("auto", "strict", "off")


def _frozen_points(points: Any, name: str, min_points: int) -> np.ndarray:
    """``points`` as a read-only ``(n, 2)`` float array; ``None`` or empty gives ``(0, 2)``."""
    if points is None or (isinstance(points, (np.ndarray, list, tuple)) and len(points) == 0):
        a = np.zeros((0, 2))
    else:
        a = validate_points(points, name=name, min_points=min_points).copy()
    a.setflags(write=False)
    return a


def _frozen_array(a: Any) -> np.ndarray | None:
    if a is None:
        return None
    arr = np.array(a, dtype=np.float64)
    arr.setflags(write=False)
    return arr


def _same(a: Any, b: Any) -> bool:
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        if a is None or b is None:
            return a is b
        return a.shape == b.shape and bool(np.array_equal(a, b))
    if isinstance(a, tuple) and isinstance(b, tuple):
        return len(a) == len(b) and all(_same(u, v) for u, v in zip(a, b, strict=True))
    return bool(a == b)


@dataclass(frozen=True, slots=True, eq=False)
class BlockSpec:
    """One block: its boundary, cell counts, point distributions and grid options.

    Parameters
    ----------
    name : str
        Block name (messages, exports, case files).
    points : (n, 2) array_like
        A closed boundary loop (first point not repeated, or repeated; either
        orientation), split into the four borders at ``corners``.
    corners : (sw, se, ne, nw) or "auto", optional
        Indices into ``points``; ``"auto"`` chooses them
        (:func:`meshcore.corners.choose_corners`).
    boundary : four (k, 2) array_like, optional
        ``(bottom, right, top, left)`` polylines instead of ``points`` + ``corners``.
    cells : (ni, nj), optional
        Re-sample every border to this many cells; ``None``: the given points
        are the boundary nodes.
    borders : mapping of border name to BorderSpec (or dict, or distribution name)
        Per-border point distribution and boundary-condition name; stored as
        sorted ``(name, BorderSpec)`` pairs.
    weights : (p13_x, p13_y)
        Weights of the paper's eq. 34 (algebraic start grid).
    initial : {"weighted", "tfi"}
        Algebraic start grid.
    curve : {"linear", "cubic", "catmull-rom"}
        Boundary curve used for re-sampling.
    periodic : bool
        Periodic ξ (O-grid): left and right coincide (four borders only).
    snap_angle : float, optional
        When re-sampling, input vertices where a border turns by more than this
        many degrees get a node exactly (keeps the corners of a cutout);
        ``None`` = pure distribution (the paper).
    control : ControlSpec or mapping, optional
        Grid control (:mod:`meshcore.control`), kept as given: boundary
        orthogonality and first-cell spacing, Thomas–Middlecoff, attraction,
        floating nodes (which slide on the given border polylines), a C-grid
        wake cut; e.g. ``{"borders": {"bottom": {"spacing": 0.01}}}``.
    p, q : array_like, optional
        Fixed source terms P, Q of the node shape (zero by default).
    """

    name: str = "block"
    points: np.ndarray = field(default_factory=lambda: _frozen_points(None, "", 0))
    corners: tuple[int, int, int, int] | str | None = None
    boundary: tuple[np.ndarray, ...] | Mapping[str, Any] | None = None
    cells: tuple[int, int] | None = None
    borders: tuple[tuple[str, BorderSpec], ...] | Mapping[str, Any] = ()
    weights: tuple[float, float] = (0.5, 0.5)
    initial: str = "weighted"
    curve: str = "linear"
    periodic: bool = False
    snap_angle: float | None = None
    control: Any = None
    p: np.ndarray | None = None
    q: np.ndarray | None = None

    def __post_init__(self) -> None:
        put = object.__setattr__
        put(self, "name", str(self.name))
        put(self, "points", _frozen_points(self.points, "boundary points", 0))
        if self.boundary is not None:
            if isinstance(self.boundary, Mapping):
                missing = [n for n in BORDER_NAMES if n not in self.boundary]
                if missing:
                    raise InvalidInputError(f"missing border(s): {', '.join(missing)}")
                put(self, "boundary", tuple(self.boundary[n] for n in BORDER_NAMES))
            if len(self.boundary) != 4:
                raise InvalidInputError("boundary must be four polylines (bottom, right, top, left)")
            put(
                self,
                "boundary",
                tuple(_frozen_points(b, f"{n} border", 2) for n, b in zip(BORDER_NAMES, self.boundary, strict=True)),
            )
        if self.corners is not None and not isinstance(self.corners, str):
            put(self, "corners", validate_indices(self.corners, name="corners"))
        if self.cells is not None:
            try:
                ni, nj = self.cells
            except (TypeError, ValueError):
                raise InvalidInputError(f"cells must be a pair (ni, nj), got {self.cells!r}") from None
            put(self, "cells", (validate_count(ni, name="cells ξ (ni)"), validate_count(nj, name="cells η (nj)")))
        put(self, "borders", _border_specs(self.borders))
        try:
            w = tuple(float(v) for v in self.weights)
        except (TypeError, ValueError):
            raise InvalidInputError(f"weights must be a pair (p13_x, p13_y), got {self.weights!r}") from None
        if len(w) != 2:
            raise InvalidInputError(f"weights must be a pair (p13_x, p13_y), got {self.weights!r}")
        put(self, "weights", (w[0], w[1]))
        put(self, "initial", str(self.initial))
        put(self, "curve", str(self.curve))
        put(self, "periodic", bool(self.periodic))
        if self.snap_angle is not None:
            put(self, "snap_angle", float(self.snap_angle))
        put(self, "p", _frozen_array(self.p))
        put(self, "q", _frozen_array(self.q))

    # ------------------------------------------------------------ queries
    @property
    def ready(self) -> bool:
        """True when the boundary is complete: four borders, or a loop with corners."""
        if self.boundary is not None:
            return True
        return self.corners is not None and len(self.points) >= 4

    @property
    def wake(self) -> int:
        """Cells of the C-grid wake cut (``control.wake``; 0 = none)."""
        c = self.control
        if c is None:
            return 0
        w = c.get("wake", 0) if isinstance(c, Mapping) else getattr(c, "wake", 0)
        return int(w or 0)

    @property
    def cell_counts(self) -> tuple[int, int] | None:
        """``cells``, or the counts the given nodes imply (None when unknown)."""
        if self.cells is not None:
            return self.cells
        if self.boundary is not None:
            bottom, _right, _top, left = self.boundary
            return (len(bottom) - 1, len(left) - 1)
        if isinstance(self.corners, tuple) and len(self.points) >= 4:
            n = len(self.points)
            if np.array_equal(self.points[0], self.points[-1]):
                n -= 1
            sw, se, ne, _nw = (c % n for c in self.corners)
            if signed_area(self.points[:n]) >= 0:
                return ((se - sw) % n, (ne - se) % n)
            return ((sw - se) % n, (se - ne) % n)
        return None

    def spec(self, border: str) -> BorderSpec:
        """The :class:`BorderSpec` of ``border`` (uniform by default)."""
        return dict(self.borders).get(border, BorderSpec())

    def border_specs(self) -> dict[str, BorderSpec]:
        """The per-border specs as a dict (only the borders that have one)."""
        return dict(self.borders)

    def border_names(self) -> dict[str, str]:
        """Boundary-condition names of the borders that have one."""
        return {n: s.name for n, s in self.border_specs().items() if s.name}

    def replaced(self, **changes: Any) -> BlockSpec:
        return dataclasses.replace(self, **changes)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, BlockSpec) or type(other) is not type(self):
            return NotImplemented
        return all(_same(getattr(self, f.name), getattr(other, f.name)) for f in dataclasses.fields(self) if f.compare)

    __hash__ = None  # type: ignore[assignment]


def _border_specs(value: Any) -> tuple[tuple[str, BorderSpec], ...]:
    items = value.items() if isinstance(value, Mapping) else (value or ())
    out = {}
    for n, s in items:
        if n not in BORDER_NAMES:
            raise InvalidInputError(f"unknown border {n!r}; valid: {', '.join(BORDER_NAMES)}")
        out[n] = BorderSpec.coerce(s, border=n)
    return tuple(sorted(out.items()))


@dataclass(frozen=True, slots=True)
class SolverSpec:
    """How a block (or a multiblock case) is solved.

    The fields of :class:`meshcore.elliptic.EllipticConfig` plus the fold-free
    step after the solve.

    Parameters
    ----------
    method : str
        ``"auto"``, ``"sor"``, ``"multigrid"`` (see :class:`EllipticConfig`), or
        ``"foldfree"``: the default elliptic solve, then the barrier functional
        minimised over the whole block (:func:`meshcore.foldfree.smooth`).
    tolerance, max_iterations, omega, report_interval, threads
        As in :class:`~meshcore.elliptic.EllipticConfig` (``threads``: 0 = all
        cores on large grids, 1 = serial; every choice gives the same grid).
    repair : {"auto", "strict", "off"}
        Folded or non-convex cells after the solve: ``"auto"`` repairs them
        (:func:`meshcore.foldfree.repair`) and returns the best grid with
        ``converged=False`` when no fold-free grid exists; ``"strict"`` raises
        :class:`~meshcore.errors.FoldedGridError` then; ``"off"`` keeps the
        elliptic result.
    """

    method: str = "auto"
    tolerance: float | None = None
    max_iterations: int = 50_000
    omega: float | None = None
    report_interval: float = 1.0 / 30.0
    threads: int = 0
    repair: str = "auto"

    def __post_init__(self) -> None:
        if not isinstance(self.method, str):
            raise InvalidInputError(f"method must be a string, got {self.method!r}")
        object.__setattr__(self, "method", self.method.lower())
        object.__setattr__(self, "repair", validate_choice(self.repair, REPAIR_CHOICES, name="repair"))
        cfg = self.config()  # validates the solver fields
        for name in ("max_iterations", "threads"):  # whole numbers kept as ints (a TOML 1e4 is a float)
            object.__setattr__(self, name, getattr(cfg, name))

    @property
    def foldfree(self) -> bool:
        """True for ``method="foldfree"`` (solve, then minimise the barrier functional)."""
        return self.method == "foldfree"

    def config(self, **changes: Any) -> EllipticConfig:
        """The :class:`EllipticConfig` of the elliptic solve (``foldfree`` solves with ``"auto"``)."""
        kw = {f.name: getattr(self, f.name) for f in dataclasses.fields(EllipticConfig)}
        if self.foldfree:
            kw["method"] = "auto"
        return EllipticConfig(**(kw | changes))

    @classmethod
    def from_config(cls, config: EllipticConfig, **changes: Any) -> SolverSpec:
        """A solver spec with the settings of ``config`` (plus ``changes``, e.g. ``repair``)."""
        kw = {f.name: getattr(config, f.name) for f in dataclasses.fields(EllipticConfig)}
        return cls(**(kw | changes))

    def replaced(self, **changes: Any) -> SolverSpec:
        return dataclasses.replace(self, **changes)
