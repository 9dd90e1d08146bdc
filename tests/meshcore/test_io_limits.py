"""Readers refuse what they should: non-finite grids, allocation bombs, oversized inputs.

Every grid reader checks that coordinates (and the stored local origin) are
finite; sizes declared by a file are checked against the limits of
:mod:`meshcore._validation` before anything of that size is allocated; parsers
are linear in their input.
"""

from __future__ import annotations

import os
import struct
import tracemalloc
import zlib
from pathlib import Path

import numpy as np
import pytest

import meshcore
from meshcore.cli import main
from meshcore.errors import ReadError
from meshcore.io import read_blocks, read_points, write

GRID_FILES = ["g.xyz", "g.vts", "g.npz", "g.cgns", "g.grd", "g.nc", "g.csv"]


def _grid(bad: float | None = None, names=None):
    s, t = np.meshgrid(np.linspace(0, 1, 6), np.linspace(0, 1, 4), indexing="ij")
    x = 1000 * s + 50 * t
    if bad is not None:
        x = x.copy()
        x[2, 1] = bad
    return meshcore.StructuredGrid(x, 600 * t + 30 * s * s, names=names or {})


@pytest.mark.parametrize("name", GRID_FILES)
@pytest.mark.parametrize("bad", [np.nan, np.inf, -1e300])
def test_non_finite_or_huge_coordinates_are_refused(tmp_path, name, bad):
    opts = {"mode": "binary"} if name.endswith(".xyz") else {}
    with np.errstate(all="ignore"):
        f = write(tmp_path / name, _grid(bad), crs="EPSG:32632", origin=(480000.0, 5240000.0), **opts)
    with pytest.raises(ReadError) as exc:
        read_blocks(f)
    msg = str(exc.value)
    assert str(f) in msg and "\n" not in msg
    assert "(i=2, j=1)" in msg or "finite" in msg or "missing" in msg
    assert "np.float" not in msg  # the value as a user writes it: nan, inf, -1e+300


def _replace_origin(f, value: bytes) -> None:
    data = f.read_bytes()
    start = data.index(b'Name="origin"')
    a, b = data.index(b">", start) + 1, data.index(b"</Array>", start)
    f.write_bytes(data[:a] + value + data[b:])


def test_vts_nan_origin_is_refused(tmp_path, capsys):
    f = write(tmp_path / "g.vts", _grid(), crs="EPSG:32632", origin=(480000.0, 5240000.0))
    _replace_origin(f, b"nan 5240000.0")
    with pytest.raises(ReadError, match="origin"):
        read_blocks(f)
    # the command line: `quality --strict` does not say "folded cells 0, area nan" and exit 0
    assert main(["quality", "--strict", str(f)]) == 2
    err = capsys.readouterr().err
    assert "g.vts" in err and err.count("\n") == 1
    assert main(["convert", str(f), str(tmp_path / "o.xyz")]) == 2
    assert not (tmp_path / "o.xyz").exists()


def test_cgns_declared_sizes_are_checked_before_reading(tmp_path):
    """A small file whose HDF5 datasets declare 20 000 × 20 000 nodes (unwritten chunks read as zeros)."""
    h5py = pytest.importorskip("h5py")
    f = write(tmp_path / "g.cgns", _grid())
    with h5py.File(f, "r+") as h:
        gc = h["Base/block1/GridCoordinates"]
        for c in ("CoordinateX", "CoordinateY"):
            del gc[c][" data"]
            gc[c].create_dataset(" data", shape=(20000, 20000), dtype="f8", chunks=(100, 100))
    assert f.stat().st_size < 100_000
    tracemalloc.start()
    try:
        with pytest.raises(ReadError, match=r"400,000,000 nodes.*limit.*MESHCORE_MAX_NODES"):
            read_blocks(f)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 50 * 2**20


def _vts_with_compressed_points(tmp_path, inflated: int, ni: int = 1, nj: int = 1):
    """A .vts whose Points array is one zlib block inflating to ``inflated`` bytes of zeros."""
    body = zlib.compress(bytes(inflated), 9)
    head = struct.pack("<QQQQ", 1, inflated, inflated, len(body))
    ext = f"0 {ni} 0 {nj} 0 0"
    xml = (
        '<?xml version="1.0"?>\n<VTKFile type="StructuredGrid" version="1.0" byte_order="LittleEndian" '
        f'header_type="UInt64" compressor="vtkZLibDataCompressor">\n<StructuredGrid WholeExtent="{ext}">\n'
        f'<Piece Extent="{ext}"><Points><DataArray type="Float64" NumberOfComponents="3" format="appended" '
        'offset="0"/></Points></Piece>\n</StructuredGrid>\n<AppendedData encoding="raw">\n_'
    ).encode()
    f = tmp_path / "bomb.vts"
    f.write_bytes(xml + head + body + b"\n</AppendedData>\n</VTKFile>\n")
    return f


def test_vts_zlib_bomb_is_refused_before_inflating(tmp_path):
    f = _vts_with_compressed_points(tmp_path, 200 * 2**20)  # 200 MB of zeros in a ~200 kB file
    assert f.stat().st_size < 1_000_000
    tracemalloc.start()
    try:
        with pytest.raises(ReadError, match=r"refused.*inflate"):
            read_blocks(f)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 20 * 2**20
    # a header that under-states its block: inflating stops at the declared size
    body = zlib.compress(bytes(100 * 2**20), 9)
    data = _vts_with_compressed_points(tmp_path, 96).read_bytes()
    a = data.index(b"_", data.index(b"<AppendedData")) + 1
    f.write_bytes(data[:a] + struct.pack("<QQQQ", 1, 96, 96, len(body)) + body + b"\n</AppendedData>\n</VTKFile>\n")
    tracemalloc.start()
    try:
        with pytest.raises(ReadError, match="does not inflate to its declared 96 bytes"):
            read_blocks(f)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 20 * 2**20


def test_grid_node_limit_names_the_variable(tmp_path, monkeypatch):
    f = write(tmp_path / "g.grd", _grid())
    monkeypatch.setenv("MESHCORE_MAX_NODES", "10")
    with pytest.raises(ReadError, match=r"6 × 4 nodes make 24 nodes.*limit is 10 nodes.*MESHCORE_MAX_NODES"):
        read_blocks(f)


def test_point_file_line_limit_is_checked_before_parsing(tmp_path, monkeypatch):
    f = tmp_path / "many.csv"
    f.write_text("x,y\n" + "".join(f"{k},{k % 7}\n" for k in range(5000)))
    monkeypatch.setenv("MESHCORE_MAX_POINTS", "1000")
    msg = r"many\.csv: lines: 5,002 is more than the limit of 1,000.*MESHCORE_MAX_POINTS"
    with pytest.raises(ReadError, match=msg):
        read_points(f)


def test_csv_reader_memory_per_line(tmp_path):
    """The reader keeps two floats per point, not the tokens of every line (it took ~660 bytes a line)."""
    n = 200_000
    f = tmp_path / "big.csv"
    k = np.arange(n)
    f.write_text("x,y\n" + "\n".join(f"{a:.6f},{b:.6f}" for a, b in zip(k * 0.5, np.sin(k), strict=True)) + "\n")
    size = f.stat().st_size
    tracemalloc.start()
    try:
        ps = read_points(f)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert len(ps.polylines[0]) == n
    # the file's bytes and its text are held once each; beyond that ~ 16-40 bytes per point
    assert (peak - 3 * size) / n < 100


def test_kml_parsing_is_linear_in_the_rings_of_a_placemark(tmp_path, monkeypatch):
    """16 000 small polygons in one placemark took 185 s: every ring searched the whole placemark."""
    from meshcore.io import kml

    calls = {"n": 0}
    real = kml._local

    def counting(tag):
        calls["n"] += 1
        return real(tag)

    monkeypatch.setattr(kml, "_local", counting)
    ring = "<LinearRing><coordinates>8,47 8.001,47 8.001,47.001 8,47</coordinates></LinearRing>"
    counts = {}
    for n in (200, 800):
        polys = "".join(f"<Polygon><outerBoundaryIs>{ring}</outerBoundaryIs></Polygon>" for _ in range(n))
        f = tmp_path / f"p{n}.kml"
        f.write_text(f"<kml><Placemark><name>lake</name><MultiGeometry>{polys}</MultiGeometry></Placemark></kml>")
        calls["n"] = 0
        assert len(read_points(f)) == n
        counts[n] = calls["n"]
    assert counts[800] <= 4.5 * counts[200]  # linear (quadratic would be 16 ×)


def test_geojson_position_limit(tmp_path, monkeypatch):
    f = tmp_path / "l.geojson"
    f.write_text('{"type": "LineString", "coordinates": [' + ",".join(f"[{k}, 0]" for k in range(300)) + "]}")
    monkeypatch.setenv("MESHCORE_MAX_POINTS", "100")
    with pytest.raises(ReadError, match=r"positions.*limit of 100"):
        read_points(f)


def test_file_size_limit(tmp_path, monkeypatch):
    f = write(tmp_path / "g.vts", _grid())
    monkeypatch.setenv("MESHCORE_MAX_BYTES", "1000")
    with pytest.raises(ReadError, match=r"file size in bytes.*limit of 1,000.*MESHCORE_MAX_BYTES"):
        read_blocks(f)


def test_bad_limit_variable_is_one_clear_error(tmp_path, monkeypatch, capsys):
    f = write(tmp_path / "g.vts", _grid())
    monkeypatch.setenv("MESHCORE_MAX_NODES", "lots")
    assert main(["quality", str(f)]) == 2
    assert "MESHCORE_MAX_NODES must be a positive integer" in capsys.readouterr().err


def test_readme_promises_the_limits_the_code_has(monkeypatch):
    from meshcore import _validation as v
    from tests.conftest import ROOT

    for name in ("MESHCORE_MAX_NODES", "MESHCORE_MAX_POINTS", "MESHCORE_MAX_BYTES"):
        monkeypatch.delenv(name, raising=False)
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    promise = text[text.index("## What we promise") :]
    assert v.max_nodes() == 2**24 and "2²⁴ = 16 777 216" in promise
    assert v.max_points() == 5_000_000 and "| 5 000 000 |" in promise
    assert v.max_bytes() == 512 * 2**20 and "512 MiB" in promise
    assert v.MAX_COORDINATE == 1e100 and "≤ 1e100" in promise and f"≥ {v.MIN_EXTENT:g}" in promise
    from meshcore.io import dxf, kml

    assert dxf.SPLINE_MAX_POINTS == 200_000 and "| 200 000 (a larger" in promise
    assert kml.KMZ_LIMIT == 64 * 2**20 and "KMZ: 64 MiB" in promise


def _limit_memory():  # in the child: a reader of /dev/zero fails on memory, not on the machine
    import resource

    resource.setrlimit(resource.RLIMIT_AS, (3 * 2**30, 3 * 2**30))


@pytest.mark.skipif(not hasattr(os, "mkfifo") or not os.path.exists("/dev/zero"), reason="POSIX fifos and devices")
@pytest.mark.parametrize(
    ("argv", "target", "kind"),
    [
        (["import", "{f}", "-o", "{d}/o.toml"], "lake.csv", "fifo"),
        (["generate", "{f}", "-o", "{d}/o.vts"], "case.toml", "fifo"),
        (["quality", "{f}"], "grid.vts", "device"),
    ],
)
def test_a_pipe_or_a_device_is_refused_not_read_for_ever(tmp_path, argv, target, kind):
    """A fifo without a writer blocked every reader; /dev/zero was read until memory ran out."""
    import subprocess
    import sys

    f = tmp_path / target
    if kind == "fifo":
        os.mkfifo(f)
    else:
        f.symlink_to("/dev/zero")
    env = dict(os.environ, PYTHONPATH=str(Path(meshcore.__file__).parents[1]))
    cmd = [sys.executable, "-m", "meshcore"] + [a.format(f=f, d=tmp_path) for a in argv]
    r = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=120, preexec_fn=_limit_memory)
    assert r.returncode == 2, r.stderr[-2000:]
    assert r.stderr.count("\n") == 1 and f"{f}: not a regular file" in r.stderr


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="POSIX fifos")
@pytest.mark.parametrize("part", [".shx", ".dbf", ".prj"])
def test_a_shapefile_part_that_is_a_pipe_is_refused(tmp_path, part):
    from tests.conftest import DATA

    for ext in (".shp", ".shx", ".dbf", ".prj"):
        if ext != part:
            (tmp_path / f"w{ext}").write_bytes((DATA / f"windermere_sparse{ext}").read_bytes())
    os.mkfifo(tmp_path / f"w{part}")  # opening it would wait for a writer for ever
    with pytest.raises(ReadError, match=rf"w\{part}: not a regular file"):
        read_points(tmp_path / "w.shp")
