"""From a project to grids: the generator the solver worker runs (no Qt).

:func:`solve_project` walks the ready blocks, builds each block's algebraic
start grid with meshcore and iterates :func:`meshcore.iterate` on it, yielding
``(block_index, SolverProgress)`` snapshots and returning ``{index: grid}``.

Warm start (live remesh): when the previous grid of a block has the same
shape, the candidate start grid is ``A_new + (G_old − A_old)`` — the new
algebraic grid plus the correction the solver applied last time.  Boundary
nodes stay exactly those of ``A_new`` (the correction vanishes on the
boundary).  It is used when its residual (the solver's stopping measure) is
smaller than that of ``A_new``; after a small edit it usually is.
"""

from __future__ import annotations

import threading
from collections.abc import Generator, Mapping
from dataclasses import dataclass

import numpy as np

from meshcore import StructuredGrid, borders_from_polylines, initial_grid, iterate, prepare_borders
from meshcore.elliptic import residual

from .project import Block, Project

__all__ = ["BlockResult", "block_borders", "block_initial_grid", "solve_project", "warmup"]


def _wake(block: Block) -> int:
    c = block.control
    if c is None:
        return 0
    w = getattr(c, "wake", None)
    if w is None and isinstance(c, Mapping):
        w = c.get("wake", 0)
    return int(w or 0)


def block_borders(block: Block):
    """The re-sampled :class:`meshcore.Borders` of a ready block (may raise MeshcoreError)."""
    specs = block.border_specs()
    cells = None if block.keep_nodes else block.cells
    if block.boundary is not None:
        # copies: meshcore snaps corners in place (read-only input arrays would fail)
        b, r, t, l = (np.array(a) for a in block.boundary)
        if _wake(block):
            # a C-grid: the bottom folds back on itself along the wake cut; nodes as given
            bd = borders_from_polylines(b, r, t, l, check_intersections=False)
            bd.check_counts()
            return bd
        return prepare_borders(
            b,
            r,
            t,
            l,
            cells=cells,
            borders=specs,
            curve=block.curve,
            periodic=block.periodic,
            snap_angle=block.snap_angle,
            where=block.name,
        )
    return prepare_borders(
        loop=np.array(block.points),
        corners=block.corners,
        cells=cells,
        borders=specs,
        curve=block.curve,
        snap_angle=block.snap_angle,
        where=block.name,
    )


def block_sources(block: Block):
    """The control-function updater of a block (None without ``control``), as in generate_block."""
    if block.control is None:
        return None
    import warnings

    from meshcore import MeshcoreError, borders_from_loop
    from meshcore.control import make_sources

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # already reported when the borders were built
            if block.boundary is not None:
                raw = borders_from_polylines(
                    *(np.array(a) for a in block.boundary),
                    periodic=block.periodic,
                    check_intersections=not _wake(block),
                )
            else:
                raw = borders_from_loop(np.array(block.points), block.corners)
        curves = {n: raw[n] for n in ("bottom", "right", "top", "left")}
    except MeshcoreError:
        curves = None
    return make_sources(block.control, periodic=block.periodic, curves=curves)


def block_initial_grid(block: Block) -> StructuredGrid:
    """The algebraic start grid of a ready block (may raise MeshcoreError)."""
    names = {n: s.name for n, s in block.borders if s.name}
    return initial_grid(block_borders(block), initial=block.initial, weights=block.weights, names=names)


@dataclass(frozen=True, slots=True)
class ResidualProgress:
    """Progress of a solve that has no grid snapshots (multiblock): relative residuals only.

    Yielded as ``(ALL_BLOCKS, progress, None)``.
    """

    iteration: int
    residual: float
    history: tuple[tuple[int, float], ...]
    method: str = "multiblock"
    tolerance: float = float("nan")


#: block index of progress items that concern all blocks at once
ALL_BLOCKS = -1


@dataclass(frozen=True, slots=True)
class BlockResult:
    """What the worker returns: final grids and start grids per block."""

    grids: dict
    initial: dict
    multiblock: object = None  # the meshcore MultiBlockGrid of a multiblock case (connectivity)


def solve_project(
    project: Project,
    *,
    warm: Mapping[int, tuple[StructuredGrid, StructuredGrid]] | None = None,
    stop_event: threading.Event | None = None,
    report_interval: float = 1 / 40,
    smooth: bool = True,
    blocks: list[int] | None = None,
) -> Generator[tuple[int, object], object, BlockResult]:
    """Solve every ready block; yield snapshots; return :class:`BlockResult`.

    Yields ``(index, item, algebraic)``: first ``item`` = the start grid
    (a :class:`StructuredGrid`), then :class:`meshcore.SolverProgress`
    snapshots; ``algebraic`` is the block's algebraic grid (for warm starts).
    ``warm`` maps a block index to ``(previous algebraic grid, previous grid)``.
    """
    cfg = project.solver.config(report_interval=report_interval)
    if project.multiblock is not None:
        return (yield from _solve_multiblock(project, cfg, stop_event))
    grids: dict[int, StructuredGrid] = {}
    starts: dict[int, StructuredGrid] = {}
    indices = blocks if blocks is not None else range(len(project.blocks))
    for k in indices:
        block = project.blocks[k]
        if not block.ready:
            continue
        g0 = block_initial_grid(block)
        starts[k] = g0
        start = g0
        if warm and k in warm:
            a_old, g_old = warm[k]
            if a_old.shape == g0.shape and g_old.shape == g0.shape:
                cand = g0.replaced(x=g0.x + (g_old.x - a_old.x), y=g0.y + (g_old.y - a_old.y))
                # keep whichever start is closer to the solution (the stopping measure)
                if residual(cand) < residual(g0):
                    start = cand
        yield k, start, g0
        if not smooth:
            grids[k] = g0
            continue
        gen = iterate(start, cfg, stop_event=stop_event, sources=block_sources(block))
        try:
            snap = next(gen)
            while True:
                cmd = yield k, snap, g0
                snap = gen.send(cmd)
        except StopIteration as fin:
            grids[k] = fin.value
        if stop_event is not None and stop_event.is_set():
            break
        grids[k] = _fold_free(grids[k], project.solver)
    return BlockResult(grids=grids, initial=starts)


def _solve_multiblock(project: Project, cfg, stop_event):
    """A multiblock case: all blocks solved together by :func:`meshcore.multiblock.solve_multiblock`.

    Yields the algebraic start grids (for display), then runs the global
    solve, whose callback honours ``stop_event``; returns every block's grid.
    """
    from meshcore.multiblock import initial_grids, solve_multiblock
    from meshcore.multiblock.case import _settings, case_topology

    case = project.multiblock
    mode, start = _settings(case)
    topo = case_topology(case)
    starts = dict(enumerate(initial_grids(topo)))
    for k, g in starts.items():
        yield k, g, g

    history: list[tuple[int, float]] = []
    out: dict = {}

    def callback(iteration, rel_residual):
        history.append((int(iteration), float(rel_residual)))
        return "stop" if stop_event is not None and stop_event.is_set() else None

    def run() -> None:  # the global solve reports only through its callback: run it aside
        try:
            out["mb"] = solve_multiblock(topo, mode=mode, start=start, config=cfg, callback=callback)
        except BaseException as exc:  # handed back to the worker below
            out["error"] = exc

    th = threading.Thread(target=run, name="multiblock-solve", daemon=True)
    th.start()
    seen = 0
    while th.is_alive():
        th.join(cfg.report_interval)
        if len(history) > seen:
            seen = len(history)
            it, r = history[-1]
            yield ALL_BLOCKS, ResidualProgress(it, r, tuple(history)), None
    if "error" in out:
        raise out["error"]
    mb = out["mb"]
    grids = dict(enumerate(mb.grids))
    return BlockResult(grids=grids, initial=starts, multiblock=mb)


def _fold_free(grid: StructuredGrid, solver) -> StructuredGrid:
    """The fold-free step of :func:`meshcore.generate_block` (repair, or smooth for "foldfree")."""
    try:
        from meshcore import foldfree
    except ImportError:  # older meshcore
        return grid
    if solver.method == "foldfree":
        return foldfree.smooth(grid, strict=False).grid
    if solver.repair == "off":
        return grid
    return foldfree.repair(grid, strict=False).grid


def folded_cells(grid: StructuredGrid) -> np.ndarray:
    """``(k, 2)`` indices of cells with non-positive area (cheap; for live checks)."""
    x, y = grid.x, grid.y
    area = 0.5 * (
        (x[1:, 1:] - x[:-1, :-1]) * (y[:-1, 1:] - y[1:, :-1]) - (x[:-1, 1:] - x[1:, :-1]) * (y[1:, 1:] - y[:-1, :-1])
    )
    return np.argwhere(area <= 0)


def warmup() -> None:
    """Load the numba kernels and shapely and run the whole pipeline once on a tiny square.

    Run in a background thread at start-up so that the first real solve (and
    the first drag with auto-generate) pays no one-time costs.
    """
    from meshcore import elliptic

    elliptic.warmup()
    sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [0.0, 0.5]])
    project = Project(blocks=(Block(points=sq, closed=True, corners=(0, 1, 2, 3), cells=(4, 4)),))
    gen = solve_project(project)
    try:
        while True:
            next(gen)
    except StopIteration:
        pass
