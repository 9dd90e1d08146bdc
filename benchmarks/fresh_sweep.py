"""Lake grids on generated water bodies of seeds nobody has tuned anything to.

The development sweeps (``interface_sweep.py``, the tests) use fixed seeds, and every rule of
the layout was checked on them: a rule can fit those shapes and fail on the next.  This runs
:func:`meshcore.mesh_outline` (default options, or ``--regular``) on the same families of
:mod:`meshcore.testing` — channel networks (also with arms narrower than two cells and rough
shores), lobed lakes with six to ten islands, round lakes with islands, jagged networks, a tight
spiral (with ``--more``: headlands, dendritic reservoirs, thin peninsulas, small islands, shores
sampled densely or coarsely, :func:`more_cases`) — with seeds from ``--base`` (default: a new
random base, printed, so that a run can be repeated), and prints one row per shape, the
issue-12 targets met, and every error: a ``MeshcoreError`` (a clear message, allowed) or anything else (a bug)::

    python benchmarks/fresh_sweep.py [--base N] [--cells 15000] [--regular] [--more] [--options JSON] [--json OUT]
"""

from __future__ import annotations

import argparse
import json
import random
import sys
import time
import traceback
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import interface_sweep
from lake_grids import SHORTEST


def cases(base: int) -> dict[str, str]:
    """Name → expression in :mod:`meshcore.testing` for seeds from ``base``."""
    out: dict[str, str] = {}
    for k in range(12):
        s = base + k
        out[f"net {s}"] = f"testing.channel_network({s}, n_branches={3 + k % 6})"
    for k in range(6):
        s = base + 100 + k
        out[f"narrow net {s}"] = f"testing.channel_network({s}, n_branches=5, width=(0.3, 1.0))"
        s = base + 200 + k
        out[f"rough net {s}"] = f"testing.channel_network({s}, n_branches=4, width=(1.0, 3.0), roughness=0.15)"
    for k in range(8):
        s = base + 300 + k
        out[f"islands {s}"] = f"testing.lake_with_islands({s}, n_islands={6 + k % 5}, lobes={4 + k % 5})"
        s = base + 400 + k
        kind = ("blob", "arms", "ring", "disc")[k % 4]
        out[f"round {kind} {s}"] = f"testing.round_lake({s}, kind={kind!r}, n_islands=5)"
    for k in range(4):
        s = base + 500 + k
        out[f"jagged net {s}"] = (
            f"testing.jagged(testing.channel_network({s}, n_branches=4, width=(1.0, 2.5)), 0.08, seed={s})"
        )
    out["spiral 2.5 turns"] = "testing.spiral(turns=2.5, width=0.7, gap=1.2)"
    return out


def more_cases(base: int) -> dict[str, str]:
    """The ``--more`` set: what a real lake has and :func:`cases` does not — rounded headlands
    with islands off their tips, dendritic reservoirs (arms under two cells wide, long thin
    ridges), islands near the shore and each other, thin peninsulas, and shores sampled
    densely (12 000 points) or coarsely (20 points)."""
    out: dict[str, str] = {}
    for k in range(6):
        s = base + 600 + k
        out[f"headlands {s}"] = f"testing.headlands({s}, n={6 + k % 5})"
        s = base + 700 + k
        out[f"dendritic {s}"] = f"testing.dendritic({s})"
    for k in range(4):
        s = base + 800 + k
        out[f"peninsulas {s}"] = f"testing.small_islands({s}, n_islands=4, peninsulas=4, widths=(0.5, 3.0))"
    for k in range(3):
        s = base + 850 + k
        out[f"small islands {s}"] = f"testing.small_islands({s}, n_islands=10)"
    for k in range(2):
        s = base + 900 + k
        out[f"dense islands {s}"] = f"testing.resampled(testing.lake_with_islands({s}, n_islands=6), 12000)"
        s = base + 910 + k
        out[f"dense net {s}"] = f"testing.resampled(testing.channel_network({s}, n_branches=5), 12000)"
        s = base + 920 + k
        out[f"coarse round {s}"] = f"testing.resampled(testing.round_lake({s}, kind='blob', n_islands=2), 20)"
        s = base + 930 + k
        out[f"coarse net {s}"] = f"testing.resampled(testing.channel_network({s}, n_branches=3, width=(1.0, 2.0)), 20)"
    return out


def main(argv: list[str] | None = None) -> int:
    from meshcore.errors import MeshcoreError

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--base", type=int, help="first seed (default: random, printed)")
    ap.add_argument("--cells", type=int, default=15000)
    ap.add_argument("--regular", action="store_true", help="Delft3D domain-decomposition layouts")
    ap.add_argument("--json", help="write the results here")
    ap.add_argument("--more", action="store_true", help="the other set (more_cases): headlands, dendritic, ...")
    ap.add_argument("--options", default="{}", help="more options of mesh_outline as JSON")
    a = ap.parse_args(argv)
    base = a.base if a.base is not None else random.SystemRandom().randrange(10_000, 1_000_000, 1000)
    options = {"regular": True} if a.regular else {}
    options.update(json.loads(a.options))
    more = (", regular" if a.regular else "") + (f", {a.options}" if a.options != "{}" else "")
    print(f"seeds from {base}, {a.cells} cells{more}\n")
    print(interface_sweep.HEAD)
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    res: dict[str, dict] = {}
    todo = more_cases(base) if a.more else cases(base)
    for name, expr in todo.items():
        t = time.process_time()
        try:
            r = interface_sweep.run_one(expr, a.cells, options)
        except MeshcoreError as exc:
            r = {"clear_error": str(exc)[:300]}
            print(f"| {name} | error (clear): {r['clear_error']} |", flush=True)
        except Exception as exc:  # a bug: the traceback's end
            r = {"bug": f"{type(exc).__name__}: {exc}", "where": traceback.format_exc()[-800:]}
            print(f"| {name} | BUG: {r['bug'][:200]} |", flush=True)
        else:
            places = " ".join(f"{k}:{v}" for k, v in sorted(r["places"].items()))
            print(
                f"| {name} | {r['blocks']} | {r['max_ratio']:.2f} | {r['pct_le_2']:.1f} | {r['worst_at']} | "
                f"{places} | {r['folded']} | {r['within3']:.1f} | {r['mean_dev']:.2f} | {r['pairs12']:.1f} | "
                f"{r['shore']:.2f} | {r['cpu']:.1f} |",
                flush=True,
            )
        r["cpu_total"] = time.process_time() - t
        r["expr"] = expr
        res[name] = r
    ok = [r for r in res.values() if "blocks" in r]
    n = len(todo)
    print(
        f"\n{n} shapes (seeds from {base}): grid {len(ok)}, clear errors "
        f"{sum('clear_error' in r for r in res.values())}, bugs {sum('bug' in r for r in res.values())}; "
        f"0 folded cells {sum(r['folded'] == 0 for r in ok)}, ≥ 90 % within 3° {sum(r['within3'] >= 90 for r in ok)}, "
        f"mean deviation ≤ 3° {sum(r['mean_dev'] <= 3 for r in ok)}, |cos| ≤ 0.02 at ≥ 80 % "
        f"{sum(r['cos02'] >= 80 for r in ok)}, edge pairs ≥ 95 % "
        f"{sum(r['pairs12'] >= 95 for r in ok)}, every interface ratio ≤ 2 {sum(r['max_ratio'] <= 2 for r in ok)}, "
        f"shore ≤ 0.5 cells {sum(r['shore'] <= 0.5 for r in ok)}, shortest edge ≥ {SHORTEST} cells "
        f"{sum(r['min_edge'] >= SHORTEST for r in ok)}; CPU median "
        f"{np.median([r['cpu'] for r in ok]) if ok else float('nan'):.1f} s, max "
        f"{max((r['cpu'] for r in ok), default=float('nan')):.1f} s",
        flush=True,
    )
    if a.json:
        with open(a.json, "w", encoding="utf-8") as f:
            json.dump({"base": base, "cells": a.cells, "regular": a.regular, "results": res}, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
