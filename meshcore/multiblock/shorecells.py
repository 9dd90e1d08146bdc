r"""How many cells a stretch of shore needs so that the coarse grid levels still follow it.

The grid is solved coarse first (:mod:`meshcore.orthogonal.levels`): on the coarsest level a
chain of ``n`` cells has ``n / multiple`` cells, whose straight edges join every
``multiple``-th node of the chain.  Where the chain is short in cells but long on the shore —
round a small island, into a bay — those edges are chords across the land: the coarse grid
crosses the island, and refinement does not bring it back (the fine nodes on the far side of
the island are out of the water, and the fold-free guard keeps them there).  Before, the
cell counts left a 13-cell arc round an island (``round_lake(9, kind="disc")``) with 4 cells,
one coarse edge: the finished grid had nodes 3.7 cells inside the island.

:func:`least_cells` is the count the program (:func:`~.counts.solve_counts`, its ``least``)
is pushed towards: the fewest cells, a multiple of ``multiple``, whose coarsest-level chords
stay within :data:`SAG` cells of the chain; :func:`least_weights` how much a shortfall costs
(more where the coarse chords would cross an island, :func:`over_island`).
"""

from __future__ import annotations

import functools
import math

import numpy as np

from ..segments import feet

__all__ = ["SAG", "islands_of", "least_cells", "least_weights", "over_island", "sag"]

#: Largest distance, in (fine) cells, between a shore chain and the straight edges of its
#: coarsest-level sampling.  One cell: the coarse level's own shore sweep lets a stretch of
#: shore stray a quarter of a coarse edge (``shore_gap``: one fine cell at ``multiple`` 4) from
#: the edges between two shore nodes, so a sampling within one cell is one the coarse level
#: keeps; less asks for denser cells round every curved shore (checked on generated lakes with
#: islands in a sweep not committed: 0.5 gave the same shore fit with more cells).
SAG = 1.0
#: At most this many times the chain's cells at the cell size: a corner of the shore inside a
#: chain (no sampling follows it exactly) must not ask for ever more cells.
MOST = 2.0


def sag(chain: np.ndarray, cells: int) -> float:
    """The largest distance from the vertices of polyline ``chain`` to the straight edges
    joining its ``cells + 1`` points uniform in arc length (the chain's re-sampling)."""
    p = np.asarray(chain, dtype=float)
    s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(p, axis=0).T))])
    if s[-1] <= 0.0 or cells < 1:
        return 0.0
    u = np.linspace(0.0, s[-1], cells + 1)
    nodes = np.column_stack([np.interp(u, s, p[:, 0]), np.interp(u, s, p[:, 1])])
    j = np.clip(np.searchsorted(u, s, side="right") - 1, 0, cells - 1)
    return float(feet(nodes[j], nodes[j + 1], p)[0].max())


def least_cells(chain: np.ndarray, cell_size: float, multiple: int, *, tol: float = SAG, most: float = MOST) -> int:
    """The fewest cells (a multiple of ``multiple``) for which the chain's sampling at every
    ``multiple``-th node stays within ``tol`` cells of it; at most ``most`` times its length in
    cells (rounded up to a multiple), at least ``multiple``.

    Remembered for the last :data:`_REMEMBERED` chains: a layout edited by hand (a cut end
    dragged) asks again for every shore chain the edit left as it was."""
    p = np.ascontiguousarray(chain, dtype=float)
    return _least_cells(p.tobytes(), p.shape, float(cell_size), int(multiple), float(tol), float(most))


#: chains whose :func:`least_cells` is remembered (a few layouts: a 16-block lake has ~40 shore chains)
_REMEMBERED = 2048


@functools.lru_cache(maxsize=_REMEMBERED)
def _least_cells(data: bytes, shape: tuple, cell_size: float, multiple: int, tol: float, most: float) -> int:
    p = np.frombuffer(data, dtype=float).reshape(shape)
    length = float(np.hypot(*np.diff(p, axis=0).T).sum())
    m = max(int(multiple), 1)
    top = max(1, math.ceil(most * length / cell_size / m))
    limit = tol * cell_size
    for k in range(1, top + 1):
        if sag(p, k) <= limit:
            return k * m
    return top * m


def shore_least(chains, on_shore, cell_size: float, multiple: int) -> np.ndarray:
    """:func:`least_cells` of every chain on the shore (``on_shore``), 0 for the others: the
    ``least`` of :func:`~.counts.solve_counts`."""
    return np.array(
        [least_cells(c, cell_size, multiple) if s else 0 for c, s in zip(chains, on_shore, strict=True)], dtype=float
    )


def islands_of(regions) -> list:
    """The islands of the water made of the block regions ``regions`` (counter-clockwise rings):
    the holes of their union, as shapely Polygons."""
    import shapely

    water = shapely.union_all([shapely.Polygon(r) for r in regions])
    return [shapely.Polygon(h) for part in getattr(water, "geoms", [water]) for h in part.interiors]


def over_island(chain: np.ndarray, islands) -> bool:
    """Whether the area between shore chain ``chain`` and the straight line between its ends
    lies mostly on ``islands`` (a shapely geometry): the block beside the chain wraps a convex
    stretch of an island's shore, and a coarse edge would cross the island or run along its far
    side.  (Between a chain that bulges away from its block and its chord lies water, a bay;
    a headland of the outer shore is left to :data:`~.counts.LEAST_WEIGHT`: with the island
    weight there too, a headland lake lost 4.5 points of nodes within 3°.)"""
    import shapely

    p = np.asarray(chain, dtype=float)
    if len(p) < 3 or islands is None or islands.is_empty:
        return False
    lo, hi = p.min(axis=0), p.max(axis=0)
    if not shapely.intersects(islands, shapely.box(lo[0], lo[1], hi[0], hi[1])):
        return False  # no island near (the test below, a polygon made valid, costs a layout 2–4 %)
    between = shapely.make_valid(shapely.Polygon(p))
    area = between.area
    return area > 0.0 and shapely.intersection(between, islands).area > 0.5 * area


def least_weights(chains, on_shore, regions) -> np.ndarray:
    """Per chain, the cost per cell by which it falls short of its :func:`least_cells`:
    :data:`~.counts.LAND_WEIGHT` where the chain is on the shore (``on_shore``) and
    :func:`over_island` (the islands of the block regions ``regions``, :func:`islands_of`),
    :data:`~.counts.LEAST_WEIGHT` elsewhere."""
    import shapely

    from .counts import LAND_WEIGHT, LEAST_WEIGHT

    islands = shapely.union_all(islands_of(regions)) if any(on_shore) else None
    if islands is not None:
        shapely.prepare(islands)  # (tested against every shore chain)
    return np.array(
        [LAND_WEIGHT if s and over_island(c, islands) else LEAST_WEIGHT for c, s in zip(chains, on_shore, strict=True)],
        dtype=float,
    )
