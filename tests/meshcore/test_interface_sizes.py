"""Cell sizes across block interfaces (issue 12: cross-interface area ratio ≤ 2).

The integer cell counts decide the spacing on both sides of every cut line before any
smoothing: two chains in a row along a block side, and the two blocks across a shared
chain, should not differ by more than a small factor where the shape allows it.
"""

from __future__ import annotations

import numpy as np
import pytest

import meshcore.multiblock.counts as counts
from meshcore import testing
from meshcore.layout import auto_layout
from meshcore.multiblock.counts import solve_counts

# Two blocks as at a Y junction's star: block B's bottom (chain 0, 17 cells long) is part of
# block A's left side, after a shore chain (4) of 24.6 cells; B's top (1) is 29 long, so B's
# bottom must carry as many cells as a side 1.7 times longer.
#   chains: 0 shared, 1 B top, 2 B left, 3 B right, 4 A's shore part of its left side,
#           5 A bottom, 6 A right, 7 A top
TARGETS = [17.0, 29.0, 24.0, 24.0, 24.6, 17.0, 24.6, 29.0]
SIDES = [([0], [3], [1], [2]), ([5], [6], [7], [4, 0])]


def _along(n: np.ndarray) -> float:
    """Spacing ratio of the two chains in a row on A's left side."""
    d4, d0 = n[4] / TARGETS[4], n[0] / TARGETS[0]
    return max(d4 / d0, d0 / d4)


def test_counts_keep_the_spacing_along_a_side_continuous(monkeypatch):
    n = solve_counts(TARGETS, SIDES)
    assert n[0] == n[1] and n[2] == n[3] and n[5] == n[7] and n[4] + n[0] == n[6]  # still a valid solution
    assert _along(n) <= counts.JUMP * 1.05
    # without the jump terms the same program puts 2-3 times more cells on chain 0 than on 4
    monkeypatch.setattr(counts, "JUMP_WEIGHT", 0.0)
    assert _along(solve_counts(TARGETS, SIDES)) > 2.0


def _border_jump(lay) -> float:
    """Largest ratio of two consecutive node spacings along any block border of the layout."""
    worst = 1.0
    for b in lay.topology().blocks:
        for side in ("bottom", "right", "top", "left"):
            e = np.hypot(*np.diff(np.asarray(getattr(b.borders, side)), axis=0).T)
            if len(e) > 1:
                worst = max(worst, float(np.max(np.maximum(e[1:] / e[:-1], e[:-1] / e[1:]))))
    return worst


@pytest.mark.parametrize("cell_size", [0.05, 0.085, 0.12])
@pytest.mark.parametrize("angle0", [90.0, 17.0])
def test_y_junction_borders_have_no_spacing_jump(cell_size, angle0):
    """The star's blocks each have a reflex corner of the shore inside one side, where the cut
    from the centre meets it: the counts of the two chains there agree within the limit (they
    differed 5-10 times, 28 cells on the cut against 4 on the shore beside it)."""
    lay = auto_layout(testing.y_junction(angle0=angle0), cell_size=cell_size)
    assert _border_jump(lay) <= 2.0


def test_shore_nodes_do_not_crowd_into_an_obtuse_block_corner():
    """A block whose corner on the shore is obtuse (127° here): sliding each shore node to the
    foot of the perpendicular from its inward neighbour crowds them into the corner, each edge
    1.5-1.7 times the next (the polar fan that makes a 20-40x jump across a cut line ending
    there).  The slide stops where a node's two shore edges differ by the smoothness limit."""
    from meshcore.algebraic import tfi
    from meshcore.boundary import Borders
    from meshcore.multiblock.topology import Block, MultiBlockTopology
    from meshcore.orthogonal import orthogonalize
    from meshcore.quality import lake_metrics

    def line(a, b, n):
        return np.asarray(a) + np.linspace(0, 1, n + 1)[:, None] * (np.asarray(b) - np.asarray(a))

    sw, se, ne, nw = (0.0, 0.0), (5.0, 0.0), (5.0, 2.0), (-1.5, 2.0)
    bd = Borders(bottom=line(sw, se, 20), right=line(se, ne, 8), top=line(nw, ne, 20), left=line(sw, nw, 8))
    topo = MultiBlockTopology((Block("a", bd),), (), check_geometry=False)
    corners = np.array([sw, se, ne, nw])
    ring = np.vstack([line(corners[k], corners[(k + 1) % 4], 100)[:-1] for k in range(4)])
    lo = 1.2
    res = orthogonalize(topo, [tfi(bd)], [ring], max_sweeps=3000, smooth=0.02, omega=1.8, size_ratio=(lo, 2.0))
    x, y = res.grids[0].x, res.grids[0].y
    for px, py in ((x[:, 0], y[:, 0]), (x[0], y[0]), (x[:, -1], y[:, -1]), (x[-1], y[-1])):
        e = np.hypot(np.diff(px), np.diff(py))
        assert np.max(np.maximum(e[1:] / e[:-1], e[:-1] / e[1:])) <= lo * 1.05
    m = lake_metrics(res.grids[0])
    assert m.values("folded").sum() == 0
    assert m.share("deviation", 3.0) >= 0.9  # orthogonal but at the obtuse corner


def _cut_end_ratios(mb) -> np.ndarray:
    """At every shore node where three or more cells meet (a cut line ending on the shore beside
    a block that passes it with a side): the ratio of its two shore edges."""
    m = mb.topology.node_map
    X, Y = np.zeros(m.n_nodes), np.zeros(m.n_nodes)
    for g, ids in zip(mb.grids, m.ids, strict=True):
        X[ids], Y[ids] = g.x, g.y
    cnt = np.bincount(m.cells.ravel(), minlength=m.n_nodes)
    e0, e1 = m.cells.reshape(-1), np.roll(m.cells, -1, axis=1).reshape(-1)
    key, once = np.unique(np.minimum(e0, e1) * m.n_nodes + np.maximum(e0, e1), return_counts=True)
    a, b = np.divmod(key[once == 1], m.n_nodes)  # shore edges
    length = np.hypot(X[a] - X[b], Y[a] - Y[b])
    out = []
    for p in np.flatnonzero(m.boundary & (cnt >= 3)):
        e = length[(a == p) | (b == p)]
        if len(e) == 2:
            out.append(e.max() / e.min())
    return np.array(out)


@pytest.mark.parametrize(
    "make, cells, options, ends",
    [
        # a Y without a star (only nodes where four blocks meet): a side arm's mouth at its crotch
        (lambda: testing.y_junction(), 3000, {"regular": True}, 2),
        (lambda: testing.y_junction(angle0=17.0), 3000, {"regular": True}, 2),
        (lambda: testing.channel_network(2, n_branches=6), 8000, {}, 3),
    ],
)
def test_cells_alike_across_a_cut_that_ends_beside_a_side(make, cells, options, ends):
    """Where a cut line ends on the shore and one block passes the end with a side (a Y's
    crotch, a side arm's mouth), the shore edges on its two sides are the first cells of the two
    blocks.  Free to slide, the corner block's shore nodes crowded into the corner: those two edges
    differed 5-8 times (Y junction) and the cells across the cut up to 2.3-2.8 times in area; the
    shore sweep keeps the edge next to the end within the smoothness limit of the edge beyond.
    (A Y's star has no such end since its spokes are straight: both blocks at a crotch have a
    corner there; the Ys here are laid out without a star.)"""
    from meshcore.lakegrid import mesh_outline
    from meshcore.quality import lake_metrics

    poly = make()
    mb = mesh_outline(poly, target_cells=cells, **options)
    r = _cut_end_ratios(mb)
    assert len(r) >= ends
    assert r.max() <= 2.5
    m = lake_metrics(mb, polygon=poly)
    assert m.max("interface_ratio") <= 2.0
    assert m.values("folded").sum() == 0


@pytest.mark.parametrize(
    "make",
    [
        lambda: testing.y_junction(angle0=20.0),
        lambda: testing.y_junction(arm=4.0, width=1.5, angle0=70.0),
        lambda: testing.y_junction(width=0.7, angle0=-40.0),
        lambda: testing.y_junction(arm=5.0, width=1.2, angle0=100.0),
    ],
)
def test_a_y_junction_star_keeps_cells_alike_across_its_spokes(make, monkeypatch):
    """A Y's star: straight spokes from the centre to the three crotches and one to the middle of
    each arm's opening, six blocks round the centre.  With spokes curved to arrive along the
    continued shore (one block's corner at a crotch 60°, its neighbour's side straight there) the
    solves straightened them and opened that corner into a fan: cells 1.8-2.9 times apart across
    the spoke at 4000 cells; now 1.00-1.04.  (The layout choice's coarse ratio guard as it was when
    this was written: with ``DEFAULT_RATIO`` one of these Ys takes another scale's 6-block layout,
    99.97 % within 3°, interface ratio 1.25 — not a star.)"""
    import meshcore.layout as layout_pkg
    from meshcore.lakegrid import mesh_outline
    from meshcore.quality import lake_metrics

    monkeypatch.setattr(layout_pkg, "DEFAULT_RATIO", 0.0)
    poly = make()
    mb = mesh_outline(poly, target_cells=4000)
    m = lake_metrics(mb, polygon=poly)
    assert len(mb.grids) == 9  # three arms, six blocks round the centre
    assert m.max("interface_ratio") <= 1.5
    assert m.values("folded").sum() == 0
