"""Where the cross-interface area ratio is worst, and what the layout does there.

For one case of ``lake_grids.py`` (a name fragment) prints the worst cell pairs across block
interfaces (blocks, cells, areas in h², edge lengths) and, for every shore node where blocks
meet nearest to them, which block has a corner there (with its angle) and which passes with a side::

    python benchmarks/interface_worst.py "islands 2" --cells 15000 --png /tmp/worst.png
    python benchmarks/interface_worst.py "testing.channel_network(23, n_branches=7)" --png /tmp/w.png
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))


def _polygon(what: str):
    from meshcore import testing  # noqa: F401  (used by eval)
    from meshcore.cli.lakefile import local_frame
    from meshcore.io import read_points
    from meshcore.layout.polygon import water_from_points, water_polygon

    if what.startswith("testing."):
        return eval(what)
    ps, _ = local_frame(read_points(what), "auto")
    outer, islands = water_from_points(ps)
    return water_polygon(outer, holes=islands)[0]


def _junctions(mb, h: float) -> dict:
    """Points where several blocks' borders meet: ``{point key: [(block, kind, angle)]}``."""
    out: dict = {}
    for name, g in zip(mb.names, mb.grids, strict=True):
        P = np.stack([np.asarray(g.x), np.asarray(g.y)], -1)
        ni, nj = g.cells
        for i, j, di, dj in ((0, 0, 1, 1), (ni, 0, -1, 1), (ni, nj, -1, -1), (0, nj, 1, -1)):
            u, v = P[i + di, j] - P[i, j], P[i, j + dj] - P[i, j]
            ang = abs(np.degrees(np.arctan2(u[0] * v[1] - u[1] * v[0], u @ v)))
            out.setdefault(tuple(np.round(P[i, j] / h * 1e2).astype(int)), []).append((name, "corner", ang))
        for side in (P[1:-1, 0], P[1:-1, -1], P[0, 1:-1], P[-1, 1:-1]):
            for o in side:
                out.setdefault(tuple(np.round(o / h * 1e2).astype(int)), []).append((name, "side", None))
    return {k: v for k, v in out.items() if len({b for b, _, _ in v}) > 1}


def main(argv: list[str] | None = None) -> int:
    import lake_grids

    from meshcore.lakegrid import mesh_outline
    from meshcore.quality.interfaces import interface_pairs, signed_area

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("case", help='a name fragment of a lake_grids.py case, an outline file, or "testing.…(…)"')
    ap.add_argument("--cells", type=int, default=15000)
    ap.add_argument("--worst", type=int, default=8)
    ap.add_argument("--png", help="a figure of the worst place")
    a = ap.parse_args(argv)
    if a.case.startswith("testing.") or Path(a.case).is_file():  # an expression or any outline file
        cases = [(a.case, a.case)]
    else:
        cases = lake_grids._cases([a.case])
    if not cases:
        raise SystemExit(f"no case matches {a.case!r}")
    name, what = cases[0]
    poly = _polygon(what)
    mb = mesh_outline(poly, target_cells=a.cells)
    h = float(np.sqrt(poly.area / sum(g.cells[0] * g.cells[1] for g in mb.grids)))
    pr = interface_pairs(mb.grids)
    area = [np.abs(signed_area(np.asarray(g.x), np.asarray(g.y))) / h**2 for g in mb.grids]
    import shapely

    shore = poly.boundary
    joints = {
        k: v for k, v in _junctions(mb, h).items() if shore.distance(shapely.Point(np.array(k) * h / 1e2)) < 0.01 * h
    }
    keys = np.array(list(joints)) * h / 1e2 if joints else np.zeros((0, 2))
    print(f"{name}: {len(mb.grids)} blocks, {len(pr['ratio'])} pairs, {(pr['ratio'] > 2).sum()} above 2")
    shown: list[np.ndarray] = []
    for q in np.argsort(-pr["ratio"]):
        m = pr["mid"][q]
        if len(shown) >= a.worst or any(np.hypot(*(m - s)) < 3 * h for s in shown):
            continue
        shown.append(m)
        (ba, ia, ja), (bb, ib, jb) = pr["cell_a"][q], pr["cell_b"][q]
        line = (
            f"  {pr['ratio'][q]:6.2f}  {mb.names[ba]}({ia},{ja}) {area[ba][ia, ja]:.2f}h²"
            f"  {mb.names[bb]}({ib},{jb}) {area[bb][ib, jb]:.2f}h²  at ({m[0]:.6g}, {m[1]:.6g})"
        )
        if len(keys):
            d = np.hypot(*(keys - m).T)
            k = int(np.argmin(d))
            parts = ", ".join(
                f"{b} {kind}" + (f" {t:.0f}°" if t is not None else "") for b, kind, t in joints[list(joints)[k]]
            )
            line += f"; {d[k] / h:.1f} h from [{parts}]"
        print(line)
    if a.png and shown:
        _figure(mb, poly, pr, shown[0], h, a.png)
    return 0


def _figure(mb, poly, pr, m, h: float, out: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from meshcore.quality.interfaces import signed_area

    fig, ax = plt.subplots(figsize=(8, 8))
    for g in mb.grids:
        x, y = np.asarray(g.x), np.asarray(g.y)
        a = np.abs(signed_area(x, y))
        ax.pcolormesh(x, y, np.log2(a / h**2), cmap="RdBu_r", vmin=-2, vmax=2, shading="flat", alpha=0.6)
        ax.plot(x, y, "k-", lw=0.3)
        ax.plot(x.T, y.T, "k-", lw=0.3)
        for bx, by in ((x[0], y[0]), (x[-1], y[-1]), (x[:, 0], y[:, 0]), (x[:, -1], y[:, -1])):
            ax.plot(bx, by, "b-", lw=1.5)
    bad = pr["ratio"] > 2
    ax.plot(pr["mid"][bad, 0], pr["mid"][bad, 1], "r.", ms=8)
    ax.set_xlim(m[0] - 10 * h, m[0] + 10 * h)
    ax.set_ylim(m[1] - 10 * h, m[1] + 10 * h)
    ax.set_aspect("equal")
    ax.set_title("cell area / h² (log2); red: interface pairs above 2")
    fig.savefig(out, dpi=80, bbox_inches="tight")


if __name__ == "__main__":
    raise SystemExit(main())
