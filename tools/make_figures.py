"""Regenerate docs/figures/<case>.png and docs/paper-cases.md for the paper's monoblock cases.

Each figure shows the grid with the case's input boundary points (the paper's
"predefined points") as open circles; the Markdown file holds each grid's
quality table and solve summary.  Run: python tools/make_figures.py
"""

from __future__ import annotations

import time
from pathlib import Path

import meshcore
from meshcore.case import generate_case, load_case
from meshcore.cli.examples import example_path
from meshcore.plot import plot_grid

ROOT = Path(__file__).resolve().parent.parent
CASES = [
    "rectangle-cutout-coarse",
    "rectangle-cutout-fine",
    "two-circles-coarse",
    "two-circles-fine",
    "bottle-coarse",
    "bottle-fine",
    "annulus-sector",
]


def main() -> None:
    figs = ROOT / "docs" / "figures"
    figs.mkdir(parents=True, exist_ok=True)
    lines = [
        "# The paper's monoblock cases, regenerated",
        "",
        "Made by `python tools/make_figures.py` from `resources/examples/*.toml`.",
        "",
    ]
    for name in CASES:
        case = load_case(example_path(name))
        t0 = time.perf_counter()
        grid = generate_case(case)[0]
        dt = time.perf_counter() - t0
        blk = case.blocks[0]
        pts = list(blk.boundary) if blk.boundary is not None else [blk.points]
        plot_grid(
            grid, figs / f"{name}.png", title=f"{case.title}\n{grid.cells[0]} × {grid.cells[1]} cells", points=pts
        )
        rep = meshcore.quality(grid)
        lines += [
            f"## {case.title}",
            "",
            f"![{name}](figures/{name}.png)",
            "",
            f"`{name}`: {grid.info.method}, {grid.info.message} after {grid.iterations} iterations, "
            f"residual {grid.residual:.2e} (tolerance {grid.info.tolerance:.1e}), {dt * 1e3:.1f} ms "
            "including start-up of the solve.",
            "",
            rep.table(),
            "",
        ]
    (ROOT / "docs" / "paper-cases.md").write_text("\n".join(lines), encoding="utf-8")


if __name__ == "__main__":
    main()
