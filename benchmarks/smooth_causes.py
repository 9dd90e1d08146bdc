"""Where the edge pairs with a length ratio above 1.2 lie (issue 12's smoothness target).

Runs :func:`meshcore.mesh_outline` on the shapes of ``fresh_sweep.py`` (same seeds from
``--base``, ``--more`` for the other set) and classifies every consecutive edge pair along a grid
line whose length ratio is above ``--limit`` (the metric counts pairs inside one block only: two
edges of a pair are never in different blocks).  A pair (node ``(i, j)`` of block ``b``, along ξ
or η) is counted in every class it belongs to:

* ``xi`` / ``eta`` — the family of the line;
* ``on_shore`` / ``on_itf`` — both edges lie on a block border that is shore / an interface;
* ``touch_shore`` / ``touch_itf`` — one edge of a line crossing the border starts on it (the
  first edge from the shore or an interface and the next);
* ``row1_shore`` / ``row1_itf`` — the pair lies along the first row inside (parallel to the border);
* ``near_<kind>`` — within 2 index steps (Chebyshev, in the block) of a block corner of kind
  ``shore`` (a block corner or cut end on the shore), ``T`` (one block's corner on another's side),
  ``star`` (3 or 5 blocks round the node), ``4`` (a regular 4-block corner);
* ``odd`` — the node lies between the edges of one coarse-level edge (odd index along the line:
  made by the last refinement); ``coarse4`` — the node existed on the coarsest level (index ÷ 4);
* ``narrow`` — the block is at most 8 cells across the line's direction.

    python benchmarks/smooth_causes.py --base N [--more] [--cells 15000] [--out DIR] [--options JSON]

Writes ``DIR/<case>.npz`` (the grid and the pairs) and ``DIR/summary.json``.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import fresh_sweep

CLASSES = (
    "xi",
    "eta",
    "on_shore",
    "on_itf",
    "touch_shore",
    "touch_itf",
    "row1_shore",
    "row1_itf",
    "near_shore",
    "near_T",
    "near_star",
    "near_4",
    "odd",
    "coarse4",
    "narrow",
)


def _features(mb) -> dict[int, str]:
    """Global node id → kind of every block corner (see the module docstring)."""
    m = mb.topology.node_map
    val = np.bincount(m.cells.ravel(), minlength=m.n_nodes)
    corner_of: set[int] = set()
    side_of: set[int] = set()
    for ids in m.ids:
        c = {int(ids[0, 0]), int(ids[-1, 0]), int(ids[0, -1]), int(ids[-1, -1])}
        corner_of |= c
        border = np.concatenate([ids[1:-1, 0], ids[1:-1, -1], ids[0, 1:-1], ids[-1, 1:-1]])
        side_of |= {int(v) for v in border}
    out = {}
    for n in corner_of:
        if m.boundary[n]:
            out[n] = "shore"
        elif n in side_of:
            out[n] = "T"
        elif val[n] != 4:
            out[n] = "star"
        else:
            out[n] = "4"
    for n in side_of:  # cut ends on the shore that are no block's corner cannot exist; kept for safety
        if m.boundary[n] and m.shared[n] and n not in out:
            out[n] = "shore"
    return out


def classify(mb, limit: float = 1.2) -> tuple[dict[str, int], int, int, list[dict]]:
    """Counts per class of the pairs above ``limit``, their number, all pairs, and per-pair rows."""
    from meshcore.quality.lake import _smoothness

    m = mb.topology.node_map
    feats = _features(mb)
    counts = dict.fromkeys(CLASSES, 0)
    total = bad = 0
    rows: list[dict] = []
    for b, (g, ids) in enumerate(zip(mb.grids, m.ids, strict=True)):
        x, y = np.asarray(g.x), np.asarray(g.y)
        n1, m1 = x.shape
        sxi, seta = _smoothness(x, y, False)
        shore = m.boundary[ids]
        # border kinds: a border is "shore" where its middle node is on the boundary
        fij = [(i, j, feats[int(ids[i, j])]) for i in (0, n1 - 1) for j in range(m1) if int(ids[i, j]) in feats]
        fij += [(i, j, feats[int(ids[i, j])]) for j in (0, m1 - 1) for i in range(1, n1 - 1) if int(ids[i, j]) in feats]
        for axis, s in ((0, sxi), (1, seta)):
            ok = ~np.isnan(s)
            total += int(ok.sum())
            ii, jj = np.nonzero(ok & (s > limit))
            bad += len(ii)
            for i, j in zip(ii.tolist(), jj.tolist(), strict=True):
                cl = ["xi" if axis == 0 else "eta"]
                along, across = (i, j) if axis == 0 else (j, i)
                n_along, n_across = (n1, m1) if axis == 0 else (m1, n1)

                def kind(a: int, c: int, axis: int = axis, shore: np.ndarray = shore) -> str:  # (along a, across c)
                    return "shore" if (shore[a, c] if axis == 0 else shore[c, a]) else "itf"

                if across == 0 or across == n_across - 1:
                    cl.append("on_" + kind(along, across))
                elif across == 1:
                    cl.append("row1_" + kind(along, 0))
                elif across == n_across - 2:
                    cl.append("row1_" + kind(along, n_across - 1))
                if along == 1:
                    cl.append("touch_" + kind(0, across))
                if along == n_along - 2:
                    cl.append("touch_" + kind(n_along - 1, across))
                kinds = {k for fi, fj, k in fij if max(abs(fi - i), abs(fj - j)) <= 2}
                cl += [f"near_{k}" for k in sorted(kinds)]
                cl.append("odd" if along % 2 else ("coarse4" if along % 4 == 0 else "even"))
                if n_across - 1 <= 8:
                    cl.append("narrow")
                for c in set(cl):
                    if c in counts:
                        counts[c] += 1
                rows.append({"b": b, "i": i, "j": j, "axis": axis, "r": float(s[i, j]), "cl": cl})
    return counts, bad, total, rows


def main(argv: list[str] | None = None) -> int:
    from meshcore import testing  # noqa: F401  (used by eval)
    from meshcore.cellsize import default_cell_size
    from meshcore.lakegrid import mesh_outline
    from meshcore.layout.polygon import water_polygon
    from meshcore.quality import lake_metrics

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--base", type=int, required=True)
    ap.add_argument("--more", action="store_true")
    ap.add_argument("--cells", type=int, default=15000)
    ap.add_argument("--out", default="/tmp/smooth_causes")
    ap.add_argument("--only", help="comma-separated name fragments")
    ap.add_argument("--options", default="{}")
    a = ap.parse_args(argv)
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    todo = fresh_sweep.more_cases(a.base) if a.more else fresh_sweep.cases(a.base)
    if a.only:
        todo = {k: v for k, v in todo.items() if any(f in k for f in a.only.split(","))}
    opts = json.loads(a.options)
    summary = {}
    for name, expr in todo.items():
        poly = eval(expr)
        t = time.process_time()
        try:
            mb = mesh_outline(poly, target_cells=a.cells, **opts)
        except Exception as exc:
            print(f"{name}: {type(exc).__name__}: {str(exc)[:100]}", flush=True)
            continue
        cpu = time.process_time() - t
        hl = default_cell_size(water_polygon(poly)[0].area, a.cells)
        s = lake_metrics(mb, polygon=poly, cell_size=hl).summary()
        counts, bad, total, rows = classify(mb)
        r = {
            "pairs12": s["pct_smoothness_le_1.2"],
            "within3": s["pct_nodes_within_3deg"],
            "cos02": s.get("pct_nodes_cos_le_0.02", float("nan")),
            "mean_dev": s["mean_deviation_deg"],
            "folded": s["folded_cells"],
            "shore": s["hausdorff_cells"],
            "max_itf": s["max_interface_ratio"],
            "bad": bad,
            "total": total,
            "counts": counts,
            "cpu": cpu,
        }
        summary[name] = r
        np.savez_compressed(
            out / f"{name.replace(' ', '_')}.npz",
            **{f"x{k}": np.asarray(g.x) for k, g in enumerate(mb.grids)},
            **{f"y{k}": np.asarray(g.y) for k, g in enumerate(mb.grids)},
            rows=np.array([[q["b"], q["i"], q["j"], q["axis"], q["r"]] for q in rows]).reshape(-1, 5),
            n=len(mb.grids),
        )
        top = sorted(((v, c) for c, v in counts.items() if c not in ("xi", "eta")), reverse=True)[:5]
        print(
            f"{name}: pairs {r['pairs12']:.1f} % ({bad}/{total}) 3° {r['within3']:.1f} fold {r['folded']} "
            f"cpu {cpu:.1f} | " + " ".join(f"{c}:{v}" for v, c in top),
            flush=True,
        )
    (out / "summary.json").write_text(json.dumps(summary, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
