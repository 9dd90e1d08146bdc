"""A Delft3D single-domain ``.grd`` (+ ``.enc``) and EFDC's ``cell.inp`` (+ ``corners.inp``) read back
by :func:`meshcore.io.read_blocks`: the merged nodes, the inactive ones and the water cells as written,
the water cells as rectangular blocks; malformed files refused naming the file and line."""

from __future__ import annotations

import numpy as np
import pytest

import meshcore
from meshcore.errors import ReadError
from meshcore.io import GridSet, read_blocks, write
from meshcore.io import efdc as efdc_io
from meshcore.io.delft3d_single import merged, read_index_space
from meshcore.multiblock.indexspace import embed, from_mask
from meshcore.quality import quality
from meshcore.testing import round_lake
from tests.meshcore.test_indexspace import frame, oriented
from tests.meshcore.test_mesh_cli import _synthetic_rings
from tests.meshcore.test_single_domain import CASES


def _island_lake():
    shore, island = _synthetic_rings()
    return meshcore.mesh_outline(shore, holes=[island], target_cells=600, single=True)


def _round_lake():
    poly = round_lake(812355, n_islands=0)
    return meshcore.mesh_outline(300.0 * np.asarray(poly.exterior.coords)[:-1], target_cells=600, single=True)


@pytest.fixture(scope="module", params=["island", "round"])
def lake(request):
    """A real multiblock lake grid made for one index space (world coordinates, metres)."""
    return (_island_lake if request.param == "island" else _round_lake)()


def _cells(blocks, decimals: int) -> set[frozenset]:
    out = set()
    for g in blocks:
        x, y = np.round(g.x, decimals), np.round(g.y, decimals)
        for i in range(g.cells[0]):
            for j in range(g.cells[1]):
                out.add(frozenset((x[a, b], y[a, b]) for a, b in ((i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1))))
    return out


def _as_written(blocks) -> list:
    """The blocks with each coordinate as EFDC's files hold it (six decimals)."""
    six = np.vectorize(lambda v: float(f"{v:.6f}"))
    return [g.replaced(x=six(g.x), y=six(g.y)) for g in blocks]


def _same_space(got, want, atol: float) -> None:
    assert got.shape == want.shape
    np.testing.assert_array_equal(got.active_nodes, want.active_nodes)
    act = want.active_nodes
    np.testing.assert_allclose(got.x[act], want.x[act], rtol=0, atol=atol)
    np.testing.assert_allclose(got.y[act], want.y[act], rtol=0, atol=atol)
    np.testing.assert_array_equal(got.water, want.water)


def test_a_lake_written_as_one_delft3d_domain_reads_back_node_for_node(tmp_path, lake):
    assert len(lake.blocks) > 1
    path = tmp_path / "lake.grd"
    write(path, lake, format="delft3d-single")
    want = merged(GridSet(lake.blocks))
    if len(lake.blocks) == 4:  # the island lake: inactive points, the file the reader refused
        assert (~want.active_nodes).any()
    space, fr = read_index_space(path)
    _same_space(space, want, atol=0.0)  # 17 significant digits: the very numbers
    gs = read_blocks(path)  # .grd with missing points: the single-domain reader
    assert gs is not None and fr.crs is None
    n = sum(g.cells[0] * g.cells[1] for g in lake.blocks)
    assert sum(g.cells[0] * g.cells[1] for g in gs.blocks) == n
    assert _cells(gs.blocks, 9) == _cells(lake.blocks, 9)  # every cell, nothing else
    assert read_blocks(path, format="delft3d-single").block_names == gs.block_names
    assert len(gs.connectivity) >= len(gs.blocks) - 1  # the rectangles share borders
    assert all(quality(g).n_folded == 0 for g in gs.blocks)


def test_a_lake_written_for_efdc_reads_back_node_for_node(tmp_path, lake):
    run = tmp_path / "run"
    run.mkdir()
    write(run / "cell.inp", lake)
    want = merged(GridSet(lake.blocks))
    space, _fr = efdc_io.read_index_space(run / "cell.inp")
    _same_space(space, want, atol=1e-6)  # six decimals written
    gs = read_blocks(run / "cell.inp")
    n = sum(g.cells[0] * g.cells[1] for g in lake.blocks)
    assert sum(g.cells[0] * g.cells[1] for g in gs.blocks) == n == int(want.water.sum())
    assert _cells(gs.blocks, 9) == _cells(_as_written(lake.blocks), 9)
    assert gs.source.endswith("cell.inp")


def test_the_crs_comes_back_with_the_grid(tmp_path):
    blocks = CASES["frame"]
    shifted = [g.translated(500_000.0, 5_200_000.0) for g in blocks]
    write(tmp_path / "lake.grd", shifted, format="delft3d-single", crs="EPSG:32632")
    assert read_blocks(tmp_path / "lake.grd").frame.crs == "EPSG:32632"
    write(tmp_path / "cell.inp", shifted, crs="EPSG:32632")
    gs = read_blocks(tmp_path / "cell.inp")
    assert gs.frame.crs == "EPSG:32632"
    assert _cells(gs.blocks, 9) == _cells(_as_written(shifted), 9)


@pytest.mark.parametrize("case", list(CASES))
def test_the_small_index_spaces_read_back(tmp_path, case):
    """Turned blocks, an L, an island one cell across in index space (all its points active: only the
    .enc says which cells are water)."""
    blocks = CASES[case]
    write(tmp_path / "g.grd", blocks, format="delft3d-single")
    write(tmp_path / "cell.inp", blocks)
    want = merged(GridSet(tuple(blocks)))
    for got, atol in (
        (read_index_space(tmp_path / "g.grd")[0], 0.0),
        (efdc_io.read_index_space(tmp_path / "cell.inp")[0], 1e-6),
    ):
        _same_space(got, want, atol)
    assert _cells(read_blocks(tmp_path / "g.grd").blocks, 9) == _cells(blocks, 9)
    assert _cells(read_blocks(tmp_path / "cell.inp").blocks, 9) == _cells(_as_written(blocks), 9)


def test_a_full_grid_still_reads_as_one_block(tmp_path):
    g = CASES["L"][0]
    write(tmp_path / "one.grd", g)
    gs = read_blocks(tmp_path / "one.grd")
    assert len(gs.blocks) == 1 and gs.blocks[0] == g


def test_an_index_space_gives_back_its_blocks():
    blocks = [oriented(g, k) for g, k in zip(frame(), (2, 5, 1, 7), strict=True)]
    space = embed(blocks)
    for got, want in zip(space.blocks(), blocks, strict=True):
        np.testing.assert_array_equal(got.x, want.x)
        np.testing.assert_array_equal(got.y, want.y)
    cut = from_mask(space.x, space.y, space.water)
    np.testing.assert_array_equal(cut.water, space.water)
    assert cut.n_components == 1 and len(cut.placements) == 4
    with pytest.raises(ValueError, match="inactive corner"):
        from_mask(space.x, space.y, np.ones_like(space.water))


# ------------------------------------------------------------------ malformed files
@pytest.fixture
def grd(tmp_path):
    path = tmp_path / "lake.grd"
    write(path, CASES["frame"], format="delft3d-single")
    return path


@pytest.fixture
def efdc(tmp_path):
    write(tmp_path / "cell.inp", CASES["frame"])
    return tmp_path


def _edit(path, old: str, new: str, count: int = 1) -> None:
    text = path.read_text()
    assert old in text
    path.write_text(text.replace(old, new, count))


def test_a_grd_with_x_missing_and_y_not_is_refused_naming_the_node(grd):
    lines = grd.read_text().splitlines()
    k = next(i for i, ln in enumerate(lines) if "-9.99999000000000024E+02" in ln and "ETA=" in ln)
    lines[k] = lines[k].replace("-9.99999000000000024E+02", " 1.00000000000000000E+00", 1)
    grd.write_text("\n".join(lines) + "\n")
    with pytest.raises(ReadError, match=r"lake\.grd: node \(m=\d+, n=\d+\): y is the missing value"):
        read_blocks(grd)


def test_an_enclosure_from_another_write_is_refused(grd):
    enc = grd.with_suffix(".enc")
    enc.write_text("     1     1\n     8     1\n     8     8\n     1     8\n     1     1\n")  # no island
    with pytest.raises(
        ReadError, match=r"lake\.enc: the enclosure makes cell .* active, but a corner .* different writes"
    ):
        read_blocks(grd)
    enc.write_text("     1     1\n     3     1\n     3     3\n")
    with pytest.raises(ReadError, match=r"lake\.enc: the last polygon .* is not closed"):
        read_blocks(grd)
    enc.write_text("     1     1\n  x\n")
    with pytest.raises(ReadError, match=r"lake\.enc: line 2: expected two integers"):
        read_blocks(grd)


def test_a_ddb_domain_with_inactive_points_is_refused(tmp_path, grd):
    (tmp_path / "dd.ddb").write_text("lake.grd 1 1 1 3 lake.grd 1 1 1 3\n")
    with pytest.raises(
        ReadError,
        match=r"lake\.grd: grid has missing \(inactive\) points or an enclosure that leaves cells out; a full grid",
    ):
        read_blocks(tmp_path / "dd.ddb")


def test_malformed_efdc_files_are_refused_naming_file_and_line(efdc):
    cell, corners = efdc / "cell.inp", efdc / "corners.inp"
    good_cell, good_corners = cell.read_text(), corners.read_text()
    lines = good_cell.splitlines()
    k = next(i for i, ln in enumerate(lines) if not ln.startswith("C") and "5" in ln[5:])
    for bad, match in (
        (lines[k][:5] + "x" + lines[k][6:], rf"cell\.inp: line {k + 1}, column 6: 'x' is not a cell type"),
        (lines[k].replace("5", "3", 1), rf"cell\.inp: line {k + 1}: cell .* type 3: a triangular water cell"),
        (lines[k] + "9", rf"cell\.inp: line {k + 1}: row J = \d+ has \d+ cells"),
        ("  ab " + lines[k][5:], rf"cell\.inp: line {k + 1}: expected the row number J"),
    ):
        cell.write_text("\n".join([*lines[:k], bad, *lines[k + 1 :]]) + "\n")
        with pytest.raises(ReadError, match=match):
            read_blocks(cell)
    cell.write_text(good_cell)
    rows = good_corners.splitlines()
    first = next(i for i, ln in enumerate(rows) if not ln.startswith("C"))
    i, j = rows[first].split()[:2]
    corners.write_text("\n".join(rows[:first] + rows[first + 1 :]) + "\n")  # a water cell left out
    with pytest.raises(ReadError, match=rf"corners\.inp: no line for water cell \(I={i}, J={j}\)"):
        read_blocks(cell)
    corners.write_text("\n".join([*rows, rows[first]]) + "\n")  # twice
    with pytest.raises(ReadError, match=rf"corners\.inp: line {len(rows) + 1}: cell \(I={i}, J={j}\) again"):
        read_blocks(cell)
    moved = rows[first + 1].split()  # the second cell (J + 1): its SW corner is the first cell's NW corner
    moved[2] = f"{float(moved[2]) + 0.5:.6f}"
    corners.write_text("\n".join([*rows[: first + 1], " ".join(moved), *rows[first + 2 :]]) + "\n")
    with pytest.raises(ReadError, match=rf"corners\.inp: line {first + 2}: corner SW of cell .* line {first + 1} puts"):
        read_blocks(cell)
    corners.write_text("\n".join([*rows[:first], "  2  2  1 2 3", *rows[first + 1 :]]) + "\n")
    with pytest.raises(ReadError, match=rf"corners\.inp: line {first + 1}: expected 'I J X1 Y1"):
        read_blocks(cell)
    corners.unlink()
    with pytest.raises(ReadError, match=r"cell\.inp: no corners\.inp beside it"):
        read_blocks(cell)
    (efdc / "grid.inp").write_text("x\n")
    with pytest.raises(ReadError, match=r"grid\.inp: EFDC grids are read from cell\.inp"):
        read_blocks(efdc / "grid.inp")
