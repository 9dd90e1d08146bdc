"""What each cut end on the shore costs: the nodes beyond 3° and edge pairs above 1.2 near it, by its geometry.

A cut end on the shore is a shore node of two (or more) blocks.  For each the script measures the
water angle ``W`` of the outline at 1.5 cells either side (``point`` ≥ 250°, ``reflex`` 200–250°,
``straight`` 160–200°, ``convex`` below), which of the blocks has a corner there (``1/2``: one
block's corner beside another block's passing side), whether the end lies on an island, the nodes
beyond 3° and the edge pairs above 1.2 within 2 cells (each counted at its nearest end) and whether
an interface pair above 2 lies within 2 cells; then sums them by geometry over the shapes of
``fresh_sweep.py`` (``--more``: the other set) at 15 000 cells, default options::

    python benchmarks/cut_ends.py --base N [--more] [--cells 15000] [--json OUT]
"""

from __future__ import annotations

import argparse
import json
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import fresh_sweep


def _angle(u: np.ndarray, v: np.ndarray) -> float:
    """Counter-clockwise angle from ``u`` to ``v``, degrees in [0, 360)."""
    return float(np.degrees(np.arctan2(u[0] * v[1] - u[1] * v[0], u @ v)) % 360.0)


def water_angle(poly, p: np.ndarray, d: float) -> tuple[float, bool]:
    """The water angle of ``poly`` at its shore point nearest ``p`` between the points ``d``
    along the shore either side, and whether that shore is an island's."""
    from shapely.geometry import Point

    rings = [poly.exterior, *poly.interiors]
    k = int(np.argmin([r.distance(Point(p)) for r in rings]))
    ring = rings[k]
    s, n = ring.project(Point(p)), ring.length
    q = np.array(ring.interpolate(s).coords[0])
    a = np.array(ring.interpolate((s - d) % n).coords[0]) - q
    b = np.array(ring.interpolate((s + d) % n).coords[0]) - q
    t = _angle(a, b)
    half = np.radians(t / 2) + np.arctan2(a[1], a[0])
    inside = poly.contains(Point(q + 0.05 * d * np.array([np.cos(half), np.sin(half)])))
    return (t if inside else 360.0 - t), k > 0


def _block_angle(X, Y, ids: np.ndarray, e: int) -> tuple[bool, float] | None:
    """``(corner, angle)`` of the block with node ids ``ids`` at its border node ``e``."""
    i, j = np.argwhere(ids == e)[0]
    n1, m1 = ids.shape
    nb = [
        int(ids[a, b])
        for a, b, along in (
            (i + 1, j, j in (0, m1 - 1)),
            (i - 1, j, j in (0, m1 - 1)),
            (i, j + 1, i in (0, n1 - 1)),
            (i, j - 1, i in (0, n1 - 1)),
        )
        if along and 0 <= a < n1 and 0 <= b < m1
    ]
    if len(nb) < 2:
        return None
    p = np.array([X[e], Y[e]])
    u, v = np.array([X[nb[0]], Y[nb[0]]]) - p, np.array([X[nb[1]], Y[nb[1]]]) - p
    c = ids[min(max(i, 1), n1 - 2), min(max(j, 1), m1 - 2)]
    t = _angle(u, v)
    if _angle(u, np.array([X[c], Y[c]]) - p) > t:
        t = 360.0 - t
    return bool(i in (0, n1 - 1) and j in (0, m1 - 1)), t


def cut_ends(mb, poly) -> dict:
    """Every cut end on the shore of ``mb`` (a grid of ``poly``) with its geometry and costs."""
    from meshcore.quality.interfaces import interface_pairs
    from meshcore.quality.lake import _smoothness, node_cos

    m = mb.topology.node_map
    X, Y = np.zeros(m.n_nodes), np.zeros(m.n_nodes)
    for g, ids in zip(mb.grids, m.ids, strict=True):
        X[ids], Y[ids] = g.x, g.y
    h = float(np.sqrt(poly.area / sum(g.cells[0] * g.cells[1] for g in mb.grids)))
    bad: dict[str, list] = {"nodes": [], "pairs": []}
    for g in mb.grids:
        x, y = np.asarray(g.x), np.asarray(g.y)
        c = node_cos(x, y, g.periodic)
        sel = ~np.isnan(c) & (c > np.sin(np.radians(3.0)))
        bad["nodes"] += list(zip(x[sel], y[sel], strict=True))
        for s in _smoothness(x, y, g.periodic):
            sel = ~np.isnan(s) & (s > 1.2)
            bad["pairs"] += list(zip(x[sel], y[sel], strict=True))
    blocks_of = np.zeros(m.n_nodes, dtype=int)
    for ids in m.ids:
        blocks_of[np.unique(ids)] += 1
    rows = []
    for e in np.flatnonzero(m.boundary & (blocks_of >= 2)):
        p = np.array([X[e], Y[e]])
        at = [a for ids in m.ids if (ids == e).any() and (a := _block_angle(X, Y, ids, e)) is not None]
        w, isl = water_angle(poly, p, 1.5 * h)
        rows.append(
            {
                "x": p[0],
                "y": p[1],
                "W": w,
                "island": isl,
                "blocks": len(at),
                "corners": sum(c for c, _ in at),
                "angles": [t for _, t in at],
                "nodes": 0,
                "pairs": 0,
                "ratio": 1.0,
            }
        )
    if rows:
        E = np.array([[r["x"], r["y"]] for r in rows])
        pr = interface_pairs(mb.grids)
        pts = {**{k: np.array(v).reshape(-1, 2) for k, v in bad.items()}, "ratio": np.asarray(pr["mid"]).reshape(-1, 2)}
        for key, P in pts.items():
            if not len(P):
                continue
            d = np.hypot(P[:, None, 0] - E[None, :, 0], P[:, None, 1] - E[None, :, 1])
            k = d.argmin(axis=1)
            near = d[np.arange(len(P)), k] <= 2 * h
            for q, i in zip(k[near], np.flatnonzero(near), strict=True):
                if key == "ratio":
                    rows[q]["ratio"] = max(rows[q]["ratio"], float(pr["ratio"][i]))
                else:
                    rows[q][key] += 1
    return {"rows": rows, "bad_nodes": len(bad["nodes"]), "bad_pairs": len(bad["pairs"])}


def kind(r: dict) -> tuple[str, str]:
    w = r["W"]
    where = "convex" if w < 160 else "straight" if w <= 200 else "reflex" if w < 250 else "point"
    return where, f"{r['corners']}/{r['blocks']}"


def main(argv: list[str] | None = None) -> int:
    from meshcore import testing  # noqa: F401  (used by eval)
    from meshcore.lakegrid import mesh_outline

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--base", type=int, required=True)
    ap.add_argument("--more", action="store_true")
    ap.add_argument("--cells", type=int, default=15000)
    ap.add_argument("--json", help="write every end here")
    a = ap.parse_args(argv)
    todo = fresh_sweep.more_cases(a.base) if a.more else fresh_sweep.cases(a.base)
    agg: dict = defaultdict(lambda: [0, 0, 0, 0, 0])
    out, nodes, pairs = {}, [0, 0], [0, 0]
    for name, expr in todo.items():
        poly = eval(expr)
        try:
            mb = mesh_outline(poly, target_cells=a.cells)
        except Exception as exc:  # a clear error or a bug: one line, the next shape
            print(f"{name}: {type(exc).__name__}: {str(exc)[:100]}", flush=True)
            continue
        res = cut_ends(mb, poly)
        out[name] = res
        nodes[0] += res["bad_nodes"]
        pairs[0] += res["bad_pairs"]
        for r in res["rows"]:
            v = agg[kind(r)]
            v[0] += 1
            v[1] += r["nodes"]
            v[2] += r["pairs"]
            v[3] += r["ratio"] > 2
            v[4] += r["island"]
            nodes[1] += r["nodes"]
            pairs[1] += r["pairs"]
        print(f"{name}: {len(res['rows'])} cut ends", flush=True)
    print(
        f"\nwithin 2 cells of a cut end: {nodes[1]} of {nodes[0]} nodes beyond 3°, "
        f"{pairs[1]} of {pairs[0]} pairs above 1.2\n"
    )
    print("| W | corners | ends | on islands | nodes > 3° | pairs > 1.2 | ends with a ratio > 2 |")
    print("|---|---|---|---|---|---|---|")
    for k, v in sorted(agg.items(), key=lambda kv: -(kv[1][1] + kv[1][2])):
        print(f"| {k[0]} | {k[1]} | {v[0]} | {v[4]} | {v[1]} | {v[2]} | {v[3]} |")
    if a.json:
        Path(a.json).write_text(json.dumps(out, default=float))
    return 0


if __name__ == "__main__":
    sys.exit(main())
