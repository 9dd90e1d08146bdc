"""The figures of docs/lake-grids.md: shipped lakes meshed by ``meshcore mesh``, cells coloured by
their largest deviation from 90°.

    python tools/make_lake_figures.py                   # all of them, into docs/figures/
    python tools/make_lake_figures.py --only como --cells 6000

Each lake is one ``meshcore mesh LAKE --cells N --png docs/figures/lake-NAME.png --colour
deviation`` run; the progress lines go to the terminal.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SHARED = ROOT.parent / "shared" / "data" / "lakes"
LAKES = {
    "como": ROOT / "benchmarks" / "lakes" / "lake_como.geojson",  # Y-shaped
    "shasta": SHARED / "shasta_lake.csv",  # dendritic reservoir
    "iseo": ROOT / "benchmarks" / "lakes" / "lake_iseo.geojson",  # an island
    "lucerne": ROOT / "benchmarks" / "lakes" / "lake_lucerne.geojson",  # many arms and bends
    "mono": ROOT / "benchmarks" / "lakes" / "mono_lake.geojson",  # two islands in a round lake
    "windermere": SHARED / "windermere.csv",  # a long loch
}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", help="comma-separated names of " + ", ".join(LAKES))
    ap.add_argument("--cells", type=int, default=15000, help="cells per lake (those of benchmarks/lake_grids.py)")
    ap.add_argument("--out", default=str(ROOT / "docs" / "figures"))
    a = ap.parse_args(argv)
    names = a.only.split(",") if a.only else list(LAKES)
    for name in names:
        src = LAKES[name]
        png = Path(a.out) / f"lake-{name}.png"
        cmd = [sys.executable, "-m", "meshcore", "mesh", str(src), "--cells", str(a.cells)]
        cmd += ["-o", str(png.with_suffix(".npz")), "--png", str(png), "--colour", "deviation", "-q"]
        rc = subprocess.run(cmd, cwd=ROOT).returncode
        png.with_suffix(".npz").unlink(missing_ok=True)
        print(f"{png}: exit {rc}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
