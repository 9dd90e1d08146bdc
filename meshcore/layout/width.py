"""How wide a piece of a split is (:mod:`.split`): a piece narrower than three cells is not made.

:func:`width` is twice the area over the perimeter (exact for long strips, half the side for a
square); :func:`too_narrow` with ``thin`` also admits pieces two cells across
(:data:`THIN_ACROSS`), for the arms 2–4 cells wide of dendritic lakes.
"""

from __future__ import annotations

import numpy as np

__all__ = ["THIN_ACROSS", "THIN_CUT", "THIN_WIDTH", "inscribed", "too_narrow", "width"]


def width(ring: np.ndarray, poly=None) -> float:
    """A width scale of a region: twice its area over its perimeter (exact for long strips);
    ``poly``: ``shapely.polygons(ring)``, if made already."""
    import shapely

    p = shapely.polygons(ring) if poly is None else poly  # (the Polygon class's checks cost more than GEOS's area)
    return 2.0 * float(shapely.area(p)) / max(float(shapely.length(p)), 1e-300)


#: With ``thin`` (:func:`~.split.best_split`), a motorcycle cut may leave pieces narrower than
#: ``min_width`` by :func:`width` (twice area over perimeter, which is below the width for any
#: piece of finite length: a square of side ``w`` has ``w / 2``) as long as a disc of
#: ``THIN_ACROSS × min_width`` fits in them and their :func:`width` is at least
#: ``THIN_WIDTH × min_width`` (with ``min_width`` = 3 cells: two cells across, one by 2A/P).
#: Without it no cut is admissible in an arm 2–4 cells wide, so a junction of such arms, or a
#: thin arm that bends at a reflex corner, stays one block whose side runs round the corner
#: (cells fan out from it: "feathers" on generated dendritic reservoirs).
THIN_ACROSS = 2.0 / 3.0
THIN_WIDTH = 1.0 / 3.0

#: ... and only where the cut that makes them is at most this × ``min_width`` long (6 cells):
#: across an arm 2–4 cells wide, not the long cuts of a wide basin, which left a strip two
#: cells wide along a shore or beside an island (generated lakes with thin peninsulas and
#: islands: 41 folded cells where main has none, dendritic reservoirs 12; none with this).
#: Nor in a region that an island bounds (:func:`~.build.layout_pieces`): such regions are
#: wide water, where a thin piece's count (4 cells) went along a chain of blocks into a wide
#: bay beside the island (`headlands(746605)` 89.9 → 85.0 % of nodes within 3°,
#: `peninsulas(752802)` 61.4 → 59.3); with this rule, on three `--more` sets, every row but
#: the dendritic reservoirs' within 0.7 points of the grid without the option.
THIN_CUT = 2.0


def inscribed(ring: np.ndarray, tol: float) -> float:
    """The diameter of the largest disc inside ``ring`` (to ``tol``; 0 for an invalid ring):
    :func:`~meshcore.quality.coverage.island_width` of the piece."""
    from shapely.geometry import Polygon

    from ..quality.coverage import island_width

    p = Polygon(ring)
    return island_width(p, tol)[0] if p.is_valid else 0.0


def too_narrow(ring: np.ndarray, min_width: float, thin: bool = False, poly=None) -> bool:
    """True if a piece ``ring`` is narrower than ``min_width`` (see :data:`THIN_ACROSS` for ``thin``;
    ``poly``: ``shapely.polygons(ring)``, if made already)."""
    w = width(ring, poly)
    if w >= min_width:
        return False
    if not thin or w < THIN_WIDTH * min_width:
        return True
    return inscribed(ring, 0.02 * min_width) < THIN_ACROSS * min_width
