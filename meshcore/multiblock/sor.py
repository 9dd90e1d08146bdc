"""SOR over all blocks of a multiblock grid (``engine="blocks"`` or ``"table"``).

``"table"`` sweeps every free node through the global neighbour table;
``"blocks"`` sweeps each block's interior with the single-block kernel and the
border nodes with the table (see :mod:`.solver`).  :func:`iterate_sor` yields
after every residual check, so a caller can report progress and stop.
"""

from __future__ import annotations

import math
from collections.abc import Generator
from typing import Any

import numpy as np

from ..elliptic import EllipticConfig
from . import _kernels

__all__ = ["iterate_sor", "sor_engine"]


class _TableEngine:
    """Every free node through the global neighbour table."""

    def __init__(self, x, y, m) -> None:
        self.x, self.y = x, y
        self.args = (m.nodes, m.nbr, m.irr_nodes, m.irr_ptr, m.irr_ring)

    def sweep(self, omega: float) -> float:
        return float(_kernels.table_sweep(self.x, self.y, *self.args, omega))

    def residual(self) -> float:
        return float(_kernels.table_residual(self.x, self.y, *self.args))

    def save(self):
        return (self.x.copy(), self.y.copy())

    def restore(self, saved) -> None:
        self.x[...] = saved[0]
        self.y[...] = saved[1]

    def finish(self) -> None:
        pass

    def grids(self, ids: list[np.ndarray]) -> list[tuple[np.ndarray, np.ndarray]]:
        return [(self.x[i], self.y[i]) for i in ids]


class _BlockEngine:
    """Block interiors with the single-block kernel, border nodes with the table.

    One sweep: (1) ``sweep4`` on each block's own array (its frame fixed);
    (2) copy each block's first interior ring — the only interior values a
    border stencil reads — into the global array; (3) table sweep over the
    free border nodes; (4) copy the border values back into the block frames.
    """

    def __init__(self, x, y, m) -> None:
        from ..elliptic import _kernels as bk

        self.bk = bk
        self.x, self.y = x, y
        self.e = np.zeros((0, 0))
        k0 = m.n_interior
        self.args = (m.nodes[k0:], m.nbr[k0:], m.irr_nodes, m.irr_ptr, m.irr_ring)
        # the blocks' arrays: views into one buffer, so the copies between them and the global
        # arrays are one gather and one scatter a sweep, not two per block
        start = np.cumsum([0] + [ids.size for ids in m.ids])
        self.fx = np.concatenate([x[ids].ravel() for ids in m.ids])
        self.fy = np.concatenate([y[ids].ravel() for ids in m.ids])
        self.bx = [self.fx[a : a + ids.size].reshape(ids.shape) for a, ids in zip(start, m.ids, strict=False)]
        self.by = [self.fy[a : a + ids.size].reshape(ids.shape) for a, ids in zip(start, m.ids, strict=False)]
        needed = np.zeros(m.n_nodes, dtype=bool)
        needed[self.args[1].ravel()] = True
        needed[m.irr_ring] = True
        ring, frame = [], []  # (place in the buffer, node) of each block's needed interior, of its frame
        for a, ids in zip(start, m.ids, strict=False):
            flat = ids.ravel()
            inner = np.zeros(ids.shape, dtype=bool)
            inner[1:-1, 1:-1] = True
            li = np.flatnonzero(inner.ravel() & needed[flat])
            ring.append((a + li, flat[li]))
            fr = np.flatnonzero(~inner.ravel())
            frame.append((a + fr, flat[fr]))
        self.ring = (np.concatenate([r[0] for r in ring]), np.concatenate([r[1] for r in ring]))
        self.frame = (np.concatenate([f[0] for f in frame]), np.concatenate([f[1] for f in frame]))
        self.ids = m.ids

    def sweep(self, omega: float) -> float:
        d = 0.0
        for bx, by in zip(self.bx, self.by, strict=True):
            if bx.shape[0] > 2 and bx.shape[1] > 2:
                d = max(d, self.bk.sweep4(bx, by, self.e, self.e, omega, False))
        li, gi = self.ring  # (each block's interior nodes are its own: the order of the copies is free)
        self.x[gi] = self.fx[li]
        self.y[gi] = self.fy[li]
        d = max(d, float(_kernels.table_sweep(self.x, self.y, *self.args, omega)))
        fr, gf = self.frame
        self.fx[fr] = self.x[gf]
        self.fy[fr] = self.y[gf]
        return d

    def residual(self) -> float:
        r = float(_kernels.table_residual(self.x, self.y, *self.args))
        for bx, by in zip(self.bx, self.by, strict=True):
            r = max(r, float(self.bk.jacobi_residual(bx, by, self.e, self.e, False)))
        return r

    def save(self):
        return (self.fx.copy(), self.fy.copy(), self.x.copy(), self.y.copy())

    def restore(self, saved) -> None:
        self.fx[...] = saved[0]
        self.fy[...] = saved[1]
        self.x[...] = saved[2]
        self.y[...] = saved[3]

    def finish(self) -> None:
        for bx, by, ids in zip(self.bx, self.by, self.ids, strict=True):
            self.x[ids] = bx
            self.y[ids] = by

    def grids(self, ids: list[np.ndarray]) -> list[tuple[np.ndarray, np.ndarray]]:
        del ids  # every block array is whole after a sweep (its frame is copied back)
        return [(bx.copy(), by.copy()) for bx, by in zip(self.bx, self.by, strict=True)]


def sor_engine(x: np.ndarray, y: np.ndarray, m: Any, engine: str = "blocks") -> _BlockEngine | _TableEngine:
    """The SOR engine ``"blocks"`` or ``"table"`` on the global arrays ``x, y`` (see :mod:`.solver`)."""
    return _BlockEngine(x, y, m) if engine == "blocks" else _TableEngine(x, y, m)


def iterate_sor(eng: Any, m: Any, cfg: EllipticConfig, tol: float) -> Generator[tuple[int, float], Any, tuple]:
    """SOR sweeps until the Jacobi residual ≤ ``tol``; yields ``(sweep, residual)`` at every check.

    Send ``"stop"`` to stop.  Returns ``(sweeps, residual, history, message)``
    (absolute residuals); the engine's arrays are written back to ``x, y``.
    """
    try:
        return (yield from _sor_loop(eng, m, cfg, tol))
    finally:
        eng.finish()


def _sor_loop(eng: Any, m: Any, cfg: EllipticConfig, tol: float) -> Generator[tuple[int, float], Any, tuple]:
    n_eff = max(math.sqrt(2.0 * max(m.n_nodes, 4)), 2.0)
    omega = cfg.omega if cfg.omega is not None else 2.0 / (1.0 + math.sin(math.pi / n_eff))
    auto = cfg.omega is None
    r = eng.residual()
    history = [(0, r)]
    if r <= tol:
        return 0, r, history, ""
    best = r
    saved = eng.save()
    check_every, since, message = 1, 0, ""
    it = 0
    for it in range(1, cfg.max_iterations + 1):
        d = eng.sweep(omega) / omega
        since += 1
        if not math.isfinite(d) or since >= check_every or d < 4.0 * tol:
            since = 0
            r = eng.residual() if math.isfinite(d) else math.inf
            history.append((it, r))
            if (yield it, r) == "stop":
                return it, r, history, "stopped"
            if r <= tol:
                return it, r, history, ""
            if not math.isfinite(r) or r > 1e3 * best:
                eng.restore(saved)
                if not auto and omega <= 1.0:
                    return it, eng.residual(), history, "diverged"
                omega = 1.0 + 0.5 * (omega - 1.0) if omega > 1.05 else 0.7 * omega
                message = f"omega reduced to {omega:.3f}"
                check_every = 1
            elif r < best:
                best = r
                saved = eng.save()
                check_every = min(2 * check_every, 32)
    return it, eng.residual(), history, message
