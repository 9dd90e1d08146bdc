r"""Grid sequencing: solve on a coarse copy of the layout, refine, solve again.

The orthogonal smoother is a Gauss–Seidel iteration: it removes local errors in a few sweeps
but needs thousands to move nodes along a 30-km shore.  Those slow, smooth errors are
resolved cheaply on a coarse grid — the same blocks with half (or a quarter of) the cells —
and carried to the fine grid by :func:`refine`, where a few sweeps remove what the
interpolation left.  Cell counts must be multiples of ``2**levels`` (the layout's integer
program arranges that).
"""

from __future__ import annotations

import numpy as np

from ..multiblock.topology import Block, Interface, MultiBlockTopology, Side

__all__ = ["coarsen_topology", "refine"]


def _refine_grid(x: np.ndarray) -> np.ndarray:
    """Bilinear refinement in index space: ``(n+1, m+1)`` nodes → ``(2n+1, 2m+1)``."""
    n, m = x.shape
    out = np.empty((2 * n - 1, 2 * m - 1))
    out[::2, ::2] = x
    out[1::2, ::2] = 0.5 * (x[:-1] + x[1:])
    out[::2, 1::2] = 0.5 * (x[:, :-1] + x[:, 1:])
    out[1::2, 1::2] = 0.25 * (x[:-1, :-1] + x[1:, :-1] + x[:-1, 1:] + x[1:, 1:])
    return out


def refine(grids) -> list:
    """Every block grid refined twice in each direction (interface nodes stay shared:
    the midpoint of a shared edge is computed the same way from either side)."""
    return [g.replaced(x=_refine_grid(g.x), y=_refine_grid(g.y)) for g in grids]


def coarsen_topology(topology: MultiBlockTopology, factor: int) -> MultiBlockTopology:
    """The topology with every block's borders sub-sampled by ``factor`` (cells divisible by it)."""
    blocks = []
    for b in topology.blocks:
        ni, nj = b.cells
        if ni % factor or nj % factor:
            raise ValueError(f"block {b.name!r}: cells {ni}×{nj} are not multiples of {factor}")
        bd = b.borders
        sub = type(bd)(
            bottom=bd.bottom[::factor].copy(),
            right=bd.right[::factor].copy(),
            top=bd.top[::factor].copy(),
            left=bd.left[::factor].copy(),
        )
        blocks.append(Block(b.name, sub, initial=b.initial, weights=b.weights, names=dict(b.names)))
    itfs = []
    for itf in topology.interfaces:
        sides = []
        for s in (itf.a, itf.b):
            if s.start % factor or s.stop % factor:
                raise ValueError(f"interface side {s.label} is not a multiple of {factor}")
            sides.append(Side(s.block, s.border, s.start // factor, s.stop // factor))
        itfs.append(Interface(sides[0], sides[1], itf.reversed))
    return MultiBlockTopology(tuple(blocks), tuple(itfs), check_geometry=False)


def _project(rings: list[np.ndarray], pts: np.ndarray):
    """Ring index, arc length and perimeter of the nearest ring point to every point."""
    best = np.full(len(pts), np.inf)
    ring_of = np.zeros(len(pts), dtype=int)
    s_of = np.zeros(len(pts))
    for k, r in enumerate(rings):
        a, b = r, np.roll(r, -1, axis=0)
        d = b - a
        L = np.hypot(*d.T)
        cum = np.concatenate([[0.0], np.cumsum(L)])
        for lo in range(0, len(pts), 256):
            q = pts[lo : lo + 256, None, :]
            t = np.clip(((q - a) * d).sum(-1) / np.maximum(L * L, 1e-300), 0.0, 1.0)
            dist = np.hypot(*(a + t[..., None] * d - q).transpose(2, 0, 1))
            j = np.argmin(dist, axis=1)
            dj = dist[np.arange(len(j)), j]
            better = dj < best[lo : lo + 256]
            idx = np.arange(lo, lo + len(j))[better]
            best[idx] = dj[better]
            ring_of[idx] = k
            s_of[idx] = cum[j[better]] + t[np.arange(len(j)), j][better] * L[j[better]]
    return ring_of, s_of


def _ring_point(ring: np.ndarray, s: np.ndarray) -> np.ndarray:
    closed = np.vstack([ring, ring[:1]])
    cum = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(closed, axis=0).T))])
    s = np.mod(s, cum[-1])
    return np.column_stack([np.interp(s, cum, closed[:, 0]), np.interp(s, cum, closed[:, 1])])


def refine_shore(grids, topology: MultiBlockTopology, rings: list[np.ndarray]) -> list:
    """After :func:`refine`, put every new shore node on the shore, halfway along it between
    its two neighbours (the straight midpoint would cut across every bay the coarse edge
    spanned, and the nearest shore point would be at its mouth)."""
    if not rings:
        return list(grids)
    m = topology.node_map
    per = [float(np.hypot(*(np.roll(r, -1, axis=0) - r).T).sum()) for r in rings]
    out = []
    for g, ids in zip(grids, m.ids, strict=True):
        x, y = np.array(g.x), np.array(g.y)
        trip = []
        for sl in ((slice(None), 0), (slice(None), -1), (0, slice(None)), (-1, slice(None))):
            bid = ids[sl]
            idx = np.arange(x.shape[0]) if isinstance(sl[0], slice) else np.arange(x.shape[1])
            for j in range(1, len(bid) - 1, 2):
                if m.boundary[bid[j - 1]] and m.boundary[bid[j]] and m.boundary[bid[j + 1]]:
                    trip.append((sl, idx[j - 1], idx[j], idx[j + 1]))
        if trip:

            def at(sl, j):
                return (j, sl[1]) if isinstance(sl[0], slice) else (sl[0], j)

            ends = np.array([[x[at(sl, a)], y[at(sl, a)], x[at(sl, b)], y[at(sl, b)]] for sl, a, _, b in trip])
            ra, sa = _project(rings, ends[:, :2])
            rb, sb = _project(rings, ends[:, 2:])
            for (sl, _, j, _), r1, s1, r2, s2 in zip(trip, ra, sa, rb, sb, strict=True):
                if r1 != r2:
                    continue
                total = per[r1]
                d = (s2 - s1) % total
                if d > total / 2:  # the short way round
                    d -= total
                p = _ring_point(rings[r1], np.array([s1 + d / 2]))[0]
                x[at(sl, j)], y[at(sl, j)] = p
        out.append(g.replaced(x=x, y=y))
    return out
