"""Which cells are invalid, which block corners cannot be convex, and patches of free nodes."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..grid import StructuredGrid
from . import _kernels

__all__ = ["BoundaryCorner", "block_corner_problems", "invalid_cells"]


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


def _folded(x, y) -> int:
    a = (x[1:, 1:] - x[:-1, :-1]) * (y[:-1, 1:] - y[1:, :-1]) - (x[:-1, 1:] - x[1:, :-1]) * (y[1:, 1:] - y[:-1, :-1])
    return int((a <= 0).sum())


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
    # more rows across a border first: real lakes as one block (24 000 nodes) whose bad cells lay in one
    # border's row were repaired with twice the cells across (Shasta 399 → 0, Como 363 → 5 bad
    # cells), not with twice the cells along (399 → 733, 363 → 508)
    along, across = ("ξ", "η") if border in ("bottom", "top") else ("η", "ξ")
    msg = (
        f"no fold-free grid found for these boundary nodes: {len(idx)} cell(s) stay folded or "
        f"non-convex: {', '.join(parts)}{more}. Fix: more grid lines along the {border} border "
        f"(raise cells in {across}: the side arms and bays it traces need rows that enter them), "
        f"or put more nodes on it (raise cells in {along}) or a finer distribution there, choose "
        f"other corners, or split the region into blocks"
    )
    places = _places(x, y, bad)
    if len(places) > 1:
        msg += f". The bad cells lie in {len(places)} places: " + "; ".join(places[:8])
        if len(places) > 8:
            msg += f"; and {len(places) - 8} more"
    if exempt:
        msg += "; also: " + "; ".join(c.message for c in exempt)
    return msg


def _places(x: np.ndarray, y: np.ndarray, bad: np.ndarray) -> list[str]:
    """The connected groups of bad cells, largest first: how many, their index ranges, the border
    nearest to them (index space) and where their middle cell is."""
    from scipy import ndimage

    ni, nj = bad.shape
    lab, n = ndimage.label(bad, structure=np.ones((3, 3), dtype=bool))
    out = []
    for k in sorted(range(1, n + 1), key=lambda k: -int((lab == k).sum())):
        idx = np.argwhere(lab == k)
        ci, cj = idx[len(idx) // 2]
        cx = 0.25 * (x[ci, cj] + x[ci + 1, cj] + x[ci + 1, cj + 1] + x[ci, cj + 1])
        cy = 0.25 * (y[ci, cj] + y[ci + 1, cj] + y[ci + 1, cj + 1] + y[ci, cj + 1])
        i0, j0 = idx.min(axis=0)
        i1, j1 = idx.max(axis=0)
        d = {"bottom": j0, "top": nj - 1 - j1, "left": i0, "right": ni - 1 - i1}
        border = min(d, key=lambda k: d[k])
        rng = f"i {i0}–{i1}" if i0 != i1 else f"i {i0}"
        rng += f", j {j0}–{j1}" if j0 != j1 else f", j {j0}"
        out.append(f"{len(idx)} cell(s) at {rng} by the {border} border, around ({cx:.6g}, {cy:.6g})")
    return out
