r"""Does the grid cover the water?  Area of the union of cells and shoreline distance.

* ``area_ratio`` — area of the union of all cells over the polygon's area
  (islands excluded from both); ``area_error = |area_ratio − 1|``.
* ``hausdorff`` — Hausdorff distance between the grid's outer boundary (every
  ring of the union of cells: the shore and the islands) and the polygon's
  boundary (the shore and every island the grid goes round), and
  ``hausdorff_cells`` the same in units of the cell size (``sqrt(grid area /
  cells)`` unless given);
* ``islands_covered`` — the polygon's islands that the grid covers (at least
  half of the island's area lies under its cells).  Each is named (its number
  among the polygon's islands, from 1), with its area, its width (the diameter
  of the largest disc inside it) and a point inside it; the table lists them on
  a row of their own.  One narrower than two cells is **left out**: the layout
  leaves such islands out by design (:data:`MIN_ISLAND_CELLS`),
  and its rim is not part of the Hausdorff distance above (an island a cell
  across under the grid would read as a shore tens of cells off wherever it
  lies, hiding the distance of the shores the grid follows).  A wider one is
  **lost** (:attr:`Coverage.islands_lost`): the grid should go round it; its rim
  stays in the Hausdorff distance.  The area of either is counted: the grid
  area includes the water over it, so the area ratio rises by its share;
* ``hausdorff_as_given`` — the same with the shore's spikes of water or land
  narrower than half a cell, and its dead-end arms narrower than two cells,
  included.  The layout smooths the former out and leaves the latter out on
  purpose (:func:`meshcore.layout.polygon.without_slivers`,
  :func:`meshcore.layout.shore.without_narrow_arms`, each with a note: no grid
  line can follow a spike without folding a cell, an arm gets cells hundreds of
  times longer than wide), so ``hausdorff`` leaves the shore points on them out
  (the arms by the layout's rule: pass its cell size, found as the layout finds them: on the
  shore without its spikes); a grid point counts as near as the nearer of the shore as given
  and the shore these rules make, and the lines the rules draw (an arm's mouth) count only where
  the grid stops short of them; the table shows both where they differ.  Islands the layout joins, closer than
  :data:`~meshcore.layout.islandgaps.GAP_CELLS` cells to each other or
  :data:`~meshcore.layout.islandgaps.SHORE_GAP_CELLS` to the shore
  (:func:`meshcore.layout.islandgaps.without_island_gaps`, with a note naming the
  water given up), are measured the same way: by the rim of the joined land;
* ``island_cells`` — cells whose centre lies on land: inside an island the
  grid goes round (a narrow end of it that a block side cut across, say), or
  beyond the outer shore (across a narrow peninsula) — per island (its number;
  0 for the outer shore): how many cells, the deepest such centre (its distance
  from that shore, in cells) and where it is.  A grid that follows every shore
  within half a cell has none deeper than half a cell.

The union of a block's cells is its boundary loop when no cell is folded and
the loop is simple (a locally one-to-one map of a square whose boundary is a
simple curve is one-to-one); otherwise the cells themselves are united
(folded ones made valid first).  The distance is measured between both
boundaries sampled at ``cell_size / 10`` and the other boundary's segments
(an STR-tree nearest-segment query), so it is exact at vertices and within
``cell_size / 20`` elsewhere.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import InvalidInputError
from ..grid import StructuredGrid
from .samples import Samples

__all__ = ["MIN_ISLAND_CELLS", "Coverage", "CoveredIsland", "as_polygon", "coverage", "island_width", "without_spikes"]

#: The layout keeps an island at least this many cells across where it is widest
#: (:func:`island_width`; :func:`meshcore.layout.polygon.water_polygon` is given it times the
#: cell size, and its docstring has the measurement behind it); a narrower one under the grid is
#: left out by design, a wider one lost.
MIN_ISLAND_CELLS = 2.0

#: An island is covered when at least this share of its area lies under the grid's cells: a grid
#: that goes round an island leaves only the slivers between its boundary chords and a curved
#: rim under cells (a few percent on islands one or two cells across), one laid over it nearly all.
COVERED = 0.5


@dataclass(frozen=True, slots=True)
class CoveredIsland:
    """An island of the water polygon that the grid covers: its number among the polygon's
    islands (from 1), area, width (diameter of the largest disc inside it), a point inside it,
    and the share of its area under the grid's cells."""

    index: int
    area: float
    width: float
    x: float
    y: float
    share: float

    def describe(self, cell_size: float) -> str:
        return (
            f"island {self.index} ({self.width / cell_size:.2g} cells across, {self.area / cell_size**2:.2g} cells² "
            f"near ({self.x:.6g}, {self.y:.6g}){'' if self.left_out(cell_size) else ', lost'})"
        )

    def left_out(self, cell_size: float) -> bool:
        """Narrower than the layout keeps (:data:`MIN_ISLAND_CELLS`)."""
        return self.width < MIN_ISLAND_CELLS * cell_size


def island_width(island: Any, tolerance: float) -> tuple[float, Any]:
    """The diameter of the largest disc inside the polygon ``island`` (to ``tolerance``) and its
    centre: how wide the island is where it is widest, whatever its shape (a needle's width, not
    its length; a blob's diameter)."""
    from shapely.ops import polylabel

    c = polylabel(island, tolerance=max(tolerance, 1e-12 * max(island.length, 1e-300)))
    return 2.0 * float(island.exterior.distance(c)), c


@dataclass(frozen=True, slots=True)
class Coverage:
    """Coverage of the water polygon by the grid (see module docstring)."""

    grid_area: float
    polygon_area: float
    area_ratio: float
    hausdorff: float
    cell_size: float
    where: tuple[float, float]  # the point where the Hausdorff distance is reached
    side: str  # "grid" (a grid boundary point far from the shore) or "shore"
    islands_covered: tuple[CoveredIsland, ...] = ()
    island_cells: tuple[tuple[int, int, float, float, float], ...] = ()  # (island, cells, depth, x, y)
    #: the Hausdorff distance to the shore as given, its spikes narrower than half a cell and arms
    #: narrower than two cells included (``hausdorff`` leaves them out: the layout smooths and
    #: leaves them out on purpose, with a note)
    hausdorff_as_given: float = math.nan

    @property
    def hausdorff_cells(self) -> float:
        return self.hausdorff / self.cell_size if self.cell_size > 0 else math.inf

    @property
    def islands_lost(self) -> tuple[CoveredIsland, ...]:
        """The islands under the grid that are wide enough for the layout to go round them."""
        return tuple(i for i in self.islands_covered if not i.left_out(self.cell_size))

    def warnings(self) -> list[str]:
        """One sentence per island the grid covers although it should go round it, and per island
        with cells more than half a cell inside its shore: what a user must not miss.  (Cells
        beyond the outer shore are in the table only: the layout smooths a shore jagged below the
        cell size on purpose, with a note saying how far its shore moved.)"""
        out = [
            f"{i.describe(self.cell_size)} is under the grid although the layout goes round it: the grid "
            f"lost it (make its blocks by hand in a [outline] case, or try another cell size)"
            for i in self.islands_lost
        ]
        out += [
            f"{n} cell(s) lie {_land(k)}, up to {d:.2g} cells inside its shore near ({x:.6g}, {y:.6g}): "
            f"the grid cuts across it there"
            for k, n, d, x, y in self.island_cells
            if d > 0.5 and k  # the outer shore's: a jagged shore smoothed on purpose (and noted)
        ]
        return out

    @property
    def area_error(self) -> float:
        return abs(self.area_ratio - 1.0)

    def as_dict(self) -> dict[str, float]:
        return {
            "grid_area": self.grid_area,
            "polygon_area": self.polygon_area,
            "area_ratio": self.area_ratio,
            "hausdorff": self.hausdorff,
            "hausdorff_cells": self.hausdorff_cells,
            "hausdorff_as_given_cells": self.hausdorff_as_given / self.cell_size if self.cell_size > 0 else math.inf,
            "cell_size": self.cell_size,
            "islands_covered": len(self.islands_covered),
            "islands_lost": len(self.islands_lost),
            "cells_over_islands": sum(t[1] for t in self.island_cells),
            "deepest_cell_on_island": max((t[2] for t in self.island_cells), default=0.0),
        }

    def rows(self) -> list[tuple[str, str, str]]:
        x, y = self.where
        what = "grid boundary point" if self.side == "grid" else "shore point"
        return (
            [
                ("grid area / polygon area", f"{self.area_ratio:.5f}", ""),
                (
                    "shoreline distance (Hausdorff)",
                    f"{self.hausdorff_cells:.3g} cells ({self.hausdorff:.4g}; cell size {self.cell_size:.4g})",
                    f"{what} ({x:.6g}, {y:.6g})",
                ),
            ]
            + self._spike_rows()
            + self._island_rows()
        )

    def _spike_rows(self) -> list[tuple[str, str, str]]:
        if not self.hausdorff_as_given > self.hausdorff:
            return []
        return [
            (
                "shoreline distance, spikes included (and narrow arms)",
                f"{self.hausdorff_as_given / self.cell_size:.3g} cells",
                "spikes of the shore narrower than half a cell and arms narrower than two cells, "
                "smoothed out and left out by the layout on purpose",
            )
        ]

    def _island_rows(self) -> list[tuple[str, str, str]]:
        rows = []
        if self.islands_covered:
            isl = self.islands_covered
            area = sum(i.area for i in isl)
            names = "; ".join(i.describe(self.cell_size) for i in isl[:5]) + ("; …" if len(isl) > 5 else "")
            rows.append(
                (
                    "islands under the grid",
                    f"{len(isl)} ({100 * area / self.polygon_area:.2g} % of the water area"
                    f"{f'; {len(self.islands_lost)} lost' if self.islands_lost else ''})",
                    names,
                )
            )
        if self.island_cells:
            n = sum(t[1] for t in self.island_cells)
            deep = max(t[2] for t in self.island_cells)
            where = "; ".join(
                f"{_land(k).removeprefix('on ')}: {c}, up to {d:.2g} cells inside near ({x:.6g}, {y:.6g})"
                for k, c, d, x, y in self.island_cells[:5]
            )
            rows.append(("cells with their centre on land", f"{n} (up to {deep:.2g} cells in)", where))
        return rows

    def samples(self, metric: str) -> Any:
        v = self.area_error if metric == "area_error" else self.hausdorff_cells
        x, y = (math.nan, math.nan) if metric == "area_error" else self.where
        one = lambda a, dt=float: np.array([a], dtype=dt)  # noqa: E731
        return Samples(metric, one(v), one(-1, np.int64), one(-1, np.int64), one(-1, np.int64), one(x), one(y))


def as_polygon(polygon: Any, holes: Sequence[Any] = ()) -> Any:
    """A shapely (Multi)Polygon from a shapely geometry or an ``(n, 2)`` outer ring plus holes."""
    import shapely
    from shapely.geometry import Polygon

    if isinstance(polygon, shapely.Geometry):
        if holes:
            raise InvalidInputError("holes: give them as interior rings of the shapely polygon")
        poly = polygon
    else:
        ring = np.asarray(polygon, dtype=float)
        if ring.ndim != 2 or ring.shape[1] != 2 or len(ring) < 3:
            raise InvalidInputError(f"polygon must be an (n, 2) array of at least 3 points, got shape {ring.shape}")
        poly = Polygon(ring, [np.asarray(h, dtype=float) for h in holes])
    if poly.geom_type not in ("Polygon", "MultiPolygon") or poly.is_empty:
        raise InvalidInputError(f"polygon must be a non-empty Polygon or MultiPolygon, got {poly.geom_type}")
    if not poly.is_valid:
        raise InvalidInputError(f"polygon is not valid: {shapely.is_valid_reason(poly)}")
    return poly


def _block_region(g: StructuredGrid, folded: np.ndarray) -> Any:
    import shapely
    from shapely.geometry import Polygon

    x, y = np.asarray(g.x), np.asarray(g.y)
    if not folded.any():
        loop = np.vstack(
            [g.border("bottom"), g.border("right")[1:], g.border("top")[::-1][1:], g.border("left")[::-1][1:]]
        )
        poly = Polygon(loop)
        if poly.is_valid:
            return poly
    c = np.stack([x[:-1, :-1], x[1:, :-1], x[1:, 1:], x[:-1, 1:]], axis=-1).reshape(-1, 4)
    d = np.stack([y[:-1, :-1], y[1:, :-1], y[1:, 1:], y[:-1, 1:]], axis=-1).reshape(-1, 4)
    cells = shapely.polygons(np.stack([c, d], axis=-1))
    bad = ~shapely.is_valid(cells)
    cells[bad] = shapely.make_valid(cells[bad])
    return _areal(shapely.union_all(cells))


def _areal(geom: Any) -> Any:
    """The polygons of ``geom``: a folded cell made valid can leave lines and points beside
    them (a GeometryCollection), whose boundary is empty: the shore distance had no points."""
    import shapely

    if geom.geom_type in ("Polygon", "MultiPolygon"):
        return geom
    return shapely.union_all([p for p in shapely.get_parts(geom) if p.geom_type in ("Polygon", "MultiPolygon")])


def _directed(points: np.ndarray, lines: Any) -> tuple[float, int]:
    """Largest distance from ``points`` to the segments of ``lines``, and its index."""
    dist = _distances(points, lines)
    k = int(np.argmax(dist))
    return float(dist[k]), k


def _distances(points: np.ndarray, lines: Any) -> np.ndarray:
    """Distance from each of ``points`` to the nearest segment of ``lines``."""
    import shapely

    segs = []
    for ring in shapely.get_parts(lines):
        c = shapely.get_coordinates(ring)
        segs.append(np.stack([c[:-1], c[1:]], axis=1))
    seg = np.concatenate(segs)
    seg = seg[np.any(seg[:, 0] != seg[:, 1], axis=1)]
    tree = shapely.STRtree(shapely.linestrings(seg))
    idx, dist = tree.query_nearest(shapely.points(points), return_distance=True, all_matches=False)
    out = np.empty(len(points))
    out[idx[0]] = dist
    return out


#: The most points :func:`_boundary_points` puts on a boundary (a grid flung far beyond its lake
#: by a solver fault asked for more points than memory holds: 23 GB before the OOM killer).
MAX_POINTS = 2_000_000


def _boundary_points(boundary: Any, step: float) -> np.ndarray:
    """Points every ``step`` along ``boundary`` (at most about :data:`MAX_POINTS`)."""
    import shapely

    step = max(step, float(shapely.length(boundary)) / MAX_POINTS)
    return shapely.get_coordinates(shapely.segmentize(boundary, step))


def coverage(
    grids: Sequence[StructuredGrid],
    block_metrics: Sequence[Any],
    polygon: Any,
    *,
    holes: Sequence[Any] = (),
    cell_size: float | None = None,
    arms: Sequence[Any] | None = None,
) -> Coverage:
    """Coverage of ``polygon`` (shapely, or an outer ring plus ``holes``) by the grid.

    ``arms``: the dead-end arms the layout left out (:class:`meshcore.layout.Layout` ``arms``); by
    default they are found again by the layout's rule on this shore, which a shore the layout
    prepared otherwise (islands joined, spikes smoothed) can find other ones on."""
    import shapely

    from ..layout.shore import DENSE_TOLERANCE, without_dense_vertices

    poly = as_polygon(polygon, holes)
    union = _areal(shapely.union_all([_block_region(g, b.folded) for g, b in zip(grids, block_metrics, strict=True)]))
    n_cells = sum(g.cells[0] * g.cells[1] for g in grids)
    h = float(cell_size) if cell_size is not None else math.sqrt(union.area / max(n_cells, 1))
    if not h > 0:
        raise InvalidInputError(f"cell_size must be positive, got {h}")
    covered, rims, land = _islands(poly, union, h)
    gb, sb = union.boundary, shapely.union_all(rims)
    given = sb
    step = h / 10.0
    gp, sp = _boundary_points(gb, step), _boundary_points(sb, step)
    to_given = _distances(gp, sb)
    d_grid_given = float(to_given.max())
    d_given, _ = _directed(sp, gb)
    # the arms and spikes below are found on the shore the layout worked on: an outline with far
    # more vertices than cells is simplified first, as the layout does (a shore of 120 000 points
    # took 37 s of buffers here); the distances stay measured to the outline as given
    simple = without_dense_vertices(poly, h)[0] if poly.geom_type == "Polygon" else poly  # parts: as given
    slack = 0.0 if simple is poly else DENSE_TOLERANCE * h
    # the dead-end arms narrower than two cells, which the layout leaves out on purpose
    # (:func:`meshcore.layout.shore.without_narrow_arms`, its rule at this cell size, with a note):
    # measured against the water without them, whose shore crosses their mouths; found as the
    # layout finds them, on the shore without its spikes (below): a Z-shaped sliver of land and
    # water narrower than half a cell is smoothed out there, not left out as an arm
    if arms is None:
        despiked = without_spikes(simple, 0.5 * h) or simple
        found = _without_narrow_arms(despiked, h)  # on the layout's shore
        water = None
        if found is not despiked:
            water = found if simple is poly else _cut_off(poly, simple.difference(found), slack)
        ruled = found if found is not despiked else poly
    else:  # the layout's own, found on its shore (simplified, cleaned): cut off the shore as given
        water = _cut_off(poly, shapely.union_all(list(arms)), DENSE_TOLERANCE * h) if len(arms) else None
        ruled = water if water is not None else poly
    if water is not None:
        sb = shapely.union_all(_islands(water, union, h)[1])
        sp = _boundary_points(sb, step)
    # islands closer than the layout keeps apart, joined with a note (to each other or to the
    # shore, :func:`meshcore.layout.islandgaps.without_island_gaps`): measured against the joined land
    joined = _joined_islands(ruled, h)
    if joined is not None:
        sb = shapely.union_all(_islands(joined, union, h)[1])
        sp = _boundary_points(sb, step)
    # a grid point is as near the shore as the nearer of the two: the shore as given or the one
    # the rules above make (a sliver of water the layout smooths out first may read as a narrow
    # arm here; the grid that covers part of it follows the shore as given there)
    to_shore = np.minimum(to_given, _distances(gp, sb))
    kg = int(np.argmax(to_shore))
    d_grid = float(to_shore[kg])
    # the shore's spikes narrower than half a cell, which the layout smooths out on purpose
    # (:func:`meshcore.layout.polygon.without_slivers`, with a note): measured apart, found on the
    # layout's shore as well (``slack`` wider)
    keep = ~_in_spikes(_spikes(simple, h, slack), sp)
    if sb is not given:
        # the lines the rules draw (an arm's mouth, the water between joined islands) are not
        # shore: they count only where the grid stops short of them, not where it covers water
        # beyond them (a sliver the layout smoothed into its water that reads as an arm here)
        drawn = _distances(sp, given) > 1e-6 * h
        keep &= ~(drawn & shapely.contains_xy(union, sp[:, 0], sp[:, 1]))
    d_shore, ks = _directed(sp[keep], gb) if keep.any() else (0.0, 0)
    sp = sp[keep] if keep.any() else sp
    if d_grid >= d_shore:
        dist, where, side = d_grid, gp[kg], "grid"
    else:
        dist, where, side = d_shore, sp[ks], "shore"
    return Coverage(
        grid_area=float(union.area),
        polygon_area=float(poly.area),
        area_ratio=float(union.area / poly.area) if poly.area > 0 else math.inf,
        hausdorff=dist,
        cell_size=h,
        where=(float(where[0]), float(where[1])),
        side=side,
        islands_covered=covered,
        island_cells=_cells_on(poly, land, grids, h),
        hausdorff_as_given=max(d_grid_given, d_given),
    )


def _joined_islands(water: Any, h: float) -> Any:
    """The water with the islands the layout keeps joined as it joins them, or None when it joins none."""
    if water.geom_type != "Polygon" or not len(water.interiors):
        return None
    from shapely.geometry import Polygon

    from ..layout.islandgaps import without_island_gaps

    wide = [
        r for r in water.interiors if island_width(Polygon(r), 0.01 * MIN_ISLAND_CELLS * h)[0] >= MIN_ISLAND_CELLS * h
    ]
    out, notes = without_island_gaps(Polygon(water.exterior, wide), h)  # the islands the layout keeps
    return out if notes else None


def without_spikes(poly: Any, width: float) -> Any:
    """``poly`` without its spikes of water or land narrower than ``width`` (a morphological opening
    and closing with mitred corners, what they change kept within ``width / 2`` of the shore), or
    None where that changes nothing or more than the spikes (splits the water, joins an island to
    the shore, or moves 1 % of its area).  The layout smooths them out
    (:func:`meshcore.layout.polygon.without_slivers`, half a cell), the shore distance measures
    them apart (:func:`coverage`)."""
    if width <= 0:
        return None
    r = 0.5 * width
    opts = {"join_style": "mitre", "mitre_limit": 10.0}
    clean = poly.buffer(-r, **opts).buffer(r, **opts).buffer(r, **opts).buffer(-r, **opts)
    changed = poly.symmetric_difference(clean)
    cut = _within_reach(poly, clean, changed, r)
    if cut is not clean:
        clean, changed = cut, poly.symmetric_difference(cut)
    if (
        clean.geom_type != "Polygon"
        or len(clean.interiors) != len(poly.interiors)
        or abs(clean.area - poly.area) > 0.01 * poly.area
        or not clean.is_valid
    ):
        return None
    if changed.area <= 1e-9 * poly.area:
        return None
    return clean


#: How far beyond ``r`` a point :func:`without_spikes` adds or takes may lie from the water or the
#: land before it is given back: rounding, and the mitres' corners within a disk's reach.
REACH_SLACK = 0.02


def _within_reach(poly: Any, clean: Any, changed: Any, r: float) -> Any:
    """``clean`` (``poly`` opened and closed by ``r``; ``changed``: the symmetric difference of the
    two) with what it changed kept within ``r`` of the shore.

    A closing with a disk of radius ``r`` adds only points within ``r`` of the water (the disk
    centred on an added point meets the water), an opening takes only points within ``r`` of the
    land.  The mitred buffers of :func:`without_spikes` keep the shore's corners sharp, but at a
    sharp corner beside a notch their mitres reach farther: on a held-out lake a spike of land
    3.3 ``r`` long became water (the grid covered it, 0.76 cells beyond the shore).  Each piece
    whose outline strays beyond the reach is cut back to it: the part farther than the reach from
    the water is land again (or, for a piece the opening took, farther from the land is water)."""
    import shapely

    reach = (1.0 + REACH_SLACK) * r
    parts = [g for g in shapely.get_parts(changed) if g.geom_type == "Polygon" and g.area > 0.0]
    if not parts:
        return clean
    # how far each piece's outline strays from the shore (its farthest vertex: the pieces are
    # narrow, a mitre's reach ends in a vertex); one nearest-segment query for all
    rim, which = shapely.get_coordinates(shapely.get_exterior_ring(parts), return_index=True)
    stray = np.zeros(len(parts))
    np.maximum.at(stray, which, _distances(rim, poly.boundary))
    out = clean
    for k in np.flatnonzero(stray > reach):
        g = parts[k]
        inside = g.point_on_surface()
        added = not poly.contains(inside)  # land the closing covers, else water the opening takes
        x0, y0, x1, y1 = g.bounds
        # the water (land added) or the land (water taken) near the piece: the box lies two
        # reaches beyond the piece, so its own rim is never within reach of it
        near = shapely.box(x0, y0, x1, y1).buffer(2.0 * reach, join_style="mitre")
        side = near.intersection(poly) if added else near.difference(poly)
        far = g.difference(side.buffer(reach))
        if not far.is_empty and far.area > 0.0:
            # a hair wider: where the piece's rim runs on along the shore's line (a mitre beyond
            # a corner), the cut alone left a sliver of no width out to the mitre's tip
            far = far.buffer(1e-6 * r, join_style="mitre")
            out = out.difference(far) if added else out.union(far)
    return out


def _spikes(poly: Any, h: float, slack: float = 0.0) -> Any:
    """Where the shore's spikes of water or land narrower than half a cell lie (what
    :func:`without_spikes` removes, a little widened so that the shore points on their rims fall
    inside, and by ``slack`` more: how far the outline may lie from ``poly``), or None."""
    import shapely

    clean = without_spikes(poly, 0.5 * h)
    if clean is None:
        return None
    # each piece widened on its own: one buffer of the whole difference unions tens of thousands
    # of pieces on a shore of 10^5 points (62 s); the union of the pieces' buffers is the same set
    return shapely.buffer(shapely.get_parts(poly.symmetric_difference(clean)), 1e-3 * h + slack)


def _in_spikes(pieces: Any, points: np.ndarray) -> np.ndarray:
    """Which ``points`` lie inside one of the widened spike ``pieces`` (:func:`_spikes`)."""
    import shapely

    out = np.zeros(len(points), bool)
    if pieces is None or not len(pieces):
        return out
    hit = shapely.STRtree(pieces).query(shapely.points(points), predicate="within")
    out[hit[0]] = True
    return out


def _cut_off(poly: Any, arms: Any, slack: float) -> Any:
    """``poly`` without the ``arms`` found on its simplified shore (widened by ``slack``, how far
    that shore may lie from ``poly``'s, so that no strip of an arm's rim stays), or ``poly`` where
    that would not leave one polygon with its islands."""
    import shapely

    cut = poly.difference(shapely.buffer(arms, slack))
    cut = shapely.make_valid(cut) if not cut.is_valid else cut
    if cut.geom_type == "MultiPolygon":  # crumbs of the outline's wiggles beyond the widened arms
        cut = max(cut.geoms, key=lambda g: g.area)
    if cut.geom_type != "Polygon" or len(cut.interiors) != len(poly.interiors):
        return poly
    return cut


def _without_narrow_arms(poly: Any, h: float) -> Any:
    """``poly`` without the dead-end arms narrower than two cells that the layout leaves out of
    the grid (:func:`meshcore.layout.shore.without_narrow_arms`: its own rule at the same cell
    size), or ``poly`` itself when it has none."""
    from ..layout.shore import without_narrow_arms

    kept, notes = without_narrow_arms(poly, h)
    return kept if notes else poly


def _land(k: int) -> str:
    return f"on island {k}" if k else "beyond the outer shore"


def _cells_on(poly: Any, islands: list[tuple[int, Any]], grids: Sequence[StructuredGrid], h: float) -> tuple:
    """Per shore with cell centres on its land — beyond the outer rings of ``poly`` (number 0),
    inside one of ``islands`` (number, polygon) — (number, count, depth of the deepest in cells,
    its place)."""
    import shapely
    from shapely.geometry import Polygon

    cx, cy = [], []
    for g in grids:
        x, y = np.asarray(g.x, dtype=float), np.asarray(g.y, dtype=float)
        cx.append((0.25 * (x[:-1, :-1] + x[1:, :-1] + x[1:, 1:] + x[:-1, 1:])).ravel())
        cy.append((0.25 * (y[:-1, :-1] + y[1:, :-1] + y[1:, 1:] + y[:-1, 1:])).ravel())
    px, py = np.concatenate(cx), np.concatenate(cy)
    out = []
    shell = shapely.union_all([Polygon(p.exterior) for p in getattr(poly, "geoms", [poly])])
    beyond = np.flatnonzero(~shapely.contains_xy(shell, px, py))
    if len(beyond):
        depth = shapely.distance(shapely.points(px[beyond], py[beyond]), shell.boundary)
        d = int(np.argmax(depth))
        out.append((0, len(beyond), float(depth[d]) / h, float(px[beyond[d]]), float(py[beyond[d]])))
    for k, island in islands:
        inside = np.flatnonzero(shapely.contains_xy(island, px, py))
        if len(inside):
            depth = shapely.distance(shapely.points(px[inside], py[inside]), island.exterior)
            d = int(np.argmax(depth))
            out.append((k, len(inside), float(depth[d]) / h, float(px[inside[d]]), float(py[inside[d]])))
    return tuple(out)


def _islands(poly: Any, union: Any, h: float) -> tuple[tuple[CoveredIsland, ...], list[Any], list[tuple[int, Any]]]:
    """The islands of ``poly`` the grid (``union``) covers, the rings it is measured against
    (every outer ring and every island ring not covered), and the islands not covered."""
    from shapely.geometry import Polygon

    covered: list[CoveredIsland] = []
    rims: list[Any] = []
    land: list[tuple[int, Any]] = []
    k = 0
    for part in getattr(poly, "geoms", [poly]):
        rims.append(part.exterior)
        for ring in part.interiors:
            k += 1
            island = Polygon(ring)
            share = union.intersection(island).area / island.area if island.area > 0 else 0.0
            if share < COVERED:
                rims.append(ring)
                land.append((k, island))
                continue
            # to the layout's tolerance (``water_polygon``'s, 1 % of the two cells): an island it
            # left out as narrower than two cells is measured as left out, not lost
            width, c = island_width(island, 0.01 * MIN_ISLAND_CELLS * h)
            covered.append(CoveredIsland(k, float(island.area), width, float(c.x), float(c.y), float(share)))
            if not covered[-1].left_out(h):
                rims.append(ring)  # lost: measured
    return tuple(covered), rims, land
