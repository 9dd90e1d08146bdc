"""Cells of two blocks that share an edge: found from the coordinates, with their area ratio.

An edge of one block's border and an edge of another block's border are
shared when both end nodes coincide within ``rtol`` times the domain size (in
the same or the opposite direction).  Matching by coordinates, not by the
topology, lets one function serve a :class:`~meshcore.multiblock.MultiBlockGrid`
(whose ``quality()`` uses it too), blocks read back from a file, and partial
(T-junction) interfaces.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..grid import StructuredGrid

__all__ = ["interface_pairs", "no_pairs", "ratio", "signed_area"]


def ratio(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``max(a/b, b/a)`` of magnitudes, ``inf`` when one is 0 (a collapsed edge or cell)."""
    a, b = np.abs(a), np.abs(b)
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    with np.errstate(divide="ignore", invalid="ignore"):
        r = hi / lo
    return np.where(lo > 0, r, np.inf)


def signed_area(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """``(ni, nj)`` signed cell areas (positive for counter-clockwise cells)."""
    return 0.5 * (
        (x[1:, 1:] - x[:-1, :-1]) * (y[:-1, 1:] - y[1:, :-1]) - (x[:-1, 1:] - x[1:, :-1]) * (y[1:, 1:] - y[:-1, :-1])
    )


def _border_edges(grids: Sequence[StructuredGrid]) -> dict[str, np.ndarray]:
    """Every border edge of every block: end points, adjacent cell ``(block, i, j)``."""
    p, q, cell = [], [], []
    for k, g in enumerate(grids):
        x, y = np.asarray(g.x), np.asarray(g.y)
        ni, nj = g.cells
        i, j = np.arange(ni), np.arange(nj)
        sides = (
            (x[:-1, 0], y[:-1, 0], x[1:, 0], y[1:, 0], i, np.zeros(ni, int)),  # bottom
            (x[:-1, -1], y[:-1, -1], x[1:, -1], y[1:, -1], i, np.full(ni, nj - 1)),  # top
            (x[0, :-1], y[0, :-1], x[0, 1:], y[0, 1:], np.zeros(nj, int), j),  # left
            (x[-1, :-1], y[-1, :-1], x[-1, 1:], y[-1, 1:], np.full(nj, ni - 1), j),  # right
        )
        for x0, y0, x1, y1, ci, cj in sides:
            p.append(np.column_stack([x0, y0]))
            q.append(np.column_stack([x1, y1]))
            cell.append(np.column_stack([np.full(len(ci), k), ci, cj]))
    return {"p": np.vstack(p), "q": np.vstack(q), "cell": np.vstack(cell).astype(np.int64)}


def interface_pairs(grids: Sequence[StructuredGrid], *, rtol: float = 1e-7) -> dict[str, np.ndarray]:
    """Cells of two different blocks that share an edge, and their area ratio.

    Returns arrays ``cell_a``/``cell_b`` (``(n, 3)``: block, i, j), ``ratio``
    (``max(A₁/A₂, A₂/A₁)``) and ``mid`` (``(n, 2)``, the shared edge's midpoint),
    ordered by block, then cell.  An edge shared by two blocks is one whose end
    nodes coincide within ``rtol`` times the domain size (either direction).
    """
    from scipy.spatial import cKDTree

    e = _border_edges(grids)
    allx = np.concatenate([np.ravel(g.x) for g in grids])
    ally = np.concatenate([np.ravel(g.y) for g in grids])
    tol = rtol * max(float(np.hypot(np.ptp(allx), np.ptp(ally))), np.finfo(float).tiny)
    mid = 0.5 * (e["p"] + e["q"])
    pairs = cKDTree(mid).query_pairs(tol, p=np.inf, output_type="ndarray")
    if len(pairs):
        a, b = pairs[:, 0], pairs[:, 1]
        gap_same = np.maximum(np.abs(e["p"][a] - e["p"][b]).max(1), np.abs(e["q"][a] - e["q"][b]).max(1))
        gap_flip = np.maximum(np.abs(e["p"][a] - e["q"][b]).max(1), np.abs(e["q"][a] - e["p"][b]).max(1))
        keep = (np.minimum(gap_same, gap_flip) <= tol) & (e["cell"][a, 0] != e["cell"][b, 0])
        a, b = a[keep], b[keep]
        swap = e["cell"][a, 0] > e["cell"][b, 0]
        a, b = np.where(swap, b, a), np.where(swap, a, b)
        order = np.lexsort((e["cell"][a, 2], e["cell"][a, 1], e["cell"][b, 0], e["cell"][a, 0]))
        a, b = a[order], b[order]
    else:
        a = b = np.zeros(0, np.int64)
    if not len(a):
        return no_pairs()
    areas = np.concatenate([np.abs(signed_area(np.asarray(g.x), np.asarray(g.y))).ravel() for g in grids])
    start = np.cumsum([0] + [g.cells[0] * g.cells[1] for g in grids])
    nj = np.array([g.cells[1] for g in grids])
    ca, cb = e["cell"][a], e["cell"][b]
    aa = areas[start[ca[:, 0]] + ca[:, 1] * nj[ca[:, 0]] + ca[:, 2]]
    ab = areas[start[cb[:, 0]] + cb[:, 1] * nj[cb[:, 0]] + cb[:, 2]]
    return {"cell_a": ca, "cell_b": cb, "ratio": ratio(aa, ab), "mid": mid[a]}


def no_pairs() -> dict[str, np.ndarray]:
    """The result of :func:`interface_pairs` when no edge is shared."""
    z = np.zeros((0, 3), np.int64)
    return {"cell_a": z, "cell_b": z, "ratio": np.zeros(0), "mid": np.zeros((0, 2))}
