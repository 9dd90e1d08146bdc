"""Case files and the command line, driven as a user would."""

from __future__ import annotations

import subprocess
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest

import meshcore
from meshcore.case import dumps_case, generate_case, load_case, loads_case, save_case
from meshcore.cli import main
from meshcore.cli.examples import example_path, list_examples
from meshcore.errors import CaseFileError

PAPER = [
    "rectangle-cutout-coarse",
    "rectangle-cutout-fine",
    "two-circles-coarse",
    "two-circles-fine",
    "bottle-coarse",
    "bottle-fine",
]

MINI = """
title = "mini"
[[blocks]]
name = "b"
cells = [4, 3]
[blocks.boundary]
bottom = [[0, 0], [2, 0]]
right = [[2, 0], [2, 1]]
top = [[0, 1], [2, 1]]
left = [[0, 0], [0, 1]]
"""


def test_paper_examples_are_bundled():
    names = list_examples()
    for n in [*PAPER, "annulus-sector"]:
        assert n in names


@pytest.mark.parametrize("name", sorted(set(PAPER) | {"annulus-sector"}))
def test_every_bundled_example_runs_through_the_cli(name, tmp_path, capsys):
    assert main(["examples", name, str(tmp_path)]) == 0
    case = tmp_path / f"{name}.toml"
    out = tmp_path / f"{name}.vts"
    assert main(["generate", str(case), "-o", str(out), "-q"]) == 0
    grid = meshcore.io.read_grid(out)[0]
    rep = meshcore.quality(grid)
    assert rep.n_folded == 0
    c = load_case(case)
    if c.blocks[0].cells:
        assert grid.cells == c.blocks[0].cells


def test_paper_cases_match_the_tables():
    cells = {n: load_case(example_path(n)).blocks[0].cells for n in PAPER}
    assert cells["rectangle-cutout-coarse"] == (15, 6) and cells["rectangle-cutout-fine"] == (30, 12)
    assert cells["two-circles-coarse"] == (30, 6) and cells["two-circles-fine"] == (40, 8)
    assert cells["bottle-coarse"] == (6, 15) and cells["bottle-fine"] == (12, 30)
    b = load_case(example_path("bottle-coarse")).blocks[0]
    assert (len(b.boundary[0]), len(b.boundary[3])) == (4, 10)
    assert b.weights == (1.0, 0.5)
    rc = load_case(example_path("rectangle-cutout-coarse")).blocks[0]
    assert (len(rc.boundary[0]), len(rc.boundary[3])) == (10, 4)
    assert rc.weights == (pytest.approx(0.1), 0.0)  # p24 = (0.9, 1.0)
    tc = load_case(example_path("two-circles-coarse")).blocks[0]
    assert (len(tc.boundary[0]), len(tc.boundary[3])) == (20, 4)


def test_annulus_example_is_close_to_exact():
    c = load_case(example_path("annulus-sector"))
    g = generate_case(c)[0]
    r = np.hypot(g.x, g.y)
    th = np.arctan2(g.y, g.x)
    # interior nodes lie on the exact log-polar lattice to discretisation accuracy
    ni, nj = g.cells
    r_exact = 4.0 ** (np.arange(ni + 1) / ni)
    th_exact = np.linspace(0, np.pi / 2, nj + 1)
    assert np.max(np.abs(r - r_exact[:, None])) < 5e-3 * 4
    assert np.max(np.abs(th - th_exact[None, :])) < 5e-3


def test_case_round_trip(tmp_path):
    c = load_case(example_path("bottle-fine"))
    p = save_case(c, tmp_path / "copy.toml")
    c2 = load_case(p)
    assert c2.blocks[0].cells == c.blocks[0].cells
    assert c2.blocks[0].weights == c.blocks[0].weights
    for k in range(4):
        np.testing.assert_array_equal(c2.blocks[0].boundary[k], c.blocks[0].boundary[k])
    g1, g2 = generate_case(c)[0], generate_case(c2)[0]
    np.testing.assert_array_equal(g1.x, g2.x)
    assert tomllib.loads(dumps_case(c2))["blocks"][0]["name"] == "bottle"


def test_points_file_and_corners(tmp_path):
    pts = np.array([[0, 0], [1, 0], [2, 0], [2, 1], [1, 1], [0, 1]], float)
    np.savetxt(tmp_path / "loop.csv", pts, delimiter=",", header="x,y", comments="")
    (tmp_path / "c.toml").write_text(
        '[[blocks]]\ncells = [6, 3]\n[blocks.boundary]\npoints = "loop.csv"\ncorners = [0, 2, 3, 5]\n'
    )
    g = generate_case(load_case(tmp_path / "c.toml"))[0]
    assert g.cells == (6, 3) and g.converged


@pytest.mark.parametrize(
    ("text", "match"),
    [
        (MINI.replace('title = "mini"', 'titel = "mini"'), r"unknown key 'titel'; valid keys: .*title"),
        (MINI.replace("cells = [4, 3]", "cels = [4, 3]"), r"block 'b'|unknown key 'cels'"),
        (MINI + "[solver]\nomega = 2.5\n", r"\[solver\]: omega must be in \(0, 2\)"),
        (MINI + "[solver]\ntol = 1e-3\n", r"\[solver\]: unknown key 'tol'"),
        (MINI.replace("bottom = [[0, 0], [2, 0]]\n", ""), r"missing border\(s\) bottom"),
        (
            MINI + "[blocks.borders.bottom]\ndistribution = 'tanh'\nfrist = 0.1\n",
            r"borders.bottom: unknown key 'frist'",
        ),
        (MINI.replace("cells = [4, 3]", "cells = [4]"), r"cells: expected a pair"),
        ("[[blocks]]\nname = 'x'\n", r"missing \[blocks.boundary\]"),
        ("title = 'x'\n", r"needs at least one \[\[blocks\]\]"),
        ("title = \n", r"invalid TOML"),
    ],
)
def test_case_errors_name_the_key(text, match):
    with pytest.raises(CaseFileError, match=match):
        loads_case(text, source="t.toml")


def test_missing_point_file_is_named(tmp_path):
    (tmp_path / "c.toml").write_text('[[blocks]]\n[blocks.boundary]\npoints = "nope.csv"\ncorners = [0, 1, 2, 3]\n')
    with pytest.raises(CaseFileError, match=r"point file .*nope.csv.* not found"):
        load_case(tmp_path / "c.toml")


def test_cli_bad_input_exit_2_one_line_no_partial_output(tmp_path):
    case = tmp_path / "bad.toml"
    case.write_text(MINI.replace("top = [[0, 1], [2, 1]]", "top = [[0, 1.5], [2, 1]]"))
    out = tmp_path / "out.vts"
    proc = subprocess.run(
        [sys.executable, "-m", "meshcore", "generate", str(case), "-o", str(out)],
        capture_output=True,
        text=True,
        cwd=Path(__file__).resolve().parents[2],
    )
    assert proc.returncode == 2
    err = proc.stderr.strip().splitlines()
    assert len(err) == 1 and "corner mismatch" in err[0] and "Traceback" not in proc.stderr
    assert not out.exists()
    assert list(tmp_path.iterdir()) == [case]


def test_cli_not_converged_exit_3(tmp_path, capsys):
    assert main(["examples", "bottle-fine", str(tmp_path)]) == 0
    rc = main(
        [
            "generate",
            str(tmp_path / "bottle-fine.toml"),
            "--max-iterations",
            "2",
            "--method",
            "sor",
            "-o",
            str(tmp_path / "o.npz"),
            "-q",
        ]
    )
    assert rc == 3
    assert (tmp_path / "o.npz").exists()  # the unconverged grid is still written, and said so
    assert "did not converge" in capsys.readouterr().err


def test_cli_png_and_quality(tmp_path, capsys):
    main(["examples", "two-circles-coarse", str(tmp_path)])
    assert (
        main(
            [
                "generate",
                str(tmp_path / "two-circles-coarse.toml"),
                "-o",
                str(tmp_path / "g.xyz"),
                "--png",
                str(tmp_path / "g.png"),
                "-q",
            ]
        )
        == 0
    )
    assert (tmp_path / "g.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    capsys.readouterr()
    assert main(["quality", str(tmp_path / "g.xyz")]) == 0
    out = capsys.readouterr().out
    assert "folded cells" in out and "| 0 " in out


def test_examples_listing(capsys):
    assert main(["examples"]) == 0
    assert "bottle-fine" in capsys.readouterr().out.split()
    assert main(["examples", "no-such-case", "x"]) == 2


def test_import_meshcore_does_not_import_qt():
    code = (
        "import sys, meshcore, meshcore.case, meshcore.cli;"
        "bad=[m for m in ('PySide6','pyqtgraph','superqt','psygnal','matplotlib') if m in sys.modules];"
        "print(bad); sys.exit(1 if bad else 0)"
    )
    proc = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, cwd=Path(__file__).resolve().parents[2]
    )
    assert proc.returncode == 0, proc.stdout + proc.stderr


def test_lonlat_point_file_in_a_case_is_projected(tmp_path):
    """A case that points at a lon/lat CSV is meshed in metres (UTM of the centroid, local origin)."""
    import shutil

    from tests.conftest import DATA

    shutil.copy(DATA / "windermere_sparse.csv", tmp_path / "lake.csv")
    (tmp_path / "c.toml").write_text(
        '[[blocks]]\ncells = [40, 6]\n[blocks.boundary]\npoints = "lake.csv"\ncorners = [0, 10, 20, 30]\n'
    )
    case = load_case(tmp_path / "c.toml")
    assert case.crs["crs"] == "EPSG:32630"  # Windermere is in UTM zone 30N
    loop = case.blocks[0].points
    assert 10_000 < np.ptp(loop[:, 1]) < 20_000  # ~14 km long, in metres, not degrees
    assert np.abs(loop).max() < 1e5  # relative to a local origin
    # saved and re-loaded, the case keeps its frame and gives the same grid
    p = save_case(case, tmp_path / "saved.toml")
    again = load_case(p)
    assert again.crs["origin"] == case.crs["origin"]
    g1, g2 = generate_case(case)[0], generate_case(again)[0]
    np.testing.assert_allclose(g1.x, g2.x, atol=1e-6)


def test_solver_repair_key(tmp_path):
    text = example_path("rectangle-cutout-coarse").read_text() + '\n[solver]\nrepair = "off"\n'
    c = loads_case(text, source="t.toml")
    assert c.repair == "off"
    off = generate_case(c)[0]
    on = generate_case(c.replaced(solver=c.solver.replaced(repair="auto")))[0]
    assert meshcore.quality(off).n_nonconvex > 0  # Winslow leaves non-convex cells at the cutout
    assert meshcore.quality(on).n_nonconvex == 0 and "foldfree" in on.info.method
    assert loads_case(dumps_case(c), source="t2").repair == "off"
    with pytest.raises(CaseFileError, match="repair must be one of auto, strict, off"):
        loads_case(example_path("bottle-fine").read_text() + '\n[solver]\nrepair = "maybe"\n', source="t")


def test_examples_copy_keeps_data_inside_dest(tmp_path, capsys):
    dest = tmp_path / "dest"
    assert main(["examples", "shasta-multiblock-coarse", str(dest)]) == 0
    files = sorted(p.name for p in dest.iterdir())
    assert "shasta_lake.csv" in files and any(f.startswith("LICENSE") for f in files)
    assert not (tmp_path / "lakes").exists()  # nothing written outside DEST
    assert main(["generate", str(dest / "shasta-multiblock-coarse.toml"), "-o", str(dest / "s.vtm"), "-q"]) == 0
