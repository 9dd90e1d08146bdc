"""The elliptic solver driver: one generator for the CLI, the GUI and scripts.

:func:`iterate` yields :class:`SolverProgress` snapshots (a *copy* of the grid)
at most every ``report_interval`` seconds and returns the final
:class:`~meshcore.grid.StructuredGrid` (``StopIteration.value``);
:func:`solve` drains it.  Non-convergence is a result (``grid.converged``),
never an exception.

Stopping rule (shared by every method, so results compare)
----------------------------------------------------------
Let ``r`` be the largest displacement that one point-Jacobi update of the
discrete equations (eq. 30, with the current P, Q) would make at any interior
node, and ``L`` the diagonal of the grid's bounding box.  The solve has
converged when ``r ≤ tolerance · L``.  The default tolerance is scale aware::

    tolerance = 1e-6 · min(1, (32 / (n − 1))²),   n = max(ni, nj) + 1

because the Jacobi displacement of a fixed discretisation error shrinks like
``h²``; a fixed ``1e-6`` would call a 1025² grid converged before it moved.

Cooperative stop: ``gen.send("stop")`` (or setting ``stop_event``) makes the
generator return the current grid with ``converged=False`` and
``info.message == "stopped"`` at the next sweep.  Sending an
:class:`EllipticConfig` changes ``omega`` and ``report_interval`` on the fly.
"""

from __future__ import annotations

import dataclasses
import math
import threading
import time
from collections.abc import Callable, Generator
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .._generators import drain
from .._validation import validate_choice, validate_count, validate_positive
from ..errors import InvalidInputError
from ..grid import SolveInfo, StructuredGrid
from . import _kernels

__all__ = [
    "METHODS",
    "EllipticConfig",
    "SolverProgress",
    "default_tolerance",
    "iterate",
    "register_method",
    "residual",
    "solve",
]

#: Solver methods; "multigrid" and others register themselves (see register_method).
METHODS: dict[str, Callable[..., Generator]] = {}

#: Snapshots come at most every ``max(report_interval, SNAPSHOT_COST_FACTOR × t)``
#: seconds, ``t`` the time the last snapshot took (copying x, y of a huge grid).
SNAPSHOT_COST_FACTOR = 20.0
#: Assumed snapshot copy speed before the first snapshot is timed: fresh pages included
#: (measured: 67 MB in 130-150 ms when the kernel first compacts transparent huge pages).
SNAPSHOT_BYTES_PER_S = 0.5e9
#: Grids whose x, y take at least this many bytes have their snapshots spaced by what a copy
#: costs.  Smaller grids copy in microseconds: a copy that took long was the process waiting
#: for a core (a busy machine), and spacing snapshots by it froze the live view for seconds.
SNAPSHOT_HUGE_BYTES = 4 << 20


def register_method(name: str, fn: Callable[..., Generator]) -> None:
    """Register a solver generator ``fn(state) -> Generator`` under ``name``."""
    METHODS[name] = fn


def default_tolerance(shape: tuple[int, int]) -> float:
    """Scale-aware default tolerance ``1e-6 · min(1, (32/(n−1))²)``."""
    n = max(shape)
    return 1e-6 * min(1.0, (32.0 / max(n - 1, 1)) ** 2)


@dataclass(frozen=True, slots=True)
class EllipticConfig:
    """Solver settings (defaults live here only).

    Parameters
    ----------
    method : str
        ``"auto"`` (multigrid where it pays off, SOR for tiny grids), ``"sor"``,
        ``"multigrid"`` when available, or another registered method.
    tolerance : float or None
        Relative tolerance of the stopping rule (see module docstring);
        ``None`` = scale-aware default.
    max_iterations : int
        Cap on sweeps (SOR) or cycles (multigrid).
    omega : float or None
        SOR relaxation factor in (0, 2); ``None`` = ``2 / (1 + sin(π / n))``
        with automatic back-off if the iteration diverges.
    report_interval : float
        Seconds between progress snapshots (at least 20× the time one snapshot
        takes, so that copying a huge grid costs < 5 %).
    threads : int
        0 (default) = automatic: all the threads numba may use (``NUMBA_NUM_THREADS``)
        on grids of at least :data:`AUTO_THREADS_MIN_NODES` nodes, serial below;
        1 = serial kernels; > 1 uses the ``parallel=True`` kernels.  Every choice
        gives bit-identical grids.
    """

    method: str = "auto"
    tolerance: float | None = None
    max_iterations: int = 50_000
    omega: float | None = None
    report_interval: float = 1.0 / 30.0
    threads: int = 0

    def __post_init__(self) -> None:
        if not isinstance(self.method, str):
            raise InvalidInputError(f"method must be a string, got {self.method!r}")
        object.__setattr__(self, "method", self.method.lower())
        if self.tolerance is not None:
            validate_positive(self.tolerance, name="tolerance")
        # stored as ints: a TOML/JSON 1e9 or 2.0 is a whole number, but range() needs an int
        object.__setattr__(self, "max_iterations", validate_count(self.max_iterations, name="max_iterations"))
        if self.omega is not None and not (0.0 < float(self.omega) < 2.0):
            raise InvalidInputError(f"omega must be in (0, 2), got {self.omega}")
        validate_positive(self.report_interval, name="report_interval")
        object.__setattr__(self, "threads", validate_count(self.threads, name="threads", minimum=0))

    def replaced(self, **kw: Any) -> EllipticConfig:
        return dataclasses.replace(self, **kw)


@dataclass(frozen=True, slots=True)
class SolverProgress:
    """A progress snapshot; ``grid`` is a copy, safe to read from another thread.

    ``residual`` and ``history`` (``(iteration, residual)`` pairs) are relative to
    the grid size, like ``tolerance``.  A multiblock solve
    (:func:`meshcore.multiblock.iterate_multiblock`) has ``grid=None`` and every
    block's current grid in ``grids``.
    """

    iteration: int
    residual: float
    tolerance: float
    grid: StructuredGrid | None
    elapsed: float
    method: str
    history: tuple[tuple[int, float], ...] = field(default=(), repr=False)
    grids: tuple[StructuredGrid, ...] = field(default=(), repr=False)

    @property
    def relative_residual(self) -> float:
        return self.residual / self.tolerance if self.tolerance > 0 else float("nan")


@dataclass(slots=True)
class SolverState:
    """Mutable working state handed to a method generator (driver-owned arrays)."""

    x: np.ndarray
    y: np.ndarray
    p: np.ndarray
    q: np.ndarray
    periodic: bool
    config: EllipticConfig
    tol_abs: float
    length: float
    stop_event: threading.Event | None
    sources: Any = None
    #: P, Q as given, before ``sources.initialize`` (to start the control over).
    pq_given: tuple | None = None
    #: The start grid ``(x, y)`` (the caller's arrays: read, never written).
    start: tuple | None = None
    fixed: np.ndarray | None = None
    history: list = field(default_factory=list)
    message: str = ""
    iterations: int = 0
    #: The stopping measure of the final grid, when the method computed it right before
    #: returning converged (saves the driver recomputing it).
    final_residual: float | None = None

    def residual(self) -> float:
        return float(_kernels.jacobi_residual(self.x, self.y, self.p, self.q, self.periodic))


def residual(grid: StructuredGrid, p: np.ndarray | None = None, q: np.ndarray | None = None) -> float:
    """Absolute stopping measure of ``grid`` (largest point-Jacobi displacement)."""
    x = np.ascontiguousarray(grid.x, dtype=np.float64).copy()
    y = np.ascontiguousarray(grid.y, dtype=np.float64).copy()
    pp, qq = _pq(p, q, x.shape)
    return float(_kernels.jacobi_residual(x, y, pp, qq, grid.periodic))


def _pq(p, q, shape):
    if p is None and q is None:
        e = np.zeros((0, 0))
        return e, e
    # own writable copies (a broadcast view is read-only: a distinct array type for numba)
    pp = np.zeros(shape) if p is None else np.array(np.broadcast_to(p, shape), dtype=np.float64, order="C")
    qq = np.zeros(shape) if q is None else np.array(np.broadcast_to(q, shape), dtype=np.float64, order="C")
    for nm, arr in (("P", pp), ("Q", qq)):
        if not np.isfinite(arr).all():
            raise InvalidInputError(f"source term {nm} contains NaN or inf")
    return pp, qq


def _sources_settled(state: SolverState) -> bool:
    """False while a control-function updater says its sources are still moving."""
    settled = getattr(state.sources, "settled", None)
    return True if settled is None else bool(settled())


def _sor(state: SolverState) -> Generator[str, None, bool]:
    """SOR in 4-colour order. Yields ``"tick"`` after each sweep; returns converged."""
    cfg = state.config
    x, y, p, q, per = state.x, state.y, state.p, state.q, state.periodic
    n = max(x.shape) - 1
    omega = cfg.omega if cfg.omega is not None else 2.0 / (1.0 + math.sin(math.pi / max(n, 2)))
    auto_omega = cfg.omega is None
    sweep = _kernels.sweep4_parallel if cfg.threads > 1 else _kernels.sweep4
    tol = state.tol_abs
    prefix = f"{state.message}; " if state.message else ""  # e.g. why multigrid handed over
    r = state.residual()
    state.history.append((0, r))
    if r <= tol:
        return True
    best = r
    # with a control-function updater the residual jumps when the sources move:
    # judge divergence against a floor well above the tolerance
    floor = 0.0 if state.sources is None else 1e3 * tol
    saved = (x.copy(), y.copy())
    since_check = 0
    check_every = 1
    for it in range(1, cfg.max_iterations + 1):
        if state.sources is not None and state.sources.wants_update(it):
            state.sources.update(x, y, p, q, it)
        d = sweep(x, y, p, q, omega, per) / omega
        since_check += 1
        if not math.isfinite(d) or since_check >= check_every or d < 4.0 * tol:
            since_check = 0
            r = state.residual() if math.isfinite(d) else math.inf
            if r <= tol and not (np.isfinite(x).all() and np.isfinite(y).all()):
                r = math.inf  # the kernels skip NaN nodes: never call a NaN grid converged
            state.history.append((it, r))
            if r <= tol and _sources_settled(state):
                state.iterations = it
                state.final_residual = r
                return True
            if not math.isfinite(r) or r > 1e3 * max(best, floor):
                # diverging: restore the last good iterate and relax less
                x[...] = saved[0]
                y[...] = saved[1]
                if not auto_omega and omega <= 1.0:
                    state.message = f"{prefix}diverged"
                    return False
                omega = 1.0 + 0.5 * (omega - 1.0) if omega > 1.05 else 0.7 * omega
                state.message = f"{prefix}omega reduced to {omega:.3f}"
                check_every = 1
            elif r < best:
                best = r
                saved[0][...] = x
                saved[1][...] = y
                check_every = min(2 * check_every, 32)
        state.iterations = it
        yield "tick"
    return False


register_method("sor", _sor)


#: ``threads=0`` runs serial below this many nodes (measured with benchmarks/run.py: two
#: threads gain 9 % at 129², 24 % at 257², 40 % from 513² on; on a few thousand nodes the
#: threading overhead costs more than it saves).
AUTO_THREADS_MIN_NODES = 16_000


def resolve_threads(threads: int, nodes: int) -> int:
    """The thread count ``threads`` (0 = automatic) means for a grid of ``nodes`` nodes."""
    if threads:
        return threads
    if nodes < AUTO_THREADS_MIN_NODES:
        return 1
    import numba

    return max(1, int(numba.config.NUMBA_NUM_THREADS))


def config_with(config: EllipticConfig | None, overrides: dict[str, Any]) -> EllipticConfig:
    """``config`` (default settings if None) with keyword ``overrides``; unknown names raise."""
    cfg = config or EllipticConfig()
    if overrides:
        try:
            cfg = cfg.replaced(**overrides)
        except TypeError as exc:
            raise InvalidInputError(f"unknown solver option: {exc}") from None
    return cfg


def _choose_method(cfg: EllipticConfig, shape: tuple[int, int]) -> str:
    m = cfg.method
    if m == "auto":
        # multigrid pays off once there are enough levels and nodes to amortise its set-up
        # (measured with benchmarks/run.py: SOR wins below ~2000 nodes, e.g. 3.4x at 17x33,
        # multigrid wins from ~49x49 on, 2x at 65x65 and 7x at 129x129)
        if "multigrid" in METHODS and min(shape) >= 17 and shape[0] * shape[1] >= 2000:
            return "multigrid"
        return "sor"
    validate_choice(m, [*METHODS, "auto"], name="method")
    return m


def iterate(
    initial: StructuredGrid,
    config: EllipticConfig | None = None,
    *,
    p: np.ndarray | None = None,
    q: np.ndarray | None = None,
    sources: Any = None,
    stop_event: threading.Event | None = None,
    **overrides: Any,
) -> Generator[SolverProgress, Any, StructuredGrid]:
    """Iterate the elliptic grid equations from ``initial``; borders stay fixed.

    Parameters
    ----------
    initial : StructuredGrid
        Start grid (its boundary nodes are the Dirichlet data).
    config : EllipticConfig, optional
        Solver settings; keyword ``overrides`` replace single fields.
    p, q : array_like, optional
        Source terms P, Q (broadcast to the node array; interior values used).
    sources : object, optional
        Control-function updater with ``wants_update(it)`` and
        ``update(x, y, p, q, it)`` (see :mod:`meshcore.control`).
    stop_event : threading.Event, optional
        Cooperative stop flag (checked every sweep/cycle).

    Yields
    ------
    SolverProgress
        Snapshots at most every ``config.report_interval`` seconds.

    Returns
    -------
    StructuredGrid
        The final grid, with ``info`` (method, converged, iterations, residual).
    """
    cfg = config_with(config, overrides)
    x = np.array(initial.x, dtype=np.float64, order="C", copy=True)
    y = np.array(initial.y, dtype=np.float64, order="C", copy=True)
    if not (np.isfinite(x).all() and np.isfinite(y).all()):
        raise InvalidInputError("initial grid contains NaN or inf coordinates")
    if cfg.threads == 0:
        cfg = cfg.replaced(threads=resolve_threads(0, x.size))
    pp, qq = _pq(p, q, x.shape)
    if sources is not None and pp.size == 0:
        pp, qq = np.zeros(x.shape), np.zeros(x.shape)
    length = initial.size or 1.0
    tol_rel = cfg.tolerance if cfg.tolerance is not None else default_tolerance(x.shape)
    method = _choose_method(cfg, x.shape)
    state = SolverState(
        x=x,
        y=y,
        p=pp,
        q=qq,
        periodic=initial.periodic,
        config=cfg,
        tol_abs=tol_rel * length,
        length=length,
        stop_event=stop_event,
        sources=sources,
        start=(np.asarray(initial.x, dtype=np.float64), np.asarray(initial.y, dtype=np.float64)),
    )
    if sources is not None:
        state.pq_given = (pp.copy(), qq.copy())
        sources.initialize(x, y, pp, qq)
    t0 = time.perf_counter()
    last = t0
    # until a snapshot has been timed: assume copying x, y of a huge grid (arrays that numpy
    # places in transparent huge pages, ≥ 4 MB) runs at SNAPSHOT_BYTES_PER_S
    huge = x.nbytes >= SNAPSHOT_HUGE_BYTES
    interval_floor = SNAPSHOT_COST_FACTOR * 2 * x.nbytes / SNAPSHOT_BYTES_PER_S if huge else 0.0
    gen = METHODS[method](state)
    rel: list[tuple[int, float]] = []  # the relative history so far (extended, not rebuilt, per snapshot)
    converged = False
    stopped = False
    try:
        while True:
            next(gen)
            if stop_event is not None and stop_event.is_set():
                stopped = True
                break
            now = time.perf_counter()
            if now - last >= max(cfg.report_interval, interval_floor):
                r = state.history[-1][1] if state.history else float("nan")
                snap = SolverProgress(
                    iteration=state.iterations,
                    residual=r / length,
                    tolerance=tol_rel,
                    grid=StructuredGrid(x, y, periodic=initial.periodic, names=initial.names),
                    elapsed=now - t0,
                    method=method,
                    history=_relative(state.history, rel, length),
                )
                last = time.perf_counter()
                # a snapshot copies x, y: keep that below ~5 % of the solve on huge grids
                interval_floor = SNAPSHOT_COST_FACTOR * (last - now) if huge else 0.0
                cmd = yield snap
                if cmd == "stop":
                    stopped = True
                    break
                if isinstance(cmd, EllipticConfig):
                    state.config = cmd
                    cfg = cmd
    except StopIteration as fin:
        converged = bool(fin.value)
    finally:
        gen.close()
    r_final = state.final_residual
    if stopped or not converged or r_final is None:
        r_final = state.residual()
    if stopped:
        msg = "stopped"
        converged = False
    elif converged:
        msg = f"converged ({state.message})" if state.message else "converged"
    else:
        msg = state.message or f"not converged after {state.iterations} iterations"
    info = SolveInfo(
        method=method,
        converged=converged and r_final <= state.tol_abs * (1 + 1e-12),
        iterations=state.iterations,
        residual=r_final / length,
        tolerance=tol_rel,
        residual_history=tuple((int(i), float(v) / length) for i, v in state.history),
        elapsed=time.perf_counter() - t0,
        message=msg,
    )
    return StructuredGrid(x, y, info=info, names=initial.names, periodic=initial.periodic)


def _relative(history: list, rel: list, length: float) -> tuple[tuple[int, float], ...]:
    """``history`` relative to ``length``, extending ``rel`` by the new entries only."""
    if len(history) < len(rel) or (rel and history and history[len(rel) - 1][0] != rel[-1][0]):
        rel.clear()  # a method restarted its history (multigrid falling back to SOR)
    rel.extend((i, v / length) for i, v in history[len(rel) :])
    return tuple(rel)


def solve(
    initial: StructuredGrid,
    config: EllipticConfig | None = None,
    *,
    callback: Callable[[SolverProgress], Any] | None = None,
    **kwargs: Any,
) -> StructuredGrid:
    """Drain :func:`iterate`; ``callback(progress)`` sees every snapshot.

    If the callback returns ``"stop"`` (or ``False``) the solve stops early.
    """
    return drain(iterate(initial, config, **kwargs), callback)
