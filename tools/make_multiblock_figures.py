"""Shasta Lake multiblock figures and quality tables (docs/figures/shasta-multiblock-*.png).

Run from the repository root::

    python tools/make_multiblock_figures.py        # writes docs/figures/ and prints the tables
"""

from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))


from meshcore.case import case_topology, load_case, outline_points  # noqa: E402
from meshcore.multiblock import solve_multiblock  # noqa: E402
from meshcore.multiblock.figure import plot_multiblock  # noqa: E402

FIG = ROOT / "docs" / "figures"
EX = ROOT / "resources" / "examples"


def main() -> None:
    shore = outline_points(load_case(EX / "shasta-multiblock-coarse.toml"))
    out = {}
    for tag in ("coarse", "fine"):
        case = load_case(EX / f"shasta-multiblock-{tag}.toml")
        topo = case_topology(case)
        res = {m: solve_multiblock(topo, mode=m) for m in ("smooth", "frozen")}
        out[tag] = (topo, res)
        mb = res["smooth"]
        n = sum(g.cells[0] * g.cells[1] for g in mb.grids)
        plot_multiblock(
            mb,
            FIG / f"shasta-multiblock-{tag}.png",
            outline=shore,
            scale=1e-3,
            unit="km",
            title=f"Shasta Lake, {len(mb)} blocks, {n} cells, smooth interfaces ({tag})",
        )
        print(f"## {tag}\n")
        print(mb.report())
        print()
        for m, r in res.items():
            print(
                f"### mode {m}: {r.info.message}, {r.info.iterations} iterations, "
                f"{r.info.elapsed:.3f} s, interface mismatch {r.interface_mismatch():.3g}\n"
            )
            print(r.quality().table())
            print()
    # zoom on the main ↔ east and east ↔ arms interfaces: frozen vs smooth
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    topo, res = out["coarse"]
    fig, axes = plt.subplots(1, 2, figsize=(14, 6))
    # window: the east junction block and the end of the main basin (km)
    ex0, ey0, ex1, ey1 = (v * 1e-3 for v in res["smooth"]["east"].bounds())
    win = (ex0 - 4.0, ey0 - 0.6, ex1 + 1.5, ey1 + 1.2)
    for ax, m in zip(axes, ("frozen", "smooth"), strict=True):
        plot_multiblock(
            res[m],
            ax=ax,
            outline=shore,
            scale=1e-3,
            unit="km",
            window=win,
            labels=True,
            linewidth=0.6,
            title=f"{m}: interface size ratio {res[m].quality().worst_interface:.2f}",
        )
    fig.savefig(FIG / "shasta-multiblock-interfaces.png", dpi=140, bbox_inches="tight")
    plt.close(fig)
    # the confluence: three blocks meet at the centre (irregular corner)
    case = load_case(EX / "confluence-multiblock.toml")
    mb = solve_multiblock(case_topology(case))
    pts = outline_points(case)
    fig, axes = plt.subplots(1, 2, figsize=(14, 6.5))
    plot_multiblock(mb, ax=axes[0], outline=pts, labels=False, title="confluence: 6 blocks, smooth")
    plot_multiblock(
        mb,
        ax=axes[1],
        outline=pts,
        window=(-1.8, -1.8, 1.8, 1.6),
        linewidth=0.7,
        title="junction: three blocks meet at the centre (Laplacian update there)",
    )
    fig.savefig(FIG / "multiblock-confluence.png", dpi=140, bbox_inches="tight")
    plt.close(fig)
    print("## confluence\n")
    print(mb.report())
    print()
    print(mb.quality().table())


if __name__ == "__main__":
    main()
