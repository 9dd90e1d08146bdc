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
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._validation import check_allocation, max_nodes, validate_count, validate_points
from ..boundary import Borders, signed_area
from ..errors import InvalidInputError, TopologyError
from .topology import Block, Interface, MultiBlockTopology, Side

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


def _project_on(poly: np.ndarray, q: np.ndarray, closed: bool) -> tuple[float, int, float]:
    """(distance, segment index, parameter t) of the point of ``poly`` nearest to ``q``."""
    a = poly
    b = np.roll(poly, -1, axis=0) if closed else poly[1:]
    a = a if closed else poly[:-1]
    d = b - a
    L2 = (d * d).sum(axis=1)
    t = np.where(L2 > 0, ((q - a) * d).sum(axis=1) / np.where(L2 > 0, L2, 1.0), 0.0)
    t = np.clip(t, 0.0, 1.0)
    foot = a + t[:, None] * d
    dist = np.hypot(*(foot - q).T)
    k = int(np.argmin(dist))
    return float(dist[k]), k, float(t[k])


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


def _resample(chain: np.ndarray, n_cells: int) -> np.ndarray:
    s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(chain, axis=0).T))])
    u = np.linspace(0.0, s[-1], n_cells + 1)
    out = np.column_stack([np.interp(u, s, chain[:, 0]), np.interp(u, s, chain[:, 1])])
    out[0], out[-1] = chain[0], chain[-1]
    return out


def _key(p: np.ndarray) -> tuple[float, float]:
    return (float(p[0]), float(p[1]))


def from_outline(
    outline: Any,
    *,
    cuts: Sequence[Any],
    blocks: Sequence[Any],
    snap: float | None = None,
    multiple: int = 1,
) -> OutlineBlocks:
    """Split a closed outline by cut lines into four-sided blocks glued by interfaces.

    Parameters
    ----------
    outline : (n, 2) array_like
        Closed shoreline (first point not repeated, or repeated; either orientation).
    cuts : sequence of (k, 2) array_like
        Polylines across the water; each end on the outline or on another cut.
    blocks : sequence of BlockOutline or mappings
        ``{"name", "corners": [sw, se, ne, nw], "cells": [ni, nj]}``; a corner is
        an ``[x, y]`` point (snapped to the nearest outline/cut vertex) or an
        integer index of an outline point.
    multiple : int
        Every chain gets a multiple of this many cells (all block cells must be
        multiples of it): ``2**k`` lets the multigrid coarsen the blocks ``k``
        times.
    snap : float, optional
        Distance within which cut ends and corners are snapped
        (default ``1e-3 ×`` the outline's bounding-box diagonal).

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
    from shapely.geometry import LineString, Polygon
    from shapely.geometry.polygon import orient

    ring = validate_points(outline, name="outline", min_points=3)
    size0 = float(math.hypot(*(ring.max(axis=0) - ring.min(axis=0))))
    if np.hypot(*(ring[0] - ring[-1])) <= 1e-12 * size0:
        ring = ring[:-1]
    given_ring = ring.copy()
    ccw = signed_area(ring) > 0
    if not ccw:
        ring = ring[::-1].copy()
    size = size0
    snap = 1e-3 * size if snap is None else float(snap)
    eps = 1e-12 * size
    lake = Polygon(ring)
    if not lake.is_valid:
        raise TopologyError(f"the outline crosses itself ({shapely.is_valid_reason(lake)})")
    cut_list = []
    for k, c in enumerate(cuts):
        try:
            pts = [given_ring[int(v)] if isinstance(v, (int, np.integer)) else v for v in c]
        except (IndexError, TypeError):
            raise TopologyError(
                f"cut {k}: points must be [x, y] pairs or outline point indices (0 … {len(given_ring) - 1}), got {c!r}"
            ) from None
        cut_list.append(validate_points(pts, name=f"cut {k}"))
    if not cut_list:
        raise TopologyError("from_outline needs at least one cut line (one block needs no multiblock)")
    # --- snap the cut ends onto the outline or onto other cuts (inserting vertices there)
    for k in range(len(cut_list)):
        for end in (0, -1):
            q = cut_list[k][end]
            best = (_project_on(ring, q, True), "outline", -1)
            for m, other in enumerate(cut_list):
                if m == k:
                    continue
                cand = _project_on(other, q, False)
                if cand[0] < best[0][0]:
                    best = (cand, "cut", m)
            (dist, seg, t), kind, m = best
            if dist > snap:
                raise TopologyError(
                    f"cut {k}: its {'first' if end == 0 else 'last'} point ({q[0]:.6g}, {q[1]:.6g}) "
                    f"is {dist:.4g} from the outline and from every other cut (snap distance "
                    f"{snap:.4g}); cuts must end on the outline or on another cut"
                )
            if kind == "outline":
                ring, p = _insert(ring, seg, t, True, eps)
            else:
                cut_list[m], p = _insert(cut_list[m], seg, t, False, eps)
            cut_list[k][end] = p
    lake = Polygon(ring)
    inside = lake.buffer(snap)
    for k, c in enumerate(cut_list):
        ls = LineString(c)
        if not inside.contains(ls):
            bad = ls.difference(inside)
            pt = bad.representative_point() if not bad.is_empty else ls.representative_point()
            raise TopologyError(
                f"cut {k} leaves the water near ({pt.x:.6g}, {pt.y:.6g}); cut lines must run "
                f"across the inside of the outline"
            )
        inner = LineString(c).intersection(LineString(np.vstack([ring, ring[:1]])))
        n_touch = len(getattr(inner, "geoms", [inner])) if not inner.is_empty else 0
        if n_touch > 2:
            raise TopologyError(f"cut {k} touches the outline {n_touch} times; a cut may meet it only at its ends")
    # --- regions
    lines = shapely.union_all([LineString(np.vstack([ring, ring[:1]])), *(LineString(c) for c in cut_list)])
    faces = [orient(f, 1.0) for f in shapely.polygonize(list(getattr(lines, "geoms", [lines]))).geoms]
    faces = [f for f in faces if f.area > 1e-12 * size * size]
    area = sum(f.area for f in faces)
    if abs(area - lake.area) > 1e-6 * lake.area:
        raise TopologyError(
            f"the cuts do not split the lake cleanly: regions cover {area:.6g} of its area {lake.area:.6g}"
        )
    for f in faces:
        if f.interiors:
            c = f.representative_point()
            raise TopologyError(
                f"the region near ({c.x:.6g}, {c.y:.6g}) encloses another region (a closed cut "
                f"loop); connect it with a cut to the outline"
            )
    rings = [np.asarray(f.exterior.coords)[:-1] for f in faces]
    # directed segment → region; vertex degree in the line graph
    seg_face: dict = {}
    nbrs: dict = defaultdict(set)
    for fi, r in enumerate(rings):
        for a, b in zip(r, np.roll(r, -1, axis=0), strict=True):
            seg_face[(_key(a), _key(b))] = fi
            nbrs[_key(a)].add(_key(b))
            nbrs[_key(b)].add(_key(a))
    vertices = np.array(list(nbrs))
    # --- blocks on regions
    specs = [BlockOutline.coerce(b) for b in blocks]
    names = [s.name for s in specs]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise TopologyError(f"block names must be unique; repeated: {', '.join(dup)}")
    given_n = len(given_ring)
    face_of: dict[int, str] = {}
    block_corners: dict[str, list[tuple[float, float]]] = {}
    block_face: dict[str, int] = {}
    corner_set: set = set()
    total_nodes = 0
    for s in specs:
        if len(s.corners) != 4:
            raise TopologyError(f"block {s.name!r}: needs 4 corners (sw, se, ne, nw), got {len(s.corners)}")
        try:
            ni = validate_count(s.cells[0], name=f"block {s.name!r} cells ni")
            nj = validate_count(s.cells[1], name=f"block {s.name!r} cells nj")
        except (IndexError, TypeError):
            raise TopologyError(f"block {s.name!r}: cells must be [ni, nj], got {s.cells!r}") from None
        total_nodes += (ni + 1) * (nj + 1)
        check_allocation(
            total_nodes, max_nodes(), what=f"nodes of the blocks up to {s.name!r}", env="MESHCORE_MAX_NODES"
        )
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
            cs.append(_key(vertices[k]))
        if len(set(cs)) != 4:
            raise TopologyError(f"block {s.name!r}: two corners snap to the same point {cs}")
        cand = []
        for fi, r in enumerate(rings):
            pos = {_key(p): i for i, p in enumerate(r)}
            if all(c in pos for c in cs):
                idx = [pos[c] for c in cs]
                rel = [(i - idx[0]) % len(r) for i in idx]
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
        fi = ok[0]
        if fi in face_of:
            raise TopologyError(f"blocks {face_of[fi]!r} and {s.name!r} overlap: both are the same region")
        face_of[fi] = s.name
        block_face[s.name] = fi
        block_corners[s.name] = cs
        corner_set.update(cs)
    for fi, f in enumerate(faces):
        if fi not in face_of:
            c = f.representative_point()
            around = sorted({face_of[g] for g in face_of if faces[g].distance(f) <= 1e-9 * size})
            raise TopologyError(
                f"gap: the region near ({c.x:.6g}, {c.y:.6g}) (area {f.area:.4g}, next to "
                f"{', '.join(repr(a) for a in around) or 'no block'}) is covered by no block; "
                f"add a block with its four corners there"
            )
    multiple = validate_count(multiple, name="multiple")
    for s in specs:
        if s.cells[0] % multiple or s.cells[1] % multiple:
            raise TopologyError(
                f"block {s.name!r}: cells {list(s.cells)} must be multiples of {multiple} (multiple = {multiple})"
            )
    # --- sides → chains
    breaks = set(corner_set) | {v for v, nb in nbrs.items() if len(nb) >= 3}
    side_chains: dict[tuple[str, str], list[tuple]] = {}  # (block, side) → [chain keys]
    chain_pts: dict[tuple, np.ndarray] = {}
    chain_users: dict[tuple, list[tuple[str, str]]] = defaultdict(list)
    for s in specs:
        r = rings[block_face[s.name]]
        n = len(r)
        pos = {_key(p): i for i, p in enumerate(r)}
        ci = [pos[c] for c in block_corners[s.name]]
        for side, (a, b) in zip(("bottom", "right", "top", "left"), zip(ci, ci[1:] + ci[:1], strict=True), strict=True):
            walk = [r[(a + k) % n] for k in range((b - a) % n + 1)]
            chains, cur = [], [walk[0]]
            for p in walk[1:]:
                cur.append(p)
                if _key(p) in breaks:
                    chains.append(np.array(cur))
                    cur = [p]
            keys = []
            for ch in chains:
                fwd = tuple(_key(p) for p in ch)
                key = min(fwd, fwd[::-1])
                chain_pts.setdefault(key, np.array(key))
                keys.append(key)
                chain_users[key].append((s.name, side))
            side_chains[(s.name, side)] = keys
    # --- cell counts per chain
    spec_of = {s.name: s for s in specs}
    need = {
        (s.name, side): int(s.cells[0] if side in ("bottom", "top") else s.cells[1])
        for s in specs
        for side in ("bottom", "right", "top", "left")
    }
    count: dict[tuple, int] = {}

    def arclen(key: tuple) -> float:
        p = chain_pts[key]
        return float(np.hypot(*np.diff(p, axis=0).T).sum())

    def describe(bs: tuple[str, str]) -> str:
        parts = []
        for key in side_chains[bs]:
            other = [u for u in chain_users[key] if u != bs]
            who = f"shared with {other[0][0]}.{other[0][1]}" if other else "shore"
            parts.append(f"{count.get(key, '?')} ({who})")
        return " + ".join(parts)

    changed = True
    while True:
        while changed:
            changed = False
            for bs, keys in side_chains.items():
                unknown = [k for k in keys if k not in count]
                if len(unknown) == 1:
                    rest = need[bs] - sum(count[k] for k in keys if k in count)
                    if rest < 1:
                        raise TopologyError(
                            f"cell counts disagree at block {bs[0]!r} {bs[1]} border: it has "
                            f"{need[bs]} cells but its parts already need {describe(bs)}"
                        )
                    count[unknown[0]] = rest
                    changed = True
        open_sides = [(bs, keys) for bs, keys in side_chains.items() if any(k not in count for k in keys)]
        if not open_sides:
            break
        bs, keys = open_sides[0]
        unknown = [k for k in keys if k not in count]
        rest = need[bs] - sum(count[k] for k in keys if k in count)
        if rest < len(unknown) * multiple:
            raise TopologyError(
                f"cell counts disagree at block {bs[0]!r} {bs[1]} border: {need[bs]} cells cannot "
                f"hold its parts {describe(bs)} with at least {multiple} cell(s) each"
            )
        units = rest // multiple  # shares in units of `multiple` cells
        w = np.array([arclen(k) for k in unknown])
        share = 1 + (units - len(unknown)) * w / w.sum()
        base = np.floor(share).astype(int)
        for k in np.argsort(-(share - base))[: units - int(base.sum())]:
            base[k] += 1
        for k, c in zip(unknown, base.tolist(), strict=True):
            count[k] = int(c) * multiple
        changed = True
    for bs, keys in side_chains.items():
        if sum(count[k] for k in keys) != need[bs]:
            raise TopologyError(
                f"cell counts disagree across an interface: block {bs[0]!r} {bs[1]} border needs "
                f"{need[bs]} cells but its parts have {describe(bs)} = "
                f"{sum(count[k] for k in keys)}; change the cells of {bs[0]!r} or of its neighbours"
            )
    # --- re-sample chains, build blocks and interfaces
    nodes = {key: _resample(chain_pts[key], count[key]) for key in chain_pts}
    blocks_out = []
    offsets: dict[tuple[str, str, tuple], tuple[int, int]] = {}
    for s in specs:
        sides = {}
        for side in ("bottom", "right", "top", "left"):
            pieces = []
            at = 0
            for key in side_chains[(s.name, side)]:
                p = nodes[key]
                if pieces:
                    prev_end = pieces[-1][-1]
                    if not np.array_equal(p[0], prev_end):
                        p = p[::-1]
                else:
                    start = block_corners[s.name][("bottom", "right", "top", "left").index(side)]
                    if _key(p[0]) != start:
                        p = p[::-1]
                offsets[(s.name, side, key)] = (at, at + len(p) - 1)
                at += len(p) - 1
                pieces.append(p)
            walk = np.vstack([pieces[0]] + [q[1:] for q in pieces[1:]])
            sides[side] = walk
        # walked CCW: bottom sw→se, right se→ne, top ne→nw, left nw→sw
        top = sides["top"][::-1].copy()
        left = sides["left"][::-1].copy()
        ntop, nleft = len(top) - 1, len(left) - 1
        for key in side_chains[(s.name, "top")]:
            a, b = offsets[(s.name, "top", key)]
            offsets[(s.name, "top", key)] = (ntop - b, ntop - a)
        for key in side_chains[(s.name, "left")]:
            a, b = offsets[(s.name, "left", key)]
            offsets[(s.name, "left", key)] = (nleft - b, nleft - a)
        bd = Borders(bottom=sides["bottom"], right=sides["right"], top=top, left=left)
        blocks_out.append(Block(s.name, bd, initial=spec_of[s.name].initial))
    interfaces = []
    for key, users in chain_users.items():
        if len(users) == 2:
            (ba, sa), (bb, sb) = users
            a0, a1 = offsets[(ba, sa, key)]
            b0, b1 = offsets[(bb, sb, key)]
            interfaces.append(Interface(Side(ba, sa, a0, a1), Side(bb, sb, b0, b1), None))
    topo = MultiBlockTopology(tuple(blocks_out), tuple(interfaces))
    return OutlineBlocks(
        topology=topo,
        outline=ring,
        cuts=tuple(cut_list),
        regions=tuple(rings),
    )
