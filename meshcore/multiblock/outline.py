r"""From one closed outline (a lake shore) plus cut lines to four-sided blocks.

The lake workflow:

1. one closed **outline** (the shoreline), in model units (see
   :func:`project_lonlat` for lon/lat data);
2. **cut lines**: polylines across the water.  Each end of a cut must lie on
   the outline or on another cut (within ``snap``; it is then moved exactly
   onto it).  Cuts may cross each other; crossings become shared vertices;
3. **blocks**: a name, four corner points ``(sw, se, ne, nw)`` in
   counter-clockwise order (coordinates, or integer indices of outline
   points) and the cells ``(ni, nj)``.

The outline and the cuts split the water into regions (shapely
``polygonize``).  Each block's corners must lie on one region's boundary; the
region's boundary is split at the corners into the four sides.  The cuts
become shared borders: every side is split into **chains** at block corners
and at points where three or more lines meet, each chain is re-sampled once
(uniformly in arc length, the paper's linear spline) and used by both
neighbouring blocks, so interface nodes are identical by construction.

Cell counts per chain follow from the blocks' ``cells``: a side's chains must
add up to its block's ``ni`` (bottom, top) or ``nj`` (left, right).  Chains
whose count is fixed by another block are taken from there; the remaining
cells of a side are shared among its free chains by arc length.  Conflicts are
a :class:`~meshcore.errors.TopologyError` naming both blocks and borders.
"""

from __future__ import annotations

import math
from collections import defaultdict
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .._validation import check_allocation, max_nodes, validate_count, validate_points
from ..boundary import signed_area
from ..errors import InvalidInputError, TopologyError
from ..pointindex import point_key, point_keys
from ..segments import feet, nearest_on_polyline
from .topology import MultiBlockTopology

__all__ = ["BlockOutline", "OutlineBlocks", "from_outline", "project_lonlat"]

EARTH_RADIUS_M = 6_371_008.8  # mean Earth radius (IUGG)


def project_lonlat(lonlat: Any, *, origin: tuple[float, float] | None = None) -> tuple[np.ndarray, tuple[float, float]]:
    r"""Local equirectangular projection of lon/lat degrees to metres.

    .. math::  x = R\,(λ − λ_0)\cos φ_0,\qquad y = R\,(φ − φ_0)

    about ``origin = (λ_0, φ_0)`` (default: the mean of the points), with
    ``R`` the mean Earth radius.  Distortion is below 0.1 % over a few tens of
    kilometres, enough for lake grids.

    Returns
    -------
    xy : (n, 2) ndarray
    origin : (lon0, lat0)
    """
    p = validate_points(lonlat, name="lon/lat points")
    lon0, lat0 = origin if origin is not None else (float(p[:, 0].mean()), float(p[:, 1].mean()))
    x = np.radians(p[:, 0] - lon0) * EARTH_RADIUS_M * math.cos(math.radians(lat0))
    y = np.radians(p[:, 1] - lat0) * EARTH_RADIUS_M
    return np.column_stack([x, y]), (lon0, lat0)


@dataclass(frozen=True, slots=True)
class BlockOutline:
    """A block picked on the outline: name, corners ``(sw, se, ne, nw)``, cells."""

    name: str
    corners: tuple
    cells: tuple[int, int]
    initial: str = "tfi"

    @classmethod
    def coerce(cls, value: Any) -> BlockOutline:
        if isinstance(value, BlockOutline):
            return value
        if isinstance(value, Mapping):
            valid = {"name", "corners", "cells", "initial"}
            unknown = set(value) - valid
            if unknown:
                raise InvalidInputError(
                    f"outline block {value.get('name', '?')!r}: unknown key(s) {sorted(unknown)}; "
                    f"valid: {sorted(valid)}"
                )
            missing = {"name", "corners", "cells"} - set(value)
            if missing:
                raise InvalidInputError(f"outline block {value.get('name', '?')!r}: missing {sorted(missing)}")
            return cls(
                name=str(value["name"]),
                corners=tuple(value["corners"]),
                cells=tuple(value["cells"]),
                initial=str(value.get("initial", "tfi")),
            )
        raise InvalidInputError(f"outline block must be a mapping, got {value!r}")


@dataclass(frozen=True, slots=True, eq=False)
class OutlineBlocks:
    """The result of :func:`from_outline`: the topology plus what it came from."""

    topology: MultiBlockTopology
    outline: np.ndarray
    cuts: tuple[np.ndarray, ...]
    regions: tuple[np.ndarray, ...]  # CCW vertex rings of the regions
    islands: tuple[np.ndarray, ...] = ()  # clockwise rings of the islands (cut ends inserted)
    block_regions: tuple[int, ...] = ()  # per block of the topology, the index of its region in ``regions``
    side_cells: Mapping[tuple[str, str], tuple[int, ...]] = field(
        default_factory=dict
    )  # (block, side) → its chains' cells


def _insert(poly: np.ndarray, k: int, t: float, closed: bool, eps: float) -> tuple[np.ndarray, np.ndarray]:
    """Insert the point at parameter ``t`` of segment ``k``; return (new poly, the point)."""
    n = len(poly)
    a = poly[k]
    b = poly[(k + 1) % n] if closed else poly[k + 1]
    p = a + t * (b - a)
    if np.hypot(*(p - a)) <= eps:
        return poly, a.copy()
    if np.hypot(*(p - b)) <= eps:
        return poly, b.copy()
    return np.insert(poly, k + 1, p, axis=0), p


def _resolve_cuts(given_ring: np.ndarray, cuts: Sequence[Any]) -> list[np.ndarray]:
    """The cut polylines as points (outline indices replaced by the outline's points)."""
    cut_list = []
    for k, c in enumerate(cuts):
        try:
            pts = [given_ring[int(v)] if isinstance(v, (int, np.integer)) else v for v in c]
        except (IndexError, TypeError):
            raise TopologyError(
                f"cut {k + 1}: points must be [x, y] pairs or outline point indices "
                f"(0 … {len(given_ring) - 1}), got {c!r}"
            ) from None
        cut_list.append(validate_points(pts, name=f"cut {k + 1}"))
    return cut_list


def _nearest_on_cuts(cut_list: list[np.ndarray], k: int, q: np.ndarray) -> tuple[float, int, int, float]:
    """(distance, cut, segment, t) of the point nearest to ``q`` on every cut but cut ``k`` (the
    first cut and segment at the least distance), as :func:`_project_on` per cut, in one pass."""
    others = [m for m in range(len(cut_list)) if m != k]
    if not others:
        return math.inf, -1, -1, 0.0
    a = np.vstack([cut_list[m][:-1] for m in others])
    b = np.vstack([cut_list[m][1:] for m in others])
    dist, t = feet(a, b, q)
    i = int(np.argmin(dist))
    starts = np.cumsum([0] + [len(cut_list[m]) - 1 for m in others])
    j = int(np.searchsorted(starts, i, side="right")) - 1
    return float(dist[i]), others[j], i - int(starts[j]), float(t[i])


def _nearest_ring(rings: list[np.ndarray], boxes: list, q: np.ndarray) -> tuple[tuple[float, int, float], str, int]:
    """``((distance, segment, t), "outline", ring)``: :func:`nearest_on_polyline` of ``q`` on the
    first ring at the least distance, as ``min`` over all of them; a ring whose bounding box
    (``boxes``) is farther than the best so far (by more than rounding) is not measured: none of
    its points can be nearer."""
    best: tuple[tuple[float, int, float], str, int] | None = None
    for ri, r in enumerate(rings):
        if best is not None:
            lo, hi = boxes[ri]
            gap = np.maximum(np.maximum(lo - q, q - hi), 0.0)
            if math.hypot(gap[0], gap[1]) > best[0][0] * (1.0 + 1e-9):
                continue
        got = nearest_on_polyline(r, q, True)
        if best is None or got[0] < best[0][0]:
            best = (got, "outline", ri)
    assert best is not None
    return best


def _snap_cut_ends(rings: list[np.ndarray], cut_list: list[np.ndarray], snap: float, eps: float) -> list[np.ndarray]:
    """Move every cut end onto the outline, an island or another cut, inserting the point there;
    returns the shore rings (outline first, then the islands)."""
    rings = list(rings)
    on_ring = [set(point_keys(r)) for r in rings]
    boxes = [(r.min(axis=0), r.max(axis=0)) for r in rings]
    for k in range(len(cut_list)):
        for end in (0, -1):
            q = cut_list[k][end]
            if any(point_key(q) in v for v in on_ring):
                continue  # a vertex of the shore already: it would snap onto itself
            best = _nearest_ring(rings, boxes, q)
            dist, m, seg, t = _nearest_on_cuts(cut_list, k, q)
            if dist < best[0][0]:
                best = ((dist, seg, t), "cut", m)
            (dist, seg, t), kind, m = best
            if dist > snap:
                raise TopologyError(
                    f"cut {k + 1}: its {'first' if end == 0 else 'last'} point ({q[0]:.6g}, {q[1]:.6g}) "
                    f"is {dist:.4g} from the shore and from every other cut (snap distance "
                    f"{snap:.4g}); cuts must end on the outline, an island or another cut"
                )
            if kind == "outline":
                rings[m], p = _insert(rings[m], seg, t, True, eps)
                on_ring[m].add(point_key(p))
                boxes[m] = (rings[m].min(axis=0), rings[m].max(axis=0))
            else:
                cut_list[m], p = _insert(cut_list[m], seg, t, False, eps)
            cut_list[k][end] = p
    return rings


def _check_cuts(rings: list[np.ndarray], cut_list: list[np.ndarray], snap: float) -> None:
    """Every cut runs inside the water and meets the shore only at its ends."""
    from shapely.geometry import LineString, MultiLineString, Polygon

    inside = Polygon(rings[0], rings[1:]).buffer(snap)
    shore = MultiLineString([np.vstack([r, r[:1]]) for r in rings])
    for k, c in enumerate(cut_list):
        ls = LineString(c)
        if not inside.contains(ls):
            bad = ls.difference(inside)
            pt = bad.representative_point() if not bad.is_empty else ls.representative_point()
            raise TopologyError(
                f"cut {k + 1} leaves the water near ({pt.x:.6g}, {pt.y:.6g}); cut lines must run "
                f"across the inside of the outline"
            )
        inner = LineString(c).intersection(shore)
        n_touch = len(getattr(inner, "geoms", [inner])) if not inner.is_empty else 0
        if n_touch > 2:
            raise TopologyError(f"cut {k + 1} touches the shore {n_touch} times; a cut may meet it only at its ends")


def _regions(rings: list[np.ndarray], cut_list: list[np.ndarray], size: float) -> list[Any]:
    """The faces (CCW polygons) into which the shore (outline and islands) and the cuts split the water."""
    import shapely
    from shapely.geometry import LineString, Polygon
    from shapely.geometry.polygon import orient

    lake = Polygon(rings[0], rings[1:])
    lines = shapely.union_all([LineString(np.vstack([r, r[:1]])) for r in rings] + [LineString(c) for c in cut_list])
    faces = [orient(f, 1.0) for f in shapely.polygonize(list(getattr(lines, "geoms", [lines]))).geoms]
    faces = [f for f in faces if f.area > 1e-12 * size * size]
    islands = [Polygon(r) for r in rings[1:]]
    faces = [f for f in faces if not any(i.contains(f.representative_point()) for i in islands)]
    area = sum(f.area for f in faces)
    if abs(area - lake.area) > 1e-6 * lake.area:
        raise TopologyError(
            f"the cuts do not split the lake cleanly: regions cover {area:.6g} of its area {lake.area:.6g}"
        )
    for f in faces:
        if f.interiors:
            c = f.interiors[0].coords[0]
            raise TopologyError(
                f"the region round ({c[0]:.6g}, {c[1]:.6g}) encloses an island or another region (a "
                f"closed cut loop); connect it with cuts to the shore on two sides"
            )
    return faces


def _neighbours(rings: list[np.ndarray]) -> dict:
    """Vertex → its neighbours in the line graph of outline and cuts."""
    nbrs: dict = defaultdict(set)
    for r in rings:
        kr = point_keys(r)
        for a, b in zip(kr, kr[1:] + kr[:1], strict=True):
            nbrs[a].add(b)
            nbrs[b].add(a)
    return nbrs


def _block_cells(s: BlockOutline) -> tuple[int, int]:
    """A block's ``(ni, nj)``, checked (after its corner count)."""
    if len(s.corners) != 4:
        raise TopologyError(f"block {s.name!r}: needs 4 corners (sw, se, ne, nw), got {len(s.corners)}")
    try:
        ni = validate_count(s.cells[0], name=f"block {s.name!r} cells ni")
        nj = validate_count(s.cells[1], name=f"block {s.name!r} cells nj")
    except (IndexError, TypeError):
        raise TopologyError(f"block {s.name!r}: cells must be [ni, nj], got {s.cells!r}") from None
    return ni, nj


def _block_corners(s: BlockOutline, given_ring: np.ndarray, vertices: np.ndarray, snap: float) -> list[tuple]:
    """The four corners of a block, snapped to outline/cut vertices."""
    given_n = len(given_ring)
    cs = []
    for lab, c in zip(("sw", "se", "ne", "nw"), s.corners, strict=True):
        if isinstance(c, (int, np.integer)):
            if not -given_n <= int(c) < given_n:
                raise TopologyError(
                    f"block {s.name!r}: corner {lab} index {c} is outside the outline (0 … {given_n - 1})"
                )
            q = given_ring[int(c)]
        else:
            q = validate_points([c], name=f"block {s.name!r} corner {lab}", min_points=1)[0]
        dist = np.hypot(*(vertices - q).T)
        k = int(np.argmin(dist))
        if dist[k] > snap:
            raise TopologyError(
                f"block {s.name!r}: corner {lab} ({q[0]:.6g}, {q[1]:.6g}) is {dist[k]:.4g} from "
                f"the nearest outline or cut vertex (snap distance {snap:.4g})"
            )
        cs.append(point_key(vertices[k]))
    if len(set(cs)) != 4:
        raise TopologyError(f"block {s.name!r}: two corners snap to the same point {cs}")
    return cs


def _vertex_faces(rings: list[np.ndarray]) -> dict[tuple, dict[int, int]]:
    """Vertex → {region: its position on the region's ring} (the last one where it repeats)."""
    where: dict[tuple, dict[int, int]] = {}
    for fi, r in enumerate(rings):
        for i, k in enumerate(point_keys(r)):
            where.setdefault(k, {})[fi] = i
    return where


def _block_face(s: BlockOutline, cs: list[tuple], rings: list[np.ndarray], where: dict) -> int:
    """The region whose boundary holds the four corners in counter-clockwise order
    (``where``: :func:`_vertex_faces` of ``rings``)."""
    cand = []
    for fi in sorted(set.intersection(*(set(where.get(c, ())) for c in cs))):
        idx = [where[c][fi] for c in cs]
        rel = [(i - idx[0]) % len(rings[fi]) for i in idx]
        cand.append((fi, rel[0] < rel[1] < rel[2] < rel[3]))
    if not cand:
        raise TopologyError(
            f"block {s.name!r}: its four corners do not lie on the boundary of one region "
            f"between the shore and the cuts (a block must be one region with exactly four "
            f"sides; check the corners and the cuts)"
        )
    ok = [fi for fi, good in cand if good]
    if not ok:
        raise TopologyError(f"block {s.name!r}: corners must be given counter-clockwise as sw, se, ne, nw")
    return ok[0]


def _place_blocks(
    specs: list[BlockOutline],
    given_ring: np.ndarray,
    rings: list,
    faces: list,
    vertices: np.ndarray,
    snap: float,
    size: float,
) -> tuple[dict[str, list[tuple]], dict[str, int]]:
    """Each block's corners and region; every region must be exactly one block."""
    names = [s.name for s in specs]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise TopologyError(f"block names must be unique; repeated: {', '.join(dup)}")
    face_of: dict[int, str] = {}
    where = _vertex_faces(rings)
    block_corners: dict[str, list[tuple]] = {}
    block_face: dict[str, int] = {}
    total_nodes = 0
    for s in specs:
        ni, nj = _block_cells(s)
        total_nodes += (ni + 1) * (nj + 1)
        check_allocation(
            total_nodes, max_nodes(), what=f"nodes of the blocks up to {s.name!r}", env="MESHCORE_MAX_NODES"
        )
        cs = _block_corners(s, given_ring, vertices, snap)
        fi = _block_face(s, cs, rings, where)
        if fi in face_of:
            raise TopologyError(f"blocks {face_of[fi]!r} and {s.name!r} overlap: both are the same region")
        face_of[fi] = s.name
        block_face[s.name] = fi
        block_corners[s.name] = cs
    for fi, f in enumerate(faces):
        if fi not in face_of:
            c = f.representative_point()
            around = sorted({face_of[g] for g in face_of if faces[g].distance(f) <= 1e-9 * size})
            raise TopologyError(
                f"gap: the region near ({c.x:.6g}, {c.y:.6g}) (area {f.area:.4g}, next to "
                f"{', '.join(repr(a) for a in around) or 'no block'}) is covered by no block; "
                f"add a block with its four corners there"
            )
    return block_corners, block_face


def _islands(holes: Sequence[Any], lake: Any) -> list[np.ndarray]:
    """The island rings, clockwise (as holes), each checked to be a simple ring inside the lake."""
    from shapely.geometry import Polygon

    out: list[np.ndarray] = []
    for k, h in enumerate(holes):
        r = validate_points(h, name=f"island {k}", min_points=3)
        if np.hypot(*(r[0] - r[-1])) <= 1e-12 * float(np.ptp(r, axis=0).max()):
            r = r[:-1]
        isl = Polygon(r)
        if not isl.is_valid or isl.area <= 0:
            raise TopologyError(f"island {k} is not a simple ring with an area")
        if not lake.contains(isl):
            c = isl.representative_point()
            raise TopologyError(f"island {k} (near ({c.x:.6g}, {c.y:.6g})) is not inside the outline")
        for j, other in enumerate(out):
            if isl.intersects(Polygon(other)):
                raise TopologyError(f"islands {j} and {k} overlap or touch")
        out.append(r[::-1].copy() if signed_area(r) > 0 else r)
    return out


def from_outline(
    outline: Any,
    *,
    cuts: Sequence[Any],
    blocks: Sequence[Any],
    holes: Sequence[Any] = (),
    snap: float | None = None,
    multiple: int = 1,
    cell_size: float | None = None,
    keep_cells: Mapping[tuple[str, str], Sequence[int]] | None = None,
    single: bool = False,
) -> OutlineBlocks:
    """Split a closed outline by cut lines into four-sided blocks glued by interfaces.

    Parameters
    ----------
    outline : (n, 2) array_like
        Closed shoreline (first point not repeated, or repeated; either orientation).
    cuts : sequence of (k, 2) array_like
        Polylines across the water; each end on the outline or on another cut.
    holes : sequence of (k, 2) array_like
        Islands: closed rings inside the outline.  Cuts may end on them; every
        region must be simply connected (an island needs cuts to the shore).
    blocks : sequence of BlockOutline or mappings
        ``{"name", "corners": [sw, se, ne, nw], "cells": [ni, nj]}``; a corner is
        an ``[x, y]`` point (snapped to the nearest outline/cut vertex) or an
        integer index of an outline point.
    multiple : int
        Every chain gets a multiple of this many cells (all block cells must be
        multiples of it): ``2**k`` lets the multigrid coarsen the blocks ``k``
        times.
    cell_size : float, optional
        Where a block side has several parts (a T-junction), its cells are shared among
        them closest to ``length / cell_size`` (default: that side's own cell size).
    snap : float, optional
        Distance within which cut ends and corners are snapped
        (default ``1e-3 ×`` the outline's bounding-box diagonal).
    keep_cells : mapping, optional
        The ``side_cells`` of an earlier result (the layout before a cut end was dragged):
        where a block side has several parts, their cells are kept while they still fit,
        without the integer program that shares them (a drag's steps are quicker).  The
        program's shares can differ: a layout to keep is made without ``keep_cells``.
    single : bool
        The cells of a side's parts also close every ring of blocks in one ``(I, J)`` index
        space (:mod:`.closure`): a single-domain grid's (Delft3D ``.grd``, EFDC).

    Returns
    -------
    OutlineBlocks
        ``.topology`` is a validated :class:`MultiBlockTopology`.

    Raises
    ------
    TopologyError
        One message per malformed case, naming the blocks, borders or cuts.
    """
    import shapely
    from shapely.geometry import Polygon

    from .chains import chain_topology

    ring = validate_points(outline, name="outline", min_points=3)
    size = float(math.hypot(*(ring.max(axis=0) - ring.min(axis=0))))
    if np.hypot(*(ring[0] - ring[-1])) <= 1e-12 * size:
        ring = ring[:-1]
    given_ring = ring.copy()
    if signed_area(ring) <= 0:
        ring = ring[::-1].copy()
    snap = 1e-3 * size if snap is None else float(snap)
    lake = Polygon(ring)
    if not lake.is_valid:
        raise TopologyError(f"the outline crosses itself ({shapely.is_valid_reason(lake)})")
    islands = _islands(holes, lake)
    cut_list = _resolve_cuts(given_ring, cuts)
    ring, *islands = _snap_cut_ends([ring, *islands], cut_list, snap, 1e-12 * size)
    _check_cuts([ring, *islands], cut_list, snap)
    faces = _regions([ring, *islands], cut_list, size)
    rings = [np.asarray(f.exterior.coords)[:-1] for f in faces]
    nbrs = _neighbours(rings)
    specs = [BlockOutline.coerce(b) for b in blocks]
    block_corners, block_face = _place_blocks(specs, given_ring, rings, faces, np.array(list(nbrs)), snap, size)
    multiple = validate_count(multiple, name="multiple")
    for s in specs:
        if s.cells[0] % multiple or s.cells[1] % multiple:
            raise TopologyError(
                f"block {s.name!r}: cells {list(s.cells)} must be multiples of {multiple} (multiple = {multiple})"
            )
    breaks = {c for cs in block_corners.values() for c in cs} | {v for v, nb in nbrs.items() if len(nb) >= 3}
    sides = {s.name: rings[block_face[s.name]] for s in specs}
    # with islands the blocks leave holes by design; the regions were checked above (they are the
    # water exactly, each is one block)
    topo, side_cells = chain_topology(
        specs,
        sides,
        block_corners,
        breaks,
        multiple,
        check_geometry=not islands,
        cell_size=cell_size,
        keep=keep_cells,
        single=single,
    )
    return OutlineBlocks(
        topology=topo,
        outline=ring,
        cuts=tuple(cut_list),
        regions=tuple(rings),
        islands=tuple(islands),
        block_regions=tuple(block_face[s.name] for s in specs),
        side_cells=side_cells,
    )
