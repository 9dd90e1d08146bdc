"""The segment foot of :mod:`meshcore.segments` against shapely's distances and projections."""

import numpy as np
import pytest
import shapely

from meshcore.segments import SegmentIndex, feet, nearest_on_polyline


@pytest.mark.parametrize("seed", range(5))
def test_feet_match_shapely(seed):
    rng = np.random.default_rng(seed)
    a = rng.normal(size=(50, 2))
    b = a + rng.normal(size=(50, 2))
    b[::7] = a[::7]  # segments of zero length
    q = rng.normal(size=2) * 2
    dist, t = feet(a, b, q)
    lines = shapely.linestrings(np.stack([a, b], axis=1))
    assert np.allclose(dist, shapely.distance(lines, shapely.points(q)))
    assert np.all((t >= 0) & (t <= 1))
    assert np.all(t[::7] == 0.0)
    foot = a + t[:, None] * (b - a)
    assert np.allclose(np.hypot(*(foot - q).T), dist)


def test_feet_one_point_per_segment():
    a = np.array([[0.0, 0.0], [0.0, 0.0]])
    b = np.array([[2.0, 0.0], [0.0, 2.0]])
    q = np.array([[1.0, 1.0], [3.0, 1.0]])
    dist, t = feet(a, b, q)
    assert np.allclose(dist, [1.0, 3.0]) and np.allclose(t, [0.5, 0.5])


@pytest.mark.parametrize("closed", [True, False])
def test_nearest_on_polyline(closed):
    rng = np.random.default_rng(7)
    poly = np.cumsum(rng.normal(size=(30, 2)), axis=0)
    geom = shapely.LinearRing(poly) if closed else shapely.LineString(poly)
    for q in rng.normal(size=(20, 2)) * 5:
        d, k, t = nearest_on_polyline(poly, q, closed)
        assert d == pytest.approx(geom.distance(shapely.Point(q)), abs=1e-9)
        p = poly[k] + t * (poly[(k + 1) % len(poly)] - poly[k])
        assert np.hypot(*(p - q)) == pytest.approx(d, abs=1e-9)


def _rings(rng, k):
    """``k`` closed rings of random points, with repeated points and points on other rings' edges."""
    rings = []
    for _ in range(k):
        n = int(rng.integers(3, 40))
        r = rng.normal(size=(n, 2)) + rng.normal(size=2) * 3
        r[int(rng.integers(n))] = r[0]  # a zero-length edge somewhere (or the first point twice)
        rings.append(r)
    return rings


@pytest.mark.parametrize("seed", range(8))
def test_segment_index_is_the_scan(seed):
    """The indexed nearest segment is the scan's: first ring, then first segment, at the least
    distance; query points on vertices and edges (ties between segments) as well as off them."""
    rng = np.random.default_rng(seed + 8610)
    rings = _rings(rng, int(rng.integers(1, 5)))
    index = SegmentIndex(rings)
    qs = [rng.normal(size=2) * 4 for _ in range(30)]
    qs += [rings[0][1].copy(), rings[-1][-1].copy(), 0.5 * (rings[0][0] + rings[0][1])]
    for q in qs:
        best = None
        for k, r in enumerate(rings):
            d, i, t = nearest_on_polyline(r, q, closed=True)
            if best is None or d < best[0]:
                best = (d, k, i, t)
        assert index.nearest(q) == best
    pts = np.array(qs + [r[2 % len(r)] for r in rings])
    whole = shapely.MultiLineString([np.vstack([r, r[:1]]) for r in rings])
    for eps in (1e-9, 0.3, 2.0):
        d = shapely.distance(shapely.points(pts), whole)
        assert np.array_equal(index.near(pts, eps), d < eps)
        assert np.array_equal(index.near(pts, eps, within=True), d <= eps)
