"""Sharp land tips and rough notches on the shore.

* A block side that passes a sharp tip of land (a peninsula's or the gap between two lobes'
  pointed end) whose own grid line points at the tip: the shore node must go a cell or more out,
  past the nodes inwards of it, and neither the node alone nor its grid line carried along can
  keep the cells convex (``channel_network(263005)``: the grid's edge 1.0 cells from the tip).
  :func:`meshcore.orthogonal.levels.fit_bends` then moves a patch of the block's interior with
  it and, where even that leaves a cell non-convex, lets the fold-free repair move the rest.
* A block corner on a notch of a rough shore (the water turning beyond 180° there) keeps its
  one cell non-convex through every level: no free node can mend it.
  :func:`meshcore.orthogonal.untangle.untangle` given the shore rings slides it along the shore
  (``mesh_outline(..., slide_ends=True)``; off by default).
"""

from __future__ import annotations

import numpy as np
import pytest

from meshcore import StructuredGrid, testing  # noqa: F401  (testing: used by eval)
from meshcore.lakegrid import mesh_outline
from meshcore.orthogonal.driver import _assemble
from meshcore.orthogonal.levels import fit_bends
from meshcore.orthogonal.shore import project_to_rings
from meshcore.orthogonal.untangle import bad_cells, untangle
from meshcore.quality import lake_metrics
from meshcore.quality.lake import block_metrics
from tests.meshcore.test_shore_bends import _one_block, _ring


def _tip_block(lean: float, tall: float):
    """A block of 15 × 8 cells (0.25 wide) over [0, 4] × [0, 2] and a shore ring along its bottom
    with a wedge of land from (1.6, 0) to (2.4, 0) whose tip is at ``(2 + lean, tall)``; the block's
    bottom nodes at x = 1.75 and 2.25 sit on the wedge's sides and their edge cuts the tip off; the
    rows inwards of the bottom are squeezed to a hundredth of a cell, as a solve leaves them along a
    side that passes such a tip."""
    tip = (2.0 + lean, tall)
    xs = np.r_[np.linspace(0.0, 1.75, 8), np.linspace(2.25, 4.0, 8)]
    ys = np.r_[0.0, 0.0025, 0.005, np.linspace(0.25, 2.0, 8)]
    shore = np.interp(xs, [0.0, 1.6, tip[0], 2.4, 4.0], [0.0, 0.0, tip[1], 0.0, 0.0])
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    Y = shore[:, None] * (1.0 - Y / 2.0) + Y
    rings = _ring([(0, 0), (1.6, 0), tip, (2.4, 0), (4, 0), (4, 2), (0, 2)])
    return X, Y, rings, tip


def _fits_onto_the_tip(topo, g, rings, tip, h: float) -> None:
    """:func:`fit_bends` on block ``g`` (cells ``h`` wide) puts a side node within a quarter cell of
    ``tip``, folds no cell and leaves every shore node on the shore."""
    cells = topo.node_map.cells
    (out,), moved = fit_bends([g], topo, rings, 0.25 * h)
    assert moved >= 1
    bx, by = out.x[:, 0], out.y[:, 0]
    assert np.hypot(bx - tip[0], by - tip[1]).min() <= 0.25 * h  # a node at the tip
    assert not len(bad_cells(*_assemble([out], topo.node_map), cells))
    _, _, off = project_to_rings(rings, np.c_[bx, by])
    assert off.max() < 1e-9  # every shore node still on the shore


@pytest.mark.parametrize("lean", [-0.1, 0.0, 0.08])
@pytest.mark.parametrize("tall", [0.4, 0.5])
def test_a_side_node_goes_onto_a_sharp_tip_its_grid_line_points_at(lean, tall):
    X, Y, rings, tip = _tip_block(lean, tall)
    topo, g = _one_block(X, Y)
    assert not len(bad_cells(*_assemble([g], topo.node_map), topo.node_map.cells))
    h = 0.25
    assert np.hypot(X[:, 0] - tip[0], Y[:, 0] - tip[1]).min() > 0.7 * h
    _fits_onto_the_tip(topo, g, rings, tip, h)


@pytest.mark.parametrize("tall", [0.8, 1.0])
def test_a_side_node_goes_onto_a_tip_beyond_squeezed_rows_with_a_larger_patch(tall):
    # a sharp wedge of land (0.4 wide, 0.8–1.0 tall) in the middle of a block side of cells 0.125
    # wide, its tip 2–2.6 cells beyond the edge that cuts it off, and four rows squeezed to 0.002
    # along the side: the patch of radius 8 and its repair leave a cell folded, so the node stayed
    # where it was (main: 2.06 and 2.55 cells from the tip); a patch of radius 12 puts it there
    # (``channel_network(158204, …, roughness=0.15)``'s rough network at 15 000 cells: 0.61 cells)
    h = 0.125
    tip = (2.0, tall)
    xs = np.r_[0.0, np.arange(h / 2, 4.0, h), 4.0]
    ys = np.r_[0.0, 0.002 * np.arange(1, 5), np.linspace(0.25, 2.0, 8)]
    shore = np.interp(xs, [0.0, 1.8, tip[0], 2.2, 4.0], [0.0, 0.0, tip[1], 0.0, 0.0])
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    Y = shore[:, None] * (1.0 - Y / 2.0) + Y
    rings = _ring([(0, 0), (1.8, 0), tip, (2.2, 0), (4, 0), (4, 2), (0, 2)])
    topo, g = _one_block(X, Y)
    assert np.hypot(X[:, 0] - tip[0], Y[:, 0] - tip[1]).min() > 2 * h
    _fits_onto_the_tip(topo, g, rings, tip, h)


def test_a_block_corner_on_a_notch_slides_along_the_shore_until_its_cell_is_convex():
    # the corner node sits on the tip of a tooth of land in the block's corner: the water turns
    # beyond 180° there and its one cell, between its neighbours (0.5, 0) and (0, 0.25), is
    # non-convex; no free node can change that
    X, Y = np.meshgrid(np.linspace(0.0, 4.0, 9), np.linspace(0.0, 1.0, 5), indexing="ij")
    X[0, 0], Y[0, 0] = 0.2, 0.2
    topo, g = _one_block(X, Y)
    rings = _ring([(0, 1), (0, 0.15), (0.2, 0.2), (0.15, 0), (4, 0), (4, 1)])
    cells = topo.node_map.cells
    assert len(bad_cells(*_assemble([g], topo.node_map), cells)) == 1
    (kept,), _ = untangle(topo, [g])  # shore nodes stay without the rings
    assert len(bad_cells(*_assemble([kept], topo.node_map), cells)) == 1
    (out,), moved = untangle(topo, [g], rings=rings)
    assert moved >= 1
    assert not len(bad_cells(*_assemble([out], topo.node_map), cells))
    _, _, off = project_to_rings(rings, np.c_[[out.x[0, 0]], [out.y[0, 0]]])
    assert off[0] < 1e-9  # still on the shore
    np.testing.assert_array_equal(out.x[1:], X[1:])  # nothing else moved
    np.testing.assert_array_equal(out.y[1:], Y[1:])


@pytest.mark.slow
@pytest.mark.parametrize(
    "expr",
    [
        "testing.channel_network(263005, n_branches=8)",  # a tip 1.02 cells outside the grid before
        "testing.channel_network(158204, n_branches=4, width=(1.0, 3.0), roughness=0.15)",  # 0.72
    ],
)
def test_generated_networks_keep_their_tips_and_fold_no_cell(expr):
    # channel networks (a rough shore in one) of the fresh sweeps at 15 000 cells: every shore
    # point within half a cell of the grid's shore, the tips included, and no folded cell
    poly = eval(expr)
    mb = mesh_outline(poly, target_cells=15000)
    assert sum(int(block_metrics(g).folded.sum()) for g in mb.grids) == 0
    assert lake_metrics(mb, polygon=poly).coverage.hausdorff_cells <= 0.5


@pytest.mark.slow
@pytest.mark.parametrize(
    "expr",
    [
        "testing.channel_network(158200, n_branches=4, width=(1.0, 3.0), roughness=0.15)",
        "testing.channel_network(263202, n_branches=4, width=(1.0, 3.0), roughness=0.15)",
    ],
)
def test_rough_networks_with_sliding_ends_fold_no_cell(expr):
    # one folded cell each at a block corner on a notch without the option (it is off by default:
    # see mesh_layout's slide_ends)
    mb = mesh_outline(eval(expr), target_cells=15000, slide_ends=True)
    assert sum(int(block_metrics(g).folded.sum()) for g in mb.grids) == 0
