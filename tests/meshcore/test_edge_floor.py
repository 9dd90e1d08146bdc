"""The size blend's floor (``orthogonal.driver.EDGE_FLOOR``): no polar fan of tiny cells into an
obtuse block corner.

Held-out g183278 (GSHHG, four blocks): its tip block has its fourth corner on the east shore where
the shore turns by some 20°.  The only orthogonal grid there is a polar fan whose cells shrink into
the corner at a steady ratio (under the size blend's 1.15): at 10 000 cells its shortest edge was
1/50 of the cell size, an explicit model's time step ÷ 50.  With the floor the edges there stay
above ~1/10 of it, for a few nodes' angles at the corner.
"""

from __future__ import annotations

import numpy as np
import pytest

from meshcore import mesh_outline
from meshcore.cli.lakefile import local_frame
from meshcore.io import read_points
from meshcore.layout.polygon import water_from_points, water_polygon
from meshcore.orthogonal import driver
from meshcore.quality import lake_metrics
from tests.conftest import ROOT


@pytest.fixture(scope="module")
def tip_lake():
    ps, _ = local_frame(read_points(ROOT / "tests" / "data" / "gshhg_g183278.geojson"), "auto")
    outer, islands = water_from_points(ps)
    poly, _ = water_polygon(outer, holes=islands)
    return poly


def _summary(poly):
    mb = mesh_outline(poly, target_cells=4000)
    return mb, lake_metrics(mb, polygon=poly).summary()


def test_the_floor_keeps_the_cells_at_an_obtuse_corner(tip_lake, monkeypatch):
    mb, on = _summary(tip_lake)
    monkeypatch.setattr(driver, "EDGE_FLOOR", 0.0)
    mb0, off = _summary(tip_lake)
    assert len(mb.grids) == len(mb0.grids) == 4  # the same layout: the solve makes the difference
    assert off["min_edge_cells"] < 0.06  # the fan (0.045 when measured)
    assert on["min_edge_cells"] > 0.08  # (0.105)
    for s in (on, off):
        assert s["folded_cells"] == 0
        assert s["pct_nodes_within_3deg"] >= 99.0  # a few nodes' angles at the corner, no more
        assert s["pct_smoothness_le_1.2"] >= 99.0
    # where the floor acts: the shortest edges of the grid without it lie at the one corner
    worst = [np.hypot(*np.diff([g.x, g.y], axis=k + 1)).min() for g in mb0.grids for k in (0, 1)]
    assert min(worst) < 0.5 * min(np.hypot(*np.diff([g.x, g.y], axis=k + 1)).min() for g in mb.grids for k in (0, 1))
