"""Regenerate the grid-control example cases in resources/examples/ (issue 7).

* ``bottle-orthogonal``: the paper's bottle (12×30), every wall met at 90° with a
  first cell of 0.05 (borders clustered to match at the corners).
* ``two-circles-orthogonal``: the paper's two circles joined by a (fixed) cut,
  both circles met at 90°.
* ``two-circles-ogrid``: the same region as a periodic O-grid (the cut is a seam).
* ``naca0012-ogrid`` / ``naca0012-cgrid``: NACA 0012 (closed trailing edge) in a
  far field of 5 chords, first cell for y⁺ = 30 at Re = 10⁶, Thomas–Middlecoff
  interior and an orthogonal wall; the C-grid's wake cut is solved (``wake``).

Run: python tools/make_control_examples.py
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from meshcore.airfoil import first_cell_height, naca4_body
from meshcore.boundary import BorderSpec
from meshcore.case import Case, save_case
from meshcore.spec import BlockSpec, SolverSpec
from meshcore.topology import cgrid, radial_nodes

sys.path.insert(0, str(Path(__file__).resolve().parent))
from make_examples import bottle, two_circles

OUT = Path(__file__).resolve().parent.parent / "resources" / "examples"
WALLS = ("bottom", "right", "top", "left")


def r(a):
    return np.round(np.asarray(a, dtype=float), 8)


def main():
    sor = SolverSpec(method="sor", max_iterations=100_000)
    cases = {}
    sp = 0.05
    cases["bottle-orthogonal"] = Case(
        title="Bottle (paper Table 3, refinement 2), orthogonal walls, first cell 0.05",
        description="Hilgenstock-White boundary control on all four walls; borders clustered to the same spacing.",
        solver=sor,
        blocks=(
            BlockSpec(
                name="bottle",
                cells=(12, 30),
                weights=(1.0, 0.5),
                boundary=bottle(),
                borders={n: BorderSpec(distribution="vinokur", first=sp, last=sp) for n in WALLS},
                control={"kind": "hilgenstock-white", "borders": {n: {"spacing": sp} for n in WALLS}},
            ),
        ),
    )
    tc = two_circles()
    cases["two-circles-orthogonal"] = Case(
        title="Two circles joined by a cut (paper Table 2, refinement 2), circles met at 90°",
        description=(
            "The cut is held fixed (clustered to 0.05 at both circles); both circles are walls "
            "with a first cell of 0.05."
        ),
        solver=sor,
        blocks=(
            BlockSpec(
                name="two-circles",
                cells=(40, 8),
                weights=(0.05, 0.0),
                boundary=tc,
                borders={n: BorderSpec(distribution="vinokur", first=0.05, last=0.05) for n in ("left", "right")},
                control={"borders": {"bottom": {"spacing": 0.05}, "top": {"spacing": 0.05}}},
            ),
        ),
    )
    cases["two-circles-ogrid"] = Case(
        title="Two circles as a periodic O-grid (no seam), circles met at 90°",
        description="left = right is the seam, solved like the interior.",
        solver=sor,
        blocks=(
            BlockSpec(
                name="two-circles",
                cells=(40, 8),
                initial="tfi",
                boundary=tc,
                periodic=True,
                control={"borders": {"bottom": {"spacing": 0.05}, "top": {"spacing": 0.05}}},
            ),
        ),
    )
    dy = first_cell_height(30.0, 1e6)
    n, nj, R = 64, 48, 5.0
    body = naca4_body("0012", n)
    th = -np.linspace(0, 2 * np.pi, 2 * n + 1)
    top = np.column_stack([0.5 + R * np.cos(th), R * np.sin(th)])
    top[-1] = top[0]
    cut = radial_nodes(body[0], top[0], nj, first=dy)
    cases["naca0012-ogrid"] = Case(
        title="NACA 0012 O-grid 128×48, far field 5 chords, y+ ≈ 30 at Re 1e6",
        description=f"Nodes given; wall first cell {dy:.3e} chords, orthogonal; Thomas-Middlecoff interior.",
        solver=sor,
        blocks=(
            BlockSpec(
                name="naca0012",
                cells=None,
                initial="tfi",
                periodic=True,
                boundary={"bottom": r(body), "right": r(cut), "top": r(top), "left": r(cut)},
                borders={"bottom": BorderSpec(name="wall"), "top": BorderSpec(name="farfield")},
                control={"thomas-middlecoff": True, "borders": {"bottom": {"spacing": float(f"{dy:.4e}")}}},
            ),
        ),
    )
    C = cgrid(naca4_body("0012", 48), cells_wake=24, cells_normal=40, first=dy)
    g = C.grid
    bd = {
        "bottom": np.column_stack([g.x[:, 0], g.y[:, 0]]),
        "right": np.column_stack([g.x[-1], g.y[-1]]),
        "top": np.column_stack([g.x[:, -1], g.y[:, -1]]),
        "left": np.column_stack([g.x[0], g.y[0]]),
    }
    cases["naca0012-cgrid"] = Case(
        title="NACA 0012 C-grid 144×40 (wake 24 cells per side), y+ ≈ 30 at Re 1e6",
        description=(
            "Nodes given; the bottom border runs along the lower wake cut, around the airfoil and out "
            "along the upper cut; control.wake = 24 solves the cut nodes like interior nodes."
        ),
        solver=sor,
        blocks=(
            BlockSpec(
                name="naca0012",
                cells=None,
                initial="tfi",
                boundary={k: r(v) for k, v in bd.items()},
                borders={
                    "top": BorderSpec(name="farfield"),
                    "left": BorderSpec(name="outflow"),
                    "right": BorderSpec(name="outflow"),
                },
                control={
                    "thomas-middlecoff": True,
                    "wake": C.wake,
                    "borders": {"bottom": {"spacing": float(f"{dy:.4e}"), "start": C.body[0] + 1, "stop": C.body[1]}},
                },
            ),
        ),
    )
    for name, case in cases.items():
        save_case(case, OUT / f"{name}.toml")
        print("wrote", OUT / f"{name}.toml")


if __name__ == "__main__":
    main()
