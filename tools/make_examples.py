"""Regenerate resources/examples/*.toml: the paper's monoblock cases and an exact annulus.

The paper published its input points only as figures; these point sets are
designed to match its descriptions and input counts (Tables 1–3):

* rectangle with a cutout: 10 points on bottom/top, 4 on left/right;
  refinements 15×6 and 30×12; weights p24 = (0.9, 1.0) → p13 = (0.1, 0.0).
* doubly connected region (two circles joined by a cut): 20 points on each
  circle, 4 on the cut; refinements 30×6 and 40×8; p13 = (0.05, 0.0).
* bottle: 4 points on bottom/top, 10 on each side; refinements 6×15 and 12×30;
  p13 = (1.0, 0.5).

Run: python tools/make_examples.py
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from meshcore.boundary import BorderSpec
from meshcore.case import Case, save_case
from meshcore.spec import BlockSpec

OUT = Path(__file__).resolve().parent.parent / "resources" / "examples"


def r(a):
    return np.round(np.asarray(a, dtype=float), 6)


def rectangle_cutout():
    bottom = np.column_stack([np.linspace(0, 10, 10), np.zeros(10)])
    top = np.array(
        [[0, 4], [1.75, 4], [3.5, 4], [3.5, 3.25], [3.5, 2.5], [6.5, 2.5], [6.5, 3.25], [6.5, 4], [8.25, 4], [10, 4]],
        float,
    )
    left = np.column_stack([np.zeros(4), np.linspace(0, 4, 4)])
    right = np.column_stack([np.full(4, 10.0), np.linspace(0, 4, 4)])
    return {"bottom": r(bottom), "right": r(right), "top": r(top), "left": r(left)}


def two_circles():
    # bottom = outer circle (R = 2) counter-clockwise, top = inner circle (r = 1)
    # counter-clockwise; left = right = the cut from the outer to the inner circle.
    t = np.linspace(0.0, 2 * math.pi, 20)
    outer = np.column_stack([2 * np.cos(t), 2 * np.sin(t)])
    inner = np.column_stack([np.cos(t), np.sin(t)])
    outer[-1] = outer[0]
    inner[-1] = inner[0]
    cut = np.column_stack([np.linspace(2, 1, 4), np.zeros(4)])
    return {"bottom": r(outer), "right": r(cut), "top": r(inner), "left": r(cut)}


def bottle():
    right = np.array(
        [
            [3.0, 0.0],
            [3.2, 1.0],
            [3.2, 2.2],
            [3.1, 3.4],
            [2.8, 4.4],
            [2.1, 5.2],
            [1.4, 5.9],
            [1.0, 6.6],
            [1.0, 7.4],
            [1.1, 8.0],
        ]
    )
    left = right * [-1, 1]
    bottom = np.column_stack([np.linspace(-3, 3, 4), np.zeros(4)])
    top = np.column_stack([np.linspace(-1.1, 1.1, 4), np.full(4, 8.0)])
    return {"bottom": r(bottom), "right": r(right), "top": r(top), "left": r(left)}


def annulus(ni=24, nj=16, r0=1.0, r1=4.0, th1=math.pi / 2):
    rr = r0 * (r1 / r0) ** np.linspace(0, 1, ni + 1)
    th = np.linspace(0, th1, nj + 1)
    bottom = np.column_stack([rr, np.zeros_like(rr)])
    top = np.column_stack([rr * math.cos(th1), rr * math.sin(th1)])
    left = np.column_stack([r0 * np.cos(th), r0 * np.sin(th)])
    right = np.column_stack([r1 * np.cos(th), r1 * np.sin(th)])
    return {"bottom": bottom, "right": right, "top": top, "left": left}


def main():
    OUT.mkdir(parents=True, exist_ok=True)
    cases = {
        "rectangle-cutout-coarse": (
            "Rectangle with a cutout (paper Table 1, refinement 1)",
            rectangle_cutout(),
            (15, 6),
            (0.1, 0.0),
        ),
        "rectangle-cutout-fine": (
            "Rectangle with a cutout (paper Table 1, refinement 2)",
            rectangle_cutout(),
            (30, 12),
            (0.1, 0.0),
        ),
        "two-circles-coarse": (
            "Doubly connected region, two circles joined by a cut (paper Table 2, refinement 1)",
            two_circles(),
            (30, 6),
            (0.05, 0.0),
        ),
        "two-circles-fine": (
            "Doubly connected region, two circles joined by a cut (paper Table 2, refinement 2)",
            two_circles(),
            (40, 8),
            (0.05, 0.0),
        ),
        "bottle-coarse": ("Bottle (paper Table 3, refinement 1)", bottle(), (6, 15), (1.0, 0.5)),
        "bottle-fine": ("Bottle (paper Table 3, refinement 2)", bottle(), (12, 30), (1.0, 0.5)),
    }
    for name, (title, b, cells, w) in cases.items():
        # The cutout's corners are kept as nodes (snap_angle); the paper's
        # uniform re-sampling would cut them off.
        block = BlockSpec(
            name=name.rsplit("-", 1)[0],
            cells=cells,
            weights=w,
            boundary=b,
            borders={},
            snap_angle=30.0 if "cutout" in name else None,
        )
        save_case(
            Case(
                blocks=(block,),
                title=title,
                description="Input points designed to match the paper's description and counts.",
            ),
            OUT / f"{name}.toml",
        )
    b = annulus()
    block = BlockSpec(
        name="annulus-sector",
        cells=None,
        weights=(0.5, 0.5),
        initial="tfi",
        boundary=b,
        borders={"right": BorderSpec(name="outer"), "left": BorderSpec(name="inner")},
    )
    save_case(
        Case(
            blocks=(block,),
            title="Annulus sector with an exact answer",
            description=(
                "Radii geometric (ln r uniform), angles uniform: θ and ln r are harmonic, "
                "so the Winslow grid is x = r cos θ, y = r sin θ exactly; the discrete "
                "error falls at second order."
            ),
        ),
        OUT / "annulus-sector.toml",
    )


if __name__ == "__main__":
    main()
