"""Lakes in the app: the water (shore + islands), its block layout, and the layout's grid (no Qt).

The same functions as ``meshcore mesh`` (:mod:`meshcore.cli.mesh`) so that the same file
gives the same layout in the app and on the command line:

* the water: every ring of the point file, projected like the rest of the project
  (:func:`meshcore.cli.lakefile.local_frame`; lon/lat by :func:`meshcore.cli.lakefile.is_lonlat`),
  split into shore and islands by :func:`meshcore.cli.lakefile.lake_rings` (open lines that
  cannot be islands dropped with a note);
* the layout: :func:`meshcore.layout.auto_layout` at the cell size the user set, or at
  ``sqrt(water area / 10 000)`` (:data:`meshcore.cli.mesh.DEFAULT_CELLS`), with cell counts
  that are multiples of ``2**LEVELS`` (the grid sequencing of :func:`meshcore.lakegrid.mesh_layout`);
* the grid: :func:`meshcore.lakegrid.mesh_layout` (see :func:`app.pipeline.solve_project`).

A :class:`Lake` is part of the immutable :class:`~app.project.Project`; with a layout, the
project's blocks are the layout's blocks (:func:`with_layout`) and are solved together.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from meshcore import MeshcoreError
from meshcore.errors import Stopped

__all__ = [
    "BRANCHED_FILL",
    "Lake",
    "area_text",
    "cell_size_of",
    "compute_layout",
    "crs_unit",
    "default_cell_size",
    "expected_cells",
    "layout_blocks",
    "looks_branched",
    "near_header",
    "part_area",
    "part_centres",
    "read_lake",
    "read_lake_parts",
    "split_layout",
    "water",
    "with_layout",
]

#: an outline whose water fills less than this share of its convex hull is "branched":
#: one block would be poor, the app offers Auto layout on import
BRANCHED_FILL = 0.5


def _frozen(a: Any) -> np.ndarray:
    out = np.array(a, dtype=np.float64).reshape(-1, 2)
    out.setflags(write=False)
    return out


@dataclass(frozen=True, slots=True, eq=False)
class Lake:
    """The water of a lake project and its block layout.

    ``outline`` is the shore and ``holes`` the islands (local model coordinates);
    ``cell_size`` the wanted cell size (None: about :data:`target_cells` cells);
    ``regular`` asks for a layout without 3- or 5-block corners (Delft3D DD); ``single`` one whose
    rings of blocks round islands also close in one index space (Delft3D single domain, EFDC);
    ``layout`` is the :class:`meshcore.layout.Layout` (None until Auto layout).
    """

    outline: np.ndarray
    holes: tuple[np.ndarray, ...] = ()
    cell_size: float | None = None
    target_cells: int = 10_000
    regular: bool = False
    single: bool = False
    layout: Any = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "outline", _frozen(self.outline))
        object.__setattr__(self, "holes", tuple(_frozen(h) for h in self.holes))

    def replaced(self, **kw: Any) -> Lake:
        return replace(self, **kw)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Lake):
            return NotImplemented
        return (
            np.array_equal(self.outline, other.outline)
            and len(self.holes) == len(other.holes)
            and all(np.array_equal(a, b) for a, b in zip(self.holes, other.holes, strict=True))
            and self._settings() == other._settings()
            and self.layout is other.layout
        )

    __hash__ = None  # type: ignore[assignment]

    def _settings(self) -> tuple:
        return (self.cell_size, self.target_cells, self.regular, self.single)


# ------------------------------------------------------------------ reading
def read_lake(
    pointset: Any, frame: Any = None, *, lonlat: bool = False, part: int = 1, metres: bool = True
) -> tuple[np.ndarray, list, Any, list[str]]:
    """Shore, islands, frame and notes of a point file's rings, by the rules of ``meshcore mesh``.

    ``pointset`` is the :class:`meshcore.io.PointSet` read from the file; with ``lonlat``
    its degrees go to ``frame`` (the project's) or to the UTM zone of the centroid with a
    round local origin (:func:`meshcore.cli.lakefile.local_frame`).  Open lines touching the
    shore are dropped with a note (:func:`meshcore.cli.lakefile.lake_parts`).  A file of several
    separate parts of water gives part ``part`` (1: the largest; its shore and islands) and a
    note naming the parts left out (:func:`several_parts_note`).  Raises
    :class:`~meshcore.MeshcoreError` when the rings are not water (an island across the shore,
    parts that overlap, a ring of fewer than three points).
    """
    parts, frame, notes = read_lake_parts(pointset, frame, lonlat=lonlat)
    if not 1 <= part <= len(parts):
        raise MeshcoreError(f"part {part} asked for; the file has {len(parts)} part{'s' * (len(parts) != 1)} of water")
    _, outer, islands = parts[part - 1]
    if len(parts) > 1:
        notes = [*notes, several_parts_note(parts, part, metres=metres, frame=frame, lonlat=lonlat or not metres)]
    return outer, islands, frame, notes


def read_lake_parts(pointset: Any, frame: Any = None, *, lonlat: bool = False) -> tuple[list, Any, list[str]]:
    """The separate parts of water of a point file, ``[(name, shore, islands), ...]`` largest first
    (numbered from 1 in that order, as ``meshcore mesh`` numbers them), the frame and the notes;
    projected as :func:`read_lake` says."""
    from meshcore import crs as mcrs
    from meshcore.cli.lakefile import lake_parts, local_frame

    ps = pointset
    if not lonlat and ps.crs and frame is not None and frame.crs and not mcrs.is_geographic(ps.crs):
        ps, frame = mcrs.project(ps, frame.crs, origin=frame.origin)  # a projected file: into the frame
    elif lonlat:
        src = mcrs.LONLAT if ps.crs is None else None
        if frame is not None and frame.crs:
            ps, frame = mcrs.project(ps, frame.crs, origin=frame.origin, source_crs=src)
        else:  # the rule of ``meshcore mesh``: the same local numbers, the same layout and grid
            ps, frame = local_frame(ps, "auto", source_crs=src)
    parts, notes = lake_parts(ps)
    return parts, frame, notes


def part_area(part: Any) -> float:
    """Water area of a part ``(name, shore, islands)`` of :func:`read_lake_parts` (islands taken out)."""
    from shapely.geometry import Polygon

    _, outer, islands = part
    return float(Polygon(outer).area - sum(Polygon(h).area for h in islands))


def expected_cells(lake: Any) -> int:
    """About how many cells a layout of ``lake`` has: its water area over the cell size squared (the
    automatic size gives about 10 000)."""
    area = part_area(("", lake.outline, lake.holes)) if len(lake.outline) >= 3 else 0.0
    h = lake.cell_size if lake.cell_size else default_cell_size(area) if area > 0 else 0.0
    return round(area / h**2) if h > 0 and area > 0 else 0


def area_text(area: float, metres: bool = True) -> str:
    """An area as a modeller reads it: km² from 1 km² up, else hectares (model units² without metres)."""
    if not metres:
        return f"{area:.4g} units²"
    return f"{area / 1e6:,.3g} km²" if area >= 1e6 else f"{area / 1e4:,.3g} ha"


def crs_unit(crs: str | None) -> str:
    """The unit of a projected CRS's x axis as a modeller writes it ("m", "ft", "US survey foot");
    "m" for none (the app takes plain numbers as metres, as its areas in km² do)."""
    if not crs:
        return "m"
    from meshcore.crs import proj_call

    def unit():
        import pyproj

        return pyproj.CRS.from_user_input(crs).axis_info[0].unit_name

    try:
        name = str(proj_call(unit))
    except Exception:  # an unknown CRS: its numbers said without a unit
        return "units"
    return {"metre": "m", "meter": "m", "foot": "ft", "kilometre": "km"}.get(name, name)


def part_centres(parts: list, frame: Any = None, *, lonlat: bool = False, metres: bool = True):
    """Where each part lies, in the numbers the user knows the file by, and their unit: the
    file's longitude/latitude for a lon/lat file (``lonlat``; projected or kept as degrees,
    ``metres`` False), else the CRS's own coordinates (the local ones plus the frame's origin)
    in the CRS's unit.  ``[(x, y), ...], "lon/lat" | unit``."""
    from shapely.geometry import Polygon

    local = np.array([Polygon(outer).centroid.coords[0] for _name, outer, _isl in parts], float).reshape(-1, 2)
    if not metres:  # lon/lat kept as degrees: the parts are in degrees already
        return [tuple(c) for c in local], "lon/lat"
    if lonlat and frame is not None and frame.crs:
        try:
            lon, lat = frame.to_lonlat(local[:, 0], local[:, 1])
            return list(zip(np.atleast_1d(lon).tolist(), np.atleast_1d(lat).tolist(), strict=True)), "lon/lat"
        except Exception:  # PROJ refused: the projected numbers below, with their unit
            pass
    if frame is not None:
        x, y = frame.to_world(local[:, 0], local[:, 1])
        local = np.column_stack([x, y])
    return [tuple(c) for c in local], crs_unit(getattr(frame, "crs", None))


def near_header(unit: str) -> str:
    """The heading of the centre column, with its unit (it had none: metres of a local origin,
    degrees or feet looked alike)."""
    return "near (lon, lat)" if unit == "lon/lat" else f"near (x, y), {unit}"


def several_parts_note(
    parts: list, chosen: int = 1, *, metres: bool = True, frame: Any = None, lonlat: bool = False
) -> str:
    """What the import of a file of several separate parts of water says: the app grids one lake,
    part ``chosen`` (with its islands); ``meshcore mesh`` grids every part.  Where each part lies as
    :func:`part_centres` says (``frame``, ``lonlat``: the parts' frame, a lon/lat file)."""
    centres, unit = part_centres(parts, frame, lonlat=lonlat, metres=metres)
    where = "lon/lat " if unit == "lon/lat" else ""
    unit = "" if unit == "lon/lat" else f" {unit}"

    def part(k: int) -> str:
        name, x, y = parts[k - 1][0], *centres[k - 1]
        return (
            f"part {k} ({name!r}, {area_text(part_area(parts[k - 1]), metres)}, near {where}({x:.6g}, {y:.6g}){unit})"
        )

    rest = [k for k in range(1, len(parts) + 1) if k != chosen]
    left = ", ".join(part(k) for k in rest)
    who = f"the largest, {part(1)}" if chosen == 1 else part(chosen)
    return (
        f"{len(parts)} separate parts of water: the app grids one lake, so {who} is imported "
        f"with its islands and {left} {'is' if len(rest) == 1 else 'are'} left out (File ▸ Import again to "
        f"open another); 'meshcore mesh' grids every part of the file into one grid (--part N for some)"
    )


def water(outline: Any, holes: Any = ()) -> Any:
    """The water polygon (shapely, islands as holes, cleaned as meshcore cleans it) and its notes."""
    from meshcore.layout.polygon import water_polygon

    return water_polygon(np.asarray(outline, float), holes=[np.asarray(h, float) for h in holes])


def looks_branched(outline: Any, holes: Any = ()) -> bool:
    """True for water that one block grids poorly: islands, or a shape far from convex (arms)."""
    if len(holes):
        return True
    try:
        poly, _ = water(outline)
    except MeshcoreError:
        return False
    hull = poly.convex_hull.area
    return hull > 0 and poly.area / hull < BRANCHED_FILL


# ------------------------------------------------------------------ layout
def default_cell_size(area: float, target_cells: int | None = None) -> float:
    """``sqrt(water area / cells)``: the cell size ``meshcore mesh`` chooses by default
    (:func:`meshcore.cellsize.default_cell_size`)."""
    from meshcore.cellsize import default_cell_size as rule

    return rule(area, target_cells)


def cell_size_of(lake: Lake) -> float:
    """The cell size a layout of ``lake`` uses (the set one, or the default)."""
    if lake.cell_size is not None:
        return float(lake.cell_size)
    poly, _ = water(lake.outline, lake.holes)
    return default_cell_size(poly.area, lake.target_cells)


def compute_layout(lake: Lake, cuts: Any = None, *, stop_event: Any = None) -> Any:
    """The :class:`meshcore.layout.Layout` of ``lake`` (what ``meshcore mesh`` would make).

    Runs :func:`meshcore.layout.auto_layout` (seconds on a 10 000-cell lake: call it off the
    GUI thread); with ``cuts`` (cut lines drawn by hand, in any topology: ending on the shore,
    on other cuts or meeting at a point) :func:`split_layout` makes the blocks between them
    instead, each with four corners where it turns, the cuts' ends snapped as the Cut line tool
    snaps them over a layout.  Raises
    :class:`~meshcore.MeshcoreError` naming the problem (e.g. the region that cannot be
    four-sided).  ``stop_event`` (a :class:`threading.Event`): once set, the layout ends with
    :class:`meshcore.errors.Stopped` at its next check — between the stages of a draw and between draws
    (:mod:`meshcore.layout.stopping`: a tenth of a second or so on Vänern at 10 000 cells, whose first
    coarse reading comes ~4 s after the start), before and after each coarse reading, and at the next
    sweep of a reading under way — a layout no longer wanted stops keeping a core busy.
    """
    from meshcore.cli.mesh_steps import LEVELS, MIN_CELLS
    from meshcore.errors import InvalidInputError
    from meshcore.layout import auto_layout

    poly, _ = water(lake.outline, lake.holes)
    h = cell_size_of(lake)
    if not (h > 0 and math.isfinite(h)):
        raise InvalidInputError(f"cell size must be positive, got {h}")
    est = poly.area / h / h
    if est < MIN_CELLS:
        raise InvalidInputError(
            f"a cell size of {h:.4g} gives about {est:.2g} cells; give at most {math.sqrt(poly.area / MIN_CELLS):.4g}"
        )
    if lake.cell_size is None:  # points on (almost) one line: nothing to lay out (was: 90 s, "All-NaN slice")
        from meshcore.lakeparts import on_one_line

        why = on_one_line(poly, h, " m")
        if why:
            raise InvalidInputError(why.replace("give a cell size of", "set the cell size (Lake panel) to"))
    if cuts:
        return split_layout(poly, [np.asarray(c, float) for c in cuts], h, 2**LEVELS)
    from .lake_solve import coarse_readings, hold_readings

    readings = coarse_readings()  # the chosen layout's coarse level solved once, as meshcore mesh does
    # a reading under way stops at its next sweep; auto_layout's own checks (between the stages of a draw and
    # between draws) end the layout with Stopped, and a reading a stop cut short is never used (raised below)
    readings.stop_event.event = stop_event
    try:
        lay = auto_layout(
            poly,
            cell_size=h,
            multiple=2**LEVELS,
            regular=lake.regular,
            single=lake.single,
            reading=readings,
            stop_event=stop_event,
        )
    finally:
        readings.stop_event.event = None  # the held solves take the stop of the solve that goes on from one
    if stop_event is not None and stop_event.is_set():
        raise Stopped("the layout was stopped")
    hold_readings(lay, readings)  # its grid (app.lake_solve.solve_layout) goes on from there
    return lay


def split_layout(poly: Any, cuts: list, cell_size: float, multiple: int) -> Any:
    """The layout of the cut lines drawn by hand (Split into blocks by cut lines): each end that
    lands within :data:`meshcore.layout.edit.SNAP_CELLS` cells of an earlier cut's end or a shore
    tip goes onto it, as the Cut line tool over a layout puts it (:func:`app.layout_edit.with_drawn_cut`;
    an end a cell or two off makes a thin wedge block); the layout's notes (the Messages) say which
    end moved and where.  When the snapped cuts give no layout, the cuts as drawn do, and a note
    says so; their error is the one they give unsnapped."""
    from meshcore.errors import TopologyError
    from meshcore.layout import layout_from_cuts
    from meshcore.layout.edit import SNAP_CELLS

    try:
        lay = layout_from_cuts(poly, cuts, cell_size=cell_size, multiple=multiple, snap=SNAP_CELLS)
        if lay.notes:
            lay.topology()  # checked here: a snapped layout the solve cannot read is no layout
        return lay
    except TopologyError as exc:
        plain = layout_from_cuts(poly, cuts, cell_size=cell_size, multiple=multiple)
        why = f"cut lines: their ends stay where drawn (snapped, they give no layout: {exc})"
        return replace(plain, notes=(*plain.notes, why))


def layout_blocks(layout: Any) -> tuple:
    """One :class:`~app.project.Block` per layout block: its four borders (read-only) and cells."""
    from meshcore import BORDER_NAMES

    from .lake_solve import layout_topology
    from .project import Block

    topo = layout_topology(layout)  # made by the worker that made the layout, as a rule
    out = []
    for lb, b in zip(layout.blocks, topo.blocks, strict=True):
        out.append(
            Block(
                name=lb.name,
                boundary=tuple(np.asarray(b.borders[n], float) for n in BORDER_NAMES),
                cells=None,
                closed=True,
            )
        )
    return tuple(out)


def with_layout(project: Any, lake: Lake) -> Any:
    """The project with ``lake`` (and, when it has a layout, the layout's blocks)."""
    if lake.layout is None:
        return project.replaced(lake=lake)
    return project.replaced(lake=lake, blocks=layout_blocks(lake.layout), multiblock=None)
