"""The pipeline's faster paths (session 30) give the numbers and choices of the plain code they replace.

Each reference below is the code as it was before (the test oracle): the nearest shore ring of a cut
end measured only where its bounding box could be nearer (:func:`meshcore.multiblock.outline._nearest_ring`),
an island's second cut read only up to the candidate taken (:func:`meshcore.layout.regions._first_apart`),
the chosen layout's grid going on from its coarse reading (:class:`meshcore.lakegrid.CoarseReadings`),
and the block SOR engine's copies as one gather and one scatter a sweep (:mod:`meshcore.multiblock.sor`).
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from meshcore import testing
from meshcore.lakegrid import CoarseReadings, coarse_reading, mesh_layout, mesh_outline
from meshcore.layout import auto_layout, regions
from meshcore.multiblock import sor
from meshcore.multiblock.outline import _nearest_ring
from meshcore.segments import nearest_on_polyline


def _rings(rng) -> list[np.ndarray]:
    out = []
    for _ in range(int(rng.integers(1, 12))):
        n = int(rng.integers(3, 40))
        ang = np.sort(rng.uniform(0.0, 2 * np.pi, n))
        c = rng.uniform(-10.0, 10.0, 2)
        out.append(c + np.column_stack([np.cos(ang), np.sin(ang)]) * rng.uniform(0.2, 3.0, (n, 1)))
    if rng.random() < 0.5:  # the same ring twice: the first is kept, as min keeps it
        out.append(out[int(rng.integers(len(out)))].copy())
    return out


@pytest.mark.parametrize("seed", range(20))
def test_nearest_ring_is_the_min_over_every_ring(seed):
    rng = np.random.default_rng(seed)
    rings = _rings(rng)
    boxes = [(r.min(axis=0), r.max(axis=0)) for r in rings]
    pts = list(rng.uniform(-14.0, 14.0, (30, 2))) + [rings[0][0], 0.5 * (rings[-1][0] + rings[-1][1])]
    for q in pts:
        near = ((nearest_on_polyline(r, q, True), "outline", ri) for ri, r in enumerate(rings))
        want = min(near, key=lambda b: b[0][0])
        assert _nearest_ring(rings, boxes, q) == want


def _second_fallback_ref(more, hole, rings, sigma, beside, away):
    """The fallback of ``_second_cut`` as it was: ``(good or apart)[0]`` or None."""
    apart = [
        seg for _, seg in regions._apart(regions._without_wedges(more, hole, rings, sigma) or more, beside, 2 * sigma)
    ]
    good = [seg for seg in apart if away(seg)]
    both = good or apart
    return both[0] if both else None


@pytest.mark.parametrize("seed", range(40))
def test_first_apart_takes_what_the_full_lists_took(seed, monkeypatch):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(0, 12))
    segs = [np.array([[float(k), 0.0], [float(k), 1.0]]) for k in range(n)]
    more = [(float(k), s) for k, s in enumerate(segs)]
    p_wedge, p_apart, p_away = rng.uniform(0.0, 1.0, 3)
    wedge = {k: rng.random() < p_wedge for k in range(n)}
    apart = {k: rng.random() < p_apart for k in range(n)}
    far = {k: rng.random() < p_away for k in range(n)}
    calls = []

    def key(seg):
        return int(seg[0][0])

    def without_wedges(cand, hole, rings, sigma):
        calls.extend(key(s) for _, s in cand)
        return [(L, s) for L, s in cand if not wedge[key(s)]]

    monkeypatch.setattr(regions, "_without_wedges", without_wedges)
    monkeypatch.setattr(regions, "_apart", lambda cand, cuts, gap: [(L, s) for L, s in cand if apart[key(s)]])

    def away(seg):
        return far[key(seg)]

    want = _second_fallback_ref(more, None, None, 1.0, [], away)
    full = len(calls)
    calls.clear()
    got = regions._first_apart(more, None, None, 1.0, [], away)
    assert got is want
    assert len(calls) <= full


def _grids_equal(a, b) -> bool:
    return len(a.grids) == len(b.grids) and all(
        np.array_equal(g.x, h.x) and np.array_equal(g.y, h.y) for g, h in zip(a.grids, b.grids, strict=True)
    )


@pytest.mark.slow
@pytest.mark.parametrize(
    "poly",
    [testing.lake_with_islands(5, n_islands=3), testing.channel_network(3, n_branches=4)],
    ids=["islands", "net"],
)
def test_held_coarse_solve_gives_the_grid_of_a_fresh_one(poly):
    """The layout and grid of :func:`mesh_outline` (the chosen layout's coarse level held) are those of
    the plain steps: :func:`auto_layout` with :func:`coarse_reading`, then :func:`mesh_layout`; a
    callback sees the same levels with the same grids."""
    lay = auto_layout(poly, target_cells=2000, multiple=4, reading=coarse_reading)
    seen_fresh, seen_held = [], []

    def log(into):
        def cb(kind, value):
            into.append((kind, value[0], [g.x.copy() for g in value[1].grids]) if kind == "level" else (kind, value))

        return cb

    fresh = mesh_layout(lay, levels=2, callback=log(seen_fresh))
    readings = CoarseReadings(levels=2)
    lay2 = auto_layout(poly, target_cells=2000, multiple=4, reading=readings)
    assert lay2.blocks == lay.blocks
    n = len(readings._held)
    held = mesh_layout(lay2, levels=2, callback=log(seen_held), readings=readings)
    assert len(readings._held) == n - 1  # the held solve went on
    assert _grids_equal(held, fresh)
    assert held.info.iterations == fresh.info.iterations and held.info.message == fresh.info.message
    assert [s[:2] for s in seen_held] == [s[:2] for s in seen_fresh]
    for a, b in zip(seen_held, seen_fresh, strict=True):
        if a[0] == "level":
            assert all(np.array_equal(x, y) for x, y in zip(a[2], b[2], strict=True))
    assert _grids_equal(mesh_outline(poly, target_cells=2000), fresh)
    readings = CoarseReadings(levels=2)  # a callback that stops at the coarse level: that level's grid
    lay3 = auto_layout(poly, target_cells=2000, multiple=4, reading=readings)

    def stop(kind, value):
        return "stop" if kind == "level" else None

    got = mesh_layout(lay3, levels=2, callback=stop, readings=readings)
    want = mesh_layout(lay, levels=2, callback=stop)
    assert _grids_equal(got, want) and got.info.message == want.info.message == "stopped"


class _BlockEngineRef(sor._BlockEngine):
    """The block SOR engine as it was: each block's own array, two copies per block a sweep (its
    residual, finish and grids, which read the block arrays, are the engine's)."""

    def __init__(self, x, y, m) -> None:
        super().__init__(x, y, m)  # the kernels, the tables and which nodes each sweep copies
        self.bx = [np.ascontiguousarray(x[ids]) for ids in m.ids]
        self.by = [np.ascontiguousarray(y[ids]) for ids in m.ids]
        start = np.cumsum([0] + [ids.size for ids in m.ids])

        def per_block(pair):
            at, node = pair
            inside = [(at >= a) & (at < b) for a, b in itertools.pairwise(start)]
            return [(at[k] - a, node[k]) for a, k in zip(start, inside, strict=False)]

        self.ring, self.frame = per_block(self.ring), per_block(self.frame)

    def sweep(self, omega: float) -> float:
        from meshcore.multiblock import _kernels

        d = 0.0
        for bx, by, (li, gi) in zip(self.bx, self.by, self.ring, strict=True):
            if bx.shape[0] > 2 and bx.shape[1] > 2:
                d = max(d, self.bk.sweep4(bx, by, self.e, self.e, omega, False))
            self.x[gi] = bx.reshape(-1)[li]
            self.y[gi] = by.reshape(-1)[li]
        d = max(d, float(_kernels.table_sweep(self.x, self.y, *self.args, omega)))
        for bx, by, (fr, gf) in zip(self.bx, self.by, self.frame, strict=True):
            bx.reshape(-1)[fr] = self.x[gf]
            by.reshape(-1)[fr] = self.y[gf]
        return d

    def save(self):
        return ([b.copy() for b in self.bx], [b.copy() for b in self.by], self.x.copy(), self.y.copy())

    def restore(self, saved) -> None:
        for b, s in zip(self.bx, saved[0], strict=True):
            b[...] = s
        for b, s in zip(self.by, saved[1], strict=True):
            b[...] = s
        self.x[...] = saved[2]
        self.y[...] = saved[3]


@pytest.mark.parametrize(
    "poly",
    [testing.lake_with_islands(7, n_islands=4), testing.channel_network(11, n_branches=6), testing.y_junction()],
    ids=["islands", "net", "y"],
)
def test_block_sor_engine_gives_the_plain_engines_grids(poly, monkeypatch):
    """The start solve of a layout's coarse level (omega reduced on the way or not) with the block
    engine, bit for bit as the engine that kept each block's array apart; its sweeps and residuals too."""
    from meshcore.multiblock import solve_multiblock
    from meshcore.multiblock import solver as mb_solver
    from meshcore.orthogonal.levels import coarsen_topology

    lay = auto_layout(poly, target_cells=1500, multiple=4)
    for topo in (lay.topology(), coarsen_topology(lay.topology(), 4)):
        got = solve_multiblock(topo, mode="smooth", engine="blocks")
        monkeypatch.setattr(mb_solver, "sor_engine", lambda x, y, m, engine="blocks": _BlockEngineRef(x, y, m))
        want = solve_multiblock(topo, mode="smooth", engine="blocks")
        monkeypatch.setattr(mb_solver, "sor_engine", sor.sor_engine)
        assert _grids_equal(got, want)
        assert got.info.iterations == want.info.iterations and got.info.message == want.info.message
