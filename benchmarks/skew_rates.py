"""Why the one-block Winslow multigrid needs 29–43 cycles on the branched lakes (issue 15).

Run from the repository root::

    python benchmarks/skew_rates.py [--model] [--lakes] [--modes LAKE ...]

``--model``: a parallelogram whose grid lines cross at the angle θ (``ρ = |cos θ|``), the
affine grid its exact Winslow solution, solved from a perturbed start to a tight tolerance
with point and with alternating-line smoothing: cycles and the rate per cycle at the end.
``--lakes``: each lake of ``robust.py`` as one block (``meshcore import``'s corners and
cells, ~24 000 nodes), the Winslow solve's cycles and final rate per cycle, and the share of
nodes whose grid lines cross at ``ρ`` beyond 0.8, 0.9, 0.95 (:func:`meshcore.quality.lake.node_cos`).
``--modes``: the slowest modes of the cycle linearised at the converged grid (Arnoldi on
finite differences of one cycle; Ritz values) and the share of each mode's energy at nodes
with ``ρ > 0.9``.  Cycle counts and rates do not depend on the machine's load.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))
sys.path.insert(0, str(HERE))

import meshcore  # noqa: E402
from meshcore.elliptic import multigrid  # noqa: E402
from meshcore.elliptic.solver import EllipticConfig, SolverState, default_tolerance  # noqa: E402
from meshcore.quality.lake import node_cos  # noqa: E402

#: Cycles over which the final rate per cycle is averaged.
TAIL = 3


def tail_rate(grid: meshcore.StructuredGrid) -> float:
    """Geometric mean of the residual ratios of the last ``TAIL`` cycles."""
    h = grid.info.residual_history
    if len(h) <= TAIL:
        return math.nan
    return (h[-1][1] / h[-1 - TAIL][1]) ** (1.0 / TAIL)


def parallelogram(rho: float, n: int) -> tuple[np.ndarray, np.ndarray, meshcore.StructuredGrid]:
    """The affine grid of a parallelogram (lines crossing at ``arccos ρ``) and a start grid
    perturbed by a smooth interior bump of a tenth of the domain."""
    xi, et = np.meshgrid(np.linspace(0, 1, n + 1), np.linspace(0, 1, n + 1), indexing="ij")
    th = math.acos(rho)
    x, y = xi + et * math.cos(th), et * math.sin(th)
    bump = np.sin(math.pi * xi) * np.sin(math.pi * et)
    dx, dy = 0.1 * bump * np.sin(3 * math.pi * et), 0.1 * bump * np.sin(2 * math.pi * xi)
    start = meshcore.StructuredGrid(x + dx, y + dy)
    return x, y, start


def model(n: int = 150) -> None:
    print(f"\nParallelogram {n}×{n} cells, tolerance 1e-12, 1 thread: cycles, final rate per cycle, CPU\n")
    print("| ρ = cos θ | point smoothing | alternating lines |")
    print("|---|---|---|")
    aniso = multigrid.anisotropic
    try:
        for rho in (0.0, 0.5, 0.8, 0.9, 0.95, 0.98):
            x, y, start = parallelogram(rho, n)
            cells = []
            for lines in (False, True):
                multigrid.anisotropic = lambda _x, _y, v=lines: v  # type: ignore[assignment]
                t = time.process_time()
                g = meshcore.solve(start, threads=1, method="multigrid", tolerance=1e-12)
                t = time.process_time() - t
                err = float(np.hypot(g.x - x, g.y - y).max()) * n
                cells.append(f"{g.iterations}, {tail_rate(g):.2f}, {t * 1e3:.0f} ms (error {err:.0e} h)")
            print(f"| {rho:.2f} | " + " | ".join(cells) + " |")
    finally:
        multigrid.anisotropic = aniso


def lake_grids() -> dict:
    from robust import LAKES, lake_block

    out = {}
    for label, path in LAKES:
        g = meshcore.generate_block(**lake_block(path, 24_000), threads=1, repair="off")
        out[label] = (g, bool(multigrid.last_run.get("lines")))  # smoothing as chosen on the start grid
    return out


def lakes(grids: dict) -> None:
    print("\nLakes as one block (~24 000 nodes), Winslow solve: cycles, final rate, share of nodes by ρ\n")
    print("| lake | cycles | final rate | ρ > 0.8 | ρ > 0.9 | ρ > 0.95 |")
    print("|---|---|---|---|---|---|")
    for label, (g, _) in grids.items():
        c = node_cos(np.asarray(g.x), np.asarray(g.y))[1:-1, 1:-1]
        shares = " | ".join(f"{np.mean(c > r):.2f}" for r in (0.8, 0.9, 0.95))
        print(f"| {label} | {g.iterations} | {tail_rate(g):.2f} | {shares} |")


class CycleMap:
    """One cycle of the solver (its defect, then ``cycle(0, have_defect=True)``) as a map of the
    interior nodes ``u = (x, y)``: what ``multigrid._cycles`` repeats."""

    def __init__(self, x: np.ndarray, y: np.ndarray, lines: bool):
        self.x, self.y = np.array(x, dtype=float), np.array(y, dtype=float)
        e = np.zeros((0, 0))
        length = float(np.hypot(np.ptp(x), np.ptp(y)))
        state = SolverState(
            x=self.x,
            y=self.y,
            p=e,
            q=e,
            periodic=False,
            config=EllipticConfig(threads=1),
            tol_abs=default_tolerance(x.shape) * length,
            length=length,
            stop_event=None,
            start=(self.x.copy(), self.y.copy()),
        )
        self.mg = multigrid._FAS(state, 1, False, lines)

    def get(self) -> np.ndarray:
        return np.concatenate([self.x[1:-1, 1:-1].ravel(), self.y[1:-1, 1:-1].ravel()])

    def __call__(self, u: np.ndarray) -> np.ndarray:
        n = u.size // 2
        self.x[1:-1, 1:-1] = u[:n].reshape(self.x.shape[0] - 2, -1)
        self.y[1:-1, 1:-1] = u[n:].reshape(self.x.shape[0] - 2, -1)
        self.mg.defect_restrict(0)
        self.mg.cycle(0, have_defect=True)
        return self.get()


def modes(label: str, g: meshcore.StructuredGrid, lines: bool, m: int = 30) -> None:
    """Ritz values of the linearised cycle (line-smoothed if ``lines``) at ``g``, tightly converged first."""
    g = meshcore.solve(g, threads=1, tolerance=1e-13)
    cyc = CycleMap(g.x, g.y, lines)
    us = cyc.get()
    gs = cyc(us.copy())
    step = 1e-7 * float(np.abs(us).max())
    basis = np.zeros((us.size, m + 1))
    hess = np.zeros((m + 1, m))
    v = np.random.default_rng(0).standard_normal(us.size)
    basis[:, 0] = v / np.linalg.norm(v)
    for k in range(m):
        v = basis[:, k]
        e = step / float(np.abs(v).max())
        w = (cyc(us + e * v) - gs) / e
        for _ in range(2):  # Gram–Schmidt twice
            h = basis[:, : k + 1].T @ w
            w -= basis[:, : k + 1] @ h
            hess[: k + 1, k] += h
        hess[k + 1, k] = np.linalg.norm(w)
        basis[:, k + 1] = w / hess[k + 1, k]
    lam, vec = np.linalg.eig(hess[:m, :m])
    order = np.argsort(-np.abs(lam))
    c = node_cos(np.asarray(g.x), np.asarray(g.y))[1:-1, 1:-1].ravel()
    n = us.size // 2
    print(f"\n{label}: slowest modes of the linearised cycle (|λ|, share of the mode's energy at ρ > 0.9)")
    for k in order[:8]:
        mode = (basis[:, :m] @ vec[:, k]).real
        energy = mode[:n] ** 2 + mode[n:] ** 2
        print(f"  {abs(lam[k]):.3f}  {energy[c > 0.9].sum() / energy.sum():.2f}")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--model", action="store_true", help="the parallelogram model problem")
    ap.add_argument("--lakes", action="store_true", help="the lakes' cycles, rates and skewness")
    ap.add_argument("--modes", nargs="*", default=[], help="slowest modes of these lakes' cycle")
    args = ap.parse_args(argv)
    if not (args.model or args.lakes or args.modes):
        args.model = args.lakes = True
    if args.model:
        model()
    if args.lakes or args.modes:
        grids = lake_grids()
        if args.lakes:
            lakes(grids)
        for label in args.modes:
            modes(label, *grids[label])
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
