"""The pipeline's faster paths (session 30) give the numbers and choices of the plain code they replace.

Each reference below is the code as it was before (the test oracle): the nearest shore ring of a cut
end measured only where its bounding box could be nearer (:func:`meshcore.multiblock.outline._nearest_ring`),
an island's second cut read only up to the candidate taken (:func:`meshcore.layout.regions._first_apart`).
"""

from __future__ import annotations

import numpy as np
import pytest

from meshcore.layout import regions
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
