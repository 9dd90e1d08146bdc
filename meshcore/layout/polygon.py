r"""The water polygon: an outline and its islands, checked and cleaned once.

Rules (every violation is an :class:`~meshcore.errors.InvalidInputError` naming the ring and
the place):

* rings need at least three distinct, finite points; a repeated closing point is dropped;
* the outline must not cross itself; islands must lie inside it and must not cross or touch
  it (an island touching the shore at a point is a peninsula: join it to the outline); islands
  that touch each other are joined into one;
* orientation is free: the outline is made counter-clockwise and islands clockwise;
* islands narrower than ``drop_islands_below`` (two cells) where they are widest — the
  diameter of the largest disc inside them, a needle's width and not its length — are
  removed, with a note naming the island (its number among the given islands), where it is,
  its width and area, and the cell size that would keep it: no grid of that cell size goes
  round them.  Measured on :func:`meshcore.testing.small_islands` (islands 0.3–5 cells across,
  blobs, needles and bent spikes, 12 lakes of 8 islands, ``h = 0.25``): of the islands 1–2
  cells across that the earlier rule (``4 · area / perimeter``, which reads a needle as twice
  its width) kept, 2 of 10 (default layout) and 4 of 10 (``regular``) had grid cells over
  them, the ends narrower than two cells folded into one block side; of those at least two
  cells across, 2 of 22 and 0 of 22.
  From :data:`SUMMARY_FROM` such islands on, :func:`summarised_islands` makes their notes one
  (the count, the largest, the cell size that keeps them all; each island's note kept apart).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import InvalidInputError
from ..quality.coverage import MIN_ISLAND_CELLS, island_width, without_spikes
from .shore import without_dense_vertices  # (their home before)

__all__ = [
    "MIN_ISLAND_CELLS",
    "LeftOutIsland",
    "summarised_islands",
    "water_parts_from_points",
    "water_polygon",
    "without_dense_vertices",
]


def _ring(points: Any, what: str) -> np.ndarray:
    try:
        p = np.asarray(points, dtype=float)
    except (TypeError, ValueError):
        raise InvalidInputError(f"{what}: expected (x, y) points, got {type(points).__name__}") from None
    if p.ndim != 2 or p.shape[1] != 2:
        raise InvalidInputError(f"{what}: expected an (n, 2) array of points, got shape {p.shape}")
    bad = np.flatnonzero(~np.isfinite(p).all(axis=1))
    if len(bad):
        raise InvalidInputError(f"{what}: point {bad[0] + 1} is not finite ({p[bad[0]].tolist()})")
    if len(p) > 1 and np.array_equal(p[0], p[-1]):
        p = p[:-1]
    keep = np.concatenate([[True], np.any(np.diff(p, axis=0) != 0, axis=1)])
    p = p[keep]
    if len(p) < 3:
        raise InvalidInputError(f"{what}: needs at least 3 distinct points, got {len(p)}")
    return p


def _on_one_line(ring: np.ndarray, what: str) -> None:
    """Raise when every point of the ring lies on one straight line (a ring of no area)."""
    d = ring - ring.mean(axis=0)
    sv = np.linalg.svd(d, compute_uv=False)
    if sv[-1] <= 1e-9 * sv[0]:
        a, b = ring[np.argmin(d @ d[np.argmax(np.abs(d).sum(axis=1))])], ring[np.argmax(np.abs(d).sum(axis=1))]
        raise InvalidInputError(
            f"{what} has no area: its {len(ring)} points lie on one straight line, from near "
            f"({a[0]:.6g}, {a[1]:.6g}) to near ({b[0]:.6g}, {b[1]:.6g})"
        )


def _without_backtracks(ring: np.ndarray, what: str, notes: list[str]) -> np.ndarray:
    """The ring without points it goes out to and comes straight back from (a spike of no width).

    Such a point turns the ring by 180°: the edges before and after it overlap, which reads as the
    ring crossing itself, though no water is there.  Each is dropped with a note naming it.
    """
    _on_one_line(ring, what)
    dropped: list[np.ndarray] = []
    rounds = 0
    while len(ring) > 3:
        rounds += 1
        if rounds > _BACKTRACK_ROUNDS:  # a ring that retraces a long way: each round drops only its tip
            ring = _without_long_backtracks(ring, what, dropped)
            break
        a, b = ring - np.roll(ring, 1, axis=0), np.roll(ring, -1, axis=0) - ring
        cross = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
        dot = (a * b).sum(axis=1)
        back = np.flatnonzero((np.abs(cross) <= 1e-9 * np.hypot(*a.T) * np.hypot(*b.T)) & (dot < 0))
        if not len(back):
            break
        if len(ring) - len(back) < 3:  # fewer than 3 points left: no area (was: "crosses itself" about them)
            _retraced(ring, what, [*dropped, *ring[back]])
        dropped.extend(ring[back])
        ring = np.delete(ring, back, axis=0)
        keep = np.any(ring != np.roll(ring, 1, axis=0), axis=1)  # the point it came back to, now twice
        if keep.sum() < 3:
            _retraced(ring, what, dropped)
        ring = ring[keep]
    if dropped:
        places = ", ".join(f"near ({p[0]:.6g}, {p[1]:.6g})" for p in dropped[:3])
        more = f" and {len(dropped) - 3} more" if len(dropped) > 3 else ""
        notes.append(
            f"{what} goes out to a point and straight back (a spike of no width) {places}{more}: "
            f"{'that point' if len(dropped) == 1 else 'those points'} left out"
        )
    return ring


#: Rounds of dropping every spike tip at once before :func:`_without_long_backtracks` takes over (a
#: retraced run of k points takes k rounds of O(n) each: 40 000 points took a minute).
_BACKTRACK_ROUNDS = 8


def _is_back(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> bool:
    """The ring turns by 180° at ``b`` (the test of :func:`_without_backtracks`)."""
    u, v = b - a, c - b
    cross = u[0] * v[1] - u[1] * v[0]
    return bool(abs(cross) <= 1e-9 * math.hypot(*u) * math.hypot(*v) and u @ v < 0)


def _retraced(ring: np.ndarray, what: str, dropped: list[np.ndarray]) -> None:
    """Raise: the ring only goes out and comes back (its spikes dropped, fewer than 3 points are left)."""
    pts = np.vstack([ring, *dropped])  # every point of the ring: its two ends are the far-apart ones
    a = pts[np.argmax(np.hypot(*(pts - pts.mean(axis=0)).T))]
    b = pts[np.argmax(np.hypot(*(pts - a).T))]
    raise InvalidInputError(
        f"{what} goes out and comes back along itself, enclosing no water: from near "
        f"({a[0]:.6g}, {a[1]:.6g}) to near ({b[0]:.6g}, {b[1]:.6g}) and back"
    )


def _without_long_backtracks(ring: np.ndarray, what: str, dropped: list[np.ndarray]) -> np.ndarray:
    """:func:`_without_backtracks` in linear time: one pass with a stack drops a retraced run of any
    length; passes from the ring's middle clear runs across its seam.  The points kept keep their
    order from the ring's first.  A ring that retraces itself all the way (no area left) is an error
    naming where it turns."""
    idx = list(range(len(ring)))
    for _ in range(8):
        out: list[int] = []
        n_dropped = len(dropped)
        for i in idx:
            while len(out) >= 2 and _is_back(ring[out[-2]], ring[out[-1]], ring[i]):
                dropped.append(ring[out.pop()])
            if not out or not np.array_equal(ring[out[-1]], ring[i]):
                out.append(i)
        if len(out) > 1 and np.array_equal(ring[out[0]], ring[out[-1]]):
            out.pop(0)  # the point it came back to across the seam: the later one kept, as the rounds do
        if len(out) < 3:
            _retraced(ring, what, dropped)
        r = [ring[k] for k in out]
        idx = out[len(out) // 2 :] + out[: len(out) // 2]
        if len(dropped) == n_dropped and not _is_back(r[-2], r[-1], r[0]) and not _is_back(r[-1], r[0], r[1]):
            break
    return ring[sorted(idx)]


def _crossing(ring: np.ndarray, what: str) -> None:
    """Raise when the closed ring crosses itself, naming two crossing segments (from 1)."""
    import shapely
    from shapely.geometry import LinearRing

    if LinearRing(ring).is_simple:
        return
    n = len(ring)
    segs = shapely.linestrings(np.stack([ring, np.roll(ring, -1, axis=0)], axis=1))
    tree = shapely.STRtree(segs)
    i_idx, j_idx = tree.query(segs, predicate="intersects")
    for i, j in zip(i_idx.tolist(), j_idx.tolist(), strict=True):
        if j <= i or j == i + 1 or (i == 0 and j == n - 1):
            continue
        x = shapely.intersection(segs[i], segs[j]).representative_point()
        raise InvalidInputError(
            f"{what} crosses itself: the edge from point {i + 1} to {i % n + 2 if i + 1 < n else 1} "
            f"meets the edge from point {j + 1} to {j + 2 if j + 1 < n else 1} near ({x.x:.6g}, {x.y:.6g})"
        )
    raise InvalidInputError(f"{what} crosses itself ({shapely.is_valid_reason(shapely.Polygon(ring))})")


@dataclass(frozen=True, slots=True)
class LeftOutIsland:
    """An island :func:`water_polygon` left out as too narrow: its number, width where widest, area,
    a point of it, and its note."""

    number: int
    width: float
    area: float
    where: tuple[float, float]
    note: str


def water_polygon(
    outline: Any, *, holes: Any = (), drop_islands_below: float = 0.0, left_out: list[LeftOutIsland] | None = None
):
    """A valid shapely Polygon of the water and a list of notes about what was changed (``left_out``:
    the islands narrower than ``drop_islands_below`` are added to it as well)."""
    from shapely.geometry import Polygon
    from shapely.geometry.polygon import orient

    notes: list[str] = []
    if hasattr(outline, "exterior"):  # a shapely Polygon
        if len(holes):
            raise InvalidInputError("give the islands either as the polygon's holes or as holes=, not both")
        holes = [np.asarray(h.coords) for h in outline.interiors]
        outline = np.asarray(outline.exterior.coords)
    outer = _without_backtracks(_ring(outline, "outline"), "the outline", notes)
    _crossing(outer, "the outline")
    shell = Polygon(outer)
    size = math.hypot(*(outer.max(axis=0) - outer.min(axis=0)))
    rings: list[np.ndarray] = []
    kept: list[Any] = []  # the polygons of ``rings``, made once (300 islands: 0.4 million made per call)
    boxes = np.empty((0, 4))  # and their bounds: only islands whose boxes overlap can touch or nest
    for k, h in enumerate(holes):
        r = _without_backtracks(_ring(h, f"island {k + 1}"), f"island {k + 1}", notes)
        _crossing(r, f"island {k + 1}")
        isl = Polygon(r)
        if not shell.contains(isl):
            c = isl.representative_point()
            raise InvalidInputError(
                f"island {k + 1} (near {c.x:.6g}, {c.y:.6g}) is not inside the outline or touches it"
            )
        b = np.asarray(isl.bounds)
        near = (boxes[:, 0] <= b[2]) & (b[0] <= boxes[:, 2]) & (boxes[:, 1] <= b[3]) & (b[1] <= boxes[:, 3])
        for j in np.flatnonzero(near).tolist():
            other = kept[j]
            if other.contains(isl) or isl.contains(other):  # a pond on an island
                inner, outer_k, c = (k + 1, j + 1, isl) if other.contains(isl) else (j + 1, k + 1, other)
                c = c.representative_point()
                notes.append(
                    f"island {inner} near ({c.x:.6g}, {c.y:.6g}) lies inside island {outer_k}: water on an "
                    f"island (a pond) is not the lake's, left out"
                )
                if outer_k == k + 1:
                    rings[j], kept[j], boxes[j] = r, isl, b
                isl = None
                break
            if other.intersects(isl):  # touching islands are one island
                merged = other.union(isl)
                if merged.geom_type != "Polygon":  # touching at points: close the pinch (bevelled: a
                    # mitre reaches out up to 5 times as far at a sharp tip, across a shore 6e-7 away)
                    merged = merged.buffer(1e-7 * size, join_style="bevel").buffer(-0.5e-7 * size, join_style="bevel")
                if merged.geom_type != "Polygon":
                    c = other.intersection(isl).representative_point()
                    raise InvalidInputError(
                        f"islands {j + 1} and {k + 1} overlap in more than one place (near {c.x:.6g}, {c.y:.6g})"
                    )
                if not shell.contains(merged):
                    c = merged.intersection(shell.exterior).representative_point()
                    raise InvalidInputError(
                        f"islands {j + 1} and {k + 1} touch each other and the shore near ({c.x:.6g}, {c.y:.6g}): "
                        f"join them into the outline there"
                    )
                notes.append(f"islands {j + 1} and {k + 1} touch: joined into one")
                rings[j] = np.asarray(merged.exterior.coords)[:-1]
                kept[j] = Polygon(rings[j])
                boxes[j] = kept[j].bounds
                isl = None
                break
        if isl is None:
            continue
        if drop_islands_below > 0:
            width, c = island_width(isl, 0.01 * drop_islands_below)
            if width < drop_islands_below:
                notes.append(
                    f"island {k + 1} near ({c.x:.6g}, {c.y:.6g}) is {width:.3g} across at its widest "
                    f"(area {isl.area:.3g}, {isl.area / (0.5 * drop_islands_below) ** 2:.2g} cells²), less than "
                    f"{drop_islands_below:.3g} (two cells): too narrow for the grid to go round it, left out "
                    f"(the grid covers it); a cell size of at most {width / 2:.3g} would keep it"
                )
                if left_out is not None:
                    left_out.append(LeftOutIsland(k + 1, float(width), float(isl.area), (c.x, c.y), notes[-1]))
                continue
        rings.append(r)
        kept.append(isl)
        boxes = np.vstack([boxes, b])
    poly = orient(Polygon(outer, rings), 1.0)
    if not poly.is_valid:
        import shapely

        raise InvalidInputError(f"the water polygon is not valid ({shapely.is_valid_reason(poly)}, near that point)")
    if poly.area <= 1e-12 * size * size:  # (was: "not valid (Valid Geometry, near that point)")
        tiny = "; its coordinates are too small for double precision: scale them up" if size < 1e-100 else ""
        raise InvalidInputError(
            f"the outline encloses no area to grid (area {poly.area:.3g} within an extent of {size:.3g}, "
            f"near ({outer[0][0]:.6g}, {outer[0][1]:.6g})){tiny}"
        )
    return poly, notes


#: From this many islands left out as too narrow, their notes are one (:func:`summarised_islands`).
SUMMARY_FROM = 4


def summarised_islands(
    notes: list[str], left_out: list[LeftOutIsland], limit: float, water: float
) -> tuple[list[str], list[str]]:
    """``notes`` with the notes of the ``left_out`` islands (narrower than ``limit``; ``water``: the
    water's area) made one, where
    there are :data:`SUMMARY_FROM` of them or more, and those islands' own notes (else ``notes``
    as they are and no details).  A lake with dozens of islets read as dozens of lines that all
    say the same; the one says how many, which is the largest, and the cell size that keeps
    every one of them."""
    if len(left_out) < SUMMARY_FROM:
        return list(notes), []
    own = {isl.note for isl in left_out}
    big = max(left_out, key=lambda isl: isl.area)
    keep = min(isl.width for isl in left_out) / 2
    total = sum(isl.area for isl in left_out)
    summary = (
        f"{len(left_out)} islands are less than {limit:.3g} (two cells) across at their widest: too narrow "
        f"for the grid to go round them, left out (the grid covers them: {100 * total / water:.2g} % of the "
        f"water's area); the largest, island {big.number} near ({big.where[0]:.6g}, {big.where[1]:.6g}), is "
        f"{big.width:.3g} across (area {big.area:.3g}); a cell size of at most {keep:.3g} would keep them all "
        f"(each island: the layout's details, Messages in the app)"
    )
    out: list[str] = []
    for n in notes:
        if n in own:
            if summary not in out:
                out.append(summary)
            continue
        out.append(n)
    return out, [isl.note for isl in left_out]


def without_slivers(poly: Any, width: float) -> tuple[Any, list[str]]:
    """The water without spikes of water or land narrower than ``width`` (a morphological opening
    and closing with mitred corners), and a note; ``poly`` itself when that would change more than
    the slivers (split the water, join an island to the shore, or move 1 % of its area).

    No grid line can follow a spike narrower than half a cell: its cells would fold.
    """
    clean = without_spikes(poly, width)
    if clean is None:
        return poly, []
    moved = poly.symmetric_difference(clean).area
    from shapely.geometry.polygon import orient

    note = (
        f"spikes of water or land narrower than {width:.3g} (half a cell) smoothed out of the shore "
        f"({100 * moved / poly.area:.2g} % of the water area moved{_largest_spikes(poly, clean, width)})"
    )
    return orient(clean.simplify(1e-3 * width), 1.0), [note]


def _largest_spikes(poly: Any, clean: Any, width: float, n: int = 3) -> str:
    """``; the largest: land … near (x, y), …`` — the ``n`` largest pieces of land the grid will
    cover and of water it will leave out, with their length (half the perimeter) and place."""
    pieces = []
    for what, geom in (("land", clean.difference(poly)), ("water", poly.difference(clean))):
        for g in getattr(geom, "geoms", [geom]):
            if g.geom_type == "Polygon" and g.area > 1e-6 * width * width:
                pieces.append((g.area, what, g))
    big = sorted(pieces, key=lambda t: -t[0])[:n]
    if not big or big[0][2].length < 4 * width:  # only teeth: nothing worth naming
        return ""
    said = []
    for _, what, g in big:
        _, c = island_width(g, 0.05 * width)
        said.append(f"{what} {0.5 * g.length:.3g} long near ({c.x:.6g}, {c.y:.6g})")
    return "; the largest: " + ", ".join(said) + " (the grid covers land and leaves out water there)"


def water_from_points(pointset: Any):
    """Outline and islands from the polylines of a point file (projected already): one lake.

    The ring with the largest area is the shore; every other ring must lie inside it (an
    island).  Returns ``(outline, islands)`` as arrays.  A file of several separate water parts
    (:func:`water_parts_from_points`) is refused naming the second part; ``meshcore mesh`` and
    :func:`meshcore.mesh_outline` mesh every part.
    """
    parts = water_parts_from_points(pointset)
    if len(parts) > 1:
        (oname, _, _), (name, p, _) = parts[0], parts[1]
        from shapely.geometry import Polygon

        c = Polygon(p).representative_point()  # the place tells rings of one name apart (a MultiGeometry's)
        raise InvalidInputError(
            f"{pointset.source or 'points'}: {name!r} near ({c.x:.6g}, {c.y:.6g}) lies outside the outline "
            f"{oname!r} — a second part of the water ({len(parts)} in all): one lake here (islands are rings "
            f"inside the shore); 'meshcore mesh' meshes every part (--part N for some)"
        )
    return parts[0][1], parts[0][2]


def water_parts_from_points(pointset: Any) -> list[tuple[str, np.ndarray, list[np.ndarray]]]:
    """The separate parts of the water in the polylines of a point file (projected already).

    Rings are taken largest first: a ring inside a part's shore is an island of that part, a ring
    outside every part is a part of its own (a lake split at a dam or causeway, a reservoir and a
    pond, several placemarks).  Returns ``[(name, shore, islands), ...]``, the largest part
    first.  A ring whose boundary crosses or touches a part's shore is an error naming both and
    the place: an island across the shore, or two parts that overlap or touch (they are one water:
    draw them as one outline, or keep them apart).
    """
    from shapely.geometry import Polygon

    rings = []
    for k, pl in enumerate(pointset.polylines):
        name = pl.name or f"polyline {k + 1}"
        p = _ring(pl.points, f"{pointset.source or 'points'}: {name}")
        rings.append((abs(Polygon(p).area), name, p))
    if not rings:
        raise InvalidInputError(f"{pointset.source or 'points'}: no outline")
    rings.sort(key=lambda t: -t[0])
    parts: list[tuple[str, np.ndarray, list[np.ndarray]]] = []
    shells: list[Any] = []
    for _, name, p in rings:
        ring = Polygon(p)
        for (oname, _, islands), shell in zip(parts, shells, strict=True):
            if ring.boundary.intersects(shell.boundary):
                c = ring.boundary.intersection(shell.boundary).representative_point()
                if shell.contains(ring.representative_point()):
                    inside = ring.difference(shell).area <= 1e-9 * ring.area  # on the shore from inside
                    raise InvalidInputError(
                        f"{pointset.source or 'points'}: {name!r} {'touches' if inside else 'crosses'} the "
                        f"shore of {oname!r} near ({c.x:.6g}, {c.y:.6g}) — an island must lie inside the shore, "
                        f"clear of it (a ring that reaches the land is part of the shore: draw it into the outline)"
                    )
                raise InvalidInputError(
                    f"{pointset.source or 'points'}: the water parts {oname!r} and {name!r} overlap or touch "
                    f"near ({c.x:.6g}, {c.y:.6g}) — separate parts must lie apart (parts that meet are one "
                    f"water: draw them as one outline)"
                )
            if shell.contains(ring.representative_point()):
                islands.append(p)
                break
        else:
            parts.append((name, p, []))
            shells.append(ring.buffer(0))
    return parts
