"""Benchmarks of the solver on the grids users make (issue 15): real lakes, a busy machine,
first start, wall control, multiblock, the app against the CLI.

Run from the repository root::

    python benchmarks/robust.py [--quick] [--section lakes busy startup naca multiblock app]
        [--out benchmarks/RESULTS.md]

Every ratio compares two timings of the same run (medians; the machine is shared).
"""

from __future__ import annotations

import argparse
import math
import os
import re
import statistics
import subprocess
import sys
import tempfile
import textwrap
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(ROOT))

import meshcore  # noqa: E402

sys.path.insert(0, str(HERE))
from run import wavy_square  # noqa: E402  (the scale-series square, written once)

#: (label, file): real lakes nobody on the project drew or tuned on (GSHHG outlines, see
#: benchmarks/lakes/README.md and benchmarks/data/README.md for sources and licences).
LAKES = [
    ("Shasta", HERE / "data" / "shasta_lake.csv"),
    ("Como", HERE / "lakes" / "lake_como.csv"),
    ("Lucerne", HERE / "lakes" / "lake_lucerne.csv"),
    ("Lugano", HERE / "lakes" / "lake_lugano.csv"),
    ("Maggiore", HERE / "data" / "lake_maggiore.csv"),
    ("Garda", HERE / "data" / "lake_garda.csv"),
    ("Geneva", HERE / "data" / "lake_geneva.csv"),
    ("Lomond", HERE / "data" / "loch_lomond.csv"),
    ("Ness", HERE / "lakes" / "loch_ness.csv"),
]
#: Lakes of the automatic multiblock layouts (tens of blocks), at about LAYOUT_CELLS cells.
LAYOUT_LAKES = ["Shasta", "Como", "Lucerne", "Garda"]
LAYOUT_CELLS = 15_000


def fmt(t: float) -> str:
    if not math.isfinite(t):
        return "–"
    if t < 1e-3:
        return f"{t * 1e6:.0f} µs"
    if t < 1:
        return f"{t * 1e3:.1f} ms"
    return f"{t:.2f} s"


def timed(fn, repeats: int, warm: bool = True, budget: float = math.inf, clock=time.perf_counter):
    """``(result, median, best)`` of up to ``repeats`` calls (after one warm-up call if ``warm``);
    stops repeating once the calls took ``budget`` seconds (slow solves run once)."""
    out = fn() if warm else None
    ts: list[float] = []
    while len(ts) < repeats and sum(ts) < budget:
        t = clock()
        out = fn()
        ts.append(clock() - t)
    return out, statistics.median(ts), min(ts)


def outline(path: Path) -> np.ndarray:
    """The shore of a lake file in local metres (``meshcore import``'s projection)."""
    from meshcore.crs import project
    from meshcore.io import read_points

    local, _ = project(read_points(path), "auto")
    rings = [p for p in local.polylines if p.closed]
    return max(rings or list(local.polylines), key=len).points


def lake_block(path: Path, nodes: int = 24_000):
    """A lake as a new user grids it: ``meshcore import``'s projection, corners and cell ratio,
    scaled to about ``nodes`` nodes. Returns the keyword arguments of ``generate_block``."""
    from meshcore.io.outline import guess_cells, guess_corners

    loop = outline(path)
    corners = guess_corners(loop)
    ci, cj = guess_cells(loop, corners)
    s = math.sqrt(nodes / ((ci + 1) * (cj + 1)))
    return {"loop": loop, "corners": corners, "cells": (max(4, round(ci * s)), max(4, round(cj * s)))}


# ------------------------------------------------------------------------------ lakes
def lakes(quick: bool, emit) -> dict:
    """Each lake as one block at ~24 000 nodes against a smooth square of equal node count."""
    nodes = 24_000
    reps = 3 if quick else 5
    emit(
        f"\n### Real lakes as one block (~{nodes} nodes, 1 thread)\n\n"
        "Corners and cell ratio as `meshcore import` chooses them; Winslow = `generate_block(..., "
        'repair="off", threads=1)`, default = the same with the fold-free repair (`repair="auto"`). '
        "Square = the wavy square of the scale series with the same node count, solved the same "
        "way in the same run. Times are CPU seconds of the benchmark process (medians), not wall clock.\n"
    )
    emit(
        "| lake | cells | Winslow | cycles | fallback | ÷ square | default (repair) | ÷ square | "
        "folded after Winslow → after repair |"
    )
    emit("|---|---|---|---|---|---|---|---|---|")
    out = {}
    # one default call first: the kernels the lakes need and the square does not (line smoothing,
    # the repair) are compiled or loaded from numba's cache here, not in the first lake's timing
    meshcore.generate_block(**lake_block(LAKES[0][1], nodes), threads=1)
    for label, path in LAKES[:4] if quick else LAKES:
        kw = lake_block(path, nodes)
        ni, nj = kw["cells"]
        n = round(math.sqrt((ni + 1) * (nj + 1))) - 1
        sq = wavy_square(n)
        sb = dict(zip(("bottom", "right", "top", "left"), _borders(sq), strict=True))
        cpu = time.process_time
        _, t_sq, _ = timed(lambda sb=sb: meshcore.generate_block(**sb, threads=1, repair="off"), reps, clock=cpu)
        g, t_w, _ = timed(
            lambda kw=kw: meshcore.generate_block(**kw, threads=1, repair="off"), reps, False, 2.0, clock=cpu
        )
        cycles = g.iterations
        fallback = "SOR" if "sor" in g.info.message.lower() or g.info.method != "multigrid" else "no"
        folded = meshcore.quality(g).n_folded
        gd, t_d, _ = timed(lambda kw=kw: meshcore.generate_block(**kw, threads=1), reps, False, 2.0, clock=cpu)
        folded_d = meshcore.quality(gd).n_folded
        conv = "" if g.converged else " (not converged)"
        emit(
            f"| {label} | {ni}×{nj} | {fmt(t_w)}{conv} | {cycles} | {fallback} | {t_w / t_sq:.1f}× | "
            f"{fmt(t_d)} | {t_d / t_sq:.1f}× | {folded} → {folded_d} |"
        )
        out[label] = (t_w / t_sq, t_d / t_sq, fallback)
    sq_nodes = (n + 1) ** 2
    emit(f"\n(last square: {sq_nodes} nodes, {fmt(t_sq)}.)")
    return out


def _borders(g):
    x, y = np.asarray(g.x), np.asarray(g.y)
    return (
        np.column_stack([x[:, 0], y[:, 0]]),
        np.column_stack([x[-1], y[-1]]),
        np.column_stack([x[:, -1], y[:, -1]]),
        np.column_stack([x[0], y[0]]),
    )


# ------------------------------------------------------------------------------- busy
_BUSY_CODE = textwrap.dedent("""
    import sys, time, statistics
    sys.path.insert(0, {here!r})
    import meshcore, robust
    g0 = robust.wavy_square({n})
    res = {{}}
    for threads in (1, 0):
        meshcore.solve(g0, method="multigrid", threads=threads)
    for _ in range(3):
        for threads in (1, 0):
            ts = []
            for _ in range(5):
                t = time.perf_counter()
                meshcore.solve(g0, method="multigrid", threads=threads)
                ts.append(time.perf_counter() - t)
            res.setdefault(threads, []).append(statistics.median(ts))
    print(statistics.median(res[1]), statistics.median(res[0]))
""")


def busy(quick: bool, emit) -> dict:
    """Default threads (0) against threads=1 on 257², idle and with one process spinning on a core.

    The solves run in a new process with the environment a user has (no OMP_WAIT_POLICY),
    so that meshcore's own choice of the OpenMP wait policy is what is measured.
    """
    n = 256
    env = {k: v for k, v in os.environ.items() if k not in ("OMP_WAIT_POLICY", "GOMP_SPINCOUNT", "NUMBA_NUM_THREADS")}
    env["PYTHONPATH"] = str(ROOT)
    code = _BUSY_CODE.format(here=str(HERE), n=n)
    emit(
        f"\n### Busy machine ({n + 1}², default `threads=0` = {os.cpu_count()} threads here, against "
        "`threads=1`)\n\nA new process with a user's environment (no `OMP_WAIT_POLICY`); "
        "'busy' = one other process spinning in a Python loop meanwhile.\n"
    )
    emit("| load | threads=1 | threads=0 (default) | ratio |")
    emit("|---|---|---|---|")
    out = {}
    for label in ("idle", "one busy process"):
        hog = None
        if label != "idle":
            hog = subprocess.Popen([sys.executable, "-c", "while True: pass"])
        try:
            cmd = [sys.executable, "-c", code]
            r = subprocess.run(cmd, env=env, cwd=ROOT, capture_output=True, text=True, timeout=900)
        finally:
            if hog is not None:
                hog.kill()
                hog.wait()
        try:
            t1, t0 = (float(v) for v in r.stdout.split())
        except ValueError:
            emit(f"| {label} | failed: {r.stderr.strip()[-200:]} | | |")
            continue
        emit(f"| {label} | {fmt(t1)} | {fmt(t0)} | {t0 / t1:.2f} |")
        out[label] = t0 / t1
    return out


# ---------------------------------------------------------------------------- startup
_FIRST_SOLVE = textwrap.dedent("""
    import time; t0 = time.perf_counter()
    import numpy as np, meshcore
    t1 = time.perf_counter()
    s = np.linspace(0, 1, 65)
    g = meshcore.generate_block(np.c_[s, 0.1 * np.sin(2 * np.pi * s)], np.c_[1 + 0 * s, s], np.c_[s, 1 + 0 * s],
                                np.c_[0 * s, s])
    t2 = time.perf_counter()
    print(f"{t1 - t0:.3f} {t2 - t1:.3f} {t2 - t0:.3f} {g.info.method} {g.converged}")
""")


def startup(quick: bool, emit) -> dict:
    """A new environment: the set-up compile, then the first solve of a new process."""
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    emit(
        "\n### First solve in a new environment\n\nAn empty `NUMBA_CACHE_DIR`; `set-up` = the compile "
        "step of `scripts/setup.sh` (`compile_all()`); then new processes: import meshcore + "
        "`generate_block` 65² (default settings), and `meshcore generate` of the bottle example "
        "(whole CLI run).\n"
    )
    out = {}
    with tempfile.TemporaryDirectory() as d:
        env["NUMBA_CACHE_DIR"] = d
        t = time.perf_counter()
        r = subprocess.run(
            [sys.executable, "-c", "from meshcore._numba_setup import compile_all; compile_all()"],
            env=env, cwd=ROOT, capture_output=True, text=True, timeout=3600,
        )  # fmt: skip
        t_setup = time.perf_counter() - t
        emit("| step | import (s) | solve (s) | total (s) |")
        emit("|---|---|---|---|")
        emit(f"| set-up compile (once) | | | {t_setup:.1f}{'' if r.returncode == 0 else ' FAILED'} |")
        for k in range(2):
            r = subprocess.run([sys.executable, "-c", _FIRST_SOLVE], env=env, cwd=ROOT, capture_output=True, text=True)
            v = r.stdout.split()
            emit(f"| {'first' if k == 0 else 'second'} process: generate_block 65² | {v[0]} | {v[1]} | {v[2]} |")
            out[f"process{k}"] = float(v[2])
        with tempfile.TemporaryDirectory() as o:
            t = time.perf_counter()
            case = "resources/examples/bottle-fine.toml"
            cmd = [sys.executable, "-m", "meshcore", "generate", case, "-o", f"{o}/b.vts"]
            r = subprocess.run(cmd, env=env, cwd=ROOT, capture_output=True, text=True)
            t_cli = time.perf_counter() - t
        emit(f"| new process: `meshcore generate bottle-fine.toml` | | | {t_cli:.2f} |")
        out["cli"] = t_cli
    return out


# ------------------------------------------------------------------------------- NACA
def naca(quick: bool, emit) -> dict:
    """The NACA 0012 O- and C-grid examples with wall control (as shipped and with multigrid),
    and a wall-controlled O-grid round an ellipse at two sizes: method, cycles, time."""
    from meshcore.case import generate_case, load_case

    emit("\n### Wall control: NACA 0012 examples and an ellipse O-grid (1 thread)\n")
    emit(
        "Ellipse: semi-axes 1 and 0.3, far field at 5, geometric wall stretching (first cell "
        "0.1/nj), Thomas–Middlecoff and the wall spacing controlled; sweeps (SOR) or cycles. Times are CPU "
        "seconds of the benchmark process (medians of 3; one run for solves over 5 s). C-grid (body, wake, "
        "normal cells): a NACA 0012 C-grid (`meshcore.topology.cgrid`) whose only control is the wake cut.\n"
    )
    emit("| case | nodes | method | iterations | converged | time |")
    emit("|---|---|---|---|---|---|")
    out = {}
    reps = 1 if quick else 3
    for name in ("naca0012-ogrid", "naca0012-cgrid"):
        case = load_case(ROOT / "resources" / "examples" / f"{name}.toml")
        for method in (case.solver.method, "multigrid"):
            cfg = case.solver.replaced(threads=1, method=method)
            (g,), t, _ = timed(lambda case=case, cfg=cfg: generate_case(case, config=cfg), reps, False, 5.0, CPU)
            how = f"{g.info.method} ({g.info.message})"
            emit(f"| {name} | {g.x.size} | {how} | {g.iterations} | {g.converged} | {fmt(t)} |")
            by_mg = g.info.method == "multigrid" and "SOR" not in g.info.message
            if by_mg or name not in out:
                out[name] = (t, "multigrid" if by_mg else g.info.method)
    sizes = [(128, 48)] if quick else [(128, 48), (256, 96)]
    for ni, nj in sizes:
        for method in ("multigrid", "sor"):
            if method == "sor" and ni > 128:
                emit(f"| ellipse {ni}×{nj} | {(ni + 1) * (nj + 1)} | sor | – | – | (skipped: ≈ 2 min) |")
                continue
            g, t, _ = timed(lambda ni=ni, nj=nj, m=method: _ellipse(ni, nj, m), reps, False, 5.0, CPU)
            emit(
                f"| ellipse {ni}×{nj} | {g.x.size} | {g.info.method} ({g.info.message}) | {g.iterations} | "
                f"{g.converged} | {fmt(t)} |"
            )
    for cells in ((48, 24, 24), (96, 32, 56)):
        for method in ("multigrid", "sor"):
            if method == "sor" and cells[0] < 96:
                skip = "(skipped: 100 000 sweeps did not converge, 67 s)"
                emit(f"| C-grid {cells}, wake cut only | | sor | – | – | {skip} |")
                continue
            g, t, _ = timed(lambda c=cells, m=method: _wake_cgrid(c, m), reps, False, 5.0, CPU)
            emit(
                f"| C-grid {cells}, wake cut only | {g.x.size} | {g.info.method} ({g.info.message}) | "
                f"{g.iterations} | {g.converged} | {fmt(t)} |"
            )
    return out


def _wake_cgrid(cells: tuple, method: str):
    """A NACA 0012 C-grid (body, wake and normal cells) whose only control is the wake cut, solved."""
    from meshcore.airfoil import naca4_body
    from meshcore.control import make_sources
    from meshcore.topology import cgrid

    c = cgrid(naca4_body("0012", cells[0]), cells_wake=cells[1], cells_normal=cells[2])
    src = make_sources({"wake": c.wake})
    return meshcore.solve(c.grid, method=method, sources=src, threads=1, max_iterations=100_000)


def _ellipse(ni: int, nj: int, method: str):
    """The wall-controlled ellipse O-grid of tests/meshcore/test_multigrid_control.py, solved."""
    from meshcore.control import make_sources

    first = 0.02 / nj
    lo, hi = 1.0 + 1e-12, 2.0
    for _ in range(100):
        r = 0.5 * (lo + hi)
        lo, hi = (lo, r) if first * (r**nj - 1) / (r - 1) > 1.0 else (r, hi)
    s = np.concatenate([[0.0], np.cumsum(first * r ** np.arange(nj))])
    s /= s[-1]
    th = np.linspace(0.0, -2 * np.pi, ni + 1)
    inner = np.column_stack([np.cos(th), 0.3 * np.sin(th)])
    outer = 5.0 * np.column_stack([np.cos(th), np.sin(th)])
    X = inner[:, :1] + (outer[:, :1] - inner[:, :1]) * s
    Y = inner[:, 1:] + (outer[:, 1:] - inner[:, 1:]) * s
    X[-1], Y[-1] = X[0], Y[0]
    g0 = meshcore.StructuredGrid(X, Y, periodic=True)
    src = make_sources({"thomas-middlecoff": True, "borders": {"bottom": {"spacing": 5 * first}}}, periodic=True)
    return meshcore.solve(g0, method=method, sources=src, threads=1, max_iterations=100_000)


# ------------------------------------------------------------------------- multiblock
def _cold_warm(topo, reps: int) -> tuple:
    """``(grid, first, re-solve)``: the median of multiblock solves with the multigrid set-up built
    (its cache emptied before each, as in a new process) and the median of re-solves of the same
    structure (cached set-up, as the app re-solves after a drag)."""
    from meshcore.multiblock import solve_multiblock

    def cold():
        _clear_setup_cache()
        return solve_multiblock(topo, threads=1)

    mb, first, _ = timed(cold, reps, False, 5.0, CPU)  # one sample varied 1.5x at a load of 10
    mb, again, _ = timed(lambda: solve_multiblock(topo, threads=1), reps, False, 5.0, CPU)
    return mb, first, again


#: The multiblock rows time CPU seconds of this process: both sides run on one thread, and the
#: jobs that share the machine then do not enter the ratio (wall-clock ratios varied 2× between
#: runs at a load of 8-12).
CPU = time.process_time


def _clear_setup_cache() -> None:
    """Empty the multigrid set-up cache (as in a new process; absent before it existed)."""
    try:
        from meshcore.multiblock import hierarchy
    except ImportError:
        return
    hierarchy._CACHE.clear()


def multiblock(quick: bool, emit) -> dict:
    """The 7-block Shasta cases (and refined 2×) and automatic lake layouts against one block of
    the same node count."""
    from meshcore.case import generate_case, load_case

    emit("\n### Multiblock against one block of the same node count (1 thread, CPU time)\n")
    emit(
        "| case | blocks | nodes | CLI (case → grid) | solve, first | re-solve | method | one block (square) | "
        "÷ CLI | ÷ first | ÷ re-solve | one block via the CLI | CLI ÷ CLI |"
    )
    emit("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    out = {}
    reps = 1 if quick else 3
    for name, refine in (("shasta-multiblock-coarse", 1), ("shasta-multiblock-fine", 1), ("shasta-multiblock-fine", 2)):
        case = load_case(ROOT / "resources" / "examples" / f"{name}.toml")
        if refine > 1:
            case = _refined(case, refine)
        cfg = case.solver.replaced(threads=1)

        def cli(case=case, cfg=cfg):
            _clear_setup_cache()  # every CLI run is a new process
            return generate_case(case, config=cfg)

        mb, t_cli, _ = timed(cli, reps, True, 10.0, CPU)
        label = name + (f" refined {refine}×" if refine > 1 else "")
        out[label] = _mb_row(label, mb.topology, t_cli, reps, quick, emit)
    for label in LAYOUT_LAKES[:2] if quick else LAYOUT_LAKES:
        from meshcore.layout import auto_layout

        topo = auto_layout(outline(dict(LAKES)[label]), target_cells=LAYOUT_CELLS, multiple=4).topology()
        out[f"{label} layout"] = _mb_row(f"{label} automatic layout", topo, math.nan, reps, quick, emit)
    emit(
        "\nCLI = `generate_case` of the example (outline → blocks → topology → solve; the set-up cache "
        "emptied before every run, as in a new process). solve, first = `solve_multiblock(topology, "
        "threads=1)` with the multigrid set-up built (its cache emptied before each of the repeats); "
        "re-solve = median of further solves of the same block structure (set-up cached: the app's "
        "re-solve after a drag). Layout rows: "
        f"`meshcore.layout.auto_layout(shore, target_cells={LAYOUT_CELLS}, multiple=4)` (the layout "
        "`meshcore mesh` makes before its orthogonal smoothing; layout time excluded). One block = the "
        "wavy square of the same node count, `meshcore.solve(square, threads=1)`. Times are CPU "
        "seconds of the benchmark process (medians), not wall clock. The target "
        "ratio is ÷ CLI for the examples and ÷ first for the layouts. One block via the CLI = "
        "`generate_case` of a one-block case whose borders are the square's nodes (the same grid as "
        "the square's solve, through the CLI's pipeline: borders, start grid, solve, checks); CLI ÷ CLI "
        "compares the two CLIs (in brackets for the layouts: their first solve, no CLI)."
    )
    return out


def _mb_row(label: str, topo, t_cli: float, reps: int, quick: bool, emit) -> tuple[float, float]:
    """One row; returns the target ratios against the square's solve and the one-block CLI
    (the CLI time for the examples, the first solve for the layouts)."""
    from meshcore.case import generate_case

    nodes = topo.node_map.n_nodes
    mb, t_first, t_again = _cold_warm(topo, reps)
    finite = all(np.isfinite(g.x).all() and np.isfinite(g.y).all() for g in mb.grids)
    conv = "" if mb.info.converged and finite else " (not converged)"
    sq = wavy_square(round(math.sqrt(nodes)) - 1)
    _, t_sq, _ = timed(lambda: meshcore.solve(sq, threads=1), 3 if quick else 7, clock=CPU)
    one = square_case(sq)
    cfg = one.solver.replaced(threads=1)
    _, t_one, _ = timed(lambda: generate_case(one, config=cfg), 3 if quick else 7, clock=CPU)
    cli = f"{t_cli / t_sq:.1f}×" if math.isfinite(t_cli) else "–"
    cli_cli = f"{t_cli / t_one:.1f}×" if math.isfinite(t_cli) else f"({t_first / t_one:.1f}×)"
    emit(
        f"| {label} | {len(topo.blocks)} | {nodes} | {fmt(t_cli)} | {fmt(t_first)}{conv} | {fmt(t_again)} | "
        f"{mb.info.method}, {mb.info.iterations} it. | {fmt(t_sq)} | {cli} | {t_first / t_sq:.1f}× | "
        f"{t_again / t_sq:.1f}× | {fmt(t_one)} | {cli_cli} |"
    )
    return (t_cli if math.isfinite(t_cli) else t_first) / t_sq, (t_cli if math.isfinite(t_cli) else t_first) / t_one


def square_case(sq):
    """A one-block case file whose borders are the nodes of the square ``sq`` (no ``cells``: the
    points are the nodes), so that ``generate_case`` makes the square's grid through the CLI's
    pipeline (borders, start grid, solve, checks)."""
    from meshcore.case import loads_case

    def pts(a) -> str:
        return "[" + ", ".join(f"[{u:.17g}, {v:.17g}]" for u, v in a) + "]"

    X, Y = sq.x, sq.y
    sides = {
        "bottom": np.c_[X[:, 0], Y[:, 0]],
        "right": np.c_[X[-1], Y[-1]],
        "top": np.c_[X[:, -1], Y[:, -1]],
        "left": np.c_[X[0], Y[0]],
    }
    text = '[[blocks]]\nname = "square"\n[blocks.boundary]\n'
    text += "".join(f"{k} = {pts(v)}\n" for k, v in sides.items())
    return loads_case(text, source="<square>")


def _refined(case, k: int):
    """An ``[outline]`` multiblock case with ``k`` times the cells of every block."""
    import dataclasses

    ol = case.outline
    blocks = tuple(dataclasses.replace(b, cells=(k * b.cells[0], k * b.cells[1])) for b in ol.blocks)
    return case.replaced(outline=dataclasses.replace(ol, blocks=blocks))


# ------------------------------------------------------------------------------- app
def app(quick: bool, emit) -> dict:
    """The app's solve of a case against the CLI's (``benchmarks/app_vs_cli.py``, a new process)."""
    emit(
        "\n### The app against the CLI (same case, same run)\n\nCLI = `generate_case(load_case(CASE))` "
        "(what `meshcore generate` runs); app = the main window (offscreen) opens the case, Generate, "
        "until the solver controller reports the grid, live redraws included. Medians of 3 after a "
        "warm-up. CPU = the CLI's thread against the app's solver thread; the last column is every "
        "thread of the app during the solve (drawing included). A lake outline (taal_lake): CLI = the grid "
        "and quality stages of `meshcore mesh` (going on from the chosen layout's coarse level, as the command "
        "does), app = import, Auto layout and the grid that follows it (Live on, as a user gets it), timed from "
        "the layout set to the grid; the run checks that both made the same layout and bit-identical grids, "
        "and that the app solved the grid once.\n"
    )
    cmd = [sys.executable, str(HERE / "app_vs_cli.py"), "--repeats", "1" if quick else "3"]
    env = dict(os.environ, PYTHONPATH=str(ROOT), QT_QPA_PLATFORM="offscreen")
    r = subprocess.run(cmd, env=env, cwd=ROOT, capture_output=True, text=True, timeout=3600)
    emit("| case | CLI | app | app ÷ CLI | CLI CPU | app solver CPU | CPU ratio | app CPU, all threads |")
    emit("|---|---|---|---|---|---|---|---|")
    out = {}
    for line in r.stdout.splitlines():
        name, *v = line.split("\t")
        cli, gui, cli_cpu, gui_cpu, *proc = map(float, v)
        emit(
            f"| {name} | {fmt(cli)} | {fmt(gui)} | {gui / cli:.2f} | {fmt(cli_cpu)} | {fmt(gui_cpu)} | "
            f"{gui_cpu / cli_cpu:.2f} | {fmt(proc[0]) if proc else '—'} |"
        )
        out[name] = gui / cli
    if r.returncode != 0:
        emit(f"\n(app_vs_cli.py failed: {r.stderr.strip().splitlines()[-1] if r.stderr.strip() else r.returncode})")
    return out


def _targets(res: dict) -> list[str]:
    """Issue 15's target rows of this run (worst case of each group), as table lines."""
    rows = []
    if res.get("lakes"):
        worst_w = max(v[0] for v in res["lakes"].values())
        worst_d = max(v[1] for v in res["lakes"].values())
        sor = sum(v[2] != "no" for v in res["lakes"].values())
        rows.append(
            (
                "real lakes, one block, Winslow ÷ square",
                "≤ 3×, no SOR fallback",
                f"worst {worst_w:.1f}×, {sor} of {len(res['lakes'])} fell back to SOR",
            )
        )
        rows.append(("real lakes, one block, default (repair) ÷ square", "≤ 3×", f"worst {worst_d:.1f}×"))
    if res.get("busy"):
        rows.append(
            (
                "257², one busy process: default ÷ threads=1",
                "≤ 1.2",
                f"{res['busy'].get('one busy process', math.nan):.2f}",
            )
        )
    if res.get("multiblock"):
        for k, (sq, cli) in res["multiblock"].items():
            rows.append((f"multiblock {k} ÷ one block", "≤ 2×", f"{sq:.1f}× (one block via the CLI: {cli:.1f}×)"))
    if res.get("naca"):
        for k, v in res["naca"].items():
            rows.append((f"{k} (wall control, by multigrid)", "≤ 1 s", f"{fmt(v[0])} ({v[1]})"))
    if res.get("app"):
        for k, v in res["app"].items():
            rows.append((f"app ÷ CLI, {k}", "≤ 1.2", f"{v:.2f}"))
    if res.get("startup"):
        rows.append(
            (
                "first solve in a new process after the set-up",
                "≤ 2 s",
                f"{res['startup'].get('process0', math.nan):.2f} s",
            )
        )
    return ["| " + " | ".join(r) + " |" for r in rows]


#: Everything after this line of RESULTS.md is this script's report (``--out``); run.py keeps it.
MARKER = "<!-- benchmarks/robust.py: everything below is its report -->"
SECTIONS = {"lakes": lakes, "busy": busy, "startup": startup, "naca": naca, "multiblock": multiblock, "app": app}


#: The heading that starts each section's report, and the first cell of its target rows: a run
#: of some sections replaces only theirs in the report (``--out``).
HEADINGS = {
    "lakes": ("### Real lakes as one block", "| real lakes"),
    "busy": ("### Busy machine", "| 257²"),
    "startup": ("### First solve in a new environment", "| first solve"),
    "naca": ("### Wall control", "| naca0012"),
    "multiblock": ("### Multiblock against one block", "| multiblock"),
    "app": ("### The app against the CLI", "| app ÷ CLI"),
}
TARGETS = "### Issue 15 targets in this run"
_TARGET_HEAD = ["| target | wanted | measured |", "|---|---|---|"]


def _history(section: str) -> str:
    """The paragraphs of a report section from the first that begins ``Session `` on (what each session
    measured and tried there, with its own tables and paragraphs): a rerun replaces the section's tables
    and keeps them (only the paragraphs that began ``Session `` were kept: session 16's changes and
    their table went with a rerun of the app section)."""
    paras = re.split(r"\n[ \t]*\n", section)
    first = next((k for k, p in enumerate(paras) if p.startswith("Session ")), len(paras))
    return "\n\n".join(p.strip("\n") for p in paras[first:])


def merge_report(old: str, header: list[str], sections: dict[str, list[str]], targets: list[str]) -> str:
    """The report after :data:`MARKER`: ``old``'s sections and target rows, with those of the
    sections in ``sections`` replaced (new ones appended in :data:`HEADINGS` order)."""
    chunks = re.split(r"(?m)^(?=### )", old)
    head = chunks[0].strip("\n") or "\n".join(header)  # an old header dates the sections it ran
    kept: dict[str, str] = {}
    rows: list[str] = []
    for ch in chunks[1:]:
        if ch.startswith(TARGETS):
            rows = [r for r in ch.splitlines() if r.startswith("| ") and r not in _TARGET_HEAD]
            continue
        name = next((k for k, (h, _) in HEADINGS.items() if ch.startswith(h)), None)
        kept[name or ch.splitlines()[0]] = ch.strip("\n")
    for name, lines in sections.items():  # the rerun's tables, then the old section's sessions' notes
        history = _history(kept.get(name, ""))
        kept[name] = "\n".join(lines).strip("\n") + (f"\n\n{history}" if history else "")
    prefixes = tuple(HEADINGS[k][1] for k in sections)
    rows = [r for r in rows if not r.startswith(prefixes)] + targets
    order = [k for k in HEADINGS if k in kept] + [k for k in kept if k not in HEADINGS]
    body = [head] + [kept[k] for k in order]
    if rows:
        rows.sort(key=lambda r: next((i for i, (_, p) in enumerate(HEADINGS.values()) if r.startswith(p)), 99))
        body.append("\n".join([TARGETS, "", *_TARGET_HEAD, *rows]))
    return "\n\n".join(body) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--section", nargs="*", default=list(SECTIONS), choices=list(SECTIONS))
    ap.add_argument(
        "--out", help=f"write the report into this file after {MARKER!r} (RESULTS.md): the sections run replace theirs"
    )
    args = ap.parse_args(argv)
    header = [
        "## Issue 15: the grids users make (`benchmarks/robust.py`)\n",
        f"`python benchmarks/robust.py` on {os.cpu_count()} cores. The machine is shared with other "
        "jobs: every ratio compares two timings of the same run; times are medians of up to 3–5 "
        "repeats (one run for solves over 2 s); each section says when it ran and the load.",
    ]
    sections: dict[str, list[str]] = {}
    for name in args.section:
        lines = sections[name] = []

        def emit(s="", lines=lines):
            print(s, flush=True)
            lines.append(s)

        load = ", ".join(f"{v:.2f}" for v in os.getloadavg())
        when = time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())
        results = {name: SECTIONS[name](args.quick, emit)}
        emit(f"\n(Run {when}{' --quick' if args.quick else ''}; load average {load} at its start.)")
        sections[name] = lines
        sections[name + "/targets"] = _targets(results)
    targets = [r for k in list(sections) if k.endswith("/targets") for r in sections.pop(k)]
    for r in targets:
        print(r)
    if args.out:
        path = Path(args.out)
        text = path.read_text(encoding="utf-8") if path.exists() else ""
        keep, _, old = text.partition(MARKER)
        report = merge_report(old.strip("\n"), header, sections, targets)
        path.write_text((keep.rstrip("\n") + "\n\n" if keep.strip() else "") + MARKER + "\n" + report, encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
