"""The segment foot of :mod:`meshcore.segments` against shapely's distances and projections."""

import numpy as np
import pytest
import shapely

from meshcore.segments import feet, nearest_on_polyline


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
