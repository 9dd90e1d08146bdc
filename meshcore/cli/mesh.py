"""``meshcore mesh OUTLINE -o OUT`` — a lake outline in, a model-ready multiblock grid out.

The whole of :func:`meshcore.mesh_outline` from the command line::

    meshcore mesh lake.geojson -o lake.vtm -o lake.ddb --png lake.png --preset delft3d

1. **read** OUTLINE (any point file: CSV/TXT, KML/KMZ, GeoJSON, shapefile, DXF).  The ring
   with the largest area is the shore; every other ring must lie inside it and is an island
   (GeoJSON interior rings, KML ``innerBoundaryIs``, shapefile holes, extra CSV rings); a ring
   outside every shore is a separate part of the water (a MultiPolygon, several placemarks):
   every part is meshed at one cell size into one grid (:mod:`.mesh_parts`, ``--part N``).
   Lon/lat is projected to the UTM zone of the centroid, or to ``--crs``, relative to a round
   local origin (:func:`meshcore.crs.project`'s ``origin="auto"``, what the app does on
   import): the layout and the grid are computed in these local coordinates, so that the app
   and this command compute them from the same numbers and give the same blocks and grid
   (the layout's discrete choices are not translation invariant to the last bit).  Every
   output holds world coordinates of that CRS (metres, the origin added when writing).
2. **layout** — :func:`meshcore.layout.auto_layout` at the cell size ``--cell-size`` (default
   ``sqrt(water area / 10 000)``, or ``/ --cells``); a ``.ddb`` output asks for a layout
   without 3- or 5-block corners (``--regular``), the only kind Delft3D can couple; so do
   ``-o X.grd --single`` (Delft3D single domain) and ``-o DIR/cell.inp`` (EFDC), whose blocks
   must fit one index space (:mod:`meshcore.multiblock.indexspace`; checked before the solve).
3. **grid** — :func:`meshcore.lakegrid.mesh_layout`, coarse to fine over three levels.
4. **quality** — :func:`meshcore.quality.lake_metrics` against the water polygon, and the
   verdict of each ``--preset``.

Every output is checked before any work (a format meshcore writes, its optional dependency,
an existing writable folder, no path given twice) and again against the layout's block count
before the solve, so an exit 2 leaves no file behind.  Progress goes to stderr; the quality
table and the verdicts to stdout.  Exit codes: 0 a grid without folded cells, 2 bad input
(one line naming the file and the place), 3 a grid was written but has folded cells or did
not converge, 1 an internal error of the pipeline (one line; please report it).
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path
from typing import Any

from ..cellsize import DEFAULT_CELLS
from ..errors import InvalidInputError
from .lakefile import (
    check_crs_option,
    degrees_note,
    in_world,
    lake_parts,
    local_frame,
    lonlat_order_note,
    scale_note,
    swapped_degrees_note,
)
from .mesh_outputs import SINGLE_DOMAIN, check_blocks, single_outputs
from .mesh_steps import (
    LAYOUT_OPTIONS,
    LEVELS,
    MIN_CELLS,
    _cell_size,
    _crs_label,
    _grid,
    _layout,
    _notes,
    _Say,
    check_not_a_line,
    finish,
    guarded,
)


def add_args(p: argparse.ArgumentParser) -> None:
    from ..quality import PRESETS

    p.add_argument(
        "outline",
        help="lake outline (.csv .txt .kml .kmz .gpx .geojson .shp .dxf); inner rings are islands, "
        "separate rings separate parts of the water (each meshed, blocks named part<k>_…)",
    )
    size = p.add_mutually_exclusive_group()
    size.add_argument("--cell-size", type=float, metavar="H", help="cell size in the grid's CRS units (metres)")
    size.add_argument(
        "--cells", type=int, metavar="N", help=f"about N cells: H = sqrt(water area / N) (default {DEFAULT_CELLS})"
    )
    p.add_argument(
        "--crs", default="auto", help="CRS of the grid: auto (UTM zone of the centroid for lon/lat) or EPSG:nnnn"
    )
    p.add_argument("--source-crs", help="CRS of the outline when the file does not say (e.g. a DXF)")
    p.add_argument(
        "--columns", nargs=2, metavar=("X", "Y"), help="CSV: x and y (or lon and lat) column names or 0-based indices"
    )
    p.add_argument(
        "--preset",
        action="append",
        choices=sorted(PRESETS),
        help="print the verdict against a model's limits (repeatable)",
    )
    p.add_argument(
        "--regular",
        action="store_true",
        help="no corner where 3 or 5 blocks meet (what Delft3D domain decomposition couples; implied by .ddb)",
    )
    p.add_argument(
        "--single",
        action="store_true",
        help="-o OUT.grd: the blocks merged into one Delft3D grid with inactive points (+ .enc), for a "
        "single-domain model (implies --regular; refused, exit 2, when the layout does not fit one index space)",
    )
    p.add_argument(
        "--layout-option",
        action="append",
        default=[],
        choices=LAYOUT_OPTIONS,
        metavar="NAME",
        help="a layout choice that is off by default, repeatable (each measured mixed; docs/lake-grids.md): "
        "curve = the shore as a smooth curve through the outline's points (outlines with a point every few "
        "cells), thin-arms = blocks two cells across at junctions of arms 2-4 cells wide, mouths = junction "
        "cuts at the arms' mouths, wedges = two corners beside the tip of an arm tapering to a point, "
        "tees = junctions of regular (.ddb) layouts split as a T, bulges = blocks of regular layouts whose corners "
        "bunch on part of a round basin split, tapers = blocks of default layouts whose opposite sides differ much "
        "(a wedge) split, lookahead = each region's first split the one of its three cheapest whose pieces, split "
        "on, cost least, islands-apart = islands less than three "
        "cells apart kept apart (by default joined into one, the water between given up with a note)",
    )
    p.add_argument(
        "-o",
        "--output",
        action="append",
        default=[],
        metavar="OUT",
        help="grid file, repeatable: .vtm .cgns .xyz (PLOT3D) .ddb (Delft3D DD) .grd with --single (Delft3D "
        "single domain) DIR/cell.inp (EFDC) .npz .su2 .msh .csv "
        "(at least one of -o, --png, --case)",
    )
    p.add_argument("--png", metavar="FIG", help="draw the grid to this figure (.png .svg .pdf)")
    p.add_argument(
        "--case",
        metavar="LAYOUT.toml",
        help="also write the layout as a case file (shore, islands, cuts, blocks): edit it and "
        "'meshcore generate' it again (same grid without edits)",
    )
    p.add_argument(
        "--colour",
        "--color",
        dest="colour",
        choices=("blocks", "deviation"),
        default="blocks",
        help="figure: one colour per block (default) or cells coloured by deviation from 90°",
    )
    p.add_argument(
        "--part",
        action="append",
        type=part_numbers,
        metavar="N",
        help="a file of several separate water parts (listed while reading, largest first): mesh part N "
        "only (repeatable, or a list: --part 1,3); default every part",
    )
    p.add_argument("-q", "--quiet", action="store_true", help="no progress and no quality table")


def part_numbers(text: str) -> list[int]:
    """``--part 2`` or ``--part 1,3``: part numbers (from 1)."""
    try:
        out = [int(t) for t in text.replace(" ", "").split(",") if t]
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r}: part numbers from 1, e.g. 2 or 1,3") from None
    if not out or min(out) < 1:
        raise argparse.ArgumentTypeError(f"{text!r}: part numbers from 1, e.g. 2 or 1,3")
    return out


# ------------------------------------------------------------------ checks before any work
def _check_outputs(args: argparse.Namespace) -> list[tuple[Path, Any]]:
    """Every ``-o`` and ``--png`` checked (format, dependency, folder, not given twice)."""
    from ..io import find_format
    from .generate import check_output, probe_folder

    if not (args.output or args.png or args.case):
        raise InvalidInputError("nothing to write: give -o OUT (a grid file), --png FIG or --case LAYOUT.toml")
    seen: dict[Path, str] = {Path(args.outline).resolve(): f"the outline {args.outline}: write to another name"}
    out = []
    for opt, path in [("-o", o) for o in args.output] + ([("--png", args.png)] if args.png else []):
        p = check_output(path, opt, figure=opt == "--png")
        key = p.resolve()
        if key in seen:
            raise InvalidInputError(f"{opt} {p}: the same file as {seen[key]}")
        seen[key] = f"{opt} {p}"
        if opt == "-o":
            out.append((p, find_format(p, None, role="write")))
    if args.case:
        p = Path(args.case)
        if p.suffix.lower() != ".toml":
            raise InvalidInputError(f"--case {p}: a case file ends in .toml")
        if p.is_dir() or not p.resolve().parent.is_dir():
            raise InvalidInputError(f"--case {p}: {'is a folder' if p.is_dir() else 'its folder does not exist'}")
        if p.resolve() in seen:
            raise InvalidInputError(f"--case {p}: the same file as {seen[p.resolve()]}")
        probe_folder(p, "--case")
    return out


def _check_sizes(args: argparse.Namespace) -> None:
    from .._validation import validate_count, validate_positive

    if args.cell_size is not None:
        validate_positive(args.cell_size, name="--cell-size")
    if args.cells is not None:
        validate_count(args.cells, name="--cells", minimum=MIN_CELLS)


# ------------------------------------------------------------------ stages
def _read(args: argparse.Namespace, say: _Say):
    """The water polygon in local coordinates of the grid's CRS, and its frame (CRS and origin).

    Points projected from lon/lat get the round local origin the app's import gives them
    (:func:`~.lakefile.local_frame`); points kept as they are keep their coordinates (origin 0), as in
    the app.
    """
    from ..crs import is_geographic, normalize_crs
    from ..io import read_points
    from ..layout.polygon import water_polygon

    target = args.crs
    if target.strip().lower() not in ("auto", "none", "local"):
        target = normalize_crs(target)
        if target is not None and is_geographic(target):
            raise InvalidInputError(f"--crs {args.crs}: a geographic CRS (degrees); give a projected one (metres)")
    ps = read_points(args.outline, columns=args.columns, crs=args.source_crs)
    local, frame = local_frame(ps, target, source_crs=args.source_crs)
    if frame.crs is not None and is_geographic(frame.crs):
        raise InvalidInputError(
            f"{args.outline}: coordinates in degrees ({frame.crs}); give --crs auto or a projected EPSG code"
        )
    try:
        parts, dropped = lake_parts(local)
    except InvalidInputError as exc:  # places in the grid's CRS, as the layout's
        raise InvalidInputError(in_world(str(exc), frame)) from None
    said = (
        lonlat_order_note(ps, args.source_crs, args.columns),
        swapped_degrees_note(ps, args.source_crs, args.columns),
        degrees_note(ps, args.source_crs),
    )
    _notes([n for n in (*said, scale_note(ps, frame)) if n], frame)
    _notes(dropped, frame)
    if len(parts) > 1 or args.part:  # several parts of water: meshcore.cli.mesh_parts
        from .mesh_parts import read_parts

        return read_parts(args, parts, frame, say), frame
    _, outer, islands = parts[0]
    try:
        poly, notes = water_polygon(outer, holes=islands)
    except InvalidInputError as exc:
        raise InvalidInputError(in_world(f"{args.outline}: {exc}", frame)) from None
    n_isl = len(islands)
    where = f" from {frame.source_crs}" if frame.source_crs and frame.source_crs != frame.crs else ""
    isl = f"{n_isl} island{'s' * (n_isl != 1)} ({sum(len(r) for r in islands)} points)" if n_isl else "no islands"
    at = _centred(poly, frame)
    say(f"read {args.outline}: shore of {len(outer)} points, {isl}{at}; {_crs_label(frame.crs)}{where}")
    _notes(notes, frame)
    return poly, frame


def _centred(poly: Any, frame: Any) -> str:
    """The centroid ", centroid lon …, lat …" of a file of degrees: where the lake lands, which shows a file whose
    header says lon, lat over latitude, longitude values (both within ±90: a lake elsewhere)."""
    from ..crs import is_geographic

    if not (frame.source_crs and frame.crs and is_geographic(frame.source_crs)):
        return ""
    from .mesh_parts import _user_place

    c = poly.centroid
    return f", centroid {_user_place(c.x, c.y, frame, poly.length)}"


def run(args: argparse.Namespace) -> int:
    from ..crs import normalize_crs, not_a_map

    t_start = time.perf_counter()
    say = _Say(args.quiet)
    _check_sizes(args)
    if args.crs.strip().lower() not in ("auto", "none", "local"):
        try:  # an unknown CRS is refused before the file is read
            why = not_a_map(normalize_crs(args.crs))
        except InvalidInputError as exc:
            raise InvalidInputError(f"--crs {args.crs}: {str(exc).removeprefix('crs: ')}") from None
        if why:
            raise InvalidInputError(f"--crs {args.crs}: {why}; give a projected one (metres)")
    check_crs_option(args.source_crs, "--source-crs")
    outputs = single_outputs(args, _check_outputs(args))
    ddb = [p for p, fmt in outputs if fmt.name == "delft3d-dd"]
    one = [p for p, fmt in outputs if fmt.name in SINGLE_DOMAIN]
    regular = bool(args.regular or ddb or one)
    args.single_space = bool(one)  # the layout's counts close every ring in one index space
    if ddb and not args.regular:
        say(f"{ddb[0]}: Delft3D domain decomposition couples no 3- or 5-block corners: using --regular")
    elif one and not args.regular:
        say(f"{one[0]}: one index space has no 3- or 5-block corners: using --regular")
    poly, frame = _read(args, say)
    if not hasattr(poly, "exterior"):  # water in several parts
        from .mesh_parts import run_parts

        return run_parts(args, poly, frame, say, outputs, regular, t_start)
    unit = " m" if frame.crs else ""
    h, how = _cell_size(args, poly, unit)
    check_not_a_line(args, poly, h, unit, frame)
    say(f"water area {poly.area / 1e6:.4g} km², {how}" if frame.crs else f"water area {poly.area:.6g}, {how}")
    say.lap()

    def make():
        from ..lakegrid import CoarseReadings

        readings = CoarseReadings(levels=LEVELS)  # the chosen layout's coarse level solved once
        lay = _layout(args, poly, h, regular, say, frame, readings)
        check_blocks(outputs, lay)
        return lay, _grid(lay, say, readings)

    made = guarded(args, frame, make)
    if made is None:
        return 1
    lay, mb = made
    if args.case:  # the layout in its local frame (the case's [crs] table holds the origin)
        from ..case import layout_case, save_case
        from .mesh_steps import lake_table

        case = layout_case(lay, crs=frame, description=f"made by meshcore mesh from {args.outline}")
        save_case(case.replaced(lake=lake_table(args, poly, h, regular)), args.case)
        say(f"wrote {args.case} (the layout: edit it and run 'meshcore generate {args.case}')")
    return finish(args, mb, poly, frame, h, outputs, say, t_start)
