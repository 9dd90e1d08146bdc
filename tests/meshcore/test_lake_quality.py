"""Lake-grid metrics (shared/design/lake-grids.md): exact values, multiblock pairs, coverage, presets."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from shapely.geometry import Polygon

import meshcore
from meshcore import StructuredGrid
from meshcore.errors import InvalidInputError
from meshcore.quality import PRESETS, Limit, Preset, check, lake_metrics
from tests.conftest import ROOT

EXAMPLES = ROOT / "resources" / "examples"


def product(xs, ys) -> StructuredGrid:
    X, Y = np.meshgrid(np.asarray(xs, float), np.asarray(ys, float), indexing="ij")
    return StructuredGrid(X, Y)


def wavy(ni=12, nj=9, a=0.08) -> StructuredGrid:
    """A smooth non-orthogonal, non-uniform grid (every metric varies)."""
    s, t = np.meshgrid(np.linspace(0, 1, ni + 1) ** 1.3, np.linspace(0, 1, nj + 1), indexing="ij")
    return StructuredGrid(2 * s + a * np.sin(3 * t) + 0.3 * t, t + a * np.sin(4 * s) + 0.1 * s * t)


# ----------------------------------------------------------- exact values
@pytest.mark.parametrize("periodic", [False, True])
def test_polar_grid_is_exactly_orthogonal(periodic):
    # any radial spacing, uniform angles: x_ξ = P(i+1) − P(i−1) lies on the ray and the chord
    # x_η = P(j+1) − P(j−1) is perpendicular to it, so |cos| = 0 to rounding
    r = np.array([1.0, 1.2, 1.7, 1.9, 2.6, 3.0, 3.1])
    if periodic:
        th = np.linspace(0, 2 * np.pi, 25)
        T, R = np.meshgrid(th, r, indexing="ij")  # i along θ (periodic, seam at θ = 0), j along r
        x, y = R * np.cos(T), R * np.sin(T)
        x[-1], y[-1] = x[0], y[0]  # column ni repeats column 0 exactly
        g = StructuredGrid(x, y, periodic=True)
    else:
        th = np.linspace(0.2, 1.4, 7)
        R, T = np.meshgrid(r, th, indexing="ij")
        g = StructuredGrid(R * np.cos(T), R * np.sin(T))
    m = lake_metrics(g)
    ni, nj = g.cells
    n_interior = (ni if periodic else ni - 1) * (nj - 1)
    assert len(m.values("cos")) == n_interior
    assert m.max("cos") < 1e-13 and m.max("deviation") < 1e-11
    assert m.share("cos", 0.02) == 1.0
    assert m.values("folded").sum() == 0


@pytest.mark.parametrize(("a", "b", "s"), [(1.0, 1.0, 0.5), (2.0, 0.5, -0.3), (0.3, 3.0, 4.0)])
def test_sheared_grid_has_the_analytic_cos(a, b, s):
    xi, eta = np.meshgrid(np.arange(7.0), np.arange(5.0), indexing="ij")
    g = StructuredGrid(a * xi + s * eta, b * eta)
    m = lake_metrics(g)
    cos = abs(s) / math.hypot(s, b)  # x_ξ = (a, 0), x_η = (s, b)
    np.testing.assert_allclose(m.values("cos"), cos, rtol=1e-12)
    np.testing.assert_allclose(m.values("deviation"), math.degrees(math.asin(cos)), rtol=1e-12)
    np.testing.assert_allclose(m.values("aspect_ratio"), max(a, math.hypot(s, b)) / min(a, math.hypot(s, b)))
    np.testing.assert_allclose(m.values("smoothness"), 1.0)
    assert m.blocks[0].cos[0, 2] != m.blocks[0].cos[0, 2]  # NaN on borders
    assert len(m.values("cos")) == 5 * 3


@pytest.mark.parametrize(("rx", "ry"), [(1.1, 1.0), (1.3, 0.8), (0.7, 1.25)])
def test_smoothness_of_geometric_stretching_is_its_ratio(rx, ry):
    xs = np.cumsum([0.0] + [rx**k for k in range(8)])
    ys = np.cumsum([0.0] + [ry**k for k in range(5)])
    m = lake_metrics(product(xs, ys))
    b = m.blocks[0]
    np.testing.assert_allclose(b.smooth_xi[1:-1], max(rx, 1 / rx), rtol=1e-12)
    np.testing.assert_allclose(b.smooth_eta[:, 1:-1], max(ry, 1 / ry), rtol=1e-12)
    assert np.isnan(b.smooth_xi[[0, -1]]).all() and np.isnan(b.smooth_eta[:, [0, -1]]).all()
    assert len(m.values("smoothness")) == 7 * 6 + 9 * 4  # pairs along ξ-lines + along η-lines
    assert m.max("cos") < 1e-15


def test_shrink_is_the_mean_cell_size_over_each_cells_shortest_edge():
    # columns 1, 1, 0.01, 1, 2 wide, rows 1, 0.5, 1 high: cells of known edges and a known mean size
    xs, ys = np.cumsum([0.0, 1, 1, 0.01, 1, 2]), np.cumsum([0.0, 1, 0.5, 1])
    m = lake_metrics(product(xs, ys))
    dx, dy = np.diff(xs), np.diff(ys)
    h = math.sqrt(xs[-1] * ys[-1] / (len(dx) * len(dy)))
    assert m.cell_size == pytest.approx(h, rel=1e-12)
    np.testing.assert_allclose(m.blocks[0].shortest, np.minimum.outer(dx, dy), rtol=1e-12)
    np.testing.assert_allclose(m.values("shrink"), (h / np.minimum.outer(dx, dy)).ravel(), rtol=1e-12)
    assert m.summary()["min_edge_cells"] == pytest.approx(0.01 / h, rel=1e-12)
    worst = m.worst("shrink", 3)  # the thin column's three cells, at their centres
    assert {(w.i, w.j) for w in worst} == {(2, 0), (2, 1), (2, 2)} and worst[0].x == pytest.approx(2.005)
    row = next(line for line in m.table().splitlines() if "shortest edge" in line)
    assert f"{0.01 / h:.3g} cells" in row and f"time step ÷ {h / 0.01:.3g}" in row and "b" in row
    # a given cell size is the unit instead (the CLI's asked size)
    assert lake_metrics(product(xs, ys), cell_size=2.0).summary()["min_edge_cells"] == pytest.approx(0.005)


def test_a_cell_far_smaller_than_the_rest_gets_a_note():
    from meshcore.quality.lake import SHRINK_NOTE

    even = lake_metrics(product(np.arange(6.0), np.arange(4.0)))
    assert even.max("shrink") == pytest.approx(1.0) and even.small_cell_note() is None
    xs = np.cumsum([0.0, 1, 1, 1e-3, 1, 2])  # a column 1/1000 wide
    m = lake_metrics(product(xs, np.arange(4.0)))
    assert m.max("shrink") > SHRINK_NOTE
    note = m.small_cell_note()
    assert note.startswith("cell block1(2,") and f"explicit time step ÷ {m.max('shrink'):.3g})" in note
    assert f"shortest edge, {1 / m.max('shrink'):.3g} cells (" in note
    assert m.small_cell_note(limit=2 * m.max("shrink")) is None


def test_a_collapsed_edge_shrinks_without_limit():
    X, Y = np.meshgrid([0.0, 1.0, 2.0], [0.0, 1.0, 2.0], indexing="ij")
    X[1, 2], Y[1, 2] = X[0, 2], Y[0, 2]  # top row: its first edge has length 0
    m = lake_metrics(StructuredGrid(X, Y))
    assert m.max("shrink") == math.inf and m.summary()["min_edge_cells"] == 0.0
    assert "| 0 cells (a collapsed edge: an explicit model cannot step there) |" in m.table()
    assert "a collapsed edge: an explicit model cannot step there" in m.small_cell_note()
    X, Y = np.meshgrid(np.arange(4.0), np.arange(3.0), indexing="ij")
    flat = lake_metrics(StructuredGrid(X + Y, X + Y))  # edges but no area: no mean cell size to measure by
    assert flat.summary()["min_edge_cells"] is None and flat.small_cell_note() is None
    assert "| shortest edge (in mean cell sizes)        | —" in flat.table()


def test_one_moved_node_fails_exactly_the_stencils_that_see_it():
    xi, eta = np.meshgrid(np.arange(7.0), np.arange(7.0), indexing="ij")
    y = eta.copy()
    d = 0.1
    y[3, 3] += d
    m = lake_metrics(StructuredGrid(xi, y))
    # cos ≠ 0 only at (2,3) and (4,3), whose x_ξ = (2, ±d) reaches the moved node
    bad = m.worst("cos", 10, above=1e-14)
    assert sorted((w.i, w.j) for w in bad) == [(2, 3), (4, 3)]
    assert bad[0].value == pytest.approx(d / math.hypot(2, d), rel=1e-12)
    # along the η-line i = 3 the edges are 1, 1+d, 1-d, 1: ratios 1+d, (1+d)/(1-d), 1/(1-d)
    v = check(m, "delft3d")
    cos_r, smooth_r, fold_r = v.results
    assert (cos_r.n_checked, cos_r.n_failed) == (25, 2) and not cos_r.passed
    assert smooth_r.n_failed == 1 and (smooth_r.worst[0].i, smooth_r.worst[0].j) == (3, 3)
    assert smooth_r.worst[0].value == pytest.approx((1 + d) / (1 - d)) and smooth_r.worst[0].note == "η-line"
    assert fold_r.passed and not v.passed
    assert [r.limit.metric for r in v.failed] == ["cos", "smoothness"]


def test_folds_are_relative_to_the_block_orientation():
    g = product(np.arange(5.0), np.arange(4.0))
    mirrored = StructuredGrid(-g.x, g.y)  # clockwise, but not folded
    assert lake_metrics(mirrored).values("folded").sum() == 0
    x = g.x.copy()
    x[2, 2] = 3.6  # past its neighbour (3, 2)
    m = lake_metrics(StructuredGrid(x, g.y))
    folded = {(w.i, w.j) for w in m.worst("folded", None, above=0)}
    assert folded == {(2, 1), (2, 2)}  # a corner Jacobian ≤ 0 at (3, 2) and at the moved node
    assert not check(m, "efdc").results[-1].passed


# ------------------------------------------------------------- multiblock
def two_blocks(width_b: float = 0.25):
    a = product(np.linspace(0, 2, 5), np.linspace(0, 1, 3))  # cells 0.5 × 0.5
    b = product(2 + width_b * np.arange(5), np.linspace(0, 1, 3))
    return [a, b]


def test_interface_ratio_of_two_blocks():
    m = lake_metrics(two_blocks(0.25))
    s = m.samples["interface_ratio"]
    assert len(s) == 2
    np.testing.assert_allclose(s.values, 2.0)
    assert [tuple(c) for c in zip(s.block, s.i, s.j, strict=True)] == [(0, 3, 0), (0, 3, 1)]
    assert [tuple(p) for p in s.partner] == [(1, 0, 0), (1, 0, 1)]
    np.testing.assert_allclose(np.c_[s.x, s.y], [[2, 0.25], [2, 0.75]])
    assert m.worst("interface_ratio", 1)[0].note == "| block2(0,0)"
    # blocks that only touch at a corner share no edge
    c = product(np.linspace(2, 3, 3), np.linspace(1, 2, 3))
    assert len(lake_metrics([two_blocks()[0], c]).values("interface_ratio")) == 0


def test_partial_interface_t_junction_and_reversed_orientation():
    main = product(np.linspace(0, 4, 9), np.linspace(0, 1, 3))  # cells 0.5 × 0.5
    # an arm on main's top between x = 1 and 3, turned by 180°: i runs right → left, j downwards,
    # so its *top* border (j = 4, y = 1) is main's top nodes 2…6 in reverse; cells 0.5 × 0.2
    i, j = np.meshgrid(np.arange(5.0), np.arange(5.0), indexing="ij")
    arm = StructuredGrid(3 - 0.5 * i, 1.8 - 0.2 * j)
    m = lake_metrics({"main": main, "arm": arm})
    s = m.samples["interface_ratio"]
    assert len(s) == 4 and m.names == ("main", "arm")
    np.testing.assert_allclose(s.values, 0.25 / 0.1)
    assert s.i.tolist() == [2, 3, 4, 5] and set(s.j.tolist()) == {1}
    assert s.partner.tolist() == [[1, 3, 3], [1, 2, 3], [1, 1, 3], [1, 0, 3]]
    assert m.values("folded").sum() == 0


def test_interface_pairs_match_the_topology_of_the_shasta_case():
    from meshcore.case import case_topology, load_case
    from meshcore.multiblock import initial_grids

    topo = case_topology(load_case(EXAMPLES / "shasta-multiblock-coarse.toml"))
    grids = initial_grids(topo)
    names = tuple(b.name for b in topo.blocks)
    s = lake_metrics(dict(zip(names, grids, strict=True))).samples["interface_ratio"]
    assert len(s) == sum(i.a.stop - i.a.start for i in topo.interfaces)
    declared = {frozenset((i.a.block, i.b.block)) for i in topo.interfaces}
    found = {frozenset((names[a], names[p[0]])) for a, p in zip(s.block, s.partner, strict=True)}
    assert found == declared


def test_multiblock_quality_uses_the_same_interface_ratios():
    from meshcore.boundary import Borders
    from meshcore.multiblock import Block, Interface, MultiBlockTopology, Side, solve_multiblock

    def block(name, g):
        return Block(name, Borders(*(g.border(b) for b in ("bottom", "right", "top", "left"))))

    a, b = two_blocks(0.25)
    topo = MultiBlockTopology((block("a", a), block("b", b)), (Interface(Side("a", "right"), Side("b", "left")),))
    mb = solve_multiblock(topo, mode="frozen")
    q = mb.quality()
    m = lake_metrics(mb)
    assert m.names == ("a", "b")
    assert q.interfaces == {"a ↔ b": pytest.approx(m.max("interface_ratio"))}


# --------------------------------------------------------------- coverage
def ring_of_blocks():
    """Four blocks around the square hole [1, 2]² inside [0, 3]², and that polygon."""
    n = 4
    t = np.linspace(0, 1, n + 1)

    def quad(p00, p10, p11, p01):
        p00, p10, p11, p01 = (np.asarray(p, float) for p in (p00, p10, p11, p01))
        S, T = np.meshgrid(t, t, indexing="ij")
        P = (1 - S)[..., None] * (1 - T)[..., None] * p00 + S[..., None] * (1 - T)[..., None] * p10
        P = P + S[..., None] * T[..., None] * p11 + (1 - S)[..., None] * T[..., None] * p01
        return StructuredGrid(P[..., 0], P[..., 1])

    blocks = [
        quad((0, 0), (3, 0), (2, 1), (1, 1)),
        quad((3, 0), (3, 3), (2, 2), (2, 1)),
        quad((3, 3), (0, 3), (1, 2), (2, 2)),
        quad((0, 3), (0, 0), (1, 1), (1, 2)),
    ]
    poly = Polygon([(0, 0), (3, 0), (3, 3), (0, 3)], [[(1, 1), (2, 1), (2, 2), (1, 2)]])
    return blocks, poly


def test_coverage_of_a_grid_equal_to_its_polygon():
    g = wavy()
    loop = np.vstack(
        [g.border("bottom"), g.border("right")[1:], g.border("top")[::-1][1:], g.border("left")[::-1][1:-1]]
    )
    c = lake_metrics(g, polygon=loop).coverage
    assert c.area_ratio == pytest.approx(1.0, abs=1e-12) and c.hausdorff == pytest.approx(0.0, abs=1e-12)
    blocks, poly = ring_of_blocks()
    m = lake_metrics(blocks, polygon=poly)
    assert m.coverage.area_ratio == pytest.approx(1.0, abs=1e-12) and m.coverage.hausdorff < 1e-12
    assert m.coverage.cell_size == pytest.approx(math.sqrt(8 / 64))
    assert len(m.values("interface_ratio")) == 4 * 4 and check(m, "gcmesh-lake").results[-1].passed


def test_coverage_measures_a_shifted_shore_and_a_missing_island():
    blocks, poly = ring_of_blocks()
    d = 0.05
    shifted = Polygon(np.asarray(poly.exterior.coords) + [d, 0], [np.asarray(poly.interiors[0].coords) + [d, 0]])
    c = lake_metrics(blocks, polygon=shifted).coverage
    assert c.hausdorff == pytest.approx(d, rel=1e-9)
    assert c.hausdorff_cells == pytest.approx(d / c.cell_size)
    # the shore without its island: the grid covers 8/9 of it and its island's rim lies 1 from the shore
    c2 = lake_metrics(blocks, polygon=Polygon(poly.exterior)).coverage
    assert c2.area_ratio == pytest.approx(8 / 9) and c2.hausdorff == pytest.approx(1.0, rel=1e-12)
    assert c2.side == "grid"
    # a folded block: the union of its cells is still measured
    x = blocks[0].x.copy()
    x[2, 2] += 0.9
    folded = [StructuredGrid(x, blocks[0].y), *blocks[1:]]
    m = lake_metrics(folded, polygon=poly)
    assert m.values("folded").sum() > 0 and m.coverage.area_ratio <= 1.0


@pytest.mark.parametrize("bad", [[[0, 0], [1, 1]], [[0, 0], [1, 1], [1, 0], [0, 1]]])
def test_bad_polygon_is_a_clear_error(bad):
    with pytest.raises(InvalidInputError, match="polygon"):
        lake_metrics(wavy(), polygon=bad)


# ------------------------------------------------------------- invariance
@settings(max_examples=25, deadline=None)
@given(
    st.floats(-1e3, 1e3),
    st.floats(-1e3, 1e3),
    st.floats(0, 2 * math.pi),
    st.floats(1e-3, 1e3),
)
def test_metrics_are_invariant_under_similarity(ux, uy, angle, scale):
    dx, dy = ux * scale, uy * scale  # offsets in units of the grid's size: no cancellation beyond rounding
    blocks, poly = ring_of_blocks()
    blocks = [wavy(), *[b.translated(5, 0) for b in blocks]]
    poly = Polygon(np.asarray(poly.exterior.coords) + [5, 0], [np.asarray(poly.interiors[0].coords) + [5, 0]])
    moved = [b.rotated(angle).scaled(scale).translated(dx, dy) for b in blocks]
    c, s = math.cos(angle), math.sin(angle)

    def tf(p):
        p = np.asarray(p)
        return scale * (p @ np.array([[c, s], [-s, c]])) + [dx, dy]

    mpoly = Polygon(tf(poly.exterior.coords), [tf(poly.interiors[0].coords)])
    m0 = lake_metrics(blocks[1:], polygon=poly)
    m1 = lake_metrics(moved[1:], polygon=mpoly)
    w0, w1 = lake_metrics(blocks[0]), lake_metrics(moved[0])
    for a, b in ((m0, m1), (w0, w1)):
        for k in ("cos", "smoothness", "aspect_ratio", "shrink", "folded", "interface_ratio"):
            np.testing.assert_allclose(b.values(k), a.values(k), rtol=1e-7, atol=1e-9)
        np.testing.assert_allclose(b.values("deviation"), a.values("deviation"), atol=1e-6)
    assert m1.coverage.area_ratio == pytest.approx(m0.coverage.area_ratio, rel=1e-9)
    assert m1.coverage.hausdorff_cells == pytest.approx(m0.coverage.hausdorff_cells, abs=1e-6)


# ------------------------------------------------------ presets, verdicts
def test_a_share_just_short_of_all_is_not_printed_as_100_per_cent():
    """``meshcore quality --preset efdc`` of a held-out lake's grid (1 node of 8598 over 3°) printed
    "FAIL (100.0 % ok)": the share was rounded up.  The app rounded it down; now the table does too."""
    xi, eta = np.meshgrid(np.arange(101.0), np.arange(101.0), indexing="ij")
    y = eta.copy()
    y[50, 50] += 0.1  # two of the 99 × 99 interior nodes miss the orthogonality limit
    v = check(lake_metrics(StructuredGrid(xi, y)), "delft3d")
    assert v.results[0].n_failed == 2 and v.results[0].value == pytest.approx(1 - 2 / 99**2)
    text = v.table()
    assert "FAIL (99.9 % ok)" in text and "FAIL (100.0 % ok)" not in text
    assert "pass (100.0 % ok)" in text  # no folded cell: all of them, 100.0
    # the metrics' own table reads the shares as the verdict does (it printed 97.8 % beside 97.7 % ok)
    m = lake_metrics(StructuredGrid(xi, y))
    row = next(line for line in m.table().splitlines() if "nodes within 3°" in line)
    assert "| 100.0 % / 99.9 % / 100.0 %" in row, row  # |cos| ≤ 0.02 at 99.98 %: rounded up it read 100.0


def test_presets_are_frozen_data_with_sources():
    assert {"delft3d", "efdc"} <= set(PRESETS)
    d = PRESETS["delft3d"]
    assert {(lim.metric, lim.max) for lim in d.limits} >= {("cos", 0.02), ("smoothness", 1.2)}
    assert ("deviation", 3.0) in {(lim.metric, lim.max) for lim in PRESETS["efdc"].limits}
    for p in PRESETS.values():
        assert p.source and p.title
    with pytest.raises(AttributeError):
        d.name = "x"  # type: ignore[misc]


def test_verdict_table_json_and_own_preset():
    g = wavy()
    v = check(g, "efdc")
    text = str(v)
    assert text.startswith("efdc:") and "| limit" in text and "source:" in text
    assert ("PASS" in text) == v.passed
    json.dumps(v.as_dict())  # serialisable
    for r in v.failed:
        vals = [w.value for w in r.worst]
        assert vals == sorted(vals, reverse=True) and min(vals) > r.limit.max and len(vals) == min(5, r.n_failed)
    mine = Preset("mine", "aspect only", (Limit("aspect_ratio", 1e9),), "a test")
    assert check(g, mine).passed
    assert check(g, Preset("x", "no polygon", (Limit("shore_distance", 0.5),), "t")).results[0].passed is None
    with pytest.raises(InvalidInputError, match="delft3d"):
        check(g, "nope")
    with pytest.raises(InvalidInputError, match="unknown metric"):
        Limit("nope", 1.0)


def test_existing_quality_report_still_works():
    r = meshcore.quality(wavy())
    assert r.n_folded == 0 and "folded cells" in r.table()
    from meshcore.quality import QualityReport, cell_quality

    assert isinstance(r, QualityReport) and cell_quality(wavy())["area"].shape == (12, 9)


def test_cli_quality_preset(tmp_path, capsys):
    from meshcore.cli import main
    from meshcore.io import write

    blocks, _ = ring_of_blocks()
    write(tmp_path / "ring.vtm", blocks, block_names=["s", "e", "n", "w"])
    assert main(["quality", str(tmp_path / "ring.vtm"), "--preset", "delft3d", "--preset", "efdc"]) == 0
    out = capsys.readouterr().out
    assert "delft3d: Delft3D" in out and "efdc: EFDC" in out and "cross-interface area ratio" in out
    rc = main(["quality", str(tmp_path / "ring.vtm"), "--preset", "delft3d", "--json", "--strict"])
    data = json.loads(capsys.readouterr().out)
    assert data["presets"][0]["preset"] == "delft3d"
    assert rc == (0 if data["presets"][0]["passed"] else 2)
    assert data["lake_metrics"]["interface_cell_pairs"] == 16
    assert 0 < data["lake_metrics"]["min_edge_cells"] < 1  # the ring's blocks are not all alike


def test_docstring_examples_run():
    import doctest

    from meshcore.quality import lake, presets

    for mod in (lake, presets):
        r = doctest.testmod(mod, optionflags=doctest.ELLIPSIS)
        assert r.attempted > 0 and r.failed == 0, mod.__name__


def test_a_straight_cell_corner_counts_alike_in_local_and_world_coordinates():
    """A cell corner at 180° (three nodes on one straight shore) has a Jacobian that is zero up to
    rounding: held-out lake g180765's tip block read as fold-free in its local frame and as
    non-convex in UTM (``meshcore mesh`` exit 3).  In both frames it is one straight-angle cell,
    not folded."""
    from meshcore.quality.cells import quality as cell_report
    from meshcore.quality.lake import block_metrics

    rng = np.random.default_rng(7)
    for _ in range(40):
        xi, eta = np.meshgrid(np.arange(4.0), np.arange(4.0), indexing="ij")
        x, y = 150.0 * xi, 150.0 * eta
        x[1, 0], x[0, 1], y[0, 1] = rng.uniform(50, 150), -rng.uniform(20, 100), 0.0  # (1,0), (0,0), (0,1) on y = 0
        c, s = np.cos(th := rng.uniform(0, 2 * np.pi)), np.sin(th)
        x, y = c * x - s * y, s * x + c * y
        seen = set()
        for off in ((0.0, 0.0), (rng.uniform(2e5, 8e5), rng.uniform(1e6, 9e6))):
            g = StructuredGrid(x + off[0], y + off[1])
            b = block_metrics(g)
            m = lake_metrics([g]).summary()
            seen.add((bool(b.folded[0, 0]), bool(b.straight[0, 0]), m["folded_cells"], m["straight_angle_cells"]))
            seen.add(("cells", [0, 0] in cell_report(g).nonconvex.tolist()))
        assert seen == {(False, True, 0, 1), ("cells", False)}
