"""Straight (180°) block corners of regular, single and ``wedges`` layouts: a census.

A block corner on a straight stretch of shore gives a corner cell with a 180° angle (a triangle;
:data:`meshcore.quality.cells.STRAIGHT_SINE`).  The default layouts no longer make them
(``layout.build._flat_corner_on_cut``, ``orthogonal.levels.fit_ends``); this counts them where
they were left: regular layouts (``--regular``, ``.ddb``), single index spaces (``--single``) and
the ``wedges`` layout option.  Each shape runs in a fresh process::

    python benchmarks/straight_corners.py OUT.json --cells 10000 --modes regular,single
    python benchmarks/straight_corners.py OUT.json --layout-only      # the layouts alone (fast)
    python benchmarks/straight_corners.py OUT.json --compare BASE.json  # print, against a base run

Per run: ``layout`` — a hash of the blocks' corners and cell counts (equal hashes: the same
grid), ``flat`` — block corners with both ring neighbours on the shore whose vertex turns by less
than 1° (the layout's own count), ``blocks``, and with the grid (not ``--layout-only``)
``straight_angle_cells``, ``folded_cells``, ``pct_nodes_within_3deg``; ``error`` when refused.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import lake_grids  # (benchmarks/, not a package)

ROOT = Path(__file__).resolve().parent.parent
LAKES = ROOT / "benchmarks" / "lakes"

#: Generated shapes with islands (every one of them has at least one), and arms ending in wedges.
GENERATED = [
    *(f"testing.lake_with_islands({s})" for s in range(10)),
    *(f"testing.round_lake({s})" for s in range(6)),
    *(f"testing.archipelago({s})" for s in range(2)),
    *(f"testing.channel_network({s})" for s in (0, 5, 7, 13)),
    *(f"testing.headlands({s})" for s in range(2)),
]
WEDGED = [f"testing.narrow_arms({s})" for s in range(4)]

_CHILD = r"""
import json, sys
import numpy as np
import shapely
from meshcore import testing
from meshcore.cli.lakefile import local_frame
from meshcore.io import read_points
from meshcore.lakegrid import coarse_reading, mesh_layout
from meshcore.layout import LayoutOptions, auto_layout
from meshcore.layout.corners import _raw_turning
from meshcore.layout.polygon import water_from_points, water_polygon
from meshcore.quality import lake_metrics
from meshcore.cellsize import default_cell_size
what, cells, mode, grid = sys.argv[1], int(sys.argv[2]), sys.argv[3], sys.argv[4] == "1"


def lake(path):  # in the frame `meshcore mesh` lays out in
    outer, islands = water_from_points(local_frame(read_points(path), "auto")[0])
    return water_polygon(outer, holes=islands)[0]


poly = eval(what) if what.startswith("testing.") else lake(what)
out = {}
try:
    lay = auto_layout(poly, target_cells=cells, multiple=4, regular=mode == "regular", single=mode == "single",
                      options=LayoutOptions(wedges=mode == "wedges"), reading=coarse_reading)
except Exception as exc:
    print("RESULT " + json.dumps({"error": f"{type(exc).__name__}: {exc}"[:300]}))
    sys.exit(0)
rim = shapely.boundary(lay.polygon)
size = float(np.hypot(*np.subtract(*np.reshape(lay.polygon.bounds, (2, 2))[::-1])))
flat, where = 0, []
for pc in lay.pieces:
    r = pc.ring
    on = shapely.distance(shapely.points(r), rim) < 1e-9 * size
    raw = _raw_turning(r)
    n = len(r)
    for i in pc.corners:
        if on[i] and on[i - 1] and on[(i + 1) % n] and abs(raw[i]) < 1.0:
            flat += 1
            where.append([round(float(r[i][0]), 4), round(float(r[i][1]), 4)])
import hashlib
key = repr([(b.corners, b.cells) for b in lay.blocks]).encode()
out.update(blocks=len(lay.pieces), flat=flat, flat_at=where[:6], layout=hashlib.sha1(key).hexdigest()[:12])
if grid:
    mb = mesh_layout(lay, levels=2)
    s = lake_metrics(mb, polygon=poly, cell_size=default_cell_size(poly.area, cells)).summary()
    out.update({k: s[k] for k in ("cells", "straight_angle_cells", "folded_cells", "pct_nodes_within_3deg",
                                  "max_interface_ratio", "hausdorff_cells")})
print("RESULT " + json.dumps(out))
"""


def run(what: str, cells: int, mode: str, grid: bool, timeout: float = 900.0) -> dict:
    """One shape's layout (and grid) in a fresh process: the census numbers, or ``error``."""
    return lake_grids._run(what, cells, timeout, child=_CHILD, args=(mode, "1" if grid else "0"))


def shapes(which: str) -> list[str]:
    """The shapes of a set: ``lakes`` (the 24 shipped), ``generated``, ``wedged`` or ``all``."""
    lakes = [str(p) for p in sorted(LAKES.glob("*.geojson")) if not p.stem.endswith("_sparse")]
    sets = {"lakes": lakes, "generated": GENERATED, "wedged": WEDGED}
    return [s for k, v in sets.items() if which in (k, "all") for s in v]


def _name(what: str) -> str:
    return Path(what).stem if not what.startswith("testing.") else what.removeprefix("testing.")


def _said(r: dict) -> str:
    return (
        r["error"][:90]
        if "error" in r
        else json.dumps({k: v for k, v in r.items() if k not in ("flat_at", "layout")})
        + ("" if "layout" not in r else f" layout {r['layout']}")
    )


def compare(res: dict, base: dict) -> None:
    """Print every run and, against ``base``, what changed; then the totals."""
    keys = ("flat", "straight_angle_cells", "folded_cells")
    tot = {k: [0, 0] for k in keys}
    for key, r in res.items():
        b = base.get(key, {})
        for k in keys:
            tot[k][0] += b.get(k, 0) or 0
            tot[k][1] += r.get(k, 0) or 0
        line = f"{key}: {_said(r)}"
        if b and _said(b) != _said(r):
            line += f"\n    base: {_said(b)}"
        print(line)
    for k, (a, b) in tot.items():
        print(f"total {k}: {a} -> {b}")
    both = [k for k in res if k in base]
    was, now = sum("error" in base[k] for k in both), sum("error" in res[k] for k in both)
    print(f"refused ({len(both)} runs in both): {was} -> {now}")
    for k in both:
        if ("error" in base[k]) != ("error" in res[k]):
            print("  refused in", "the base only:" if "error" in base[k] else "this run only:", k)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out")
    ap.add_argument("--cells", default="10000", help="comma-separated target cell counts")
    ap.add_argument("--modes", default="regular,single,wedges")
    ap.add_argument("--set", default="all", help="lakes, generated, wedged or all")
    ap.add_argument("--layout-only", action="store_true")
    ap.add_argument("--compare", help="a base run's JSON: print the differences and stop")
    a = ap.parse_args(argv)
    if a.compare:
        compare(json.loads(Path(a.out).read_text()), json.loads(Path(a.compare).read_text()))
        return 0
    res: dict = json.loads(Path(a.out).read_text()) if Path(a.out).exists() else {}
    for cells in (int(c) for c in a.cells.split(",")):
        for mode in a.modes.split(","):
            for what in shapes(a.set):
                if mode == "wedges" and what in GENERATED:
                    continue  # no wedges at islands: the lakes and the wedged arms
                if mode != "wedges" and what in WEDGED:
                    continue
                key = f"{_name(what)} {mode} {cells}"
                if key in res:
                    continue
                res[key] = run(what, cells, mode, not a.layout_only)
                print(key, res[key], flush=True)
                Path(a.out).write_text(json.dumps(res, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
