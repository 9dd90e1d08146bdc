r"""Water in several separate parts: one grid of all of them (:func:`mesh_parts`).

Real lake files often hold more than one piece of water: a lake split at a causeway, dam or
bridge into parts (OpenStreetMap, national lake layers), a reservoir's main basin and a separate
pond, several placemarks in one KML.  :func:`meshcore.mesh_outline` given a shapely
``MultiPolygon`` (or a list of Polygons) and ``meshcore mesh`` given such a file mesh every part:

* every part is laid out and meshed on its own (:func:`meshcore.lakegrid.mesh_outline`) at the
  **same cell size** (default ``sqrt(total water area / target_cells)``), so cells are alike
  across the whole grid and one part's layout never depends on another's;
* the parts share nothing: their blocks are joined into one
  :class:`~meshcore.multiblock.MultiBlockGrid` with no interface between parts (a Delft3D
  ``.ddb`` couples no two parts), each block named ``part<k>_<name>`` (:func:`part_of` reads
  it back); parts are numbered from 1, largest area first;
* islands (holes given apart) go to the part whose shore holds them;
* parts that overlap or touch are an :class:`~meshcore.errors.InvalidInputError` naming both
  and the place (water that meets is one water: draw it as one outline);
* a part narrower than :data:`MIN_PART_CELLS` cells where it is widest (the largest disc inside
  it) is left out with a note naming it, unless it is the only one asked for.

Why not one layout of the whole ``MultiPolygon``?  The layout works on one connected polygon (its
medial axis, chords and regions); parts that do not touch have no interface to agree on, so
meshing them apart gives the same grid as one layout could, and keeps each part's grid the same
as when that part is meshed alone (``parts=[k]``; tested).
"""

from __future__ import annotations

import dataclasses
import re
from typing import Any

import numpy as np

from .cellsize import DEFAULT_CELLS, default_cell_size
from .errors import InvalidInputError

__all__ = [
    "MIN_PART_CELLS",
    "is_several",
    "join_grids",
    "on_one_line",
    "part_grids",
    "part_of",
    "select_parts",
    "water_parts",
]

#: A part fewer than this many cells across where it is widest is left out (with a note): the
#: layout needs blocks of at least 3 cells each way, and a grid 1–2 cells across is no model of
#: the water there.
MIN_PART_CELLS = 3.0

_PART = re.compile(r"^part(\d+)_")


def is_several(outline: Any) -> bool:
    """True for a shapely MultiPolygon or a list/tuple of shapely Polygons (several parts)."""
    if getattr(outline, "geom_type", None) == "MultiPolygon":
        return True
    return isinstance(outline, (list, tuple)) and bool(outline) and all(hasattr(p, "exterior") for p in outline)


def water_parts(outline: Any, holes: Any = ()) -> list[Any]:
    """The parts as shapely Polygons (largest first), each with the islands it holds.

    ``outline``: a MultiPolygon or a sequence of Polygons (their holes kept); ``holes``: more
    islands, each given to the part whose shore holds it.  Raises
    :class:`~meshcore.errors.InvalidInputError` for parts that overlap or touch (naming both
    and the place) and for an island in no part.
    """
    from shapely.geometry import Polygon

    polys = list(getattr(outline, "geoms", outline))
    polys = sorted((Polygon(p.exterior.coords, [r.coords for r in p.interiors]) for p in polys), key=lambda p: -p.area)
    _check_apart(polys)
    extra: list[list[Any]] = [[] for _ in polys]
    for k, h in enumerate(holes):
        isl = Polygon(np.asarray(h, dtype=float))
        c = isl.representative_point()
        home = [i for i, p in enumerate(polys) if Polygon(p.exterior.coords).contains(c)]
        if not home:
            raise InvalidInputError(f"island {k + 1} (near {c.x:.6g}, {c.y:.6g}) is inside no part of the water")
        extra[home[0]].append(np.asarray(h, dtype=float))
    return [
        Polygon(p.exterior.coords, [*(r.coords for r in p.interiors), *e]) if e else p
        for p, e in zip(polys, extra, strict=True)
    ]


def _check_apart(polys: list[Any]) -> None:
    import shapely

    shells = [shapely.Polygon(p.exterior.coords) for p in polys]
    tree = shapely.STRtree(shells)
    for i, j in zip(*tree.query(shells, predicate="intersects"), strict=True):
        if i < j:
            c = shells[i].intersection(shells[j]).representative_point()
            raise InvalidInputError(
                f"parts {i + 1} and {j + 1} of the water overlap or touch near ({c.x:.6g}, {c.y:.6g}): separate "
                f"parts must lie apart (water that meets is one water: draw it as one outline)"
            )


def part_width(poly: Any, cell_size: float) -> tuple[float, Any]:
    """How wide the part is where it is widest (the diameter of the largest disc inside it, its
    islands counted) and that disc's centre."""
    from shapely.ops import polylabel

    c = polylabel(poly, tolerance=max(0.05 * cell_size, 1e-12 * max(poly.length, 1e-300)))
    return 2.0 * float(poly.boundary.distance(c)), c


def on_one_line(poly: Any, cell_size: float, unit: str = "") -> str | None:
    """Why water is no water at ``cell_size``, or None: narrower where it is widest than one cell.

    With the cell size from the area (``sqrt(area / cells)``) that happens only when the outline
    is more than ``cells`` times longer than it is wide: points on (almost) one line, such as
    lon/lat on a line but for the rounding of their decimals, where the layout has nothing to
    put a block in.  The text names the widest place and the cell size that gives 3 cells there.
    """
    width, c = part_width(poly, cell_size)
    if width >= cell_size:
        return None
    long = poly.length / 2.0
    return (
        f"the water is {width:.3g}{unit} across at its widest (near ({c.x:.6g}, {c.y:.6g})) and about "
        f"{long:.4g}{unit} long: its points lie (almost) on one line, {long / max(width, 1e-300):,.0f} times longer "
        f"than wide, narrower than the cell size {cell_size:.3g}{unit} its area gives; if it is water, give a cell "
        f"size of at most {width / 3:.3g}{unit} (3 cells across)"
    )


def select_parts(
    polys: list[Any], numbers: Any, cell_size: float, names: Any = None
) -> tuple[list[tuple[int, Any]], list[str]]:
    """The parts to mesh, ``[(number, polygon), ...]``, and notes on those left out.

    ``numbers``: part numbers (from 1) asked for, None for all.  A part narrower than
    :data:`MIN_PART_CELLS` cells is left out with a note, unless it is the only one asked for.
    """
    n = len(polys)
    want = list(range(1, n + 1)) if numbers is None else list(dict.fromkeys(int(k) for k in numbers))
    bad = [k for k in want if not 1 <= k <= n]
    if bad:
        raise InvalidInputError(f"no part {bad[0]}: the water has {n} part{'s' * (n != 1)} (1 … {n})")
    if not want:
        raise InvalidInputError("no part asked for")
    kept, notes = [], []
    for k in want:
        p = polys[k - 1]
        width, c = part_width(p, cell_size)
        if len(want) > 1 and width < MIN_PART_CELLS * cell_size:
            name = f" ({names[k - 1]!r})" if names is not None else ""
            notes.append(
                f"part {k}{name} near ({c.x:.6g}, {c.y:.6g}) is {width:.3g} across at its widest (area "
                f"{p.area:.3g}), fewer than {MIN_PART_CELLS:g} cells of {cell_size:.3g}: left out; a cell size "
                f"of at most {width / MIN_PART_CELLS:.3g} would keep it"
            )
            continue
        kept.append((k, p))
    if not kept:
        raise InvalidInputError(
            f"every part asked for is narrower than {MIN_PART_CELLS:g} cells of {cell_size:.3g}: " + "; ".join(notes)
        )
    return kept, notes


def part_of(name: str) -> int | None:
    """The part number (from 1) a block of a several-part grid belongs to (None: one part)."""
    m = _PART.match(name)
    return int(m[1]) if m else None


def join_grids(results: list[tuple[int, Any]], notes: Any = ()) -> Any:
    """One :class:`~meshcore.multiblock.MultiBlockGrid` of the parts' grids ``[(number, grid)]``:
    blocks renamed ``part<k>_<name>``, no interface between parts, the infos summed."""
    from .grid import SolveInfo
    from .multiblock import MultiBlockGrid, MultiBlockTopology
    from .multiblock.topology import Interface

    grids: list[Any] = []
    names: list[str] = []
    blocks: list[Any] = []
    interfaces: list[Any] = []
    all_notes = list(notes)
    for k, mb in results:
        new = {nm: f"part{k}_{nm}" for nm in mb.names}
        # writers name blocks by the grid's names["block"] (meshcore.io._base.block_names)
        grids += [
            g.replaced(names={**(g.names or {}), "block": new[nm]}) for g, nm in zip(mb.grids, mb.names, strict=True)
        ]
        names += [new[nm] for nm in mb.names]
        for itf in mb.interfaces:
            sides = [dataclasses.replace(s, block=new[s.block]) for s in (itf.a, itf.b)]
            interfaces.append(Interface(sides[0], sides[1], itf.reversed))
        if mb.topology is not None:
            blocks += [dataclasses.replace(b, name=new[b.name]) for b in mb.topology.blocks]
        all_notes += [f"part {k}: {nt}" for nt in mb.notes]
    topo = MultiBlockTopology(tuple(blocks), tuple(interfaces), check_geometry=False) if blocks else None
    infos = [mb.info for _, mb in results]
    info = SolveInfo(
        method=infos[0].method,
        converged=all(i.converged for i in infos),
        iterations=sum(i.iterations for i in infos),
        elapsed=sum(i.elapsed for i in infos),
        message=f"{len(results)} parts of the water: " + "; ".join(f"part {k}: {mb.info.message}" for k, mb in results),
    )
    mode = results[0][1].mode
    frame = results[0][1].frame
    return MultiBlockGrid(tuple(grids), tuple(names), tuple(interfaces), mode, info, topo, frame, tuple(all_notes))


def part_grids(mb: Any) -> dict[int, Any]:
    """``{part number: MultiBlockGrid of that part's blocks}`` of a grid made by :func:`join_grids`
    (``{1: mb}`` for a grid of one part)."""
    from .multiblock import MultiBlockGrid

    groups: dict[int, list[int]] = {}
    for i, nm in enumerate(mb.names):
        groups.setdefault(part_of(nm) or 1, []).append(i)
    if len(groups) == 1 and part_of(mb.names[0]) is None:
        return {1: mb}
    out = {}
    for k, idx in groups.items():
        names = {mb.names[i] for i in idx}
        itfs = tuple(itf for itf in mb.interfaces if itf.a.block in names)
        out[k] = MultiBlockGrid(
            tuple(mb.grids[i] for i in idx), tuple(mb.names[i] for i in idx), itfs, mb.mode, mb.info, None, mb.frame
        )
    return out


def mesh_parts(
    outline: Any,
    mesh_one: Any,
    *,
    holes: Any = (),
    parts: Any = None,
    cell_size: float | None = None,
    target_cells: int = DEFAULT_CELLS,
    **options: Any,
) -> Any:
    """:func:`meshcore.mesh_outline` of water in several parts (see the module docstring).

    ``mesh_one``: :func:`~meshcore.lakegrid.mesh_outline`, called for every part (passed in by it:
    this module sits below the pipeline); ``parts``: the part numbers (from 1, largest first) to
    mesh, None for all; ``options`` as for ``mesh_one`` (``strict`` raises when any part has folded
    cells).
    """
    polys = water_parts(outline, holes)
    h = float(cell_size) if cell_size is not None else default_cell_size(sum(p.area for p in polys), target_cells)
    kept, notes = select_parts(polys, parts, h)
    results = [(k, mesh_one(p, cell_size=h, **options)) for k, p in kept]
    return join_grids(results, notes)
