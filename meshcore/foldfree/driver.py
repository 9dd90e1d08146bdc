r"""Fold-free grids: untangle and minimise the corner-triangle barrier functional.

Validity
--------
A grid is *valid* when all four corner Jacobians of every cell are positive
(:func:`meshcore.quality.quality`: ``n_nonconvex == 0``).  The corner Jacobian
of a block-corner cell at the block corner depends on three boundary nodes
only; when the boundary angle there is ≥ 180° it cannot be positive.  Such a
corner is *exempt*: it is reported as a boundary problem (which corner to
move) and ignored by the optimisation and by the validity test.

Method
------
Minimise ``E = Σ_cells Σ_corners F/χ(D, ε)`` (see
:mod:`meshcore.foldfree._kernels`) over the free nodes:

1. *Untangling* (only while some corner Jacobian ``D ≤ 0``): ``ε`` starts at
   ``sqrt(0.04 D_min²)`` and after each inner minimisation is updated by the
   rule of Garanzha et al. (2021): ``σ = max(1 − E/E_prev, 0.1)``,
   ``μ = (1 − σ) χ(D_min, ε)``, ``ε ← 2 sqrt(μ (μ − D_min))`` if
   ``D_min < μ`` — it shrinks ``χ`` at the worst corner by ``1 − σ``.
2. *Barrier* (``ε = 0``): node-wise damped Newton in 4-colour order, trying
   the over-relaxed step ``1.9·δ`` first (nonlinear SOR); every
   accepted step lowers the energy and the barrier ``E = ∞`` at ``D = 0``
   keeps every corner Jacobian positive, so the grid stays valid.

:func:`repair` applies this to *patches*: the invalid cells dilated by ``r``
cells, with all other nodes fixed.  The patch falls apart into connected
pieces, each minimised on its own: a piece that ends valid keeps its nodes,
a failed one gets them back and grows (``r`` doubles) until it covers 30 %
of the block or, when a coarse start can follow, is :data:`TRANSPLANT` cells
wide, so one fold that cannot be repaired locally does not drag the
others along.  For the cells still bad, a *multilevel start*: every second
grid line of the given grid gives a coarse grid, which is repaired (the
same steps, recursively); its bilinear prolongation is convex inside every
convex coarse cell (iso-lines of a bilinear map are straight, so a fine
corner Jacobian is the bilinear Jacobian times the index steps), and only
cells near the finer boundary need a local repair.  It replaces the grid
within :data:`TRANSPLANT` cells of the cells still bad (then the seam is
relaxed), or, if that fails, the whole grid (then relaxed by barrier
sweeps); on the coarse levels of that recursion the transplant is skipped
when the level below needed its whole coarse start (:data:`SKIP_TRANSPLANT`).
The whole block with a full minimisation per ε is tried on the
coarse levels of that recursion and on grids too small to coarsen; on the
given grid it never succeeded where the coarse start had failed (15 generated
one-block shapes, 8 real lakes) and cost 18 s of CPU on a 24 000-node lake,
so it is not tried there.  A repair that fails keeps the pieces it repaired
and names the cells still bad.
A Winslow grid that folds in a few places is repaired
at a small fraction of the cost of the elliptic solve.  :func:`smooth`
minimises over the whole block (``method="foldfree"`` of
:func:`meshcore.generate_block`).  Periodic (O-grid) blocks are supported:
the seam nodes are free and column ``ni`` follows column 0.

When no valid grid is found (a narrow arm with too few border nodes, a
boundary that crosses itself after re-sampling, …) the functions raise
:class:`~meshcore.errors.FoldedGridError` (``strict=True``, the default) or
return the best grid with ``converged=False``; the message names the cells,
their coordinates and the fix.  An invalid grid is never reported as
converged.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ..errors import FoldedGridError
from ..grid import SolveInfo, StructuredGrid
from .cells import (
    BoundaryCorner,
    _dilate,
    _exempt_bits,
    _failure_message,
    _folded,
    _median_edge,
    _nodes_of,
    _touched_cells,
    block_corner_problems,
    invalid_cells,
)
from .minimise import minimise, patches

#: Cells around those still bad after the local repair that take the coarse-grid start's nodes
#: (the multilevel stage, first try).  4, 8, 16 on 5 generated one-block shapes whose repair took
#: this path and a lake: 8 and 16 took 0.6–1.0 CPU-s each, 4 up to twice as long (its
#: seam folded again more often); the smaller of the two keeps more of the elliptic grid.
#: Also the widest patch (radius) of the local repairs before and after the transplant when a
#: coarse start can follow: a place a patch this wide does not repair is the coarse start's.
#: Without the cap the patches grew to 30 % of the block first: on 24 one-block grids
#: (8 real lakes at 24 000 nodes, 16 generated shapes at 6 000, the ratio of
#: :func:`meshcore.cellratio.cell_ratio`) the same outcome on all, 2 of them repaired by the
#: coarse start instead of a wide patch (fewer nodes moved, the same orthogonality), repair
#: CPU 32.8 → 22.7 s in all (Shasta 6.0 → 4.0 s, Lucerne 4.3 → 1.7 s, Como 8.0 → 5.0 s).
TRANSPLANT = 8
#: Cells beyond the transplanted region whose nodes are relaxed with it (the seam between the
#: coarse start and the kept grid): largest adjacent size ratio 168 → 56, 1320 → 61 on two of the
#: grids above, no change on the others, at no measurable cost.
SEAM = 4
#: Most barrier sweeps when a coarse start is relaxed.  0, 25, 100, 400 on 5 grids (4 generated,
#: a lake) whose repair relaxed the whole block: no setting better on all of mean orthogonality,
#: largest size ratio and least Jacobian ratio; 400 cost up to 4 CPU-s more at 24 000 nodes than 100.
RELAX_SWEEPS = 100
#: On a coarse level of the multilevel start (whose grid only starts the finer one), when the coarse
#: grid below it needed one of these steps (its own whole coarse start, or the whole block), the
#: places are wider than a transplant: the transplant is not tried, the whole coarse start follows at
#: once.  repair() on 22 Winslow grids (6 real lakes at 24 000 nodes, 16 generated one-block shapes
#: at 6000), four runs alternating with the repair without it, CPU, load 7-9: 17.8 -> 14.1,
#: 17.0 -> 13.8, 19.7 -> 16.1, 17.5 -> 15.4 s in all (Como 3.9-5.6 -> 2.3-2.9 s, Lugano 3.2-4.2 ->
#: 2.4-2.8, spiral 1.4-1.5 -> 1.1-1.3; Shasta 2.7-2.9 -> 2.4-3.3); the same grids bit for bit on
#: 18, all 22 as fold-free as before; the four that differ (mean deviation from orthogonality,
#: largest size ratio, least Jacobian ratio): Shasta 50.7 -> 50.6°, 37 -> 44, 0.016 -> 0.005;
#: Como 61.0 -> 61.6°, 100 -> 55, 0.008 -> 0.011; Lugano 60.1 -> 60.3°, 805 -> 35, 0.002 ->
#: 0.004; spiral 71.0 -> 68.3°, 418 -> 295, 0.003 -> 0.007.  On the given grid the transplant is
#: still tried (it succeeded on a generated network whose coarse grid needed its whole start), and
#: when the given grid's repair fails from a start built with skips it is tried once more without
#: them (a 20 × 30 hairpin slot was left with 2 bad cells otherwise).
SKIP_TRANSPLANT = ("coarse", "whole")
#: The coarse start is made after one round of patches (``radius``); when its repair needed its
#: whole coarse start (as :data:`SKIP_TRANSPLANT`), the wider patches are not tried (on a coarse
#: level the transplant neither: the whole coarse start follows at once; the given grid still
#: tries its transplant), otherwise the wider patches and the transplant follow as before.
#: Session 16, measured in benchmarks/RESULTS.md (real lakes as one block).
EARLY_START = True
#: Solve the coarse grid of the multilevel start (every second grid line) for Winslow before it is
#: repaired.  Off: the coarse grid is the given grid's own lines.  Those lines are a converged
#: elliptic solution already (the finer one: the given grid, or the level above), and the coarse
#: grid only starts the finer one; re-solving it on the branched lakes took 104 multigrid cycles at
#: the first coarse level (Shasta, 58 ms) and hundreds of SOR sweeps below.  repair() on 79 saved
#: Winslow grids (8 real lakes at 24 000 nodes, 70 generated one-block shapes at 6000 and 24 000;
#: session 30, benchmarks/RESULTS.md): 58 repaired either way (one generated network lost, one
#: gained), CPU -8 % to -16 % on the branched lakes.
COARSE_SOLVE = False

__all__ = [
    "BoundaryCorner",
    "FoldFreeResult",
    "block_corner_problems",
    "invalid_cells",
    "repair",
    "smooth",
]


@dataclass(frozen=True, slots=True, eq=False)
class FoldFreeResult:
    """What :func:`repair` / :func:`smooth` did (also summarised in ``grid.info``)."""

    grid: StructuredGrid
    ok: bool
    invalid_before: int
    folded_before: int
    invalid_after: int
    exempt: tuple[BoundaryCorner, ...]
    free_nodes: int
    sweeps: int
    elapsed: float
    message: str
    bad_cells: np.ndarray = field(repr=False)


def _prepare(grid: StructuredGrid) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[BoundaryCorner], np.ndarray]:
    """``(x, y, invalid cells, exempt corners, their bits)``: the working copy of a grid to repair."""
    exempt = block_corner_problems(grid)
    ex_bits = _exempt_bits(grid, exempt)
    x = np.array(grid.x, dtype=np.float64, order="C")
    y = np.array(grid.y, dtype=np.float64, order="C")
    return x, y, invalid_cells(x, y, ex_bits), exempt, ex_bits


def _result(grid, x, y, *, ok, before, folded_before, exempt, ex_bits, nodes, sweeps, t0, method, msg):
    bad = invalid_cells(x, y, ex_bits)
    ok = ok and not bad.any()
    flat = _folded(x, y)
    if flat and ok:  # an exempt corner excuses a corner angle, never a cell without area
        ok = False
        msg = (
            f"{msg}; {flat} cell(s) have no area (area ≤ 0): the block's corners leave them no room "
            f"(choose other corners or more cells)"
        )
    info = SolveInfo(
        method=method,
        converged=grid.info.converged and ok,
        iterations=grid.info.iterations,
        residual=grid.info.residual,
        tolerance=grid.info.tolerance,
        residual_history=grid.info.residual_history,
        elapsed=grid.info.elapsed + (time.perf_counter() - t0),
        message=msg,
    )
    g = StructuredGrid(x, y, info=info, names=grid.names, periodic=grid.periodic)
    return FoldFreeResult(
        grid=g,
        ok=ok,
        invalid_before=before,
        folded_before=folded_before,
        invalid_after=int(bad.sum()),
        exempt=tuple(exempt),
        free_nodes=int(nodes),
        sweeps=sweeps,
        elapsed=time.perf_counter() - t0,
        message=msg,
        bad_cells=np.argwhere(bad),
    )


def _raise_if_failed(res: FoldFreeResult, failed: bool) -> FoldFreeResult:
    """``res``, or (strict mode, ``failed``) a :class:`FoldedGridError` that carries it."""
    if failed:
        err = FoldedGridError(res.message)
        err.result = res  # type: ignore[attr-defined]
        raise err
    return res


def repair(
    grid: StructuredGrid,
    *,
    radius: int = 2,
    tolerance: float = 1e-4,
    max_sweeps: int = 400,
    strict: bool = True,
) -> FoldFreeResult:
    """Make a grid fold-free by local barrier minimisation around its invalid cells.

    Parameters
    ----------
    grid : StructuredGrid
        E.g. a converged Winslow grid; its boundary nodes stay fixed.
    radius : int
        Initial patch radius (cells) around the invalid cells; doubled on failure
        until the patch is the whole block.
    tolerance : float
        Stop the barrier sweeps when no node moves more than
        ``tolerance × h`` (``h`` = median edge length of the patch).
    max_sweeps : int
        Cap on barrier sweeps per patch.
    strict : bool
        Raise :class:`FoldedGridError` when no valid grid is found; otherwise
        return the best grid with ``ok = False`` and ``grid.converged = False``.

    Returns
    -------
    FoldFreeResult
        ``result.grid`` is the repaired grid (``info.method`` ends in
        ``+foldfree`` when nodes moved, ``info.message`` says why).
    """
    return _repair(grid, radius=radius, tolerance=tolerance, max_sweeps=max_sweeps, strict=strict, whole=False)


def _repair(
    grid: StructuredGrid,
    *,
    radius: int = 2,
    tolerance: float = 1e-4,
    max_sweeps: int = 400,
    strict: bool = False,
    whole: bool,
    path: list[str] | None = None,
    skip: bool = True,
) -> FoldFreeResult:
    """:func:`repair`; ``whole``: try the whole block when the coarse start fails (the coarse levels);
    ``path`` gets the step that made the grid valid (``"local"``, ``"transplant"``, ``"coarse"``:
    the whole coarse start, ``"whole"``) or ``"failed"``, and ``"skip"`` when a coarse level skipped
    its transplant (``skip``: allowed, see :data:`SKIP_TRANSPLANT`)."""
    path = [] if path is None else path
    t0 = time.perf_counter()
    x, y, bad, exempt, ex_bits = _prepare(grid)
    before, folded_before = int(bad.sum()), _folded(x, y)
    exempt_note = ("; " + "; ".join(c.message for c in exempt)) if exempt else ""
    common = {"folded_before": folded_before, "exempt": exempt, "ex_bits": ex_bits, "t0": t0}
    if before == 0:
        msg = grid.info.message + exempt_note
        res = _result(grid, x, y, ok=True, before=0, nodes=0, sweeps=0, method=grid.info.method, msg=msg, **common)
        return _raise_if_failed(res, strict and not res.ok)
    opts = {"tolerance": tolerance, "max_sweeps": max_sweeps, "periodic": grid.periodic}
    coarse = min(grid.cells) >= 8
    ok, nfree, total, start = _local(grid, x, y, bad, ex_bits, radius, opts, coarse=coarse, skip=skip, path=path)
    how = ""
    if ok:
        path.append("local")
    if not ok and coarse:
        # the pieces repaired so far stay; the rest from a coarse-grid start
        kept = None if whole else (x.copy(), y.copy())
        ok, nfree, total = _multilevel(
            grid, x, y, ex_bits, radius, opts, nfree, total, seam=not whole, path=path, skip=skip, start=start
        )
        if not ok and kept is not None and "skip" in path:
            # the given grid failed from a start whose coarse levels skipped their transplant: once
            # more without skipping (a 20 × 30 hairpin slot failed by two cells, see SKIP_TRANSPLANT)
            x[...], y[...] = kept
            ok, nfree, total = _multilevel(
                grid, x, y, ex_bits, radius, opts, nfree, total, seam=True, path=path, skip=False
            )
        how = " after a coarse-grid (multilevel) start" if ok else ""
    if not ok and (whole or not coarse):
        ok, nfree, sw = _whole(grid, x, y, ex_bits, opts)
        total += sw
        path.append("whole" if ok else "failed")
    elif not ok:
        path.append("failed")
    origin = f"{grid.info.method} {grid.info.message}".strip()
    if ok:
        msg = (
            f"{origin}; its grid had {before} non-convex cell(s) ({folded_before} folded); "
            f"repaired by the fold-free barrier method on {nfree} node(s) ({total} sweeps){how}"
            f"{exempt_note}"
        )
    else:
        msg = f"{origin}; " + _failure_message(StructuredGrid(x, y), invalid_cells(x, y, ex_bits), exempt)
    method = f"{grid.info.method}+foldfree"
    res = _result(grid, x, y, ok=ok, before=before, nodes=nfree, sweeps=total, method=method, msg=msg, **common)
    return _raise_if_failed(res, strict and not res.ok)


def _local(
    grid: StructuredGrid,
    x: np.ndarray,
    y: np.ndarray,
    bad: np.ndarray,
    ex_bits: np.ndarray,
    radius: int,
    opts: dict,
    *,
    coarse: bool,
    skip: bool,
    path: list[str],
) -> tuple[bool, int, int, tuple[np.ndarray, np.ndarray, bool] | bool | None]:
    """The local stage of :func:`_repair`: ``(ok, free nodes, sweeps, coarse start)``.

    Where a coarse start can follow (``coarse``) the pieces grow no wider than its transplant
    (see :data:`TRANSPLANT`), and with :data:`EARLY_START` the coarse start is made after the
    first round (``radius``): when its repair needed its whole coarse start, the wider rounds are
    not tried.  The start is returned for :func:`_multilevel` (``None``: not made yet, ``False``:
    its coarse grid was not repaired).
    """
    cap = TRANSPLANT if coarse else None
    if not (coarse and EARLY_START):
        return (*patches(x, y, bad, ex_bits, radius=radius, max_fraction=0.3, max_radius=cap, **opts), None)
    ok, nfree, total = patches(x, y, bad, ex_bits, radius=radius, max_fraction=0.3, max_radius=radius, **opts)
    if ok:
        return ok, nfree, total, None
    start = _coarse_start(grid, skip, path) or False
    if start and start[2] and skip:
        return ok, nfree, total, start
    ok, nf, sw = patches(
        x, y, invalid_cells(x, y, ex_bits), ex_bits, radius=2 * radius, max_fraction=0.3, max_radius=cap, **opts
    )
    return ok, nfree + nf, total + sw, start


def _whole(
    grid: StructuredGrid, x: np.ndarray, y: np.ndarray, ex_bits: np.ndarray, opts: dict
) -> tuple[bool, int, int]:
    """The whole block, a full minimisation per ε (``(ok, free nodes, sweeps)``; ``x, y`` kept on failure)."""
    n = max(grid.cells)
    return patches(x, y, invalid_cells(x, y, ex_bits), ex_bits, radius=n, max_fraction=1.0, inner=20, **opts)


def _relax(x: np.ndarray, y: np.ndarray, region: np.ndarray, ex_bits: np.ndarray, opts: dict) -> int:
    """At most ``RELAX_SWEEPS`` barrier sweeps over the nodes of the valid cells ``region``; the sweeps made."""
    nodes = _nodes_of(region, opts["periodic"])
    if nodes.size == 0:
        return 0
    cells = _touched_cells(nodes, region.shape, opts["periodic"])
    tol = opts["tolerance"] * _median_edge(x, y, cells)
    sweeps = min(opts["max_sweeps"], RELAX_SWEEPS)
    return minimise(x, y, nodes, cells, ex_bits, tol=tol, max_sweeps=sweeps, periodic=opts["periodic"])[1]


def _multilevel(
    grid: StructuredGrid,
    x: np.ndarray,
    y: np.ndarray,
    ex_bits: np.ndarray,
    radius: int,
    opts: dict,
    nfree: int,
    total: int,
    *,
    seam: bool,
    path: list[str],
    skip: bool,
    start: tuple[np.ndarray, np.ndarray, bool] | bool | None = None,
) -> tuple[bool, int, int]:
    """The multilevel stage of :func:`repair`: ``(ok, free nodes, sweeps)``.

    ``x, y`` hold the grid with the pieces repaired locally so far.  First the
    coarse start replaces the nodes within ``TRANSPLANT`` cells of the cells
    still bad and those are repaired locally (the rest of the grid is kept;
    ``seam``: the seam is relaxed; not on the coarse levels, where a relaxed
    seam made a 20 × 30 hairpin slot fail one level up);
    if that fails, the whole grid becomes the coarse start, its few bad cells
    (near the finer boundary) are repaired locally and the block is relaxed
    by barrier sweeps.  On failure ``x, y`` keep the grid with the fewest bad
    cells.
    """
    if start is None:
        start = _coarse_start(grid, skip, path)
    if not start:  # None or False: the coarse grid was not repaired
        return False, nfree, total
    x2, y2, wide = start
    bad = invalid_cells(x, y, ex_bits)
    xk, yk = x.copy(), y.copy()
    best = (int(bad.sum()), xk, yk)
    if skip and wide and not seam:  # a coarse level whose own coarse start needed more than a
        # transplant (see SKIP_TRANSPLANT)
        path.append("skip")
        return _whole_start(x, y, x2, y2, ex_bits, radius, opts, nfree, total, best, path)
    # (1) the coarse start only around the cells still bad
    region = _dilate(bad, TRANSPLANT, grid.periodic)
    nodes = _nodes_of(region, grid.periodic)
    ii, jj = nodes[:, 0], nodes[:, 1]
    x[ii, jj], y[ii, jj] = x2[ii, jj], y2[ii, jj]
    if grid.periodic:
        x[-1, :], y[-1, :] = x[0, :], y[0, :]
    # patches no wider than the transplant: a seam they cannot repair (the coarse start's rows
    # follow arms where the kept grid's did not) is the whole coarse start's case
    placed = (x.copy(), y.copy())
    transplant = {"radius": radius, "max_fraction": 0.3, "max_radius": TRANSPLANT, **opts}
    ok, nf, sw = patches(x, y, invalid_cells(x, y, ex_bits), ex_bits, give_up_early=True, **transplant)
    total += sw
    if ok:
        # relax the seam between the coarse start and the kept grid: barrier sweeps around the region
        if seam:
            total += _relax(x, y, _dilate(region, SEAM, grid.periodic), ex_bits, opts)
        path.append("transplant")
        return True, nfree + nf, total

    def finished() -> tuple[int, np.ndarray, np.ndarray]:
        # the failed transplant with all its pieces tried: the grid kept if the whole start fails too
        xf, yf = placed[0].copy(), placed[1].copy()
        patches(xf, yf, invalid_cells(xf, yf, ex_bits), ex_bits, **transplant)
        return int(invalid_cells(xf, yf, ex_bits).sum()), xf, yf

    return _whole_start(x, y, x2, y2, ex_bits, radius, opts, nfree, total, best, path, finished)


def _whole_start(
    x: np.ndarray,
    y: np.ndarray,
    x2: np.ndarray,
    y2: np.ndarray,
    ex_bits: np.ndarray,
    radius: int,
    opts: dict,
    nfree: int,
    total: int,
    best: tuple,
    path: list[str],
    transplant: Callable[[], tuple[int, np.ndarray, np.ndarray]] | None = None,
) -> tuple[bool, int, int]:
    """Step (2) of :func:`_multilevel`: the whole coarse start ``x2, y2``, its bad cells repaired
    locally, the block relaxed; on failure ``x, y`` become ``best`` (``(bad cells, x, y)``, or the
    failed transplant's grid ``transplant()`` if that has fewer) unless the coarse start has fewer
    bad cells."""
    x[...], y[...] = x2, y2
    ok, _, sw = patches(x, y, invalid_cells(x, y, ex_bits), ex_bits, radius=radius, max_fraction=0.3, **opts)
    total += sw
    if ok:
        # the prolonged grid is piecewise bilinear: relax it on the whole block
        whole = np.ones((x.shape[0] - 1, x.shape[1] - 1), dtype=bool)
        path.append("coarse")
        return True, len(_nodes_of(whole, opts["periodic"])), total + _relax(x, y, whole, ex_bits, opts)
    now = int(invalid_cells(x, y, ex_bits).sum())
    if transplant is not None:
        tried = transplant()
        if tried[0] < best[0]:
            best = tried
    if now >= best[0]:
        x[...], y[...] = best[1], best[2]
    return False, nfree, total


def _coarse_start(
    grid: StructuredGrid, skip: bool = True, path: list[str] | None = None
) -> tuple[np.ndarray, np.ndarray, bool] | None:
    """Multilevel start: every second grid line (of the grid as it is, see :data:`COARSE_SOLVE`),
    repaired there, bilinear prolongation;
    ``(x, y, wide)``, ``wide``: the coarse grid's repair was one of :data:`SKIP_TRANSPLANT`
    (``skip``: its coarse levels may skip their transplant; ``path`` gets ``"skip"`` if one did).

    Inside a convex coarse cell the bilinear map is injective and its
    iso-lines are straight, so the fine cells it creates are convex (their
    corner Jacobians are the bilinear Jacobian times the index steps); only
    fine cells near the boundary (whose nodes are the true, finer boundary)
    and across coarse-cell edges may need a local repair afterwards.
    """
    ni, nj = grid.cells
    ic = np.unique(np.r_[np.arange(0, ni + 1, 2), ni])
    jc = np.unique(np.r_[np.arange(0, nj + 1, 2), nj])
    gc = StructuredGrid(grid.x[np.ix_(ic, jc)], grid.y[np.ix_(ic, jc)], periodic=grid.periodic)
    if COARSE_SOLVE:
        from ..elliptic import solve

        gc = solve(gc)
    below: list[str] = []
    res = _repair(gc, whole=True, path=below, skip=skip)
    if path is not None and "skip" in below:
        path.append("skip")
    if not res.ok:
        return None
    xc, yc = res.grid.x, res.grid.y

    def param(n: int, idx: np.ndarray):
        k = np.clip(np.searchsorted(idx, np.arange(n + 1), side="right") - 1, 0, len(idx) - 2)
        u = (np.arange(n + 1) - idx[k]) / (idx[k + 1] - idx[k])
        return k, u

    ki, u = param(ni, ic)
    kj, v = param(nj, jc)
    u = u[:, None]
    v = v[None, :]
    out = []
    for c, f in ((xc, grid.x), (yc, grid.y)):
        a00 = c[np.ix_(ki, kj)]
        a10 = c[np.ix_(ki + 1, kj)]
        a11 = c[np.ix_(ki + 1, kj + 1)]
        a01 = c[np.ix_(ki, kj + 1)]
        z = (1 - u) * (1 - v) * a00 + u * (1 - v) * a10 + u * v * a11 + (1 - u) * v * a01
        z[0, :], z[-1, :], z[:, 0], z[:, -1] = f[0, :], f[-1, :], f[:, 0], f[:, -1]
        out.append(np.ascontiguousarray(z))
    return out[0], out[1], bool(below) and below[-1] in SKIP_TRANSPLANT


def smooth(
    grid: StructuredGrid,
    *,
    tolerance: float = 1e-5,
    max_sweeps: int = 5000,
    strict: bool = True,
) -> FoldFreeResult:
    """Minimise the barrier functional over the whole block (untangling first if needed).

    The result is the discrete Winslow–Ivanenko grid: every corner Jacobian
    positive, close to the Winslow grid where that one is valid.  Parameters
    as in :func:`repair`; ``tolerance`` is relative to the median edge length.
    """
    t0 = time.perf_counter()
    x, y, bad, exempt, ex_bits = _prepare(grid)
    before, folded_before = int(bad.sum()), _folded(x, y)
    nodes = _nodes_of(np.ones(grid.cells, dtype=bool), grid.periodic)
    cells = _touched_cells(nodes, grid.cells, grid.periodic) if nodes.size else np.zeros((0, 2), np.int32)
    h = _median_edge(x, y, cells) if nodes.size else 0.0
    sw = 0
    ok = True
    if before and nodes.size:
        # untangle first where it is cheap: local patches, multilevel start, whole block
        fixed = _repair(grid, whole=True)
        sw += fixed.sweeps
        ok = fixed.ok
        if ok:
            x[...], y[...] = fixed.grid.x, fixed.grid.y
    if ok and nodes.size:
        ok, sw2 = minimise(
            x,
            y,
            nodes,
            cells,
            ex_bits,
            tol=tolerance * h,
            max_sweeps=max_sweeps,
            periodic=grid.periodic,
        )
        sw += sw2
    exempt_note = ("; " + "; ".join(c.message for c in exempt)) if exempt else ""
    if ok and not invalid_cells(x, y, ex_bits).any():
        msg = (
            f"fold-free barrier minimisation ({sw} sweeps; start grid had {before} non-convex, "
            f"{folded_before} folded cell(s)){exempt_note}"
        )
    else:
        ok = False
        msg = _failure_message(StructuredGrid(x, y), invalid_cells(x, y, ex_bits), exempt)
    res = _result(
        grid,
        x,
        y,
        ok=ok,
        before=before,
        folded_before=folded_before,
        exempt=exempt,
        ex_bits=ex_bits,
        nodes=len(nodes),
        sweeps=sw,
        t0=t0,
        method="foldfree",
        msg=msg,
    )
    return _raise_if_failed(res, strict and not res.ok)
