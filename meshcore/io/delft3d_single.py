r"""Delft3D-4 single domain: the blocks merged into ONE RGFGRID ``.grd`` with inactive points, and its ``.enc``.

``write("lake.grd", mbgrid, format="delft3d-single")`` (``meshcore mesh … -o lake.grd
--single``) places the blocks in one index space (:mod:`meshcore.multiblock.indexspace`:
every block an offset and an orientation, shared interface nodes on the same index node)
and writes

``lake.grd``
    the merged grid in the layout of :mod:`.delft3d` (RGFGRID's: ``Coordinate System``,
    ``Missing Value``, ``MMAX NMAX``, ``0 0 0``, the ETA rows of x then of y, 5 values a
    line).  Index nodes no block has (land, the water round an island, the columns
    between parts) hold RGFGRID's missing value, ``-9.99999000000000024E+02``
    (-999.999, the value RGFGRID writes in the header and at inactive points);
``lake.enc``
    the computational grid enclosure: closed polygons of water-level point indices
    ``(m, n)`` (cell ``(m, n)`` has the depth points ``m-1 … m``, ``n-1 … n``; 1-based),
    one point per change of direction, each polygon closed by repeating its first point.
    The first polygon is the outer enclosure, the next ones the internal enclosures
    (islands), as the Delft3D-FLOW manual (appendix A, "computational grid enclosure")
    describes.  A cell is active when it lies strictly inside the outer polygon and not
    inside or on an internal one; the polygons run through the centres of the inactive
    cells next to the water (half a cell outside the water's cell edges), so the active
    cells are exactly the cells of the blocks.  For a full grid this gives the enclosure
    of :mod:`.delft3d`, ``(1,1) (MMAX+1,1) (MMAX+1,NMAX+1) (1,NMAX+1) (1,1)``.

A cell whose four corners are active points but which no block has (water a ring of
blocks closes round, an island one cell wide in index space) is left out by the
enclosure.  An island one cell across in index space gives a degenerate internal
polygon (a line or a point), which still marks its cells inactive.

Refused (:class:`~meshcore.errors.WriteError`, the place named): a layout that does not
fit one index space (a ring of blocks round an island whose cell counts do not add up,
3- or 5-block corners, arms that fold onto each other in index space: write a ``.ddb``
instead), and water in several parts (one outer enclosure only: write each part with
``--part``).  The two files are written as a set (:mod:`._atomic`).

Reading (:func:`read_grd_single`; :func:`meshcore.io.read_blocks` of a ``.grd`` with missing
points comes here): the merged node array, missing values inactive, and the water cells of the
``.enc`` beside it (without one: every cell whose four corners are active) make an
:class:`~meshcore.multiblock.indexspace.IndexSpace` (:func:`read_index_space`); the water cells
cut into rectangles (:func:`~meshcore.multiblock.indexspace.from_mask`) are the blocks of the
:class:`GridSet` returned, ready for the quality report or another format.  The blocks written
are not kept (the format has no place for them): the cells and nodes are.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from ..crs import Frame
from ..errors import ReadError, WriteError
from ._atomic import atomic_paths
from ._base import GridSet, find_interfaces, grid_from_world
from .delft3d import full_grid, grd_text, read_enc, read_grd_arrays

__all__ = [
    "MISSING_VALUE",
    "enclosure_polygons",
    "gridset_of",
    "merged",
    "read_enc",
    "read_grd_single",
    "read_index_space",
    "write_grd_single",
]

#: RGFGRID's missing value (header and inactive points).
MISSING_VALUE = -999.999


def merged(gs: GridSet, path: Any = "") -> Any:
    """The blocks of ``gs`` in one index space (:class:`~meshcore.multiblock.indexspace.IndexSpace`),
    an :class:`~meshcore.multiblock.indexspace.EmbeddingError` turned into a
    :class:`~meshcore.errors.WriteError` naming ``path``."""
    from ..multiblock.indexspace import EmbeddingError, embed

    try:
        return embed(gs.blocks, gs.block_names)
    except EmbeddingError as exc:
        raise WriteError(f"{path}: {exc}; write a .ddb (domain decomposition) or .vtm instead") from None


def _trace(water: np.ndarray) -> list[list[tuple[int, int, int, int]]]:
    """Closed loops of the water cells' outer edges, water on the left: ``(x, y, dx, dy)`` per edge.

    Vertices are index nodes (cell ``(I, J)`` spans nodes ``I … I+1``, ``J … J+1``).  Where two
    water cells touch at a corner only, the loop turns left, so they stay apart.
    """
    w = np.pad(water, 1)
    out: dict[tuple[int, int], list[tuple[int, int]]] = {}
    for I, J in zip(*np.nonzero(water), strict=True):
        a, b = int(I) + 1, int(J) + 1  # padded
        x, y = int(I), int(J)
        if not w[a, b - 1]:
            out.setdefault((x, y), []).append((1, 0))
        if not w[a + 1, b]:
            out.setdefault((x + 1, y), []).append((0, 1))
        if not w[a, b + 1]:
            out.setdefault((x + 1, y + 1), []).append((-1, 0))
        if not w[a - 1, b]:
            out.setdefault((x, y + 1), []).append((0, -1))
    loops = []
    while out:
        start = next(iter(out))
        v, d = start, out[start][0]
        loop = []
        while True:
            out[v].remove(d)
            if not out[v]:
                del out[v]
            loop.append((v[0], v[1], d[0], d[1]))
            v = (v[0] + d[0], v[1] + d[1])
            if v == start or v not in out:
                break
            left, straight, right = (-d[1], d[0]), d, (d[1], -d[0])
            d = next(c for c in (left, straight, right) if c in out[v])
        loops.append(loop)
    return loops


def enclosure_polygons(water: np.ndarray) -> list[list[tuple[int, int]]]:
    """The enclosure polygons (water-level point indices, closed) of the water cells, outer first."""
    outer, inner = _polygons(water)
    return outer + inner


def _polygons(water: np.ndarray) -> tuple[list[list[tuple[int, int]]], list[list[tuple[int, int]]]]:
    """(outer polygons: anticlockwise, internal ones: the rest), each closed."""
    polys = []
    for loop in _trace(water):
        pts = []
        for k, (x, y, dx, dy) in enumerate(loop):
            pdx, pdy = loop[k - 1][2:]
            if (pdx, pdy) == (dx, dy):
                continue
            # the vertex moved half a cell out along both edges' outward normals (water on the left)
            cx = x + 0.5 * (pdy + dy) - 0.5
            cy = y + 0.5 * (-pdx - dx) - 0.5
            pts.append((round(cx) + 2, round(cy) + 2))
        pts = [p for k, p in enumerate(pts) if p != pts[k - 1]] or pts[:1]
        area = sum(a[0] * b[1] - b[0] * a[1] for a, b in zip(pts, pts[1:] + pts[:1], strict=True))
        polys.append((area, pts + [pts[0]]))
    return [p for a, p in polys if a > 0], [p for a, p in polys if a <= 0]


def _grd_text(gs: GridSet, x: np.ndarray, y: np.ndarray, lonlat: bool) -> str:
    ok = np.isfinite(x)
    if lonlat:
        X, Y = gs.frame.to_lonlat(np.where(ok, x, 0.0), np.where(ok, y, 0.0))
    else:
        X, Y = gs.frame.to_world(np.where(ok, x, 0.0), np.where(ok, y, 0.0))
    X = np.where(ok, X, MISSING_VALUE)
    Y = np.where(ok, Y, MISSING_VALUE)
    return grd_text(X, Y, gs.frame.crs, lonlat, MISSING_VALUE, ": blocks merged into one domain")


def write_grd_single(path: Path, gs: GridSet, *, lonlat: bool = False, **_: Any) -> None:
    """Write the blocks of ``gs`` as one Delft3D grid with inactive points and its enclosure."""
    path = Path(path)
    space = merged(gs, path)
    outer, inner = _polygons(space.water)
    n_outer = len(outer)
    if space.n_components > 1 or n_outer != 1:
        raise WriteError(
            f"{path}: the water is in {max(space.n_components, n_outer)} parts (or cells that touch at a "
            f"corner only), and a Delft3D enclosure has one outer polygon: write each part with --part, "
            f"or the parts as a .vtm"
        )
    text = _grd_text(gs, space.x, space.y, lonlat)
    enc = "".join(f"{m:6d}{n:6d}\n" for poly in outer + inner for m, n in poly)
    with atomic_paths([path.with_suffix(".enc"), path]) as (tmp_enc, tmp_grd):
        tmp_grd.write_text(text, encoding="ascii")
        tmp_enc.write_text(enc, encoding="ascii")


# ------------------------------------------------------------------- reading
def _enclosed(polys: list[list[tuple[int, int]]], shape: tuple[int, int]) -> np.ndarray:
    """Cells ``(I, J)`` (water-level points ``(I + 2, J + 2)``) strictly inside the first polygon and
    not inside or on another (see the module docstring)."""
    import shapely

    m, n = np.meshgrid(np.arange(shape[0]) + 2.0, np.arange(shape[1]) + 2.0, indexing="ij")

    def geom(p):
        u = list(dict.fromkeys(p))
        return shapely.Polygon(p) if len(u) > 2 else shapely.LineString(u) if len(u) == 2 else shapely.Point(u[0])

    inside = shapely.contains_xy(geom(polys[0]), m, n)
    for p in polys[1:]:
        inside &= ~shapely.intersects_xy(geom(p), m, n)
    return inside


def read_index_space(path: Path, arrays: tuple | None = None) -> tuple[Any, Frame]:
    """The merged grid of a ``.grd`` (missing points inactive) and its water cells (from the ``.enc``
    beside it, else every cell with four active corners), with its frame (``arrays``: the file's
    :func:`.delft3d.read_grd_arrays`, if read already)."""
    from ..multiblock.indexspace import from_mask

    path = Path(path)
    X, Y, crs, spherical, missing = read_grd_arrays(path) if arrays is None else arrays
    gone_x, gone_y = np.equal(X, missing), np.equal(Y, missing)
    if (gone_x != gone_y).any():
        m, n = (int(v) for v in np.argwhere(gone_x != gone_y)[0])
        which = "x" if gone_x[m, n] else "y"
        raise ReadError(
            f"{path}: node (m={m + 1}, n={n + 1}): {which} is the missing value {missing:g} and the other "
            f"coordinate is not"
        )
    act = ~gone_x
    if act.sum() < 4:
        raise ReadError(f"{path}: fewer than 4 active points: no cell")
    x, y = np.where(act, X, np.nan), np.where(act, Y, np.nan)
    corners = act[:-1, :-1] & act[1:, :-1] & act[1:, 1:] & act[:-1, 1:]
    enc = path.with_suffix(".enc")
    if enc.is_file():
        water = _enclosed(read_enc(enc), corners.shape)
        bad = water & ~corners
        if bad.any():
            i, j = (int(v) for v in np.argwhere(bad)[0])
            raise ReadError(
                f"{enc}: the enclosure makes cell (m={i + 2}, n={j + 2}) active, but a corner of it is a "
                f"missing point of {path.name}: the two files come from different writes"
            )
    else:
        water = corners
    if not water.any():
        raise ReadError(f"{path}: no active cell")
    space = from_mask(x, y, water)
    return space, Frame("EPSG:4326" if spherical else crs, (0.0, 0.0))


def gridset_of(space: Any, frame: Frame, path: Path) -> GridSet:
    """The blocks of an index space read back as a :class:`GridSet` (world coordinates: origin 0)."""
    blocks = tuple(
        grid_from_world(g.x, g.y, (0.0, 0.0), path, f"block {nm}")
        for g, nm in zip(space.blocks(), space.names, strict=True)
    )
    return GridSet(blocks, frame, space.names, find_interfaces(blocks), str(path))


def read_grd_single(path: Path, **_: Any) -> GridSet:
    """Read a single-domain ``.grd`` (+ ``.enc``): its water cells as rectangular blocks (module docstring)."""
    space, frame = read_index_space(path)
    return gridset_of(space, frame, Path(path))


def read_grd_any(path: Path, **_: Any) -> GridSet:
    """Read an RGFGRID ``.grd``: a full grid as one block (:func:`.delft3d.read_grd`), one with missing
    (inactive) points or an ``.enc`` that leaves cells out as a single-domain grid (:func:`read_grd_single`)."""
    arrays = read_grd_arrays(path)  # (read once for both)
    full = full_grid(path, arrays)
    return full if full is not None else gridset_of(*read_index_space(path, arrays), Path(path))
