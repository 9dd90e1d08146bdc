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
   without 3- or 5-block corners (``--regular``), the only kind Delft3D can couple.
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
import dataclasses
import math
import sys
import time
from pathlib import Path
from typing import Any

from ..cellsize import DEFAULT_CELLS, default_cell_size
from ..errors import InvalidInputError, MeshcoreError
from .lakefile import degrees_note, in_world, lake_parts, local_frame, lonlat_order_note, scale_note
from .mesh_figure import figure as _figure

#: Fewest cells asked for (``--cells``, or the cell size's ``area / H²``).
MIN_CELLS = 16
#: Largest coordinate (after the local origin) the pipeline meshes: a circle of radius 1e75 meshes,
#: one of 1e80 made the layout's triangulation fail (Qhull: "initial simplex is flat"), exit 1.
MAX_COORDINATE = 1e75
#: Coarse levels of the grid sequencing (cell counts are multiples of ``2**LEVELS``).
LEVELS = 2


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
        "--layout-option",
        action="append",
        default=[],
        choices=LAYOUT_OPTIONS,
        metavar="NAME",
        help="a layout choice that is off by default, repeatable (each measured mixed; docs/lake-grids.md): "
        "curve = the shore as a smooth curve through the outline's points (outlines with a point every few "
        "cells), thin-arms = blocks two cells across at junctions of arms 2-4 cells wide, mouths = junction "
        "cuts at the arms' mouths, wedges = two corners beside the tip of an arm tapering to a point",
    )
    p.add_argument(
        "-o",
        "--output",
        action="append",
        default=[],
        metavar="OUT",
        help="grid file, repeatable: .vtm .cgns .xyz (PLOT3D) .ddb (Delft3D DD) .npz .su2 .msh .csv "
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


class _Say:
    """Progress lines on stderr (nothing with ``-q``)."""

    def __init__(self, quiet: bool) -> None:
        self.quiet = quiet
        self.t0 = time.perf_counter()

    def __call__(self, msg: str) -> None:
        if not self.quiet:
            print(msg, file=sys.stderr, flush=True)

    def lap(self) -> float:
        t, self.t0 = self.t0, time.perf_counter()
        return self.t0 - t


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


def _check_blocks(outputs: list[tuple[Path, Any]], lay: Any) -> None:
    """Refuse, before the solve, an output that cannot hold this layout.

    A ``.ddb`` is written once, from the algebraic grids of the layout's blocks, into a
    temporary folder: the couplings (and whether Delft3D can orient them) depend on the
    layout only, so the real write after the solve cannot fail on them.
    """
    n_blocks = len(lay.blocks)
    for p, fmt in outputs:
        if n_blocks > 1 and not fmt.multiblock:
            raise InvalidInputError(
                f"-o {p}: the {fmt.name} format holds one block and the layout has {n_blocks}; "
                f"write .vtm, .cgns, .xyz, .ddb, .npz, .su2 or .msh"
            )
        if fmt.name == "delft3d-dd":
            if n_blocks < 2:
                raise InvalidInputError(f"-o {p}: the layout is one block; write it as .grd, not as a .ddb")
            _dry_run_ddb(p, lay)


def _dry_run_ddb(p: Path, lay: Any) -> None:
    import tempfile

    from ..algebraic import tfi
    from ..errors import WriteError
    from ..io import write

    topo = lay.topology()
    grids = [tfi(b.borders) for b in topo.blocks]
    with tempfile.TemporaryDirectory(prefix="meshcore-mesh-") as d:
        trial = Path(d) / p.name
        try:
            write(trial, grids, block_names=[b.name for b in topo.blocks])
        except WriteError as exc:
            from ..layout.frames import frame_defects

            msg = str(exc).replace(f"{trial}: ", "").replace(str(trial), str(p))
            where = "; ".join(d.note() for d in frame_defects(list(lay.pieces)))
            msg += f"; here {where}" if where else ""
            raise InvalidInputError(f"-o {p}: {msg} (write .vtm, .cgns or .xyz instead)") from None


# ------------------------------------------------------------------ stages
def _crs_label(crs: str | None) -> str:
    if crs is None:
        return "no CRS: the grid keeps the file's coordinates"
    from ..crs import crs_name

    try:
        name = f" ({crs_name(crs)})"
    except Exception:  # a label only: the CRS itself was checked by meshcore.crs
        name = ""
    return f"grid CRS {crs}{name}"


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
    said = (lonlat_order_note(ps, args.source_crs, args.columns), degrees_note(ps, args.source_crs))
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
    say(f"read {args.outline}: shore of {len(outer)} points, {isl}; {_crs_label(frame.crs)}{where}")
    _notes(notes, frame)
    return poly, frame


def _world(mb: Any, poly: Any, frame: Any) -> tuple[Any, Any, Any]:
    """The grid, the water and the frame in world coordinates (origin added, frame origin 0)."""
    from shapely import affinity

    ox, oy = frame.origin
    if ox == 0.0 and oy == 0.0:
        return mb, poly, frame
    grids = tuple(g.replaced(x=g.x + ox, y=g.y + oy) for g in mb.grids)
    world = dataclasses.replace(frame, origin=(0.0, 0.0))
    return dataclasses.replace(mb, grids=grids, frame=world), affinity.translate(poly, ox, oy), world


def _cell_size(args: argparse.Namespace, poly: Any, unit: str) -> tuple[float, str]:
    """The cell size and how it was chosen; refused when the grid would pass the node limit."""
    from .._validation import max_nodes

    big = max(abs(v) for v in poly.bounds)
    if not big <= MAX_COORDINATE:
        raise InvalidInputError(
            f"{args.outline}: coordinates reach {big:.3g}{unit}; meshcore mesh works with coordinates up to "
            f"{MAX_COORDINATE:.0e}: give the outline in larger units"
        )
    area = float(poly.area)
    if args.cell_size is not None:
        h, why = float(args.cell_size), "--cell-size"
    else:
        n = args.cells or DEFAULT_CELLS
        h = default_cell_size(area, n)
        why = f"sqrt(water area / {n})"
    est = area / h / h  # not area / h², which underflows to 0 for h ≈ 1e-200
    if est > max_nodes():
        raise InvalidInputError(
            f"{args.outline}: {why} {h:.4g}{unit} gives about {est:,.0f} cells; the limit is "
            f"{max_nodes():,} nodes (set MESHCORE_MAX_NODES to raise it)"
        )
    if est < MIN_CELLS:
        raise InvalidInputError(
            f"{args.outline}: {why} {h:.4g}{unit} gives about {est:.2g} cells for a water area of "
            f"{area:.4g}{unit + '²' if unit else ''}; give a cell size of at most "
            f"{math.sqrt(area / MIN_CELLS):.4g}{unit}"
        )
    return h, f"cell size {h:.4g}{unit} ({why}, about {est:,.0f} cells)"


def _notes(notes: Any, frame: Any = None) -> None:
    """What the pipeline changed in the water (islands joined or too small): shown even with -q
    (places in the grid's CRS: :func:`in_world`)."""
    for n in notes:
        print(f"meshcore mesh: note: {in_world(n, frame)}", file=sys.stderr)


#: ``--layout-option`` names: the fields of :class:`~meshcore.layout.LayoutOptions`, with dashes.
LAYOUT_OPTIONS = ("curve", "thin-arms", "mouths", "wedges")


def layout_options(args):
    """The :class:`~meshcore.layout.LayoutOptions` that ``--layout-option`` asked for."""
    from ..layout import LayoutOptions

    return LayoutOptions(**{name.replace("-", "_"): True for name in args.layout_option})


def _layout(args, poly, h: float, regular: bool, say: _Say, frame: Any = None):
    from ..layout import LayoutOptions, auto_layout

    options = layout_options(args)
    try:
        lay = auto_layout(poly, cell_size=h, multiple=2**LEVELS, regular=regular, options=options)
    except InvalidInputError as exc:
        msg = in_world(str(exc), frame)
        raise InvalidInputError(msg if msg.startswith(str(args.outline)) else f"{args.outline}: {msg}") from None
    n = len(lay.blocks)
    say(
        f"layout: {n} block{'s' * (n != 1)}, {lay.n_cells:,} cells"
        f"{' (regular: no 3- or 5-block corners)' if regular else ''}"
        f"{f' (options: {options})' if options != LayoutOptions() else ''}, {say.lap():.1f} s"
    )
    _notes(lay.notes, frame)
    return lay


def _grid(lay, say: _Say):
    from ..lakegrid import mesh_layout

    n_levels = LEVELS + 1

    def level(kind: str, value: Any) -> None:
        if kind == "equalize":
            say(f"interfaces: {value} patch(es) of cells more than 2× apart across a cut made alike, {say.lap():.1f} s")
            return
        if kind != "level":
            return
        lev, res = value
        f = 2 ** (LEVELS - lev)
        cells = sum(g.cells[0] * g.cells[1] for g in res.grids)
        scale = f"cells ÷ {f}" if f > 1 else "full"
        say(f"grid level {lev + 1}/{n_levels} ({scale}, {cells:,} cells): {res.sweeps} sweeps, {say.lap():.1f} s")

    return mesh_layout(lay, levels=LEVELS, callback=level)


# ------------------------------------------------------------------ the command
def guarded(args: argparse.Namespace, frame: Any, make):
    """``make()``, its errors told in the grid's CRS (:func:`in_world`); None after an error that is a
    bug of the pipeline, not bad input (one line on stderr, exit 1 for the caller)."""
    try:
        return make()
    except MeshcoreError as exc:
        msg = in_world(str(exc), frame)
        if msg == str(exc):
            raise
        raise type(exc)(msg) from None
    except Exception as exc:
        print(
            f"meshcore mesh: internal error while making the grid of {args.outline} "
            f"({type(exc).__name__}: {' '.join(str(exc).split())[:200]}); please report it with the file",
            file=sys.stderr,
        )
        return None


def run(args: argparse.Namespace) -> int:
    from ..crs import normalize_crs, not_a_map

    t_start = time.perf_counter()
    say = _Say(args.quiet)
    _check_sizes(args)
    if args.crs.strip().lower() not in ("auto", "none", "local"):
        why = not_a_map(normalize_crs(args.crs))  # an unknown CRS is refused before the file is read
        if why:
            raise InvalidInputError(f"--crs {args.crs}: {why}; give a projected one (metres)")
    outputs = _check_outputs(args)
    ddb = [p for p, fmt in outputs if fmt.name == "delft3d-dd"]
    regular = bool(args.regular or ddb)
    if ddb and not args.regular:
        say(f"{ddb[0]}: Delft3D domain decomposition couples no 3- or 5-block corners: using --regular")
    poly, frame = _read(args, say)
    if not hasattr(poly, "exterior"):  # water in several parts
        from .mesh_parts import run_parts

        return run_parts(args, poly, frame, say, outputs, regular, t_start)
    unit = " m" if frame.crs else ""
    h, how = _cell_size(args, poly, unit)
    say(f"water area {poly.area / 1e6:.4g} km², {how}" if frame.crs else f"water area {poly.area:.6g}, {how}")
    say.lap()

    def make():
        lay = _layout(args, poly, h, regular, say, frame)
        _check_blocks(outputs, lay)
        return lay, _grid(lay, say)

    made = guarded(args, frame, make)
    if made is None:
        return 1
    lay, mb = made
    if args.case:  # the layout in its local frame (the case's [crs] table holds the origin)
        from ..case import layout_case, save_case

        save_case(layout_case(lay, crs=frame, description=f"made by meshcore mesh from {args.outline}"), args.case)
        say(f"wrote {args.case} (the layout: edit it and run 'meshcore generate {args.case}')")
    return finish(args, mb, poly, frame, h, outputs, say, t_start)


def finish(
    args, mb, poly, frame, h: float, outputs, say: _Say, t_start: float, per_part: Any = None, left_out=()
) -> int:
    """World coordinates, quality, outputs, figure, table and exit code (``per_part(mb, poly)``:
    lines printed before the table, ``left_out``: parts drawn dashed, for water in several parts)."""
    from shapely import affinity

    from ..io import write
    from ..quality import check, lake_metrics

    left_out = [affinity.translate(p, *frame.origin) for p in left_out]
    mb, poly, frame = _world(dataclasses.replace(mb, frame=frame), poly, frame)
    m = lake_metrics(mb, polygon=poly, cell_size=h)
    n_folded = int(m.values("folded").sum())
    say(f"quality: {n_folded} folded cells, mean deviation from 90° {m.mean('deviation'):.2f}°, {say.lap():.1f} s")
    for p, _ in outputs:
        write(p, mb, crs=frame)
        say(f"wrote {p}")
    if args.png:
        _figure(Path(args.png), mb, poly, frame, args.colour, m, left_out)
        say(f"wrote {args.png}")
    if not args.quiet:
        for line in per_part(mb, poly) if per_part is not None else ():
            print(line)
        print(m.table())
        for name in dict.fromkeys(args.preset or ()):
            print("\n" + check(m, name).table())
        print(f"\n{len(mb.grids)} blocks, {m.summary()['cells']:,} cells in {time.perf_counter() - t_start:.1f} s")
    for w in m.coverage.warnings():  # islands lost or cut across: shown even with -q
        print(f"meshcore mesh: warning: {w}", file=sys.stderr)
    lost = len(m.coverage.islands_lost)
    if n_folded or not mb.converged or lost:
        why = f"{n_folded} folded or non-convex cells" if n_folded else "the solver did not converge"
        why = why if n_folded or not mb.converged else f"{lost} island(s) under the grid"
        print(f"meshcore mesh: warning: {why} (exit code 3)", file=sys.stderr)
        return 3
    return 0
