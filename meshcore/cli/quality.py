"""``meshcore quality MESHFILE`` — the quality table of each block."""

from __future__ import annotations

import argparse
import json


def add_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("mesh", help="mesh file (.vts, .xyz, .npz, ...)")
    p.add_argument("--json", action="store_true", help="print JSON instead of tables")
    p.add_argument("--strict", action="store_true", help="exit 2 if any cell is folded or non-convex")


def run(args: argparse.Namespace) -> int:
    from ..io import read_grid
    from ..quality import quality

    blocks = read_grid(args.mesh)
    reports = [quality(g) for g in blocks]
    if args.json:
        print(json.dumps([r.as_dict() for r in reports], indent=2))
    else:
        for k, r in enumerate(reports):
            if len(reports) > 1:
                print(f"block {k + 1}")
            print(r.table())
    if args.strict and not all(r.ok for r in reports):
        return 2
    return 0
