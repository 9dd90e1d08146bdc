"""``meshcore quality MESHFILE [--preset NAME]`` — the quality table of each block, and verdicts."""

from __future__ import annotations

import argparse
import dataclasses
import json


def add_args(p: argparse.ArgumentParser) -> None:
    from ..quality import PRESETS

    p.add_argument("mesh", help="mesh file (.vts, .xyz, .npz, ...)")
    p.add_argument("--json", action="store_true", help="print JSON instead of tables")
    p.add_argument(
        "--strict", action="store_true", help="exit 2 if any cell is folded or non-convex (or a preset fails)"
    )
    p.add_argument(
        "--preset",
        action="append",
        choices=sorted(PRESETS),
        help="also print the lake-grid metrics and the verdict against a model's limits (repeatable)",
    )


def run(args: argparse.Namespace) -> int:
    from ..io import read_blocks
    from ..quality import check, lake_metrics, quality

    gs = read_blocks(args.mesh)
    blocks = gs.blocks
    reports = [quality(g) for g in blocks]
    verdicts = []
    if args.preset:  # measured in world coordinates, so the places printed are the file's
        ox, oy = gs.frame.origin
        world = [g.translated(ox, oy) if (ox, oy) != (0.0, 0.0) else g for g in blocks]
        m = lake_metrics(dataclasses.replace(gs, blocks=tuple(world)))
        verdicts = [check(m, name) for name in dict.fromkeys(args.preset)]
    if args.json:
        out = [r.as_dict() for r in reports]
        if verdicts:
            out = {
                "blocks": out,
                "lake_metrics": verdicts[0].metrics.summary(),
                "presets": [v.as_dict() for v in verdicts],
            }
        print(json.dumps(out, indent=2))
    else:
        for k, r in enumerate(reports):
            if len(reports) > 1:
                print(f"block {k + 1}")
            print(r.table())
        if verdicts:
            print("\n" + verdicts[0].metrics.table())
        for v in verdicts:
            print("\n" + v.table())
    if args.strict and not (all(r.ok for r in reports) and all(v.passed for v in verdicts)):
        return 2
    return 0
