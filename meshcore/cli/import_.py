"""``meshcore import POINTS -o CASE.toml`` — a case file from a shoreline point file.

Reads POINTS (CSV/TXT, KML/KMZ, GeoJSON, shapefile, DXF), projects lon/lat to
the UTM zone of the centroid (``--crs auto``, the default) or to a given EPSG
code, moves the points to a local origin, picks the outline (the longest ring,
or ``--polyline NAME``), four corners (``--corners`` or a guess along the
principal axes) and cell counts (``--cells`` or roughly square cells), and
writes a case file whose top-level ``crs`` table records the CRS and origin.
"""

from __future__ import annotations

import argparse


def add_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("points", help="point file (.csv .txt .xy .kml .kmz .geojson .shp .dxf)")
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
        help="cell counts (default: 40 along the long sides, square cells)",
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


def run(args: argparse.Namespace) -> int:
    import re
    from pathlib import Path

    from ..boundary import BorderSpec
    from ..case import BlockCase, Case, save_case
    from ..crs import project
    from ..errors import InvalidInputError
    from ..grid import BORDER_NAMES
    from ..io import read_points
    from ..io.outline import guess_cells, guess_corners

    ps = read_points(args.points, columns=args.columns)
    local, frame = project(ps, None if args.crs.lower() == "none" else args.crs, source_crs=args.source_crs)
    if args.polyline:
        pl = local[args.polyline] if args.polyline in local.names else None
        if pl is None:
            raise InvalidInputError(f"{args.points}: no polyline named {args.polyline!r} (have {list(local.names)})")
    else:
        rings = [p for p in local.polylines if p.closed]
        pl = max(rings or list(local.polylines), key=len)
    loop = pl.points
    corners = tuple(args.corners) if args.corners else guess_corners(loop)
    cells = tuple(args.cells) if args.cells else guess_cells(loop, corners)
    specs = {}
    for item in args.border_name:
        b, _, nm = item.partition("=")
        if b not in BORDER_NAMES or not nm:
            raise InvalidInputError(f"--border-name expects BORDER=NAME with BORDER in {BORDER_NAMES}, got {item!r}")
        specs[b] = BorderSpec(name=nm)
    name = args.name or re.sub(r"[^\w-]+", "_", pl.name).strip("_") or "lake"
    crs_tbl = frame.as_dict()
    crs_tbl["source"] = str(Path(args.points).name)
    case = Case(
        blocks=(BlockCase(name=name, cells=cells, loop=loop, corners=corners, border_specs=specs),),
        title=args.title or f"{pl.name} (imported from {Path(args.points).name})",
        extra={"crs": crs_tbl},
    )
    out = save_case(case, args.output)
    print(
        f"{args.points}: {len(loop)} points of {pl.name!r} -> {out}: "
        f"{frame.crs or 'no CRS'}, origin {frame.origin}, corners {list(corners)}, "
        f"cells {list(cells)}"
    )
    return 0
