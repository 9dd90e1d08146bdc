"""Benchmark: Winslow + fold-free repair on every lake (full and sparse), ~6000 and ~24000 nodes.

Each lake is one block with corners from :func:`meshcore.corners.choose_corners`
and cells chosen so that ``(ni+1)(nj+1) ≈ nodes`` with ``ni/nj`` ≈ the ratio of
the lengths of opposite borders.  Times are the minimum of ``--repeat`` runs
(the machine is shared: compare the ratio repair / Winslow, measured in the
same run).  Prints a Markdown table.

    /work/venv/bin/python benchmarks/foldfree.py [--repeat 3] [--nodes 6000 24000]
"""

from __future__ import annotations

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


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--nodes", type=int, nargs="+", default=[6000, 24000])
    ap.add_argument("--lakes", nargs="*", default=None)
    args = ap.parse_args()
    names = args.lakes or sorted(p.stem for p in LAKES.glob("*.csv"))
    # warm up the numba caches
    meshcore.generate_block(loop=load_lake(names[0]), corners=choose_corners(load_lake(names[0])),
                            cells=(20, 10))
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


if __name__ == "__main__":
    main()
