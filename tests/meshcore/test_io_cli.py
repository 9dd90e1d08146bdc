"""``meshcore import`` and ``meshcore convert``, end to end through the CLI."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from meshcore.case import load_case
from meshcore.cli import main
from meshcore.crs import frame_from_case
from meshcore.io import read_blocks
from tests.conftest import DATA, ROOT


def test_import_generate_convert_a_lake(tmp_path, capsys):
    pytest.importorskip("pyproj")
    case = tmp_path / "zurich.toml"
    assert (
        main(
            [
                "import",
                str(DATA / "lake_zurich_sparse.kmz"),
                "-o",
                str(case),
                "--border-name",
                "left=inlet",
                "--border-name",
                "right=outlet",
                "--cells",
                "30",
                "6",
            ]
        )
        == 0
    )
    out = capsys.readouterr().out
    assert "EPSG:32632" in out and "zurich.toml" in out
    c = load_case(case)
    frame = frame_from_case(c)
    assert frame.crs == "EPSG:32632" and frame.source_crs == "EPSG:4326"
    assert c.blocks[0].cells == (30, 6) and len(c.blocks[0].points) == 40
    assert np.abs(c.blocks[0].points).max() < 2e4  # local coordinates
    # generate → .vts keeps the CRS and the origin
    vts = tmp_path / "zurich.vts"
    assert main(["generate", str(case), "-o", str(vts), "-q"]) == 0
    gs = read_blocks(vts)
    assert gs.frame.crs == "EPSG:32632" and gs.frame.origin == frame.origin
    assert gs.blocks[0].names == {"left": "inlet", "right": "outlet"}
    # convert → CGNS → SGRID → PLOT3D: the world coordinates survive
    for suffix in (".cgns", ".nc", ".xyz", ".msh", ".su2", ".grd", ".csv", ".png"):
        target = tmp_path / f"zurich{suffix}"
        assert main(["convert", str(vts if suffix != ".xyz" else tmp_path / "zurich.nc"), str(target)]) == 0, suffix
    g0 = gs.blocks[0]
    for suffix in (".cgns", ".nc", ".grd", ".csv"):
        back = read_blocks(tmp_path / f"zurich{suffix}")
        X, Y = back.world(0)
        np.testing.assert_allclose(X, g0.x + frame.origin[0], rtol=1e-15, atol=1e-9)
        np.testing.assert_allclose(Y, g0.y + frame.origin[1], rtol=1e-15, atol=1e-9)


def test_import_csv_with_columns_and_no_projection(tmp_path):
    f = tmp_path / "pts.csv"
    ring = np.array([[0, 0], [4, 0], [8, 0], [8, 2], [8, 4], [4, 4], [0, 4], [0, 2]], float)
    f.write_text("id;x;y\n" + "".join(f"{k};{a};{b}\n" for k, (a, b) in enumerate(ring)))
    case = tmp_path / "c.toml"
    assert (
        main(
            ["import", str(f), "-o", str(case), "--crs", "none", "--columns", "x", "y", "--corners", "0", "2", "4", "6"]
        )
        == 0
    )
    c = load_case(case)
    np.testing.assert_array_equal(c.blocks[0].points, ring)
    assert c.blocks[0].corners == (0, 2, 4, 6)
    assert frame_from_case(c).crs is None


def test_cli_bad_input_exit_codes(tmp_path, capsys):
    empty = tmp_path / "empty.kml"
    empty.write_text("")
    assert main(["import", str(empty), "-o", str(tmp_path / "x.toml")]) == 2
    err = capsys.readouterr().err
    assert "empty.kml" in err and err.count("\n") == 1
    assert not (tmp_path / "x.toml").exists()
    assert main(["convert", str(tmp_path / "nope.vts"), str(tmp_path / "o.cgns")]) == 2
    assert "no such file" in capsys.readouterr().err
    assert not (tmp_path / "o.cgns").exists()


def test_import_meshcore_stays_light():
    """``import meshcore`` (and meshcore.io) must not pull in the heavy optional readers."""
    code = (
        "import sys, meshcore, meshcore.io, meshcore.crs; "
        "heavy = {'vtk', 'gmsh', 'h5py', 'netCDF4', 'pyproj', 'ezdxf', 'shapefile', "
        "'matplotlib', 'meshio', 'defusedxml'}; "
        "print(sorted(heavy & set(sys.modules)))"
    )
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, check=True)
    assert r.stdout.strip() == "[]"


def test_top_level_reexports(tmp_path):
    import meshcore

    ps = meshcore.read_points(DATA / "windermere_sparse.csv")
    assert isinstance(ps, meshcore.PointSet) and ps.crs == "EPSG:4326"
    s, t = np.meshgrid(np.linspace(0, 1, 3), np.linspace(0, 1, 2), indexing="ij")
    f = meshcore.write(tmp_path / "g.vts", meshcore.StructuredGrid(s, t))
    assert meshcore.read_grid(f)[0].shape == (3, 2)


SUFFIXES = [".xyz", ".vts", ".vtm", ".npz", ".csv", ".cgns", ".msh", ".su2", ".grd", ".nc", ".png", ".svg", ".pdf"]


def test_generate_writes_every_format(tmp_path, capsys):
    pytest.importorskip("pyproj")
    case = tmp_path / "w.toml"
    assert main(["import", str(DATA / "windermere_sparse.csv"), "-o", str(case), "--cells", "16", "4"]) == 0
    frame = frame_from_case(load_case(case))
    for suffix in SUFFIXES:
        out = tmp_path / f"w{suffix}"
        assert main(["generate", str(case), "-o", str(out), "-q"]) == 0, suffix
        assert out.stat().st_size > 0
        if suffix in (".vts", ".vtm", ".npz", ".csv", ".cgns", ".nc", ".grd"):
            gs = read_blocks(out)
            assert gs.frame.crs == frame.crs == "EPSG:32630", suffix
            assert gs.blocks[0].cells == (16, 4)
    capsys.readouterr()
