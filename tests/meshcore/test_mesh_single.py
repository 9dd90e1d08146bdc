"""``meshcore mesh … -o lake.grd --single`` and ``-o DIR/cell.inp``: the blocks in one index space,
end to end (the files read back by the parsers of ``test_single_domain``), and the exit 2 with
nothing written when the layout does not fit one index space."""

from __future__ import annotations

import os

import numpy as np
import pytest

from meshcore.io import read_blocks
from meshcore.testing import round_lake
from tests.meshcore.test_mesh_cli import _synthetic_rings, mesh
from tests.meshcore.test_single_domain import active_cells, read_efdc, read_enc, read_grd_with_missing


def csv(path, rings) -> None:
    rows = [f"{x:.4f},{y:.4f},r{k}" for k, ring in enumerate(rings) for x, y in ring]
    path.write_text("x,y,ring\n" + "\n".join(rows) + "\n")


@pytest.fixture
def round_csv(tmp_path):
    """A generated round lake without islands (seed from a base nobody used), in metres."""
    poly = round_lake(812355, n_islands=0)
    f = tmp_path / "round.csv"
    csv(f, [300.0 * np.asarray(poly.exterior.coords)[:-1]])
    return f


def test_single_domain_and_efdc_end_to_end(tmp_path, round_csv):
    out = tmp_path / "run"
    out.mkdir()
    run = mesh(
        round_csv,
        "--cells",
        2000,
        "-o",
        tmp_path / "r.grd",
        "--single",
        "-o",
        out / "cell.inp",
        "-o",
        tmp_path / "r.npz",
    )
    assert run.rc == 0, run.err
    assert "using --regular" in run.err
    blocks = read_blocks(tmp_path / "r.npz").blocks
    n_cells = sum(g.cells[0] * g.cells[1] for g in blocks)
    X, Y, missing = read_grd_with_missing(tmp_path / "r.grd")
    act = active_cells(read_enc(tmp_path / "r.enc"), *X.shape)
    assert int(act.sum()) == n_cells
    valid = np.not_equal(X, missing)
    pts = np.round(np.column_stack([X[valid], Y[valid]]), 6)
    ref = np.round(np.concatenate([g.points for g in blocks]), 6)
    assert {tuple(p) for p in pts} == {tuple(p) for p in ref}
    types, dxdy, lxly, corners = read_efdc(out)
    assert int((types == 5).sum()) == n_cells == len(dxdy) == len(lxly) == len(corners)
    assert sorted(os.listdir(out)) == sorted(["cell.inp", "celllt.inp", "dxdy.inp", "lxly.inp", "corners.inp"])
    # the progress names every file written, not only the one given
    assert f"wrote {out / 'cell.inp'} and celllt.inp, dxdy.inp, lxly.inp, corners.inp beside it" in run.err
    assert f"wrote {tmp_path / 'r.grd'} and r.enc" in run.err


def test_a_lake_with_an_island_fits_one_index_space(tmp_path):
    """Refused until session 22 (the regular layout's ring round the island did not add up in cell
    counts): the layout for one index space closes it, and both single-domain files are written."""
    shore, island = _synthetic_rings()
    src = tmp_path / "isle.csv"
    csv(src, [shore, island])
    out = tmp_path / "efdc"
    out.mkdir()
    run = mesh(src, "--cells", 2000, "-o", tmp_path / "i.grd", "--single", "-o", out / "cell.inp")
    assert run.rc == 0, run.err
    types, dxdy, _, _ = read_efdc(out)
    assert int((types == 5).sum()) == len(dxdy) > 1000
    assert (tmp_path / "i.grd").exists() and (tmp_path / "i.enc").exists()


def test_a_layout_that_does_not_fit_is_refused_before_the_solve(tmp_path):
    """A branched channel whose arms fold onto each other in index space at every scale the layout
    tries: exit 2, one line naming the file and the place, no file written."""
    from meshcore import testing

    poly = testing.channel_network(812352, n_branches=5)
    src = tmp_path / "net.csv"
    csv(src, [300.0 * np.asarray(poly.exterior.coords)[:-1]])
    for out in (tmp_path / "i.grd", tmp_path / "cell.inp"):
        extra = ("--single",) if out.suffix == ".grd" else ()
        run = mesh(src, "--cells", 2000, "-o", out, *extra, "-o", tmp_path / "i.vtm")
        assert run.rc == 2, run.err
        last = run.err.strip().splitlines()[-1]
        assert str(src) in last and "one index space" in last and ".ddb" in last
        assert "folds back onto itself" in last
        assert "grid level" not in run.err
        assert sorted(os.listdir(tmp_path)) == ["net.csv"]


def test_single_needs_a_grd(tmp_path, round_csv):
    run = mesh(round_csv, "--cells", 2000, "-o", tmp_path / "r.vtm", "--single")
    assert run.rc == 2 and "--single" in run.err and ".grd" in run.err


def test_water_in_two_parts(tmp_path):
    """EFDC holds parts side by side (land between them); a Delft3D enclosure has one outer polygon."""
    t = np.linspace(0, 2 * np.pi, 60, endpoint=False)
    src = tmp_path / "two.csv"
    csv(src, [np.c_[3000 * np.cos(t), 1500 * np.sin(t)], np.c_[9000 + 1500 * np.cos(t), 1000 * np.sin(t)]])
    run = mesh(src, "--cells", 2000, "-o", tmp_path / "cell.inp", "-o", tmp_path / "two.npz")
    assert run.rc == 0, run.err
    types, dxdy, _, _ = read_efdc(tmp_path)
    n_cells = sum(g.cells[0] * g.cells[1] for g in read_blocks(tmp_path / "two.npz").blocks)
    assert int((types == 5).sum()) == len(dxdy) == n_cells
    water_columns = (types == 5).any(axis=1)
    assert (np.diff(water_columns.astype(int)) != 0).sum() == 4  # two runs of water columns, land between
    run = mesh(src, "--cells", 2000, "-o", tmp_path / "two.grd", "--single")
    assert run.rc == 2 and "2 parts" in run.err.strip().splitlines()[-1]
    assert not (tmp_path / "two.grd").exists()


def test_a_refusal_names_its_place_in_the_files_coordinates(monkeypatch):
    """The layout's refusal names its place in the grid's CRS once: the local frame's origin was
    added twice (the layout step and the command's guard), so a held-out lake near northing
    5.49e6 was said to fold near 1.098e7."""
    import argparse
    from types import SimpleNamespace

    import meshcore.layout
    from meshcore.cli import mesh_steps
    from meshcore.errors import InvalidInputError, TopologyError

    def refuse(*a, **k):
        raise TopologyError("automatic layout: the blocks fold back near (10.5, -20.25)")

    monkeypatch.setattr(meshcore.layout, "auto_layout", refuse)
    args = argparse.Namespace(outline="lake.kml", layout_option=[], single_space=True)
    frame = SimpleNamespace(origin=(500_000.0, 5_400_000.0), crs="EPSG:32618")
    with pytest.raises(InvalidInputError) as got:
        mesh_steps.guarded(args, frame, lambda: mesh_steps._layout(args, None, 1.0, True, print, frame))
    assert "near (500010.5, 5399979.75)" in str(got.value), got.value
    assert str(got.value).startswith("lake.kml: ")
