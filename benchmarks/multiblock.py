"""Cost of multiblock smoothing versus one block of the same node count.

Run from the repository root (serial kernels; timings are best of ``--repeat``)::

    python benchmarks/multiblock.py [--repeat 3] [--quick]

1. Per-sweep cost on a curved rectangle split in two blocks: the single-block
   kernel ``sweep4``, the multiblock table kernel (``engine="table"``) and
   the block engine (``sweep4`` per block + table on the border nodes).
2. Whole solves to the same tolerance from the same algebraic start: one
   block (SOR, and multigrid when registered) against the same nodes split in
   2 and 4 blocks (smooth mode: multigrid over all blocks, block-engine SOR,
   table-engine SOR).  In this test the multiblock solution equals the
   single-block one.
3. Shasta Lake (the example cases): smooth (frozen start / algebraic start)
   and frozen, against one curved-rectangle block with the same node count.
4. Where the multiblock CLI's time goes (``--stages``): CPU time per stage of
   ``generate_case`` on the Shasta examples (and refined 2×), min of ``--repeat``
   runs with the multigrid set-up built in each (as in a new process).
5. Where a multiblock solve's time goes against one block (``--cycles``): per topology
   the cycles and rates, set-up, full-multigrid start, one V-cycle, the finest level's
   smoothing fused against its kernels one by one, and the square's solve per cycle.
"""

from __future__ import annotations

import argparse
import itertools
import math
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

import meshcore  # noqa: E402
from meshcore.elliptic import _kernels as bk  # noqa: E402
from meshcore.elliptic.solver import METHODS, default_tolerance  # noqa: E402
from meshcore.multiblock import (  # noqa: E402
    Block,
    Interface,
    MultiBlockTopology,
    Side,
    initial_grids,
    solve_multiblock,
)
from meshcore.multiblock.sor import _BlockEngine, _TableEngine  # noqa: E402
from tests.meshcore.test_multiblock import borders, curved_rectangle  # noqa: E402  (one definition)


def split(X, Y, nb: int) -> MultiBlockTopology:
    ni, nj = X.shape[0] - 1, X.shape[1] - 1
    if nb == 2:
        h = ni // 2
        return MultiBlockTopology(
            (Block("a", borders(X[: h + 1], Y[: h + 1])), Block("b", borders(X[h:], Y[h:]))),
            (Interface(Side("a", "right"), Side("b", "left")),),
        )
    h, v = ni // 2, nj // 2
    parts = {"sw": np.s_[: h + 1, : v + 1], "se": np.s_[h:, : v + 1], "nw": np.s_[: h + 1, v:], "ne": np.s_[h:, v:]}
    bl = tuple(Block(n, borders(X[s], Y[s])) for n, s in parts.items())
    itf = tuple(
        Interface(Side(a, ba), Side(b, bb))
        for a, ba, b, bb in (
            ("sw", "right", "se", "left"),
            ("nw", "right", "ne", "left"),
            ("sw", "top", "nw", "bottom"),
            ("se", "top", "ne", "bottom"),
        )
    )
    return MultiBlockTopology(bl, itf)


def best(fn, repeat: int):
    out, ts = None, []
    for _ in range(repeat):
        t = time.perf_counter()
        out = fn()
        ts.append(time.perf_counter() - t)
    return min(ts), out


def per_sweep(repeat: int, sizes) -> None:
    print("## 1. cost per sweep (ms), curved rectangle split in 2 blocks\n")
    print("| nodes | sweep4 (1 block) | table engine | block engine | table/sweep4 | blocks/sweep4 |")
    print("|---|---|---|---|---|---|")
    e = np.zeros((0, 0))
    for ni, nj in sizes:
        X, Y = curved_rectangle(ni, nj)
        n = max(20, int(2e6 / X.size))
        x, y = X.copy(), Y.copy()
        bk.sweep4(x, y, e, e, 1.5, False)

        def run4(x=x, y=y, n=n):
            for _ in range(n):
                bk.sweep4(x, y, e, e, 1.5, False)

        t4 = best(run4, repeat)[0] / n
        topo = split(X, Y, 2)
        m = topo.node_map
        res = []
        for cls in (_TableEngine, _BlockEngine):
            gx, gy = np.empty(m.n_nodes), np.empty(m.n_nodes)
            for g, ids in zip(initial_grids(topo), m.ids, strict=True):
                gx[ids.ravel()], gy[ids.ravel()] = g.x.ravel(), g.y.ravel()
            eng = cls(gx, gy, m)
            eng.sweep(1.5)

            def run(eng=eng, n=n):
                for _ in range(n):
                    eng.sweep(1.5)

            res.append(best(run, repeat)[0] / n)
        tt, tb = res
        print(
            f"| {X.shape[0]}×{X.shape[1]} = {X.size} | {t4 * 1e3:.3f} | {tt * 1e3:.3f} | "
            f"{tb * 1e3:.3f} | {tt / t4:.2f} | {tb / t4:.2f} |"
        )
    print()


def whole_solves(repeat: int, sizes) -> None:
    print("## 2. whole solves from the same algebraic start, same tolerance\n")
    print("| nodes | solver | iterations | time (s) | × one block (SOR) | max distance to one block / size |")
    print("|---|---|---|---|---|---|")
    for ni, nj in sizes:
        X, Y = curved_rectangle(ni, nj)
        g0 = meshcore.StructuredGrid(X, Y)
        tol = default_tolerance(g0.shape)
        t1, ref = best(lambda g0=g0, tol=tol: meshcore.solve(g0, method="sor", tolerance=tol), repeat)
        rows = [("1 block, SOR", ref.iterations, t1, 0.0)]
        if "multigrid" in METHODS:
            tm, gm = best(lambda g0=g0, tol=tol: meshcore.solve(g0, method="multigrid", tolerance=tol), repeat)
            rows.append(("1 block, multigrid", gm.iterations, tm, float(np.abs(gm.x - ref.x).max())))
        for nb in (2, 4):
            topo = split(X, Y, nb)
            for engine, start in (
                ("multigrid", "algebraic"),
                ("blocks", "algebraic"),
                ("blocks", "frozen"),
                ("table", "algebraic"),
            ):
                tb, mb = best(
                    lambda topo=topo, engine=engine, start=start, tol=tol: solve_multiblock(
                        topo, mode="smooth", tolerance=tol, engine=engine, start=start
                    ),
                    repeat,
                )
                xs = np.full(X.shape, np.nan)
                ys = np.full(X.shape, np.nan)
                h, v = ni // 2, nj // 2
                offs = {"a": (0, 0), "b": (h, 0), "sw": (0, 0), "se": (h, 0), "nw": (0, v), "ne": (h, v)}
                for name, g in zip(mb.names, mb.grids, strict=True):
                    i0, j0 = offs[name]
                    xs[i0 : i0 + g.shape[0], j0 : j0 + g.shape[1]] = g.x
                    ys[i0 : i0 + g.shape[0], j0 : j0 + g.shape[1]] = g.y
                dist = float(np.hypot(xs - ref.x, ys - ref.y).max()) / ref.size
                rows.append((f"{nb} blocks smooth, {engine}, {start} start", mb.info.iterations, tb, dist))
        for label, it, t, d in rows:
            print(f"| {X.size} | {label} | {it} | {t:.3f} | {t / t1:.2f} | {d:.1e} |")
    print()


def lake(repeat: int, quick: bool) -> None:
    from meshcore.case import case_topology, load_case

    print("## 3. Shasta Lake vs one block with the same node count\n")
    print("| case | nodes | solver | iterations | time (s) | × one block (same nodes, same tolerance) |")
    print("|---|---|---|---|---|---|")
    for tag in ("coarse",) if quick else ("coarse", "fine"):
        topo = case_topology(load_case(ROOT / "resources" / "examples" / f"shasta-multiblock-{tag}.toml"))
        n = topo.node_map.n_nodes
        # one block of (about) the same node count, aspect 2:1
        nj = round(math.sqrt(n / 2.0)) - 1
        ni = round(n / (nj + 1)) - 1
        X, Y = curved_rectangle(ni, nj)
        n_big = max(max(b.cells) + 1 for b in topo.blocks)
        tol = default_tolerance((n_big, n_big))
        g0 = meshcore.StructuredGrid(X, Y)
        t1, one = best(lambda g0=g0, tol=tol: meshcore.solve(g0, method="sor", tolerance=tol), repeat)
        print(f"| {tag} | {X.size} | one block {ni}×{nj}, SOR | {one.iterations} | {t1:.3f} | 1.00 |")
        if "multigrid" in METHODS:
            tm, gm = best(lambda g0=g0, tol=tol: meshcore.solve(g0, method="multigrid", tolerance=tol), repeat)
            print(f"| {tag} | {X.size} | one block {ni}×{nj}, multigrid | {gm.iterations} | {tm:.3f} | {tm / t1:.2f} |")
        for label, kw in (
            ("smooth, auto (default)", {"mode": "smooth"}),
            ("smooth, multigrid only", {"mode": "smooth", "engine": "multigrid"}),
            ("smooth, blocks engine (SOR)", {"mode": "smooth", "engine": "blocks"}),
            ("smooth, table engine (SOR)", {"mode": "smooth", "engine": "table"}),
            ("frozen (blocks solved separately)", {"mode": "frozen"}),
        ):
            t, mb = best(lambda kw=kw, tol=tol, topo=topo: solve_multiblock(topo, tolerance=tol, **kw), repeat)
            print(
                f"| {tag} | {n} | {len(topo.blocks)} blocks {label}: {mb.info.method} | "
                f"{mb.info.iterations} | {t:.3f} | {t / t1:.2f} |"
            )
    print()


#: The stages of ``generate_case`` of an ``[outline]`` multiblock case: (label, module, function).
STAGES = (
    ("outline: read and project", "meshcore.case.multiblock", "_outline_geometry"),
    ("blocks: chain cell counts", "meshcore.multiblock.chains", "_chain_counts"),
    ("blocks: re-sample the chains", "meshcore.multiblock.chains", "_resample"),
    ("topology: geometry check", "meshcore.multiblock.topology:MultiBlockTopology", "_check_geometry"),
    ("topology: node map", "meshcore.multiblock.topology", "build_node_map"),
    ("start grids", "meshcore.multiblock.solver", "initial_grids"),
    ("multigrid set-up: levels", "meshcore.multiblock.multigrid", "levels"),
    ("multigrid set-up: pack", "meshcore.multiblock.multigrid", "pack"),
    ("cycles: V-cycles", "meshcore.multiblock._mg_fused", "vcycle"),
    ("cycles: hot-spot sweeps", "meshcore.multiblock.multigrid", "_hot_sweeps"),
    ("cycles: defects", "meshcore.multiblock._kernels", "table_defect"),
)


def stages(repeat: int, quick: bool) -> None:
    """CPU time per stage of the multiblock CLI (each stage's function wrapped by a CPU timer)."""
    import importlib

    from meshcore.case import generate_case, load_case
    from meshcore.multiblock import hierarchy

    sys.path.insert(0, str(ROOT / "benchmarks"))
    from robust import _refined  # the refined example of the robust.py rows, written once

    spent: dict[str, float] = {}

    def timed(label, fn):
        def wrapper(*args, **kwargs):
            t = time.process_time()
            try:
                return fn(*args, **kwargs)
            finally:
                spent[label] = spent.get(label, 0.0) + time.process_time() - t

        return wrapper

    undo = []
    for label, where, name in STAGES:
        mod, _, cls = where.partition(":")
        owner = getattr(importlib.import_module(mod), cls) if cls else importlib.import_module(mod)
        undo.append((owner, name, getattr(owner, name)))
        setattr(owner, name, timed(label, getattr(owner, name)))
    print("## 4. multiblock CLI (generate_case) by stage, CPU ms, min of the repeats\n")
    runs = [("shasta-multiblock-coarse", 1)]
    runs += [] if quick else [("shasta-multiblock-fine", 1), ("shasta-multiblock-fine", 2)]
    rows: dict[str, list[float]] = {}
    try:
        for name, k in runs:
            case = load_case(ROOT / "resources" / "examples" / f"{name}.toml")
            if k > 1:
                case = _refined(case, k)
            cfg = case.solver.replaced(threads=1)
            best: dict[str, float] = {}
            for _ in range(repeat + 1):  # the first run loads the kernels
                hierarchy._CACHE.clear()
                spent.clear()
                t = time.process_time()
                generate_case(case, config=cfg)
                spent["CLI (all)"] = time.process_time() - t
                best = {key: min(v, best.get(key, math.inf)) for key, v in spent.items()}
            for label in [s[0] for s in STAGES] + ["CLI (all)"]:
                rows.setdefault(label, []).append(best.get(label, 0.0))
    finally:
        for owner, name, fn in undo:
            setattr(owner, name, fn)
    print("| stage | " + " | ".join(f"{n[18:]}{f' ×{k}' if k > 1 else ''}" for n, k in runs) + " |")
    print("|---|" + "---|" * len(runs))
    for label, ts in rows.items():
        print(f"| {label} | " + " | ".join(f"{1e3 * t:.1f}" for t in ts) + " |")
    print()


def cycle_costs(repeat: int, quick: bool) -> None:
    """Where a multiblock solve's time goes against one block of the same node count (section 5):
    per topology the cycles and their rates, the first solve and a re-solve, the set-up
    (``levels()``, ``pack``), the full-multigrid start, one V-cycle, the finest level's four
    smoothing steps in the fused cycle against its kernels called one by one (with the level's own
    int64 tables: the two differ where the tables do not stay in the cache), and one block's solve
    per cycle (the wavy square of robust.py).  CPU time, min of the repeats."""
    sys.path.insert(0, str(ROOT / "benchmarks"))
    import robust
    from run import wavy_square

    from meshcore.case import generate_case, load_case
    from meshcore.layout import auto_layout
    from meshcore.multiblock import _kernels as mk
    from meshcore.multiblock import _mg_fused as fused
    from meshcore.multiblock import hierarchy
    from meshcore.multiblock import multigrid as mg
    from meshcore.multiblock.result import assemble

    def cpu(fn, n: int) -> float:
        return min(_cpu_once(fn) for _ in range(n))

    topos = []
    for name, k in [("shasta-multiblock-coarse", 1)] + (
        [] if quick else [("shasta-multiblock-fine", 1), ("shasta-multiblock-fine", 2)]
    ):
        case = load_case(ROOT / "resources" / "examples" / f"{name}.toml")
        case = robust._refined(case, k) if k > 1 else case
        topos.append(
            (
                name[18:] + (f" ×{k}" if k > 1 else ""),
                generate_case(case, config=case.solver.replaced(threads=1)).topology,
            )
        )
    for lake in robust.LAYOUT_LAKES[:1] if quick else robust.LAYOUT_LAKES:
        shore = robust.outline(dict(robust.LAKES)[lake])
        topos.append((f"{lake} layout", auto_layout(shore, target_cells=robust.LAYOUT_CELLS, multiple=4).topology()))
    print("## 5. where a multiblock solve's time goes, CPU ms (min of the repeats)\n")
    print(
        "| topology | blocks | nodes | cycles: rates | first | re-solve | levels | pack | FMG | V-cycle (ns/node) "
        "| finest 4 steps: fused / kernels | one block: solve, cycles, ns/node/cycle |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")

    def row(label: str, topo) -> None:
        n = topo.node_map.n_nodes
        first = cpu(lambda: (hierarchy._CACHE.clear(), solve_multiblock(topo, threads=1)), repeat)
        again = cpu(lambda: solve_multiblock(topo, threads=1), repeat)
        h = [r for _, r in solve_multiblock(topo, threads=1).info.residual_history]
        rates = " ".join(f"{b / a:.2f}" for a, b in itertools.pairwise(h))
        t_lv = cpu(lambda: (hierarchy._CACHE.clear(), hierarchy.levels(topo)), repeat)
        lvs = hierarchy.levels(topo)
        t_pack = cpu(lambda: mg.pack(lvs), repeat)
        x, y = assemble(initial_grids(topo), topo.node_map)
        t_fmg = cpu(lambda: mg._fmg(lvs, x.copy(), y.copy()), repeat)
        mg._fmg(lvs, x, y)
        z = np.zeros(n)
        t_cyc = cpu(lambda: mg._cycle(lvs, 0, x.copy(), y.copy(), z, z), 5 * repeat)
        fb, ib, meta = mg._packed(lvs)
        m0, lv, e = meta[0], lvs[0], np.zeros(0)
        xf, yf = fused._f(fb, m0, fused.C_X), fused._f(fb, m0, fused.C_Y)
        steps = cpu(lambda: fused._smooth(fb, ib, m0, 4, mg.BORDER_SWEEPS, mg.BAND_SWEEPS, 1.0, False), 5 * repeat)
        sweep = [
            cpu(lambda t=t: mk.table_sweep_rhs(xf, yf, e, e, *t, 1.0), 5 * repeat)
            for t in (lv.args, lv.border, lv.band)
        ]
        lines = [cpu(lambda t=t: mk.line_sweep_rhs(xf, yf, e, e, *t, 1.0), 5 * repeat) for t in lv.lines]
        alone = 4 * sweep[0] + 2 * sum(lines) + 4 * (mg.BORDER_SWEEPS * sweep[1] + mg.BAND_SWEEPS * sweep[2])
        sq = wavy_square(round(math.sqrt(n)) - 1)
        t_sq = cpu(lambda: meshcore.solve(sq, threads=1), repeat)
        its = max(meshcore.solve(sq, threads=1).info.iterations, 1)
        ms = [f"{1e3 * t:.2f}" for t in (first, again, t_lv, t_pack, t_fmg)]
        print(
            f"| {label} | {len(topo.blocks)} | {n} | {len(h) - 1}: {rates} | "
            + " | ".join(ms)
            + f" | {1e3 * t_cyc:.2f} "
            f"({1e9 * t_cyc / n:.0f}) | {1e3 * steps:.2f} / {1e3 * alone:.2f} | {1e3 * t_sq:.2f}, {its}, "
            f"{1e9 * t_sq / its / n:.0f} |"
        )

    for label, topo in topos:
        row(label, topo)
    print()


def _cpu_once(fn) -> float:
    t = time.process_time()
    fn()
    return time.process_time() - t


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--quick", action="store_true", help="small sizes only")
    ap.add_argument("--stages", action="store_true", help="only the CLI's stages (section 4)")
    ap.add_argument("--cycles", action="store_true", help="only where a solve's time goes (section 5)")
    a = ap.parse_args()
    print(f"numba threading layer: {bk.threading_layer()}; serial kernels; best of {a.repeat}\n")
    meshcore.elliptic.warmup()
    if a.stages or a.cycles:
        (stages if a.stages else cycle_costs)(a.repeat, a.quick)
        return
    sizes = [(128, 64)] if a.quick else [(128, 64), (256, 128), (512, 256)]
    per_sweep(a.repeat, sizes)
    whole_solves(a.repeat, [(64, 32)] if a.quick else [(128, 64), (256, 128), (512, 256)])
    lake(a.repeat, a.quick)
    stages(a.repeat, a.quick)
    cycle_costs(a.repeat, a.quick)


if __name__ == "__main__":
    main()
