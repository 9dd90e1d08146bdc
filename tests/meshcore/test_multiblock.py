"""Multiblock grids: topology, validation, smooth/frozen solves, outline → blocks, case files."""

from __future__ import annotations

import itertools
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import meshcore
from meshcore.boundary import Borders
from meshcore.errors import CaseFileError, TopologyError
from meshcore.multiblock import (
    Block,
    Interface,
    MultiBlockTopology,
    Side,
    _kernels,
    _reference,
    parse_side,
    solve_multiblock,
)
from meshcore.multiblock.outline import from_outline, project_lonlat

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "resources" / "examples"
TIGHT = 1e-12


# ------------------------------------------------------------------ helpers
def curved_rectangle(ni: int = 24, nj: int = 12):
    """Algebraic start grid of [0, 2] × [0, f(x)] with a curved top (non-trivial solution)."""
    xs = np.linspace(0.0, 2.0, ni + 1)
    t = np.linspace(0.0, 1.0, nj + 1)
    # top: y = 1 + 0.35 sin(πx/2)·x/2, nodes uniform in arc length (so x is not linear in ξ)
    xf = np.linspace(0.0, 2.0, 4001)
    yf = 1.0 + 0.35 * np.sin(0.5 * np.pi * xf) * xf / 2.0
    s = np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(xf), np.diff(yf)))])
    u = np.linspace(0.0, s[-1], ni + 1)
    xt, yt = np.interp(u, s, xf), np.interp(u, s, yf)
    X = xs[:, None] + (xt - xs)[:, None] * t[None, :]
    Y = yt[:, None] * t[None, :]
    return X, Y


def borders(X, Y) -> Borders:
    return Borders(
        bottom=np.column_stack([X[:, 0], Y[:, 0]]),
        right=np.column_stack([X[-1], Y[-1]]),
        top=np.column_stack([X[:, -1], Y[:, -1]]),
        left=np.column_stack([X[0], Y[0]]),
    )


def block(name, X, Y) -> Block:
    return Block(name, borders(X, Y))


@pytest.fixture(scope="module")
def rect():
    X, Y = curved_rectangle()
    ref = meshcore.solve(meshcore.StructuredGrid(X, Y), method="sor", tolerance=TIGHT)
    assert ref.converged
    return X, Y, ref


def two_blocks(X, Y, cut: int):
    a, b = block("a", X[: cut + 1], Y[: cut + 1]), block("b", X[cut:], Y[cut:])
    return MultiBlockTopology((a, b), (Interface(Side("a", "right"), Side("b", "left")),))


def four_blocks(X, Y, ci: int, cj: int):
    bl = (
        block("sw", X[: ci + 1, : cj + 1], Y[: ci + 1, : cj + 1]),
        block("se", X[ci:, : cj + 1], Y[ci:, : cj + 1]),
        block("nw", X[: ci + 1, cj:], Y[: ci + 1, cj:]),
        block("ne", X[ci:, cj:], Y[ci:, cj:]),
    )
    itf = (
        Interface(parse_side("sw.right"), parse_side("se.left")),
        Interface(parse_side("nw.right"), parse_side("ne.left")),
        Interface(parse_side("sw.top"), parse_side("nw.bottom")),
        Interface(parse_side("se.top"), parse_side("ne.bottom")),
    )
    return MultiBlockTopology(bl, itf)


def assert_glued(mb) -> None:
    """Interface nodes are bit-identical in both adjoining blocks."""
    assert mb.interfaces
    for itf in mb.interfaces:
        pa = mb[itf.a.block].border(itf.a.border)[itf.a.start : itf.a.stop + 1]
        pb = mb[itf.b.block].border(itf.b.border)[itf.b.start : itf.b.stop + 1]
        assert np.array_equal(pa, pb[::-1] if itf.reversed else pb), itf.label
    assert mb.interface_mismatch() == 0.0


# ------------------------------------------------ equivalence with one block
@pytest.mark.parametrize(
    ("start", "engine"),
    [("algebraic", "blocks"), ("frozen", "blocks"), ("algebraic", "table"), ("algebraic", "multigrid")],
)
def test_two_blocks_smooth_equals_single_block(rect, start, engine):
    X, Y, ref = rect
    mb = solve_multiblock(two_blocks(X, Y, 10), mode="smooth", tolerance=TIGHT, start=start, engine=engine)
    assert mb.converged
    size = ref.size
    d = max(
        np.abs(mb["a"].x - ref.x[:11]).max(),
        np.abs(mb["a"].y - ref.y[:11]).max(),
        np.abs(mb["b"].x - ref.x[10:]).max(),
        np.abs(mb["b"].y - ref.y[10:]).max(),
    )
    assert d <= 1e-6 * size
    assert_glued(mb)
    # the interface really moved away from its algebraic start
    assert np.hypot(mb["a"].x[-1] - X[10], mb["a"].y[-1] - Y[10]).max() > 1e-3 * size


@pytest.mark.parametrize("engine", ["blocks", "table", "multigrid"])
def test_four_blocks_smooth_equals_single_block(rect, engine):
    X, Y, ref = rect
    topo = four_blocks(X, Y, 14, 5)
    (corner,) = topo.node_map.corners  # the node where four blocks meet
    assert corner.valence == 4 and corner.free and len(corner.blocks) == 4
    mb = solve_multiblock(topo, mode="smooth", tolerance=TIGHT, engine=engine)
    assert mb.converged
    d = 0.0
    for name, sl in (("sw", np.s_[:15, :6]), ("se", np.s_[14:, :6]), ("nw", np.s_[:15, 5:]), ("ne", np.s_[14:, 5:])):
        d = max(d, np.abs(mb[name].x - ref.x[sl]).max(), np.abs(mb[name].y - ref.y[sl]).max())
    assert d <= 1e-6 * ref.size
    assert_glued(mb)


def test_frozen_mode_keeps_interfaces_and_differs_from_smooth(rect):
    X, Y, ref = rect
    topo = four_blocks(X, Y, 14, 5)
    fz = solve_multiblock(topo, mode="frozen", tolerance=TIGHT)
    assert fz.converged
    assert_glued(fz)
    # the interface nodes are the re-sampled (start) ones
    assert np.array_equal(fz["sw"].x[-1], X[14, :6])
    assert np.array_equal(fz["sw"].y[:, -1], Y[:15, 5])
    sm = solve_multiblock(topo, mode="smooth", tolerance=TIGHT)
    moved = np.hypot(sm["sw"].x[-1] - fz["sw"].x[-1], sm["sw"].y[-1] - fz["sw"].y[-1])
    assert moved.max() > 1e-4 * ref.size


def test_single_block_topology_matches_block_solver(rect):
    X, Y, ref = rect
    topo = MultiBlockTopology((block("only", X, Y),))
    mb = solve_multiblock(topo, mode="smooth", tolerance=TIGHT, start="algebraic")
    assert np.abs(mb["only"].x - ref.x).max() <= 1e-6 * ref.size


# ---------------------------------------------------------------- kernels
@pytest.mark.kernel
def test_table_kernel_matches_numpy_reference_and_block_kernel(rect):
    X, Y, _ = rect
    topo = four_blocks(X, Y, 14, 5)
    m = topo.node_map
    rng = np.random.default_rng(1)
    x = np.empty(m.n_nodes)
    y = np.empty(m.n_nodes)
    for g, ids in zip(meshcore.multiblock.initial_grids(topo), m.ids, strict=True):
        x[ids.ravel()], y[ids.ravel()] = g.x.ravel(), g.y.ravel()
    x += 1e-3 * rng.standard_normal(x.size) * ~m.boundary
    y += 1e-3 * rng.standard_normal(y.size) * ~m.boundary
    args = (m.nodes, m.nbr, m.irr_nodes, m.irr_ptr, m.irr_ring)
    tx, ty = _reference.jacobi_targets(x, y, *args)
    r = _kernels.table_residual(x, y, *args)
    assert r == pytest.approx(np.hypot(tx - x, ty - y).max(), rel=1e-12)
    # the same stencil as the single-block kernel on the assembled array
    from meshcore.elliptic import _kernels as bk

    sx, sy = np.zeros(X.shape), np.zeros(X.shape)
    for name, (i0, j0) in (("sw", (0, 0)), ("se", (14, 0)), ("nw", (0, 5)), ("ne", (14, 5))):
        ids = m.ids[topo.index(name)]
        sx[i0 : i0 + ids.shape[0], j0 : j0 + ids.shape[1]] = x[ids]
        sy[i0 : i0 + ids.shape[0], j0 : j0 + ids.shape[1]] = y[ids]
    e = np.zeros((0, 0))
    assert r == pytest.approx(bk.jacobi_residual(sx, sy, e, e, False), rel=1e-12)
    # one SOR sweep with omega = 1 moves only free nodes
    x0, y0 = x.copy(), y.copy()
    _kernels.table_sweep(x, y, *args, 1.0)
    assert np.array_equal(x[m.boundary], x0[m.boundary])
    assert not np.array_equal(x, x0)
    del y0


# ---------------------------------------------------- 3- and 5-block corners
def star(k: int, n: int = 8):
    """A regular 2k-gon split into k quads meeting at the centre (valence k)."""
    ang = np.pi / k
    verts = [np.array([math.cos(a), math.sin(a)]) for a in ang * np.arange(2 * k)]
    c = np.zeros(2)
    blocks, itfs = [], []
    lin = np.linspace(0.0, 1.0, n + 1)[:, None]
    for q in range(k):
        v0, v1, v2 = verts[(2 * q - 1) % (2 * k)], verts[2 * q], verts[(2 * q + 1) % (2 * k)]
        # corners: sw = centre, se = midpoint vertex v0, ne = v1, nw = v2 (CCW)
        sw, se, ne, nw = c, v0, v1, v2
        bd = Borders(
            bottom=sw + lin * (se - sw),
            right=se + lin * (ne - se),
            top=nw + lin * (ne - nw),
            left=sw + lin * (nw - sw),
        )
        blocks.append(Block(f"q{q}", bd))
        itfs.append(Interface(Side(f"q{q}", "left"), Side(f"q{(q + 1) % k}", "bottom")))
    return MultiBlockTopology(tuple(blocks), tuple(itfs))


@pytest.mark.parametrize("engine", ["blocks", "table", "multigrid"])
@pytest.mark.parametrize("k", [3, 5])
def test_irregular_corner_of_k_blocks(k, engine):
    topo = star(k)
    m = topo.node_map
    (corner,) = [c for c in m.corners if c.free]
    assert corner.valence == k and len(m.irr_nodes) == 1
    assert "Laplacian" in corner.handling
    assert "Laplacian" in topo.connectivity_report()
    # push the centre off-centre; the symmetric solution brings it back
    init = meshcore.multiblock.initial_grids(topo)
    shifted = []
    for g in init:
        x, y = np.array(g.x), np.array(g.y)
        x[1:-1, 1:-1] += 0.05
        shifted.append(meshcore.StructuredGrid(x, y))
    mb = solve_multiblock(topo, mode="smooth", tolerance=1e-11, initial=shifted, start="algebraic", engine=engine)
    assert mb.converged
    assert_glued(mb)
    centre = mb["q0"].x[0, 0], mb["q0"].y[0, 0]
    assert math.hypot(*centre) < 1e-8
    q = mb.quality()
    assert q.n_folded == 0
    # the k blocks are rotations of each other
    for j in range(1, k):
        a = 2 * np.pi * j / k
        g0, gj = mb["q0"], mb[f"q{j}"]
        rx = math.cos(a) * g0.x - math.sin(a) * g0.y
        assert np.abs(rx - gj.x).max() < 1e-8


# --------------------------------------------------------------- the lake
@pytest.fixture(scope="module")
def shasta_topology():
    from meshcore.case import case_topology, load_case

    return case_topology(load_case(EXAMPLES / "shasta-multiblock-coarse.toml"))


def test_shasta_lake_has_arms_in_blocks(shasta_topology):
    topo = shasta_topology
    assert len(topo.blocks) >= 3
    assert len(topo.interfaces) >= 2
    # a partial interface: the main basin's top border carries two arms
    parts = [i for i in topo.interfaces if "main" in (i.a.block, i.b.block)]
    assert len(parts) >= 3
    rep = topo.connectivity_report()
    for b in topo.blocks:
        assert b.name in rep


@pytest.mark.parametrize("mode", ["smooth", "frozen"])
def test_shasta_lake_quality_and_glue(shasta_topology, mode):
    mb = solve_multiblock(shasta_topology, mode=mode)
    assert mb.converged
    assert_glued(mb)
    q = mb.quality()
    assert q.n_folded == 0
    assert set(q.interfaces) == {" ↔ ".join(sorted((i.a.block, i.b.block), key=mb.names.index)) for i in mb.interfaces}
    if mode == "smooth":
        assert q.worst_interface <= 1.5 * q.worst_inside
    from meshcore.quality import quality

    given = mb.quality([quality(g) for g in mb.grids])  # the CLI's reports, not made twice
    assert given.table() == q.table() and given.blocks.keys() == q.blocks.keys()


def test_smooth_interfaces_are_smoother_than_frozen(shasta_topology):
    sm = solve_multiblock(shasta_topology, mode="smooth").quality()
    fz = solve_multiblock(shasta_topology, mode="frozen").quality()
    assert sm.worst_interface < fz.worst_interface


@pytest.mark.slow
def test_shasta_lake_fine_case():
    from meshcore.case import generate_case, load_case

    mb = generate_case(load_case(EXAMPLES / "shasta-multiblock-fine.toml"))
    assert mb.converged
    assert_glued(mb)
    q = mb.quality()
    assert q.n_folded == 0
    assert q.worst_interface <= 1.5 * q.worst_inside


def test_project_lonlat_distances():
    # 1/1000 degree of latitude ≈ 111.2 m anywhere; of longitude ≈ 111.2 m × cos(lat)
    xy, org = project_lonlat([[-122.0, 40.0], [-122.001, 40.0], [-122.0, 40.001]], origin=(-122.0, 40.0))
    assert org == (-122.0, 40.0)
    assert xy[2, 1] == pytest.approx(111.19, abs=0.01)
    assert -xy[1, 0] == pytest.approx(111.19 * math.cos(math.radians(40.0)), abs=0.01)


# -------------------------------------------------------- from an outline
def outline_case():
    xs = np.linspace(0, 2, 21)
    top = np.c_[xs[::-1], 1 + 0.2 * np.sin(np.pi * xs[::-1] / 2)]
    ring = np.vstack([np.c_[xs, 0 * xs], [[2, 0.55]], top, [[0, 0.5]]])
    cuts = [[[1, 0], [1, 1.2]], [[0, 0.5], [2, 0.55]]]
    ym = 0.525
    blocks = [
        {"name": "sw", "corners": [[0, 0], [1, 0], [1, ym], [0, 0.5]], "cells": [8, 4]},
        {"name": "se", "corners": [[1, 0], [2, 0], [2, 0.55], [1, ym]], "cells": [8, 4]},
        {"name": "nw", "corners": [[0, 0.5], [1, ym], [1, 1.2], [0, 1]], "cells": [8, 6]},
        {"name": "ne", "corners": [[1, ym], [2, 0.55], [2, 1], [1, 1.2]], "cells": [8, 6]},
    ]
    return ring, cuts, blocks


def test_from_outline_crossing_cuts_give_four_blocks():
    ring, cuts, blocks = outline_case()
    ob = from_outline(ring, cuts=cuts, blocks=blocks)
    topo = ob.topology
    assert len(ob.regions) == 4 and len(topo.interfaces) == 4
    (c,) = topo.node_map.corners
    assert c.valence == 4 and c.point == pytest.approx((1.0, 0.525))
    mb = solve_multiblock(topo)
    assert mb.converged and mb.quality().n_folded == 0
    assert_glued(mb)
    # the shore nodes stay on the outline
    from shapely.geometry import LinearRing, Point

    shore = LinearRing(ring)
    for g in mb:
        for b in ("bottom", "right", "top", "left"):
            p = g.border(b)
            d = [shore.distance(Point(q)) for q in p]
            assert min(d) < 1e-12  # every border touches the shore
    assert mb["sw"].border("bottom")[:, 1] == pytest.approx(0.0, abs=1e-15)


def test_from_outline_partial_interface_t_junction():
    # a long main block with an arm attached to the middle of its top border
    ring = np.array([[0, 0], [6, 0], [6, 1], [4, 1], [4, 3], [2, 3], [2, 1], [0, 1]], float)
    blocks = [
        {"name": "main", "corners": [0, 1, 2, 7], "cells": [12, 4]},
        {"name": "arm", "corners": [[2, 1], [4, 1], 4, 5], "cells": [4, 4]},
    ]
    ob = from_outline(ring, cuts=[[6, 3]], blocks=blocks)
    (itf,) = ob.topology.interfaces
    sides = {itf.a.block: itf.a, itf.b.block: itf.b}
    assert sides["main"].border == "top" and (sides["main"].start, sides["main"].stop) == (4, 8)
    assert sides["arm"].border == "bottom"
    mb = solve_multiblock(ob.topology)
    assert mb.converged and mb.quality().n_folded == 0
    assert_glued(mb)
    # shore parts of main's top border stay fixed; the mouth moved
    top = mb["main"].border("top")
    assert np.allclose(top[:5, 1], 1.0) and np.allclose(top[8:, 1], 1.0)
    assert np.abs(top[5:8, 1] - 1.0).max() > 1e-3


# ------------------------------------------------- malformed topologies
@pytest.fixture(scope="module")
def pair():
    X, Y = curved_rectangle(8, 4)
    return X, Y


def _err(fn) -> str:
    with pytest.raises(TopologyError) as ei:
        fn()
    return str(ei.value)


def test_error_unknown_block_and_border(pair):
    X, Y = pair
    a, b = block("a", X[:5], Y[:5]), block("b", X[4:], Y[4:])
    msg = _err(lambda: MultiBlockTopology((a, b), (Interface(Side("a", "right"), Side("c", "left")),)))
    assert "'c'" in msg and "a.right" in msg
    msg = _err(lambda: MultiBlockTopology((a, b), (Interface(Side("a", "east"), Side("b", "left")),)))
    assert "a.east" in msg and "bottom" in msg


def test_error_counts_disagree(pair):
    X, Y = pair
    Xb, Yb = curved_rectangle(8, 4)
    a = block("a", X[:5], Y[:5])
    b2 = Block("b", borders(*[np.column_stack([v[4:, 0]] * 3) for v in (Xb, Yb)]))
    msg = _err(lambda: MultiBlockTopology((a, b2), (Interface(Side("a", "right"), Side("b", "left")),)))
    assert "a.right" in msg and "b.left" in msg and "4 cells" in msg and "2 on b.left" in msg


def test_error_nodes_do_not_coincide(pair):
    X, Y = pair
    a, b = block("a", X[:5], Y[:5]), block("b", X[4:], Y[4:])
    msg = _err(lambda: MultiBlockTopology((a, b), (Interface(Side("a", "left"), Side("b", "right")),)))
    assert "a.left" in msg and "b.right" in msg and "do not coincide" in msg


def test_error_range_outside_border(pair):
    X, Y = pair
    a, b = block("a", X[:5], Y[:5]), block("b", X[4:], Y[4:])
    msg = _err(lambda: MultiBlockTopology((a, b), (Interface(Side("a", "right", 0, 9), Side("b", "left", 0, 9)),)))
    assert "a.right[0:9]" in msg and "5 nodes" in msg


def test_error_overlapping_blocks(pair):
    X, Y = pair
    a, b = block("a", X[:6], Y[:6]), block("b", X[4:], Y[4:])
    msg = _err(lambda: MultiBlockTopology((a, b)))
    assert "'a'" in msg and "'b'" in msg and "overlap" in msg


@pytest.mark.parametrize("depth", [1e-5, 1e-3])
def test_error_sliver_overlap_of_blocks(pair, depth):
    """Two blocks overlapping in a sliver ``depth`` of a cell wide (2.5e-6 and 2.5e-4 of the
    smaller block, the threshold is 1e-6): the check that skips the pairwise intersections
    when Σ areas − union area is below the threshold still reports it."""
    X, Y = pair
    Xb = X[4:].copy()
    Xb[0] -= depth * (X[5, 0] - X[4, 0])  # b's left border pushed into a
    a, b = block("a", X[:5], Y[:5]), block("b", Xb, Y[4:])
    msg = _err(lambda: MultiBlockTopology((a, b)))
    assert "'a'" in msg and "'b'" in msg and "overlap" in msg


def test_error_undeclared_shared_border(pair):
    X, Y = pair
    a, b = block("a", X[:5], Y[:5]), block("b", X[4:], Y[4:])
    msg = _err(lambda: MultiBlockTopology((a, b)))
    assert "'a'" in msg and "'b'" in msg and "touch" in msg


def test_error_gap_hole_named():
    # two L-shaped arrangements leaving a hole: blocks around it are named
    def quad(sw, se, ne, nw):  # axis-parallel, cells of size 1
        sw, se, ne, nw = (np.asarray(v, dtype=float) for v in (sw, se, ne, nw))
        ni, nj = round(se[0] - sw[0]), round(nw[1] - sw[1])
        li, lj = np.linspace(0, 1, ni + 1)[:, None], np.linspace(0, 1, nj + 1)[:, None]
        return Borders(
            bottom=sw + li * (se - sw), right=se + lj * (ne - se), top=nw + li * (ne - nw), left=sw + lj * (nw - sw)
        )

    bl = (
        Block("a", quad([0, 0], [2, 0], [2, 1], [0, 1])),
        Block("b", quad([2, 0], [4, 0], [4, 1], [2, 1])),
        Block("c", quad([0, 1], [1, 1], [1, 3], [0, 3])),
        Block("d", quad([3, 1], [4, 1], [4, 3], [3, 3])),
        Block("e", quad([0, 3], [2, 3], [2, 4], [0, 4])),
        Block("f", quad([2, 3], [4, 3], [4, 4], [2, 4])),
    )
    S = Side
    itf = (
        Interface(S("a", "right"), S("b", "left")),
        Interface(S("e", "right"), S("f", "left")),
        Interface(S("a", "top", 0, 1), S("c", "bottom")),
        Interface(S("b", "top", 1, 2), S("d", "bottom")),
        Interface(S("c", "top"), S("e", "bottom", 0, 1)),
        Interface(S("d", "top"), S("f", "bottom", 1, 2)),
    )
    msg = _err(lambda: MultiBlockTopology(bl, itf))
    assert "gap" in msg and "hole" in msg
    assert all(f"'{n}'" in msg for n in "abcdef")


def test_error_border_parts_overlap(pair):
    X, Y = pair
    a, b = block("a", X[:5], Y[:5]), block("b", X[4:], Y[4:])
    itf = (
        Interface(Side("a", "right", 0, 3), Side("b", "left", 0, 3)),
        Interface(Side("a", "right", 2, 4), Side("b", "left", 2, 4)),
    )
    msg = _err(lambda: MultiBlockTopology((a, b), itf))
    assert "a.right" in msg and "overlap" in msg


def test_outline_error_cut_not_ending_on_outline():
    ring, cuts, blocks = outline_case()
    cuts = [[[1, 0.3], [1, 1.2]], cuts[1]]
    msg = _err(lambda: from_outline(ring, cuts=cuts, blocks=blocks))
    assert "cut 1" in msg and "first point" in msg


def test_outline_error_block_not_four_sided():
    ring, cuts, blocks = outline_case()
    blocks[0] = {**blocks[0], "corners": [[0, 0], [1, 0], [2, 0.55], [0, 0.5]]}
    msg = _err(lambda: from_outline(ring, cuts=cuts, blocks=blocks))
    assert "'sw'" in msg and "four" in msg


def test_outline_error_corners_clockwise():
    ring, cuts, blocks = outline_case()
    blocks[0] = {**blocks[0], "corners": blocks[0]["corners"][::-1]}
    msg = _err(lambda: from_outline(ring, cuts=cuts, blocks=blocks))
    assert "'sw'" in msg and "counter-clockwise" in msg


def test_outline_error_gap_region_without_block():
    ring, cuts, blocks = outline_case()
    msg = _err(lambda: from_outline(ring, cuts=cuts, blocks=blocks[:3]))
    assert "gap" in msg and "'se'" in msg and "'nw'" in msg


def test_outline_error_two_blocks_on_one_region():
    ring, cuts, blocks = outline_case()
    blocks[3] = {**blocks[2], "name": "other"}
    msg = _err(lambda: from_outline(ring, cuts=cuts, blocks=blocks))
    assert "'nw'" in msg and "'other'" in msg and "overlap" in msg


def test_outline_error_counts_disagree_across_interface():
    ring, cuts, blocks = outline_case()
    blocks[1] = {**blocks[1], "cells": [8, 5]}
    msg = _err(lambda: from_outline(ring, cuts=cuts, blocks=blocks))
    assert "cell counts disagree" in msg
    assert ("'sw'" in msg or "'se'" in msg) and "shared with" in msg


def test_outline_error_cut_leaves_the_water():
    ring, cuts, blocks = outline_case()
    cuts = [[[1, 0], [1.5, -0.5], [1, 1.2]], cuts[1]]
    msg = _err(lambda: from_outline(ring, cuts=cuts, blocks=blocks))
    assert "cut 1" in msg and ("leaves" in msg or "touches" in msg)


# -------------------------------------------------------------- case files
INTERFACE_CASE = """
title = "two blocks"
[multiblock]
mode = "smooth"
[[blocks]]
name = "left"
cells = [6, 4]
[blocks.boundary]
bottom = [[0, 0], [1, 0]]
right = [[1, 0], [1, 1]]
top = [[0, 1], [1, 1]]
left = [[0, 0], [0, 1]]
[[blocks]]
name = "right"
cells = [8, 4]
[blocks.boundary]
bottom = [[1, 0], [2, 0]]
right = [[2, 0], [2.2, 1.3]]
top = [[1, 1], [2.2, 1.3]]
left = [[1, 0], [1, 1]]
[[interfaces]]
a = "left.right"
b = "right.left"
"""


def test_case_with_interfaces(tmp_path):
    from meshcore.case import generate_case, load_case

    p = tmp_path / "two.toml"
    p.write_text(INTERFACE_CASE)
    mb = generate_case(load_case(p))
    assert mb.names == ("left", "right") and mb.mode == "smooth" and mb.converged
    assert_glued(mb)
    assert mb["left"].cells == (6, 4) and mb["right"].cells == (8, 4)


@pytest.mark.parametrize(
    ("edit", "key"),
    [
        (("[multiblock]\nmode", "[multiblock]\nspeed = 1\nmode"), "speed"),
        (('a = "left.right"', 'a = "left.right"\nflip = true'), "flip"),
    ],
)
def test_case_unknown_keys(tmp_path, edit, key):
    from meshcore.case import generate_case, load_case

    p = tmp_path / "bad.toml"
    p.write_text(INTERFACE_CASE.replace(*edit))
    with pytest.raises(CaseFileError) as ei:
        generate_case(load_case(p))
    assert repr(key) in str(ei.value) and "valid keys" in str(ei.value)


def test_case_outline_unknown_key_and_mode(tmp_path):
    from meshcore.case import generate_case, load_case

    text = (EXAMPLES / "shasta-multiblock-coarse.toml").read_text()
    (tmp_path / "lakes").mkdir()
    for f in (ROOT / "resources" / "lakes").glob("*.csv"):
        (tmp_path / "lakes" / f.name).write_text(f.read_text())
    d = tmp_path / "ex"
    d.mkdir()
    (d / "a.toml").write_text(text.replace('crs = "utm"', 'crs = "utm"\ncolour = 1'))
    with pytest.raises(CaseFileError, match=r"'colour'.*valid keys"):
        generate_case(load_case(d / "a.toml"))
    (d / "b.toml").write_text(text.replace('mode = "smooth"', 'mode = "wobbly"'))
    with pytest.raises(CaseFileError, match="mode must be one of smooth, frozen"):
        generate_case(load_case(d / "b.toml"))


def test_cli_generate_multiblock_case(tmp_path):
    out = tmp_path / "shasta.xyz"
    r = subprocess.run(
        [sys.executable, "-m", "meshcore", "generate", str(EXAMPLES / "shasta-multiblock-coarse.toml"), "-o", str(out)],
        capture_output=True,
        text=True,
        cwd=ROOT,
        timeout=300,
    )
    assert r.returncode == 0, r.stderr
    assert "Interfaces" in r.stdout and "main.top" in r.stdout
    from meshcore.io import read_grid

    blocks = read_grid(out)
    assert len(blocks) == 7
    from meshcore.case import generate_case, load_case

    mb = generate_case(load_case(EXAMPLES / "shasta-multiblock-coarse.toml"))
    ox, oy = mb.frame.origin  # files hold world (UTM) coordinates
    for g, h in zip(mb, blocks, strict=True):
        assert np.abs(g.x + ox - h.x).max() < 1e-6 and np.abs(g.y + oy - h.y).max() < 1e-6


def test_vtm_and_plot3d_via_io_read_by_vtk(tmp_path, rect):
    vtk = pytest.importorskip("vtkmodules.vtkIOXML")
    from meshcore.io import read_grid, write
    from meshcore.multiblock.export import write_report

    X, Y, _ = rect
    mb = solve_multiblock(four_blocks(X, Y, 14, 5))
    p = write(tmp_path / "rect.vtm", mb)
    reader = vtk.vtkXMLMultiBlockDataReader()
    reader.SetFileName(str(p))
    reader.Update()
    data = reader.GetOutput()
    assert data.GetNumberOfBlocks() == 4
    for k, g in enumerate(mb):
        blk = data.GetBlock(k)
        assert data.GetMetaData(k).Get(data.NAME()) == mb.names[k]
        assert blk.GetNumberOfPoints() == g.n_nodes
        dims = [0, 0, 0]
        blk.GetDimensions(dims)
        assert tuple(dims[:2]) == g.shape
        pt = blk.GetPoint(g.shape[0] + 1)  # node (1, 1): VTK order, i fastest
        assert pt[:2] == pytest.approx((g.x[1, 1], g.y[1, 1]), abs=1e-12)
    back = read_grid(write(tmp_path / "rect.xyz", mb))
    assert len(back) == 4
    assert all(np.array_equal(g.x, h.x) for g, h in zip(mb, back, strict=True))
    rep = write_report(tmp_path / "rect.txt", mb).read_text(encoding="utf-8")
    assert "sw.right nodes 0…5" in rep and "max adjacent-cell size ratio across" in rep


def test_lonlat_outline_projections_agree(tmp_path):
    """utm (pyproj) and lonlat (equirectangular) give nearly the same lake, in metres."""
    from meshcore.case import case_frame, load_case, outline_points

    text = (EXAMPLES / "shasta-multiblock-coarse.toml").read_text()
    (tmp_path / "lakes").mkdir()
    for f in (ROOT / "resources" / "lakes").glob("*.csv"):
        (tmp_path / "lakes" / f.name).write_text(f.read_text())
    (tmp_path / "ex").mkdir()
    (tmp_path / "ex" / "utm.toml").write_text(text)
    (tmp_path / "ex" / "eq.toml").write_text(text.replace('crs = "utm"', 'crs = "lonlat"'))
    cu, ce = load_case(tmp_path / "ex" / "utm.toml"), load_case(tmp_path / "ex" / "eq.toml")
    fr = case_frame(cu)
    assert fr.crs == "EPSG:32610" and fr.source_crs == "EPSG:4326"
    pu, pe = outline_points(cu), outline_points(ce)
    # same shape up to a rigid motion; lengths agree to < 0.5 % (equirectangular E–W
    # distortion over ±0.1° of latitude ≈ 0.2 %, UTM scale 0.7° off the central meridian)
    lu, le = np.hypot(*(pu - pu[0]).T), np.hypot(*(pe - pe[0]).T)
    assert np.abs(lu - le).max() < 5e-3 * le.max()
    # the grid nodes on the shore map back to the lon/lat shoreline
    from meshcore.case import generate_case

    mb = generate_case(cu)
    lon, lat = mb.frame.to_lonlat(mb["main"].x[:, 0], mb["main"].y[:, 0])
    shore = np.loadtxt(ROOT / "resources" / "lakes" / "shasta_lake.csv", delimiter=",", skiprows=1)
    from shapely.geometry import LinearRing, Point

    ring = LinearRing(shore)
    assert max(ring.distance(Point(a, b)) for a, b in zip(lon, lat, strict=True)) < 1e-7


def test_cli_generate_vtm_with_crs(tmp_path):
    vtk = pytest.importorskip("vtkmodules.vtkIOXML")
    out = tmp_path / "lake.vtm"
    r = subprocess.run(
        [
            sys.executable,
            "-m",
            "meshcore",
            "generate",
            str(EXAMPLES / "shasta-multiblock-coarse.toml"),
            "-o",
            str(out),
            "-q",
        ],
        capture_output=True,
        text=True,
        cwd=ROOT,
        timeout=300,
    )
    assert r.returncode == 0, r.stderr
    reader = vtk.vtkXMLMultiBlockDataReader()
    reader.SetFileName(str(out))
    reader.Update()
    data = reader.GetOutput()
    assert data.GetNumberOfBlocks() == 7
    # world coordinates (UTM 10N metres) are written, not the local ones
    x0 = data.GetBlock(0).GetPoint(0)[0]
    assert 5e5 < x0 < 6.5e5


def test_connectivity_case_round_trip(tmp_path, shasta_topology):
    """The derived blocks + interfaces saved as an explicit case give the same grid."""
    from meshcore.case import generate_case, load_case, save_case, topology_case

    case = topology_case(shasta_topology, title="Shasta, explicit connectivity")
    p = save_case(case, tmp_path / "explicit.toml")
    text = p.read_text(encoding="utf-8")
    assert text.count("[[interfaces]]") == len(shasta_topology.interfaces)
    assert 'a = "main.top[' in text or 'b = "main.top[' in text
    again = generate_case(load_case(p))
    direct = solve_multiblock(shasta_topology)
    assert again.names == direct.names
    for g, h in zip(again, direct, strict=True):
        assert np.array_equal(g.x, h.x) and np.array_equal(g.y, h.y)


def test_from_outline_cut_ending_on_another_cut():
    # a vertical cut across the lake, and a second cut from the west shore that ends on it
    ring = np.array([[0, 0], [4, 0], [4, 2], [0, 2]], float)
    cuts = [[[2, 0], [2, 2]], [[0, 1.0], [2.0 + 1e-4, 1.1]]]  # ends (within snap) on cut 0
    blocks = [
        {"name": "sw", "corners": [[0, 0], [2, 0], [2, 1.1], [0, 1]], "cells": [6, 3]},
        {"name": "nw", "corners": [[0, 1], [2, 1.1], [2, 2], [0, 2]], "cells": [6, 3]},
        {"name": "east", "corners": [[2, 0], [4, 0], [4, 2], [2, 2]], "cells": [6, 6]},
    ]
    ob = from_outline(ring, cuts=cuts, blocks=blocks, snap=1e-3)
    topo = ob.topology
    # the snapped end is exactly on cut 0 and is a node of all three blocks
    (t,) = [c for c in topo.node_map.corners if len(c.blocks) == 3]
    assert t.point == (2.0, 1.1) and t.valence == 4 and t.free
    east_parts = sorted((s.start, s.stop) for i in topo.interfaces for s in (i.a, i.b) if s.block == "east")
    assert east_parts == [(0, 3), (3, 6)]  # east.left is split at the T point
    mb = solve_multiblock(topo)
    assert mb.converged and mb.quality().n_folded == 0
    assert_glued(mb)
    # the T node moved along with the solution (it is solved like an interior node)
    assert abs(mb["east"].y[0, 3] - 1.1) > 1e-3


def test_confluence_case_three_blocks_meet_at_the_centre():
    from meshcore.case import generate_case, load_case

    case = load_case(EXAMPLES / "confluence-multiblock.toml")
    mb = generate_case(case)
    assert mb.converged and mb.quality().n_folded == 0
    assert_glued(mb)
    corners = [c for c in mb.topology.node_map.corners if c.free and c.valence == 3]
    assert len(corners) == 1 and corners[0].point == (0.0, 0.0)
    # the centre stays at the centre, and the arms are rotations of each other by 120°: the
    # discrete solution's symmetry, checked on a grid solved well below the default tolerance
    # (at 1e-6 the cycle that meets the stopping rule may leave the centre ~1.5e-6 × the domain
    # size off, 2.6e-5 here: about the error the stopping rule allows on the lake layouts)
    mb = generate_case(case, config=case.solver.replaced(tolerance=1e-8))
    g = mb["junction-ne"]
    assert math.hypot(g.x[0, 0], g.y[0, 0]) < 1e-5
    a = -2.0 * np.pi / 3.0
    n, se = mb["north"], mb["southeast"]
    assert np.abs(math.cos(a) * n.x - math.sin(a) * n.y - se.x).max() < 1e-4


def test_multigrid_hierarchy_and_convergence(rect):
    """FAS over the blocks: coarse levels keep every block and interface, odd counts coarsen
    too; the defect drops ≥ 5× per cycle; the grid is the SOR grid."""
    from meshcore.multiblock.hierarchy import levels

    X, Y, ref = rect
    lv = levels(four_blocks(X, Y, 12, 6))
    assert [lv_.shapes for lv_ in lv][:2] == [[(13, 7), (13, 7), (13, 7), (13, 7)], [(7, 4), (7, 4), (7, 4), (7, 4)]]
    odd = levels(four_blocks(X, Y, 14, 5))  # 14 and 5 cells: one or two fine cells per coarse cell
    assert len(odd) >= 2 and odd[1].shapes[0] == (8, 4)
    X2, Y2 = curved_rectangle(64, 32)
    mb = solve_multiblock(four_blocks(X2, Y2, 32, 16), tolerance=1e-10, engine="multigrid")
    assert mb.converged and mb.info.method.startswith("smooth/multigrid(")
    h = [v for _, v in mb.info.residual_history]
    assert len(h) <= 12
    assert all(b <= a / 5.0 for a, b in itertools.pairwise(h[1:]))
    # the same discrete solution as SOR
    sor = solve_multiblock(four_blocks(X2, Y2, 32, 16), tolerance=1e-10, engine="blocks")
    for g, k in zip(mb, sor, strict=True):
        assert np.abs(g.x - k.x).max() < 1e-7 * ref.size
    # serial = parallel (the smooth iteration is serial whatever ``threads`` says)
    two = solve_multiblock(four_blocks(X2, Y2, 32, 16), tolerance=1e-10, engine="multigrid", threads=2)
    assert all(np.array_equal(g.x, k.x) and np.array_equal(g.y, k.y) for g, k in zip(mb, two, strict=True))


def test_coarse_levels_keep_the_blocks_glued():
    """Every coarse level of a lake-like structure (odd counts, T-junctions, a 5-block corner)
    is a valid multiblock structure: shared nodes are kept by all their blocks or by none."""
    from meshcore.multiblock.hierarchy import levels

    lvs = levels(star(5, 9))
    assert len(lvs) >= 2
    for fine, coarse in itertools.pairwise(lvs):
        kept = np.zeros(fine.n, dtype=int)
        for g, (si, sj) in zip(fine.ids, coarse.sel, strict=True):
            np.add.at(kept, g[np.ix_(si, sj)].ravel(), 1)
        touched = kept > 0
        assert np.array_equal(kept[touched], fine.mult[touched])  # all blocks of a kept node keep it
        assert np.array_equal(fine.ids[0][np.ix_(*coarse.sel[0])].ravel()[:3], coarse.inj[coarse.ids[0].ravel()[:3]])
        assert len(coarse.args[2]) == 1  # the 5-block corner stays irregular


@pytest.mark.parametrize("make", ["network", "islands"])
def test_layout_hierarchy_stops_before_levels_that_barely_coarsen(make):
    """On generated lake layouts every coarse level keeps at most MAX_KEEP (half) of the finer
    level's nodes (the last levels kept 60-80 % before: set-up without fewer cycles), and the
    multigrid still converges to the SOR grid."""
    from meshcore.layout import auto_layout
    from meshcore.multiblock.hierarchy import MAX_KEEP, levels
    from meshcore.testing import channel_network, lake_with_islands

    shape = channel_network(1, n_branches=5) if make == "network" else lake_with_islands(2)
    topo = auto_layout(shape, target_cells=4000, multiple=4).topology()
    lvs = levels(topo)
    assert len(lvs) >= 3
    assert all(co.n <= MAX_KEEP * fine.n for fine, co in itertools.pairwise(lvs))
    assert MAX_KEEP <= 0.5
    mb = solve_multiblock(topo, tolerance=1e-9, engine="multigrid")
    assert mb.converged
    sor = solve_multiblock(topo, tolerance=1e-9, engine="blocks", max_iterations=200_000)
    assert sor.converged
    for g, k in zip(mb, sor, strict=True):
        assert np.hypot(g.x - k.x, g.y - k.y).max() < 1e-6 * topo.size


def test_auto_retries_multigrid_with_one_level_fewer_before_sor(monkeypatch, rect):
    """engine="auto": a multigrid that is slow with its whole hierarchy starts over from the start
    grid with the coarsest level dropped (solver.RETRY_FEWER_LEVELS), and only then falls back
    to SOR; the cycles of both attempts are counted."""
    from meshcore.multiblock import multigrid, solver
    from meshcore.multiblock.hierarchy import levels

    X, Y = curved_rectangle(64, 32)
    topo = four_blocks(X, Y, 32, 16)
    depth = len(levels(topo))
    assert depth >= 3
    real, seen = multigrid.iterate_fas, []

    def slow_when_deep(x, y, topo_, tol, max_cycles, give_up_rate=None, lvs=None, line_omega=1.0):
        seen.append(len(lvs))
        if len(lvs) == depth:  # two cycles, then "slow"
            yield 1, 1.0
            yield 2, 0.9
            return 2, 0.9, [(0, 1.0), (1, 1.0), (2, 0.9)], "slow", depth
        return (yield from real(x, y, topo_, tol, max_cycles, give_up_rate, lvs))

    monkeypatch.setattr(multigrid, "iterate_fas", slow_when_deep)
    mb = solve_multiblock(topo, tolerance=1e-10)
    assert seen == [depth, depth - 1]
    assert mb.converged and mb.info.method == f"smooth/multigrid({depth - 1} levels)"
    h = mb.info.residual_history
    assert [i for i, _ in h] == list(range(len(h))) and mb.info.iterations == len(h) - 1 > 2
    ref = solve_multiblock(topo, tolerance=1e-10, engine="multigrid")
    for g, k in zip(mb, ref, strict=True):
        assert np.hypot(g.x - k.x, g.y - k.y).max() < 1e-7 * topo.size
    seen.clear()  # no retry for engine="multigrid", and none when disabled: SOR
    monkeypatch.setattr(solver, "RETRY_FEWER_LEVELS", 0)
    monkeypatch.setattr(solver, "RETRY_LINE_OMEGA", 1.0)
    sor = solve_multiblock(topo, tolerance=1e-10)
    assert seen == [depth] and sor.converged and sor.info.method == "smooth/blocks-sor after 2 multigrid cycles"


def test_auto_retries_with_damped_lines_before_sor(monkeypatch, rect):
    """engine="auto": when the undamped cycles are slow with the whole hierarchy and without its
    coarsest level, the multigrid starts over once more with all levels and its line sweeps damped
    (solver.RETRY_LINE_OMEGA) before SOR; that solve reaches the grid of the undamped cycles."""
    from meshcore.multiblock import multigrid, solver
    from meshcore.multiblock.hierarchy import levels

    X, Y = curved_rectangle(64, 32)
    topo = four_blocks(X, Y, 32, 16)
    depth = len(levels(topo))
    assert depth >= 3
    real, seen = multigrid.iterate_fas, []

    def slow_unless_damped(x, y, topo_, tol, max_cycles, give_up_rate=None, lvs=None, line_omega=1.0):
        seen.append((len(lvs), line_omega, give_up_rate))
        if line_omega == 1.0:
            yield 1, 1.0
            return 1, 1.0, [(0, 1.0), (1, 1.0)], "slow", len(lvs)
        return (yield from real(x, y, topo_, tol, max_cycles, give_up_rate, lvs, line_omega))

    monkeypatch.setattr(multigrid, "iterate_fas", slow_unless_damped)
    mb = solve_multiblock(topo, tolerance=1e-10)
    omega, rate = solver.RETRY_LINE_OMEGA, solver.RETRY_GIVE_UP_RATE
    assert seen == [(depth, 1.0, 0.5), (depth - 1, 1.0, 0.5), (depth, omega, rate)] and omega < 1.0
    assert mb.converged and mb.info.method == f"smooth/multigrid({depth} levels, damped lines)"
    ref = solve_multiblock(topo, tolerance=1e-10, engine="multigrid")
    for g, k in zip(mb, ref, strict=True):
        assert np.hypot(g.x - k.x, g.y - k.y).max() < 1e-7 * topo.size


@pytest.mark.slow
def test_generated_lake_whose_coarsest_level_stalls_converges_by_multigrid():
    """A generated lake (round_lake(3), 9 blocks, ~16 000 nodes): with all 5 levels the cycles
    stall at ~40× the default tolerance (the solve fell back to SOR: 2290 sweeps); engine="auto"
    retries without the coarsest level and converges by multigrid, to a tight tolerance (the
    stopping measure is SOR's)."""
    from meshcore.layout import auto_layout
    from meshcore.multiblock.hierarchy import levels
    from meshcore.testing import round_lake

    topo = auto_layout(round_lake(3, kind="blob"), target_cells=15000, multiple=4).topology()
    n = len(levels(topo))
    mb = solve_multiblock(topo, tolerance=1e-9)
    assert mb.converged and mb.info.method == f"smooth/multigrid({n - 1} levels)", mb.info.method


@pytest.mark.slow
def test_generated_layout_whose_cycles_stall_converges_by_damped_multigrid(monkeypatch):
    """A generated layout (headlands(861006), 31 blocks, ~16 000 nodes): the undamped cycles stall
    (rate ~0.9) and, without the coarsest level, diverge; the solve fell back to SOR (4 275
    sweeps).  engine="auto" now retries with damped lines and converges by multigrid.  (The
    layout as drawn before blocks round a peninsula's tip were split, ``layout.fans.wraps``: the
    33 blocks drawn now end in SOR, a case for the solver; ``mesh_outline`` keeps the same grid;
    and before a fan's two side ratios were read by their product, ``layout.fans.FAN_AREA``.)"""
    from meshcore.layout import auto_layout, fans
    from meshcore.testing import headlands

    monkeypatch.setattr(fans, "_wraps", lambda *a, **k: False)
    monkeypatch.setattr(fans, "FAN_AREA", math.inf)
    topo = auto_layout(headlands(861006), target_cells=15000, multiple=4).topology()
    assert len(topo.blocks) == 31
    mb = solve_multiblock(topo)
    assert mb.converged and mb.info.method.startswith("smooth/multigrid("), mb.info.method


def test_hot_spot_sweeps_save_cycles_and_keep_the_grid(monkeypatch):
    """The point sweeps round the largest defects after each cycle (multigrid.HOT_SWEEPS) save
    cycles on a generated lake with islands and give the same grid (7 -> 5 cycles when written;
    9 -> 7 on its layout since the Y stars got six blocks round the centre, 6 -> 4 before)."""
    from meshcore.layout import auto_layout
    from meshcore.multiblock import multigrid
    from meshcore.testing import lake_with_islands

    topo = auto_layout(lake_with_islands(2), target_cells=4000, multiple=4).topology()
    hot = solve_multiblock(topo, engine="multigrid")
    tight = solve_multiblock(topo, engine="multigrid", tolerance=1e-9)
    monkeypatch.setattr(multigrid, "HOT_SWEEPS", 0)
    cold = solve_multiblock(topo, engine="multigrid")
    assert hot.converged and cold.converged
    assert hot.info.iterations < cold.info.iterations
    cold = solve_multiblock(topo, engine="multigrid", tolerance=1e-9)
    assert tight.converged and cold.converged
    for g, k in zip(tight, cold, strict=True):
        assert np.hypot(g.x - k.x, g.y - k.y).max() < 1e-6 * topo.size


@pytest.mark.parametrize("make", ["star5", "islands"])
def test_defect_after_the_hot_spot_sweeps_is_the_full_defect(make):
    """After the hot-spot sweeps only the defect round the swept nodes is recomputed: the same
    largest defect and the same defect at every node as a full table_defect (a 5-block corner:
    its irregular node; a generated lake with islands), also when a node is NaN."""
    from meshcore.layout import auto_layout
    from meshcore.multiblock import _kernels, multigrid
    from meshcore.multiblock.hierarchy import levels
    from meshcore.testing import lake_with_islands

    topo = star(5, 9) if make == "star5" else auto_layout(lake_with_islands(2), target_cells=4000).topology()
    lv = levels(topo)[0]
    m = topo.node_map
    x, y = np.empty(m.n_nodes), np.empty(m.n_nodes)
    for g, ids in zip(meshcore.multiblock.initial_grids(topo), m.ids, strict=True):
        x[ids.ravel()], y[ids.ravel()] = g.x.ravel(), g.y.ravel()
    zero = np.zeros(lv.n)
    rx, ry = np.zeros(lv.n), np.zeros(lv.n)
    _kernels.table_defect(x, y, zero, zero, *lv.args, rx, ry)
    swept = multigrid._hot_sweeps(lv, x, y, rx, ry)
    assert 0 < len(swept[0]) < len(lv.args[0])  # some rows, not all
    got = multigrid._defect_after(lv, x, y, zero, rx, ry, swept[0])
    wx, wy = np.zeros(lv.n), np.zeros(lv.n)
    want = _kernels.table_defect(x, y, zero, zero, *lv.args, wx, wy)
    assert got == want and np.array_equal(rx, wx) and np.array_equal(ry, wy)
    x[swept[0][0]] = np.nan
    assert multigrid._defect_after(lv, x, y, zero, rx, ry, swept[0][:1]) == np.inf


@pytest.mark.kernel
def test_grow_near_matches_numpy_reference():
    """The compiled growth of a node set over the table equals the NumPy one (seeds anywhere:
    fixed, border, irregular and interior nodes), and so does the growth outward from the seeds
    (``hot_rows``, the hot-spot sweeps')."""
    from meshcore.multiblock import _hier_kernels
    from meshcore.multiblock.hierarchy import hot_rows, levels, near_reference, near_rows

    lv = levels(star(5, 9))[0]
    rng = np.random.default_rng(3)
    for width in (0, 1, 2, 3):
        seed = rng.random(lv.n) < 0.02
        want = near_reference(lv.args, seed, width)
        got = _hier_kernels.grow_near(lv.args[0], lv.args[1], seed, width)
        assert np.array_equal(got, want)
        assert np.array_equal(near_rows(lv.args, seed, width)[0], lv.args[0][want[lv.args[0]]])
        got_rows = hot_rows(lv, np.flatnonzero(seed), width)  # grown from the seeds: the same rows
        assert all(np.array_equal(a, b) for a, b in zip(got_rows, near_rows(lv.args, seed, width), strict=True))


@pytest.mark.kernel
def test_line_kernel_matches_numpy_reference():
    """line_sweep_rhs (rows gathered in line order, interface ends included) equals tridiagonal
    solves line by line over the same rows (NumPy), with and without f."""
    from meshcore.multiblock.hierarchy import levels

    X, Y = curved_rectangle(20, 9)
    topo = two_blocks(X, Y, 8)
    m = topo.node_map
    rng = np.random.default_rng(3)
    x = np.empty(m.n_nodes)
    y = np.empty(m.n_nodes)
    for g, ids in zip(meshcore.multiblock.initial_grids(topo), m.ids, strict=True):
        x[ids.ravel()], y[ids.ravel()] = g.x.ravel(), g.y.ravel()
    x += 0.01 * rng.standard_normal(x.size) * ~m.boundary
    lv = levels(topo)[0]
    for f in (np.zeros(0), 1e-3 * rng.standard_normal(m.n_nodes)):
        fy = f[::-1].copy() if f.size else f
        for lines in lv.lines:
            lnodes, lnbr, ptr, axis = lines
            xk, yk = x.copy(), y.copy()
            xr, yr = _reference.line_sweep(x, y, f, fy, lnodes, lnbr, np.arange(len(lnodes)), ptr, axis)
            d = _kernels.line_sweep_rhs(xk, yk, f, fy, *lines)
            assert np.allclose(xk, xr, rtol=0, atol=1e-13) and np.allclose(yk, yr, rtol=0, atol=1e-13)
            assert d == pytest.approx(np.hypot(xr - x, yr - y).max(), rel=1e-9)
            assert np.array_equal(xk[m.boundary], x[m.boundary])


#: The irregular-node arguments of a table with none (``jacobi_targets`` of regular rows only).
_NO_IRR = (np.zeros(0, dtype=np.int64), np.zeros(1, dtype=np.int64), np.zeros(0, dtype=np.int64))


@pytest.mark.parametrize("make", ["four", "star", "network"])
def test_block_lines_run_through_interface_nodes_in_the_block_frame(make):
    """Every block line takes the free regular nodes at its two ends on the block border (an
    interface) into its tridiagonal solve: each such node lies on a line of every block that
    holds it, across the border.  Its stencil row, which the node map read off the ring of cells
    in any of the 8 orientations, is turned into the block's frame: the row's E/W/N/S are the
    block's +i/−i/+j/−j neighbours (the line solve reads W, E or S, N as the line's neighbours),
    and the 9-point target is the table's (a symmetry of the stencil)."""
    from meshcore.multiblock.hierarchy import levels

    if make == "four":
        X, Y = curved_rectangle(16, 12)
        topo = four_blocks(X, Y, 8, 6)
    elif make == "star":
        topo = star(5)
    else:
        from meshcore.layout import auto_layout
        from meshcore.testing import channel_network

        topo = auto_layout(channel_network(1, n_branches=5), target_cells=3000, multiple=4).topology()
    m = topo.node_map
    from meshcore.multiblock.result import assemble

    x, y = assemble(meshcore.multiblock.initial_grids(topo), m)
    rng = np.random.default_rng(5)
    x = x + 1e-3 * topo.size * rng.standard_normal(x.size) * ~m.boundary
    for lv in levels(topo):
        nodes, nbr = lv.args[0], lv.args[1]
        pos = np.full(lv.n, -1)
        pos[nodes] = np.arange(len(nodes))
        border_free = np.zeros(lv.n, dtype=bool)
        border_free[lv.border[0]] = True
        for ax, (lnodes, lnbr, ptr, axis) in enumerate(lv.lines):
            assert np.all(axis == ax)
            tx, ty = _reference.jacobi_targets(x, y, lnodes, lnbr, *_NO_IRR)
            ux, uy = _reference.jacobi_targets(x, y, nodes, nbr, *_NO_IRR)
            assert np.allclose(tx[lnodes], ux[lnodes], rtol=0, atol=1e-12 * topo.size)
            assert np.allclose(ty[lnodes], uy[lnodes], rtol=0, atol=1e-12 * topo.size)
            on_lines = set()
            for g in lv.ids:
                ids = g if ax == 0 else g.T
                if min(ids.shape) < 3:
                    continue
                for j in range(1, ids.shape[1] - 1):
                    want = [int(p) for p in ids[:, j] if pos[p] >= 0]
                    on_lines.add(tuple(want))
                    for t in (0, -1):  # an end node on a free border: the row in the block frame
                        p = int(ids[t, j])
                        if pos[p] < 0:
                            continue
                        row = lnbr[np.flatnonzero(lnodes == p)]
                        inward = int(ids[1 if t == 0 else -2, j])
                        along = (int(ids[t, j + 1]), int(ids[t, j - 1]))
                        lo, hi, up, down = (1, 0, 2, 3) if ax == 0 else (3, 2, 0, 1)
                        k = lo if t == -1 else hi  # the inward neighbour: W at the +i end, E at the −i end
                        assert any(r[k] == inward and (r[up], r[down]) == along for r in row)
            got = {tuple(int(p) for p in lnodes[a:b]) for a, b in itertools.pairwise(ptr)}
            assert got == on_lines
        on_any = np.zeros(lv.n, dtype=bool)
        on_any[np.concatenate([lv.lines[0][0], lv.lines[1][0]])] = True
        assert on_any[lv.border[0]].mean() > 0.5  # most free border nodes are on a line now


@pytest.mark.slow
def test_lines_through_interface_nodes_save_cycles_on_a_generated_layout(monkeypatch):
    """A generated channel network (20 blocks, ~14 000 nodes): with the interface nodes inside the
    line solves the multigrid takes fewer cycles than with the lines ending next to the block
    borders (4 → 3), to the same grid."""
    from meshcore.layout import auto_layout
    from meshcore.multiblock import hierarchy
    from meshcore.testing import channel_network

    topo = auto_layout(channel_network(3, n_branches=7), target_cells=15000, multiple=4).topology()
    new = solve_multiblock(topo, engine="multigrid")
    tight = solve_multiblock(topo, engine="multigrid", tolerance=1e-10)
    real = hierarchy._lines

    def interior_only(ids, nodes, nbr, n):  # the lines before: block-interior nodes only
        interior = np.zeros(n, dtype=bool)
        for g in ids:
            interior[g[1:-1, 1:-1].ravel()] = True
        out = []
        for rows, lnbr, ptr, axis in real(ids, nodes, nbr, n):
            keep = interior[nodes[rows]]
            ptr = np.concatenate([[0], np.cumsum(np.add.reduceat(keep, ptr[:-1]) if len(rows) else [])])
            out.append((rows[keep], lnbr[keep], ptr.astype(np.int64), axis))
        return tuple(out)

    hierarchy._CACHE.clear()
    monkeypatch.setattr(hierarchy, "_lines", interior_only)
    old = solve_multiblock(topo, engine="multigrid")
    tight_old = solve_multiblock(topo, engine="multigrid", tolerance=1e-10)
    hierarchy._CACHE.clear()
    assert new.converged and old.converged
    assert new.info.iterations < old.info.iterations, (new.info.iterations, old.info.iterations)
    for g, k in zip(tight, tight_old, strict=True):
        assert np.hypot(g.x - k.x, g.y - k.y).max() < 1e-8 * topo.size


@pytest.mark.kernel
def test_multigrid_kernels_match_reference():
    """table_defect with f = 0 equals the NumPy Jacobi targets minus u."""
    topo = star(5)
    m = topo.node_map
    x = np.empty(m.n_nodes)
    y = np.empty(m.n_nodes)
    for g, ids in zip(meshcore.multiblock.initial_grids(topo), m.ids, strict=True):
        x[ids.ravel()], y[ids.ravel()] = g.x.ravel(), g.y.ravel()
    x += 0.01 * np.sin(7 * y) * ~m.boundary
    args = (m.nodes, m.nbr, m.irr_nodes, m.irr_ptr, m.irr_ring)
    tx, ty = _reference.jacobi_targets(x, y, *args)
    rx, ry = np.zeros(m.n_nodes), np.zeros(m.n_nodes)
    z = np.zeros(m.n_nodes)
    r = _kernels.table_defect(x, y, z, z, *args, rx, ry)
    assert np.allclose(rx, tx - x, atol=1e-14) and np.allclose(ry, ty - y, atol=1e-14)
    assert r == pytest.approx(np.hypot(tx - x, ty - y).max(), rel=1e-12)
    # a sweep with f = (T − u) of the current state leaves u fixed at nodes already solved
    fx, fy = 0.3 * np.ones(m.n_nodes), np.zeros(m.n_nodes)
    x2, y2 = x.copy(), y.copy()
    _kernels.table_sweep_rhs(x2, y2, fx, fy, *args, 1.0)
    assert np.array_equal(x2[m.boundary], x[m.boundary])


@pytest.mark.kernel
@pytest.mark.parametrize("make", ["star5", "four_blocks", "odd"])
def test_setup_kernels_match_their_references(make, rect):
    """The position classes (union–find) are the graph's connected components, and the greedy
    choice of kept classes equals the Python loop, on every level."""
    import scipy.sparse as sp

    from meshcore.multiblock import _hier_kernels, hierarchy

    if make == "star5":
        topo = star(5, 9)
    elif make == "four_blocks":
        topo = four_blocks(*curved_rectangle(56, 20), 30, 10)
    else:
        topo = two_blocks(*curved_rectangle(45, 13), 17)
    lvs = hierarchy.levels(topo)
    assert len(lvs) >= 2
    for lv in lvs:
        lines, comp = hierarchy._positions(lv.ids)
        ref = hierarchy.positions_reference(lv.ids)
        pairs = np.unique(np.c_[comp, ref], axis=0)  # one-to-one: the same partition
        assert len(pairs) == len(np.unique(comp)) == len(np.unique(ref))
        cl = [comp[e] for e in lines]
        nc = int(comp.max()) + 1
        a = np.concatenate([c[:-1] for c in cl])
        b = np.concatenate([c[1:] for c in cl])
        adj = sp.csr_matrix((np.ones(2 * len(a)), (np.r_[a, b], np.r_[b, a])), shape=(nc, nc))
        state = np.zeros(nc, dtype=np.int64)
        state[[c[0] for c in cl] + [c[-1] for c in cl]] = 1
        expect = state.copy()
        hierarchy.greedy_reference(cl, adj, expect)
        ptr = np.concatenate([[0], np.cumsum([len(c) for c in cl])]).astype(np.int64)
        _hier_kernels.greedy_drop(
            np.concatenate(cl), ptr, adj.indptr.astype(np.int64), adj.indices.astype(np.int64), state
        )
        assert np.array_equal(state, expect) and (state == 2).any() and (state == 1).any()


@pytest.mark.kernel
@pytest.mark.parametrize("make", ["star5", "odd", "network", "islands", "spiral"])
def test_level_table_kernels_match_their_numpy_references(make):
    """The per-block tables of every level built in one compiled call each (perimeter cells,
    interior stencils, 4-colour order, block lines, the choice of kept positions, FAS scaling,
    kept ids, sparse transfers) equal the block-by-block NumPy references: 5-block corners, odd counts, thin blocks
    and generated lake layouts."""
    from meshcore.layout import auto_layout
    from meshcore.multiblock import _hier_kernels, hierarchy, nodemap
    from meshcore.testing import channel_network, lake_with_islands, spiral

    if make == "star5":
        topo = star(5, 9)
    elif make == "odd":
        topo = two_blocks(*curved_rectangle(45, 13), 17)
    else:
        shape = {"network": channel_network(3, n_branches=4), "islands": lake_with_islands(1), "spiral": spiral()}
        topo = auto_layout(shape[make], target_cells=3000, multiple=4).topology()
    lvs = hierarchy.levels(topo)
    assert len(lvs) >= 2
    thin = 0
    for k, lv in enumerate(lvs):
        flat, off, shape = nodemap.flat_ids(lv.ids)
        thin += int((shape.min(axis=1) <= 3).sum())
        assert np.array_equal(_hier_kernels.perimeter_cells(flat, off, shape), nodemap._perimeter_cells(lv.ids))
        assert np.array_equal(nodemap._side_boundary(lv.ids, lv.n), nodemap.side_boundary_reference(lv.ids, lv.n))
        nodes_l, nbr_l = nodemap._interior_stencils(lv.ids)
        nodes, nbr = _hier_kernels.interior_stencils(flat, off, shape)
        assert np.array_equal(nodes, np.concatenate(nodes_l)) and np.array_equal(nbr, np.vstack(nbr_l))
        args, n_int = nodemap.solver_tables(lv.ids, lv.n) if k else ((lv.args[0], lv.args[1]), topo.node_map.n_interior)
        if k:  # the finest level's table comes from the node map, already in colour order
            got = hierarchy._colour_order(lv.ids, args, n_int)
            want = hierarchy.colour_order_reference(lv.ids, args, n_int)
            assert all(np.array_equal(a, b) for a, b in zip(got, want, strict=True))
        got_l = hierarchy._lines(lv.ids, lv.args[0], lv.args[1], lv.n)
        for a, b in zip(got_l, hierarchy.lines_reference(lv.ids, lv.args[0], lv.args[1], lv.n), strict=True):
            assert all(np.array_equal(u, v) for u, v in zip(a, b, strict=True))
        want_sel, got_sel = hierarchy.select_reference(lv.ids), hierarchy.select(lv.ids)
        assert (want_sel is None) == (got_sel is None)
        for (a1, b1), (a2, b2) in zip(want_sel or [], got_sel or [], strict=True):
            assert np.array_equal(a1, a2) and np.array_equal(b1, b2)
        if k:
            assert np.array_equal(hierarchy._scale(lv), hierarchy.scale_reference(lv))
            fine = lvs[k - 1]
            got_t, want_t = hierarchy._transfers(fine, lv), hierarchy.transfers_reference(fine, lv)
            for a, b in zip(got_t[:2], want_t[:2], strict=True):
                assert a.shape == b.shape
                assert all(
                    np.array_equal(u, w) for u, w in ((a.indptr, b.indptr), (a.indices, b.indices), (a.data, b.data))
                )
            assert np.array_equal(got_t[2], want_t[2])
            want_inj = np.unique(
                np.concatenate([g[np.ix_(si, sj)].ravel() for g, (si, sj) in zip(fine.ids, lv.sel, strict=True)])
            )
            assert np.array_equal(lv.inj, want_inj)
            for g, gc, (si, sj) in zip(fine.ids, lv.ids, lv.sel, strict=True):
                assert np.array_equal(lv.inj[gc], g[np.ix_(si, sj)])
    assert thin or make in ("star5", "odd")  # the layouts' coarse levels have blocks with one interior line


@pytest.mark.parametrize("make", ["star5", "network", "islands"])
def test_corner_records_equal_the_node_by_node_reference(make):
    """The node map's corners (owners, coordinates), built in one pass over the blocks' ids,
    equal node_owners / node_xy node by node: a 5-block corner, the junctions and islands of
    generated layouts, and any other nodes (shore, interface, block interior: no border, NaN)."""
    from meshcore.layout import auto_layout
    from meshcore.multiblock import nodemap
    from meshcore.testing import channel_network, lake_with_islands

    if make == "star5":
        topo = star(5, 9)
    else:
        shape = {"network": channel_network(3, n_branches=6), "islands": lake_with_islands(1)}[make]
        topo = auto_layout(shape, target_cells=3000, multiple=4).topology()
    m = topo.node_map
    assert len(m.corners) >= (1 if make == "star5" else 3)
    count = np.bincount(m.cells.ravel(), minlength=m.n_nodes)
    rng = np.random.default_rng(0)
    nodes = [c.node for c in m.corners] + rng.choice(m.n_nodes, 60, replace=False).tolist()
    interior = int(m.ids[0][1, 1])
    got = nodemap.corner_records(topo.blocks, m.ids, nodes + [interior], count, m.boundary)
    assert [c.node for c in got] == nodes + [interior]
    for c in got:
        want_xy = nodemap.node_xy(topo.blocks, m.ids, c.node)
        assert c.blocks == nodemap.node_owners(topo.blocks, m.ids, c.node)
        assert np.array_equal(c.point, want_xy, equal_nan=True)
        assert (c.valence, c.free) == (int(count[c.node]), not bool(m.boundary[c.node]))
    assert np.isnan(got[-1].point).all() and len(got[-1].blocks) == 1
    assert [(c.node, c.blocks, c.point) for c in m.corners] == [
        (c.node, c.blocks, c.point) for c in got[: len(m.corners)]
    ]


@pytest.mark.kernel
@pytest.mark.parametrize("make", ["star5", "network", "islands", "spiral"])
def test_compiled_start_grids_equal_the_numpy_tfi(make):
    """The start grids of a multiblock solve (one compiled call per block) are the NumPy
    transfinite interpolation of meshcore.algebraic, bit for bit; a block asking for the paper's
    weighted average still gets it."""
    import dataclasses

    from meshcore.algebraic import tfi, weighted_average
    from meshcore.layout import auto_layout
    from meshcore.multiblock.start import initial_grids, snapped_borders
    from meshcore.testing import channel_network, lake_with_islands, spiral

    if make == "star5":
        topo = star(5, 9)
    else:
        shape = {"network": channel_network(3, n_branches=4), "islands": lake_with_islands(1), "spiral": spiral()}
        topo = auto_layout(shape[make], target_cells=3000, multiple=4).topology()
    assert all(b.initial == "tfi" for b in topo.blocks)
    got = initial_grids(topo)
    for g, b, bd in zip(got, topo.blocks, snapped_borders(topo), strict=True):
        want = tfi(bd)
        assert np.array_equal(g.x, want.x) and np.array_equal(g.y, want.y) and g.names == dict(b.names)
    blocks = (dataclasses.replace(topo.blocks[0], initial="weighted"), *topo.blocks[1:])
    mixed = MultiBlockTopology(blocks, topo.interfaces, check_geometry=False)
    g0 = initial_grids(mixed)[0]
    want = weighted_average(snapped_borders(mixed)[0], blocks[0].weights)
    assert np.array_equal(g0.x, want.x) and np.array_equal(g0.y, want.y)


@pytest.mark.parametrize("make", ["star5", "network"])
def test_snapped_borders_give_every_shared_node_its_first_copy(make):
    """Every copy of a border node (interfaces, corners of 3-5 blocks) gets the coordinates of
    its first copy, block by block in the order bottom, top, left, right (a loop over the
    blocks' sides: the reference of the vectorised start.snapped_borders)."""
    import dataclasses

    from meshcore.layout import auto_layout
    from meshcore.multiblock.start import snapped_borders
    from meshcore.testing import channel_network

    if make == "star5":
        topo = star(5, 9)
    else:
        topo = auto_layout(channel_network(3, n_branches=4), target_cells=3000, multiple=4).topology()
    # every block's copies of the shared nodes a little off (by block): the first copy decides
    blocks = tuple(
        dataclasses.replace(
            b,
            borders=Borders(
                **{s: np.asarray(p, dtype=float) + 1e-9 * (k + 1) * topo.size for s, p in b.borders.items()}
            ),
        )
        for k, b in enumerate(topo.blocks)
    )
    topo = MultiBlockTopology(blocks, topo.interfaces, check_geometry=False)
    sides = {"bottom": np.s_[:, 0], "top": np.s_[:, -1], "left": np.s_[0, :], "right": np.s_[-1, :]}
    first: dict[int, np.ndarray] = {}
    for b, ids in zip(topo.blocks, topo.node_map.ids, strict=True):
        for name, sl in sides.items():
            for p, xy in zip(ids[sl], np.asarray(b.borders[name], dtype=float), strict=True):
                first.setdefault(int(p), xy)
    moved = 0  # copies that differed from the first copy before the snap
    for b, bd, ids in zip(topo.blocks, snapped_borders(topo), topo.node_map.ids, strict=True):
        for name, sl in sides.items():
            want = np.array([first[int(p)] for p in ids[sl]])
            assert np.array_equal(getattr(bd, name), want)
            moved += int((np.asarray(b.borders[name], dtype=float) != want).any(axis=1).sum())
    assert moved > 0


def test_band_is_the_nodes_two_stencil_steps_from_the_boundary():
    """The smoother's boundary band holds exactly the regular free nodes whose 8-point stencil
    reaches a fixed node within BAND_WIDTH steps (breadth-first search over the stencils)."""
    from meshcore.multiblock import hierarchy

    for lv in hierarchy.levels(star(5, 9))[:2]:
        nodes, nbr = lv.args[0], lv.args[1]
        stencil = {int(p): {int(q) for q in row} for p, row in zip(nodes, nbr, strict=True)}
        dist = {int(p): 0 for p in np.flatnonzero(~lv.free)}
        for d in range(1, hierarchy.BAND_WIDTH + 1):
            for p, row in stencil.items():
                if p not in dist and any(dist.get(q) == d - 1 for q in row):
                    dist[p] = d
        expect = sorted(p for p in stencil if p in dist)
        assert sorted(lv.band[0].tolist()) == expect
        assert 0 < len(expect) < len(nodes)
        assert np.array_equal(lv.band[1], nbr[np.isin(nodes, lv.band[0])])


@pytest.mark.parametrize("make", ["star5", "four_blocks", "odd", "shasta"])
def test_coarse_level_cells_and_boundary_equal_the_full_ones(make, rect, shasta_topology):
    """The coarse-level tables read only the cells along the block borders and the block sides:
    the same cells in the same order (the stencil frames depend on it) and the same fixed nodes as
    the full cell list, on every level."""
    from meshcore.multiblock import hierarchy, nodemap

    X, Y, _ = rect
    topo = {"star5": lambda: star(5, 9), "four_blocks": lambda: four_blocks(X, Y, 12, 6),
            "odd": lambda: four_blocks(X, Y, 14, 5), "shasta": lambda: shasta_topology}[make]()  # fmt: skip
    for lv in hierarchy.levels(topo):
        cells, _, boundary = nodemap._cells([str(k) for k in range(len(lv.ids))], lv.ids, lv.n)
        assert np.array_equal(nodemap._side_boundary(lv.ids, lv.n), boundary)
        assert np.array_equal(nodemap.side_boundary_reference(lv.ids, lv.n), boundary)
        side = np.zeros(lv.n, dtype=bool)
        for g in lv.ids:
            side[np.concatenate([g[0], g[-1], g[:, 0], g[:, -1]])] = True
        assert np.array_equal(nodemap._perimeter_cells(lv.ids), cells[side[cells].any(axis=1)])


def test_level_tables_hold_the_node_map_stencils_in_colour_order(rect):
    """The finest level's table is the node map's, each block's interior rows re-ordered so that
    consecutive rows of one colour are never in each other's stencil (four runs per block)."""
    from meshcore.multiblock import hierarchy

    X, Y, _ = rect
    for topo in (star(5, 9), four_blocks(X, Y, 12, 7)):
        m = topo.node_map
        lv = hierarchy.levels(topo)[0]
        nodes, nbr = lv.args[0], lv.args[1]
        assert sorted(map(tuple, np.column_stack([nodes, nbr]).tolist())) == sorted(
            map(tuple, np.column_stack([m.nodes, m.nbr]).tolist())
        )
        assert np.array_equal(nodes[m.n_interior :], m.nodes[m.n_interior :])
        runs, start = 0, 0
        for k in range(1, m.n_interior + 1):  # maximal runs of mutually independent rows
            if k == m.n_interior or np.isin(nbr[start:k], nodes[k]).any() or np.isin(nbr[k], nodes[start:k]).any():
                runs += 1
                start = k
        blocks = sum(g.shape[0] > 2 and g.shape[1] > 2 for g in m.ids)
        assert runs <= 4 * blocks


@pytest.mark.kernel
@pytest.mark.parametrize("make", ["star5", "four_blocks", "stretched"])
def test_fused_cycle_equals_the_kernel_by_kernel_cycle(make, rect):
    """The V-cycle in one compiled call gives the iterates of the Python driver (same kernels,
    same order): every level, irregular corners, odd counts, clustered rows."""
    from meshcore.multiblock import multigrid
    from meshcore.multiblock.hierarchy import levels

    if make == "star5":
        topo = star(5, 9)
    elif make == "four_blocks":
        topo = four_blocks(*curved_rectangle(40, 16), 22, 8)
    else:
        X, Y = _stretched(60, 12, 30.0)
        topo = two_blocks(X, Y, 23)
    lvs = levels(topo)
    assert len(lvs) >= 3
    m = topo.node_map
    x = np.empty(m.n_nodes)
    y = np.empty(m.n_nodes)
    for g, ids in zip(meshcore.multiblock.initial_grids(topo), m.ids, strict=True):
        x[ids.ravel()], y[ids.ravel()] = g.x.ravel(), g.y.ravel()
    z = np.zeros(m.n_nodes)
    xr, yr = x.copy(), y.copy()
    x0 = x.copy()
    for omega in (1.0, 1.0, 0.8):  # the damped lines of the retry (solver.RETRY_LINE_OMEGA) too
        multigrid._cycle(lvs, 0, x, y, z, z, omega)
        multigrid._cycle_reference(lvs, 0, xr, yr, z, z, omega)
        assert np.abs(x - xr).max() <= 1e-12 * topo.size and np.abs(y - yr).max() <= 1e-12 * topo.size
    assert np.abs(x - x0).max() > 1e-3 * topo.size  # the cycles moved the grid


@pytest.mark.kernel
def test_fused_cycle_same_iterates_with_int32_tables_and_an_unread_zero_f():
    """The packed tables in int32 (the default when they fit) and level ``k0``'s ``f = 0`` left
    unread (``vcycle(..., f0=False)``, what :func:`.multigrid._cycle` passes for the solver's
    cycles) give the iterates of int64 tables with ``f`` read, bit for bit (the same ids, the
    same arithmetic; ``x + 0 − u`` is ``x − u``), from the finest level and from a coarse one."""
    from meshcore import testing
    from meshcore.layout import auto_layout
    from meshcore.multiblock import _mg_fused as F
    from meshcore.multiblock import multigrid
    from meshcore.multiblock.hierarchy import levels
    from meshcore.multiblock.result import assemble

    topo = auto_layout(testing.lake_with_islands(938211), target_cells=1500, multiple=4).topology()
    lvs = levels(topo)
    assert len(lvs) >= 3
    x0, y0 = assemble(meshcore.multiblock.initial_grids(topo), topo.node_map)
    wide = multigrid.pack(lvs, np.int64)
    narrow = multigrid.pack(lvs)
    assert narrow[1].dtype == np.int32 and np.array_equal(narrow[1], wide[1])
    for k0 in (0, 1):
        xk, yk = x0, y0
        for co in lvs[1 : k0 + 1]:
            xk, yk = xk[co.inj], yk[co.inj]
        out = []
        for (fb, ib, meta), f0 in ((wide, True), (narrow, True), (narrow, False)):
            fb = fb.copy()
            mk, n = meta[k0], lvs[k0].n
            fb[mk[F.C_X] : mk[F.C_X] + n], fb[mk[F.C_Y] : mk[F.C_Y] + n] = xk, yk
            fb[mk[F.C_FX] : mk[F.C_FX] + n], fb[mk[F.C_FY] : mk[F.C_FY] + n] = 0.0, 0.0
            for _ in range(2):
                F.vcycle(fb, ib, meta, k0, 2, 2, 2, 2, 20, 1e-3, 100, 1.0, f0)
            out.append(fb[mk[F.C_X] : mk[F.C_X] + n].copy())
        assert np.abs(out[0] - xk).max() > 1e-3 * topo.size  # the cycles moved the grid
        assert np.array_equal(out[0], out[1]) and np.array_equal(out[0], out[2])


@pytest.mark.parametrize("make", ["star5", "four_blocks", "layout"])
def test_every_id_the_kernels_gather_is_a_node_of_its_level(make):
    """The table kernels index with unsigned ids (``_kernels._u``: no test for a negative index,
    faster), so a negative id in a table would read outside the node array where it used to wrap
    around: every id of every level's tables (point, lines, border, band, hot-spot rows, the
    irregular rings, the injection and the transfers) lies in ``0 … n − 1``."""
    from meshcore import testing
    from meshcore.layout import auto_layout
    from meshcore.multiblock.hierarchy import hot_rows, levels

    if make == "star5":
        topo = star(5, 9)
    elif make == "four_blocks":
        topo = four_blocks(*curved_rectangle(40, 16), 22, 8)
    else:
        topo = auto_layout(testing.lake_with_islands(938211), target_cells=1500, multiple=4).topology()
    lvs = levels(topo)
    assert len(lvs) >= 2
    for k, lv in enumerate(lvs):
        nodes, nbr, irr_n, _, ring = lv.args
        tables = [nodes, nbr, irr_n, ring, *lv.lines[0][:2], *lv.lines[1][:2], *lv.border[:2], *lv.band[:2]]
        tables += list(hot_rows(lv, np.flatnonzero(lv.free)[:3], 2)[:2])
        if k > 0:  # P: finer × this level, R and the injection: ids of the finer level
            tables.append(lv.P.indices)
            for t in (lv.R.indices, lv.inj):
                assert t.min() >= 0 and t.max() < lvs[k - 1].n
        for t in tables:
            assert t.size == 0 or (t.min() >= 0 and t.max() < lv.n)


@pytest.mark.parametrize("make", ["star5", "four_blocks", "odd"])
def test_sparse_transfers_match_the_blockwise_reference(make, rect):
    """The global sparse P and R equal the block-by-block interpolation and its normalised
    transpose (shared interface nodes, a node where five blocks meet, odd cell counts)."""
    from meshcore.multiblock.hierarchy import levels, prolong_reference, restrict_reference

    X, Y, _ = rect
    if make == "star5":
        topo = star(5)
    elif make == "four_blocks":
        topo = four_blocks(X, Y, 12, 6)
    else:
        topo = two_blocks(*curved_rectangle(45, 13), 17)
    lvs = levels(topo)
    assert len(lvs) >= 2
    rng = np.random.default_rng(5)
    for fine, coarse in itertools.pairwise(lvs):
        r = rng.standard_normal(fine.n)
        e = rng.standard_normal(coarse.n)
        assert np.allclose(coarse.R @ r, restrict_reference(fine, coarse, r), rtol=0, atol=1e-13)
        assert np.allclose(coarse.P @ e, prolong_reference(fine, coarse, e), rtol=0, atol=1e-13)
        # P reproduces constants away from the fixed boundary; R of a constant is the constant
        one = np.ones(coarse.n)
        assert np.allclose((coarse.P @ one)[fine.free], 1.0)
        assert np.allclose((coarse.R @ np.ones(fine.n))[coarse.free], 1.0)


@pytest.mark.kernel
def test_a_nan_node_makes_every_measure_infinite():
    """The table kernels' largest displacement is inf when a node is NaN (max() ignored it)."""
    topo = star(5)
    m = topo.node_map
    x = np.empty(m.n_nodes)
    y = np.empty(m.n_nodes)
    for g, ids in zip(meshcore.multiblock.initial_grids(topo), m.ids, strict=True):
        x[ids.ravel()], y[ids.ravel()] = g.x.ravel(), g.y.ravel()
    x[m.nodes[len(m.nodes) // 2]] = np.nan
    args = (m.nodes, m.nbr, m.irr_nodes, m.irr_ptr, m.irr_ring)
    z = np.zeros(m.n_nodes)
    assert _kernels.table_residual(x, y, *args) == np.inf
    assert _kernels.table_defect(x, y, z, z, *args, z.copy(), z.copy()) == np.inf
    assert _kernels.table_sweep_rhs(x.copy(), y.copy(), z, z, *args, 1.0) == np.inf


def test_a_nan_grid_is_never_reported_converged(rect, monkeypatch):
    """A cycle that leaves NaN in the grid (as a degenerate block did) counts as diverged: the
    solve continues with SOR from the last finite grid and ends finite, or is not converged."""
    from meshcore.multiblock import multigrid

    X, Y, _ = rect
    topo = four_blocks(X, Y, 12, 6)
    node = int(topo.node_map.nodes[3])
    real = multigrid._cycle

    def poisoned(lvs, k, x, y, fx, fy, line_omega=1.0):
        real(lvs, k, x, y, fx, fy, line_omega)
        if k == 0:
            x[node] = np.nan

    monkeypatch.setattr(multigrid, "_cycle", poisoned)
    mb = solve_multiblock(topo, engine="multigrid", tolerance=1e-8)
    finite = all(np.isfinite(g.x).all() and np.isfinite(g.y).all() for g in mb)
    assert finite and mb.converged and "sor" in mb.info.method
    # and if the grid itself stays NaN, the result says so
    monkeypatch.setattr(multigrid, "iterate_fas", _nan_fas)
    mb = solve_multiblock(topo, engine="multigrid", tolerance=1e-8, max_iterations=3)
    assert not mb.converged and "NaN" in mb.info.message


def _nan_fas(x, y, topo, tol, max_cycles, give_up_rate=None, lvs=None):
    x[topo.node_map.nodes] = np.nan
    yield 1, 0.0
    return 1, 0.0, [(0, 1.0), (1, 0.0)], "", 2


def test_outline_multiple_gives_coarsenable_blocks():
    from meshcore.multiblock.hierarchy import levels

    ring = np.array([[0, 0], [6, 0], [6, 1], [4, 1], [4, 3], [2, 3], [2, 1], [0, 1]], float)
    blocks = [
        {"name": "main", "corners": [0, 1, 2, 7], "cells": [24, 4]},
        {"name": "arm", "corners": [[2, 1], [4, 1], 4, 5], "cells": [8, 8]},
    ]
    topo = from_outline(ring, cuts=[[6, 3]], blocks=blocks, multiple=4).topology
    (itf,) = topo.interfaces
    assert all(v % 4 == 0 for s in (itf.a, itf.b) for v in (s.start, s.stop))
    assert levels(topo)[1].shapes == [(13, 3), (5, 5)]  # 24×4 → 12×2, 8×8 → 4×4
    bad = [{**blocks[0], "cells": [22, 4]}, blocks[1]]
    msg = _err(lambda: from_outline(ring, cuts=[[6, 3]], blocks=bad, multiple=4))
    assert "'main'" in msg and "multiples of 4" in msg


def _stretched(ni: int, nj: int, ratio: float):
    """The curved rectangle with rows clustered geometrically towards the bottom (first cell
    ``ratio`` times thinner than the last) and every other ξ node pulled sideways: cells long,
    thin and of varying shape."""
    X, Y = curved_rectangle(ni, nj)
    q = ratio ** (1.0 / (nj - 1))
    t = np.concatenate([[0.0], np.cumsum(q ** np.arange(nj))])
    t /= t[-1]
    return X, Y[:, -1:] * t[None, :]


@pytest.mark.parametrize(("ni", "nj", "ratio"), [(128, 16, 1.0), (96, 24, 30.0)])
def test_multigrid_rate_on_stretched_curved_blocks(ni, nj, ratio):
    """Cells 4× longer than wide, or rows clustered 30:1 at a curved wall: the line smoother
    keeps every cycle's defect reduction below 0.35 (the point smoother alone: 0.66–0.83
    here, measured), and the grid is the SOR grid."""
    X, Y = _stretched(ni, nj, ratio)
    topo = two_blocks(X, Y, ni // 2 + 1)
    mb = solve_multiblock(topo, tolerance=1e-10, engine="multigrid")
    h = [v for _, v in mb.info.residual_history]
    assert mb.converged and len(h) <= 14
    assert max(b / a for a, b in itertools.pairwise(h[1:])) < 0.35
    sor = solve_multiblock(topo, tolerance=1e-10, engine="blocks")
    for g, k in zip(mb, sor, strict=True):
        assert np.abs(g.x - k.x).max() < 1e-7 * mb.topology.size
        assert np.abs(g.y - k.y).max() < 1e-7 * mb.topology.size


def test_outline_case_round_trips_through_save_case(tmp_path):
    from meshcore.case import load_case, save_case
    from meshcore.cli.examples import example_path

    c = load_case(example_path("shasta-multiblock-coarse"))
    assert not c.blocks  # an [outline] case: blocks come from the cuts
    p = save_case(c, tmp_path / "again.toml")
    c2 = load_case(p)
    assert c2.outline == c.outline and c2.multiblock == c.multiblock and not c2.blocks


@pytest.mark.parametrize("make", ["star5", "four_blocks", "shasta"])
def test_vectorised_border_stencils_equal_the_node_by_node_ones(make, rect):
    """The ring of cells read off in one NumPy pass gives the frames of the node-by-node walk."""
    from meshcore.multiblock import nodemap

    if make == "star5":
        topo = star(5)
    elif make == "four_blocks":
        topo = four_blocks(*rect[:2], 14, 5)
    else:
        from meshcore.case import load_case
        from meshcore.case.multiblock import case_topology

        topo = case_topology(load_case(EXAMPLES / "shasta-multiblock-coarse.toml"))
    m = topo.node_map
    cells, _, boundary = nodemap._cells([b.name for b in topo.blocks], m.ids, m.n_nodes)
    occ = np.bincount(np.concatenate([np.unique(g) for g in m.ids]), minlength=m.n_nodes)
    free = np.flatnonzero(~boundary & (occ > 1))
    fast = nodemap._border_stencils(cells, free, str)
    slow = nodemap._ring_stencils(cells, free, str)
    assert len(fast[0]) > 0
    for a, b in zip(fast, slow, strict=True):
        assert np.array_equal(np.asarray(a), np.asarray(b))


def test_sor_after_a_slow_multigrid_starts_from_the_start_grid(monkeypatch):
    """When the multigrid gives up ("slow"), SOR starts again from the start grid, not from the
    cycles' grid: the result is the SOR grid to the bit (a generated lake's coarsest level,
    round_lake(1, blob), ended far off from the cycles' grid: 1290 folded cells at the end)."""
    import meshcore.multiblock.multigrid as mg
    import meshcore.multiblock.solver as solver

    X, Y = curved_rectangle(64, 32)
    monkeypatch.setattr(mg, "AUTO_GIVE_UP_RATE", 0.0)  # every multigrid is "slow" after 3 cycles
    monkeypatch.setattr(solver, "RETRY_GIVE_UP_RATE", 0.0)  # the damped retry's too
    auto = solve_multiblock(four_blocks(X, Y, 32, 16), tolerance=1e-12)
    # 3 cycles with every level, 3 with one level fewer (solver.RETRY_FEWER_LEVELS), 3 with damped
    # lines (solver.RETRY_LINE_OMEGA), then SOR
    assert "multigrid was slow" in auto.info.message and auto.info.method.startswith("smooth/blocks-sor after 9")
    sor = solve_multiblock(four_blocks(X, Y, 32, 16), tolerance=1e-12, engine="blocks")
    assert auto.converged and sor.converged
    for a, b in zip(auto, sor, strict=True):
        assert np.array_equal(a.x, b.x) and np.array_equal(a.y, b.y)


def test_a_round_lakes_start_grid_converges_where_the_multigrid_gives_up():
    from meshcore import testing
    from meshcore.layout import auto_layout
    from meshcore.orthogonal.levels import coarsen_topology

    lay = auto_layout(testing.round_lake(1, kind="blob"), target_cells=15000, multiple=4)
    mb = solve_multiblock(coarsen_topology(lay.topology(), 4), max_iterations=2000)
    assert mb.converged, mb.info.message
