"""Measurements and figures for grid control (issue 7): prints markdown tables,
writes docs/figures/{bottle-orthogonal,two-circles-ogrid,naca0012-ogrid,naca0012-cgrid}.png.

Run from the repository root: ``python scripts/control_report.py [--no-figures]``.
"""

from __future__ import annotations

import csv
import math
import sys
import time
from pathlib import Path

import numpy as np

import meshcore
from meshcore.airfoil import first_cell_height, naca4_body
from meshcore.algebraic import algebraic_grid
from meshcore.boundary import Borders
from meshcore.control import (
    ControlSources,
    ControlSpec,
    border_angles,
    boundary_report,
    first_spacing,
)
from meshcore.generate import initial_grid, prepare_borders
from meshcore.topology import cgrid, ogrid, radial_nodes

ROOT = Path(__file__).resolve().parent.parent
FIG = ROOT / "docs" / "figures"
LAKES = ROOT.parent / "shared" / "data" / "lakes"
if not LAKES.exists():
    LAKES = Path("/work/shared/data/lakes")
WALLS = ("bottom", "right", "top", "left")

# The measured shapes are the tests' shapes (one definition).
sys.path.insert(0, str(ROOT))
from tests.meshcore.test_control import bottle_points, circle  # noqa: E402


def run(g0, spec=None, periodic=False, curves=None, max_iterations=50000):
    src = None if spec is None else ControlSources(spec, periodic=periodic, curves=curves)
    t = time.perf_counter()
    g = meshcore.solve(g0, method="sor", sources=src, max_iterations=max_iterations)
    return g, time.perf_counter() - t


def row(name, g, dt, borders, spacing=None, wall_slice=None):
    q = meshcore.quality(g)
    if wall_slice is None:
        rep = boundary_report(g, borders, spacing)
        amax, amean, serr = (
            rep["max_angle_deviation"],
            rep["mean_angle_deviation"],
            rep["max_spacing_error"],
        )
    else:
        a = np.abs(border_angles(g, "bottom")[wall_slice] - 90)
        amax, amean = a.max(), a.mean()
        s = first_spacing(g, "bottom")[wall_slice]
        serr = np.abs(s / spacing["bottom"] - 1).max() if spacing else float("nan")
    return (
        f"| {name} | {g.cells[0]}×{g.cells[1]} | {g.converged} | {g.iterations} | {dt:.2f} | {q.n_folded} "
        f"| {amax:.3f} | {amean:.3f} | {serr * 100:.2f} | {q.mean_orthogonality:.2f} |"
    )


HEAD = (
    "| case | cells | converged | sweeps | s | folded | wall max |θ−90°| | wall mean |θ−90°| "
    "| max first-cell error % | mean cell orthogonality dev ° |\n|---|---|---|---|---|---|---|---|---|---|"
)


def plot(path, grids, titles, windows=None):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    nrow = 1 if windows is None else 2
    fig, axs = plt.subplots(nrow, len(grids), figsize=(5.5 * len(grids), 5.2 * nrow), squeeze=False)
    for k, (g, t) in enumerate(zip(grids, titles, strict=True)):
        for r in range(nrow):
            a = axs[r, k]
            a.plot(g.x, g.y, "k-", lw=0.35)
            a.plot(g.x.T, g.y.T, "k-", lw=0.35)
            a.set_aspect("equal")
            a.set_title(t if r == 0 else t + " (zoom)", fontsize=10)
            if windows is not None:
                w = windows[r]
                if w is not None:
                    a.set_xlim(w[0], w[1])
                    a.set_ylim(w[2], w[3])
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def bottle(figures):
    print("\n### Bottle (paper-like, 4×10 input points), all four walls controlled\n")
    print(HEAD)
    out = []
    for cells, sp in (((6, 15), 0.1), ((12, 30), 0.05)):
        specs = {n: {"distribution": "vinokur", "first": sp, "last": sp} for n in WALLS}
        b = prepare_borders(*bottle_points(), cells=cells, borders=specs)
        g0 = initial_grid(b, weights=(1.0, 0.5))
        gw, tw = run(g0)
        print(row("Winslow (P=Q=0)", gw, tw, WALLS, None))
        for kind in ("hilgenstock-white", "steger-sorenson"):
            g, t = run(g0, ControlSpec(kind=kind, borders={n: {"spacing": sp} for n in WALLS}))
            print(row(f"{kind}, spacing {sp}", g, t, WALLS, dict.fromkeys(WALLS, sp)))
            errs = [np.abs(first_spacing(g, n) / sp - 1)[1:-1].max() for n in WALLS]
            print(
                f"|  ↳ first-cell error without the corner-adjacent nodes: {100 * max(errs):.2f} % | | | | | | | | | |"
            )
            if kind == "hilgenstock-white":
                out.append((gw, g, cells))
    if figures:
        gw, g, _ = out[1]
        plot(
            FIG / "bottle-orthogonal.png",
            [gw, g],
            ["bottle 12×30, Winslow", "bottle 12×30, walls orthogonal, first cell 0.05"],
        )


def two_circles(figures):
    print("\n### Two circles: periodic O-grid (the cut is a seam), inner and outer wall controlled\n")
    print(HEAD)
    inner, outer = circle((0, 0), 1.0), circle((0.8, 0.4), 3.0)
    sp = {"bottom": 0.05, "top": 0.2}
    keep = None
    for cells in ((30, 6), (40, 8), (120, 32)):
        g0 = ogrid(inner, outer, cells)
        gw, tw = run(g0)
        g, t = run(g0, ControlSpec(borders={k: {"spacing": v} for k, v in sp.items()}), periodic=True)
        print(row("Winslow", gw, tw, ("bottom", "top")))
        print(row("HW, spacing 0.05 / 0.2", g, t, ("bottom", "top"), sp))
        for nm, gg in (("Winslow", gw), ("controlled", g)):
            qa = meshcore.cell_quality(gg)
            sr = qa["size_ratio"].max(axis=1)
            orr = qa["orthogonality"].mean(axis=1)
            x, y = gg.x[:-1], gg.y[:-1]
            d2 = np.hypot(
                np.roll(x, -1, 0) - 2 * x + np.roll(x, 1, 0),
                np.roll(y, -1, 0) - 2 * y + np.roll(y, 1, 0),
            )[:, 1:-1].max(axis=1)
            print(
                f"|  ↳ seam, {nm}: size ratio seam cols {sr[0]:.3f}/{sr[-1]:.3f} vs others ≤ {sr[1:-1].max():.3f}; "
                f"orthogonality seam {orr[0]:.2f}/{orr[-1]:.2f}° vs others "
                f"{orr[1:-1].min():.2f}–{orr[1:-1].max():.2f}°; "
                f"max ξ 2nd difference at seam {d2[0]:.4f} vs elsewhere ≤ {d2[1:].max():.4f} | | | | | | | | | |"
            )
        if cells == (40, 8):
            keep = (gw, g)
    # concentric: log-polar convergence
    print("\nConcentric circles r = 1 … 4 (exact grid x = 4^η (cos θ, sin θ)), Winslow, periodic:\n")
    print("| cells | max node error | rate |\n|---|---|---|")
    prev = None
    for n in (16, 32, 64):
        ni, nj = 2 * n, n // 2
        th = -np.linspace(0, 2 * np.pi, ni + 1)
        ring = np.column_stack([np.cos(th), np.sin(th)])[:-1]
        g = meshcore.solve(ogrid(ring, 4 * ring, (ni, nj)), method="sor", tolerance=1e-12, max_iterations=200000)
        R = 4.0 ** np.linspace(0, 1, nj + 1)
        e = np.max(np.hypot(g.x - np.cos(th)[:, None] * R, g.y - np.sin(th)[:, None] * R))
        print(f"| {ni}×{nj} | {e:.3e} | {'' if prev is None else f'{math.log2(prev / e):.2f}'} |")
        prev = e
    if figures:
        plot(
            FIG / "two-circles-ogrid.png",
            list(keep),
            [
                "two circles O-grid 40×8, Winslow",
                "two circles O-grid 40×8, walls orthogonal, first cell 0.05/0.2",
            ],
        )


def naca(figures):
    dy = first_cell_height(30.0, 1e6)
    print(f"\n### NACA 0012 (closed TE), first cell {dy:.2e} chords = y⁺ 30 at Re 10⁶\n")
    print(HEAD)
    n, nj, R = 64, 48, 5.0
    body = naca4_body("0012", n)
    th = -np.linspace(0, 2 * np.pi, 2 * n + 1)
    top = np.column_stack([0.5 + R * np.cos(th), R * np.sin(th)])
    cut = radial_nodes(body[0], top[0], nj, first=dy)
    g0 = algebraic_grid(Borders(bottom=body, right=cut.copy(), top=top, left=cut, periodic=True), "tfi")
    gw, tw = run(g0)
    g, t = run(g0, ControlSpec(thomas_middlecoff=True, borders={"bottom": {"spacing": dy}}), periodic=True)
    print(row("O-grid Winslow", gw, tw, ("bottom",), {"bottom": dy}))
    print(row("O-grid TM + HW wall", g, t, ("bottom",), {"bottom": dy}))
    og = (gw, g)
    C = cgrid(naca4_body("0012", 48), cells_wake=24, cells_normal=40, first=dy)
    wall = slice(C.body[0], C.body[1] - 1)
    gw, tw = run(C.grid)
    gw2, tw2 = run(C.grid, ControlSpec(wake=C.wake))
    spec = ControlSpec(
        thomas_middlecoff=True,
        wake=C.wake,
        borders={"bottom": {"spacing": dy, "start": C.body[0] + 1, "stop": C.body[1]}},
    )
    g, t = run(C.grid, spec, max_iterations=80000)
    print(row("C-grid Winslow, wake cut fixed", gw, tw, ("bottom",), {"bottom": dy}, wall))
    print(row("C-grid Winslow, wake cut solved", gw2, tw2, ("bottom",), {"bottom": dy}, wall))
    print(row("C-grid TM + HW wall, wake solved", g, t, ("bottom",), {"bottom": dy}, wall))
    if figures:
        z = (-0.15, 1.15, -0.45, 0.45)
        plot(
            FIG / "naca0012-ogrid.png",
            list(og),
            ["NACA 0012 O-grid 128×48, Winslow", "TM + orthogonal wall, y+ ≈ 30"],
            windows=[(-5, 6, -5.5, 5.5), z],
        )
        plot(
            FIG / "naca0012-cgrid.png",
            [gw2, g],
            ["NACA 0012 C-grid 144×40, Winslow", "TM + orthogonal wall, y+ ≈ 30"],
            windows=[(-5, 6.5, -5.5, 5.5), z],
        )


def lake_loop(path):
    with open(path) as fh:
        rows = list(csv.DictReader(fh))
    lon = np.array([float(r["lon"]) for r in rows])
    lat = np.array([float(r["lat"]) for r in rows])
    lat0 = math.radians(lat.mean())
    Rm = 6371008.8
    x = Rm * np.radians(lon - lon.mean()) * math.cos(lat0)
    y = Rm * np.radians(lat - lat.mean())
    p = np.column_stack([x, y])
    c = p.mean(axis=0)
    w, v = np.linalg.eigh(np.cov((p - c).T))
    ax = v[:, np.argmax(w)]
    ay = np.array([-ax[1], ax[0]])
    u = (p - c) @ np.column_stack([ax, ay])
    lo, hi = u.min(axis=0), u.max(axis=0)
    boxc = [(lo[0], lo[1]), (hi[0], lo[1]), (hi[0], hi[1]), (lo[0], hi[1])]  # sw se ne nw
    corners = []
    for bc in boxc:
        d = np.hypot(u[:, 0] - bc[0], u[:, 1] - bc[1])
        for k in np.argsort(d):
            if k not in corners:
                corners.append(int(k))
                break
    length = hi[0] - lo[0]
    width = hi[1] - lo[1]
    return p, corners, length / width


def lakes(figures):
    print(
        "\n### Real lakes (sparse outlines, equirectangular metres, corners nearest the principal-axis box corners)\n"
    )
    print(
        "| lake | cells | variant | converged | sweeps | folded | non-convex | mean cell orth. dev ° "
        "| shore mean |θ−90°| | shore max |θ−90°| |\n|---|---|---|---|---|---|---|---|---|---|"
    )
    for f in sorted(LAKES.glob("*_sparse.csv")):
        p, corners, ar = lake_loop(f)
        nj = 12
        ni = round(nj * min(max(ar, 1.0), 6.0))
        try:
            b = prepare_borders(loop=p, corners=corners, cells=(ni, nj))
        except meshcore.MeshcoreError as exc:
            print(f"| {f.stem} | — | boundary rejected: {exc} | | | | | | | |")
            continue
        g0 = initial_grid(b)
        variants = [
            ("Winslow", None),
            ("floating nodes, all shores", ControlSpec(floating=WALLS)),
            (
                "HW angle 90°, corner_blend 4",
                ControlSpec(relaxation=0.05, borders={n: {"corner_blend": 4} for n in WALLS}),
            ),
        ]
        for name, spec in variants:
            g, _ = run(
                g0,
                spec,
                curves={n: getattr(b, n) for n in WALLS} if spec else None,
                max_iterations=30000,
            )
            q = meshcore.quality(g)
            rep = boundary_report(g, WALLS)
            print(
                f"| {f.stem.replace('_sparse', '')} | {ni}×{nj} | {name} | {g.converged} "
                f"| {g.iterations} | {q.n_folded} "
                f"| {q.n_nonconvex} | {q.mean_orthogonality:.2f} | {rep['mean_angle_deviation']:.2f} "
                f"| {rep['max_angle_deviation']:.2f} |"
            )


if __name__ == "__main__":
    figs = "--no-figures" not in sys.argv
    which = [a for a in sys.argv[1:] if not a.startswith("--")] or [
        "bottle",
        "two",
        "naca",
        "lakes",
    ]
    if "bottle" in which:
        bottle(figs)
    if "two" in which:
        two_circles(figs)
    if "naca" in which:
        naca(figs)
    if "lakes" in which:
        lakes(figs)
