r"""Edge-length smoothing along grid lines after the solve, guarded (issue 12: edge pairs ≤ 1.2).

The orthogonal smoother's size blend (:func:`~meshcore.orthogonal._kernels._target`) starts
at a ratio of 1.15 and is weak at 1.2–1.5, so rows whose spacing jumps by 1.2–1.5 survive the
solve: most of them within three cells of a block border (the first edges of the lines that
cross a shore or an interface), round the fans at island and headland tips, and across narrow
blocks (``benchmarks/smooth_causes.py``).  Here each block-interior node whose two edges along
a grid line differ by more than ``lo`` moves along that line (the direction from its neighbour
behind to its neighbour ahead) a share of the way to equal edges, Jacobi-style, every block on
its own: block borders (shore, interfaces, corners) stay, so blocks stay conforming.

A move is kept only if (checked on the whole block after each pass, rejected moves undone
with their neighbours' until none offends):

* no block-interior node loses its ``|cos| ≤ 0.02`` or its 3°, and one beyond 3° gets at most
  ``0.005`` worse in ``|cos|`` (the metric of :mod:`meshcore.quality.lake`);
* no cell corner turns more than ``turn`` degrees further from 90° (border nodes' angles are
  not in the report: this keeps the lines from kinking at the shore and at interfaces) and
  every corner Jacobian stays positive (no fold, no non-convex cell).
"""

from __future__ import annotations

import numpy as np

from ..quality.lake import corner_edges, node_cos

__all__ = ["smooth_block", "smooth_spacing"]

SIN3 = float(np.sin(np.radians(3.0)))


def _node_cos(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """|cos| at the block-interior nodes (the quality metric's)."""
    return node_cos(x, y)[1:-1, 1:-1]


def _corners(x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(4, ni, nj)`` corner Jacobians and |cos| of the corner angles (CCW 00, 10, 11, 01)."""
    jac, cos = [], []
    for ux, uy, vx, vy in corner_edges(x, y):
        n = np.hypot(ux, uy) * np.hypot(vx, vy)
        jac.append(ux * vy - uy * vx)
        cos.append(np.where(n > 0, np.abs(ux * vx + uy * vy) / np.where(n > 0, n, 1.0), 1.0))
    return np.stack(jac), np.stack(cos)


def _moves(
    x: np.ndarray, y: np.ndarray, lo: float, full: float, relax: float, spread: int = 0
) -> tuple[np.ndarray, np.ndarray]:
    """The wanted move of every node along each grid line through it (``(ni+1, nj+1)``; none
    for a line's ends): towards the place where its two edges grow by the same ratio as a
    geometric progression through the edges beyond them (``g = (h₊₂ / h₋₂)^(1/3)``, one side
    only at a line's end); ``relax`` of the way, scaled from 0 where the largest ratio of the
    node's and its two neighbours' pairs is ``lo`` to 1 at ``full``; the distances averaged
    ``spread`` times over neighbouring lines (rows move together).  A graded line (constant
    ratio) is a fixed point.  Inside the block a node moves along the chord of its two line
    neighbours; on a border line (``j = 0`` or ``nj``) along the border itself, at most a
    quarter of an edge a call (it stays on the border's polyline)."""
    dx = np.zeros(x.shape)
    dy = np.zeros(x.shape)
    for axis in (0, 1):
        xx, yy = (x, y) if axis == 0 else (x.T, y.T)
        h = np.hypot(np.diff(xx, axis=0), np.diff(yy, axis=0))  # (n-1, m) edges
        hb, hf = h[:-1], h[1:]  # the node's back and front edges, (n-2, m)
        n = len(hb)
        with np.errstate(divide="ignore", invalid="ignore"):
            r = np.maximum(hb, hf) / np.minimum(hb, hf)
            rr = r.copy()
            rr[1:] = np.maximum(rr[1:], r[:-1])
            rr[:-1] = np.maximum(rr[:-1], r[1:])
            lg = np.log(h)
            g = np.zeros_like(hb)  # log of the wanted growth per edge
            if n >= 3:
                g[1:-1] = (lg[3:] - lg[:-3]) / 3.0
            if n >= 2:
                g[0] = (lg[2] - lg[0]) / 2.0
                g[-1] = (lg[-1] - lg[-3]) / 2.0
            want = (hb + hf) / (1.0 + np.exp(g))
            w = relax * np.clip((rr - lo) / (full - lo), 0.0, 1.0)
            gap = np.where(np.abs(want - hb) > 1e-9 * (hb + hf), want - hb, 0.0)  # rounding: no move
            d = np.nan_to_num(w * gap, nan=0.0, posinf=0.0, neginf=0.0)  # signed distance forward
        for _ in range(spread):
            pad = np.concatenate([d[:, :1], d, d[:, -1:]], axis=1)
            d = 0.25 * pad[:, :-2] + 0.5 * pad[:, 1:-1] + 0.25 * pad[:, 2:]
        tx = xx[2:] - xx[:-2]
        ty = yy[2:] - yy[:-2]
        tn = np.hypot(tx, ty)
        with np.errstate(divide="ignore", invalid="ignore"):
            mx = np.nan_to_num(np.where(tn > 0, d * tx / tn, 0.0))
            my = np.nan_to_num(np.where(tn > 0, d * ty / tn, 0.0))
            for c in (0, -1):  # border lines: along the border's own edges
                fwd = d[:, c] > 0
                ex = np.where(fwd, xx[2:, c] - xx[1:-1, c], xx[:-2, c] - xx[1:-1, c])
                ey = np.where(fwd, yy[2:, c] - yy[1:-1, c], yy[:-2, c] - yy[1:-1, c])
                le = np.where(fwd, hf[:, c], hb[:, c])
                f = np.nan_to_num(np.minimum(np.abs(d[:, c]) / le, 0.25))
                mx[:, c], my[:, c] = f * ex, f * ey
        if axis == 1:
            mx, my = mx.T, my.T
            dx[:, 1:-1] += mx
            dy[:, 1:-1] += my
        else:
            dx[1:-1] += mx
            dy[1:-1] += my
    return dx, dy


def _spread_undo(shape: tuple[int, int], bad_node: np.ndarray, bad_cell: np.ndarray) -> np.ndarray:
    """Interior-node mask of the moves to undo: a node whose |cos| got worse and its four line
    neighbours (its central differences), every corner of a cell that folded or turned too far."""
    undo = np.zeros(shape, dtype=bool)
    undo[1:-1, 1:-1] |= bad_node
    undo[:-2, 1:-1] |= bad_node
    undo[2:, 1:-1] |= bad_node
    undo[1:-1, :-2] |= bad_node
    undo[1:-1, 2:] |= bad_node
    undo[:-1, :-1] |= bad_cell
    undo[1:, :-1] |= bad_cell
    undo[1:, 1:] |= bad_cell
    undo[:-1, 1:] |= bad_cell
    return undo


def smooth_block(
    x: np.ndarray,
    y: np.ndarray,
    *,
    frozen: np.ndarray | None = None,
    slide: np.ndarray | None = None,
    lo: float = 1.12,
    full: float = 1.25,
    relax: float = 0.5,
    passes: int = 40,
    turn: float = 10.0,
    keep02: bool = True,
    slack: float = 0.005,
    spread: int = 3,
) -> tuple[np.ndarray, np.ndarray, int]:
    """One block's node arrays with the spacing smoothed (module docstring); returns
    ``(x, y, moved)``, ``moved`` the number of node moves kept over all passes.

    ``frozen``: ``(ni+1, nj+1)`` nodes that stay; ``slide``: border nodes that may slide along
    the border (shore nodes; the block's corners never move).  ``keep02``: no node
    loses ``|cos| ≤ 0.02`` (False: only the 3° is kept).  ``slack``: how much worse a node beyond 3° may get."""
    x = np.array(x, dtype=float)
    y = np.array(y, dtype=float)
    if x.shape[0] < 3 or x.shape[1] < 3:
        return x, y, 0
    free = np.zeros(x.shape, dtype=bool)
    free[1:-1, 1:-1] = True
    if slide is not None:  # border nodes that may slide along the border (the shore)
        free |= np.asarray(slide, dtype=bool)
    free[0, 0] = free[0, -1] = free[-1, 0] = free[-1, -1] = False
    if frozen is not None:
        free &= ~np.asarray(frozen, dtype=bool)
    cos0 = _node_cos(x, y)
    jac0, ccos0 = _corners(x, y)
    sign = -1.0 if jac0.sum() < 0 else 1.0  # a mirrored block: judged in its own sense
    jac0 = sign * jac0
    limit = np.sin(np.radians(np.minimum(np.degrees(np.arcsin(np.clip(ccos0, 0.0, 1.0))) + turn, 90.0)))
    moved = 0
    for _ in range(passes):
        dx, dy = _moves(x, y, lo, full, relax, spread)
        ok = free & ((dx != 0) | (dy != 0))
        xn, yn = x, y
        while ok.any():
            xn, yn = x.copy(), y.copy()
            xn += np.where(ok, dx, 0.0)
            yn += np.where(ok, dy, 0.0)
            cos1 = _node_cos(xn, yn)
            bad_node = ((cos0 <= SIN3) & (cos1 > SIN3)) | ((cos0 > SIN3) & (cos1 > cos0 + slack))
            lost = (cos0 <= 0.02) & (cos1 > 0.02)
            if keep02:
                bad_node |= lost
            jac1, ccos1 = _corners(xn, yn)
            bad_cell = ((sign * jac1 <= 0) & (jac0 > 0)).any(axis=0) | (ccos1 > limit).any(axis=0)
            if not bad_node.any() and not bad_cell.any():
                break
            ok &= ~_spread_undo(x.shape, bad_node, bad_cell)
        if not ok.any():
            break
        x, y = xn, yn
        moved += int(ok.sum())
    return x, y, moved


def _frozen_masks(grids, h: float) -> list[tuple[np.ndarray, np.ndarray]]:
    """Per block, the nodes on and next to an interface (border nodes another block shares,
    found by coordinates): frozen, so every cell that touches an interface keeps its area (the
    cross-interface ratios stay what the solve and the equalize step left); and the border
    nodes no other block shares (the shore), which may slide along it."""
    keys: dict[tuple[int, int], set[int]] = {}
    q = 1e-6 * h
    borders = []
    for k, g in enumerate(grids):
        x, y = np.asarray(g.x), np.asarray(g.y)
        m = np.zeros(x.shape, dtype=bool)
        m[0], m[-1], m[:, 0], m[:, -1] = True, True, True, True
        ii, jj = np.nonzero(m)
        kk = list(
            zip(
                np.round(x[ii, jj] / q).astype(np.int64).tolist(),
                np.round(y[ii, jj] / q).astype(np.int64).tolist(),
                strict=True,
            )
        )
        borders.append((ii, jj, kk))
        for key in kk:
            keys.setdefault(key, set()).add(k)
    out = []
    for k, g in enumerate(grids):
        ii, jj, kk = borders[k]
        shared = np.zeros(np.asarray(g.x).shape, dtype=bool)
        for i, j, key in zip(ii.tolist(), jj.tolist(), kk, strict=True):
            if len(keys[key]) > 1:
                shared[i, j] = True
        near = shared.copy()
        near[1:] |= shared[:-1]
        near[:-1] |= shared[1:]
        near2 = near.copy()
        near2[:, 1:] |= near[:, :-1]
        near2[:, :-1] |= near[:, 1:]
        border = np.zeros(shared.shape, dtype=bool)
        border[0], border[-1], border[:, 0], border[:, -1] = True, True, True, True
        out.append((near2, border & ~shared))
    return out


def smooth_spacing(grids, *, shore_slide: bool = False, **options) -> tuple[list, int]:
    """Every block of ``grids`` through :func:`smooth_block`, the nodes on and next to
    interfaces frozen; returns the grids and the moves kept.  ``shore_slide``: shore nodes
    slide along the grid's shore too (off: on fresh_sweep 797000 ``--more`` it changed the pairs
    by at most 0.1 point and moved the shore off the outline, ``headlands`` 797600 0.23 → 0.29
    cells: a node sliding past its neighbour's old place cuts that vertex off)."""
    grids = list(grids)
    if not grids:
        return grids, 0
    h = float(
        np.median([np.hypot(np.diff(np.asarray(g.x), axis=0), np.diff(np.asarray(g.y), axis=0)).mean() for g in grids])
    )
    frozen = _frozen_masks(grids, h)
    out, total = [], 0
    for g, (fz, sl) in zip(grids, frozen, strict=True):
        if getattr(g, "periodic", False):
            out.append(g)
            continue
        x, y, n = smooth_block(
            np.asarray(g.x), np.asarray(g.y), frozen=fz, slide=sl if shore_slide else None, **options
        )
        total += n
        out.append(g.replaced(x=x, y=y) if n else g)
    return out, total
