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
cells, with all other nodes fixed; ``r`` doubles until the patch succeeds or
covers 30 % of the block.  If that fails, a *multilevel start*: every second
grid line gives a coarse grid, which is solved (Winslow) and repaired; its
bilinear prolongation is convex inside every convex coarse cell (iso-lines
of a bilinear map are straight, so a fine corner Jacobian is the bilinear
Jacobian times the index steps), and only cells near the finer boundary
need a local repair.  The last resort is the whole block with a full
minimisation per ε.  A Winslow grid that folds in a few places is repaired
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

import math
import time
from dataclasses import dataclass, field

import numpy as np

from ..errors import FoldedGridError
from ..grid import SolveInfo, StructuredGrid
from . import _kernels

__all__ = [
    "BoundaryCorner",
    "FoldFreeResult",
    "block_corner_problems",
    "invalid_cells",
    "repair",
    "smooth",
]


@dataclass(frozen=True, slots=True)
class BoundaryCorner:
    """A block corner whose boundary angle is ≥ 180° (its corner cell cannot be convex)."""

    corner: str
    cell: tuple[int, int]
    point: tuple[float, float]
    angle: float

    @property
    def message(self) -> str:
        return (
            f"block corner {self.corner} at ({self.point[0]:.6g}, {self.point[1]:.6g}) has a "
            f"boundary angle of {self.angle:.1f}° ≥ 180°, so its corner cell {self.cell} cannot be "
            f"convex; move corner {self.corner} to a convex boundary vertex"
        )


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


def block_corner_problems(grid: StructuredGrid) -> list[BoundaryCorner]:
    """Block corners with a boundary angle ≥ 180° (corner Jacobian ≤ 0 from boundary nodes)."""
    if grid.periodic:
        return []
    x, y = grid.x, grid.y
    ni, nj = grid.cells
    # (name, cell, corner index m of that cell): corners c0..c3 = 00, 10, 11, 01
    table = (
        ("sw", (0, 0), 0),
        ("se", (ni - 1, 0), 1),
        ("ne", (ni - 1, nj - 1), 2),
        ("nw", (0, nj - 1), 3),
    )
    out = []
    for name, (ci, cj), m in table:
        cx = [x[ci, cj], x[ci + 1, cj], x[ci + 1, cj + 1], x[ci, cj + 1]]
        cy = [y[ci, cj], y[ci + 1, cj], y[ci + 1, cj + 1], y[ci, cj + 1]]
        ax, ay = cx[(m + 1) % 4] - cx[m], cy[(m + 1) % 4] - cy[m]
        bx, by = cx[(m + 3) % 4] - cx[m], cy[(m + 3) % 4] - cy[m]
        cross = ax * by - ay * bx
        if cross <= 0.0:
            ang = math.degrees(math.atan2(cross, ax * bx + ay * by)) % 360.0
            out.append(BoundaryCorner(name, (ci, cj), (float(cx[m]), float(cy[m])), ang))
    return out


def _exempt_bits(grid: StructuredGrid, corners: list[BoundaryCorner]) -> np.ndarray:
    ex = np.zeros(grid.cells, dtype=np.uint8)
    m_of = {"sw": 0, "se": 1, "ne": 2, "nw": 3}
    for c in corners:
        ex[c.cell] |= np.uint8(1 << m_of[c.corner])
    return ex


def invalid_cells(x: np.ndarray, y: np.ndarray, exempt: np.ndarray | None = None) -> np.ndarray:
    """Boolean ``(ni, nj)`` mask of cells with a corner Jacobian ≤ 0 (exempt corners ignored)."""
    cj = _kernels.corner_jacobians(np.ascontiguousarray(x), np.ascontiguousarray(y))
    bad = cj <= 0.0
    if exempt is not None:
        for m in range(4):
            bad[m] &= ((exempt >> m) & 1) == 0
    return bad.any(axis=0)


def _nodes_of(cells_mask: np.ndarray, periodic: bool) -> np.ndarray:
    """Free nodes (interior nodes of the masked cells), int32 (k, 2), in 4-colour order."""
    ni, nj = cells_mask.shape
    nm = np.zeros((ni + 1, nj + 1), dtype=bool)
    nm[:-1, :-1] |= cells_mask
    nm[1:, :-1] |= cells_mask
    nm[1:, 1:] |= cells_mask
    nm[:-1, 1:] |= cells_mask
    if periodic:  # column ni repeats column 0: a seam node is listed once, as column 0
        nm[0, :] |= nm[-1, :]
    else:
        nm[0, :] = False
    nm[-1, :] = False
    nm[:, 0] = False
    nm[:, -1] = False
    idx = np.argwhere(nm).astype(np.int32)
    colour = (idx[:, 0] % 2) * 2 + (idx[:, 1] % 2)
    return np.ascontiguousarray(idx[np.argsort(colour, kind="stable")])


def _touched_cells(nodes: np.ndarray, shape: tuple[int, int], periodic: bool = False) -> np.ndarray:
    ni, nj = shape
    m = np.zeros((ni, nj), dtype=bool)
    for di in (0, 1):
        for dj in (0, 1):
            ci = nodes[:, 0] - di
            if periodic:
                ci = ci % ni
            cj = nodes[:, 1] - dj
            ok = (ci >= 0) & (cj >= 0) & (ci < ni) & (cj < nj)
            m[ci[ok], cj[ok]] = True
    return np.ascontiguousarray(np.argwhere(m).astype(np.int32))


def _dilate(mask: np.ndarray, r: int, periodic: bool = False) -> np.ndarray:
    out = mask.copy()
    for _ in range(r):
        if periodic:  # wrap across the seam in ξ
            out = out | np.roll(out, 1, axis=0) | np.roll(out, -1, axis=0)
        m = out.copy()
        m[1:, :] |= out[:-1, :]
        m[:-1, :] |= out[1:, :]
        m[:, 1:] |= out[:, :-1]
        m[:, :-1] |= out[:, 1:]
        m[1:, 1:] |= out[:-1, :-1]
        m[:-1, :-1] |= out[1:, 1:]
        m[1:, :-1] |= out[:-1, 1:]
        m[:-1, 1:] |= out[1:, :-1]
        out = m
    return out


#: Most sweeps per ε in the untangling stage (fewer when the energy stalls); one is fastest
#: on lakes, slots and C shapes (measured 1–40); the whole-block last resort uses 20.
_INNER = 1


def _minimise(
    x: np.ndarray,
    y: np.ndarray,
    nodes: np.ndarray,
    cells: np.ndarray,
    exempt: np.ndarray,
    *,
    tol: float,
    max_sweeps: int,
    max_outer: int = 500,
    inner: int | None = None,
    omega: float = 1.9,
    periodic: bool = False,
) -> tuple[bool, int]:
    """Untangle (if needed) then minimise the barrier energy over ``nodes`` in place.

    Returns ``(valid, sweeps)``.
    """
    inner = _INNER if inner is None else inner
    sweeps = 0
    step = np.inf
    _, dmin = _kernels.patch_stats(x, y, cells, 0.0, exempt)
    if dmin <= 0.0:
        eps_floor = 1e-12 * _median_area(x, y, cells)
        eps = max(math.sqrt(0.04 * dmin * dmin), eps_floor)
        e_prev, _ = _kernels.patch_stats(x, y, cells, eps, exempt)
        for _outer in range(max_outer):
            # minimise at this ε until the energy stalls (≤ inner sweeps)
            e_in = e_prev
            for _ in range(inner):
                d = _kernels.sweep(x, y, nodes, eps, step, 1.0, periodic)
                sweeps += 1
                e, dmin = _kernels.patch_stats(x, y, cells, eps, exempt)
                if d <= tol or dmin > 0.0 or e_in - e <= 1e-3 * e:
                    break
                e_in = e
            if dmin > 0.0:
                break
            sigma = max(1.0 - e / e_prev, 0.1)
            chi = 0.5 * (dmin + math.sqrt(eps * eps + dmin * dmin))
            mu = (1.0 - sigma) * chi
            eps = 2.0 * math.sqrt(mu * (mu - dmin)) if dmin < mu else eps_floor
            eps = max(eps, eps_floor)
            if eps < 1e-4 * abs(dmin):
                break  # stagnated: ε has vanished next to the worst inverted corner
            e_prev, _ = _kernels.patch_stats(x, y, cells, eps, exempt)
        if dmin <= 0.0:
            return False, sweeps
    for _ in range(max_sweeps):
        d = _kernels.sweep(x, y, nodes, 0.0, step, omega, periodic)
        sweeps += 1
        if d <= tol:
            break
    _, dmin = _kernels.patch_stats(x, y, cells, 0.0, exempt)
    return dmin > 0.0, sweeps


def _failure_message(grid: StructuredGrid, bad: np.ndarray, exempt: list[BoundaryCorner]) -> str:
    x, y = grid.x, grid.y
    ni, nj = grid.cells
    idx = np.argwhere(bad)
    parts = []
    for ci, cj in idx[:6]:
        cx = 0.25 * (x[ci, cj] + x[ci + 1, cj] + x[ci + 1, cj + 1] + x[ci, cj + 1])
        cy = 0.25 * (y[ci, cj] + y[ci + 1, cj] + y[ci + 1, cj + 1] + y[ci, cj + 1])
        parts.append(f"({ci}, {cj}) at ({cx:.6g}, {cy:.6g})")
    more = f" and {len(idx) - 6} more" if len(idx) > 6 else ""
    # which borders are nearest to the bad cells (index-space distance)
    near = {"bottom": 0, "top": 0, "left": 0, "right": 0}
    for ci, cj in idx:
        d = {"bottom": cj, "top": nj - 1 - cj, "left": ci, "right": ni - 1 - ci}
        near[min(d, key=d.get)] += 1
    border = max(near, key=near.get)
    msg = (
        f"no fold-free grid found for these boundary nodes: {len(idx)} cell(s) stay folded or "
        f"non-convex: {', '.join(parts)}{more}. Fix: put more nodes on the {border} border "
        f"(raise cells in {'ξ' if border in ('bottom', 'top') else 'η'}) or a finer distribution "
        f"there, choose other corners, or split the region into blocks"
    )
    if exempt:
        msg += "; also: " + "; ".join(c.message for c in exempt)
    return msg


def _result(grid, x, y, *, ok, before, folded_before, exempt, ex_bits, nodes, sweeps, t0, method, msg):
    bad = invalid_cells(x, y, ex_bits)
    ok = ok and not bad.any()
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


def _folded(x, y) -> int:
    a = (x[1:, 1:] - x[:-1, :-1]) * (y[:-1, 1:] - y[1:, :-1]) - (x[:-1, 1:] - x[1:, :-1]) * (y[1:, 1:] - y[:-1, :-1])
    return int((a <= 0).sum())


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
    t0 = time.perf_counter()
    exempt = block_corner_problems(grid)
    ex_bits = _exempt_bits(grid, exempt)
    x = np.array(grid.x, dtype=np.float64, order="C")
    y = np.array(grid.y, dtype=np.float64, order="C")
    bad = invalid_cells(x, y, ex_bits)
    before = int(bad.sum())
    folded_before = _folded(x, y)
    exempt_note = ("; " + "; ".join(c.message for c in exempt)) if exempt else ""
    if before == 0:
        return _result(
            grid,
            x,
            y,
            ok=True,
            before=0,
            folded_before=folded_before,
            exempt=exempt,
            ex_bits=ex_bits,
            nodes=0,
            sweeps=0,
            t0=t0,
            method=grid.info.method,
            msg=grid.info.message + exempt_note,
        )
    ni, nj = grid.cells
    opts = {"tolerance": tolerance, "max_sweeps": max_sweeps, "periodic": grid.periodic}
    x0, y0 = x.copy(), y.copy()
    ok, nfree, total = _patches(x, y, bad, ex_bits, radius=radius, max_fraction=0.3, **opts)
    how = ""
    start = None
    if not ok:
        x[...], y[...] = x0, y0
        start = _coarse_start(grid) if min(ni, nj) >= 8 else None
        if start is not None:
            x2, y2 = start
            bad2 = invalid_cells(x2, y2, ex_bits)
            ok2, sw2 = True, 0
            if bad2.any():
                ok2, _, sw2 = _patches(x2, y2, bad2, ex_bits, radius=radius, max_fraction=0.3, **opts)
            total += sw2
            if ok2:
                # the prolonged grid is piecewise bilinear: relax it on the whole block
                nodes = _nodes_of(np.ones_like(bad), grid.periodic)
                cells = _touched_cells(nodes, (ni, nj), grid.periodic)
                h = _median_edge(x2, y2, cells)
                _, sw3 = _minimise(
                    x2,
                    y2,
                    nodes,
                    cells,
                    ex_bits,
                    tol=tolerance * h,
                    max_sweeps=max_sweeps,
                    periodic=grid.periodic,
                )
                total += sw3
                x[...], y[...] = x2, y2
                ok, nfree, how = True, len(nodes), " after a coarse-grid (multilevel) start"
    if not ok:
        # last resort: the whole block, a full minimisation per ε, from the start with fewer bad cells
        x[...], y[...] = x0, y0
        if start is not None and invalid_cells(start[0], start[1], ex_bits).sum() < before:
            x[...], y[...] = start
            bad = invalid_cells(x, y, ex_bits)
        ok, nfree, sw = _patches(x, y, bad, ex_bits, radius=max(ni, nj), max_fraction=1.0, inner=20, **opts)
        total += sw
    method = f"{grid.info.method}+foldfree"
    origin = f"{grid.info.method} {grid.info.message}".strip()
    if ok:
        msg = (
            f"{origin}; its grid had {before} non-convex cell(s) ({folded_before} folded); "
            f"repaired by the fold-free barrier method on {nfree} node(s) ({total} sweeps){how}"
            f"{exempt_note}"
        )
    else:
        bad_now = invalid_cells(x, y, ex_bits)
        msg = f"{origin}; " + _failure_message(StructuredGrid(x, y), bad_now, exempt)
    res = _result(
        grid,
        x,
        y,
        ok=ok,
        before=before,
        folded_before=folded_before,
        exempt=exempt,
        ex_bits=ex_bits,
        nodes=nfree,
        sweeps=total,
        t0=t0,
        method=method,
        msg=msg,
    )
    return _raise_if_failed(res, strict and not ok)


def _patches(
    x: np.ndarray,
    y: np.ndarray,
    bad: np.ndarray,
    ex_bits: np.ndarray,
    *,
    radius: int,
    max_fraction: float,
    tolerance: float,
    max_sweeps: int,
    inner: int | None = None,
    periodic: bool = False,
) -> tuple[bool, int, int]:
    """Barrier minimisation on patches around ``bad``; the radius doubles on failure.

    Stops when the patch covers more than ``max_fraction`` of the cells (the
    whole block is always allowed when ``max_fraction ≥ 1``).  On failure the
    nodes are left as they were.  Returns ``(ok, free nodes, sweeps)``.
    """
    ni, nj = bad.shape
    r = max(1, int(radius))
    total = 0
    nfree = 0
    while True:
        patch = _dilate(bad, r, periodic) if r < max(ni, nj) else np.ones_like(bad)
        if patch.mean() > max_fraction and max_fraction < 1.0:
            return False, nfree, total
        nodes = _nodes_of(patch, periodic)
        if nodes.size == 0:
            return False, 0, total
        cells = _touched_cells(nodes, (ni, nj), periodic)
        h = _median_edge(x, y, cells)
        xs, ys = x.copy(), y.copy()
        ok, sw = _minimise(
            x,
            y,
            nodes,
            cells,
            ex_bits,
            tol=tolerance * h,
            max_sweeps=max_sweeps,
            inner=inner,
            periodic=periodic,
        )
        total += sw
        nfree = len(nodes)
        if ok:
            bad_now = invalid_cells(x, y, ex_bits)
            if not bad_now.any():
                return True, nfree, total
            bad = bad | bad_now
        x[...], y[...] = xs, ys
        if patch.all():
            return False, nfree, total
        r *= 2


def _coarse_start(grid: StructuredGrid) -> tuple[np.ndarray, np.ndarray] | None:
    """Multilevel start: every second grid line, Winslow + repair there, bilinear prolongation.

    Inside a convex coarse cell the bilinear map is injective and its
    iso-lines are straight, so the fine cells it creates are convex (their
    corner Jacobians are the bilinear Jacobian times the index steps); only
    fine cells near the boundary (whose nodes are the true, finer boundary)
    and across coarse-cell edges may need a local repair afterwards.
    """
    from ..elliptic import solve

    ni, nj = grid.cells
    ic = np.unique(np.r_[np.arange(0, ni + 1, 2), ni])
    jc = np.unique(np.r_[np.arange(0, nj + 1, 2), nj])
    gc = solve(StructuredGrid(grid.x[np.ix_(ic, jc)], grid.y[np.ix_(ic, jc)], periodic=grid.periodic))
    res = repair(gc, strict=False)
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
    return out[0], out[1]


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
    exempt = block_corner_problems(grid)
    ex_bits = _exempt_bits(grid, exempt)
    x = np.array(grid.x, dtype=np.float64, order="C")
    y = np.array(grid.y, dtype=np.float64, order="C")
    bad = invalid_cells(x, y, ex_bits)
    before = int(bad.sum())
    folded_before = _folded(x, y)
    nodes = _nodes_of(np.ones(grid.cells, dtype=bool), grid.periodic)
    cells = _touched_cells(nodes, grid.cells, grid.periodic) if nodes.size else np.zeros((0, 2), np.int32)
    h = _median_edge(x, y, cells) if nodes.size else 0.0
    sw = 0
    ok = True
    if before and nodes.size:
        # untangle first where it is cheap: local patches, multilevel start, whole block
        fixed = repair(grid, strict=False)
        sw += fixed.sweeps
        ok = fixed.ok
        if ok:
            x[...], y[...] = fixed.grid.x, fixed.grid.y
    if ok and nodes.size:
        ok, sw2 = _minimise(
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
    return _raise_if_failed(res, strict and not ok)


def _median_area(x: np.ndarray, y: np.ndarray, cells: np.ndarray) -> float:
    ci, cj = cells[:, 0], cells[:, 1]
    a = (x[ci + 1, cj + 1] - x[ci, cj]) * (y[ci, cj + 1] - y[ci + 1, cj]) - (x[ci, cj + 1] - x[ci + 1, cj]) * (
        y[ci + 1, cj + 1] - y[ci, cj]
    )
    return float(np.median(np.abs(0.5 * a)))


def _median_edge(x: np.ndarray, y: np.ndarray, cells: np.ndarray) -> float:
    ci, cj = cells[:, 0], cells[:, 1]
    e1 = np.hypot(x[ci + 1, cj] - x[ci, cj], y[ci + 1, cj] - y[ci, cj])
    e2 = np.hypot(x[ci, cj + 1] - x[ci, cj], y[ci, cj + 1] - y[ci, cj])
    return float(np.median(np.concatenate([e1, e2])))
