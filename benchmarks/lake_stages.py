"""Where :func:`meshcore.mesh_outline` spends its CPU time, stage by stage (issue 12: one lake in ≤ 20 s).

::

    python benchmarks/lake_stages.py path/to/lake.geojson "testing.channel_network(5, n_branches=50)"
    python benchmarks/lake_stages.py --cells 15000 "testing.lake_with_islands(5, n_islands=24)"

Each case runs in a fresh process (after one warm-up run that loads the compiled kernels), at the
cell size ``sqrt(area / cells)``; a lake file is projected as ``meshcore mesh`` does it.  The
stages are timed with ``time.process_time`` (CPU of the process: on a shared machine wall time
says more about the neighbours than about the code) by wrapping the functions of the pipeline:
the layout's pieces (skeleton, chords, regions, splits, corners; the skeleton and the splits also
on their own rows: a row includes the rows of the stages it calls), its cell-count program, the
check of its case, the start grid, the orthogonal levels, the refinement onto the shore, the shore
fits before each level, the equalize step after the last.  Prints a
Markdown table, one column per case; ``--json OUT`` also writes the numbers.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

#: (label, module, function): the stages, in the order of the pipeline.  A generator's time is
#: summed over its steps.
STAGES = (
    ("layout: skeleton", "meshcore.layout.build", "skeleton"),
    ("layout: chords", "meshcore.layout.build", "place_chords"),
    ("layout: regions (island cuts)", "meshcore.layout.build", "partition"),
    ("layout: splits (best_split)", "meshcore.layout.build", "best_split"),
    ("layout: fans split (unfan)", "meshcore.layout.build", "unfan"),
    ("layout: pieces (skeleton, chords, regions, splits, corners)", "meshcore.layout", "layout_pieces"),
    ("layout: cell counts (MILP)", "meshcore.layout", "block_counts"),  # regular layouts
    ("layout: cell counts (MILP)", "meshcore.layout.tipsplit", "block_counts"),  # the others
    ("layout: case check (topology)", "meshcore.layout", "_check_case"),
    ("layout: coarse readings (choice of scale)", "meshcore.lakegrid", "coarse_reading"),
    ("layout, all", "meshcore.layout", "auto_layout"),
    ("coarse topologies", "meshcore.orthogonal.levels", "coarsen_topology"),
    ("start grid", "meshcore.lakegrid", "_start"),
    ("fold repair", "meshcore.lakegrid", "_repair_folds"),
    ("refinement onto the shore", "meshcore.orthogonal.levels", "refine_shore"),
    ("shore fits (fit_ends, fit_bends)", "meshcore.orthogonal.levels", "fit_ends"),
    ("shore fits (fit_ends, fit_bends)", "meshcore.orthogonal.levels", "fit_bends"),
    ("orthogonal levels", "meshcore.orthogonal", "iterate_orthogonalize"),
    ("equalize (interface ratios)", "meshcore.orthogonal.equalize", "equalize_interfaces"),
)

_CHILD = r"""
import functools, importlib, inspect, json, sys, time
from meshcore import testing
from meshcore.cli.lakefile import local_frame
from meshcore.io import read_points
from meshcore.lakegrid import mesh_outline
from meshcore.layout.polygon import water_from_points, water_polygon

what, cells, stages = sys.argv[1], int(sys.argv[2]), json.loads(sys.argv[3])
spent, depth = {label: 0.0 for label, _, _ in stages}, {}  # a stage the case never reaches: 0

def timed(label, f):
    if inspect.isgeneratorfunction(f):
        def gen(*a, **k):
            g, val = f(*a, **k), None
            while True:
                c = time.process_time()
                try:
                    out = g.send(val)
                except StopIteration as stop:
                    spent[label] = spent.get(label, 0.0) + time.process_time() - c
                    return stop.value
                spent[label] = spent.get(label, 0.0) + time.process_time() - c
                val = yield out
        return gen

    @functools.wraps(f)
    def call(*a, **k):
        c = time.process_time()
        depth[label] = depth.get(label, 0) + 1
        try:
            return f(*a, **k)
        finally:
            depth[label] -= 1
            if not depth[label]:  # a recursive call counts once
                spent[label] = spent.get(label, 0.0) + time.process_time() - c
    return call

for label, mod, name in stages:
    m = importlib.import_module(mod)
    setattr(m, name, timed(label, getattr(m, name)))
if what.startswith("testing."):
    poly = eval(what)
else:
    ps, _ = local_frame(read_points(what), "auto")
    outer, islands = water_from_points(ps)
    poly, _ = water_polygon(outer, holes=islands)
c = time.process_time()
mb = mesh_outline(poly, target_cells=cells)
spent["mesh_outline, all"] = time.process_time() - c
cells_out = sum((g.x.shape[0] - 1) * (g.x.shape[1] - 1) for g in mb.grids)
print("RESULT " + json.dumps(dict(blocks=len(mb.grids), cells=cells_out, cpu=spent)))
"""


def run_case(what: str, cells: int) -> dict:
    """The stage times of one case, from a fresh process."""
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    stages = json.dumps([list(s) for s in STAGES])
    r = subprocess.run(
        [sys.executable, "-c", _CHILD, what, str(cells), stages], capture_output=True, text=True, env=env, cwd=ROOT
    )
    for line in r.stdout.splitlines():
        if line.startswith("RESULT "):
            return json.loads(line[7:])
    return {"error": (r.stderr.strip().splitlines() or ["no output"])[-1][:200]}


def table(names: list[str], results: list[dict]) -> str:
    """Markdown: one row per stage, one column per case (CPU seconds)."""
    labels = list(dict.fromkeys(s[0] for s in STAGES)) + ["mesh_outline, all"]
    head = "| stage (CPU s) | " + " | ".join(names) + " |\n|---|" + "---|" * len(names)
    sizes = [f"{r.get('blocks', '–')} / {r.get('cells', '–')}" for r in results]
    rows = ["| blocks / cells | " + " | ".join(sizes) + " |"]
    for lab in labels:
        vals = [f"{r['cpu'].get(lab, 0.0):.2f}" if "cpu" in r else r.get("error", "–") for r in results]
        rows.append(f"| {lab} | " + " | ".join(vals) + " |")
    return head + "\n" + "\n".join(rows)


def main(argv: list[str] | None = None) -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("cases", nargs="+", help="lake files or testing.* expressions")
    p.add_argument("--cells", type=int, default=15000)
    p.add_argument("--json", help="also write the numbers here")
    a = p.parse_args(argv)
    run_case("testing.y_junction()", 2000)  # warm-up: the compiled kernels loaded once
    results = [run_case(c, a.cells) for c in a.cases]
    names = [Path(c).stem if not c.startswith("testing.") else c.removeprefix("testing.") for c in a.cases]
    print(table(names, results))
    if a.json:
        Path(a.json).write_text(json.dumps(dict(zip(a.cases, results, strict=True)), indent=1))


if __name__ == "__main__":
    main()
