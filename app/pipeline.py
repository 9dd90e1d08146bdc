"""From a project to grids: the generator the solver worker runs (no Qt).

:func:`solve_project` runs meshcore's block pipeline (:func:`meshcore.run_block`)
on every ready block and yields ``(block_index, event)`` pairs — meshcore's
typed events (``StartGrid``, ``SolverProgress``, ``Repaired``, ``Done``) —
and returns a :class:`BlockResult`.  A multiblock case yields
``(ALL_BLOCKS, SolverProgress)`` with every block's grid (one generator, no
second thread); a lake layout (:mod:`app.lake_solve`) likewise.  What is the app's own is
the warm start:

Warm start (live remesh): when the previous grid of a block has the same
shape, the candidate start grid is ``A_new + (G_old − A_old)`` — the new
algebraic grid plus the correction the solver applied last time.  Boundary
nodes stay exactly those of ``A_new`` (the correction vanishes on the
boundary).  It is used when its residual (the solver's stopping measure) is
smaller than that of ``A_new``; after a small edit it usually is.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Generator, Mapping

import numpy as np

from meshcore import Done, StartGrid, StructuredGrid, run_block
from meshcore.elliptic import residual

from .project import Block, Project
from .results import ALL_BLOCKS, BlockResult

__all__ = [
    "ALL_BLOCKS",
    "BlockResult",
    "block_initial_grid",
    "solve_project",
    "warm_start",
    "warmup",
]


def warm_start(previous: tuple[StructuredGrid, StructuredGrid]) -> Callable[[StructuredGrid], StructuredGrid]:
    """The warm-start rule: ``start(A_new)`` given ``previous = (A_old, G_old)`` (see module docstring)."""
    a_old, g_old = previous

    def start(g0: StructuredGrid) -> StructuredGrid:
        if a_old.shape != g0.shape or g_old.shape != g0.shape:
            return g0
        cand = g0.replaced(x=g0.x + (g_old.x - a_old.x), y=g0.y + (g_old.y - a_old.y))
        # keep whichever start is closer to the solution (the stopping measure)
        return cand if residual(cand) < residual(g0) else g0

    return start


def block_initial_grid(block: Block) -> StructuredGrid:
    """The algebraic start grid of a ready block (may raise MeshcoreError)."""
    gen = run_block(block, smooth=False)
    event = next(gen)
    gen.close()
    assert isinstance(event, StartGrid)
    return event.algebraic


def solve_project(
    project: Project,
    *,
    warm: Mapping[int, tuple[StructuredGrid, StructuredGrid]] | None = None,
    stop_event: threading.Event | None = None,
    report_interval: float = 1 / 40,
    smooth: bool = True,
    blocks: list[int] | None = None,
    hold: threading.Event | None = None,
    notify: Callable[[str, str], None] | None = None,
) -> Generator[tuple[int, object], object, BlockResult]:
    """Solve every ready block; yield ``(index, event)``; return :class:`BlockResult`.

    ``warm`` maps a block index to ``(previous algebraic grid, previous grid)``; ``hold``: a lake
    layout's warm solve waits for it before its final grid; ``notify``: told of a lake grid made again
    (both :func:`app.lake_solve.solve_layout`).
    """
    solver = project.solver.replaced(report_interval=report_interval)
    if project.multiblock is not None:
        return (yield from _solve_multiblock(project, solver, stop_event))
    if project.layout is not None:  # a lake layout: one orthogonal grid over all its blocks
        from .lake_solve import solve_layout

        return (yield from solve_layout(project.lake, warm=warm, stop_event=stop_event, hold=hold, notify=notify))
    grids: dict[int, StructuredGrid] = {}
    starts: dict[int, StructuredGrid] = {}
    notes: list[str] = []
    indices = blocks if blocks is not None else range(len(project.blocks))
    for k in indices:
        block = project.blocks[k]
        if not block.ready:
            continue
        start = warm_start(warm[k]) if warm and k in warm else None
        gen = run_block(block, solver, start=start, stop_event=stop_event, smooth=smooth)
        try:
            event = next(gen)
            while True:
                if isinstance(event, StartGrid):
                    starts[k] = event.algebraic
                elif isinstance(event, Done):
                    # meshcore names the block already (run_block's ``where``): not twice
                    notes += [w if w.startswith(f"{block.name}: ") else f"{block.name}: {w}" for w in event.warnings]
                cmd = yield k, event
                event = gen.send(cmd)
        except StopIteration as fin:
            grids[k] = fin.value
        if stop_event is not None and stop_event.is_set():
            break
    return BlockResult(grids=grids, initial=starts, warnings=tuple(notes))


def _solve_multiblock(project: Project, solver, stop_event):
    """A multiblock case: all blocks solved together (:func:`meshcore.case.iterate_multiblock_case`).

    Yields the algebraic start grids, then ``(ALL_BLOCKS, SolverProgress)``
    with every block's current grid; returns every block's grid.
    """
    from meshcore.case import case_topology, iterate_multiblock_case
    from meshcore.multiblock import initial_grids

    case = project.multiblock
    topo = case_topology(case)
    starts = dict(enumerate(initial_grids(topo)))
    for k, g in starts.items():
        yield k, StartGrid(g, g)
    gen = iterate_multiblock_case(case, solver, topology=topo, initial=list(starts.values()), stop_event=stop_event)
    try:
        snap = next(gen)
        while True:
            cmd = yield ALL_BLOCKS, snap
            snap = gen.send(cmd)
    except StopIteration as fin:
        mb = fin.value
    return BlockResult(grids=dict(enumerate(mb.grids)), initial=starts, multiblock=mb)


def folded_cells(grid: StructuredGrid) -> np.ndarray:
    """``(k, 2)`` indices of cells with non-positive area (cheap; for live checks)."""
    x, y = grid.x, grid.y
    area = 0.5 * (
        (x[1:, 1:] - x[:-1, :-1]) * (y[:-1, 1:] - y[1:, :-1]) - (x[:-1, 1:] - x[1:, :-1]) * (y[1:, 1:] - y[:-1, :-1])
    )
    return np.argwhere(area <= 0)


def warmup() -> None:
    """Load the numba kernels and shapely and run the whole pipeline once on a tiny square and strip.

    Run in a background thread at start-up so that the first real solve (and
    the first drag with auto-generate) pays no one-time costs.
    """
    from meshcore import elliptic

    elliptic.warmup()
    sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [0.0, 0.5]])
    project = Project(blocks=(Block(points=sq, closed=True, corners=(0, 1, 2, 3), cells=(4, 4)),))
    for _ in solve_project(project):
        pass
    # the lake grid's kernels and the layout's libraries (the first Auto layout pays nothing either)
    from meshcore.lakegrid import mesh_layout
    from meshcore.layout import auto_layout

    strip = np.array([[0.0, 0.0], [4.0, 0.0], [4.0, 1.0], [0.0, 1.0]])
    mesh_layout(auto_layout(strip, cell_size=0.25, multiple=2), levels=1)
