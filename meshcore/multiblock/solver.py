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

    ``engine="multigrid"`` (chosen by ``"auto"`` whenever every block and
    interface range has even cell counts) runs a nonlinear FAS multigrid over
    the whole topology with the table kernels as smoother
    (:mod:`.multigrid`): 4–5 V-cycles instead of hundreds of SOR sweeps.

    The iteration starts from the algebraic grids (``start="algebraic"``,
    default) or from the ``frozen`` solution (``start="frozen"``: the blocks
    are first solved separately with the single-block solver — multigrid when
    registered — and the global sweeps then relax the rest).  With SOR as the
    block solver the frozen start saved no time in the benchmark, because the
    slowest error modes span the whole domain either way.

Stopping rule: the single-block one (largest point-Jacobi displacement ≤
``tolerance × L``, L = bounding-box diagonal of the whole domain).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .._validation import validate_choice
from ..elliptic import EllipticConfig
from ..elliptic import solve as solve_block
from ..elliptic.solver import config_with, default_tolerance
from ..errors import InvalidInputError
from ..grid import SolveInfo, StructuredGrid
from ..quality import QualityReport, interface_pairs, quality
from . import _kernels
from .start import initial_grids
from .topology import Interface, MultiBlockTopology

__all__ = ["MODES", "MultiBlockGrid", "MultiBlockQuality", "solve_multiblock"]

MODES = ("smooth", "frozen")
#: Smooth-mode iterations: "auto" = multigrid when the blocks coarsen, else "blocks".
ENGINES = ("auto", "multigrid", "blocks", "table")


@dataclass(frozen=True, slots=True, eq=False)
class MultiBlockQuality:
    """Quality per block and across interfaces.

    ``interfaces`` maps ``"a ↔ b"`` to the largest area ratio (≥ 1) of two
    cells that share an edge across that block pair; ``worst_inside`` is the
    largest adjacent-cell size ratio inside any block.
    """

    blocks: dict[str, QualityReport]
    interfaces: dict[str, float]
    n_folded: int
    worst_inside: float
    worst_interface: float

    def table(self) -> str:
        lines = [
            "| block | cells | folded | min Jac. ratio | max orth. dev. | max skew | max aspect | max size ratio |",
            "|---|---|---|---|---|---|---|---|",
        ]
        for name, r in self.blocks.items():
            lines.append(
                f"| {name} | {r.cells[0]} × {r.cells[1]} | {r.n_folded} | "
                f"{r.min_jacobian_ratio:.3f} | "
                f"{r.max_orthogonality:.1f}° | {r.max_skewness:.3f} | {r.max_aspect_ratio:.2f} | "
                f"{r.max_size_ratio:.3f} |"
            )
        lines.append("")
        lines.append("| interface (block pair) | max adjacent-cell size ratio across |")
        lines.append("|---|---|")
        for k, v in self.interfaces.items():
            lines.append(f"| {k} | {v:.3f} |")
        lines.append("")
        lines.append(
            f"worst size ratio inside blocks {self.worst_inside:.3f}, across interfaces "
            f"{self.worst_interface:.3f}; folded cells {self.n_folded}"
        )
        return "\n".join(lines)

    def __str__(self) -> str:
        return self.table()


@dataclass(frozen=True, slots=True, eq=False)
class MultiBlockGrid:
    """The result: one :class:`StructuredGrid` per block plus the connectivity."""

    grids: tuple[StructuredGrid, ...]
    names: tuple[str, ...]
    interfaces: tuple[Interface, ...]
    mode: str = "smooth"
    info: SolveInfo = field(default_factory=SolveInfo)
    topology: MultiBlockTopology | None = field(default=None, repr=False)
    frame: Any = field(default=None, repr=False)  # meshcore.crs.Frame of the coordinates

    def __len__(self) -> int:
        return len(self.grids)

    @property
    def blocks(self) -> tuple[StructuredGrid, ...]:
        """The block grids (what writers take: ``meshcore.io.write(path, mbgrid)``)."""
        return self.grids

    def __iter__(self) -> Iterator[StructuredGrid]:
        return iter(self.grids)

    def __getitem__(self, key: int | str) -> StructuredGrid:
        if isinstance(key, str):
            try:
                return self.grids[self.names.index(key)]
            except ValueError:
                raise KeyError(f"no block named {key!r}; blocks: {', '.join(self.names)}") from None
        return self.grids[key]

    @property
    def converged(self) -> bool:
        return self.info.converged

    @property
    def n_nodes(self) -> int:
        """Unique nodes (shared interface nodes counted once) when the topology is known."""
        if self.topology is not None:
            return self.topology.node_map.n_nodes
        return sum(g.n_nodes for g in self.grids)

    def interface_mismatch(self) -> float:
        """Largest distance between the two copies of any interface node (0 when glued)."""
        worst = 0.0
        for itf in self.interfaces:
            pa = self[itf.a.block].border(itf.a.border)[itf.a.start : itf.a.stop + 1]
            pb = self[itf.b.block].border(itf.b.border)[itf.b.start : itf.b.stop + 1]
            if itf.reversed:
                pb = pb[::-1]
            worst = max(worst, float(np.hypot(*(pa - pb).T).max()))
        return worst

    def quality(self) -> MultiBlockQuality:
        reports = {n: quality(g) for n, g in zip(self.names, self.grids, strict=True)}
        inter: dict[str, float] = {}
        if len(self.grids) > 1:
            pairs = interface_pairs(self.grids)  # the cross-interface ratio of meshcore.quality
            for p, q, r in zip(pairs["cell_a"][:, 0], pairs["cell_b"][:, 0], pairs["ratio"], strict=True):
                k = f"{self.names[min(p, q)]} ↔ {self.names[max(p, q)]}"
                inter[k] = max(inter.get(k, 1.0), float(r))
        return MultiBlockQuality(
            blocks=reports,
            interfaces=inter,
            n_folded=sum(r.n_folded for r in reports.values()),
            worst_inside=max(r.max_size_ratio for r in reports.values()),
            worst_interface=max(inter.values(), default=1.0),
        )

    def report(self) -> str:
        """Connectivity report plus the solve summary."""
        head = (
            f"Multiblock grid: {len(self.grids)} blocks, mode {self.mode!r}, "
            f"{'converged' if self.info.converged else 'NOT converged'} after "
            f"{self.info.iterations} iterations (residual {self.info.residual:.3g}, "
            f"{self.info.elapsed:.3g} s)"
        )
        body = self.topology.connectivity_report() if self.topology is not None else ""
        return head + "\n" + body


def _assemble(grids, m) -> tuple[np.ndarray, np.ndarray]:
    x = np.empty(m.n_nodes)
    y = np.empty(m.n_nodes)
    for g, ids in zip(grids, m.ids, strict=True):
        x[ids.ravel()] = np.asarray(g.x).ravel()
        y[ids.ravel()] = np.asarray(g.y).ravel()
    return x, y


def solve_multiblock(
    topology: MultiBlockTopology,
    *,
    mode: str = "smooth",
    config: EllipticConfig | None = None,
    initial: list[StructuredGrid] | None = None,
    start: str = "algebraic",
    engine: str = "auto",
    callback: Callable[[int, float], Any] | None = None,
    **overrides: Any,
) -> MultiBlockGrid:
    """Generate the multiblock grid of ``topology``.

    Parameters
    ----------
    topology : MultiBlockTopology
        Blocks (re-sampled borders) and interfaces.
    mode : {"smooth", "frozen"}
        Interface treatment (see module docstring).
    config : EllipticConfig, optional
        Solver settings; ``tolerance`` and ``max_iterations`` apply to the
        global smooth iteration, and the whole config to the per-block solves.
    initial : list of StructuredGrid, optional
        Start grids per block (default: each block's algebraic grid).
    start : {"algebraic", "frozen"}
        ``smooth`` mode only: start the global iteration from the algebraic
        grids or from the frozen solution.
    engine : {"auto", "multigrid", "blocks", "table"}
        ``smooth`` mode only: nonlinear multigrid over all blocks
        (:mod:`.multigrid`; needs even cell counts and interface ranges),
        SOR with block sweeps and border exchange, or SOR over the global
        neighbour table.  ``auto``: multigrid when the blocks coarsen, else
        ``blocks``.
    callback : callable, optional
        ``callback(iteration, relative_residual)`` after each residual check
        of the smooth iteration; return ``"stop"`` to stop.

    Returns
    -------
    MultiBlockGrid
        Interface nodes are bit-identical in both adjoining blocks.
    """
    mode = validate_choice(mode, MODES, name="mode")
    start = validate_choice(start, ("frozen", "algebraic"), name="start")
    engine = validate_choice(engine, ENGINES, name="engine")
    cfg = config_with(config, overrides)
    m = topology.node_map
    t0 = time.perf_counter()
    grids = list(initial) if initial is not None else initial_grids(topology)
    if len(grids) != len(topology.blocks):
        raise InvalidInputError(f"initial: expected {len(topology.blocks)} grids (one per block), got {len(grids)}")
    names = tuple(b.name for b in topology.blocks)
    length = topology.size or 1.0
    if mode == "frozen" or start == "frozen":
        solved = [solve_block(g, cfg) for g in grids]
    else:
        solved = grids
    if mode == "frozen":
        conv = all(g.converged for g in solved)
        info = SolveInfo(
            method=f"frozen/{solved[0].info.method}",
            converged=conv,
            iterations=max(g.iterations for g in solved),
            residual=max(g.residual for g in solved),
            tolerance=max(g.info.tolerance for g in solved),
            elapsed=time.perf_counter() - t0,
            message="converged" if conv else "a block did not converge",
        )
        final = [g.replaced(names={**g.names, "block": n}) for g, n in zip(solved, names, strict=True)]
        return MultiBlockGrid(tuple(final), names, topology.interfaces, mode, info, topology)

    x, y = _assemble(solved, m)
    if not (np.isfinite(x).all() and np.isfinite(y).all()):
        raise InvalidInputError("initial grids contain NaN or inf coordinates")
    n_big = max(max(g.shape) for g in grids)
    tol_rel = cfg.tolerance if cfg.tolerance is not None else default_tolerance((n_big, n_big))
    tol = tol_rel * length
    n_levels, mg_cycles, mg_history = 1, 0, []
    if engine in ("auto", "multigrid"):
        from .multigrid import AUTO_GIVE_UP_RATE, levels, solve_fas

        lvs = levels(topology)
        if len(lvs) > 1:
            give_up = AUTO_GIVE_UP_RATE if engine == "auto" else None
            iters, r, history, message, n_levels = solve_fas(
                x, y, topology, tol, cfg.max_iterations, callback, give_up, lvs
            )
            if message in ("diverged", "slow"):  # continue with SOR from the current grid
                engine, mg_cycles, mg_history = "blocks", iters, history
            else:
                engine = "multigrid"
        else:
            engine = "blocks"
    if engine in ("blocks", "table"):
        iters, r, history, message = _smooth_sor(x, y, m, cfg, tol, callback, engine)
        if mg_cycles:
            history = mg_history + [(mg_cycles + i, v) for i, v in history[1:]]
            message = message or f"multigrid was slow; SOR after {mg_cycles} cycles"
    conv = r <= tol * (1 + 1e-12)
    info = SolveInfo(
        method=(
            f"smooth/multigrid({n_levels} levels)"
            if engine == "multigrid"
            else f"smooth/{engine}-sor" + (f" after {mg_cycles} multigrid cycles" if mg_cycles else "")
        )
        + ("+frozen-start" if start == "frozen" else ""),
        converged=conv,
        iterations=iters,
        residual=r / length,
        tolerance=tol_rel,
        residual_history=tuple((int(i), float(v) / length) for i, v in history),
        elapsed=time.perf_counter() - t0,
        message=(
            ("converged" if conv else f"not converged after {iters} iterations") + (f" ({message})" if message else "")
        ),
    )
    final = []
    for g, ids, n in zip(grids, m.ids, names, strict=True):
        final.append(StructuredGrid(x[ids], y[ids], info=info, names={**g.names, "block": n}))
    return MultiBlockGrid(tuple(final), names, topology.interfaces, mode, info, topology)


class _TableEngine:
    """Every free node through the global neighbour table."""

    def __init__(self, x, y, m) -> None:
        self.x, self.y = x, y
        self.args = (m.nodes, m.nbr, m.irr_nodes, m.irr_ptr, m.irr_ring)

    def sweep(self, omega: float) -> float:
        return float(_kernels.table_sweep(self.x, self.y, *self.args, omega))

    def residual(self) -> float:
        return float(_kernels.table_residual(self.x, self.y, *self.args))

    def save(self):
        return (self.x.copy(), self.y.copy())

    def restore(self, saved) -> None:
        self.x[...] = saved[0]
        self.y[...] = saved[1]

    def finish(self) -> None:
        pass


class _BlockEngine:
    """Block interiors with the single-block kernel, border nodes with the table.

    One sweep: (1) ``sweep4`` on each block's own array (its frame fixed);
    (2) copy each block's first interior ring — the only interior values a
    border stencil reads — into the global array; (3) table sweep over the
    free border nodes; (4) copy the border values back into the block frames.
    """

    def __init__(self, x, y, m) -> None:
        from ..elliptic import _kernels as bk

        self.bk = bk
        self.x, self.y = x, y
        self.e = np.zeros((0, 0))
        k0 = m.n_interior
        self.args = (m.nodes[k0:], m.nbr[k0:], m.irr_nodes, m.irr_ptr, m.irr_ring)
        self.bx = [np.ascontiguousarray(x[ids]) for ids in m.ids]
        self.by = [np.ascontiguousarray(y[ids]) for ids in m.ids]
        needed = np.zeros(m.n_nodes, dtype=bool)
        needed[self.args[1].ravel()] = True
        needed[m.irr_ring] = True
        self.ring, self.frame = [], []
        for ids in m.ids:
            flat = ids.ravel()
            inner = np.zeros(ids.shape, dtype=bool)
            inner[1:-1, 1:-1] = True
            li = np.flatnonzero(inner.ravel() & needed[flat])
            self.ring.append((li, flat[li]))
            fr = np.flatnonzero(~inner.ravel())
            self.frame.append((fr, flat[fr]))
        self.ids = m.ids

    def sweep(self, omega: float) -> float:
        d = 0.0
        for bx, by, (li, gi) in zip(self.bx, self.by, self.ring, strict=True):
            if bx.shape[0] > 2 and bx.shape[1] > 2:
                d = max(d, self.bk.sweep4(bx, by, self.e, self.e, omega, False))
            self.x[gi] = bx.reshape(-1)[li]
            self.y[gi] = by.reshape(-1)[li]
        d = max(d, float(_kernels.table_sweep(self.x, self.y, *self.args, omega)))
        for bx, by, (fr, gf) in zip(self.bx, self.by, self.frame, strict=True):
            bx.reshape(-1)[fr] = self.x[gf]
            by.reshape(-1)[fr] = self.y[gf]
        return d

    def residual(self) -> float:
        r = float(_kernels.table_residual(self.x, self.y, *self.args))
        for bx, by in zip(self.bx, self.by, strict=True):
            r = max(r, float(self.bk.jacobi_residual(bx, by, self.e, self.e, False)))
        return r

    def save(self):
        return ([b.copy() for b in self.bx], [b.copy() for b in self.by], self.x.copy(), self.y.copy())

    def restore(self, saved) -> None:
        for b, s in zip(self.bx, saved[0], strict=True):
            b[...] = s
        for b, s in zip(self.by, saved[1], strict=True):
            b[...] = s
        self.x[...] = saved[2]
        self.y[...] = saved[3]

    def finish(self) -> None:
        for bx, by, ids in zip(self.bx, self.by, self.ids, strict=True):
            self.x[ids] = bx
            self.y[ids] = by


def _smooth_sor(
    x, y, m, cfg: EllipticConfig, tol: float, callback, engine: str = "blocks"
) -> tuple[int, float, list, str]:
    eng = _BlockEngine(x, y, m) if engine == "blocks" else _TableEngine(x, y, m)
    try:
        return _sor_loop(eng, m, cfg, tol, callback)
    finally:
        eng.finish()


def _sor_loop(eng, m, cfg: EllipticConfig, tol: float, callback) -> tuple[int, float, list, str]:
    n_eff = max(math.sqrt(2.0 * max(m.n_nodes, 4)), 2.0)
    omega = cfg.omega if cfg.omega is not None else 2.0 / (1.0 + math.sin(math.pi / n_eff))
    auto = cfg.omega is None
    r = eng.residual()
    history = [(0, r)]
    if r <= tol:
        return 0, r, history, ""
    best = r
    saved = eng.save()
    check_every, since, message = 1, 0, ""
    it = 0
    for it in range(1, cfg.max_iterations + 1):
        d = eng.sweep(omega) / omega
        since += 1
        if not math.isfinite(d) or since >= check_every or d < 4.0 * tol:
            since = 0
            r = eng.residual() if math.isfinite(d) else math.inf
            history.append((it, r))
            if callback is not None and callback(it, r) == "stop":
                return it, r, history, "stopped"
            if r <= tol:
                return it, r, history, ""
            if not math.isfinite(r) or r > 1e3 * best:
                eng.restore(saved)
                if not auto and omega <= 1.0:
                    return it, eng.residual(), history, "diverged"
                omega = 1.0 + 0.5 * (omega - 1.0) if omega > 1.05 else 0.7 * omega
                message = f"omega reduced to {omega:.3f}"
                check_every = 1
            elif r < best:
                best = r
                saved = eng.save()
                check_every = min(2 * check_every, 32)
    return it, eng.residual(), history, message
