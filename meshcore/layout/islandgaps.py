r"""Islands closer than three cells to each other: joined into one, the water between given up.

A block between two islands needs a few cells across the water there: with counts that are
multiples of four (two coarse levels) a passage under three cells gets cells a half to a
quarter of the asked size, and a structured block carries that count across the lake; a
passage of a cell or less cannot be gridded at all.  Lakes with many islands (Finland, Sweden,
Canada) have dozens a cell or two apart: on :func:`meshcore.testing.island_clusters` (islands in
clusters, gaps of 0.3–5 cells) at 10 000 cells main made 1.3–3 × the asked cells, folded cells
in 5 of 8 lakes and 44–78 % of the nodes within 3° (``docs/lake-grids-journal.md``, *Island
clusters*).

:func:`without_island_gaps` finds every pair of islands less than ``gap_cells`` cells apart,
groups them, and fills the water between the members of each group: a bridge per close pair
(the convex hull of both islands within half a cell more than the gap of their nearest points:
a closing alone does not join two corners pointing at each other) and a morphological closing
of the group with its bridges (radius half the gap); only filled water that touches two
members is taken (the gap, not an island's own bay).  A group becomes one island.  Water the
joined land cuts off from the lake (a lagoon inside a ring of islands) is given up too.  One
note per joined island names its place, how many islands, the narrowest gap and the water
given up (area and share of the lake).  A lake whose islands are all at least ``gap_cells``
apart is returned as it is (the same object): its grid does not change.

``shore_cells`` joins islands to the shore the same way (a peninsula); off by default: on the
generated lakes with a few islands near the shore it made 1 of 6 better and 4 worse, one with
87 folded cells (journal).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

__all__ = ["GAP_CELLS", "SHORE_GAP_CELLS", "close_pairs", "without_island_gaps"]

#: Islands closer than this many cells to each other are joined.
GAP_CELLS = 3.0
#: An island closer than this many cells to the shore is joined to it: 0, off (measured worse on
#: lakes with a few islands near the shore, see the module's notes).
SHORE_GAP_CELLS = 0.0


def _find(parent: list[int], i: int) -> int:
    while parent[i] != i:
        parent[i] = parent[parent[i]]
        i = parent[i]
    return i


def close_pairs(poly: Any, gap: float, shore_gap: float | None = None) -> list[tuple[int, int, float]]:
    """``(i, j, distance)`` for the islands of ``poly`` closer than ``gap`` to each other, or than
    ``shore_gap`` (default ``gap``) to the shore (``j = -1``)."""
    import shapely
    from shapely.geometry import LineString, Polygon

    islands = [Polygon(r) for r in poly.interiors]
    if not islands:
        return []
    tree = shapely.STRtree(islands)
    a, b = tree.query(islands, predicate="dwithin", distance=gap)
    pairs = []
    for i, j in zip(a.tolist(), b.tolist(), strict=True):
        if i < j:
            pairs.append((i, j, float(islands[i].distance(islands[j]))))
    shore = LineString(poly.exterior.coords)
    d = shapely.distance(np.array(islands, dtype=object), shore)
    limit = gap if shore_gap is None else shore_gap
    pairs += [(i, -1, float(d[i])) for i in np.flatnonzero(d < limit).tolist()]
    return pairs


def _bridge(a: Any, b: Any, d: float, h: float) -> Any:
    """The convex hull of ``a`` and ``b`` within ``d + h`` of their nearest points."""
    import shapely
    from shapely.ops import nearest_points

    p, q = nearest_points(a, b)
    reach = d + 0.5 * h
    return shapely.union_all(
        [a.intersection(p.buffer(reach, quad_segs=4)), b.intersection(q.buffer(reach, quad_segs=4))]
    ).convex_hull


def without_island_gaps(
    poly: Any, h: float, *, gap_cells: float = GAP_CELLS, shore_cells: float = SHORE_GAP_CELLS
) -> tuple[Any, list[str]]:
    """The water with islands less than ``gap_cells · h`` apart, or ``shore_cells · h`` from the
    shore, joined, and notes.

    Joined land can come within ``gap`` of an island that was not: joined again, up to four rounds.
    """
    notes: list[str] = []
    for _ in range(4):
        poly, more = _joined_once(poly, h, gap_cells, shore_cells)
        if not more:
            break
        notes += more
    return poly, notes


def _joined_once(poly: Any, h: float, gap_cells: float, shore_cells: float) -> tuple[Any, list[str]]:
    import shapely
    from shapely.geometry import Polygon, box
    from shapely.geometry.polygon import orient

    gap = gap_cells * h
    pairs = close_pairs(poly, gap, shore_cells * h)
    if not pairs:
        return poly, []
    islands = [Polygon(r) for r in poly.interiors]
    n = len(islands)
    shore_id = n
    parent = list(range(n + 1))
    for i, j, _ in pairs:
        ri, rj = _find(parent, i), _find(parent, shore_id if j < 0 else j)
        if ri != rj:
            parent[max(ri, rj)] = min(ri, rj)
    groups: dict[int, list[int]] = {}
    for i in range(n + 1):
        groups.setdefault(_find(parent, i), []).append(i)
    shell = Polygon(poly.exterior)
    x0, y0, x1, y1 = shell.bounds
    land = box(x0 - 4 * gap, y0 - 4 * gap, x1 + 4 * gap, y1 + 4 * gap).difference(shell)
    radius = 0.5 * gap
    tiny, eps = 1e-6 * h, 1e-4 * h
    joined: list[Any] = []
    for members in groups.values():
        if len(members) < 2:
            continue
        isl = [m for m in members if m < n]
        near = shapely.union_all([islands[m] for m in isl])
        pieces = [islands[m] for m in isl]
        at_shore = shore_id in members
        if at_shore:
            pieces.append(land.intersection(near.buffer(gap + 2 * radius)))
        together = shapely.union_all(pieces)
        # a closing alone does not join two corners pointing at each other (a disc slips in from
        # the side): each close pair gets a bridge, the hull of both shores near its narrowest place
        bridges = [_bridge(islands[i], land if j < 0 else islands[j], d, h) for i, j, d in pairs if i in members]
        closed = shapely.union_all([together, *bridges]).buffer(radius, quad_segs=8).buffer(-radius, quad_segs=8)
        filled = closed.difference(together)
        fill = []
        for g in getattr(filled, "geoms", [filled]):
            if g.geom_type != "Polygon" or g.area <= tiny * h:
                continue
            if sum(1 for p in pieces if p.distance(g) < tiny) >= 2:  # a gap, not a bay of one island
                fill.append(g)
        if not fill:
            continue
        # closed by a hair: the fill and the islands it joins share edges only up to rounding
        group = shapely.union_all(pieces[: len(isl)] + fill)
        joined.append(group.buffer(eps, join_style="mitre").buffer(-eps, join_style="mitre"))
    if not joined:
        return poly, []
    new_land = shapely.union_all(joined).intersection(shell)
    alone = [g for g in islands if not g.representative_point().within(new_land)]
    water = shell.difference(new_land).difference(shapely.union_all(alone) if alone else Polygon())
    parts = sorted((g for g in getattr(water, "geoms", [water]) if g.geom_type == "Polygon"), key=lambda g: -g.area)
    kept = parts[0]
    cut_off = shapely.union_all(parts[1:]) if len(parts) > 1 else Polygon()
    notes = []
    said = 0.0
    # one note per piece of joined land (an island cluster, or islands joined to the shore at one place)
    ring = shell.exterior
    for piece in getattr(new_land, "geoms", [new_land]):
        if piece.geom_type != "Polygon":
            continue
        inside = [k for k, g in enumerate(islands) if g.representative_point().within(piece)]
        at_shore = piece.distance(ring) < eps
        if len(inside) < 2 and not at_shore:
            continue
        held = shapely.union_all([islands[k] for k in inside]) if inside else Polygon()
        lost = piece.difference(held).area + Polygon(piece.exterior).difference(piece).intersection(cut_off).area
        gaps = [d for i, j, d in pairs if i in inside and (j in inside or (j < 0 and at_shore))]
        c = (held if inside else piece).centroid
        what = f"{len(inside)} island{'s' if len(inside) != 1 else ''} near ({c.x:.6g}, {c.y:.6g})"
        said += lost
        notes.append(
            f"{what}{' and the shore' if at_shore else ''} less than "
            f"{f'{shore_cells:g} cells (from the shore) or ' if at_shore else ''}{gap_cells:g} cells apart (cells of "
            f"{h:.3g}; narrowest gap {min(gaps, default=0.0) / h:.2g} cells): too narrow a passage for a block; "
            f"joined into {'the shore' if at_shore else 'one island'}, the water between given up (area {lost:.4g}, "
            f"{100 * lost / poly.area:.2g} % of the water); a cell size of at most "
            f"{min(gaps, default=0.0) / gap_cells:.3g} keeps them apart"
        )
    rest = poly.area - kept.area - said
    if rest > 1e-4 * poly.area:
        c = max((p for p in parts[1:]), key=lambda p: p.area).representative_point()
        notes.append(
            f"water cut off from the lake by joined islands, the largest part near ({c.x:.6g}, {c.y:.6g}), given up "
            f"(area {rest:.4g}, {100 * rest / poly.area:.2g} % of the water)"
        )
    out = orient(Polygon(kept.exterior, list(kept.interiors)), 1.0)
    if not out.is_valid:
        out = orient(out.buffer(0), 1.0)
    assert math.isfinite(out.area)
    return out, notes
