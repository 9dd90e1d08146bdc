"""Folded cells over many generated water bodies: where does the lake-grid pipeline fold?

Runs :func:`meshcore.layout.auto_layout` and :func:`meshcore.lakegrid.mesh_layout` (what
:func:`meshcore.mesh_outline` does, default options) at the cell size ``sqrt(area / cells)``
on many seeds of every generator of :mod:`meshcore.testing` and prints one row per case:
blocks, thinnest block (its smallest cell count and its narrowest angle), folded cells after
each level (coarse first: a fold present after level 0 comes from the layout or the start),
the share of nodes within 3°, time::

    python benchmarks/fold_sweep.py                      # every family, 6 seeds each
    python benchmarks/fold_sweep.py --only round,islands --seeds 12 --cells 15000
    python benchmarks/fold_sweep.py --layout-only         # blocks and slivers only (fast)
    python benchmarks/fold_sweep.py --only islands,round --regular   # Delft3D DD layouts

``--json FILE`` writes the rows for comparisons between versions.  The cases run in one
process, one after another (the kernels compile once); an exception is one failed row.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time
import traceback
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))


def families(seeds: int) -> dict[str, list[tuple[str, object]]]:
    """Case builders per family: ``{family: [(name, () -> Polygon)]}``."""
    from meshcore import testing as t

    def y(k):
        rng = np.random.default_rng(1000 + k)
        return lambda: t.y_junction(
            arm=float(rng.uniform(4, 8)), width=float(rng.uniform(0.6, 1.6)), angle0=float(rng.uniform(0, 120))
        )

    out: dict[str, list] = {
        "network": [
            (f"channel_network({s}, n_branches={4 + s % 4})", _f(t.channel_network, s, n_branches=4 + s % 4))
            for s in range(seeds)
        ],
        "rough": [
            (f"channel_network({100 + s}, roughness=0.15)", _f(t.channel_network, 100 + s, roughness=0.15))
            for s in range(seeds)
        ],
        "islands": [(f"lake_with_islands({s})", _f(t.lake_with_islands, s)) for s in range(seeds)],
        "Y": [(f"y_junction #{k}", y(k)) for k in range(max(1, seeds // 2))],
        "spiral": [(f"spiral({1.0 + 0.25 * k:.2f})", _f(t.spiral, 1.0 + 0.25 * k)) for k in range(max(1, seeds // 2))],
        "textbook": [("straight_channel()", t.straight_channel), ("rectangle_with_hole()", t.rectangle_with_hole)],
    }
    for kind in ("disc", "blob", "ring", "arms"):
        out[f"round {kind}"] = [
            (f"round_lake({s}, kind={kind!r})", _f(t.round_lake, s, kind=kind)) for s in range(seeds)
        ]
    out["jagged"] = (
        [(f"jagged_cells(y_junction(), 1.4, {s})", _jag(t.y_junction, (), s)) for s in range(max(1, seeds // 2))]
        + [
            (
                f"jagged_cells(channel_network({s + 1}, n_branches=5), 1.4, {s})",
                _jag(t.channel_network, (s + 1,), s, n_branches=5),
            )
            for s in range(max(1, seeds // 2))
        ]
        + [
            (f"jagged_cells(round_lake({s + 5}, n_islands=1), 1.4, {s})", _jag(t.round_lake, (s + 5,), s, n_islands=1))
            for s in range(max(1, seeds // 2))
        ]
    )
    return out


def _f(fn, *args, **kw):
    return lambda: fn(*args, **kw)


def _jag(fn, args, seed, **kw):
    from meshcore import testing as t

    return lambda: t.jagged_cells(fn(*args, **kw), 1.4, seed)


def sliver_stats(layout) -> tuple[int, float]:
    """The smallest cell count of any block and the narrowest block corner (degrees: 180 minus
    the turning of the piece's boundary there, measured over one cell of arc length)."""
    from meshcore.layout.corners import turning

    few = min(min(b.cells) for b in layout.blocks)
    ang = min(180.0 - float(turning(pc.ring, layout.cell_size)[list(pc.corners)].max()) for pc in layout.pieces)
    return few, ang


def run_case(poly, cells: int, layout_only: bool, regular: bool = False) -> dict:
    from meshcore.lakegrid import mesh_layout
    from meshcore.layout import auto_layout
    from meshcore.quality import lake_metrics
    from meshcore.quality.lake import block_metrics

    h = math.sqrt(poly.area / cells)
    c0, t0 = time.process_time(), time.perf_counter()
    lay = auto_layout(poly, cell_size=h, multiple=4, regular=regular)
    few, ang = sliver_stats(lay)
    row = {"blocks": len(lay.blocks), "fewest_cells": few, "narrowest_deg": round(ang, 1)}
    row["layout_s"] = round(time.perf_counter() - t0, 2)
    if layout_only:
        return row
    per_level: list[int] = []

    def cb(kind, payload):
        if kind != "level":
            return
        _lev, res = payload
        per_level.append(sum(int(block_metrics(g).folded.sum()) for g in res.grids))

    mb = mesh_layout(lay, levels=2, callback=cb)
    m = lake_metrics(mb, polygon=poly)
    row.update(
        cells=int(m.summary()["cells"]),
        folded=int(m.values("folded").sum()),
        folded_levels=per_level,
        within3=round(100 * m.share("deviation", 3.0), 1),
        repaired="repaired" in mb.info.message,
        wall_s=round(time.perf_counter() - t0, 1),
        cpu_s=round(time.process_time() - c0, 1),
    )
    return row


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument(
        "--only",
        help="comma-separated family names (network, rough, islands, Y, spiral, "
        "textbook, round disc, round blob, round ring, round arms, jagged) or fragments",
    )
    ap.add_argument("--seeds", type=int, default=6)
    ap.add_argument("--cells", type=int, default=15000)
    ap.add_argument("--layout-only", action="store_true")
    ap.add_argument("--regular", action="store_true", help="regular layouts (Delft3D domain decomposition)")
    ap.add_argument("--json", help="write the rows here")
    a = ap.parse_args(argv)
    fam = families(a.seeds)
    only = [o.strip() for o in a.only.split(",")] if a.only else None
    rows = []
    print(f"# fold sweep, {a.cells} cells{', regular' if a.regular else ''}, load {os.getloadavg()[0]:.1f}", flush=True)
    print("| case | blocks | fewest cells | narrowest ° | folded | per level | within 3° % | s (CPU) |")
    print("|---|---|---|---|---|---|---|---|", flush=True)
    for name_f, cases in fam.items():
        if only and not any(o in name_f for o in only):
            continue
        for name, build in cases:
            try:
                r = run_case(build(), a.cells, a.layout_only, a.regular)
            except Exception as exc:
                r = {"error": f"{type(exc).__name__}: {exc}"[:160]}
                traceback.print_exc(limit=3)
            r.update(family=name_f, case=name)
            rows.append(r)
            if "error" in r:
                print(f"| {name} | error: {r['error']} |", flush=True)
                continue
            print(
                f"| {name} | {r['blocks']} | {r['fewest_cells']} | {r['narrowest_deg']} | {r.get('folded', '–')} | "
                f"{r.get('folded_levels', '–')} | {r.get('within3', '–')} | {r.get('cpu_s', r['layout_s'])} |",
                flush=True,
            )
    ok = [r for r in rows if "error" not in r]
    folded = [r for r in ok if r.get("folded")]
    print(
        f"\n{len(rows)} cases, {len(rows) - len(ok)} errors, {len(folded)} with folds "
        f"({sum(r['folded'] for r in folded)} cells); load {os.getloadavg()[0]:.1f}",
        flush=True,
    )
    if a.json:
        Path(a.json).write_text(json.dumps(rows, indent=1), encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
