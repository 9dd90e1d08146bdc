"""Lake grids on rivers: meandering reaches, reaches with bars, confluences, estuaries.

Runs :func:`meshcore.mesh_outline` (default options) on the river families of
:mod:`meshcore.testing.rivers` — ``--seeds`` seeds each from ``--base`` (meander ``base + k``,
bars ``base + 100 + k``, confluence ``base + 200 + k``, estuary ``base + 300 + k``) — at
``--cells`` cells, and prints per shape the targets of issue 12: folded cells, % of nodes within
3°, mean deviation, % of edge pairs ≤ 1.2, the largest cross-interface area ratio, the shore
distance (cells), the fewest cells of a block either way (≥ 3 wanted), the cells over area / H²,
CPU; then how many shapes meet each target, per family::

    python benchmarks/river_sweep.py [--base 810000] [--seeds 10] [--cells 10000] [--only meander]
        [--options JSON] [--json OUT]
"""

from __future__ import annotations

import argparse
import json
import sys
import time
import traceback
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import interface_sweep

FAMILIES = {"meander": 0, "meander_bars": 100, "confluence": 200, "estuary": 300}


def cases(base: int, seeds: int, only: str | None = None) -> dict[str, tuple[str, str]]:
    """Name → (family, expression in :mod:`meshcore.testing`)."""
    out: dict[str, tuple[str, str]] = {}
    for fam, off in FAMILIES.items():
        if only and not any(o == fam for o in only.split(",")):
            continue
        for k in range(seeds):
            s = base + off + k
            out[f"{fam} {s}"] = (fam, f"testing.{fam}({s})")
    return out


def main(argv: list[str] | None = None) -> int:
    from meshcore.errors import MeshcoreError

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--base", type=int, default=810000)
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--cells", type=int, default=10000)
    ap.add_argument("--only", help="comma-separated families")
    ap.add_argument("--options", default="{}", help="more options of mesh_outline as JSON")
    ap.add_argument("--json", help="write the results here")
    a = ap.parse_args(argv)
    options = json.loads(a.options)
    if isinstance(options.get("layout_options"), dict):  # {"layout_options": {"mouths": true}}
        from meshcore.layout.model import LayoutOptions

        options["layout_options"] = LayoutOptions(**options["layout_options"])
    print(f"rivers, seeds from {a.base}, {a.cells} cells{', ' + a.options if options else ''}\n")
    print(
        "| shape | blocks | folded | ≤ 3° % | mean ° | e ≤ 1.2 % | max ratio | shore | min block | cells/(A/H²) ",
        end="",
    )
    print("| CPU s |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    res: dict[str, dict] = {}
    for name, (fam, expr) in cases(a.base, a.seeds, a.only).items():
        t = time.process_time()
        try:
            r = interface_sweep.run_one(expr, a.cells, options)
        except MeshcoreError as exc:
            r = {"clear_error": str(exc)[:300]}
            print(f"| {name} | error (clear): {r['clear_error']} |", flush=True)
        except Exception as exc:  # a bug
            r = {"bug": f"{type(exc).__name__}: {exc}", "where": traceback.format_exc()[-1200:]}
            print(f"| {name} | BUG: {r['bug'][:200]} |", flush=True)
        else:
            print(
                f"| {name} | {r['blocks']} | {r['folded']} | {r['within3']:.1f} | {r['mean_dev']:.2f} | "
                f"{r['pairs12']:.1f} | {r['max_ratio']:.2f} | {r['shore']:.2f} | {r['min_block']} | "
                f"{r['cells_ratio']:.2f} | {r['cpu']:.1f} |",
                flush=True,
            )
        r["family"], r["expr"], r["cpu_total"] = fam, expr, time.process_time() - t
        res[name] = r
    print()
    for fam in FAMILIES:
        rs = [r for r in res.values() if r["family"] == fam]
        if not rs:
            continue
        ok = [r for r in rs if "blocks" in r]
        print(
            f"{fam}: {len(rs)} shapes, grid {len(ok)}, clear errors {sum('clear_error' in r for r in rs)}, "
            f"bugs {sum('bug' in r for r in rs)}; 0 folded {sum(r['folded'] == 0 for r in ok)}, "
            f"≥ 90 % within 3° {sum(r['within3'] >= 90 for r in ok)}, mean ≤ 3° {sum(r['mean_dev'] <= 3 for r in ok)}, "
            f"pairs ≥ 95 % {sum(r['pairs12'] >= 95 for r in ok)}, ratio ≤ 2 {sum(r['max_ratio'] <= 2 for r in ok)}, "
            f"shore ≤ 0.5 {sum(r['shore'] <= 0.5 for r in ok)}, blocks ≥ 3 {sum(r['min_block'] >= 3 for r in ok)}, "
            f"cells 0.5–2× {sum(0.5 <= r['cells_ratio'] <= 2 for r in ok)}; CPU median "
            f"{np.median([r['cpu'] for r in ok]) if ok else float('nan'):.1f} s, max "
            f"{max((r['cpu'] for r in ok), default=float('nan')):.1f} s",
            flush=True,
        )
    if a.json:
        with open(a.json, "w", encoding="utf-8") as f:
            json.dump({"base": a.base, "cells": a.cells, "options": a.options, "results": res}, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
