"""Grid control: boundary orthogonality/spacing, Thomas–Middlecoff, attraction, floating
nodes, O-grids (periodic seam, log-polar convergence) and NACA O-/C-grids."""

from __future__ import annotations

import math

import numpy as np
import pytest

import meshcore
from meshcore.airfoil import first_cell_height, naca4, naca4_body
from meshcore.algebraic import algebraic_grid
from meshcore.boundary import Borders
from meshcore.control import (
    ControlSources,
    ControlSpec,
    border_angles,
    boundary_report,
    control_from_mapping,
    first_spacing,
)
from meshcore.errors import InvalidInputError
from meshcore.generate import initial_grid, prepare_borders
from meshcore.topology import cgrid, ogrid, radial_nodes

WALLS = ("bottom", "right", "top", "left")


def bottle_points():
    """A bottle boundary like the paper's (4 bottom/top points, 10 per side)."""
    bottom = np.array([[0, 0], [1, 0], [2, 0], [3, 0]], float)
    right = np.array(
        [
            [3, 0],
            [3.1, 1],
            [3.1, 2],
            [3.0, 3],
            [2.6, 4],
            [2.0, 4.8],
            [1.9, 5.6],
            [1.9, 6.4],
            [1.9, 7.2],
            [1.9, 8],
        ],
        float,
    )
    left = right.copy()
    left[:, 0] = 3.0 - left[:, 0]
    top = np.array([[1.1, 8], [1.3667, 8], [1.6333, 8], [1.9, 8]])
    return bottom, right, top, left


def circle(c, r, n=20):
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    return np.column_stack([c[0] + r * np.cos(t), c[1] + r * np.sin(t)])


def solve(g0, spec=None, periodic=False, **kw):
    src = None if spec is None else ControlSources(spec, periodic=periodic)
    return meshcore.solve(g0, method="sor", sources=src, max_iterations=kw.pop("max_iterations", 20000), **kw)


# --------------------------------------------------------------------------- spec parsing


def test_control_from_mapping_and_unknown_keys():
    spec = control_from_mapping(
        {
            "kind": "steger-sorenson",
            "thomas-middlecoff": True,
            "relaxation": 0.2,
            "borders": {"bottom": {"spacing": 0.01, "angle": 80}},
            "attractors": [{"kind": "xi", "xi": 0.5, "amplitude": 0.3, "decay": 0.2}],
            "floating": ["top"],
        }
    )
    assert spec.thomas_middlecoff and spec.borders["bottom"].angle == 80
    assert spec.attractors[0].xi == 0.5 and spec.floating == ("top",)
    with pytest.raises(InvalidInputError, match=r"valid keys:.*relaxation"):
        control_from_mapping({"relax": 0.1})
    with pytest.raises(InvalidInputError, match=r"valid keys:.*spacing"):
        control_from_mapping({"borders": {"bottom": {"spcing": 0.1}}})
    with pytest.raises(InvalidInputError, match="border 'middle'"):
        control_from_mapping({"borders": {"middle": {"spacing": 0.1}}})
    with pytest.raises(InvalidInputError, match="kind"):
        control_from_mapping({"kind": "magic"})
    with pytest.raises(InvalidInputError, match="seam"):
        ControlSources(ControlSpec(borders={"left": {}}), periodic=True)


# --------------------------------------------------------------------------- paper-like cases


@pytest.mark.parametrize(("cells", "spacing"), [((6, 15), 0.1), ((12, 30), 0.05)])
def test_bottle_all_walls_orthogonal_with_requested_spacing(cells, spacing):
    specs = {n: {"distribution": "vinokur", "first": spacing, "last": spacing} for n in WALLS}
    b = prepare_borders(*bottle_points(), cells=cells, borders=specs)
    g0 = initial_grid(b, weights=(1.0, 0.5))
    ctl = ControlSpec(kind="hilgenstock-white", borders={n: {"spacing": spacing} for n in WALLS})
    g = solve(g0, ctl)
    gw = solve(g0)
    assert g.converged
    assert meshcore.quality(g).n_folded == 0
    rep = boundary_report(g, WALLS, dict.fromkeys(WALLS, spacing))
    assert rep["max_angle_deviation"] <= 2.0
    assert boundary_report(gw, WALLS)["max_angle_deviation"] > 10.0  # control did something
    # first-cell height: within 5 % away from the corners; the corner-adjacent node is
    # over-determined where the corner angle is not 90° (both walls claim the same node)
    for n in WALLS:
        err = np.abs(first_spacing(g, n) / spacing - 1.0)
        assert err[1:-1].max() <= 0.05, n
        assert err.max() <= 0.25, n


def test_two_circles_periodic_ogrid_control_and_seam():
    inner, outer = circle((0, 0), 1.0), circle((0.8, 0.4), 3.0)
    g0 = ogrid(inner, outer, (30, 6))
    sp = {"bottom": 0.05, "top": 0.2}
    ctl = ControlSpec(kind="hilgenstock-white", borders={k: {"spacing": v} for k, v in sp.items()})
    g = solve(g0, ctl, periodic=True)
    assert g.converged and g.periodic
    assert meshcore.quality(g).n_folded == 0
    rep = boundary_report(g, ("bottom", "top"), sp)
    assert rep["max_angle_deviation"] <= 2.0
    assert rep["max_spacing_error"] <= 0.05
    # the seam is interior: no kink (2nd difference along ξ) and no size jump there
    for gg in (g, solve(g0)):
        x, y = gg.x[:-1], gg.y[:-1]
        d2 = np.hypot(
            np.roll(x, -1, 0) - 2 * x + np.roll(x, 1, 0),
            np.roll(y, -1, 0) - 2 * y + np.roll(y, 1, 0),
        )[:, 1:-1].max(axis=1)
        assert d2[0] <= 1.01 * d2[1:].max()
        sr = meshcore.cell_quality(gg)["size_ratio"].max(axis=1)
        assert max(sr[0], sr[-1]) <= 1.05 * sr[1:-1].max()
        assert np.array_equal(gg.x[0], gg.x[-1])


def test_concentric_ogrid_converges_to_log_polar_at_second_order():
    errs = []
    for n in (16, 32):
        ni, nj = 2 * n, n // 2
        th = -np.linspace(0, 2 * np.pi, ni + 1)  # clockwise: i around, j out
        inner = np.column_stack([np.cos(th), np.sin(th)])[:-1]
        g = meshcore.solve(ogrid(inner, 4 * inner, (ni, nj)), method="sor", tolerance=1e-12, max_iterations=100000)
        assert g.converged
        R = 4.0 ** np.linspace(0, 1, nj + 1)
        errs.append(np.max(np.hypot(g.x - np.cos(th)[:, None] * R, g.y - np.sin(th)[:, None] * R)))
    rate = math.log2(errs[0] / errs[1])
    assert 1.8 <= rate <= 2.3, errs


# --------------------------------------------------------------------------- interior control


def test_thomas_middlecoff_reproduces_boundary_distribution_on_a_rectangle():
    u = meshcore.distribute(12, "tanh", first=0.02)
    xb = 2.0 * u
    bottom = np.column_stack([xb, np.zeros_like(xb)])
    top = np.column_stack([xb, np.ones_like(xb)])
    left = np.column_stack([np.zeros(7), np.linspace(0, 1, 7)])
    right = np.column_stack([np.full(7, 2.0), np.linspace(0, 1, 7)])
    g0 = algebraic_grid(Borders(bottom=bottom, right=right, top=top, left=left), "tfi")
    gw = solve(g0)
    g = solve(g0, ControlSpec(thomas_middlecoff=True))
    err_tm = np.abs(g.x - xb[:, None]).max()
    err_w = np.abs(gw.x - xb[:, None]).max()
    assert err_tm < 1e-4 * 2.0
    assert err_w > 100 * err_tm


def test_eta_line_attraction_clusters_and_repulsion_spreads():
    b = prepare_borders(
        *[np.asarray(p) for p in ([[0, 0], [1, 0]], [[1, 0], [1, 1]], [[0, 1], [1, 1]], [[0, 0], [0, 1]])],
        cells=(10, 20),
    )
    g0 = initial_grid(b)

    def gap(a):
        spec = ControlSpec(attractors=[{"kind": "eta", "eta": 0.5, "amplitude": a, "decay": 0.3}])
        g = solve(g0, spec)
        assert g.converged and meshcore.quality(g).n_folded == 0
        return float(np.mean(g.y[:, 11] - g.y[:, 10]))

    assert gap(0.3) < 0.7 * 0.05 < 0.05 * 1.3 < gap(-0.3)


def test_floating_nodes_untwist_an_ogrid_and_stay_on_the_curve():
    inner, outer = circle((0, 0), 1.0, 64), circle((0, 0), 3.0, 64)
    ni, nj = 32, 8
    from meshcore.topology import closed_curve_nodes

    bottom = closed_curve_nodes(inner, ni)
    top = closed_curve_nodes(outer, ni, start=outer[6])  # twisted by 6/64 of a turn
    cut = radial_nodes(bottom[0], top[0], nj)
    g0 = algebraic_grid(Borders(bottom=bottom, right=cut.copy(), top=top, left=cut, periodic=True), "tfi")
    gw = solve(g0)
    spec = ControlSpec(floating=("top",), float_every=5)
    src = ControlSources(spec, periodic=True, curves={"top": outer})  # slide on the 64-gon
    g = meshcore.solve(g0, method="sor", sources=src, max_iterations=20000)
    assert g.converged
    dev_w = np.abs(border_angles(gw, "top") - 90).max()
    dev_f = np.abs(border_angles(g, "top") - 90).max()
    assert dev_w > 10 and dev_f < 0.2 * dev_w
    r = np.hypot(g.x[:, -1], g.y[:, -1])
    assert np.all(r <= 3.0 + 1e-12) and np.all(r >= 3.0 * math.cos(math.pi / 64) - 1e-12)
    assert np.array_equal(g.x[0], g.x[-1]) and meshcore.quality(g).n_folded == 0


# --------------------------------------------------------------------------- airfoils


def test_naca4_geometry_and_yplus_spacing():
    up, lo = naca4("0012", 100)
    assert np.max(up[:, 1] - lo[:, 1]) == pytest.approx(0.12, abs=2e-3)
    assert up[-1] == pytest.approx(lo[-1]) and up[0] == pytest.approx([0, 0])
    up, lo = naca4("2412", 100)
    camber = 0.5 * (up[:, 1] + lo[:, 1])
    assert camber.max() == pytest.approx(0.02, abs=1e-3)
    assert first_cell_height(1.0, 1e6) == pytest.approx(2.35e-5, rel=0.01)
    assert first_cell_height(30.0, 1e6) == pytest.approx(30 * first_cell_height(1.0, 1e6))
    with pytest.raises(InvalidInputError, match="4 digits"):
        naca4("00120")


def test_naca0012_ogrid_wall_orthogonal_no_folds():
    body = naca4_body("0012", 32)
    R, nj, dy = 5.0, 24, 2e-3
    th = -np.linspace(0, 2 * np.pi, 65)
    top = np.column_stack([0.5 + R * np.cos(th), R * np.sin(th)])
    cut = radial_nodes(body[0], top[0], nj, first=dy)
    g0 = algebraic_grid(Borders(bottom=body, right=cut.copy(), top=top, left=cut, periodic=True), "tfi")
    spec = ControlSpec(kind="hilgenstock-white", thomas_middlecoff=True, borders={"bottom": {"spacing": dy}})
    g, gw = solve(g0, spec, periodic=True), solve(g0)
    assert g.converged and meshcore.quality(g).n_folded == 0
    rep = boundary_report(g, ("bottom",), {"bottom": dy})
    assert rep["max_angle_deviation"] <= 2.0 and rep["max_spacing_error"] <= 0.05
    assert boundary_report(gw, ("bottom",))["max_angle_deviation"] > 10


@pytest.mark.slow
def test_naca0012_cgrid_wall_orthogonal_wake_cut_solved():
    body = naca4_body("0012", 24)
    dy = 2e-3
    C = cgrid(body, cells_wake=12, cells_normal=16, first=dy)
    spec = ControlSpec(
        kind="hilgenstock-white",
        thomas_middlecoff=True,
        wake=C.wake,
        borders={"bottom": {"spacing": dy, "start": C.body[0] + 1, "stop": C.body[1]}},
    )
    g = solve(C.grid, spec, max_iterations=40000)
    assert g.converged and meshcore.quality(g).n_folded == 0
    ni = g.shape[0] - 1
    k = np.arange(C.wake + 1)
    assert np.array_equal(g.x[k, 0], g.x[ni - k, 0]) and np.array_equal(g.y[k, 0], g.y[ni - k, 0])
    assert not np.allclose(g.x[1 : C.wake, 0], C.grid.x[1 : C.wake, 0])  # the cut nodes moved
    a = border_angles(g, "bottom")[C.body[0] : C.body[1] - 1]
    s = first_spacing(g, "bottom")[C.body[0] : C.body[1] - 1]
    assert np.abs(a - 90).max() <= 2.0 and np.abs(s / dy - 1).max() <= 0.05


def test_steger_sorenson_targets_plus_feedback_on_smooth_walls():
    inner, outer = circle((0, 0), 1.0, 200), circle((0.8, 0.4), 3.0, 200)
    g0 = ogrid(inner, outer, (60, 16))
    sp = {"bottom": 0.05, "top": 0.2}
    borders = {k: {"spacing": v} for k, v in sp.items()}
    classic = solve(g0, ControlSpec(kind="steger-sorenson", feedback=0.0, borders=borders), periodic=True)
    full = solve(g0, ControlSpec(kind="steger-sorenson", borders=borders), periodic=True)
    assert classic.converged and full.converged
    rc = boundary_report(classic, ("bottom", "top"), sp)
    rf = boundary_report(full, ("bottom", "top"), sp)
    # the Taylor targets alone miss on a coarse stretched grid; the feedback closes the gap
    assert rc["max_spacing_error"] > 0.1
    assert rf["max_spacing_error"] <= 0.05 and rf["max_angle_deviation"] <= 2.0
    assert meshcore.quality(full).n_folded == 0


# --------------------------------------------------------------------------- case files

EXAMPLES = __import__("pathlib").Path(__file__).resolve().parents[2] / "resources" / "examples"


def _walls(block):
    return {k: v.get("spacing") for k, v in block.control.get("borders", {}).items()}


@pytest.mark.parametrize("name", ["bottle-orthogonal", "two-circles-orthogonal", "two-circles-ogrid", "naca0012-ogrid"])
def test_control_example_cases(name):
    from meshcore.case import dumps_case, load_case, loads_case

    case = load_case(EXAMPLES / f"{name}.toml")
    block = case.blocks[0]
    assert block.control is not None
    assert loads_case(dumps_case(case)).blocks[0].control == block.control  # round trip
    (g,) = meshcore.case.generate_case(case)
    assert g.converged and meshcore.quality(g).n_folded == 0
    sp = _walls(block)
    rep = boundary_report(g, tuple(sp), sp)
    assert rep["max_angle_deviation"] <= 2.0
    if g.periodic:
        assert rep["max_spacing_error"] <= 0.05
    else:  # next to a corner θc ≠ 90° the angle wins over the spacing (see meshcore.control)
        for n in sp:
            err = np.abs(first_spacing(g, n) / sp[n] - 1)
            assert err[1:-1].max() <= 0.05 and err.max() <= 0.25, n


def test_case_control_errors_name_the_block_and_valid_keys():
    from meshcore.case import loads_case
    from meshcore.errors import CaseFileError

    text = (EXAMPLES / "two-circles-ogrid.toml").read_text()
    bad = text.replace("[blocks.control.borders.bottom]", "[blocks.control.borders.bottom]\nspcing = 1")
    with pytest.raises(CaseFileError, match=r"block 'two-circles'.*spcing.*valid.*spacing"):
        loads_case(bad)
    bad = text.replace("[blocks.control]", "[blocks.control]\nrelax = 0.1")
    with pytest.raises(CaseFileError, match=r"relax.*valid.*relaxation"):
        loads_case(bad)


def test_cgrid_example_loads_and_starts_unfolded():
    """The C-grid example (by multigrid 0.6 s to solve, by SOR 8 s; scripts/control_report.py)."""
    from meshcore.case import load_case
    from meshcore.generate import generate_block

    block = load_case(EXAMPLES / "naca0012-cgrid.toml").blocks[0]
    wake = block.control["wake"]
    g0 = generate_block(block, smooth=False)
    ni = g0.shape[0] - 1
    k = np.arange(wake + 1)
    assert np.allclose(g0.x[k, 0], g0.x[ni - k, 0]) and np.allclose(g0.y[k, 0], g0.y[ni - k, 0])
    assert meshcore.quality(g0).n_folded == 0


def test_generate_block_control_floating_slides_on_the_input_loop():
    # a quarter annulus given as a loop; floating outer arc, nodes stay on the input polyline
    th = np.linspace(0, np.pi / 2, 40)
    outer = np.column_stack([3 * np.cos(th), 3 * np.sin(th)])
    inner = np.column_stack([np.cos(th), np.sin(th)])[::-1]
    loop = np.vstack([[[1, 0]], [[2, 0]], outer, [[0, 2]], inner[:-1]])
    sw, se = 0, 2
    ne, nw = 2 + 39, 2 + 40 + 1
    # the outer arc is clustered at one end, so the Winslow lines lean on it
    common = {
        "loop": loop,
        "corners": (sw, se, ne, nw),
        "cells": (10, 12),
        "method": "sor",
        "borders": {"right": {"distribution": "tanh", "first": 0.1}},
    }
    g = meshcore.generate_block(**common, control={"floating": ["right"], "float_every": 5})
    gw = meshcore.generate_block(**common)
    assert g.converged and meshcore.quality(g).n_folded == 0
    r = np.hypot(g.x[-1], g.y[-1])
    assert np.all(np.abs(r - 3) <= 3 * (1 - math.cos(np.pi / 2 / 39 / 2)) + 1e-9)
    dev_f = np.abs(border_angles(g, "right") - 90).max()
    dev_w = np.abs(border_angles(gw, "right") - 90).max()
    assert dev_w > 10 and dev_f < 0.2 * dev_w


def test_corner_blend_aims_at_the_corner_angle_next_to_corners():
    # a trapezoid with 120° / 60° corners: plain 90° control is over-constrained there
    bottom = np.array([[0, 0], [4, 0]], float)
    top = np.array([[1, 2], [3, 2]], float)
    left = np.array([[0, 0], [1, 2]], float)
    right = np.array([[4, 0], [3, 2]], float)
    b = prepare_borders(bottom, right, top, left, cells=(16, 8))
    g0 = initial_grid(b)
    spec = ControlSpec(borders={"bottom": {"corner_blend": 4}})
    src = ControlSources(spec)
    g = meshcore.solve(g0, method="sor", sources=src, max_iterations=20000)
    assert g.converged and meshcore.quality(g).n_folded == 0
    a = border_angles(g, "bottom")
    theta_c = math.degrees(math.atan2(2, 1))  # bottom-left corner angle, 63.4°
    want = theta_c + (90 - theta_c) * np.array([0.25, 0.5, 0.75])
    assert np.allclose(a[:3], want, atol=0.5)
    assert np.allclose(a[3:-3], 90, atol=0.5)
    assert np.allclose(a[-3:], (180 - want)[::-1], atol=0.5)
    with pytest.raises(InvalidInputError, match="corner_blend"):
        ControlSpec(borders={"bottom": {"corner_blend": -1}})


def test_xi_line_and_point_attraction():
    b = prepare_borders(
        *[np.asarray(p, float) for p in ([[0, 0], [1, 0]], [[1, 0], [1, 1]], [[0, 1], [1, 1]], [[0, 0], [0, 1]])],
        cells=(20, 20),
    )
    g0 = initial_grid(b)
    line = solve(g0, ControlSpec(attractors=[{"kind": "xi", "xi": 0.25, "amplitude": 0.3}]))
    dx = np.diff(line.x[:, 10])
    assert np.argmin(dx) in (4, 5) and dx.min() < 0.65 * 0.05  # cells shrink at ξ = 5 of 20
    point = solve(g0, ControlSpec(attractors=[{"kind": "point", "xi": 0.5, "eta": 0.5, "amplitude": 0.3}]))
    area = np.abs(meshcore.cell_quality(point)["area"])
    i, j = np.unravel_index(np.argmin(area), area.shape)
    assert {int(i), int(j)} <= {9, 10} and area.min() < 0.5 * area.max()
    assert meshcore.quality(point).n_folded == 0
    with pytest.raises(InvalidInputError, match="fraction"):
        ControlSpec(attractors=[{"kind": "point", "xi": 1.5, "eta": 0.5}])
