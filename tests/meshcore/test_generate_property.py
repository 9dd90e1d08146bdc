"""Property: whatever outline, corners, cells and options a user gives, a run ends well.

Hypothesis draws outlines (star-shaped lakes, random and self-crossing polygons,
collinear runs, duplicate points, either orientation, any scale and offset),
corner choices (``"auto"``, valid or invalid indices), cell counts (valid, zero,
negative, absurd) and options (start grid, curve, clustering, solver method,
iteration cap, tolerance, repair), and runs them through
:func:`meshcore.generate_block` and through ``meshcore generate`` on a case file.
Every run must end in exactly one of:

* a grid without folded cells, reported as converged;
* an honest "not converged" (``converged=False``; exit code 3, grid written);
* one clear :class:`~meshcore.errors.MeshcoreError` (exit code 2, one line on
  stderr naming the place, no output file).

Never a traceback (any other exception, exit code 1), a hang (every loop is
bounded: the suite's timeout would fail the run) or a folded grid reported as
converged.  The CI runs ``MESHCORE_PROPERTY_EXAMPLES`` examples per test
(default 40); set it to a few thousand for a long run.
"""

from __future__ import annotations

import contextlib
import io
import math
import os
import tempfile
import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

import meshcore
from meshcore.cli import main
from meshcore.errors import MeshcoreError, MeshcoreWarning
from meshcore.io import read_grid

EXAMPLES = int(os.environ.get("MESHCORE_PROPERTY_EXAMPLES", "40"))
PROPERTY = settings(
    max_examples=EXAMPLES,
    deadline=None,
    derandomize=os.environ.get("MESHCORE_PROPERTY_SEED") is None,
    database=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large, HealthCheck.filter_too_much],
)


# ---------------------------------------------------------------- strategies
@st.composite
def outlines(draw) -> np.ndarray:
    """A closed outline as a user might give it (or get it wrong)."""
    kind = draw(st.sampled_from(["star"] * 6 + ["rectangle"] * 2 + ["spiky"] * 2 + ["random", "collinear"]))
    n = draw(st.integers(4, 40))
    if kind == "star":
        t = np.sort(np.asarray(draw(st.lists(st.floats(0, 2 * math.pi), min_size=n, max_size=n, unique=True))))
        r = np.asarray(draw(st.lists(st.floats(0.3, 1.0), min_size=n, max_size=n)))
        p = np.c_[r * np.cos(t), r * np.sin(t)]
    elif kind == "random":  # may cross itself
        p = np.asarray(draw(st.lists(st.tuples(st.floats(-1, 1), st.floats(-1, 1)), min_size=n, max_size=n)))
    elif kind == "rectangle":
        w = draw(st.floats(0.05, 20.0))
        k = max(1, n // 4)
        s = np.linspace(0, 1, k, endpoint=False)
        p = np.vstack([np.c_[w * s, 0 * s], np.c_[w + 0 * s, s], np.c_[w * (1 - s), 1 + 0 * s], np.c_[0 * s, 1 - s]])
    elif kind == "collinear":
        x = np.sort(np.asarray(draw(st.lists(st.floats(0, 1), min_size=n, max_size=n))))
        p = np.c_[x, draw(st.floats(-1e-12, 1e-12)) * x]
    else:  # a lake with narrow arms: long spikes between short radii
        t = np.linspace(0, 2 * math.pi, n, endpoint=False)
        r = np.where(np.arange(n) % 2 == 0, 1.0, draw(st.floats(0.02, 0.5)))
        p = np.c_[r * np.cos(t), r * np.sin(t)]
    if draw(st.booleans()):
        p = p[::-1]  # clockwise
    if draw(st.integers(0, 5)) == 0 and len(p) > 2:
        k = draw(st.integers(0, len(p) - 1))
        p = np.insert(p, k, p[k], axis=0)  # a repeated point
    if draw(st.booleans()):
        p = np.vstack([p, p[:1]])  # closing point repeated
    scale = 10.0 ** draw(st.integers(-8, 9))
    offset = np.asarray(draw(st.sampled_from([(0.0, 0.0)] * 3 + [(4.8e5, 5.24e6), (1e5, 1e5), (-3.0, 7.0)])))
    return np.ascontiguousarray(p * scale + offset, dtype=np.float64)


@st.composite
def corner_choices(draw, n: int):
    kind = draw(st.sampled_from(["auto"] * 5 + ["valid"] * 2 + ["any"]))
    if kind == "auto":
        return "auto"
    if kind == "valid" and n >= 4:
        return sorted(draw(st.lists(st.integers(0, n - 1), min_size=4, max_size=4, unique=True)))
    return draw(st.lists(st.integers(-2 * n, 2 * n), min_size=4, max_size=4))


cells_st = st.integers(0, 9).flatmap(
    lambda k: (
        st.tuples(st.integers(1, 48), st.integers(1, 48))
        if k < 8
        else st.tuples(st.integers(-3, 2), st.integers(-3, 48))
        if k == 8
        else st.tuples(st.sampled_from([10_000_000, 2**40, 9223372036854775807]), st.integers(1, 3))
    )
)


@st.composite
def options(draw) -> dict:
    opt: dict = {}
    if draw(st.booleans()):
        opt["initial"] = draw(st.sampled_from(["weighted", "tfi"]))
    if draw(st.booleans()):
        opt["curve"] = draw(st.sampled_from(["linear", "cubic", "catmull-rom"]))
    if draw(st.booleans()):
        opt["method"] = draw(st.sampled_from(["auto", "sor", "multigrid"]))
    if draw(st.integers(0, 3)) == 0:
        opt["max_iterations"] = draw(st.integers(1, 200))
    if draw(st.integers(0, 3)) == 0:
        opt["tolerance"] = draw(st.sampled_from([1e-3, 1e-6, 1e-9]))
    if draw(st.integers(0, 3)) == 0:
        opt["weights"] = (draw(st.floats(0, 1)), draw(st.floats(0, 1)))
    if draw(st.integers(0, 4)) == 0:
        border = draw(st.sampled_from(["bottom", "right", "top", "left"]))
        opt["borders"] = {border: {"distribution": "tanh", "first": draw(st.floats(1e-6, 2.0))}}
    if draw(st.integers(0, 4)) == 0:
        opt["repair"] = draw(st.sampled_from(["auto", "off", "strict"]))
    return opt


# ---------------------------------------------------------------- the property
def _outcome(loop, corners, cells, opts) -> str:
    """Run generate_block; return "grid", "not converged" or "error"; fail on anything else."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", MeshcoreWarning)
            g = meshcore.generate_block(loop=loop, corners=corners, cells=cells, **opts)
    except MeshcoreError as exc:
        msg = str(exc)
        assert msg and "\n" not in msg, msg
        return "error"
    assert np.isfinite(g.x).all() and np.isfinite(g.y).all()
    if not g.converged:
        assert g.info.message, "a grid that did not converge says why"
        return "not converged"
    q = meshcore.quality(g)
    if opts.get("repair") == "off":  # the caller asked for the raw elliptic grid: folds are reported, not hidden
        return "grid"
    assert q.n_folded == 0, f"a converged grid with {q.n_folded} folded cells ({g.info.method}: {g.info.message})"
    return "grid"


@PROPERTY
@given(data=st.data())
def test_generate_block_ends_in_a_grid_an_honest_failure_or_one_error(data):
    loop = data.draw(outlines())
    corners = data.draw(corner_choices(len(loop)))
    cells = data.draw(cells_st)
    opts = data.draw(options())
    event(_outcome(loop, corners, cells, opts))


def _case_text(loop, corners, cells, opts) -> str:
    pts = ", ".join(f"[{float(x)!r}, {float(y)!r}]" for x, y in loop)
    c = "[" + ", ".join(str(int(k)) for k in corners) + "]"
    lines = ["[[blocks]]", 'name = "lake"', f"cells = [{int(cells[0])}, {int(cells[1])}]"]
    if "initial" in opts:
        lines.append(f'initial = "{opts["initial"]}"')
    if "curve" in opts:
        lines.append(f'curve = "{opts["curve"]}"')
    lines += ["[blocks.boundary]", f"points = [{pts}]", f"corners = {c}"]
    solver = {k: opts[k] for k in ("method", "max_iterations", "tolerance", "repair") if k in opts}
    if solver:
        lines.append("[solver]")
        lines += [f"{k} = {v!r}" if not isinstance(v, str) else f'{k} = "{v}"' for k, v in solver.items()]
    return "\n".join(lines) + "\n"


@PROPERTY
@given(data=st.data())
def test_cli_generate_exit_codes_are_honest(data):
    loop = data.draw(outlines())
    corners = data.draw(corner_choices(len(loop)))
    cells = data.draw(cells_st)
    keep = ("initial", "curve", "method", "max_iterations", "repair")
    opts = {k: v for k, v in data.draw(options()).items() if k in keep}
    if corners == "auto":  # case files take indices: pick them as the app and `meshcore import` do
        try:
            corners = meshcore.choose_corners(loop)
        except MeshcoreError:
            corners = [0, 1, 2, 3]
    with tempfile.TemporaryDirectory() as d:
        case, out = Path(d) / "lake.toml", Path(d) / "lake.vts"
        case.write_text(_case_text(loop, corners, cells, opts))
        err = io.StringIO()
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()), warnings.catch_warnings():
            warnings.simplefilter("ignore", MeshcoreWarning)
            rc = main(["generate", str(case), "-o", str(out), "-q"])
        msg = err.getvalue()
        event(f"exit {rc}")
        assert rc in (0, 2, 3), msg
        assert "Traceback" not in msg
        if rc == 2:
            lines = [ln for ln in msg.splitlines() if ln.startswith("meshcore generate: error:")]
            assert len(lines) == 1, msg
            assert not out.exists()
            return
        (g,) = read_grid(out)  # written in both other cases
        if rc == 3:
            assert "did not converge" in msg or "folded cell(s)" in msg
            return
        assert meshcore.quality(g).n_folded == 0


# ------------------------------------------------------------- bad command lines
WORDS = st.sampled_from(
    [
        "generate",
        "quality",
        "convert",
        "import",
        "examples",
        "-o",
        "--png",
        "--method",
        "--tolerance",
        "--max-iterations",
        "--threads",
        "--corners",
        "--cells",
        "--crs",
        "--source-crs",
        "--columns",
        "--polyline",
        "--border-name",
        "--strict",
        "--json",
        "--format",
        "--input-format",
        "--mode",
        "--lonlat",
        "-q",
        "--ignore-islands",
        "{case}",
        "{points}",
        "{grid}",
        "{out}",
        "{dir}",
        "{missing}",
        "0",
        "-1",
        "2",
        "999999999999999999999",
        "nan",
        "inf",
        "1e308",
        "EPSG:999999",
        "EPSG:32632",
        "auto",
        "bottom=inlet",
        "=",
        "x",
        "",
        "multigrid",
        "sor",
        "fortran",
        "bottle-coarse",
        "{dir}/nodir/x.vts",
        "{dir}/x.png",
        "{dir}/x.foo",
        "{dir}/x.cgns",
        "{dir}/x.su2",
        "{dir}/x.vtm",
    ]
)


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    from tests.conftest import DATA, ROOT

    d = tmp_path_factory.mktemp("cli")
    case = ROOT / "resources" / "examples" / "bottle-coarse.toml"
    grid = d / "g.vts"
    assert main(["generate", str(case), "-o", str(grid), "-q"]) == 0
    return {"case": str(case), "points": str(DATA / "windermere_sparse.csv"), "grid": str(grid)}


@settings(PROPERTY, max_examples=max(EXAMPLES, 60))
@given(words=st.lists(WORDS, min_size=1, max_size=8))
def test_bad_command_lines_give_one_line(files, words):
    with tempfile.TemporaryDirectory() as d:
        subs = dict(files, out=f"{d}/out.vts", dir=d, missing=f"{d}/missing.kml")
        argv = [w.format(**subs) for w in words]
        err = io.StringIO()
        with (
            contextlib.redirect_stderr(err),
            contextlib.redirect_stdout(io.StringIO()),
            warnings.catch_warnings(),
            np.errstate(all="ignore"),
        ):
            warnings.simplefilter("ignore")
            rc = main(argv)
        msg = err.getvalue()
        event(f"exit {rc}")
        assert rc in (0, 2, 3), (argv, msg)
        if rc == 2:
            errors = [ln for ln in msg.splitlines() if ": error:" in ln]
            assert len(errors) == 1 or msg.startswith("usage:"), (argv, msg)
