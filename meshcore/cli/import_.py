"""``meshcore import POINTS -o CASE.toml`` — a case file from a shoreline point file.

Reads POINTS (CSV/TXT, KML/KMZ, GeoJSON, shapefile, DXF), projects lon/lat to
the UTM zone of the centroid (``--crs auto``, the default) or to a given EPSG
code, moves the points to a local origin, picks the outline (the longest ring,
or ``--polyline NAME``), four corners (``--corners`` or a guess along the
principal axes) and cell counts (``--cells``, or about 10 000 cells of ``meshcore mesh``'s default
cell size ``sqrt(area / 10 000)``, ``ni : nj`` the ratio at which the Winslow grid's median cell
is square: :func:`meshcore.cellratio.cell_ratio`), and
writes a case file whose top-level ``crs`` table records the CRS and origin.

Input is refused where it is typed: corner indices out of range, repeated or
not in cyclic order, cell counts below 1 or beyond the node limit, an unknown
CRS; an outline with islands inside it is refused unless ``--ignore-islands``
(one structured block cannot leave an island out).
"""

from __future__ import annotations

import argparse


def add_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("points", help="point file (.csv .txt .xy .kml .kmz .gpx .geojson .shp .dxf)")
    p.add_argument("-o", "--output", required=True, help="case file to write (.toml)")
    p.add_argument(
        "--crs", default="auto", help="target CRS: auto (UTM of the centroid for lon/lat), an EPSG code, or none"
    )
    p.add_argument("--source-crs", help="CRS of the input when the file does not say")
    p.add_argument(
        "--columns", nargs=2, metavar=("X", "Y"), help="CSV: x and y (or lon and lat) column names or 0-based indices"
    )
    p.add_argument("--polyline", help="name of the polyline to use (default: the longest ring)")
    p.add_argument(
        "--corners",
        nargs=4,
        type=int,
        metavar=("SW", "SE", "NE", "NW"),
        help="corner point indices on the loop (default: guessed)",
    )
    p.add_argument(
        "--cells",
        nargs=2,
        type=int,
        metavar=("NI", "NJ"),
        help="cell counts (default: about 10 000 near-square cells of size sqrt(area / 10 000), as meshcore mesh)",
    )
    p.add_argument("--name", help="block name (default: the polyline's name)")
    p.add_argument(
        "--border-name",
        action="append",
        default=[],
        metavar="BORDER=NAME",
        help="name a border, e.g. bottom=inlet (repeatable)",
    )
    p.add_argument("--title", help="case title")
    p.add_argument(
        "--ignore-islands",
        action="store_true",
        help="grid over islands (inner rings) of the outline instead of refusing them",
    )


def _cells(values: list[int] | None) -> tuple[int, int] | None:
    """``--cells NI NJ``, refused where typed: counts ≥ 1 and a grid within the node limit."""
    from .._validation import check_grid_size, validate_count

    if values is None:
        return None
    ni, nj = (validate_count(v, name=f"--cells {nm}") for v, nm in zip(values, ("NI", "NJ"), strict=True))
    check_grid_size(ni, nj, what="--cells")
    return ni, nj


def _islands(outline, polylines) -> list:
    """Closed rings lying inside ``outline`` (islands of a lake; holes of a polygon)."""
    import shapely

    poly = shapely.Polygon(outline.points)
    if not poly.is_valid:
        poly = poly.buffer(0)
    out = []
    for pl in polylines:
        if pl is outline or not pl.closed or len(pl) < 3:
            continue
        if poly.contains(shapely.Point(*pl.points[0])) and shapely.Polygon(pl.points).area < poly.area:
            out.append(pl)
    return out


def _corners(args: argparse.Namespace, loop, where: str) -> tuple[int, int, int, int]:
    """``--corners`` checked where typed (in range, distinct, in cyclic order), or guessed."""
    from ..boundary import borders_from_loop
    from ..io.outline import guess_corners

    if not args.corners:
        return guess_corners(loop)
    borders_from_loop(loop, args.corners, check_intersections=False, where=f"{where}: --corners")
    return tuple(int(c) % len(loop) for c in args.corners)  # type: ignore[return-value]


def run(args: argparse.Namespace) -> int:
    import re
    import sys
    from pathlib import Path

    from ..boundary import BorderSpec
    from ..case import Case, save_case
    from ..crs import project
    from ..errors import InvalidInputError
    from ..grid import BORDER_NAMES
    from ..io import read_points
    from ..io.outline import guess_cells
    from ..layout.polygon import water_polygon
    from ..spec import BlockSpec
    from .lakefile import in_world

    cells = _cells(args.cells)
    out_path = Path(args.output)
    if out_path.suffix.lower() != ".toml":  # a typo such as -o lake.csv would overwrite a point file
        raise InvalidInputError(f"-o {out_path}: a case file ends in .toml")
    specs = {}
    for item in args.border_name:
        b, _, nm = item.partition("=")
        if b not in BORDER_NAMES or not nm:
            raise InvalidInputError(f"--border-name expects BORDER=NAME with BORDER in {BORDER_NAMES}, got {item!r}")
        specs[b] = BorderSpec(name=nm)
    from .lakefile import check_crs_option, lonlat_order_note, swapped_degrees_note

    check_crs_option(args.source_crs, "--source-crs")
    check_crs_option(args.crs, "--crs")
    ps = read_points(args.points, columns=args.columns, crs=args.source_crs)

    said = (
        lonlat_order_note(ps, args.source_crs, args.columns),
        swapped_degrees_note(ps, args.source_crs, args.columns),
    )
    for note in said:
        if note:  # as meshcore mesh says them (was: none here, a swapped file imported in silence)
            print(f"meshcore import: note: {note}", file=sys.stderr)
    local, frame = project(ps, None if args.crs.lower() == "none" else args.crs, source_crs=args.source_crs)
    if args.polyline:
        pl = local[args.polyline] if args.polyline in local.names else None
        if pl is None:
            raise InvalidInputError(f"{args.points}: no polyline named {args.polyline!r} (have {list(local.names)})")
    else:
        rings = [p for p in local.polylines if p.closed]
        pl = max(rings or list(local.polylines), key=len)
    where = f"{args.points}: {pl.name!r}"
    islands = _islands(pl, local.polylines) if pl.closed else []
    if islands:
        listed = ", ".join(repr(p.name) for p in islands[:3]) + (" …" if len(islands) > 3 else "")
        if not args.ignore_islands:
            raise InvalidInputError(
                f"{where} has {len(islands)} island(s) inside it ({listed}); one structured block cannot "
                f"leave them out: pass --ignore-islands to grid over them, or split the lake into blocks "
                f"around them (a multiblock case)"
            )
        print(
            f"meshcore import: warning: {where}: the grid covers {len(islands)} island(s) ({listed})", file=sys.stderr
        )
    others = [p for p in local.polylines if p is not pl and p.closed and all(p is not i for i in islands)]
    if others and not args.polyline:  # was: left out without a word (a second lake, a ring across the shore)
        listed = ", ".join(repr(p.name) for p in others[:3]) + (" …" if len(others) > 3 else "")
        print(
            f"meshcore import: note: {where} is imported (the ring of most points, one block); {len(others)} other "
            f"ring(s) outside it or across its shore left out ({listed}); meshcore mesh reads every ring",
            file=sys.stderr,
        )
    loop = pl.points
    try:
        poly, _ = water_polygon(loop)  # the loop crossing itself or of no area is refused here, not by generate
        corners = _corners(args, loop, where)
        if not cells:
            cells = guess_cells(loop, corners)
            _not_a_line(poly, cells, " m" if frame.crs else "")
    except InvalidInputError as exc:
        msg = in_world(str(exc), frame)  # places in the file's CRS, as meshcore mesh names them
        if len(loop) == 3:  # a triangle has no four corners; meshcore mesh (and the app's Auto layout) grid it
            msg += "; meshcore mesh grids a lake of 3 points in blocks of its own (or add a point)"
        raise type(exc)(msg if msg.startswith(where) else f"{where}: {msg}") from None
    name = args.name or re.sub(r"[^\w-]+", "_", pl.name).strip("_") or "lake"
    crs_tbl = frame.as_dict()
    crs_tbl["source"] = str(Path(args.points).name)
    case = Case(
        blocks=(BlockSpec(name=name, cells=cells, points=loop, corners=corners, borders=specs),),
        title=args.title or f"{pl.name} (imported from {Path(args.points).name})",
        crs=crs_tbl,
    )
    out = save_case(case, args.output)
    print(
        f"{args.points}: {len(loop)} points of {pl.name!r} -> {out}: "
        f"{frame.crs or 'no CRS'}, origin {frame.origin}, corners {list(corners)}, "
        f"cells {list(cells)}"
    )
    return 0


def _not_a_line(poly, cells, unit: str) -> None:
    """Refuse a loop narrower where it is widest than the cells guessed for it (points on one line
    but for their rounding: a block a few centimetres wide, which ``generate`` then solved); cells
    given with ``--cells`` are the user's."""
    import math

    from ..errors import InvalidInputError
    from ..lakeparts import on_one_line

    why = on_one_line(poly, math.sqrt(poly.area / (cells[0] * cells[1])), unit)
    if why:
        why = why.split("; if it is water")[0].replace("its area gives", "the guessed cells give")
        raise InvalidInputError(f"{why}; if it is water, give --cells NI NJ with at least 3 cells across")
