"""Shore nodes onto the bends their edges cut across (:func:`meshcore.orthogonal.levels.fit_bends`,
:func:`~meshcore.orthogonal.levels.fit_ends`).

The shore sweep keeps a shore the grid follows but does not reach for a bend its edges already
span: a coarse edge across an island's curve, a cut end the layout put a few tenths of a cell short
of a tip (``channel_network(499202, roughness=0.15)``: the tip 0.65 cells outside the grid;
``round_lake(499400, kind="blob")``: a 4-cell island side 10 cells long, 0.91 cells).
"""

from __future__ import annotations

import numpy as np
import pytest

from meshcore import StructuredGrid, testing  # noqa: F401  (testing: used by eval)
from meshcore.boundary import Borders
from meshcore.lakegrid import _shore_rings, mesh_outline
from meshcore.layout import auto_layout
from meshcore.multiblock import initial_grids
from meshcore.multiblock.topology import Block, MultiBlockTopology
from meshcore.orthogonal.driver import SHORE_GAP, _assemble
from meshcore.orthogonal.levels import coarsen_topology, fit_bends, fit_ends
from meshcore.orthogonal.shore import arc_lengths, project_to_rings, ring_point
from meshcore.orthogonal.untangle import bad_cells
from meshcore.quality import lake_metrics


def _one_block(x, y):
    bd = Borders(
        bottom=np.c_[x[:, 0], y[:, 0]], right=np.c_[x[-1], y[-1]], top=np.c_[x[:, -1], y[:, -1]], left=np.c_[x[0], y[0]]
    )
    return MultiBlockTopology((Block("a", bd),), (), check_geometry=False), StructuredGrid(x, y)


def _ring(points, step=0.01):
    """A closed ring through ``points``, densified as the lake pipeline does."""
    from shapely.geometry import Polygon

    return _shore_rings(Polygon(points), step)


def shore_gaps(topology, grids, rings) -> np.ndarray:
    """Per shore edge: how far the shore between its two nodes (the short way along their ring)
    strays from the edge."""
    m = topology.node_map
    X, Y = _assemble(grids, m)
    cells = m.cells
    u, v = cells.reshape(-1), np.roll(cells, -1, axis=1).reshape(-1)
    key, c = np.unique(np.minimum(u, v) * m.n_nodes + np.maximum(u, v), return_counts=True)
    a, b = np.divmod(key[c == 1], m.n_nodes)
    ra, sa, _ = project_to_rings(rings, np.c_[X[a], Y[a]])
    rb, sb, _ = project_to_rings(rings, np.c_[X[b], Y[b]])
    out = []
    for k in range(len(a)):
        if ra[k] != rb[k]:
            continue
        total = arc_lengths(rings[ra[k]])[-1]
        d = (sb[k] - sa[k]) % total
        d = d - total if d > total / 2 else d
        p = ring_point(rings[ra[k]], sa[k] + d * np.linspace(0.0, 1.0, 81))
        e0, e1 = np.array([X[a[k]], Y[a[k]]]), np.array([X[b[k]], Y[b[k]]])
        t = np.clip((p - e0) @ (e1 - e0) / max((e1 - e0) @ (e1 - e0), 1e-300), 0.0, 1.0)
        out.append(np.hypot(*(p - e0 - t[:, None] * (e1 - e0)).T).max())
    return np.asarray(out)


def test_a_node_beside_a_bay_goes_to_its_far_end():
    # bottom nodes at x = 0, 0.5, ..., 4 (cell 0.5); the shore dips into a bay, apex (1.5, -0.3),
    # between x = 1 and 2; the node there sits on the bay's near side, so its edge to x = 2
    # cuts 0.2 (0.4 cells) across the bay's far end
    xs, ys = np.linspace(0.0, 4.0, 9), np.linspace(0.0, 1.0, 5)
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    X[3, 0], Y[3, 0] = 1.25, -0.15
    topo, g = _one_block(X, Y)
    rings = _ring([(0, 0), (1, 0), (1.5, -0.3), (2, 0), (4, 0), (4, 1), (0, 1)])
    limit = SHORE_GAP * 0.5
    assert shore_gaps(topo, [g], rings).max() > limit
    (out,), moved = fit_bends([g], topo, rings, limit)
    assert moved == 1
    assert (out.x[3, 0], out.y[3, 0]) == pytest.approx((1.5, -0.3))
    assert shore_gaps(topo, [out], rings).max() < 1e-9
    assert not len(bad_cells(*_assemble([out], topo.node_map), topo.node_map.cells))


def test_a_block_corner_short_of_a_tip_goes_onto_it():
    # the corner node (0, 0) is a fixed node (one cell); the shore goes from it out to a tip at
    # (0.1, -0.2) and back to (0.5, 0): the corner's edge along the bottom cuts the tip off
    X, Y = np.meshgrid(np.linspace(0.0, 4.0, 9), np.linspace(0.0, 1.0, 5), indexing="ij")
    topo, g = _one_block(X, Y)
    rings = _ring([(0, 0), (0.1, -0.2), (0.5, 0), (4, 0), (4, 1), (0, 1)])
    limit = SHORE_GAP * 0.5
    assert shore_gaps(topo, [g], rings).max() == pytest.approx(0.2, rel=0.02)
    (out,), moved = fit_ends([g], topo, rings, limit)
    assert moved == 1
    # on the shore near the tip (where both its edges stray least: the corner (0, 0) behind it counts)
    assert np.hypot(out.x[0, 0] - 0.1, out.y[0, 0] + 0.2) < 0.1
    assert shore_gaps(topo, [out], rings).max() < 0.5 * limit
    assert not len(bad_cells(*_assemble([out], topo.node_map), topo.node_map.cells))


def _bad_corners(topo, grids) -> int:
    m = topo.node_map
    X, Y = _assemble(grids, m)
    p = m.cells
    q, r = np.roll(p, -1, axis=1), np.roll(p, 1, axis=1)
    return int((((X[q] - X[p]) * (Y[r] - Y[p]) - (Y[q] - Y[p]) * (X[r] - X[p])) <= 0).sum())


def test_a_block_corner_is_not_put_on_a_land_tip_its_cell_cannot_go_round():
    # Saimaa's block b114 on the coarsest level (cells of 4, here 1 fine cell = 1): its corner
    # (0, 0) has both sides on the shore and its cell is already non-convex there (the corner's
    # edge to (2.44, 1.39) cuts across a land tip at (0.92, 2.13)); the tip is the ring vertex
    # where the corner's edges leave the shore least, but on it the corner's angle in its one
    # cell is reflex: three shore nodes, no free node can make that cell convex on any level and
    # the grid went out folded.  The move may not add a non-convex corner.
    X = np.array([[1.34, 3.4, 6.39], [-0.08, 1.07, 2.44], [-1.2, -0.53, 0.0]])
    Y = np.array([[5.34, 2.84, 1.47], [2.49, 1.95, 1.39], [-0.25, -0.52, 0.0]])
    topo, g = _one_block(X, Y)
    tip = [
        (0.17, 0.39),
        (0.27, 0.8),
        (0.38, 1.33),
        (0.46, 1.69),
        (0.62, 1.99),
        (0.92, 2.13),
        (1.31, 2.06),
        (1.89, 1.75),
    ]
    shore = [(1.34, 5.34), (-0.08, 2.49), (-1.2, -0.25), (-0.53, -0.52), (0.0, 0.0), *tip, (2.44, 1.39), (6.39, 1.47)]
    rings = _ring([*shore, (3.4, 2.84)], step=0.25)
    before = _bad_corners(topo, [g])
    assert before == 1
    (out,), _ = fit_ends([g], topo, rings, SHORE_GAP * 4)
    assert _bad_corners(topo, [out]) <= before
    assert np.hypot(out.x[2, 2] - 0.92, out.y[2, 2] - 2.13) > 0.5  # not on the tip


def test_nothing_moves_where_the_grid_follows_the_shore():
    X, Y = np.meshgrid(np.linspace(0.0, 4.0, 9), np.linspace(0.0, 1.0, 5), indexing="ij")
    topo, g = _one_block(X, Y)
    rings = _ring([(0, 0), (4, 0), (4, 1), (0, 1)])
    for fit in (fit_bends, fit_ends):
        (out,), moved = fit([g], topo, rings, SHORE_GAP * 0.5)
        assert moved == 0
        np.testing.assert_array_equal(out.x, X)
        np.testing.assert_array_equal(out.y, Y)


ROUND = ("blob", "arms", "ring", "disc")
SHAPES = [
    *(f"testing.channel_network({s}, n_branches=4, width=(1.0, 3.0), roughness=0.15)" for s in range(200, 204)),
    *(f"testing.lake_with_islands({s}, n_islands={4 + s % 4}, lobes={4 + s % 3})" for s in range(300, 306)),
    *(f"testing.round_lake({400 + k}, kind={kind!r}, n_islands=4)" for k, kind in enumerate(ROUND)),
    "testing.jagged(testing.channel_network(501, n_branches=4, width=(1.0, 2.5)), 0.08, seed=501)",
]


@pytest.mark.parametrize("expr", SHAPES)
def test_fitting_the_coarse_start_grid_only_brings_its_shore_edges_closer(expr):
    # on the coarsest level of generated lakes (the start grid, before any orthogonal sweep): no
    # shore edge strays further than before, the worst by at least a tenth less where it was
    # beyond the limit, and no cell becomes non-convex
    lay = auto_layout(eval(expr), target_cells=4000, multiple=4)
    top = coarsen_topology(lay.topology(), 4)
    grids = initial_grids(top)
    rings = _shore_rings(lay.polygon, lay.cell_size / 4)
    limit = SHORE_GAP * 4 * lay.cell_size
    cells = top.node_map.cells
    bad0 = set(bad_cells(*_assemble(grids, top.node_map), cells).tolist())
    g0 = shore_gaps(top, grids, rings)
    fitted, _ = fit_ends(grids, top, rings, limit)
    fitted, _ = fit_bends(fitted, top, rings, limit)
    g1 = shore_gaps(top, fitted, rings)
    assert set(bad_cells(*_assemble(fitted, top.node_map), cells).tolist()) <= bad0
    assert g1.max() <= g0.max() + 1e-12
    if g0.max() > 2 * limit:
        assert g1.max() < 0.9 * g0.max() or g1.max() <= 2 * limit


@pytest.mark.slow
@pytest.mark.parametrize(
    "expr",
    [
        "testing.round_lake(499400, kind='blob', n_islands=5)",  # a 4-cell island side: 0.91 before
        "testing.lake_with_islands(499305, n_islands=6, lobes=4)",  # a cut end short of a tip: 0.79
        "testing.channel_network(499202, n_branches=4, width=(1.0, 3.0), roughness=0.15)",  # 0.65
    ],
)
def test_generated_lakes_whose_tips_were_cut_off_follow_the_shore_within_half_a_cell(expr):
    poly = eval(expr)
    mb = mesh_outline(poly, target_cells=15000)
    assert lake_metrics(mb, polygon=poly).coverage.hausdorff_cells <= 0.5
