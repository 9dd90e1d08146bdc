"""Extreme magnitudes and sizes: refused up front with one clear error, or gridded correctly.

Orientation and area tests do not depend on where a boundary lies or on its
scale; grids that would need more memory than the node limit are refused
before anything is allocated; nothing escapes as a RecursionError,
MemoryError, IndexError or a page of RuntimeWarnings.
"""

from __future__ import annotations

import numpy as np
import pytest

import meshcore
from meshcore.boundary import signed_area
from meshcore.cli import main
from meshcore.corners import interior_angles
from meshcore.errors import BoundaryError, InvalidInputError, MeshcoreError

T = np.linspace(0.0, 2.0 * np.pi, 41)[:-1]
CIRCLE = np.c_[np.cos(T), np.sin(T)]  # counter-clockwise


@pytest.mark.parametrize(("scale", "shift"), [(1e-3, 1e5), (1.0, 6e6), (1e-90, 0.0), (1e90, 0.0), (1e-6, 1e3)])
def test_orientation_is_translation_and_scale_invariant(scale, shift):
    p = scale * CIRCLE + shift
    assert signed_area(p) > 0 and signed_area(p[::-1]) < 0
    ang = interior_angles(p)
    np.testing.assert_allclose(ang, 180.0 - 360.0 / len(p), atol=1e-3)


def test_small_circle_far_from_the_origin_is_gridded_like_at_the_origin():
    """A counter-clockwise circle of radius 1e-3 at (1e5, 1e5) was 'running clockwise'."""
    g0 = meshcore.generate_block(loop=1e-3 * CIRCLE, corners="auto", cells=(16, 8))
    g = meshcore.generate_block(loop=1e-3 * CIRCLE + 1e5, corners="auto", cells=(16, 8))
    assert g.converged and meshcore.quality(g).n_folded == 0
    np.testing.assert_allclose(g.x - 1e5, g0.x, atol=1e-9)
    np.testing.assert_allclose(g.y - 1e5, g0.y, atol=1e-9)


@pytest.mark.parametrize(
    ("loop", "error", "needle"),
    [
        (CIRCLE * 1e300, InvalidInputError, r"beyond ±1e\+100"),
        (CIRCLE * 1e-300, BoundaryError, "scale them up"),
        (CIRCLE * 1e-5 + 1e8, BoundaryError, "local origin"),
    ],
)
def test_extreme_magnitudes_are_one_clear_error(loop, error, needle):
    # no RuntimeWarning may escape either: the test run turns warnings into errors
    with pytest.raises(error, match=needle):
        meshcore.generate_block(loop=loop, corners="auto", cells=(8, 4))


def test_collinear_outline_with_auto_corners_is_a_meshcore_error():
    """Points on one line: the orientation test and its reverse both said 'clockwise' → RecursionError."""
    x = [634103.5586954673, 635063.4100077824, 635800.5206166096, 636169.3107082576, 639185.404533773]
    x += [640470.0045422344, 641326.6566800592]
    p = np.c_[x, np.full(7, 967435.9524936767)]
    with pytest.raises(MeshcoreError):
        meshcore.generate_block(loop=p, corners="auto", cells=(4, 2))


SQ = np.array([[0, 0], [1, 0], [2, 0], [2, 1], [1, 1], [0, 1]], float)


@pytest.mark.parametrize("cells", [(10_000_000, 10_000_000), (9223372036854775807, 2), (10_000_000, 2)])
def test_grids_beyond_the_node_limit_are_refused_up_front(cells):
    with pytest.raises(InvalidInputError, match=r"cells make [\d,]+ nodes \(about .* of memory.*MESHCORE_MAX_NODES"):
        meshcore.generate_block(loop=SQ, corners=[0, 2, 3, 5], cells=cells)


def test_node_limit_can_be_raised(monkeypatch):
    monkeypatch.setenv("MESHCORE_MAX_NODES", "20")
    with pytest.raises(InvalidInputError, match="limit is 20 nodes"):
        meshcore.generate_block(loop=SQ, corners=[0, 2, 3, 5], cells=(4, 4))
    monkeypatch.setenv("MESHCORE_MAX_NODES", "25")
    assert meshcore.generate_block(loop=SQ, corners=[0, 2, 3, 5], cells=(4, 4)).converged


@pytest.mark.parametrize("cells", ["[10000000, 10000000]", "[9223372036854775807, 2]", "[10000000, 2]"])
def test_case_file_cells_beyond_the_limit(tmp_path, capsys, cells):
    case = tmp_path / "c.toml"
    case.write_text(
        "[[blocks]]\nname = 'sq'\ncells = " + cells + "\n[blocks.boundary]\n"
        "points = [[0, 0], [1, 0], [2, 0], [2, 1], [1, 1], [0, 1]]\ncorners = [0, 2, 3, 5]\n"
    )
    out = tmp_path / "g.vts"
    assert main(["generate", str(case), "-o", str(out), "-q"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "c.toml" in err and "limit" in err and "Traceback" not in err
    assert not out.exists()


def test_multiblock_total_node_limit(monkeypatch, capsys):
    from tests.conftest import ROOT

    monkeypatch.setenv("MESHCORE_MAX_NODES", "200")
    case = ROOT / "resources" / "examples" / "confluence-multiblock.toml"
    assert main(["generate", str(case), "-q"]) == 2
    err = capsys.readouterr().err
    assert "MESHCORE_MAX_NODES" in err and err.count("\n") == 1


def test_a_cell_without_area_is_never_converged():
    """Found by the property test: corners 0-3 of a 12-point square put all four block corners on one
    side, so the 1 × 1 grid's cell has no area; every corner is 'exempt' (0° or 180°), yet the grid
    must not be reported as converged."""
    s = np.linspace(0, 1, 4)[:-1]
    sq = np.vstack([np.c_[s, 0 * s], np.c_[1 + 0 * s, s], np.c_[1 - s, 1 + 0 * s], np.c_[0 * s, 1 - s]])
    g = meshcore.generate_block(loop=sq, corners=[0, 1, 2, 3], cells=(1, 1))
    assert meshcore.quality(g).n_folded == 1
    assert not g.converged and "no area" in g.info.message
    with pytest.raises(MeshcoreError):
        meshcore.generate_block(loop=sq, corners=[0, 1, 2, 3], cells=(1, 1), repair="strict")
