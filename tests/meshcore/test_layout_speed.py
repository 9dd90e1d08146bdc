"""The layout's faster paths (session 29) give the numbers and choices of the plain code they replace.

Each reference below is the code as it was before (the test oracle): the corner helpers must
agree to the last bit, the pruned split options must keep the option the full list would choose,
and :func:`~meshcore.layout.fans.unfan` must return the split its full look-ahead returned.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from meshcore import testing
from meshcore.layout import fans, split
from meshcore.layout.corners import (
    _arclength_closed,
    _sharp_peaks,
    _where_it_bends,
    _where_they_bend,
    bulge_cost,
    choose_corners,
    corner_cost,
    raw_turning,
    set_cost,
    side_cost,
    turning,
)


def _jagged_ring(seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    n = int(rng.integers(6, 160))
    ang = np.sort(rng.uniform(0.0, 2 * np.pi, n))
    return np.column_stack([np.cos(ang), np.sin(ang)]) * rng.uniform(0.5, 1.5, (n, 1))


def _turning_ref(ring, sigma):
    s, total = _arclength_closed(ring)
    sigma = min(sigma, 0.25 * total)
    xs = np.concatenate([s - total, s, s + total])
    xp = np.vstack([ring, ring, ring])

    def at(q):
        return np.column_stack([np.interp(q, xs, xp[:, 0]), np.interp(q, xs, xp[:, 1])])

    a = ring - at(s - sigma)
    b = at(s + sigma) - ring
    return np.degrees(np.arctan2(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0], (a * b).sum(axis=1)))


def _set_cost_ref(ring, sigma, picks):
    s, total = _arclength_closed(ring)
    t = _turning_ref(ring, sigma)
    near = np.zeros(len(ring), dtype=bool)
    for c in picks:
        d = np.abs(s - s[c])
        near |= np.minimum(d, total - d) < sigma
    return corner_cost(t, picks, near) + side_cost(s, total, picks) + bulge_cost(ring, picks)


def _sharp_peaks_ref(t, s, total, sigma, limit):
    """The peaks as the plain code took them (every vertex compared with every peak taken)."""
    taken: list[int] = []
    for i in np.argsort(-t).tolist():
        if t[i] < limit:
            break
        gaps = [abs(float(s[i]) - float(s[j])) for j in taken]
        if all(min(g, total - g) > sigma for g in gaps):
            taken.append(i)
    return taken


def _point_along_ref(ring, s, total, at):
    at = at % total
    xs = np.concatenate([s, [total]])
    xp = np.vstack([ring, ring[:1]])
    return np.array([np.interp(at, xs, xp[:, 0]), np.interp(at, xs, xp[:, 1])])


@pytest.mark.parametrize("seed", range(12))
def test_corner_helpers_match_the_plain_code(seed):
    ring = _jagged_ring(seed)
    rng = np.random.default_rng(100 + seed)
    s, total = _arclength_closed(ring)
    raw = raw_turning(ring)
    for sigma in (0.02, 0.15, 0.6):
        t = turning(ring, sigma)
        assert np.array_equal(t, _turning_ref(ring, sigma))
        picks = sorted(int(i) for i in rng.choice(len(ring), 4, replace=False))
        got, want = set_cost(ring, sigma, picks), _set_cost_ref(ring, sigma, picks)
        assert got == want or (math.isinf(got) and math.isinf(want))
        for limit in (20.0, 45.0):
            full = _sharp_peaks_ref(t, s, total, sigma, limit)
            assert _sharp_peaks(t, s, total, sigma, limit) == full
            assert _sharp_peaks(t, s, total, sigma, limit, most=4) == full[:4]
        some = [int(i) for i in rng.choice(len(ring), 5, replace=False)]
        for reach in (0.0, 0.5 * sigma, 2 * sigma):
            one_by_one = [_where_it_bends(raw, s, total, i, reach) for i in some]
            assert _where_they_bend(raw, s, total, some, reach) == one_by_one
        table = split._along_table(ring, s, total)
        for at in rng.uniform(-2 * total, 2 * total, 6):
            assert np.array_equal(split._point_along(ring, s, total, at, table), _point_along_ref(ring, s, total, at))
    assert _where_they_bend(raw, s, total, [], 0.1) == []


@pytest.mark.parametrize("seed", range(8))
def test_corners_of_is_choose_corners(seed):
    ring = _jagged_ring(seed)
    forced = [0, 3] if seed % 2 else []
    split._costs.clear()
    for sigma in (0.05, 0.3):
        want = choose_corners(ring, sigma, forced=forced)
        assert split.corners_of(ring, sigma, forced) == want
        assert split.corners_of(ring.copy(), sigma, forced) == want  # remembered: the same answer
        assert split.region_cost(ring, sigma, ring[forced]) == want[1]


def _region_rings():
    """CCW outer rings of generated lakes (reflex corners, bays), with their cell size."""
    shapes = [testing.y_junction(), *(testing.channel_network(s, n_branches=4) for s in (3, 4, 5))]
    shapes += [testing.round_lake(s, kind="arms", n_islands=0) for s in (1, 2)]
    for poly in shapes:
        ring = split._orient(np.asarray(poly.exterior.coords)[:-1])
        yield ring, math.sqrt(poly.area / 400.0)


def _segs(options):
    return [tuple(np.round(np.vstack(o[1]), 12).ravel()) for o in options]


def test_pruned_cut_options_keep_the_cheapest():
    """``_cut_options`` with a bound leaves out only options that cost more than it or than the
    cheapest option: the first cheapest of the full list is kept, and is the first cheapest."""
    n = 0
    for ring, h in _region_rings():
        sigma = 1.5 * h
        cuts = split._motorcycle_cuts(ring, sigma) + split._normal_cuts(ring, sigma, even=True)
        full = split._cut_options(cuts, sigma, 3 * h)
        if not full:
            continue
        n += 1
        cheapest = min(full, key=lambda o: o[2])
        for bound in (math.inf, cheapest[2], 2 * cheapest[2] + 1.0, 0.5 * cheapest[2]):
            kept = split._cut_options(cuts, sigma, 3 * h, bound=bound)
            ks = set(_segs(kept))
            assert ks <= set(_segs(full))
            # left out: only options that cost more than the bound or the cheapest
            assert all(o[2] > min(bound, cheapest[2]) for o in full if _segs([o])[0] not in ks)
            if cheapest[2] <= bound:
                first = min(kept, key=lambda o: o[2])
                assert _segs([first]) == _segs([cheapest]) and first[2] == cheapest[2]
    assert n >= 3


def test_best_split_same_with_and_without_pruning(monkeypatch):
    """The greedy split is the same when no option is left out unpriced."""
    rings = list(_region_rings())
    got = [split.best_split(r, sigma=1.5 * h, min_width=3 * h) for r, h in rings]
    plain = split._cut_options

    def unpruned(cuts, sigma, min_width, thin=False, bound=None):
        return plain(cuts, sigma, min_width, thin)

    monkeypatch.setattr(split, "_cut_options", unpruned)
    split._costs.clear()
    for (r, h), (pieces, cuts, cost) in zip(rings, got, strict=True):
        p0, c0, k0 = split.best_split(r, sigma=1.5 * h, min_width=3 * h)
        assert cost == k0 and len(pieces) == len(p0) and len(cuts) == len(c0)
        assert all(np.array_equal(a[0], b[0]) for a, b in zip(pieces, p0, strict=True))


def _unfan_ref(ring, *, sigma, min_width, center=None, depth=3, wrapped=False):
    """:func:`~meshcore.layout.fans.unfan` as it was: every option's pieces split on, in order."""
    options = split._options(ring, sigma, min_width, center, (), False, True, False)
    options += split._cut_options(split._normal_cuts(ring, sigma, even=True), sigma, min_width)
    best = None
    for pieces, cuts, _ in options:
        out_p, out_c, total = [], list(cuts), 0.0
        for pc, fc in pieces:
            pp, cc, c = split.best_split(pc, sigma=sigma, min_width=min_width, depth=depth - 1, forced=fc)
            out_p += pp
            out_c += cc
            total += c
        if any(not len(f) and (fans.fans(p, sigma) or (wrapped and fans.wraps(p, sigma))) for p, f in out_p):
            continue
        if best is None or total < best[2]:
            best = (out_p, out_c, total)
    return None if best is None else best[:2]


@pytest.mark.slow
def test_unfan_matches_its_full_look_ahead():
    n = 0
    for ring, h in _region_rings():
        for wrapped in (False, True):
            got = fans.unfan(ring, sigma=1.5 * h, min_width=3 * h, wrapped=wrapped)
            want = _unfan_ref(ring, sigma=1.5 * h, min_width=3 * h, wrapped=wrapped)
            assert (got is None) == (want is None)
            if got is None:
                continue
            n += 1
            assert len(got[0]) == len(want[0]) and len(got[1]) == len(want[1])
            assert all(np.array_equal(a[0], b[0]) for a, b in zip(got[0], want[0], strict=True))
    assert n >= 3
