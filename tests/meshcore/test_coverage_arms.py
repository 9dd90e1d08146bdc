"""The shoreline distance leaves out the dead-end arms narrower than two cells that the layout
leaves out on purpose (:func:`meshcore.layout.shore.without_narrow_arms`, with a note), measured
against the water without them (its shore crosses their mouths), as it leaves out spikes narrower
than half a cell; the distance to the shore as given keeps them (``hausdorff_as_given``).  A lake
grid carries the arms its layout left out (``MultiBlockGrid.arms``); without them the rule is the
layout's at the cell size given: an arm the layout would keep stays in."""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from shapely.geometry import LineString, box

from meshcore import testing
from meshcore.cellsize import default_cell_size
from meshcore.lakegrid import mesh_outline
from meshcore.quality import lake_metrics

CELLS = 2000


@pytest.fixture(scope="module")
def arm_lake():
    """A 10 × 3 basin with a dead-end arm 0.16 wide (1.3 cells at 2000 cells) and 3 long."""
    arm = LineString([(5.0, 2.9), (5.5, 6.0)]).buffer(0.08, cap_style="flat")
    poly = testing._clean(shapely.union_all([box(0.0, 0.0, 10.0, 3.0), arm]))
    return poly, mesh_outline(poly, target_cells=CELLS)


def test_an_arm_the_layout_leaves_out_is_measured_apart(arm_lake):
    poly, mb = arm_lake
    assert any("narrower than two cells: left out" in n for n in mb.notes)
    assert mb.arms is not None and len(mb.arms) == 1  # mesh_outline's grid (a held coarse solve) carries it
    h = default_cell_size(poly.area, CELLS)  # the layout's
    cov = lake_metrics(mb, polygon=poly, cell_size=h).coverage
    assert cov.hausdorff_cells <= 0.5
    assert cov.hausdorff_as_given / h > 20  # the arm's head, 3 long, is as far from the grid as that
    assert any("spikes included" in r[0] for r in cov.rows())


def test_an_arm_wide_enough_at_the_cell_size_given_stays_in(arm_lake):
    poly, mb = arm_lake
    h = default_cell_size(poly.area, CELLS) / 3  # at this size the layout keeps the arm
    # the blocks alone, without the layout's arms (``mb.arms``): the layout's rule at the size given
    cov = lake_metrics(list(mb.grids), polygon=poly, cell_size=h).coverage
    assert cov.hausdorff_cells > 20 * 3
    assert cov.hausdorff == pytest.approx(cov.hausdorff_as_given)


def test_boundary_points_are_bounded_whatever_the_step():
    """A grid flung far beyond its lake (a solver fault) asked segmentize for h/10 steps along a
    boundary ~10⁵ cells long: 23 GB.  The points are capped; a lake's boundary keeps its step."""
    from meshcore.quality.coverage import MAX_POINTS, _boundary_points

    far = shapely.box(0.0, 0.0, 1e6, 1.0).exterior
    assert len(_boundary_points(far, 1e-4)) <= MAX_POINTS + 5
    near = shapely.box(0.0, 0.0, 1.0, 1.0).exterior
    pts = _boundary_points(near, 0.1)
    assert len(pts) == 41 and np.allclose(np.hypot(*np.diff(pts, axis=0).T), 0.1)


def test_a_dense_outline_is_measured_as_the_layout_saw_it(arm_lake):
    """An outline traced far below the cell size (here ~60 vertices a cell, a wiggle of 0.005
    cells on each): the layout simplifies it (a note), and so does the search for arms and spikes
    (found on that shore, its buffers cost seconds on 10⁵ vertices), while the distances stay
    measured to the outline as given: the arm is measured apart as on the plain outline, and
    the wiggles are not spikes."""
    poly, mb = arm_lake
    h = default_cell_size(poly.area, CELLS)
    plain = lake_metrics(mb, polygon=poly, cell_size=h).coverage
    ring = np.asarray(shapely.segmentize(poly.exterior, h / 60).coords)[:-1]
    rng = np.random.default_rng(5)
    ring = ring + rng.uniform(-0.005 * h, 0.005 * h, ring.shape)
    dense = shapely.Polygon(ring)
    assert dense.is_valid and len(ring) > 50 * dense.length / h
    cov = lake_metrics(mb, polygon=dense, cell_size=h).coverage
    assert cov.hausdorff_as_given == pytest.approx(plain.hausdorff_as_given, abs=0.01 * h)
    assert cov.hausdorff_cells <= 0.5  # the arm left out as on the plain outline
    assert cov.hausdorff == pytest.approx(plain.hausdorff, abs=0.06 * h)  # the mouth within the slack
    assert cov.area_ratio == pytest.approx(plain.area_ratio, rel=1e-4)


def test_the_layouts_own_arms_are_the_ones_measured_apart():
    """Given the arms the layout left out (``Layout.arms``, ``MultiBlockGrid.arms``), the shore
    distance is measured across their mouths whatever the rule would find again on the shore as
    given (the two can differ where the layout's shore was prepared otherwise: big lakes g180507,
    g180510, session 52); given none, the arm's head counts."""
    from meshcore.lakegrid import mesh_layout
    from meshcore.layout import auto_layout

    h = 0.3
    arm = box(0.0, -3.0, 0.22, 0.0)  # 0.73 cells wide, 10 long, from a basin's corner
    poly = shapely.union_all([box(0.0, 0.0, 10.0, 10.0), arm])
    lay = auto_layout(poly, cell_size=h)
    assert len(lay.arms) == 1 and lay.arms[0].symmetric_difference(arm).area < 1e-6 * arm.area
    mb = mesh_layout(lay)
    assert mb.arms == lay.arms  # the grid carries them: the CLI's and the benchmarks' report use them
    own = lake_metrics(mb, polygon=poly, cell_size=h).coverage
    assert own.hausdorff_cells <= 0.5
    none = lake_metrics(mb, polygon=poly, cell_size=h, arms=()).coverage
    assert none.hausdorff / h == pytest.approx(10.0, abs=0.5)  # the arm's head, 3 below the basin
    assert own.hausdorff_as_given == none.hausdorff_as_given == pytest.approx(none.hausdorff)
