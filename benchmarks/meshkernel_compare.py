r"""MeshKernel's ``curvilinear_orthogonalize`` and ``meshcore.lakegrid.mesh_layout`` on the same blocks.

For each lake (``--only`` picks some; default :data:`LAKES`) at the cell size
``sqrt(water area / cells)`` of issue 12::

    python benchmarks/meshkernel_compare.py                       # table into benchmarks/MESHKERNEL.md
    python benchmarks/meshkernel_compare.py --only como --repeats 1 --out /tmp/t.md

1. the layout: :func:`meshcore.layout.auto_layout` with ``multiple=4`` (what
   :func:`meshcore.lakegrid.mesh_outline` uses);
2. the **start grid**, the same for both tools: what :func:`~meshcore.lakegrid.mesh_layout`
   starts from — the multiblock Winslow solve on the coarsest level (cells ÷ 4), blocks that
   fold repaired — carried to the fine level by the same bilinear refinement with new shore
   nodes put on the shore (:mod:`meshcore.orthogonal.levels`), not orthogonalised, and the
   few cells that refinement folds repaired (borders fixed) so that MeshKernel starts without
   folds;
3. MeshKernel (``meshkernel`` 8.x, the ``bench`` extra): every block loaded with the C API's
   ``mkernel_curvilinear_set`` (MeshKernelPy 8.3 does not wrap it; called through ctypes) and
   orthogonalised on its own — MeshKernel has no multiblock grids — in the
   :data:`VARIANTS` below: which border nodes it may move (:data:`BOUNDARY`) and which
   parameters (its defaults, and more outer iterations as a user would pick for a lake);
4. ours: :func:`~meshcore.lakegrid.mesh_layout` on the same layout (start grid included in
   its time);
5. every grid measured by :func:`meshcore.quality.lake_metrics` against the water polygon,
   plus the interface gap (largest distance between two copies of a node shared by blocks)
   and the cross-interface area ratios by node numbers (:func:`interface_ratios`), which also
   holds where blocks no longer meet.

Times: median of ``--repeats`` runs, wall clock and CPU time of the process (the CPU time is
what a quiet machine would show; both tools run on one thread: ``NUMBA_NUM_THREADS=1``).
MeshKernel's time is the ``curvilinear_orthogonalize`` calls only, summed over blocks; the
start grid's time is given apart (ours includes it).  Each lake runs in a fresh process.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
SHARED = ROOT.parent / "shared" / "data" / "lakes"
HELD_OUT = ROOT / "benchmarks" / "lakes"

#: The four development lakes and a selection of the held-out ones: Y-shaped and branched
#: (Como, Lucerne, Texoma, Nahuel Huapi), zig-zag (Wakatipu), with islands (Nahuel Huapi,
#: Taal, Iseo, Qiandao).
LAKES = (
    SHARED / "lake_bolsena.csv",
    SHARED / "lake_zurich.csv",
    SHARED / "shasta_lake.csv",
    SHARED / "windermere.csv",
    HELD_OUT / "lake_como.csv",
    HELD_OUT / "lake_lucerne.csv",
    HELD_OUT / "lake_texoma.csv",
    HELD_OUT / "lake_wakatipu.csv",
    HELD_OUT / "nahuel_huapi.csv",
    HELD_OUT / "taal_lake.csv",
    HELD_OUT / "lake_iseo.csv",
    HELD_OUT / "qiandao_lake.csv",
)

#: What MeshKernel may move besides block-interior nodes.  MeshKernel slides a border node
#: along a spline through the border's start nodes (not along the true shore), keeps block
#: corners, and takes no account of the neighbouring block.
BOUNDARY = {
    "fixed": "every border node stays (the orthogonalisation box is the block's interior)",
    "shore": "border sides lying wholly on the shore slide; sides with an interface stay",
    "all": "all four borders slide (MeshKernel's plain call): interfaces come apart",
}


@dataclass(frozen=True, slots=True)
class Variant:
    """One way to run MeshKernel: a label, ``OrthogonalizationParameters`` fields, a boundary mode."""

    label: str
    params: tuple[tuple[str, float], ...]
    boundary: str

    def parameters(self):
        import meshkernel as mkp

        return mkp.OrthogonalizationParameters(**dict(self.params))


#: ``()`` = MeshKernel's defaults (outer 2, boundary 25, inner 25, factor 0.975).
USER = (("outer_iterations", 10),)
VARIANTS = (
    Variant("MK defaults, borders fixed", (), "fixed"),
    Variant("MK defaults, shore slides", (), "shore"),
    Variant("MK outer 10, shore slides", USER, "shore"),
    Variant("MK defaults, all borders slide", (), "all"),
)


# --------------------------------------------------------------------------- MeshKernel I/O
def to_meshkernel(grid):
    """A new ``meshkernel.MeshKernel`` holding ``grid``'s nodes as its curvilinear grid.

    Node ``(i, j)`` of ``grid`` is MeshKernel's ``(m, n) = (i, j)``; MeshKernel stores the
    nodes row by row in ``n`` (``node_x[n * num_m + m]``).
    """
    from ctypes import byref

    import meshkernel as mkp
    from meshkernel.c_structures import CCurvilinearGrid

    x, y = np.asarray(grid.x, dtype=float), np.asarray(grid.y, dtype=float)
    cg = mkp.CurvilinearGrid(np.ascontiguousarray(x.T).ravel(), np.ascontiguousarray(y.T).ravel(), *x.shape)
    mk = mkp.MeshKernel()
    c = CCurvilinearGrid.from_curvilinearGrid(cg)  # points into cg's arrays: keep cg alive
    mk._execute_function(mk.lib.mkernel_curvilinear_set, mk._meshkernelid, byref(c))
    return mk


def from_meshkernel(mk, like):
    """MeshKernel's curvilinear grid as a copy of the :class:`~meshcore.grid.StructuredGrid` ``like``."""
    cg = mk.curvilineargrid_get()
    shape = np.asarray(like.x).shape
    if (cg.num_m, cg.num_n) != shape:
        raise RuntimeError(f"MeshKernel returned {cg.num_m}×{cg.num_n} nodes, expected {shape[0]}×{shape[1]}")
    x = cg.node_x.reshape(cg.num_n, cg.num_m).T.copy()
    y = cg.node_y.reshape(cg.num_n, cg.num_m).T.copy()
    return like.replaced(x=x, y=y)


def box(shape: tuple[int, int], sliding: tuple[bool, bool, bool, bool]) -> tuple[tuple[int, int], tuple[int, int]]:
    """Node indices of the orthogonalisation box: a side (left, right, bottom, top) slides
    when the box reaches it, and stays when the box stops one node short of it."""
    ni, nj = shape[0] - 1, shape[1] - 1
    left, right, bottom, top = sliding
    return (0 if left else 1, 0 if bottom else 1), (ni if right else ni - 1, nj if top else nj - 1)


def orthogonalize_block(grid, params, sliding=(False, False, False, False)):
    """MeshKernel's ``curvilinear_orthogonalize`` of one block; returns ``(grid, wall s, cpu s)``.

    Sides not in ``sliding`` are checked to be unchanged (MeshKernel finds the box's corners as
    the nodes nearest to two points; a wrong pick would move them).
    """
    x, y = np.asarray(grid.x), np.asarray(grid.y)
    (a0, b0), (a1, b1) = box(x.shape, sliding)
    mk = to_meshkernel(grid)
    w, c = time.perf_counter(), time.process_time()
    mk.curvilinear_orthogonalize(params, x[a0, b0], y[a0, b0], x[a1, b1], y[a1, b1])
    w, c = time.perf_counter() - w, time.process_time() - c
    out = from_meshkernel(mk, grid)
    for k, sl in enumerate(((0, slice(None)), (-1, slice(None)), (slice(None), 0), (slice(None), -1))):
        if not sliding[k] and (np.any(out.x[sl] != x[sl]) or np.any(out.y[sl] != y[sl])):
            raise RuntimeError(f"MeshKernel moved side {('left', 'right', 'bottom', 'top')[k]}, which was fixed")
    return out, w, c


def shore_sides(topology) -> list[tuple[bool, bool, bool, bool]]:
    """Per block: which sides (left, right, bottom, top) lie wholly on the shore (no node between
    its ends on an interface), the sides MeshKernel may slide in the ``shore`` mode."""
    m = topology.node_map
    out = []
    for ids in m.ids:
        sides = (ids[0, 1:-1], ids[-1, 1:-1], ids[1:-1, 0], ids[1:-1, -1])
        out.append(tuple(bool(m.boundary[s].all() and not m.shared[s].any()) for s in sides))
    return out


# --------------------------------------------------------------------------- grids
def start_grids(layout) -> list:
    """The start grid of :func:`meshcore.lakegrid.mesh_layout`, carried to the fine level
    without orthogonalising: coarse multiblock Winslow, folds repaired, refined with new shore
    nodes on the shore, folds repaired again.  (Uses two private helpers of
    :mod:`meshcore.lakegrid`, so that the start stays what ``mesh_layout`` does.)"""
    from meshcore.lakegrid import _repair_folds, _shore_rings
    from meshcore.multiblock import solve_multiblock
    from meshcore.orthogonal.levels import coarsen_topology, refine, refine_shore

    topo = layout.topology()
    levels = max(0, int(np.log2(layout.multiple))) if layout.multiple > 1 else 0
    tops = [coarsen_topology(topo, 2**k) if k else topo for k in range(levels, -1, -1)]
    grids, _ = _repair_folds(list(solve_multiblock(tops[0]).grids))
    rings = _shore_rings(layout.polygon, layout.cell_size / 4)
    for tp in tops[1:]:
        grids = refine_shore(refine(grids), tp, rings)
    # refinement can fold a few cells (a new shore node in a tight bend); MeshKernel cannot
    # untangle them, so they are repaired here, borders fixed, as mesh_layout does on its coarse level
    return _repair_folds(grids)[0]


def run_meshkernel(grids, topology, variant: Variant) -> tuple[list, float, float]:
    """Every block orthogonalised by MeshKernel on its own; returns ``(grids, wall s, cpu s)``."""
    params = variant.parameters()
    if variant.boundary == "fixed":
        sliding = [(False,) * 4] * len(grids)
    elif variant.boundary == "shore":
        sliding = shore_sides(topology)
    elif variant.boundary == "all":
        sliding = [(True,) * 4] * len(grids)
    else:
        raise ValueError(f"unknown boundary mode {variant.boundary!r}; known: {', '.join(BOUNDARY)}")
    out, wall, cpu = [], 0.0, 0.0
    for g, s in zip(grids, sliding, strict=True):
        r, w, c = orthogonalize_block(g, params, s)
        out.append(r)
        wall += w
        cpu += c
    return out, wall, cpu


# --------------------------------------------------------------------------- measures
def interface_gap(topology, grids) -> float:
    """Largest distance between two copies of a node that several blocks share (0 when they meet)."""
    ids = np.concatenate([np.ravel(i) for i in topology.node_map.ids])
    x = np.concatenate([np.ravel(g.x) for g in grids])
    y = np.concatenate([np.ravel(g.y) for g in grids])
    n = topology.node_map.n_nodes
    lo_x, hi_x = np.full(n, np.inf), np.full(n, -np.inf)
    lo_y, hi_y = np.full(n, np.inf), np.full(n, -np.inf)
    np.minimum.at(lo_x, ids, x)
    np.maximum.at(hi_x, ids, x)
    np.minimum.at(lo_y, ids, y)
    np.maximum.at(hi_y, ids, y)
    return float(np.hypot(hi_x - lo_x, hi_y - lo_y).max())


def interface_ratios(topology, grids) -> np.ndarray:
    """``max(A₁/A₂, A₂/A₁)`` of every two cells of different blocks whose edge joins the same two
    nodes in the topology's numbering — :mod:`meshcore.quality`'s cross-interface ratio, found
    by node numbers instead of coordinates, so that it holds where blocks no longer meet."""
    from meshcore.quality.interfaces import ratio, signed_area

    keys, blocks, areas = [], [], []
    for k, (ids, g) in enumerate(zip(topology.node_map.ids, grids, strict=True)):
        a = signed_area(np.asarray(g.x), np.asarray(g.y))
        for e0, e1, cell in (
            (ids[:-1, 0], ids[1:, 0], a[:, 0]),
            (ids[:-1, -1], ids[1:, -1], a[:, -1]),
            (ids[0, :-1], ids[0, 1:], a[0, :]),
            (ids[-1, :-1], ids[-1, 1:], a[-1, :]),
        ):
            keys.append(np.minimum(e0, e1).astype(np.int64) * topology.node_map.n_nodes + np.maximum(e0, e1))
            blocks.append(np.full(len(e0), k))
            areas.append(cell)
    key, blk, area = np.concatenate(keys), np.concatenate(blocks), np.concatenate(areas)
    order = np.argsort(key, kind="stable")
    key, blk, area = key[order], blk[order], area[order]
    pair = (key[1:] == key[:-1]) & (blk[1:] != blk[:-1])
    return ratio(area[:-1][pair], area[1:][pair])


def measure(grids, topology, polygon, h: float) -> dict:
    """The numbers of one grid: :func:`~meshcore.quality.lake_metrics` and the interface measures
    (with the counts behind each share, so that lakes can be pooled)."""
    from meshcore.quality import lake_metrics

    lm = lake_metrics(list(grids), polygon=polygon)
    s = lm.summary()
    dev, cos, sm = lm.values("deviation"), lm.values("cos"), lm.values("smoothness")
    itf = interface_ratios(topology, grids)
    out = {k: s.get(k) for k in KEYS}
    out.update(
        n_nodes=len(dev),
        sum_deviation=float(dev.sum()),
        n_within_3deg=int((dev <= 3.0).sum()),
        n_cos_le_002=int((cos <= 0.02).sum()),
        n_pairs=len(sm),
        n_pairs_le_12=int((sm <= 1.2).sum()),
        interface_gap_cells=interface_gap(topology, grids) / h,
        interface_ratio_by_ids=float(itf.max()) if len(itf) else None,
        n_itf_pairs=len(itf),
        n_itf_le_2=int((itf <= 2.0).sum()),
    )
    return out


KEYS = (
    "blocks",
    "cells",
    "mean_deviation_deg",
    "pct_nodes_within_3deg",
    "pct_nodes_cos_le_0.02",
    "pct_smoothness_le_1.2",
    "folded_cells",
    "max_interface_ratio",
    "interface_cell_pairs",
    "area_ratio",
    "hausdorff_cells",
)


# --------------------------------------------------------------------------- one lake
def read_lake(path: str):
    """The water polygon of a lake file, projected as :mod:`benchmarks.lake_grids` does."""
    from meshcore.crs import project
    from meshcore.io import read_points
    from meshcore.layout.polygon import water_from_points, water_polygon

    ps, _ = project(read_points(path), "auto", origin=None)
    outer, islands = water_from_points(ps)
    poly, _ = water_polygon(outer, holes=islands)
    return poly


def _timed(fn, repeats: int, warm: bool = True):
    """``fn()`` run ``repeats`` times (after one untimed run if ``warm``: kernels compiled on
    first use are not timed): its last result, median wall and CPU seconds."""
    walls, cpus, res = [], [], fn() if warm else None
    for _ in range(max(1, repeats)):
        w, c = time.perf_counter(), time.process_time()
        res = fn()
        walls.append(time.perf_counter() - w)
        cpus.append(time.process_time() - c)
    return res, statistics.median(walls), statistics.median(cpus)


def _warm_up() -> None:
    """Load the compiled kernels and MeshKernel's library before anything is timed."""
    from meshcore import testing
    from meshcore.lakegrid import mesh_outline

    mesh_outline(testing.y_junction(), target_cells=500)
    g = start_grids(_tiny_layout())[0]
    orthogonalize_block(g, Variant("warm", (), "fixed").parameters())


def _tiny_layout():
    from meshcore import testing
    from meshcore.layout import auto_layout

    return auto_layout(testing.straight_channel(), target_cells=200, multiple=4)


def _ours(lay, topo, poly, repeats: int) -> dict:
    from meshcore.lakegrid import mesh_layout

    mb, wall, cpu = _timed(lambda: mesh_layout(lay), repeats)
    return dict(measure(mb.grids, topo, poly, lay.cell_size), wall=wall, cpu=cpu)


def _theirs(start, topo, poly, h: float, variant: Variant, repeats: int) -> dict:
    runs = [run_meshkernel(start, topo, variant) for _ in range(max(1, repeats))]
    wall = statistics.median(r[1] for r in runs)
    cpu = statistics.median(r[2] for r in runs)
    return dict(measure(runs[-1][0], topo, poly, h), wall=wall, cpu=cpu)


def _guarded(fn) -> dict:
    """A row, or ``{"error": ...}`` when a tool fails on this lake (the other rows still run)."""
    try:
        return fn()
    except Exception as exc:
        return {"error": f"{type(exc).__name__}: {exc}"[:200]}


def run_lake(path: str, cells: int, repeats: int, variants=VARIANTS) -> dict:
    """Everything measured on one lake (see the module docstring)."""
    from meshcore.layout import auto_layout

    _warm_up()
    load0 = os.getloadavg()[0]
    poly = read_lake(path)
    lay, t_layout, _ = _timed(lambda: auto_layout(poly, target_cells=cells, multiple=4), 1, warm=False)
    topo = lay.topology()
    h = lay.cell_size
    start, sw, sc = _timed(lambda: start_grids(lay), repeats)
    rows = {"start grid (both)": dict(measure(start, topo, poly, h), wall=sw, cpu=sc)}
    rows["meshcore mesh_layout"] = _guarded(lambda: _ours(lay, topo, poly, repeats))
    for v in variants:
        rows[v.label] = _guarded(lambda v=v: _theirs(start, topo, poly, h, v, repeats))
    sides = shore_sides(topo)
    return {
        "lake": Path(path).stem,
        "islands": len(poly.interiors),
        "h": h,
        "layout_s": t_layout,
        "shore_sides": f"{sum(map(sum, sides))}/{4 * len(sides)}",
        "load": (load0, os.getloadavg()[0]),
        "rows": rows,
    }


# --------------------------------------------------------------------------- report
def _f(v, fmt: str) -> str:
    return "–" if v is None or (isinstance(v, float) and not np.isfinite(v)) else format(v, fmt)


def _ratio(r: dict) -> str:
    """lake_metrics' largest ratio where the blocks meet; else the one by node numbers, marked *."""
    if r["interface_gap_cells"] <= 1e-9 and r["interface_cell_pairs"]:
        return _f(r["max_interface_ratio"], ".3g")
    return _f(r["interface_ratio_by_ids"], ".3g") + "*"


def _pct(k: int, n: int) -> str:
    return f"{100 * k / n:.1f}" if n else "–"


HEAD = (
    "| lake | grid | mean dev. ° | nodes ≤ 3° % | \\|cos\\| ≤ 0.02 % | pairs ≤ 1.2 % | folded "
    "| interface pairs ≤ 2 % | max interface ratio | interface gap (cells) | area ratio | shore dist. (cells) "
    "| wall s | CPU s |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
)


def _row(lake: str, label: str, r: dict) -> str:
    if "error" in r:
        return f"| {lake} | {label} | error: {r['error']} |" + " |" * 11
    return (
        f"| {lake} | {label} | {_f(r['mean_deviation_deg'], '.2f')} | {_f(r['pct_nodes_within_3deg'], '.1f')} "
        f"| {_f(r['pct_nodes_cos_le_0.02'], '.1f')} | {_f(r['pct_smoothness_le_1.2'], '.1f')} | {r['folded_cells']} "
        f"| {_pct(r['n_itf_le_2'], r['n_itf_pairs'])} | {_ratio(r)} | {_f(r['interface_gap_cells'], '.2g')} "
        f"| {_f(r['area_ratio'], '.4f')} | {_f(r['hausdorff_cells'], '.2f')} | {_f(r['wall'], '.2f')} "
        f"| {_f(r['cpu'], '.2f')} |"
    )


def _pooled(rs: list[dict]) -> dict:
    """One grid kind over several lakes: shares and means over all their nodes / edge pairs."""
    n, p = sum(r["n_nodes"] for r in rs), sum(r["n_pairs"] for r in rs)
    ratios = [float(v.rstrip("*")) for v in map(_ratio, rs) if v.rstrip("*") != "–"]
    return {
        "cells": sum(r["cells"] for r in rs),
        "mean": sum(r["sum_deviation"] for r in rs) / n,
        "3deg": 100 * sum(r["n_within_3deg"] for r in rs) / n,
        "cos": 100 * sum(r["n_cos_le_002"] for r in rs) / n,
        "pairs": 100 * sum(r["n_pairs_le_12"] for r in rs) / p,
        "folded": sum(r["folded_cells"] for r in rs),
        "itf": _pct(sum(r["n_itf_le_2"] for r in rs), sum(r["n_itf_pairs"] for r in rs)),
        "ratio": max(ratios, default=float("nan")),
        "gap": max(r["interface_gap_cells"] for r in rs),
        "wall": sum(r["wall"] for r in rs),
        "cpu": sum(r["cpu"] for r in rs),
    }


TOTAL_HEAD = (
    "| grid | lakes | cells | mean dev. ° | nodes ≤ 3° % | \\|cos\\| ≤ 0.02 % | pairs ≤ 1.2 % | folded "
    "| interface pairs ≤ 2 % | worst interface ratio | worst interface gap (cells) | wall s | CPU s "
    "| wall s with start | CPU s with start |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
)


def _totals(results: list[dict]) -> str:
    ok = [r for r in results if "rows" in r]
    # pooled over the lakes where every grid kind has a row, so that the kinds compare
    both = [r for r in ok if not any("error" in x for x in r["rows"].values())]
    if not both:
        return ""
    start = _pooled([r["rows"]["start grid (both)"] for r in both])
    lines = [TOTAL_HEAD]
    for label in both[0]["rows"]:
        t = _pooled([r["rows"][label] for r in both])
        mk = label.startswith("MK")
        n = f"{len(both)} ({len(ok) - len(both)} left out)" if len(both) < len(ok) else str(len(ok))
        lines.append(
            f"| {label} | {n} | {t['cells']} | {t['mean']:.2f} | {t['3deg']:.1f} | {t['cos']:.1f} "
            f"| {t['pairs']:.1f} | {t['folded']} | {t['itf']} | {_f(t['ratio'], '.3g')} | {t['gap']:.2g} "
            f"| {t['wall']:.1f} "
            f"| {t['cpu']:.1f} | {_f(t['wall'] + start['wall'] if mk else None, '.1f')} "
            f"| {_f(t['cpu'] + start['cpu'] if mk else None, '.1f')} |"
        )
    return "\n".join(lines)


def report(results: list[dict], cells: int, repeats: int, seconds: float, uptime: str) -> str:
    """The Markdown results section: per lake, then pooled over the lakes."""
    import meshkernel

    rows = []
    for res in results:
        if "rows" not in res:
            rows.append(f"| {res['lake']} | error: {res['error']} |" + " |" * 12)
            continue
        name = res["lake"] + (f" ({res['islands']} isl.)" if res["islands"] else "")
        for label, r in res["rows"].items():
            rows.append(_row(name, label, r))
    loads = ", ".join(f"{r['lake']} {r['load'][0]:.1f}→{r['load'][1]:.1f}" for r in results if "load" in r)
    params = "; ".join(f"{v.label}: {dict(v.params) or 'defaults'}, {v.boundary}" for v in VARIANTS)
    return (
        f"`python benchmarks/meshkernel_compare.py --cells {cells} --repeats {repeats}` — meshkernel "
        f"{meshkernel.__version__}, cell size `sqrt(water area / {cells})`, layouts by `auto_layout(..., "
        f"multiple=4)`; {len(results)} lakes in {seconds:.0f} s. Times are medians of {repeats} runs, one "
        f"thread each. Machine: 2 cores shared with other work; `uptime` at the start: {uptime}; 1-minute "
        f"load per lake (start→end): {loads}.\n\nVariants: {params}.\n\n"
        f"### Per lake\n\n{HEAD}\n" + "\n".join(rows) + "\n\n"
        "\\* blocks no longer meet: the ratio is taken between the cells that share an edge in the "
        "layout's numbering (`interface_ratios`); `lake_metrics` finds no shared edge.\n\n"
        f"### All lakes pooled\n\nShares and means over all block-interior nodes (edge pairs) of all "
        f"lakes; times summed over lakes. MeshKernel's times are its `curvilinear_orthogonalize` calls; "
        f"'with start' adds the start grid's time (ours includes it).\n\n{_totals(results)}\n"
    )


MARK_START, MARK_END = "<!-- results:start -->", "<!-- results:end -->"


def write_results(path: Path, text: str) -> None:
    """Put ``text`` between the results markers of ``path`` (the prose around them stays)."""
    old = path.read_text(encoding="utf-8") if path.exists() else "# MeshKernel comparison\n"
    if MARK_START not in old or MARK_END not in old:
        old += f"\n{MARK_START}\n{MARK_END}\n"
    head, rest = old.split(MARK_START, 1)
    tail = rest.split(MARK_END, 1)[1]
    path.write_text(f"{head}{MARK_START}\n{text}{MARK_END}{tail}", encoding="utf-8")


def _child(path: str, cells: int, repeats: int, timeout: float) -> dict:
    env = dict(os.environ, PYTHONPATH=str(ROOT), NUMBA_NUM_THREADS="1", OMP_NUM_THREADS="1")
    cmd = [sys.executable, __file__, "--child", path, "--cells", str(cells), "--repeats", str(repeats)]
    try:
        r = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, env=env, cwd=ROOT)
    except subprocess.TimeoutExpired:
        return {"lake": Path(path).stem, "error": f"timed out after {timeout:.0f} s"}
    for line in r.stdout.splitlines():
        if line.startswith("RESULT "):
            return json.loads(line[7:])
    err = (r.stderr.strip().splitlines() or ["no output"])[-1]
    return {"lake": Path(path).stem, "error": err[:200]}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", help="comma-separated name fragments of LAKES")
    ap.add_argument("--cells", type=int, default=15000)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--timeout", type=float, default=1800.0)
    ap.add_argument("--out", default=str(ROOT / "benchmarks" / "MESHKERNEL.md"))
    ap.add_argument("--json", help="also write the raw numbers here")
    ap.add_argument("--child", help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.child:
        print("RESULT " + json.dumps(run_lake(a.child, a.cells, a.repeats)), flush=True)
        return 0
    lakes = [str(p) for p in LAKES if not a.only or any(o in p.stem for o in a.only.split(","))]
    uptime = subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()
    t0, results = time.perf_counter(), []
    for p in lakes:
        res = _child(p, a.cells, a.repeats, a.timeout)
        results.append(res)
        print(json.dumps({k: v for k, v in res.items() if k != "rows"}), file=sys.stderr, flush=True)
        for label, r in res.get("rows", {}).items():
            print(_row(res["lake"], label, r), file=sys.stderr, flush=True)
    if a.json:
        Path(a.json).write_text(json.dumps(results, indent=1), encoding="utf-8")
    write_results(Path(a.out), report(results, a.cells, a.repeats, time.perf_counter() - t0, uptime))
    print(f"wrote {a.out}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
