"""Why lakes miss the cross-interface area ratio ≤ 2: the place of every pair above 2, by cause.

Runs the shapes of ``fresh_sweep.py`` (``--base``, ``--more``) and, for every lake whose largest
ratio is above 2, describes each place above 2 (one per 3 h, worst first): the nearest node where
blocks meet on the shore (a cut's end) within 4 h, on the outer shore or an island, the water's
angle there in the final grid (reflex ≥ 200°, straight, convex), the angle of the block that has a
corner there and of the block whose side passes, whether the two cells of the pair touch that node;
else a node where 3 or 5 blocks meet in the water (``star``), else ``interior``.  Prints a table
of causes with counts (worst place per lake, and every place)::

    python benchmarks/interface_causes.py --base 717000 [--more] [--cells 15000] [--json OUT]
"""

from __future__ import annotations

import argparse
import json
import sys
from collections import Counter
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))


def node_xy(mb) -> tuple[np.ndarray, np.ndarray]:
    """Global node coordinates of a multiblock grid."""
    m = mb.topology.node_map
    X, Y = np.zeros(m.n_nodes), np.zeros(m.n_nodes)
    for g, ids in zip(mb.grids, m.ids, strict=True):
        X[ids], Y[ids] = g.x, g.y
    return X, Y


def cell_angles(mb) -> np.ndarray:
    """``(n_cells, 4)`` interior angles (degrees) of every cell at its 4 CCW corners."""
    m = mb.topology.node_map
    X, Y = node_xy(mb)
    P = np.stack([X[m.cells], Y[m.cells]], -1)  # (n, 4, 2)
    a = np.roll(P, 1, axis=1) - P
    b = np.roll(P, -1, axis=1) - P
    cross = b[..., 0] * a[..., 1] - b[..., 1] * a[..., 0]
    dot = (a * b).sum(-1)
    return np.degrees(np.arctan2(np.abs(cross), dot))


def describe(mb, poly, pr, q: int, h: float, ang: np.ndarray) -> dict:
    """What lies at interface pair ``q``."""
    import shapely

    m = mb.topology.node_map
    X, Y = node_xy(mb)
    mid = pr["mid"][q]
    cnt = np.bincount(m.cells.ravel(), minlength=m.n_nodes)
    blocks_at: dict[int, set] = {}
    for cell, b in zip(m.cells, m.cell_block, strict=True):
        for n in cell:
            blocks_at.setdefault(int(n), set()).add(int(b))
    ends = [n for n in np.flatnonzero(m.boundary) if len(blocks_at.get(int(n), ())) >= 2]
    stars = [c.node for c in m.corners if c.free and c.valence != 4]
    d_end = np.hypot(X[ends] - mid[0], Y[ends] - mid[1]) / h if ends else np.array([np.inf])
    d_star = np.hypot(X[stars] - mid[0], Y[stars] - mid[1]) / h if stars else np.array([np.inf])
    out: dict = {"ratio": float(pr["ratio"][q])}
    if min(d_end.min(), d_star.min()) > 4.0:
        out["kind"] = "interior"
        return out
    if d_star.min() < d_end.min():
        out["kind"] = "star"
        out["valence"] = int(cnt[stars[int(np.argmin(d_star))]])
        out["dist"] = float(d_star.min())
        return out
    n = int(ends[int(np.argmin(d_end))])
    out["dist"] = float(d_end.min())
    p = shapely.Point(X[n], Y[n])
    rings = [poly.exterior, *poly.interiors]
    out["ring"] = "outer" if int(np.argmin([r.distance(p) for r in rings])) == 0 else "island"
    mine = np.flatnonzero((m.cells == n).any(1))
    per_block: dict[int, float] = {}
    ncell: Counter = Counter()
    for c in mine:
        k = int(np.flatnonzero(m.cells[c] == n)[0])
        per_block[int(m.cell_block[c])] = per_block.get(int(m.cell_block[c]), 0.0) + float(ang[c, k])
        ncell[int(m.cell_block[c])] += 1
    W = sum(per_block.values())
    out["water"] = W
    out["kind"] = "end-reflex" if W >= 200 else "end-straight" if W > 160 else "end-convex"
    corner = [b for b in per_block if ncell[b] == 1]
    side = [b for b in per_block if ncell[b] >= 2]
    out["corner_angles"] = sorted(per_block[b] for b in corner)
    out["side_angles"] = sorted(per_block[b] for b in side)
    out["n_blocks"] = len(per_block)
    ca, cb = pr["cell_a"][q], pr["cell_b"][q]

    def touches(cell) -> bool:
        b, i, j = (int(v) for v in cell)
        ids = m.ids[b]
        return n in {int(ids[i, j]), int(ids[i + 1, j]), int(ids[i, j + 1]), int(ids[i + 1, j + 1])}

    out["touch"] = bool(touches(ca) or touches(cb))
    return out


def label(d: dict) -> str:
    """A short cause label."""
    if d["kind"] in ("interior", "star"):
        return d["kind"]
    fan = max(d["corner_angles"], default=0.0) >= 150
    where = "island" if d["ring"] == "island" else "outer"
    touch = "at end" if d["touch"] else "near end"
    return f"{d['kind']} {where} {touch}" + (" fan" if fan else "")


def main(argv: list[str] | None = None) -> int:
    import fresh_sweep
    import interface_sweep

    import meshcore.lakegrid as lg
    from meshcore import testing  # noqa: F401  (used by eval)
    from meshcore.quality.interfaces import interface_pairs

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--base", type=int, required=True)
    ap.add_argument("--cells", type=int, default=15000)
    ap.add_argument("--more", action="store_true")
    ap.add_argument("--only", help="comma-separated name fragments")
    ap.add_argument("--options", default="{}")
    ap.add_argument("--json")
    a = ap.parse_args(argv)
    todo = fresh_sweep.more_cases(a.base) if a.more else fresh_sweep.cases(a.base)
    if a.only:
        todo = {k: v for k, v in todo.items() if any(o in k for o in a.only.split(","))}
    last: dict = {}
    orig = lg.mesh_outline

    def keep(*args, **kw):
        last["mb"] = orig(*args, **kw)
        return last["mb"]

    lg.mesh_outline = keep
    res: dict = {}
    worst_c: Counter = Counter()
    all_c: Counter = Counter()
    for name, expr in todo.items():
        try:
            r = interface_sweep.run_one(expr, a.cells, json.loads(a.options))
        except Exception as exc:  # a row, not a stop
            res[name] = {"error": f"{type(exc).__name__}: {exc}"[:200]}
            print(f"{name}: error {res[name]['error']}", flush=True)
            continue
        mb, poly = last["mb"], eval(expr)
        pr = interface_pairs(mb.grids)
        h = float(np.sqrt(poly.area / sum(g.cells[0] * g.cells[1] for g in mb.grids)))
        r["expr"] = expr
        places = []
        if r["max_ratio"] > 2:
            ang = cell_angles(mb)
            shown: list[np.ndarray] = []
            for q in np.argsort(-pr["ratio"]):
                if pr["ratio"][q] <= 2:
                    break
                if any(np.hypot(*(pr["mid"][q] - s)) < 3 * h for s in shown):
                    continue
                shown.append(pr["mid"][q])
                d = describe(mb, poly, pr, int(q), h, ang)
                d["label"] = label(d)
                d["mid"] = [float(v) for v in pr["mid"][q]]
                places.append(d)
            worst_c[places[0]["label"]] += 1
            for d in places:
                all_c[d["label"]] += 1
        r["places_detail"] = places
        res[name] = r
        w = places[0] if places else None
        extra = ""
        if w is not None and "water" in w:
            extra = (
                f" W={w['water']:.0f} corner={[round(x) for x in w['corner_angles']]} "
                f"side={[round(x) for x in w['side_angles']]} d={w['dist']:.1f}h"
            )
        print(
            f"{name}: max {r['max_ratio']:.2f}, >2 places {len(places)}, worst: "
            f"{w['label'] if w else '-'}{extra} | 3deg {r['within3']:.1f} folded {r['folded']} "
            f"e12 {r['pairs12']:.1f} shore {r['shore']:.2f}",
            flush=True,
        )
    print("\nworst place per lake that misses:")
    for k, v in worst_c.most_common():
        print(f"  {v:3d}  {k}")
    print("every place above 2:")
    for k, v in all_c.most_common():
        print(f"  {v:3d}  {k}")
    if a.json:
        with open(a.json, "w", encoding="utf-8") as f:
            json.dump({"base": a.base, "cells": a.cells, "more": a.more, "results": res}, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
