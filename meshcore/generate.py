"""From a block spec to a smooth grid: the block pipeline, written once.

``borders → (re-sample by curve + distribution) → algebraic grid → elliptic
solve → fold-free step``.  :func:`run_block` is the pipeline as a generator
of typed events; :func:`generate_block` (the library call, case files, the
CLI) drains it and the app's solver worker iterates it.

Events, in order::

    StartGrid(grid, algebraic)        the start grid (after the caller's warm start)
    SolverProgress(...)               snapshots of the elliptic solve (0 or more)
    Repaired(grid, before, result)    the fold-free step changed the grid (0 or 1)
    Done(grid, algebraic, warnings)   the final grid and the warnings of the run

Rules that live here only: a C-grid (``control.wake > 0``) takes its four
borders node by node; grid control slides floating nodes on the *input*
polylines; ``method="foldfree"`` minimises the barrier functional after the
solve; otherwise ``repair`` decides what happens to folded cells; a stopped
solve is returned as it is.
"""

from __future__ import annotations

import contextlib
import threading
import warnings
from collections.abc import Callable, Generator, Iterator, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from ._generators import drain
from .algebraic import algebraic_grid
from .boundary import Borders, borders_from_loop, borders_from_polylines
from .elliptic import EllipticConfig, SolverProgress, iterate
from .errors import InvalidInputError, MeshcoreWarning
from .grid import BORDER_NAMES, StructuredGrid
from .spec import BlockSpec, SolverSpec

__all__ = [
    "BlockEvent",
    "Done",
    "Repaired",
    "StartGrid",
    "block_borders",
    "generate_block",
    "initial_grid",
    "prepare_borders",
    "run_block",
]


@dataclass(frozen=True, slots=True, eq=False)
class StartGrid:
    """The grid the solve starts from, and the block's algebraic grid."""

    grid: StructuredGrid
    algebraic: StructuredGrid


@dataclass(frozen=True, slots=True, eq=False)
class Repaired:
    """The fold-free step changed the grid (``result``: a :class:`meshcore.foldfree.FoldFreeResult`)."""

    grid: StructuredGrid
    before: StructuredGrid
    result: Any


@dataclass(frozen=True, slots=True, eq=False)
class Done:
    """The final grid, the algebraic grid and the warnings of the run (messages)."""

    grid: StructuredGrid
    algebraic: StructuredGrid
    warnings: tuple[str, ...] = ()


BlockEvent = StartGrid | SolverProgress | Repaired | Done


# ------------------------------------------------------------------ borders
def _raw_borders(spec: BlockSpec, where: str) -> Borders:
    """The boundary as given (validated, corners snapped), before any re-sampling."""
    if spec.boundary is not None:
        if len(spec.points):
            raise InvalidInputError("give either four borders or loop + corners, not both")
        if spec.wake:
            # C-grid: the bottom border folds back on itself along the wake cut, so the
            # self-intersection check does not apply; the nodes are used as given
            if spec.cells is not None:
                raise InvalidInputError(
                    "a C-grid (control wake > 0) needs four borders given node by node (no cells=, no loop)"
                )
            return borders_from_polylines(*spec.boundary, check_intersections=False)
        return borders_from_polylines(*spec.boundary, periodic=spec.periodic, where=where)
    if spec.wake:
        raise InvalidInputError(
            "a C-grid (control wake > 0) needs four borders given node by node (no cells=, no loop)"
        )
    if spec.corners is None:
        raise InvalidInputError('a closed loop needs four corner indices (corners=) or corners="auto"')
    corners = spec.corners
    if isinstance(corners, str) and corners == "auto":
        from .corners import choose_corners

        corners = choose_corners(spec.points)
    b = borders_from_loop(spec.points, corners, where=where)
    if spec.periodic:
        raise InvalidInputError("periodic=True needs four borders (left = right is the seam)")
    return b


def block_borders(spec: BlockSpec, *, where: str = "") -> tuple[Borders, Borders]:
    """The block's boundary nodes and its input borders: ``(nodes, given)``.

    ``nodes`` are re-sampled to ``spec.cells`` (or are the given points when
    ``cells`` is None); ``given`` are the validated input polylines (floating
    nodes of grid control slide on them).  Raises a MeshcoreError naming the
    problem.
    """
    raw = _raw_borders(spec, where)
    if spec.cells is None:
        if any(s.distribution != "uniform" for s in spec.border_specs().values()):
            raise InvalidInputError("border distributions need cells= (the borders are re-sampled)")
        raw.check_counts()
        return raw, raw
    nodes = raw.resampled(spec.cells, specs=spec.border_specs(), curve=spec.curve, snap_angle=spec.snap_angle)
    return nodes, raw


def initial_grid(
    borders: Borders,
    *,
    initial: str = "weighted",
    weights: tuple[float, float] = (0.5, 0.5),
    names: Mapping[str, str] | None = None,
) -> StructuredGrid:
    """The algebraic start grid (``weighted`` = paper eq. 34, or ``tfi``)."""
    try:
        w = tuple(weights)
    except TypeError:
        raise InvalidInputError(f"weights must be a pair (p13_x, p13_y), got {weights!r}") from None
    if len(w) != 2:
        raise InvalidInputError(f"weights must be a pair (p13_x, p13_y), got {weights!r}")
    g = algebraic_grid(borders, initial, weights=w)  # type: ignore[arg-type]
    return g.replaced(names=dict(names or {}))


# ----------------------------------------------------------------- pipeline
@contextlib.contextmanager
def _recorded(into: list[str]) -> Iterator[None]:
    """Collect the :class:`MeshcoreWarning` messages of a block of code; pass others on.

    (``warnings.catch_warnings`` is process-wide: keep the block short.)
    """
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        yield
    for w in caught:
        if issubclass(w.category, MeshcoreWarning):
            if str(w.message) not in into:
                into.append(str(w.message))
        else:
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)


def run_block(
    spec: BlockSpec,
    solver: SolverSpec | None = None,
    *,
    start: Callable[[StructuredGrid], StructuredGrid] | None = None,
    stop_event: threading.Event | None = None,
    smooth: bool = True,
    where: str | None = None,
) -> Generator[BlockEvent, Any, StructuredGrid]:
    """Generate one block, yielding typed events; returns the final grid.

    Parameters
    ----------
    spec : BlockSpec
        The block.
    solver : SolverSpec, optional
        The solve (default settings when None).
    start : callable, optional
        ``start(algebraic) -> grid``: the grid to start the solve from (a warm
        start); the algebraic grid by default.
    stop_event : threading.Event, optional
        Cooperative stop (checked every sweep/cycle); ``gen.send("stop")`` too.
    smooth : bool
        ``False``: stop after the algebraic grid.
    where : str, optional
        Prefix of boundary error messages (default: the block name).

    Yields
    ------
    StartGrid, SolverProgress, Repaired, Done
        See the module docstring.  Values sent to the generator go to
        :func:`meshcore.elliptic.iterate` (``"stop"``, a new ``EllipticConfig``).
    """
    solver = solver or SolverSpec()
    notes: list[str] = []
    with _recorded(notes):
        nodes, given = block_borders(spec, where=spec.name if where is None else where)
        g0 = initial_grid(nodes, initial=spec.initial, weights=spec.weights, names=spec.border_names())
        sources = None
        if smooth and spec.control is not None:
            from .control import make_sources

            sources = make_sources(spec.control, periodic=spec.periodic, curves={n: given[n] for n in BORDER_NAMES})
    g = start(g0) if start is not None and smooth else g0
    yield StartGrid(g, g0)
    if smooth:
        g = yield from iterate(g, solver.config(), p=spec.p, q=spec.q, sources=sources, stop_event=stop_event)
        stopped = g.info.message == "stopped" or (stop_event is not None and stop_event.is_set())
        if not stopped and (solver.foldfree or solver.repair != "off"):
            with _recorded(notes):
                fixed = _fold_free(g, spec, solver)
            if fixed.grid is not g:
                yield Repaired(fixed.grid, g, fixed)
                g = fixed.grid
    yield Done(g, g0, tuple(notes))
    return g


def _fold_free(grid: StructuredGrid, spec: BlockSpec, solver: SolverSpec) -> Any:
    """The fold-free step: :func:`meshcore.foldfree.smooth` or :func:`~meshcore.foldfree.repair`."""
    from . import foldfree

    strict = solver.repair == "strict"
    if solver.foldfree:
        if spec.p is not None or spec.q is not None:
            warnings.warn(
                'method="foldfree": the source terms P, Q shape only the elliptic start grid; '
                "the fold-free minimisation has none (the default method keeps them and "
                "repairs only the invalid cells)",
                MeshcoreWarning,
                stacklevel=2,
            )
        return foldfree.smooth(grid, strict=strict)
    return foldfree.repair(grid, strict=strict)


# ----------------------------------------------------------- keyword API
def _spec_from_keywords(bottom: Any, right: Any, top: Any, left: Any, loop: Any, corners: Any, **kw: Any) -> BlockSpec:
    given = [bottom, right, top, left]
    if loop is not None:
        if any(v is not None for v in given):
            raise InvalidInputError("give either four borders or loop + corners, not both")
        return BlockSpec(points=loop, corners=corners, **kw)
    missing = [n for n, v in zip(BORDER_NAMES, given, strict=True) if v is None]
    if missing:
        raise InvalidInputError(f"missing border(s): {', '.join(missing)}")
    return BlockSpec(boundary=tuple(given), **kw)  # type: ignore[arg-type]


def prepare_borders(
    bottom: Any = None,
    right: Any = None,
    top: Any = None,
    left: Any = None,
    *,
    loop: Any = None,
    corners: Any = None,
    cells: Any = None,
    borders: Mapping[str, Any] | None = None,
    curve: str = "linear",
    periodic: bool = False,
    snap_angle: float | None = None,
    where: str = "",
) -> Borders:
    """Validate the boundary and re-sample it (or use the given nodes when ``cells`` is None)."""
    spec = _spec_from_keywords(
        bottom,
        right,
        top,
        left,
        loop,
        corners,
        cells=cells,
        borders=borders or {},
        curve=curve,
        periodic=periodic,
        snap_angle=snap_angle,
    )
    return block_borders(spec, where=where)[0]


def generate_block(
    bottom: Any = None,
    right: Any = None,
    top: Any = None,
    left: Any = None,
    *,
    loop: Any = None,
    corners: Any = None,
    cells: Any = None,
    weights: tuple[float, float] = (0.5, 0.5),
    initial: str = "weighted",
    curve: str = "linear",
    borders: Mapping[str, Any] | None = None,
    method: str = "auto",
    tolerance: float | None = None,
    max_iterations: int = 50_000,
    omega: float | None = None,
    threads: int = 0,
    p: np.ndarray | None = None,
    q: np.ndarray | None = None,
    config: EllipticConfig | None = None,
    callback: Callable[[SolverProgress], Any] | None = None,
    smooth: bool = True,
    periodic: bool = False,
    repair: str = "auto",
    snap_angle: float | None = None,
    control: Any = None,
    solver: SolverSpec | None = None,
) -> StructuredGrid:
    """Generate one block's grid from its boundary (drains :func:`run_block`).

    Either keywords or the specs themselves: ``generate_block(spec, solver)``
    with a :class:`~meshcore.BlockSpec` and a :class:`~meshcore.SolverSpec`
    (then only ``callback`` and ``smooth`` count).  Warnings of the run are
    re-emitted as :class:`~meshcore.errors.MeshcoreWarning`.

    Parameters
    ----------
    bottom, right, top, left : (k, 2) array_like
        Border polylines in the orientation of :mod:`meshcore.grid` (bottom/top
        left→right, left/right bottom→top): ``BlockSpec.boundary``.
    loop, corners : optional
        Or a closed loop and ``(sw, se, ne, nw)`` indices / ``"auto"``:
        ``BlockSpec.points``, ``BlockSpec.corners``.
    cells, weights, initial, curve, borders, periodic, snap_angle, control, p, q
        As the fields of :class:`~meshcore.BlockSpec` (``cells=None``: the given
        points are the nodes; ``borders``: per-border distributions, e.g.
        ``{"bottom": {"distribution": "tanh", "first": 0.01}}``).
    method, tolerance, max_iterations, omega, threads, repair
        As the fields of :class:`~meshcore.SolverSpec` (``repair="auto"``:
        folded or non-convex cells are repaired by the fold-free barrier
        method; ``"strict"`` raises :class:`~meshcore.errors.FoldedGridError`
        when no fold-free grid exists; ``"off"`` keeps the elliptic grid).
    config : EllipticConfig, optional
        Solver settings as an :class:`~meshcore.elliptic.EllipticConfig` (``repair`` still counts).
    callback : callable, optional
        Called with each :class:`~meshcore.elliptic.SolverProgress`; return
        ``"stop"`` to stop early (the grid is then returned as it is).
    smooth : bool
        ``False`` returns the algebraic grid without the elliptic solve.
    solver : SolverSpec, optional
        All solver settings at once.

    Returns
    -------
    StructuredGrid
        ``grid.x, grid.y`` of shape ``(ni + 1, nj + 1)``; ``grid.converged``,
        ``grid.iterations`` and ``grid.residual`` describe the solve.

    Examples
    --------
    >>> import meshcore
    >>> g = meshcore.generate_block([[0, 0], [2, 0]], [[2, 0], [2, 1]],
    ...                             [[0, 1], [2, 1]], [[0, 0], [0, 1]], cells=(4, 2))
    >>> g.shape, g.converged
    ((5, 3), True)
    """
    if isinstance(bottom, BlockSpec):
        spec = bottom
        if isinstance(right, SolverSpec):
            solver = right
    else:
        spec = _spec_from_keywords(
            bottom,
            right,
            top,
            left,
            loop,
            corners,
            cells=cells,
            weights=weights,
            initial=initial,
            curve=curve,
            borders=borders or {},
            periodic=periodic,
            snap_angle=snap_angle,
            control=control,
            p=p,
            q=q,
        )
    if solver is None:
        if config is not None:
            solver = SolverSpec.from_config(config, repair=repair)
        else:
            solver = SolverSpec(
                method=method,
                tolerance=tolerance,
                max_iterations=max_iterations,
                omega=omega,
                threads=threads,
                repair=repair,
            )
    return _drain(run_block(spec, solver, smooth=smooth, where=""), callback)


def _drain(
    gen: Generator[BlockEvent, Any, StructuredGrid], callback: Callable[[SolverProgress], Any] | None = None
) -> StructuredGrid:
    """Run :func:`run_block` to the end; ``callback`` sees the progress; warnings are re-emitted."""

    def on_event(event: BlockEvent) -> Any:
        if isinstance(event, Done):
            for msg in event.warnings:
                warnings.warn(msg, MeshcoreWarning, stacklevel=5)  # at generate_block's caller
        elif isinstance(event, SolverProgress) and callback is not None:
            return callback(event)
        return None

    return drain(gen, on_event)
