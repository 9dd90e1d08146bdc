"""Cross-interface cell-area ratio over many generated water bodies, and where it is worst.

Runs :func:`meshcore.mesh_outline` with default options on shapes of :mod:`meshcore.testing`
(random channel networks, Y junctions at several angles, lobed lakes with islands, round
lakes of every kind, jagged shores), none of them a shipped lake, and prints per case the
largest cross-interface area ratio, the share of interface pairs ≤ 2, the other targets of
issue 12, and what lies at the worst pair: a cut line ending on the shore (``shore-end``), a
node where 3 or 5 blocks meet (``star``), or neither (``interior``: counts or smoothing)::

    python benchmarks/interface_sweep.py --cells 15000 [--only net,y] [--json /tmp/s.json]
"""

from __future__ import annotations

import argparse
import json
import sys
import time

import numpy as np


def cases() -> dict[str, str]:
    """Name → expression in :mod:`meshcore.testing` (evaluated in the worker)."""
    out: dict[str, str] = {}
    for s in range(20, 36):
        out[f"net {s}"] = f"testing.channel_network({s}, n_branches={4 + s % 4})"
    for s in range(200, 204):
        out[f"rough net {s}"] = f"testing.channel_network({s}, n_branches=5, roughness=0.12)"
    for a in (0.0, 31.0, 53.0, 77.0):
        out[f"y {a:.0f}"] = f"testing.y_junction(angle0={a})"
    out["y wide"] = "testing.y_junction(width=2.5, angle0=11.0)"
    for s in range(16):  # island tips and cut ends near islands: the commonest misses
        out[f"islands {s}"] = f"testing.lake_with_islands({s})"
    for s, kind in zip(range(40, 48), ("blob", "arms", "ring", "disc") * 2, strict=True):
        out[f"round {kind} {s}"] = f"testing.round_lake({s}, kind={kind!r})"
    for s in range(3):
        out[f"jagged net {s}"] = f"testing.jagged(testing.channel_network({50 + s}, n_branches=5), 0.08, seed={s})"
    return out


def _where(mb, pr, q: int, h: float) -> str:
    """What lies at interface pair ``q``: the nearest cut end on the shore or star node."""
    m = mb.topology.node_map
    X = np.zeros(m.n_nodes)
    Y = np.zeros(m.n_nodes)
    for g, ids in zip(mb.grids, m.ids, strict=True):
        X[ids], Y[ids] = g.x, g.y
    cnt = np.bincount(m.cells.ravel(), minlength=m.n_nodes)
    mid = pr["mid"][q]
    ends = np.flatnonzero(m.boundary & (cnt >= 3))
    stars = np.array([c.node for c in m.corners if c.free and c.valence != 4], dtype=int)
    best = ("interior", np.inf)
    for label, nodes in (("shore-end", ends), ("star", stars)):
        if len(nodes):
            d = float(np.min(np.hypot(X[nodes] - mid[0], Y[nodes] - mid[1]))) / h
            if d < best[1]:
                best = (label, d)
    return best[0] if best[1] <= 4.0 else "interior"


def run_one(expr: str, cells: int, options: dict | None = None) -> dict:
    from meshcore import testing  # noqa: F401  (used by eval)
    from meshcore.cellsize import default_cell_size
    from meshcore.lakegrid import mesh_outline
    from meshcore.layout.polygon import water_polygon
    from meshcore.quality import lake_metrics
    from meshcore.quality.interfaces import interface_pairs

    poly = eval(expr)
    c0 = time.process_time()
    mb = mesh_outline(poly, target_cells=cells, **(options or {}))
    cpu = time.process_time() - c0
    # the layout's cell size, as `meshcore mesh` and the app measure: islands the layout leaves out
    # (narrower than two of its cells) are left out for the metric too
    hl = default_cell_size(water_polygon(poly)[0].area, cells)
    m = lake_metrics(mb, polygon=poly, cell_size=hl)
    s = m.summary()
    pr = interface_pairs(mb.grids)
    h = float(np.sqrt(poly.area / sum(g.cells[0] * g.cells[1] for g in mb.grids)))
    bad = np.flatnonzero(pr["ratio"] > 2)
    kinds: dict[str, int] = {}
    shown: list[np.ndarray] = []
    for q in bad[np.argsort(-pr["ratio"][bad])]:  # one per place (3 h apart)
        if any(np.hypot(*(pr["mid"][q] - p)) < 3 * h for p in shown):
            continue
        shown.append(pr["mid"][q])
        k = _where(mb, pr, q, h)
        kinds[k] = kinds.get(k, 0) + 1
    worst = int(np.argmax(pr["ratio"])) if len(pr["ratio"]) else -1
    return {
        "blocks": len(mb.grids),
        "max_ratio": float(pr["ratio"].max()) if len(pr["ratio"]) else 1.0,
        "pct_le_2": float(100 * np.mean(pr["ratio"] <= 2)) if len(pr["ratio"]) else 100.0,
        "worst_at": (_where(mb, pr, worst, h) if worst >= 0 else "-"),
        "worst_xy": [float(v) for v in pr["mid"][worst]] if worst >= 0 else None,
        "places": kinds,
        "folded": s["folded_cells"],
        "within3": s["pct_nodes_within_3deg"],
        "cos02": s["pct_nodes_cos_le_0.02"],
        "mean_dev": s["mean_deviation_deg"],
        "pairs12": s["pct_smoothness_le_1.2"],
        "shore": s["hausdorff_cells"],
        "min_edge": s["min_edge_cells"],  # the shortest edge in cells (an explicit model's time step)
        "shore_grid_h": lake_metrics(mb, polygon=poly).summary()["hausdorff_cells"],  # before: the grid's h
        "cell_size": hl,
        "aspect": m.max("aspect_ratio"),
        "cpu": cpu,
        "min_block": int(min(min(g.cells) for g in mb.grids)),  # ≥ 3 each way wanted
        "cells_ratio": float(sum(g.cells[0] * g.cells[1] for g in mb.grids) * hl**2 / poly.area),
    }


HEAD = (
    "| case | blocks | max ratio | pairs ≤ 2 % | worst at | places > 2 | folded | ≤ 3° % | mean ° "
    "| e ≤ 1.2 % | shore | CPU s |"
)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cells", type=int, default=15000)
    ap.add_argument("--only", help="comma-separated name fragments")
    ap.add_argument("--json", help="write the results here")
    ap.add_argument("--options", default="{}", help="options of mesh_outline as JSON")
    a = ap.parse_args(argv)
    todo = {k: v for k, v in cases().items() if not a.only or any(o in k for o in a.only.split(","))}
    res: dict[str, dict] = {}
    print(HEAD)
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for name, expr in todo.items():
        try:
            r = run_one(expr, a.cells, json.loads(a.options))
        except Exception as exc:  # a failed case is one row
            r = {"error": f"{type(exc).__name__}: {exc}"[:160]}
            print(f"| {name} | error: {r['error']} |", flush=True)
            res[name] = r
            continue
        res[name] = r
        places = " ".join(f"{k}:{v}" for k, v in sorted(r["places"].items()))
        print(
            f"| {name} | {r['blocks']} | {r['max_ratio']:.2f} | {r['pct_le_2']:.1f} | {r['worst_at']} | {places} | "
            f"{r['folded']} | {r['within3']:.1f} | {r['mean_dev']:.2f} | {r['pairs12']:.1f} | {r['shore']:.2f} | "
            f"{r['cpu']:.1f} |",
            flush=True,
        )
    ok = [r for r in res.values() if "error" not in r]
    print(
        f"\n{len(todo)} cases: max ratio ≤ 2 in {sum(r['max_ratio'] <= 2 for r in ok)}, "
        f"median max ratio {np.median([r['max_ratio'] for r in ok]):.2f}, "
        f"0 folds {sum(r['folded'] == 0 for r in ok)}, ≥ 90 % within 3° {sum(r['within3'] >= 90 for r in ok)}, "
        f"pairs ≥ 95 % {sum(r['pairs12'] >= 95 for r in ok)}, shore ≤ 0.5 {sum(r['shore'] <= 0.5 for r in ok)}, "
        f"errors {len(todo) - len(ok)}, CPU {sum(r['cpu'] for r in ok):.0f} s",
        flush=True,
    )
    if a.json:
        with open(a.json, "w", encoding="utf-8") as f:
            json.dump(res, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
