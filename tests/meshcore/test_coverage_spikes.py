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


def _stray(poly, clean, h: float) -> float:
    """How far, in quarter cells, the farthest vertex ``clean`` added or took lies from the shore."""
    d = poly.symmetric_difference(clean)
    return float(shapely.distance(shapely.points(shapely.get_coordinates(d)), poly.boundary).max()) / (0.25 * h)


def test_a_mitre_beside_a_notch_does_not_carry_the_water_onto_land():
    """A shore that turns back on itself twice (a land wedge of 26° beside a water corner of 45°,
    as on a GSHHG lake): the mitred closing drew a spike of water 3.2 r out over the land, and the
    grid covered it 0.76 cells beyond the shore.  A closing with a disk adds nothing farther than
    r from the water."""
    ring = [(-4080, -13530), (-3790, -14005), (-3470, -14357), (-3555, -14323), (-3515, -14417)]
    ring += [(-2850, -14810), (0, -14810), (0, -11000), (-4080, -11000)]
    p = shapely.Polygon(ring)
    h = 206.26
    clean = cv.without_spikes(p, 0.5 * h)
    assert clean is not None and clean.is_valid
    assert _stray(p, clean, h) <= 1.0 + cv.REACH_SLACK + 1e-3


def test_what_the_spikes_rule_changes_stays_within_its_reach_of_the_shore():
    """Sharp tips and notches of generated shores (mitres clipped at their limit): whatever the
    opening and closing of half a cell take or add lies within a quarter cell of the shore."""
    for poly, cells in [
        (testing.dendritic(501703), 15000),
        (testing.dendritic(503703), 10000),
        (testing.headlands(502605, n=6), 3000),
        (testing.small_islands(502850, n_islands=10), 15000),
        (testing.channel_network(503003, n_branches=6), 3000),
    ]:
        h = math.sqrt(poly.area / cells)
        clean = cv.without_spikes(poly, 0.5 * h)
        if clean is None:
            continue
        assert clean.is_valid and len(clean.interiors) == len(poly.interiors)
        assert _stray(poly, clean, h) <= 1.0 + cv.REACH_SLACK + 1e-3, (poly, cells)
