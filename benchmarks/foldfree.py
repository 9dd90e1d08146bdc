"""Benchmark: Winslow + fold-free repair on every lake (full and sparse), ~6000 and ~24000 nodes.

Each lake is one block with corners from :func:`meshcore.corners.choose_corners`
and cells chosen so that ``(ni+1)(nj+1) ≈ nodes`` with ``ni/nj`` ≈ the ratio of
the lengths of opposite borders.  Times are the minimum of ``--repeat`` runs
(the machine is shared: compare the ratio repair / Winslow, measured in the
same run).  Prints a Markdown table.

    PYTHONPATH=. /work/venv/bin/python benchmarks/foldfree.py [--repeat 3] [--nodes 6000 24000]

A second table covers paper-like cases and a C-shaped domain (repair and the
whole-block ``method="foldfree"``, with the largest node distance to Winslow).
"""

from __future__ import annotations

import sys
from pathlib import Path as _Path

sys.path.insert(0, str(_Path(__file__).resolve().parent.parent))  # the repo's meshcore and tests

import argparse
import math
import time
from functools import partial
from pathlib import Path

import numpy as np

import meshcore
from meshcore.boundary import borders_from_loop
from meshcore.corners import choose_corners
from meshcore.foldfree import repair

LAKES = Path(__file__).resolve().parent.parent / "tests" / "data" / "lakes"


def load_lake(name: str) -> np.ndarray:
    a = np.loadtxt(LAKES / f"{name}.csv", delimiter=",", skiprows=1)
    lon, lat = a[:, 0], a[:, 1]
    r = 6371008.8
    x = r * np.radians(lon - lon.mean()) * math.cos(math.radians(lat.mean()))
    y = r * np.radians(lat - lat.mean())
    return np.column_stack([x, y])


def cells_for(loop, corners, nodes: int) -> tuple[int, int]:
    b = borders_from_loop(loop, corners)
    length = {k: float(np.hypot(*np.diff(v, axis=0).T).sum()) for k, v in b.items()}
    r = (length["bottom"] + length["top"]) / (length["left"] + length["right"])
    nj = max(2, round((-(1 + r) + math.sqrt((1 + r) ** 2 - 4 * r * (1 - nodes))) / (2 * r)))
    ni = max(2, round(nodes / (nj + 1)) - 1)
    return ni, nj


def best_of(n: int, fn):
    best, out = math.inf, None
    for _ in range(n):
        t = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t)
    return best, out


def figure(path: str) -> None:
    """Shasta Lake at ~6000 nodes: Winslow (invalid cells in red) and after the repair."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Polygon

    loop = load_lake("shasta_lake")
    c = choose_corners(loop)
    cells = cells_for(loop, c, 6000)
    w = meshcore.generate_block(loop=loop, corners=c, cells=cells, repair="off")
    g = meshcore.generate_block(loop=loop, corners=c, cells=cells)
    qw = meshcore.quality(w)
    fi = qw.folded[0]
    fx, fy = w.x[fi[0], fi[1]], w.y[fi[0], fi[1]]
    fig, axs = plt.subplots(2, 2, figsize=(12, 10))
    for col, gr in enumerate((w, g)):
        q = meshcore.quality(gr)
        for row in range(2):
            ax = axs[row, col]
            ax.plot(gr.x, gr.y, "k-", lw=0.25)
            ax.plot(gr.x.T, gr.y.T, "k-", lw=0.25)
            ax.plot(*np.vstack([loop, loop[:1]]).T, "b-", lw=0.6)
            for i, j in q.nonconvex:
                quad = [(gr.x[i + a, j + b], gr.y[i + a, j + b]) for a, b in ((0, 0), (1, 0), (1, 1), (0, 1))]
                ax.add_patch(Polygon(quad, color="r", alpha=0.6))
            ax.set_aspect("equal")
            if row == 0:
                ax.set_title(f"{gr.method}: {q.n_folded} folded, {q.n_nonconvex} non-convex cells")
                for k, nm in zip(c, ("sw", "se", "ne", "nw"), strict=True):
                    ax.annotate(nm, loop[k], color="g", fontsize=12)
            else:
                ax.set_xlim(fx - 1500, fx + 1500)
                ax.set_ylim(fy - 1500, fy + 1500)
    fig.suptitle(
        f"Shasta Lake, one block, automatic corners, {cells[0]} × {cells[1]} cells "
        f"({w.n_nodes} nodes); bottom: zoom on a fold"
    )
    fig.tight_layout()
    fig.savefig(path, dpi=72)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--nodes", type=int, nargs="+", default=[6000, 24000])
    ap.add_argument("--lakes", nargs="*", default=None)
    ap.add_argument("--shapes-only", action="store_true")
    ap.add_argument("--figure", metavar="PNG", help="only draw the Shasta figure to PNG")
    args = ap.parse_args()
    if args.figure:
        figure(args.figure)
        return
    if args.shapes_only:
        shapes(args.repeat)
        return
    names = args.lakes or sorted(p.stem for p in LAKES.glob("*.csv"))
    # warm up the numba caches
    meshcore.generate_block(loop=load_lake(names[0]), corners=choose_corners(load_lake(names[0])), cells=(20, 10))
    print(
        "| lake | nodes | cells | Winslow folded/non-convex | after folded/non-convex | "
        "min Jacobian ratio | max orthogonality (°) | Winslow s | repair s | "
        "whole generate_block s | repair / Winslow | free nodes |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for name in names:
        loop = load_lake(name)
        c = choose_corners(loop)
        for nodes in args.nodes:
            cells = cells_for(loop, c, nodes)
            gen = partial(meshcore.generate_block, loop=loop, corners=c, cells=cells)
            tw, w = best_of(args.repeat, partial(gen, repair="off"))
            tr, res = best_of(args.repeat, partial(repair, w, strict=False))
            tg, g = best_of(args.repeat, gen)
            qw, q = meshcore.quality(w), meshcore.quality(g)
            print(
                f"| {name} | {g.n_nodes} | {cells[0]}×{cells[1]} | "
                f"{qw.n_folded}/{qw.n_nonconvex} | "
                f"{q.n_folded}/{q.n_nonconvex} | {q.min_jacobian_ratio:.4f} | "
                f"{q.max_orthogonality:.1f} | {tw:.3f} | {tr:.3f} | {tg:.3f} | "
                f"{tr / tw:.2f} | {res.free_nodes} |",
                flush=True,
            )
    shapes(args.repeat)


def shapes(repeat: int) -> None:
    """Paper-like cases and the C-shaped domain: repair vs the whole-block fold-free method."""
    from meshcore.case import load_case
    from tests.meshcore.test_foldfree import c_shape

    cases = []
    root = Path(__file__).resolve().parent.parent / "resources" / "examples"
    for path in sorted(root.glob("*.toml")):
        case = load_case(path)
        if not case.blocks or case.is_multiblock:  # single-block cases only
            continue
        cases.append((path.stem, case.blocks[0], case.solver))
    for cells in [(20, 40), (30, 60), (60, 120)]:
        spec = meshcore.BlockSpec(points=c_shape(), corners=(0, 1, 6, 7), cells=cells)
        cases.append(("C (square, slot 0.2 × 0.8)", spec, meshcore.SolverSpec()))
    print()
    print(
        "| case | cells | Winslow folded/non-convex | auto: method, folded/non-convex | "
        "foldfree method: folded/non-convex | max node distance foldfree–Winslow (h) | "
        "min Jacobian ratio W / auto / foldfree | Winslow s | auto s | foldfree s |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|")
    for name, spec, solver in cases:
        tw, w = best_of(repeat, partial(meshcore.generate_block, spec, solver.replaced(repair="off")))
        tg, g = best_of(repeat, partial(meshcore.generate_block, spec, solver))
        tf, f = best_of(repeat, partial(meshcore.generate_block, spec, solver.replaced(method="foldfree")))
        qw, qg, qf = meshcore.quality(w), meshcore.quality(g), meshcore.quality(f)
        h = float(np.median(np.hypot(np.diff(w.x, axis=0), np.diff(w.y, axis=0))))
        d = float(np.hypot(f.x - w.x, f.y - w.y).max()) / h
        print(
            f"| {name} | {w.cells[0]}×{w.cells[1]} | {qw.n_folded}/{qw.n_nonconvex} | "
            f"{g.method}, {qg.n_folded}/{qg.n_nonconvex} | {qf.n_folded}/{qf.n_nonconvex} | "
            f"{d:.3f} | {qw.min_jacobian_ratio:.3f} / {qg.min_jacobian_ratio:.3f} / "
            f"{qf.min_jacobian_ratio:.3f} | {tw:.3f} | {tg:.3f} | {tf:.3f} |",
            flush=True,
        )


if __name__ == "__main__":
    main()
