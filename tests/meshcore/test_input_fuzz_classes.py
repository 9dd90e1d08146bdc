"""The classes of bad input that ``benchmarks/input_fuzz.py`` found badly handled, one test each:
real files written to tmp_path and read through the real readers and the command line."""

from __future__ import annotations

import json

import numpy as np
import pytest

from meshcore.cli import main
from meshcore.errors import InvalidInputError, ReadError
from meshcore.io import read_points
from meshcore.layout.polygon import water_polygon


def _retrace(n: int) -> np.ndarray:
    """A ring that goes out along a wavy path of ``n`` points and comes back the same way."""
    t = np.linspace(0.0, 3.0, n)
    path = np.column_stack([1000 * t, 200 * np.sin(5 * t)])
    return np.vstack([path, path[-2:0:-1]])


@pytest.mark.parametrize("n", [12, 400, 5000])
def test_a_ring_that_retraces_itself_is_named_as_such(n):
    """Was: dropping one tip per round (5000 points: seconds, 40 000: a minute, 10^5: a hang), then
    "crosses itself: the edge from point 1 to 2 …" about points of what was left."""
    with pytest.raises(InvalidInputError, match="comes back along itself, enclosing no water") as e:
        water_polygon(_retrace(n))
    assert "near (0, 0)" in str(e.value) and "near (3000, 130.058)" in str(e.value)  # the path's two ends


@pytest.mark.parametrize("depth", [3, 40])
@pytest.mark.parametrize("shift", [0, 3, 50])
def test_a_deep_spike_is_dropped_wherever_the_ring_starts(depth, shift):
    """A spike retraced ``depth`` points deep (past the rounds that drop tips at once) goes, with a note,
    and the ring keeps the order it had (here starting anywhere, the seam inside the spike too)."""
    sq = np.array([[0, 0], [1000, 0], [1000, 1000], [0, 1000.0]])
    spike = np.column_stack([1000 + 10 * np.arange(1, depth + 1), np.full(depth, 500.0)])
    ring = np.vstack([sq[:2], [[1000, 500]], spike, spike[-2::-1], [[1000, 500]], sq[2:]])
    ring = np.roll(ring, -shift, axis=0)
    poly, notes = water_polygon(ring)
    assert poly.area == pytest.approx(1e6)
    assert len(poly.exterior.coords) == 6  # the square and the spike's foot on its side
    assert any("straight back" in n for n in notes)


def test_a_retracing_outline_through_the_cli_is_exit_2(tmp_path, capsys):
    f = tmp_path / "back.csv"
    f.write_text("x,y\n" + "".join(f"{x},{y}\n" for x, y in _retrace(3000)))
    out = tmp_path / "g.vtm"
    assert main(["mesh", str(f), "--cells", "100", "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert "back.csv" in err and "comes back along itself" in err and err.count("\n") == 1, err
    assert not out.exists()


def _geojson_with_crs(tmp_path, name: str):
    ring = [[500000 + 3000 * np.cos(a), 5200000 + 2000 * np.sin(a)] for a in np.linspace(0, 6.2, 40)]
    doc = {
        "type": "Polygon",
        "crs": {"type": "name", "properties": {"name": name}},
        "coordinates": [[*ring, ring[0]]],
    }
    f = tmp_path / "lake.geojson"
    f.write_text(json.dumps(doc))
    return f


def test_geojson_crs_member_unknown_to_proj_names_the_file(tmp_path):
    """Was: read without complaint, then "crs: unknown CRS 'EPSG:99999999'" naming no file."""
    f = _geojson_with_crs(tmp_path, "urn:ogc:def:crs:EPSG::99999999")
    with pytest.raises(ReadError, match=r"lake\.geojson: its 'crs' member names .*99999999.*unknown CRS"):
        read_points(f)
    assert read_points(f, crs="EPSG:32632").crs == "EPSG:32632"  # a CRS given overrides the member


def test_geojson_crs_member_known_still_reads(tmp_path):
    assert read_points(_geojson_with_crs(tmp_path, "urn:ogc:def:crs:EPSG::32632")).crs == "EPSG:32632"


@pytest.mark.parametrize(
    ("argv", "needle"),
    [
        (["mesh", "{f}", "-o", "{d}/g.vtm", "--source-crs", "nonsense"], "--source-crs nonsense: unknown CRS"),
        (["import", "{f}", "-o", "{d}/c.toml", "--source-crs", "nonsense"], "--source-crs nonsense: unknown CRS"),
        (["import", "{f}", "-o", "{d}/c.toml", "--crs", "nonsense"], "--crs nonsense: unknown CRS"),
    ],
)
def test_an_unknown_crs_option_names_the_option(tmp_path, capsys, argv, needle):
    """Was: "crs: unknown CRS 'nonsense'" (import --crs: no option, no file) or the file's name."""
    f = tmp_path / "ring.csv"
    f.write_text("x,y\n0,0\n100,0\n100,80\n0,80\n")
    rc = main([a.format(f=f, d=tmp_path) for a in argv])
    err = capsys.readouterr().err
    assert rc == 2 and needle in err and err.count("\n") == 1, err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["ring.csv"]


_SLOW_WRITE = """
import sys, time
from pathlib import Path
import meshcore.io.native as native
from meshcore.io._atomic import atomic_path
from meshcore.cli import main

def slow(path, gs, **kw):  # a write that the signal reaches half done
    with atomic_path(path) as tmp:
        tmp.write_bytes(b"half")
        Path(sys.argv[1]).touch()
        time.sleep(300)

native.write_npz = slow
sys.exit(main(sys.argv[2:]))
"""


@pytest.mark.slow
@pytest.mark.parametrize(("sig", "code"), [("SIGINT", 130), ("SIGTERM", 143)])
def test_a_signal_during_a_write_leaves_nothing(tmp_path, sig, code):
    """Ctrl-C, and SIGTERM (``timeout``, job schedulers: was the default death, exit -15, the
    half-written temporary left beside the output), end the run with nothing written."""
    import os
    import signal
    import subprocess
    import sys
    import time

    f = tmp_path / "ring.csv"
    f.write_text("x,y\n0,0\n100,0\n100,80\n0,80\n")
    out, ready = tmp_path / "out", tmp_path / "ready"
    out.mkdir()
    script = tmp_path / "run.py"
    script.write_text(_SLOW_WRITE)
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    argv = [sys.executable, str(script), str(ready), "mesh", str(f), "--cells", "64", "-o", str(out / "g.npz"), "-q"]
    proc = subprocess.Popen(
        argv, env=env, stderr=subprocess.PIPE, preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL)
    )
    try:
        for _ in range(6000):
            if ready.exists() or proc.poll() is not None:
                break
            time.sleep(0.1)
        assert ready.exists(), proc.stderr.read().decode() if proc.poll() is not None else "no write"
        proc.send_signal(getattr(signal, sig))
        _, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == code, err.decode()
    assert "Traceback" not in err.decode() and err.decode().count("\n") == 1, err.decode()
    assert list(out.iterdir()) == []


@pytest.mark.parametrize("scale", [1e-300, 1e-200])
def test_an_outline_too_small_for_doubles_says_so(tmp_path, capsys, scale):
    """Was: "the water polygon is not valid (Valid Geometry, near that point)" (its area underflows to 0)."""
    f = tmp_path / "tiny.csv"
    f.write_text("x,y\n" + "".join(f"{x * scale},{y * scale}\n" for x, y in [(0, 0), (3, 0), (3, 2), (0, 2)]))
    assert main(["mesh", str(f), "-o", str(tmp_path / "g.vtm")]) == 2
    err = capsys.readouterr().err
    assert "tiny.csv: the outline encloses no area to grid" in err and "too small for double precision" in err, err
    assert "Valid Geometry" not in err and err.count("\n") == 1
