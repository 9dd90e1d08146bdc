"""No block that fans: a piece whose four sides span far less water than it holds is split.

The greedy split stops when no single cut lowers the corner cost; on generated lakes it left a
round lobe behind a narrow neck and the strip of water beside it as one block 4 cells across
and 184 along (`headlands(791603)`: 43 folded cells), a needle island run round by one block
side (`small_islands(760001)`: the island lost, 37–76 folded cells) and a basin whose corners
bunched by a thin peninsula (`peninsulas 745801`: 429 folded cells).  :mod:`meshcore.layout.fans`
splits such pieces with one step of look-ahead.  Measured here independently of that module:
the bulge ``R`` (area over the product of the mean lengths of opposite sides) and the ratio of
opposite sides.
"""

from __future__ import annotations

import math
import tempfile
from pathlib import Path

import numpy as np
import pytest
from shapely.geometry import Polygon

from meshcore import testing
from meshcore.layout import auto_layout

CASES = {
    "lobe behind a neck": "testing.headlands(791603, n=9)",
    "needle island near the shore": "testing.small_islands(760001, n_islands=10)",
    "basin by a thin peninsula": "testing.small_islands(745801, n_islands=4, peninsulas=4, widths=(0.5, 3.0))",
    "headlands 779600": "testing.headlands(779600, n=6)",
    # session 32: the east lobe as one block from a small island's side, sides 6.0× and 8.1× apart
    "lobe fanning from a small island": "testing.round_lake(955400, kind='blob', n_islands=5)",
}


def _sides(ring: np.ndarray, corners) -> list[float]:
    e = np.hypot(*(np.roll(ring, -1, axis=0) - ring).T)
    s = np.concatenate([[0.0], np.cumsum(e)])
    total = s[-1]
    c = sorted(corners)
    return [(s[c[(k + 1) % 4]] - s[c[k]]) % total for k in range(4)]


def _fan(ring: np.ndarray, corners) -> tuple[float, float, float]:
    """The bulge (area / mean of one pair × mean of the other), the smaller of the two ratios of
    opposite sides and their product."""
    L = _sides(ring, corners)
    bulge = Polygon(ring).area / (0.25 * (L[0] + L[2]) * (L[1] + L[3]))
    a, b = max(L[0], L[2]) / min(L[0], L[2]), max(L[1], L[3]) / min(L[1], L[3])
    return bulge, min(a, b), a * b


@pytest.mark.parametrize("name", CASES)
def test_no_block_fans_from_two_short_sides(name):
    poly = eval(CASES[name])
    lay = auto_layout(poly, target_cells=15000, multiple=4)
    for pc in lay.pieces:
        bulge, pairs, product = _fan(np.asarray(pc.ring), pc.corners)
        # main: bulge 5.3 (a block 4 × 184 cells round a lobe), 6.0 (round a needle island),
        # 3.1; 1.65 with both pairs of sides 11-12× apart (a basin's corners by a peninsula);
        # 1.24 with pairs 6.0× and 8.1× apart (product 49: the lobe from a small island)
        assert bulge < 3.0, (name, pc.ring.mean(axis=0), bulge)
        assert bulge < 1.2 or pairs < 8.0, (name, pc.ring.mean(axis=0), bulge, pairs)
        assert bulge < 1.2 or product < 32.0, (name, pc.ring.mean(axis=0), bulge, product)


def test_the_needle_island_keeps_its_blocks():
    poly = testing.small_islands(760001, n_islands=10)
    lay = auto_layout(poly, target_cells=15000, multiple=4)
    h = lay.cell_size
    # every island the layout keeps is bounded by blocks whose cells are no longer than the
    # water allows: no piece runs round half an island with cells ten times the size
    for pc in lay.pieces:
        cells = next(b.cells for b in lay.blocks if b.name == pc.name)
        assert Polygon(pc.ring).area / (cells[0] * cells[1] * h * h) < 2.5, pc.ring.mean(axis=0)


@pytest.mark.slow
@pytest.mark.parametrize("name", list(CASES)[:3])
def test_these_lakes_have_no_folded_cells_and_keep_their_islands(name):
    from meshcore.cellsize import default_cell_size
    from meshcore.lakegrid import mesh_outline
    from meshcore.layout.polygon import water_polygon
    from meshcore.quality import lake_metrics

    poly = eval(CASES[name])
    mb = mesh_outline(poly, target_cells=15000)
    h = default_cell_size(water_polygon(poly)[0].area, 15000)
    m = lake_metrics(mb, polygon=poly, cell_size=h)
    s = m.summary()
    assert s["folded_cells"] == 0  # main: 43, 76, 429
    assert m.coverage.islands_lost == ()
    assert s["hausdorff_cells"] < 1.0  # main: 7.3, 17.5, ...
    assert math.isfinite(s["pct_nodes_within_3deg"]) and s["pct_nodes_within_3deg"] >= 90.0


def _pocket_ring(depth: float) -> tuple[np.ndarray, list[int]]:
    """A basin 20 × 12 cells whose west side is a peninsula 1 cell thick reaching 16 cells east
    from (0, 8), with a pocket of water under it ``depth`` cells deep; corners at the peninsula's
    root, the basin's east corners and its north-west corner: the side from the root runs east
    round the tip, back west into the pocket and east again."""
    west = 16.0 - depth
    ring = np.array(
        [(0, 8), (16, 8), (16.6, 7.5), (16, 7), (west, 7), (west, 0), (20, 0), (20, 12), (0, 12)],
        float,
    )
    return ring, [0, 6, 7, 8]


def test_a_side_that_runs_back_round_a_tip_fans():
    """The measure of :func:`meshcore.layout.fans._wraps` (independent of the layout): a block
    whose side runs back round a peninsula (held-out GSHHG lake at 10 000 cells: one block of
    84 × 24 cells round a peninsula's tip, 86 % of nodes within 3°; split, 97 %)."""
    from meshcore.layout.fans import _wraps

    sigma = 1.5  # one cell = 1
    ring, corners = _pocket_ring(depth=15.0)
    assert _wraps(ring, corners, sigma)
    # a shallow pocket (back 3 cells against a 21.5-cell side) does not
    ring, corners = _pocket_ring(depth=3.0)
    assert not _wraps(ring, corners, sigma)
    # a channel that winds (a U round a peninsula, both banks alike) does not either
    t = np.linspace(0.0, np.pi, 40)
    outer = np.column_stack([10 + 6 * np.sin(t), 6 * np.cos(t)])
    inner = np.column_stack([10 + 2 * np.sin(t), 2 * np.cos(t)])[::-1]
    u = np.vstack([[(0, 6)], outer, [(0, -6), (0, -2)], inner, [(0, 2)]])
    u = u if Polygon(u).exterior.is_ccw else u[::-1]
    ids = [int(np.argmin(np.hypot(*(u - p).T))) for p in ((0, 6), (0, -6), (0, -2), (0, 2))]
    assert not _wraps(u, ids, sigma)
    # nor a spiral channel as one block (the generated spiral's layout)
    lay = auto_layout(testing.spiral(turns=2.5, width=0.7, gap=1.2), target_cells=4000, multiple=4)
    assert not any(_wraps(p.ring, p.corners, 1.5 * lay.cell_size) for p in lay.pieces)


def _runs_back(ring: np.ndarray, corners) -> float:
    """The most any side runs back along the line between its corners beyond what its opposite
    side does, over that line's length."""
    c = sorted(corners)
    n = len(ring)
    sides = [ring[[(c[k] + j) % n for j in range((c[(k + 1) % 4] - c[k]) % n + 1)]] for k in range(4)]
    worst = 0.0
    for k in range(4):
        chord = sides[k][-1] - sides[k][0]
        u = chord / np.linalg.norm(chord)
        own, opp = sides[k] @ u, sides[(k + 2) % 4][::-1] @ u
        back = max(own[: i + 1].max() - own[i] for i in range(len(own)))
        back_opp = max(opp[: i + 1].max() - opp[i] for i in range(len(opp)))
        worst = max(worst, (back - back_opp) / np.linalg.norm(chord))
    return worst


WRAPPED = "testing.headlands(1030600, n=6)"  # fresh_sweep --more base 1030000, 15 000 cells


def test_no_block_runs_round_a_peninsula():
    lay = auto_layout(eval(WRAPPED), target_cells=15000, multiple=4)
    # main: one block ran from a headland's root round its tip and back (0.8 of its side's span)
    assert max(_runs_back(np.asarray(pc.ring), pc.corners) for pc in lay.pieces) < 0.5


@pytest.mark.slow
def test_the_peninsula_block_no_longer_folds():
    from meshcore.lakegrid import mesh_outline
    from meshcore.quality import lake_metrics

    poly = eval(WRAPPED)
    s = lake_metrics(mesh_outline(poly, target_cells=15000), polygon=poly).summary()
    assert s["folded_cells"] == 0  # main: 77, its grid across the headland (shore 18 cells off)
    assert s["hausdorff_cells"] < 1.0


def test_regular_layouts_split_a_block_round_a_peninsulas_tip_too():
    """A regular layout (`.ddb`, `--regular`) kept a block whose lines wrap a peninsula's tip
    (GSHHG lake 181060, 10 000 cells: 79.6 % of nodes within 3°, a cell of aspect ratio 1 264);
    split as default layouts split it, 97.1 %."""
    from meshcore.cli.lakefile import local_frame
    from meshcore.io import read_points
    from meshcore.layout.fans import _wraps
    from meshcore.layout.polygon import water_from_points, water_polygon
    from tests.conftest import ROOT

    ps, _ = local_frame(read_points(ROOT / "tests" / "data" / "gshhg_g181060.geojson"), "auto")
    outer, islands = water_from_points(ps)
    poly, _ = water_polygon(outer, holes=islands)
    lay = auto_layout(poly, target_cells=10000, multiple=4, regular=True)
    assert not any(_wraps(p.ring, p.corners, 1.5 * lay.cell_size) for p in lay.pieces)


def _g183546():
    from meshcore.cli.lakefile import local_frame
    from meshcore.io import read_points
    from meshcore.layout.polygon import water_from_points, water_polygon
    from tests.conftest import ROOT

    ps, _ = local_frame(read_points(ROOT / "tests" / "data" / "gshhg_g183546.geojson"), "auto")
    outer, islands = water_from_points(ps)
    return water_polygon(outer, holes=islands)[0]


def test_regular_layouts_can_split_a_bulging_block():
    """A regular layout kept a round lake with a notch as one block whose corners bunched at the
    notch and at a blunt end (GSHHG lake 183546, 10 000 cells: bulge 3.6, 0.37 × the cells asked);
    the default layout splits it (a star).  ``LayoutOptions(bulges=True)`` splits it by the splits
    regular layouts allow (a T here): no piece bulges, and Delft3D DD couples the blocks."""
    from meshcore.layout import LayoutOptions
    from tests.meshcore.test_layout_frames import _written_and_read_back

    poly = _g183546()
    plain = auto_layout(poly, target_cells=10000, multiple=4, regular=True)
    assert len(plain.blocks) == 1 and _fan(np.asarray(plain.pieces[0].ring), plain.pieces[0].corners)[0] >= 3.0
    lay = auto_layout(poly, target_cells=10000, multiple=4, regular=True, options=LayoutOptions(bulges=True))
    assert len(lay.blocks) > 1
    for pc in lay.pieces:
        bulge, _, _ = _fan(np.asarray(pc.ring), pc.corners)
        assert bulge < 3.0, (pc.ring.mean(axis=0), bulge)
    cells = sum(ni * nj for ni, nj in (b.cells for b in lay.blocks))
    assert 0.5 * 10000 <= cells <= 2 * 10000
    with tempfile.TemporaryDirectory() as d:  # the .ddb reads back, M lines coupled to M lines
        _written_and_read_back(lay, Path(d) / "lake.ddb")


@pytest.mark.parametrize("mode", ["regular", "single"])
def test_the_regular_grid_of_a_bulging_lake_is_a_model_grid(mode):
    """What a user of ``meshcore mesh --regular`` (or ``--single``, one index space) gets on that
    lake: the layout choice reads the draw with the bulging block split (``layout.BULGE_DRAW``; a
    single layout reads that draw alone) and keeps it (before: one block, 0.37 × the cells asked,
    89.4 % of nodes within 3°, the shore 0.56 cells off)."""
    from meshcore.lakegrid import mesh_outline
    from meshcore.quality import lake_metrics

    poly = _g183546()
    mb = mesh_outline(poly, target_cells=10000, **{mode: True})
    m = lake_metrics(mb, polygon=poly, cell_size=math.sqrt(poly.area / 10000)).summary()
    assert len(mb.grids) > 1 and m["folded_cells"] == 0
    assert 0.5 <= m["cells"] / 10000 <= 2
    assert m["pct_nodes_within_3deg"] >= 90 and m["hausdorff_cells"] <= 0.5


def test_a_wedge_whose_sides_differ_by_much_tapers():
    """A wedge (a trapezoid 0.3 across at one end and 12 at the other) bulges little (0.7) but its
    cells differ in area by about the product of its ratios of opposite sides (40): it tapers, and
    fans where tapering pieces count (``LayoutOptions(tapers=True)``, session 48: held-out g180615's
    block from a neck into a basin); a rectangle does not taper."""
    from meshcore.layout import fans
    from meshcore.layout.split import corners_of

    top = np.c_[np.linspace(5.85, 6.15, 4), np.full(4, 6.0)]
    bottom = np.c_[np.linspace(0.0, 12.0, 41), np.zeros(41)]
    left = np.c_[np.linspace(5.85, 0.0, 21)[1:-1], np.linspace(6.0, 0.0, 21)[1:-1]]
    right = np.c_[np.linspace(12.0, 6.15, 21)[1:-1], np.linspace(0.0, 6.0, 21)[1:-1]]
    ring = np.vstack([bottom, right, top[::-1], left])  # counter-clockwise
    corners, _ = corners_of(ring, 0.45)
    bulge, _, product = _fan(ring, corners)
    assert bulge < 1.2 and product >= 32.0, (bulge, product)
    assert fans.tapers(ring, 0.45) and fans.fans(ring, 0.45, tapered=True)
    assert not fans.fans(ring, 0.45)  # a bulge under 1.2 does not fan by itself
    rect = np.array([(0, 0), (12, 0), (12, 6), (0, 6)], float)
    assert not fans.tapers(rect, 0.45) and not fans.fans(rect, 0.45, tapered=True)
