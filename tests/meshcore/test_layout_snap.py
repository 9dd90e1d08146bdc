"""Cut ends snapped into the shore rings and other cuts (:func:`meshcore.layout.regions.snap_to_rings`):
the nearest segment of all of them in one search, as the search per ring and per cut found it."""

from __future__ import annotations

import math

import numpy as np
import pytest

from meshcore import segments, testing
from meshcore.layout import regions
from meshcore.layout.corners import _arclength_closed, _edges, bulge_ratio, choose_corners, raw_turning, turning


def _reference(rings, cuts, eps):
    """The definition: per end, every ring then every other cut in order, the first at the least distance."""
    rings = [r.copy() for r in rings]
    cuts = [c.copy() for c in cuts]
    for k in range(len(cuts)):
        for end in (0, -1):
            q = cuts[k][end]
            best = None
            for ri, r in enumerate(rings):
                d, seg, t = segments.nearest_on_polyline(r, q, True)
                if best is None or d < best[0]:
                    best = (d, "ring", ri, seg, t)
            for ci in range(len(cuts)):
                if ci != k:
                    d, seg, t = segments.nearest_on_polyline(cuts[ci], q, False)
                    if d < best[0]:
                        best = (d, "cut", ci, seg, t)
            _, kind, idx, seg, t = best
            target = rings[idx] if kind == "ring" else cuts[idx]
            n = len(target)
            a = target[seg]
            b = target[(seg + 1) % n] if kind == "ring" else target[seg + 1]
            p = a + t * (b - a)
            if math.hypot(*(p - a)) <= eps:
                p = a.copy()
            elif math.hypot(*(p - b)) <= eps:
                p = b.copy()
            else:
                target = np.insert(target, seg + 1, p, axis=0)
                if kind == "ring":
                    rings[idx] = target
                else:
                    cuts[idx] = target
            cuts[k][end] = p
    return rings, cuts


def _cuts_across(poly, rng, n):
    """``n`` random chords of the polygon's box, some ending on earlier ones, some on a vertex."""
    x0, y0, x1, y1 = poly.bounds
    cuts = []
    for k in range(n):
        a = rng.uniform([x0, y0], [x1, y1])
        b = rng.uniform([x0, y0], [x1, y1])
        if cuts and k % 3 == 0:  # ends on an earlier cut
            c = cuts[int(rng.integers(len(cuts)))]
            b = c[0] + rng.uniform(0.2, 0.8) * (c[-1] - c[0])
        if k % 5 == 0:  # ends on a shore vertex
            ext = np.asarray(poly.exterior.coords)[:-1]
            a = ext[int(rng.integers(len(ext)))].copy()
        cuts.append(np.linspace(a, b, int(rng.integers(2, 6))))
    return cuts


@pytest.mark.parametrize("seed", range(6))
def test_snapping_is_the_search_per_ring_and_cut(seed):
    rng = np.random.default_rng(seed)
    poly = testing.lake_with_islands(seed, n_islands=2 + seed) if seed % 2 else testing.channel_network(seed)
    rings = [np.asarray(poly.exterior.coords)[:-1], *(np.asarray(h.coords)[:-1] for h in poly.interiors)]
    cuts = _cuts_across(poly, rng, 12 + 4 * seed)
    for eps in (1e-9, 0.05):
        got_r, got_c = regions.snap_to_rings(rings, cuts, eps)
        want_r, want_c = _reference(rings, cuts, eps)
        assert len(got_r) == len(want_r) and len(got_c) == len(want_c)
        assert all(np.array_equal(a, b) for a, b in zip(got_r, want_r, strict=True))
        assert all(np.array_equal(a, b) for a, b in zip(got_c, want_c, strict=True))


def test_snapping_searches_once_per_cut_end(monkeypatch):
    """One distance computation per cut end, not one per ring and per other cut (which made the
    layout quadratic in its cuts)."""
    calls = []
    real = regions.feet

    def counted(*args):
        calls.append(1)
        return real(*args)

    monkeypatch.setattr(regions, "feet", counted)
    poly = testing.lake_with_islands(3, n_islands=4)
    rings = [np.asarray(poly.exterior.coords)[:-1], *(np.asarray(h.coords)[:-1] for h in poly.interiors)]
    cuts = _cuts_across(poly, np.random.default_rng(0), 30)
    regions.snap_to_rings(rings, cuts, 1e-9)
    assert len(calls) == 2 * len(cuts)


@pytest.mark.parametrize("seed", range(5))
def test_corner_helpers_given_the_arc_lengths_are_the_same(seed):
    """``choose_corners`` computes a ring's edges and arc lengths once and hands them on: the
    helpers give the same numbers with them as without, and ``_edges`` is ``roll(ring) - ring``."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(4, 120))
    ang = np.sort(rng.uniform(0.0, 2 * np.pi, n))
    ring = np.column_stack([np.cos(ang), np.sin(ang)]) * rng.uniform(0.5, 1.5, (n, 1))
    d = _edges(ring)
    assert np.array_equal(d, np.roll(ring, -1, axis=0) - ring)
    arc = _arclength_closed(ring, d)
    s, total = _arclength_closed(ring)
    assert np.array_equal(arc[0], s) and arc[1] == total
    for sigma in (0.05, 0.4):
        assert np.array_equal(turning(ring, sigma, arc), turning(ring, sigma))
        picks, cost = choose_corners(ring, sigma)
        assert np.isfinite(cost) and len(picks) == 4
        assert bulge_ratio(ring, picks, arc) == bulge_ratio(ring, picks)
    assert np.array_equal(raw_turning(ring, d), raw_turning(ring))
