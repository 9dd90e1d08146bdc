import math

import numpy as np
import shapely

from meshcore import testing
from meshcore.quality import coverage as cv


def test_spike_pieces_mark_the_same_shore_points_as_one_buffer_of_the_whole():
    p = testing.round_lake(700401, kind="arms", n_islands=5)
    h = math.sqrt(p.area / 15000)
    sp = cv._boundary_points(p.boundary, h / 10)
    clean = cv.without_spikes(p, 0.5 * h)
    assert clean is not None
    whole = shapely.contains_xy(p.symmetric_difference(clean).buffer(1e-3 * h), sp[:, 0], sp[:, 1])
    assert whole.any()
    np.testing.assert_array_equal(cv._in_spikes(cv._spikes(p, h), sp), whole)


def _z_fold(frac: float, length: float, chirality: int, theta: float, h: float) -> np.ndarray:
    """A 4000 × 1000 lake whose top shore steps back on itself in a Z: a tooth of water and one of
    land side by side, each ``length`` cells long and ``frac`` of half a cell wide at its base."""
    g, a, top = frac * h / 2, 2300.0, 1000.0
    lo, hi = (top - g, top) if chirality else (top, top - g)
    ring = [(0, 0), (4000, 0), (4000, lo), (a, lo), (a - length * h, lo), (a + 60, hi), (0, hi)]
    c, s = math.cos(theta), math.sin(theta)
    return np.asarray(ring, float) @ np.array([[c, s], [-s, c]])


def test_a_z_shaped_sliver_is_measured_apart_like_a_spike():
    """The layout smooths the Z's teeth out first (narrower than half a cell) and finds no arm
    after; the distance leaves them out the same way.  It read the water tooth as an arm narrower
    than two cells, measured against its mouth and never below the distance as given (one GSHHG
    lake: 0.75 cells, above its 0.57 as given)."""
    from meshcore.lakegrid import mesh_outline
    from meshcore.layout.polygon import water_polygon
    from meshcore.quality import lake_metrics

    h = 40.0
    for frac, length, chirality, theta in [(0.99, 15, 0, 0.3), (0.97, 18, 1, 0.7), (0.9, 10, 1, 1.2)]:
        poly, _ = water_polygon(_z_fold(frac, length, chirality, theta, h))
        got = lake_metrics(mesh_outline(poly, cell_size=h), polygon=poly, cell_size=h).coverage
        assert got.hausdorff_as_given >= 0.4 * frac * h  # the teeth are there, as given
        assert got.hausdorff <= 0.3 * h, (frac, length, chirality, got.hausdorff / h, got.where)
