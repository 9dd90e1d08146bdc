"""``meshcore convert IN OUT`` — convert a grid file to another format.

Reads any grid format (PLOT3D, .vts, .vtm, .npz, .cgns, .grd, .ddb, .nc, EFDC cell.inp, metrics
CSV) and writes any format (the ones above plus .msh, .su2, figures), keeping
the CRS, local origin, block and border names where both formats hold them.
"""

from __future__ import annotations

import argparse


def add_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("input", help="grid file to read")
    p.add_argument("output", help="file to write; the format comes from the suffix")
    p.add_argument(
        "--format",
        help="output format name overriding the suffix "
        "(plot3d, vts, vtm, npz, metrics-csv, cgns, gmsh, su2, delft3d, sgrid, figure)",
    )
    p.add_argument("--input-format", help="input format name overriding the suffix")
    p.add_argument("--mode", choices=["ascii", "fortran", "binary"], help="PLOT3D encoding (default fortran)")
    p.add_argument("--crs", help="CRS of the input coordinates when the file does not say (EPSG code or string)")
    p.add_argument("--lonlat", action="store_true", help="Delft3D .grd: write longitude/latitude (Spherical)")


def run(args: argparse.Namespace) -> int:
    from pathlib import Path

    from ..crs import Frame, normalize_crs
    from ..errors import InvalidInputError
    from ..io import GridSet, read_blocks, write

    if Path(args.output).resolve() == Path(args.input).resolve():
        raise InvalidInputError(f"{args.output}: the same file as the input: write to another name")
    gs = read_blocks(args.input, format=args.input_format)
    if args.crs and gs.frame.crs is None:
        gs = GridSet(
            gs.blocks, Frame(normalize_crs(args.crs), gs.frame.origin), gs.block_names, gs.connectivity, gs.source
        )
    opts = {}
    if args.mode:
        opts["mode"] = args.mode
    if args.lonlat:
        opts["lonlat"] = True
    out = write(args.output, gs, format=args.format, **opts)
    n = sum(g.n_nodes for g in gs.blocks)
    print(
        f"{args.input} -> {out}: {len(gs.blocks)} block(s), {n} nodes" + (f", {gs.frame.crs}" if gs.frame.crs else "")
    )
    return 0
