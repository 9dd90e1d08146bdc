r"""Solve a multiblock grid: ``frozen`` or ``smooth`` interfaces.

``frozen`` (the paper's way)
    Every block is solved on its own with the single-block solver
    (:func:`meshcore.elliptic.solve`, multigrid when registered and the block
    is large enough); the re-sampled interface nodes stay where they are.

``smooth``
    All blocks are assembled into one node array (each shared node stored
    once, :class:`~.topology.NodeMap`) and every node that is not on the outer
    boundary is solved: interface nodes with the same 9-point Winslow stencil
    as interior nodes, built from the neighbouring block's nodes, so grid lines
    cross interfaces without kinks.  Nodes where 3, 5, … blocks meet get a
    Laplacian update over their ring of edge neighbours (documented in
    :mod:`._kernels`).  The iteration is SOR over an explicit neighbour table
    (numba, :func:`._kernels.table_sweep`).  Two engines give the same
    iterates' fixed point: ``engine="blocks"`` (default) sweeps each block's
    interior with the single-block kernel :func:`meshcore.elliptic._kernels.sweep4`
    on the block's own array, then the border nodes with the table kernel, and
    exchanges the values next to the borders after every sweep (a
    block-Schwarz/Gauss–Seidel iteration with a one-node overlap);
    ``engine="table"`` sweeps every node through the neighbour table (about
    2× slower per sweep, measured in ``benchmarks/multiblock.py``).

    ``engine="multigrid"`` (chosen by ``"auto"`` whenever the blocks coarsen at
    all, odd cell counts included) runs a nonlinear FAS multigrid over the
    whole topology with point, line and border Gauss–Seidel as smoother
    (:mod:`.multigrid`): 3–6 cycles instead of hundreds of SOR sweeps; its
    hierarchy is cached per block structure, so a re-solve after an edit
    skips the set-up.

    The iteration starts from the algebraic grids (``start="algebraic"``,
    default) or from the ``frozen`` solution (``start="frozen"``: the blocks
    are first solved separately with the single-block solver — multigrid when
    registered — and the global sweeps then relax the rest).  With SOR as the
    block solver the frozen start saved no time in the benchmark, because the
    slowest error modes span the whole domain either way.

Stopping rule: the single-block one (largest point-Jacobi displacement ≤
``tolerance × L``, L = bounding-box diagonal of the whole domain).

:func:`iterate_multiblock` yields :class:`~meshcore.elliptic.SolverProgress`
snapshots like the single-block :func:`meshcore.elliptic.iterate` (``grid`` is
None, ``grids`` holds every block's current grid; residuals relative to
``L``) and stops on ``send("stop")`` or a ``stop_event``;
:func:`solve_multiblock` drains it.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Generator
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._generators import drain
from .._validation import validate_choice
from ..elliptic import EllipticConfig, SolverProgress
from ..elliptic import iterate as iterate_block
from ..elliptic.solver import config_with, default_tolerance
from ..errors import InvalidInputError
from ..grid import SolveInfo, StructuredGrid
from .result import MultiBlockGrid, MultiBlockQuality, assemble
from .sor import iterate_sor, sor_engine
from .start import initial_grids
from .topology import MultiBlockTopology

__all__ = ["ENGINES", "MODES", "MultiBlockGrid", "MultiBlockQuality", "iterate_multiblock", "solve_multiblock"]

MODES = ("smooth", "frozen")
#: Smooth-mode iterations: "auto" = multigrid when the blocks coarsen (odd counts too), else "blocks".
ENGINES = ("auto", "multigrid", "blocks", "table")
#: ``engine="auto"``: when the multigrid is slow or diverges, try again from the start grid without
#: the coarsest level this many times before SOR.  On a generated lake (``round_lake(3)``, 9 blocks,
#: 16 000 nodes) the cycles stalled at a defect 40× the tolerance with the 5th level (146 nodes;
#: solving it 1000× more accurately did not help) and converged in 6 cycles with 4 levels: 1.1 s
#: of SOR → ~70 ms; the other 16 layouts and examples measured never retried.
RETRY_FEWER_LEVELS = 1
#: ``engine="auto"``: when that fails too, try once more from the start grid with all levels and
#: every line sweep damped by this factor (``multigrid.iterate_fas``'s ``line_omega``; 1: no such
#: retry), giving up only at a rate beyond RETRY_GIVE_UP_RATE.  A line solved with its coefficients
#: frozen overshoots where cells are nearly folded (the one-block solver damps its lines by 0.8
#: for that reason).  On a generated layout (``headlands(861006)``, 31 blocks, 15 966 nodes) the
#: undamped cycles stalled at rate ~0.9 (50+ cycles) and without the coarsest level diverged:
#: 4 275 SOR sweeps, 0.9 s; damped by 0.8 they converge in 12 cycles.  Damped by default they
#: took 70 instead of 65 cycles on 17 topologies that converge undamped (0.9: 67), so only here.
RETRY_LINE_OMEGA, RETRY_GIVE_UP_RATE = 0.8, 0.9


@dataclass
class _Reporter:
    """Turns the residual checks of an inner iteration into throttled :class:`SolverProgress`."""

    config: EllipticConfig
    tolerance: float  # relative
    length: float
    t0: float
    stop_event: threading.Event | None
    last: float = -1.0
    stopped: bool = False

    def run(
        self,
        inner: Generator[tuple[int, float], Any, Any],
        method: str,
        grids: Callable[[], list[StructuredGrid]],
        offset: int = 0,
    ) -> Generator[SolverProgress, Any, Any]:
        """Drive ``inner`` (which yields ``(iteration, absolute residual)``); return its value."""
        history: list[tuple[int, float]] = []
        try:
            it, r = next(inner)
            while True:
                history.append((offset + it, r / self.length))
                cmd = None
                now = time.perf_counter()
                if self.stop_event is not None and self.stop_event.is_set():
                    cmd = "stop"
                elif now - self.last >= self.config.report_interval:
                    self.last = now
                    snap = self.progress(offset + it, r / self.length, method, tuple(history), grids())
                    if (yield snap) == "stop":
                        cmd = "stop"
                self.stopped = self.stopped or cmd == "stop"
                it, r = inner.send(cmd)
        except StopIteration as fin:
            return fin.value

    def progress(self, it: int, r: float, method: str, history: tuple, grids: list) -> SolverProgress:
        return SolverProgress(
            iteration=it,
            residual=r,
            tolerance=self.tolerance,
            grid=None,
            elapsed=time.perf_counter() - self.t0,
            method=method,
            history=history,
            grids=tuple(grids),
        )


def _named(grids: list[StructuredGrid], names: tuple[str, ...]) -> tuple[StructuredGrid, ...]:
    return tuple(g.replaced(names={**g.names, "block": n}) for g, n in zip(grids, names, strict=True))


def _frozen(
    grids: list[StructuredGrid], cfg: EllipticConfig, rep: _Reporter
) -> Generator[SolverProgress, Any, list[StructuredGrid]]:
    """Every block solved on its own (the paper's frozen interfaces); yields the single-block progress."""
    solved = list(grids)
    for k, g in enumerate(grids):
        gen = iterate_block(g, cfg, stop_event=rep.stop_event)
        try:
            snap = next(gen)
            while True:
                view = [*solved[:k], snap.grid, *solved[k + 1 :]]
                method = f"frozen/{snap.method} (block {k + 1} of {len(grids)})"
                cmd = yield rep.progress(snap.iteration, snap.residual, method, snap.history, view)
                rep.stopped = rep.stopped or cmd == "stop"
                snap = gen.send(cmd)
        except StopIteration as fin:
            solved[k] = fin.value
        if rep.stopped or (rep.stop_event is not None and rep.stop_event.is_set()):
            rep.stopped = True
            break
    return solved


def _frozen_info(solved: list[StructuredGrid], t0: float, stopped: bool) -> SolveInfo:
    conv = all(g.converged for g in solved) and not stopped
    return SolveInfo(
        method=f"frozen/{solved[0].info.method}",
        converged=conv,
        iterations=max(g.iterations for g in solved),
        residual=max(g.residual for g in solved),
        tolerance=max(g.info.tolerance for g in solved),
        elapsed=time.perf_counter() - t0,
        message="stopped" if stopped else "converged" if conv else "a block did not converge",
    )


def _attempts(full: list, give_up: float | None) -> list[tuple[list, float | None, float]]:
    """``engine="auto"``'s multigrid tries, ``(levels, give-up rate, line damping)`` each: all levels,
    then without the coarsest (:data:`RETRY_FEWER_LEVELS` times, while two levels are left), then
    all levels with damped lines (:data:`RETRY_LINE_OMEGA`)."""
    out = [(full, give_up, 1.0)]
    out += [(full[: len(full) - k], give_up, 1.0) for k in range(1, RETRY_FEWER_LEVELS + 1) if len(full) - k >= 2]
    if RETRY_LINE_OMEGA != 1.0:
        out.append((full, RETRY_GIVE_UP_RATE, RETRY_LINE_OMEGA))
    return out


def _smooth(
    x: np.ndarray,
    y: np.ndarray,
    topology: MultiBlockTopology,
    cfg: EllipticConfig,
    tol: float,
    engine: str,
    rep: _Reporter,
) -> Generator[SolverProgress, Any, tuple]:
    """All nodes solved together (multigrid, then SOR if it is slow); returns ``(iters, r, history, msg, method)``."""
    m = topology.node_map

    def shown(xx: np.ndarray, yy: np.ndarray) -> Callable[[], list[StructuredGrid]]:
        return lambda: [StructuredGrid(xx[ids], yy[ids]) for ids in m.ids]

    n_levels, mg_cycles, omega = 1, 0, 1.0
    mg_history: list[tuple[int, float]] = []
    if engine in ("auto", "multigrid"):
        from .multigrid import AUTO_GIVE_UP_RATE, iterate_fas, levels

        full = levels(topology)
        give_up = AUTO_GIVE_UP_RATE if engine == "auto" else None
        x0, y0 = x.copy(), y.copy()
        attempts = _attempts(full, give_up) if engine == "auto" else [(full, give_up, 1.0)]
        engine = "blocks"
        for lvs, give_up, omega in attempts:
            if len(lvs) <= 1:
                break
            damped: dict[str, Any] = {} if omega == 1.0 else {"line_omega": omega}
            if rep.stop_event is not None:  # looked at inside the full-multigrid start too
                damped["should_stop"] = rep.stop_event.is_set
            fas = iterate_fas(x, y, topology, tol, cfg.max_iterations - mg_cycles, give_up, lvs, **damped)
            iters, r, history, message, n_levels = yield from rep.run(fas, "smooth/multigrid", shown(x, y), mg_cycles)
            mg_history += [(mg_cycles + i, v) for i, v in history[bool(mg_history) :]]
            mg_cycles += iters
            if message not in ("diverged", "slow"):
                engine, iters, history = "multigrid", mg_cycles, mg_history
                break
            # start over from the start grid: the cycles' grid can lie where SOR does not
            # converge (a generated lake's coarsest level: omega reduced, 2000 sweeps, 1290
            # folded cells at the end; from the start grid 79 sweeps)
            x[...], y[...] = x0, y0
    if engine in ("blocks", "table"):
        eng = sor_engine(x, y, m, engine)
        sor = iterate_sor(eng, m, cfg, tol)
        iters, r, history, message = yield from rep.run(
            sor, f"smooth/{engine}-sor", lambda: [StructuredGrid(a, b) for a, b in eng.grids(list(m.ids))], mg_cycles
        )
        if mg_cycles:
            history = mg_history + [(mg_cycles + i, v) for i, v in history[1:]]
            message = message or f"multigrid was slow; SOR after {mg_cycles} cycles"
    method = (
        f"smooth/multigrid({n_levels} levels{', damped lines' if engine == 'multigrid' and omega != 1.0 else ''})"
        if engine == "multigrid"
        else f"smooth/{engine}-sor" + (f" after {mg_cycles} multigrid cycles" if mg_cycles else "")
    )
    return iters, r, history, message, method


def iterate_multiblock(
    topology: MultiBlockTopology,
    *,
    mode: str = "smooth",
    config: EllipticConfig | None = None,
    initial: list[StructuredGrid] | None = None,
    start: str = "algebraic",
    engine: str = "auto",
    stop_event: threading.Event | None = None,
    **overrides: Any,
) -> Generator[SolverProgress, Any, MultiBlockGrid]:
    """Generate the multiblock grid of ``topology``, yielding progress; returns a :class:`MultiBlockGrid`.

    Parameters
    ----------
    topology : MultiBlockTopology
        Blocks (re-sampled borders) and interfaces.
    mode : {"smooth", "frozen"}
        Interface treatment (see module docstring).
    config : EllipticConfig, optional
        Solver settings; ``tolerance`` and ``max_iterations`` apply to the
        global smooth iteration, and the whole config to the per-block solves;
        snapshots come at most every ``report_interval`` seconds.
    initial : list of StructuredGrid, optional
        Start grids per block (default: each block's algebraic grid).
    start : {"algebraic", "frozen"}
        ``smooth`` mode only: start the global iteration from the algebraic
        grids or from the frozen solution.
    engine : {"auto", "multigrid", "blocks", "table"}
        ``smooth`` mode only: nonlinear multigrid over all blocks
        (:mod:`.multigrid`; any cell counts),
        SOR with block sweeps and border exchange, or SOR over the global
        neighbour table.  ``auto``: multigrid when the blocks coarsen, else
        ``blocks``.
    stop_event : threading.Event, optional
        Cooperative stop (also ``gen.send("stop")``): the current grids are
        returned with ``converged=False`` and ``info.message == "stopped"``.

    Yields
    ------
    SolverProgress
        ``grid`` None, ``grids`` the current grid of every block.
    """
    mode = validate_choice(mode, MODES, name="mode")
    start = validate_choice(start, ("frozen", "algebraic"), name="start")
    engine = validate_choice(engine, ENGINES, name="engine")
    cfg = config_with(config, overrides)
    t0 = time.perf_counter()
    grids = list(initial) if initial is not None else initial_grids(topology)
    if len(grids) != len(topology.blocks):
        raise InvalidInputError(f"initial: expected {len(topology.blocks)} grids (one per block), got {len(grids)}")
    names = tuple(b.name for b in topology.blocks)
    length = topology.size or 1.0
    n_big = max(max(g.shape) for g in grids)
    tol_rel = cfg.tolerance if cfg.tolerance is not None else default_tolerance((n_big, n_big))
    rep = _Reporter(cfg, tol_rel, length, t0, stop_event)
    solved = grids
    if mode == "frozen" or start == "frozen":
        solved = yield from _frozen(grids, cfg, rep)
    if mode == "frozen" or rep.stopped:
        info = _frozen_info(solved, t0, rep.stopped)
        final = [g.replaced(info=info) if rep.stopped else g for g in solved]
        return MultiBlockGrid(_named(final, names), names, topology.interfaces, mode, info, topology)

    x, y = assemble(solved, topology.node_map)
    if not (np.isfinite(x).all() and np.isfinite(y).all()):
        raise InvalidInputError("initial grids contain NaN or inf coordinates")
    tol = tol_rel * length
    iters, r, history, message, method = yield from _smooth(x, y, topology, cfg, tol, engine, rep)
    if not (np.isfinite(x).all() and np.isfinite(y).all()):  # never report a NaN grid converged
        r, message = np.inf, (message + "; " if message else "") + "NaN or inf coordinates (a degenerate block?)"
    conv = r <= tol * (1 + 1e-12) and message != "stopped"
    info = SolveInfo(
        method=method + ("+frozen-start" if start == "frozen" else ""),
        converged=conv,
        iterations=iters,
        residual=r / length,
        tolerance=tol_rel,
        residual_history=tuple((int(i), float(v) / length) for i, v in history),
        elapsed=time.perf_counter() - t0,
        message=(
            "stopped"
            if message == "stopped"
            else ("converged" if conv else f"not converged after {iters} iterations")
            + (f" ({message})" if message else "")
        ),
    )
    final = [
        StructuredGrid(x[ids], y[ids], info=info, names=g.names)
        for g, ids in zip(grids, topology.node_map.ids, strict=True)
    ]
    return MultiBlockGrid(_named(final, names), names, topology.interfaces, mode, info, topology)


def solve_multiblock(
    topology: MultiBlockTopology,
    *,
    callback: Callable[[SolverProgress], Any] | None = None,
    **kwargs: Any,
) -> MultiBlockGrid:
    """Drain :func:`iterate_multiblock` (same arguments); ``callback(progress)`` may return ``"stop"``.

    Examples
    --------
    See :mod:`meshcore.multiblock`.
    """
    return drain(iterate_multiblock(topology, **kwargs), callback)
