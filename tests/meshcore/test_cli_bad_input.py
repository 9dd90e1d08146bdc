"""The command line with bad input: exit 2 and one line naming the place — never a hang,
a traceback or an output file left behind."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

import meshcore
from meshcore.case import load_case
from meshcore.cli import main
from tests.conftest import DATA, ROOT

RING = np.array([[0, 0], [4, 0], [8, 0], [8, 2], [8, 4], [4, 4], [0, 4], [0, 2]], float)


@pytest.fixture
def ring_csv(tmp_path):
    f = tmp_path / "ring.csv"
    f.write_text("x,y\n" + "".join(f"{a},{b}\n" for a, b in RING))
    return f


def _bad(capsys, argv, *needles):
    rc = main([str(a) for a in argv])
    err = capsys.readouterr().err
    assert rc == 2, err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    for n in needles:
        assert n in err, (n, err)
    return err


@pytest.mark.parametrize(
    ("corners", "needle"),
    [
        (["0", "2", "4", "999"], "index 999 is out of range"),  # hung: an unguarded walk around the loop
        (["0", "2", "4", "-20"], "index -20 is out of range"),
        (["0", "4", "2", "6"], "not in cyclic order"),
        (["0", "2", "2", "6"], "4 different points"),
    ],
)
def test_import_refuses_bad_corners_where_typed(tmp_path, capsys, ring_csv, corners, needle):
    out = tmp_path / "c.toml"
    argv = ["import", ring_csv, "-o", out, "--crs", "none", "--corners", *corners]
    _bad(capsys, argv, "ring.csv", "--corners", needle)
    assert not out.exists()


def test_import_negative_corner_indices_count_from_the_end(tmp_path, capsys, ring_csv):
    out = tmp_path / "c.toml"
    assert main(["import", str(ring_csv), "-o", str(out), "--crs", "none", "--corners", "0", "2", "4", "-2"]) == 0
    assert load_case(out).blocks[0].corners == (0, 2, 4, 6)
    capsys.readouterr()


@pytest.mark.parametrize(
    ("cells", "needle"),
    [
        (["0", "4"], "--cells NI must be >= 1, got 0"),
        (["8", "-3"], "--cells NJ must be >= 1, got -3"),
        (["10000000", "10000000"], "--cells: 10000000 × 10000000 cells make"),
        (["9223372036854775807", "2"], "--cells: 9223372036854775807 × 2 cells make"),
    ],
)
def test_import_refuses_bad_cells_where_typed(tmp_path, capsys, ring_csv, cells, needle):
    out = tmp_path / "c.toml"
    _bad(capsys, ["import", ring_csv, "-o", out, "--crs", "none", "--cells", *cells], needle)
    assert not out.exists()


def test_import_unknown_crs_is_one_line(tmp_path, capsys):
    out = tmp_path / "c.toml"
    argv = ["import", DATA / "lake_zurich_sparse.kml", "-o", out, "--crs", "EPSG:999999"]
    _bad(capsys, argv, "unknown CRS 'EPSG:999999'")
    assert not out.exists()


def test_case_file_with_unknown_crs_is_refused(tmp_path, capsys, ring_csv):
    case = tmp_path / "c.toml"
    assert main(["import", str(ring_csv), "-o", str(case), "--crs", "none", "--cells", "8", "4"]) == 0
    text = case.read_text()
    case.write_text(text.replace("[crs]", '[crs]\ncrs = "EPSG:999999"'))
    assert "EPSG:999999" in case.read_text()
    capsys.readouterr()
    out = tmp_path / "g.vts"
    _bad(capsys, ["generate", case, "-o", out, "-q"], "c.toml", "unknown CRS 'EPSG:999999'")
    assert not out.exists()


def test_import_does_not_drop_islands_silently(tmp_path, capsys):
    lake = tmp_path / "lake.kml"
    lake.write_text(
        '<kml xmlns="http://www.opengis.net/kml/2.2"><Placemark><name>Lake</name><Polygon>'
        "<outerBoundaryIs><LinearRing><coordinates>9,47 9.02,47 9.02,47.01 9,47.01 9,47</coordinates>"
        "</LinearRing></outerBoundaryIs><innerBoundaryIs><LinearRing><coordinates>"
        "9.008,47.004 9.012,47.004 9.012,47.006 9.008,47.006 9.008,47.004</coordinates></LinearRing>"
        "</innerBoundaryIs></Polygon></Placemark></kml>"
    )
    out = tmp_path / "c.toml"
    _bad(capsys, ["import", lake, "-o", out], "lake.kml", "1 island(s)", "'Lake hole 1'", "--ignore-islands")
    assert not out.exists()
    assert main(["import", str(lake), "-o", str(out), "--ignore-islands"]) == 0
    err = capsys.readouterr().err
    assert "warning" in err and "island" in err
    assert len(load_case(out).blocks[0].points) == 4


def test_import_too_few_points_names_the_file(tmp_path, capsys):
    f = tmp_path / "tri.csv"
    f.write_text("x,y\n0,0\n1,0\n1,1\n0,0\n")
    _bad(capsys, ["import", f, "-o", tmp_path / "c.toml", "--crs", "none"], "tri.csv", "needs at least 4 points")


@pytest.mark.parametrize(
    ("extra", "needle"),
    [
        (["-o", "{d}/out.vts", "--png", "{d}/nodir/fig.png"], "--png"),
        (["-o", "{d}/nodir/out.vts"], "does not exist"),
        (["-o", "{d}/out.vts", "--png", "{d}/fig.vts"], "expected a figure file"),
        (["-o", "{d}/out.foo"], "cannot write .foo files"),
        (["-o", "{d}"], "is a folder"),
    ],
)
def test_generate_checks_every_output_before_solving(tmp_path, capsys, extra, needle):
    case = ROOT / "resources" / "examples" / "bottle-coarse.toml"
    argv = ["generate", case, "-q", *(a.format(d=tmp_path) for a in extra)]
    _bad(capsys, argv, needle)
    assert sorted(p.name for p in tmp_path.iterdir()) == []  # out.vts is not written


def test_generate_multiblock_into_a_one_block_format(tmp_path, capsys):
    case = ROOT / "resources" / "examples" / "confluence-multiblock.toml"
    _bad(capsys, ["generate", case, "-o", tmp_path / "m.vts", "-q"], "holds one block")
    assert list(tmp_path.iterdir()) == []


def test_missing_optional_writer_is_one_line_naming_the_extra(tmp_path, capsys, monkeypatch):
    import importlib.util

    from meshcore import StructuredGrid
    from meshcore.io import write

    s, t = np.meshgrid(np.linspace(0, 1, 4), np.linspace(0, 1, 3), indexing="ij")
    src = write(tmp_path / "g.vts", StructuredGrid(s, t))
    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec", lambda name, *a: None if name == "h5py" else real(name, *a))
    _bad(capsys, ["convert", src, tmp_path / "g.cgns"], "g.cgns", "h5py", "pip install 'gcmesh[io]'")
    case = ROOT / "resources" / "examples" / "bottle-coarse.toml"
    _bad(capsys, ["generate", case, "-o", tmp_path / "b.cgns", "-q"], "gcmesh[io]")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["g.vts"]


def test_default_install_does_the_main_jobs():
    """`pip install gcmesh` (no extras): the app and every lake-file reader need only default dependencies."""
    import tomllib

    deps = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["dependencies"]
    names = {d.split(">")[0].split("<")[0].split("=")[0].split("[")[0].strip().lower() for d in deps}
    for need in ("pyproj", "defusedxml", "pyshp", "ezdxf", "pyside6-essentials", "pyqtgraph", "superqt", "psygnal"):
        assert need in names, need
    # and with everything outside the default dependencies hidden, lake files are read and the app starts
    hide = ["h5py", "netCDF4", "matplotlib", "meshio", "vtk", "gmsh", "hypothesis", "meshkernel"]
    code = f"""
import importlib.abc, sys
class Hide(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] in {hide!r}:
            raise ModuleNotFoundError(name)
sys.meta_path.insert(0, Hide())
from meshcore.cli import main
for f in ("lake_zurich_sparse.kml", "lake_zurich_sparse.kmz", "lake_zurich_sparse.geojson",
          "windermere_sparse.shp", "lake_zurich_sparse_utm32.dxf", "lake_zurich_sparse.csv"):
    out = sys.argv[1] + "/" + f + ".toml"
    assert main(["import", {str(DATA)!r} + "/" + f, "-o", out, "--cells", "12", "4"]) == 0, f
assert main(["generate", sys.argv[1] + "/lake_zurich_sparse.kml.toml", "-o", sys.argv[1] + "/z.vts", "-q"]) == 0
from PySide6 import QtWidgets
app = QtWidgets.QApplication([])
from app.main_window import MainWindow
w = MainWindow(restore_layout=False)
print("ok")
"""
    import tempfile

    with tempfile.TemporaryDirectory() as d:
        r = subprocess.run([sys.executable, "-c", code, d], capture_output=True, text=True, cwd=ROOT, timeout=600)
    assert r.returncode == 0 and r.stdout.strip().endswith("ok"), r.stderr[-3000:]


def test_a_folded_grid_is_never_exit_0(tmp_path, capsys):
    """With repair = "off" the elliptic grid keeps its folded cell: written, but exit 3 and said so."""
    pts = [[0.848, 0.088], [0.196, 0.051], [-0.11, 0.879], [-0.218, -0.061], [-0.614, -0.487]]
    pts += [[-0.222, -0.258], [-0.114, -0.883], [0.245, -0.584], [0.375, -0.229], [0.494, -0.214]]
    case = tmp_path / "fold.toml"
    case.write_text(
        f"[[blocks]]\nname = 'f'\ncells = [12, 12]\n[blocks.boundary]\npoints = {pts}\ncorners = [0, 1, 2, 8]\n"
        "[solver]\nrepair = 'off'\n"
    )
    out = tmp_path / "f.vts"
    assert main(["generate", str(case), "-o", str(out), "-q"]) == 3
    assert "1 folded cell(s)" in capsys.readouterr().err
    assert out.exists()
    case.write_text(case.read_text().replace("repair = 'off'", "repair = 'auto'"))
    assert main(["generate", str(case), "-o", str(out), "-q"]) == 0
    capsys.readouterr()


@pytest.mark.parametrize(
    "argv",
    [["generate"], ["import", "x.kml", "--corners", "1", "2"], ["bogus"], ["generate", "c.toml", "--threads", "x"]],
)
def test_usage_errors_are_one_line_exit_2(capsys, argv):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and ": error: " in err and "--help" in err


def test_an_internal_error_is_one_line_exit_1(capsys, monkeypatch, tmp_path):
    from meshcore.cli import quality

    def boom(args):
        raise TypeError("unexpected")

    monkeypatch.setattr(quality, "run", boom)
    assert main(["quality", str(tmp_path / "g.vts")]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "internal error: TypeError: unexpected" in err and "MESHCORE_DEBUG" in err
    monkeypatch.setenv("MESHCORE_DEBUG", "1")
    with pytest.raises(TypeError):
        main(["quality", str(tmp_path / "g.vts")])


def test_whole_numbers_written_as_floats_are_counts(tmp_path, capsys):
    """`max_iterations = 1e3` in a case file (TOML reads a float) was an internal error (exit 1)
    in the solver's loop; a whole number is a count, a fraction is one clear error."""
    case = ROOT / "resources" / "examples" / "bottle-coarse.toml"
    text = case.read_text().replace("[[blocks]]", "[solver]\nmax_iterations = 1e3\nthreads = 1.0\n[[blocks]]", 1)
    (tmp_path / "c.toml").write_text(text)
    assert main(["generate", str(tmp_path / "c.toml"), "-o", str(tmp_path / "c.vts"), "-q"]) in (0, 3)
    spec = meshcore.SolverSpec(max_iterations=1e3, threads=1.0)
    assert (spec.max_iterations, spec.threads) == (1000, 1) and type(spec.config().max_iterations) is int
    (tmp_path / "c.toml").write_text(text.replace("1e3", "10.5"))
    assert main(["generate", str(tmp_path / "c.toml"), "-q"]) == 2
    assert "max_iterations must be an integer, got 10.5" in capsys.readouterr().err


def test_the_command_exits_without_the_teardown_but_as_a_normal_exit(tmp_path):
    """``python -m meshcore`` (and the console script) end with ``os._exit`` after :func:`main`:
    the exit code is main's, what was printed reaches the pipe, the atexit functions run."""
    code = (
        "import atexit, sys\n"
        "atexit.register(lambda: print('atexit ran', file=sys.stderr))\n"
        "sys.argv = ['meshcore'] + sys.argv[1:]\n"
        "from meshcore.cli import console\n"
        "print('before', end='')\n"  # buffered: flushed by console(), not by a teardown
        "console()\n"
        "print('never')\n"
    )

    def run(*argv: str) -> subprocess.CompletedProcess:
        return subprocess.run([sys.executable, *argv], capture_output=True, text=True, cwd=ROOT, timeout=300)

    ok = run("-c", code, "--version")
    assert ok.returncode == 0
    assert ok.stdout.startswith("before") and "meshcore " in ok.stdout and "never" not in ok.stdout
    assert "atexit ran" in ok.stderr
    bad = run("-c", code, "mesh", str(tmp_path / "missing.csv"), "-o", str(tmp_path / "g.vtm"))
    assert bad.returncode == 2 and "missing.csv" in bad.stderr and "atexit ran" in bad.stderr
    assert not list(tmp_path.iterdir())
    module = run("-m", "meshcore", "--version")
    assert module.returncode == 0 and module.stdout.startswith("meshcore ")
