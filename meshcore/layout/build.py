r"""The layout pipeline: a water polygon and a cell size in, four-cornered pieces out.

1. :func:`~.skeleton.skeleton` — the pruned medial axis: arms, junctions, rings round islands;
2. :func:`~.chords.place_chords` — cuts across the arms at right angles to the banks;
3. :func:`~.regions.partition` — the regions between shore and cuts (islands cut free);
4. :func:`~.split.best_split` — regions that are not four-sided are split at their reflex
   corners (T, L, X shapes) or by a star from their junction (Y shapes);
5. :func:`~.corners.choose_corners` — four corners per piece;
6. :func:`~.blocks.conform` — every vertex inserted into the rings it lies on, so neighbours
   share their common edges vertex for vertex (T-junctions explicit).

Every length is relative to the cell size ``h`` (sampling ``h/2``, shortest cut ``2h``,
narrowest piece ``3h``, corners read at the scale ``1.5h``) or to the local channel width;
nothing depends on the units or on a particular lake.
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from ..pointindex import PointIndex
from ..segments import SegmentIndex
from . import pinch
from .blocks import Piece, conform, weld
from .chords import Chord, place_chords
from .corners import wedge_corners
from .fans import bulges as bulging
from .fans import fans, noted_unsplit, unfan, wraps
from .fans import tapers as tapering
from .frames import _vertices, close_frames, corner_flaws, frame_defects, straight_corners
from .memo import copied, digest, remembered
from .regions import partition
from .ringcuts import ring_cuts
from .skeleton import Skeleton, skeleton
from .split import _GOOD, LOOKAHEAD, best_split, corners_of, forced_indices, region_cost
from .stopping import check
from .tee import tee
from .tipcuts import noted_pinch, noted_tips, tips_split, untipped

__all__ = ["layout_pieces"]


def _densify(line: np.ndarray, step: float) -> np.ndarray:
    import shapely

    return np.asarray(shapely.segmentize(shapely.LineString(line), step).coords)


def _insert_mid(r: np.ndarray) -> np.ndarray:
    """Insert the midpoint of the longest edge (a triangle gets a fourth vertex)."""
    L = np.hypot(*(np.roll(r, -1, axis=0) - r).T)
    k = int(np.argmax(L))
    return np.insert(r, k + 1, 0.5 * (r[k] + r[(k + 1) % len(r)]), axis=0)


def _merged(a: np.ndarray, b: np.ndarray):
    """The ring of ``a ∪ b`` when they share one contiguous run of edges, else None."""
    na, nb = len(a), len(b)
    ix = PointIndex([a, b])
    ida, idb = ix.ids
    pos_b = np.full(len(ix), -1)
    pos_b[idb] = np.arange(nb)  # a point repeated in b: its last position
    pa = pos_b[ida]
    pn = np.roll(pa, -1)
    shared = np.flatnonzero((pa >= 0) & (pn >= 0) & ((pa - pn) % nb == 1)).tolist()
    if not shared or len(shared) >= na - 1:
        return None
    # the shared run in a: edges i, i+1, …, j (cyclic, contiguous)
    s = set(shared)
    start = next(i for i in shared if (i - 1) % na not in s)
    run = [start]
    while (run[-1] + 1) % na in s:
        run.append((run[-1] + 1) % na)
    if len(run) != len(shared):
        return None  # two separate contacts: the union would have a hole
    p0, pk = start, (run[-1] + 1) % na  # a[p0] … a[pk] is the shared path
    j0, jk = int(pa[p0]), int(pa[pk])
    out = np.vstack(
        [a[(pk + np.arange((p0 - pk) % na + 1)) % na], b[(j0 + np.arange(1, (jk - j0) % nb)) % nb]]
    )  # a from pk round to p0, then b from p0 round to pk
    from shapely.geometry import Polygon

    return out if len(out) >= 4 and Polygon(out).is_valid else None


def _merge_strips(rings: list[np.ndarray], forced: list[tuple], sigma: float, keep=None):
    """Join neighbouring pieces whose union is a good four-sided block and no worse than the
    two (a straight or gently curved arm cut by chords becomes one block again); ``keep``: a
    function of a point that says whether two pieces that share it stay apart (a cut end on an
    island, in the fallback for one index space: joined, the ring of blocks round the island
    loses the cut end :mod:`.ringcuts` made for it)."""
    rings, forced = list(rings), list(forced)

    def kept(i: int, j: int) -> bool:
        return keep is not None and any(
            keep(p) for p in {*map(tuple, rings[i].tolist())} & {*map(tuple, rings[j].tolist())}
        )

    cost = [region_cost(r, sigma) for r in rings]  # (most costed by the splits already)
    box = [np.r_[r.min(axis=0), r.max(axis=0)] for r in rings]
    seen: dict[tuple[int, int], tuple] = {}  # (id a, id b) → (a, b, union, its cost): each pair once

    def union(i: int, j: int):
        k = (id(rings[i]), id(rings[j]))
        if k not in seen:
            m = _merged(rings[i], rings[j])
            seen[k] = (rings[i], rings[j], m, None if m is None else region_cost(m, sigma))
        return seen[k][2:]

    changed = True
    while changed:
        changed = False
        boxes = np.array(box)
        for i in range(len(rings)):
            # the pieces after i whose boxes meet i's (the others are apart: no shared edge),
            # in one test per i: a test per pair made the restarts after each merge quadratic
            lo, hi = boxes[i + 1 :, :2], boxes[i + 1 :, 2:]
            meets = ~((boxes[i, :2] > hi).any(axis=1) | (lo > boxes[i, 2:]).any(axis=1))
            for j in (i + 1 + np.flatnonzero(meets)).tolist():
                if forced[i] or forced[j] or kept(i, j):
                    continue
                m, c = union(i, j)
                if m is None:
                    continue
                if c <= min(cost[i] + cost[j], _GOOD) + 1e-9:
                    rings[i], cost[i], box[i] = m, c, np.r_[m.min(axis=0), m.max(axis=0)]
                    del rings[j], cost[j], forced[j], box[j]
                    changed = True
                    break
            if changed:
                break
    return rings, forced


def layout_pieces(
    poly,
    h: float,
    *,
    regular: bool = False,
    normal: bool = True,
    thin: bool = False,
    mouths: bool = False,
    wedges: bool = False,
    tees: bool = False,
    bulges: bool = False,
    tapers: bool = False,
    single: bool = False,
    ring: bool = False,
    lookahead: bool = False,
) -> tuple[Skeleton, list[Chord], list[np.ndarray], list[Piece]]:
    """Skeleton, chords, all cut lines and the conforming pieces of ``poly`` for cell size ``h``
    (``regular``: only nodes where four blocks meet; ``normal``: splits may cut along the shore's
    normal; ``thin``: cuts from reflex corners may leave pieces two cells across; ``mouths``:
    junction chords at the arms' mouths, :func:`~.chords.place_chords`; see
    :func:`~.split.best_split`; ``wedges``: a block ending in a wedge's tip has two corners either
    side of it, :func:`~.corners.wedge_corners`; ``tees``: junctions of regular layouts may be split
    as a T, :mod:`.tee`; ``bulges``: regular layouts split pieces that bulge, :func:`~.fans.bulges`;
    ``tapers``: default layouts split pieces that taper, :func:`~.fans.tapers`;
    ``single``: with ``regular``, every island's ring of blocks turns once,
    :data:`~.frames.ONE_TURN`, so that it can close in one index space; ``ring``: every island gets
    at least four cut ends, :func:`~.ringcuts.ring_cuts`, without which its ring cannot turn once;
    ``lookahead``: each region's first split looks ahead, :data:`~.split.LOOKAHEAD`)."""
    import shapely
    from shapely.geometry import Polygon

    sk, chords = _skeleton_and_chords(poly, h, mouths)
    check()
    dense = shapely.segmentize(poly, h)
    sigma = 1.5 * h
    junctions = sk.nodes[sk.degree() >= 3]
    # thin pieces only in regions that no island bounds (:data:`~.width.THIN_CUT`)
    islands = shapely.union_all([shapely.LinearRing(r.coords) for r in dense.interiors]) if thin else None
    size = math.hypot(*np.subtract(*np.reshape(poly.bounds, (2, 2))[::-1]))
    holes = shapely.union_all([shapely.LinearRing(r.coords) for r in dense.interiors])

    def on_island(p) -> bool:
        return bool(shapely.dwithin(holes, shapely.Point(p), 1e-9 * size))

    # the water's turning along the shore: cuts passing land tips or grazing the land (.pinch)
    pinching = pinch.PINCH and not regular
    water = pinch.Water(dense, h) if pinching or (regular and pinch.NECK) else None

    def made(lines: list[np.ndarray]) -> tuple[list[Piece], list]:
        regions, cuts = _partition(dense, lines, sigma)
        rings: list[np.ndarray] = []
        forced: list[tuple] = []
        for r in regions:
            check()  # (a region's split: up to a tenth of a second on Vänern)
            P = Polygon(r)
            here = thin and (islands is None or islands.is_empty or P.exterior.distance(islands) > 1e-6 * h)
            pieces, new_cuts = _split_region(
                r,
                junctions,
                sigma,
                3 * h,
                regular=regular,
                normal=normal,
                thin=here,
                tees=tees and regular,
                bulges=bulges and regular,
                tapers=tapers and not regular,
                look=LOOKAHEAD if lookahead else 1,
            )
            if tips_split() and not regular:  # (a candidate of the layout choice, .tipcuts)
                pieces, new_cuts = untipped(pieces, new_cuts, sigma, 3 * h, normal, here)
            elif not regular:  # would the tip draw split any of these? (.tipcuts.watching_tips)
                noted_tips(pieces, sigma, 3 * h, normal, here)
            rings += [p for p, _ in pieces]
            forced += [f for _, f in pieces]
            cuts += new_cuts
        check()
        rings, forced = _welded(rings, forced, 1e-9 * size)
        if pinching and water is not None:  # (the tip draw: cuts passing close by land tips bent through them)
            if tips_split():
                rings, forced = pinch.pinched(rings, forced, water, sigma, 3 * h)
            elif pinch.pinch_candidates(rings, forced, water, sigma, 3 * h):
                noted_pinch()
        rings = [r if len(r) >= 4 else _insert_mid(_insert_mid(r) if len(r) < 3 else r) for r in rings]
        rings, forced = _merge_strips(rings, forced, sigma, keep=on_island if ring else None)
        corner_pts = []
        rim = SegmentIndex([np.asarray(r.coords)[:-1] for r in (dense.exterior, *dense.interiors)])
        for r, f in zip(rings, forced, strict=True):
            fi = forced_indices(r, f)
            c, _ = corners_of(r, sigma, fi)
            on_shore = rim.near(r, 1e-9 * size)
            w = wedge_corners(r, c, sigma, shore=on_shore, forced=fi) if wedges and c is not None else c
            if w is not None and tuple(w) != tuple(c):
                c = w
            elif c is not None:  # (regular layouts: no T-junction, only onto a vertex that turns)
                c = _flat_corner_on_cut(r, c, on_shore, fi, sigma / 1.5, onto_cut=not regular)
            corner_pts.append([r[i] for i in c])
        check()
        rings = conform(rings, 1e-9 * size)
        pieces = []
        for r, cs in zip(rings, corner_pts, strict=True):
            idx = tuple(sorted(int(np.argmin(np.hypot(*(r - c).T))) for c in cs))
            pieces.append(Piece(r, idx))
        return pieces, cuts

    lines = [c.points for c in chords]
    if regular and water is not None:  # chords grazing the land (default layouts: .pinch.pinched in the tip draw)
        split = pinch.necked_lines(lines, water, h, 2 * h)
        if len(split) != len(lines):
            if tips_split():  # (the layout choice's tip draw)
                lines = split
            else:
                noted_pinch()
    lines = [_densify(c, h) for c in lines]
    pieces, cuts = made(lines)
    for _ in range(RING_ROUNDS if ring else 0):  # islands with fewer than four cut ends: more cuts
        v = _vertices(pieces)
        more = ring_cuts(dense, cuts, sigma, ends=v.index.points[(v.loop > 0) & (v.m >= 2)])
        if not more:
            break
        lines = lines + more
        pieces, cuts = made(lines)
    check()
    _check_pieces(poly, pieces)
    if regular:  # every island's ring of blocks closes up (Delft3D's domain decomposition)
        pieces, cuts = _closed(pieces, cuts, h, size, sigma, single, ring)
    else:
        pieces, cuts = _make_countable(pieces, cuts, h, size)
    pieces = [Piece(p.ring, p.corners, f"b{k}") for k, p in enumerate(pieces)]
    return sk, chords, cuts, pieces


#: A block corner whose shore vertices turn by less than this (degrees, between their two edges)
#: is on a straight edge of the outline: the block's corner cell there has an angle of 180° up to
#: rounding (:func:`_flat_corner_on_cut`).
FLAT_TURN = 0.01

#: How far (cells, along the shore either side, up to the piece's next corner) a vertex that
#: turns may take a flat corner's place (:data:`CONVEX_TURN`).
REACH = 1.0

#: A shore vertex within :data:`REACH` cells of a flat corner that turns by at least this
#: (degrees, towards the water) takes the corner instead: the blunt end of an arm drawn with two
#: vertices, whose smoothed turning peaks between them (the corner was put on the straight edge
#: in between, a cell of 180°; on the vertex the cell has the end's own angle).
CONVEX_TURN = 20.0


def _flat_corner_on_cut(r: np.ndarray, c, on_shore: np.ndarray, forced, h: float, *, onto_cut: bool = True) -> tuple:
    """The corners ``c`` of piece ``r`` with a corner on a straight shore moved off it.

    A piece with three sharp corners (the pointed end of an arm beyond its tip chord, a triangular
    lake's corner zone) gets its fourth from :func:`~.corners.choose_corners` where a side turns
    most; on a straight shore that is nowhere: the corner turns by 0°, its corner cell is a
    triangle with a 180° angle and a corner Jacobian that is zero up to rounding (the same grid
    read as fold-free in local coordinates and as folded in UTM ones): whatever the shore does a
    cell further on, the grid's first nodes along the two sides lie on the straight edge unless
    the block's cells are longer than the edge's halves.  A shore vertex within a cell that turns
    by :data:`CONVEX_TURN` or more takes the corner (the most turning one).  Else the corner goes
    onto a cut, where it costs nothing: the block beyond passes it (a T-junction) and the solve,
    which moves interface nodes, opens the corner there (about 120° for each of the three cells).
    The new corner is the cut vertex nearest the middle of the piece's longest run of cut
    vertices (by arc length); ``c`` unchanged when no corner or more than one is flat, a flat
    corner is ``forced``, or the piece has no cut (``on_shore``: the ring's vertices on the
    shore; ``h``: the cell size).  ``onto_cut`` False (regular layouts, whose blocks meet four
    corners to four: no T-junction): only onto a vertex that turns."""
    from .corners import raw_turning

    raw = raw_turning(r)
    n = len(r)
    corners = {int(i) for i in c}

    def reach(i: int) -> list[int]:  # the shore vertices within a cell either side, up to a corner
        out = []
        for step in (1, -1):
            k, d = (i + step) % n, math.hypot(*(r[(i + step) % n] - r[i]))
            while d < REACH * h and on_shore[k] and k not in corners:
                out.append(k)
                k, d = (k + step) % n, d + math.hypot(*(r[(k + step) % n] - r[k]))
        return out

    held = {int(f) for f in forced}
    flat = []
    for i in c:
        if i in held or abs(raw[i]) >= FLAT_TURN or not (on_shore[i - 1] and on_shore[(i + 1) % n]):
            continue
        near = reach(i)
        convex = [k for k in near if raw[k] >= CONVEX_TURN and k not in corners]
        if convex:
            k = max(convex, key=lambda k: raw[k])
            new = sorted((corners - {int(i)}) | {k})
            return tuple(new) if len(new) == 4 else tuple(c)
        flat.append(i)
    if not onto_cut or len(flat) != 1 or on_shore.all() or not on_shore.any():
        return tuple(c)
    start = int(np.flatnonzero(on_shore)[0])
    runs: list[list[int]] = []  # each stretch of cut vertices with the shore vertex either side
    cur: list[int] = []
    for m in range(1, n + 1):
        i = (start + m) % n
        if not on_shore[i]:
            cur.append(i)
        elif cur:
            runs.append([(cur[0] - 1) % n, *cur, i])
            cur = []
    if not runs:
        return tuple(c)

    def length(run):
        return float(np.hypot(*np.diff(r[run], axis=0).T).sum())

    run = max(runs, key=length)
    along = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(r[run], axis=0).T))])
    inner = list(range(1, len(run) - 1))
    mid = run[min(inner, key=lambda k: abs(along[k] - 0.5 * along[-1]))]
    new = sorted((set(c) - {flat[0]}) | {mid})
    return tuple(new) if len(new) == 4 else tuple(c)


def _junction_centre(ring: np.ndarray, junctions: np.ndarray):
    """The mean of the skeleton's junctions inside ``ring`` (a star split's centre), or None."""
    import shapely

    if not len(junctions):
        return None
    js = np.asarray(junctions, dtype=float).reshape(-1, 2)
    inside = js[shapely.contains_xy(shapely.Polygon(ring), js[:, 0], js[:, 1])]
    return np.mean(inside, axis=0) if len(inside) else None


def _skeleton_and_chords(poly, h: float, mouths: bool) -> tuple[Skeleton, list[Chord]]:
    """The skeleton and chords of ``poly`` at cell size ``h`` (:func:`layout_pieces`), remembered
    within :func:`.memo.remembering` (keyed by a 128-bit digest of the polygon's WKB, ``h`` and
    ``mouths``): the layout choice's tip draw (:mod:`.tipcuts`) is made at a scale drawn before.
    The chords come back as a new list of the same (frozen) chords."""
    import shapely

    def make():
        sk = skeleton(poly, spacing=h / 2, prune=0.5, min_arm=3 * h)
        return sk, place_chords(poly, sk, min_length=2 * h, mouths=mouths)

    key = ("skeleton", digest(shapely.to_wkb(poly)), float(h), bool(mouths))
    sk, chords = remembered(key, make)
    return sk, list(chords)


def _partition(dense, lines: list[np.ndarray], sigma: float) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """:func:`~.regions.partition` of the water ``dense`` by ``lines``, remembered within
    :func:`.memo.remembering` (keyed by a 128-bit digest of the water's WKB and the lines): the
    layout choice's tip draw (:mod:`.tipcuts`) cuts the water as the draw at its scale did (copies
    are returned: callers own what they get)."""
    import shapely

    key = (
        "partition",
        digest(shapely.to_wkb(dense), *(np.ascontiguousarray(c, dtype=float) for c in lines)),
        tuple(np.shape(c) for c in lines),
        float(sigma),
    )
    regions, cuts = remembered(key, lambda: partition(dense, lines, sigma))
    return [np.array(r) for r in regions], [np.array(c) for c in cuts]


def _split_region(
    r,
    junctions,
    sigma: float,
    min_width: float,
    *,
    regular: bool,
    normal: bool,
    thin: bool,
    tees: bool,
    bulges: bool = False,
    tapers: bool = False,
    look: int = 1,
):
    """``(pieces, cuts)`` of the region ``r``: :func:`~.split.best_split` (``look``: its first split
    looks ahead, :data:`~.split.LOOKAHEAD`), then :func:`_unfanned`
    (``bulges``: regular layouts split pieces that bulge too, ``tapers``: default layouts pieces
    that taper; without it a piece kept that bulges, or tapers, is noted, :func:`~.fans.noted_unsplit`);
    remembered within :func:`.memo.remembering` (keyed by a 128-bit digest of the ring, the skeleton's
    junctions inside it and the options): the layout choice's tip draw (:mod:`.tipcuts`)
    partitions the water as the draw at its scale did and splits the same regions again (copies
    are returned: callers own what they get)."""
    import shapely

    center = _junction_centre(r, junctions)
    ring = np.ascontiguousarray(r, dtype=float)
    js = np.asarray(junctions, dtype=float).reshape(-1, 2)
    # the junctions inside: the centre of the region's and of its pieces' star splits
    js = js[shapely.contains_xy(shapely.Polygon(ring), js[:, 0], js[:, 1])] if len(js) else js
    key = (
        "split",
        digest(ring, js),
        ring.shape,
        float(sigma),
        float(min_width),
        regular,
        normal,
        thin,
        tees,
        bulges,
        tapers,
        look,
    )

    def make():
        kw: dict = {"regular": regular, "normal": normal, "thin": thin, "tee": tee if tees else None}
        pieces, cuts, _ = best_split(r, sigma=sigma, min_width=min_width, center=center, look=look, **kw)
        pieces, cuts = _unfanned(pieces, cuts, junctions, sigma, min_width, normal, thin, regular, bulges, tapers)
        kept = [p for p, fc in pieces if not len(fc)]
        unsplit = None  # what the layout choice's draw with LayoutOptions(bulges=, tapers=True) would split
        if regular and not bulges and any(bulging(p, sigma) for p in kept):
            unsplit = "bulge"
        elif not regular and not tapers and any(tapering(p, sigma) and not fans(p, sigma) for p in kept):
            unsplit = "taper"
        return pieces, cuts, unsplit

    pieces, cuts, unsplit = remembered(key, make)
    if unsplit:
        noted_unsplit(unsplit)
    return copied((pieces, cuts))


def _unfanned(
    pieces: list,
    cuts: list,
    junctions,
    sigma: float,
    min_width: float,
    normal: bool,
    thin: bool,
    regular: bool = False,
    bulges: bool = False,
    tapers: bool = False,
):
    """``pieces`` (``(ring, forced)``) and ``cuts`` with every piece that fans
    (:func:`~.fans.fans`; ``tapers``: or tapers, :func:`~.fans.tapers`) split by
    :func:`~.fans.unfan` where it can be, and every piece with a side round a tip of land
    (:func:`~.fans.wraps`) where that split costs less (the split's
    ``min_width``, ``normal`` and ``thin`` as the region's).  ``regular``: only the pieces round a
    tip, by the splits regular layouts allow (session 29: a block wrapping a peninsula, 79.6 → 97.1 %
    of nodes within 3°; the fan splits there changed a round lake's grid for the worse, not kept)."""
    out: list = []
    for ring, fc in pieces:
        fan = not len(fc) and (bulges and bulging(ring, sigma) if regular else fans(ring, sigma, tapered=tapers))
        if len(fc) or not (fan or wraps(ring, sigma)):
            out.append((ring, fc))
            continue
        got = unfan(
            ring,
            sigma=sigma,
            min_width=min_width,
            center=_junction_centre(ring, junctions),
            normal=normal,
            thin=thin,
            wrapped=not fan,
            regular=regular,
            tapered=tapers,
        )
        if got is not None and not fan and sum(region_cost(r, sigma, f) for r, f in got[0]) >= region_cost(ring, sigma):
            got = None  # a C round a thin peninsula grids well: split only where that costs less
        if got is None:
            out.append((ring, fc))
            continue
        out += got[0]
        cuts = cuts + got[1]
    return out, cuts


def _closed(pieces: list[Piece], cuts: list, h: float, size: float, sigma: float, single: bool = False, ring=False):
    """The pieces with corners that close up round every island (:func:`~.frames.close_frames`),
    the first choice whose cells can be counted; the pieces as they are when there is none
    (their layout is valid, Delft3D's domain decomposition cannot couple it).  ``ring`` (with
    ``single``, the fallback of :func:`layout_pieces`): new corners may also turn less than
    :data:`~.frames._LEAST_TURN` (:data:`RING_LEAST_TURN`).

    Where that choice moves a corner onto a vertex of a straight shore (a corner cell of 180°,
    :func:`~.frames.straight_corners`), the corners are chosen again with moves onto bends of
    their own only, then onto vertices that turn (:func:`~.frames._bends`), and such a choice
    is taken when it has fewer straight corners and no more corners beside a sharper bend or
    blocks with two sides under ``sigma`` (:func:`~.frames.corner_flaws`); else the first
    choice stays.  Not with ``single``: five generated lakes with islands at 10 000 cells lost
    their straight cells (5 → 0) but three lost 4–8 points of nodes within 3° or got interface
    ratios of 2.7 and 5.7 (docs/lake-grids-journal.md, session 28)."""
    # corners costed by the turning their cells see first; when no such choice can be counted,
    # those costed at sigma (lake_with_islands(4) at 1500 cells: closed only by the latter)
    least = {"least": RING_LEAST_TURN} if single and ring else {}
    for own in (True, False):
        got = _first_countable(pieces, cuts, h, size, sigma, single, own, 0, least)
        if got is None:
            continue
        straight, borrowed, short = corner_flaws(got[0], sigma)
        if single or straight <= len(straight_corners(pieces)):  # (single: measured worse, see below)
            return got
        for bends, own_ in itertools.product((2, 1), (own, not own)):
            other = _first_countable(pieces, cuts, h, size, sigma, single, own_, bends, least)
            if other is None:
                continue
            s, b, k = corner_flaws(other[0], sigma)
            if s < straight and b <= borrowed and k <= short:  # no corner beside a bend, no short block end instead
                return other
        return got
    if single and not frame_defects(pieces, single=True) and _countable(pieces, h, closed=True):
        return pieces, cuts
    return _make_countable(pieces, cuts, h, size)


def _first_countable(
    pieces, cuts, h: float, size: float, sigma: float, single: bool, own: bool, bends: int, least: dict | None = None
):
    """The first choice of :func:`~.frames.close_frames` (``own``, ``bends``) whose cells can be
    counted (with ``single``, in one index space), as ``(pieces, cuts)``; None if there is none
    (``least``: :func:`~.frames.close_frames`' least turning of a new corner, if given)."""
    # each choice as it is: the T-junction extensions of :func:`_make_countable` never made a
    # closure choice countable (sessions 38 and 44: 421 calls) and cost 10-20 count programs a choice
    for closed in close_frames(
        pieces, sigma, own=own, single=single, tries=SINGLE_TRIES if single else 3, bends=bends, **(least or {})
    ):
        if _countable(closed, h) and (not single or _countable(closed, h, closed=True)):
            return closed, cuts
    return None


#: Rounds of :func:`~.ringcuts.ring_cuts` in the fallback for one index space (``ring``): the
#: layout is drawn again with the new cuts, and an island whose cuts a strip merge or a split
#: took away (two cuts a few cells apart at an island near the shore) gets more.
RING_ROUNDS = 3

#: The least turning (degrees) of a new block corner in the fallback for one index space
#: (``ring``): any vertex where blocks meet, and the sharpest shore bends of a piece whatever they
#: turn, the corner cost choosing among them.  GSHHG lake g180753 (one island near its shore,
#: 10 000 cells): its ring turned once only with a corner at a cut end turning 10–15°.
RING_LEAST_TURN = 0.0


#: Corner choices tried per island set-up for a single index space (``single``): a choice whose
#: rings turn once can still have no counts that close them (a ring whose blocks' own sides tie
#: its two sides to different lengths); the next choice differs in at least one piece.
SINGLE_TRIES = 8


def _welded(rings: list[np.ndarray], forced: list[tuple], eps: float):
    """:func:`~.blocks.weld` on the rings, keeping each ring's forced corners (moved with their
    vertices; a ring that loses its area is dropped with them)."""
    from scipy.spatial import cKDTree

    out_r, out_f = [], []
    for r, f in zip(rings, forced, strict=True):
        w = weld([r], eps)  # the ring alone first: drops its own repeated points
        if not w:
            continue
        out_r.append(_despiked(w[0]))
        out_f.append(f)
    allw = weld(out_r, eps)
    if len(allw) != len(out_r):  # a ring collapsed only against the others: keep them as they are
        return out_r, out_f
    fixed = []
    for r, f in zip(allw, out_f, strict=True):
        if len(f):
            _, k = cKDTree(r).query(np.asarray(f, dtype=float))
            f = tuple(tuple(r[i]) for i in np.atleast_1d(k))
        fixed.append(f)
    return allw, fixed


#: A ring vertex whose two edges run back along each other (the sine of the angle between them
#: below this) is the tip of a spike of no width: dropped (:func:`_despiked`).
SPIKE_SINE = 1e-9


def _despiked(r: np.ndarray) -> np.ndarray:
    """``r`` without vertices where the ring turns straight back (a spike of no width).

    A cut that starts on the shore and runs along it for a short way before it leaves into the
    water (the shore straight there, `dendritic(955700)`: 0.3 cells) gave the piece beside it a
    spike out along the cut and back: a ring whose own vertex lies on its own edge, which
    :func:`~.blocks.conform` inserted there a second time, and every scale's layout was refused
    as self-intersecting.  Without the spike the piece and the water are the same area."""
    r = np.asarray(r)
    while len(r) > 3:
        u = r - np.roll(r, 1, axis=0)  # the edge into each vertex
        v = np.roll(r, -1, axis=0) - r  # ... and out of it
        norm = np.hypot(*u.T) * np.hypot(*v.T)
        cross = u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]
        back = (np.abs(cross) <= SPIKE_SINE * norm) & (np.einsum("ij,ij->i", u, v) < 0) & (norm > 0)
        if not back.any():
            break
        r = np.delete(r, int(np.flatnonzero(back)[0]), axis=0)
    return r


def _check_pieces(poly, pieces: list[Piece]) -> None:
    """Every piece a valid polygon, and together exactly the water: else a clear error."""
    from shapely.geometry import Polygon

    from ..errors import TopologyError

    for pc in pieces:
        P = Polygon(pc.ring)
        if not P.is_valid:
            c = P.representative_point()
            raise TopologyError(
                f"automatic layout: a block near ({c.x:.6g}, {c.y:.6g}) came out self-intersecting; "
                f"add cut lines there by hand (a [outline] case) or try another cell size"
            )
    total = sum(Polygon(pc.ring).area for pc in pieces)
    if abs(total - poly.area) > 1e-6 * poly.area:
        raise TopologyError(
            f"automatic layout: the blocks cover {total:.6g} of the water's {poly.area:.6g}; "
            f"add cut lines by hand (a [outline] case) or try another cell size"
        )


def _countable(pieces: list[Piece], h: float, closed: bool = False) -> bool:
    from ..errors import TopologyError
    from .blocks import block_counts

    try:
        block_counts(pieces, h, best=False, closed=closed)
    except TopologyError:
        return False
    return True


#: :func:`_make_countable` gives up when this many rounds of T-junction extensions have not lowered
#: the number of T-junctions: a cut carried round a ring of blocks splits it thinner round after round
#: without end.  Session 38: `lake_with_islands(440302)` regular at 15 000 cells ran 5 × 128 rounds
#: (17 T-junctions left from the 11th round on; 679 count programs, 53 s of its 57 s of CPU) before
#: every such choice failed; of 304 calls on 128 shapes and held-out lakes (default and regular) every
#: one that succeeded did so before any extension, and those that failed had the last fall in their
#: T-junctions by round 12.
PLATEAU_ROUNDS = 8


def _make_countable(pieces: list[Piece], cuts: list, h: float, size: float):
    """Continue T-junctions across their blocks while no integer cell counts exist (giving up
    after :data:`PLATEAU_ROUNDS` rounds that leave as many T-junctions)."""
    from .tjunction import extend_t_junctions, t_junctions

    fewest, flat = None, 0
    for _ in range(4 * len(pieces) + 4):
        if _countable(pieces, h):
            return pieces, cuts
        todo = t_junctions(pieces)
        fewest, flat = (len(todo), 0) if fewest is None or len(todo) < fewest else (fewest, flat + 1)
        if flat >= PLATEAU_ROUNDS:
            break
        new, new_cuts = extend_t_junctions(pieces, todo)
        if not new_cuts:
            break
        cuts = cuts + new_cuts
        rings = conform([p.ring for p in new], 1e-9 * size)
        pieces = [
            Piece(r, tuple(sorted(int(np.argmin(np.hypot(*(r - p.ring[c]).T))) for c in p.corners)))
            for r, p in zip(rings, new, strict=True)
        ]
    if _countable(pieces, h):
        return pieces, cuts
    from ..errors import TopologyError
    from .tjunction import t_junctions

    where = [pieces[i].ring[v] for i, v in t_junctions(pieces)] or [pieces[0].ring[0]]
    raise TopologyError(
        f"automatic layout: no cell counts agree round the blocks near ({where[0][0]:.6g}, {where[0][1]:.6g}); "
        f"add cut lines there by hand (a [outline] case) or try another cell size"
    )
