"""Untangling across interfaces (meshcore.orthogonal.untangle): a non-convex cell at a cut's end
on the shore, which the per-block repair (borders fixed) cannot mend, is made convex by moving
interface nodes; grids without bad cells are returned untouched; and generated lakes whose
grids kept such a cell come out without folded or non-convex cells."""

from __future__ import annotations

import numpy as np
import pytest

from meshcore import testing
from meshcore.layout import auto_layout
from meshcore.multiblock import initial_grids
from meshcore.orthogonal.driver import _assemble
from meshcore.orthogonal.levels import coarsen_topology
from meshcore.orthogonal.untangle import bad_cells, untangle


def _node_arrays(topo, grids):
    X, Y = _assemble(grids, topo.node_map)
    return X, Y, topo.node_map.cells.astype(np.int64)


def _spoilt_cut_end():
    """A Y junction's coarse layout grids with a cut's first interface node turned about the cut's
    shore end until a cell at that end is non-convex and stays so after the per-block repair;
    returns (topology, layout grids, those grids repaired, end node, moved node)."""
    from meshcore.lakegrid import _repair_folds

    lay = auto_layout(testing.y_junction(), target_cells=1500, multiple=4)
    topo = coarsen_topology(lay.topology(), 2)
    base = initial_grids(topo)
    m = topo.node_map
    X, Y, cells = _node_arrays(topo, base)
    assert not len(bad_cells(X, Y, cells))
    cnt = np.bincount(cells.reshape(-1), minlength=m.n_nodes)
    ends = np.flatnonzero(m.boundary & (cnt >= 3))
    assert len(ends)
    for end in ends:
        nbr = {int(v) for c in cells[(cells == end).any(axis=1)] for v in c}
        inner = [v for v in nbr if m.shared[v] and not m.boundary[v]]
        for v in inner:
            for turn in np.linspace(0.2, 2.8, 14):
                for sign in (1.0, -1.0):
                    c, s = np.cos(sign * turn), np.sin(sign * turn)
                    dx, dy = X[v] - X[end], Y[v] - Y[end]
                    X2, Y2 = X.copy(), Y.copy()
                    X2[v], Y2[v] = X[end] + c * dx - s * dy, Y[end] + s * dx + c * dy
                    bad = bad_cells(X2, Y2, cells)
                    # only cells at the end may go bad (a clean case of the fault)
                    if not len(bad) or not all(end in cells[b] for b in bad):
                        continue
                    grids = [g.replaced(x=X2[ids], y=Y2[ids]) for g, ids in zip(base, m.ids, strict=True)]
                    repaired, _ = _repair_folds(grids)  # borders fixed: the interface node stays
                    if len(bad_cells(*_node_arrays(topo, repaired))):
                        return topo, base, repaired, int(end), int(v)
    pytest.fail("no cut end of the Y could be spoilt")


def test_a_cut_end_cell_the_block_repair_cannot_mend_is_made_convex():
    topo, layout, repaired, end, _v = _spoilt_cut_end()
    for lay in (layout, None):  # with the layout's lines, and by node moves alone
        out, moved = untangle(topo, repaired, layout=lay)
        X, Y, cells = _node_arrays(topo, out)
        assert moved > 0
        assert not len(bad_cells(X, Y, cells))
        X0, Y0, _ = _node_arrays(topo, repaired)
        assert X[end] == X0[end] and Y[end] == Y0[end]  # the shore node stays
        m = topo.node_map
        assert np.array_equal(X[m.boundary], X0[m.boundary]) and np.array_equal(Y[m.boundary], Y0[m.boundary])
        for g, ids in zip(out, m.ids, strict=True):  # interface nodes stay shared
            assert np.array_equal(g.x, X[ids])


def test_a_grid_without_bad_cells_is_returned_as_it_is():
    lay = auto_layout(testing.y_junction(), target_cells=1500, multiple=4)
    topo = coarsen_topology(lay.topology(), 2)
    grids = initial_grids(topo)
    assert not len(bad_cells(*_node_arrays(topo, grids)))
    out, moved = untangle(topo, grids)
    assert moved == 0
    assert all(a is b for a, b in zip(out, grids, strict=True))


@pytest.mark.slow
@pytest.mark.parametrize(
    "make",
    [
        # each kept one non-convex cell at a cut's end on the shore before untangling
        lambda: testing.channel_network(7007, n_branches=8),
        lambda: testing.channel_network(7010, n_branches=5),
        lambda: testing.lake_with_islands(7305, n_islands=6, lobes=4),
    ],
)
def test_lakes_whose_cut_ends_folded_have_no_bad_cells(make):
    from meshcore.lakegrid import mesh_outline
    from meshcore.quality import lake_metrics

    poly = make()
    mb = mesh_outline(poly, target_cells=15000)
    m = lake_metrics(mb, polygon=poly)
    assert m.values("folded").sum() == 0
    assert mb.info.converged
    assert mb.interface_mismatch() == 0.0


@pytest.mark.parametrize("seed", range(4))
def test_node_moves_stay_in_the_water_on_a_scrambled_grid(seed):
    """Free nodes thrown about by two edge lengths fold most cells; where no candidate position
    mends a node's cells, the best one may not be a far one.  Scored over the cells' own mean
    area, a node taken out of its star made huge slivers that scored better, and round after
    round of moves flung nodes ever further (headlands(745600) at 15 000 cells: a block 686 611
    long in a lake 20 across)."""
    lay = auto_layout(testing.y_junction(), target_cells=1500, multiple=4)
    topo = coarsen_topology(lay.topology(), 2)
    grids = initial_grids(topo)
    m = topo.node_map
    X, Y, cells = _node_arrays(topo, grids)
    free = ~m.boundary
    edge = float(np.median(np.hypot(X[cells[:, 1]] - X[cells[:, 0]], Y[cells[:, 1]] - Y[cells[:, 0]])))
    rng = np.random.default_rng(seed)
    X2, Y2 = X.copy(), Y.copy()
    X2[free] += rng.normal(0, 2 * edge, free.sum())
    Y2[free] += rng.normal(0, 2 * edge, free.sum())
    assert len(bad_cells(X2, Y2, cells)) > len(cells) // 4
    spoilt = [g.replaced(x=X2[ids], y=Y2[ids]) for g, ids in zip(grids, m.ids, strict=True)]
    out, moved = untangle(topo, spoilt)
    assert moved > 0
    X3, Y3, _ = _node_arrays(topo, out)
    lo = np.minimum([X.min(), Y.min()], [X2.min(), Y2.min()]) - 2 * edge
    hi = np.maximum([X.max(), Y.max()], [X2.max(), Y2.max()]) + 2 * edge
    pts = np.column_stack([X3, Y3])
    assert np.all(pts >= lo) and np.all(pts <= hi)
    assert len(bad_cells(X3, Y3, cells)) < len(bad_cells(X2, Y2, cells))
