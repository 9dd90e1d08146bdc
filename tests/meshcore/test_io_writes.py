"""Writes: multi-file outputs are atomic as a set, stale temporaries are cleaned up,
names in any language survive, messages are one line naming the file."""

from __future__ import annotations

import errno
import os
import pathlib
import time

import numpy as np
import pytest

import meshcore
from meshcore.errors import ReadError, WriteError
from meshcore.io import read_blocks, read_points, write


def _grid(ni=5, nj=3, shift=0.0, names=None):
    s, t = np.meshgrid(np.linspace(0, 1, ni + 1), np.linspace(0, 1, nj + 1), indexing="ij")
    return meshcore.StructuredGrid(100 * s + shift, 60 * t + 3 * s * s, names=names or {})


def _fail_on(monkeypatch, needle: str):
    """Make writing any file whose name contains ``needle`` fail as on a full disk."""
    real = pathlib.Path.write_text

    def write_text(self, *a, **k):
        if needle in self.name:
            raise OSError(errno.ENOSPC, "No space left on device")
        return real(self, *a, **k)

    monkeypatch.setattr(pathlib.Path, "write_text", write_text)


def test_grd_and_enc_are_written_as_a_set(tmp_path, monkeypatch):
    f = write(tmp_path / "g.grd", _grid())
    old_grd, old_enc = f.read_bytes(), (tmp_path / "g.enc").read_bytes()
    _fail_on(monkeypatch, ".enc.")  # the disk fills up after the .grd
    with pytest.raises(WriteError, match="No space left") as exc:
        write(f, _grid(8, 4, shift=5.0))
    assert "\n" not in str(exc.value)
    assert f.read_bytes() == old_grd and (tmp_path / "g.enc").read_bytes() == old_enc
    assert sorted(p.name for p in tmp_path.iterdir()) == ["g.enc", "g.grd"]  # no temporaries left


def test_grd_reader_spots_an_enclosure_from_another_write(tmp_path):
    f = write(tmp_path / "g.grd", _grid(8, 4))
    enc = (tmp_path / "g.enc").read_bytes()
    write(f, _grid(5, 3))
    (tmp_path / "g.enc").write_bytes(enc)  # the pair of a crash between the two renames
    with pytest.raises(ReadError, match=r"g\.enc.*does not fit this 6 x 4 grid"):
        read_blocks(f)


def test_vtm_failure_keeps_the_old_set(tmp_path, monkeypatch):
    f = write(tmp_path / "m.vtm", [_grid(), _grid(shift=100.0)])
    before = {p.relative_to(tmp_path): p.read_bytes() for p in tmp_path.rglob("*") if p.is_file()}
    _fail_on(monkeypatch, ".vtm.")
    with pytest.raises(WriteError):
        write(f, [_grid(4, 2), _grid(4, 2, shift=100.0), _grid(4, 2, shift=200.0)])
    after = {p.relative_to(tmp_path): p.read_bytes() for p in tmp_path.rglob("*") if p.is_file()}
    assert after == before
    assert len(read_blocks(f).blocks) == 2


def _dead_pid() -> int:
    pid = 4_000_000
    while True:
        try:
            os.kill(pid, 0)
        except ProcessLookupError:
            return pid
        except PermissionError:
            pass
        pid += 1


def test_vtm_never_replaces_a_folder_that_is_not_its_blocks(tmp_path):
    """A .vtm's blocks go to the folder of its name, replaced whole: ``meshcore mesh
    lake/outline.kml -o lake.vtm`` deleted the folder holding its own input."""
    mine = tmp_path / "lake"
    mine.mkdir()
    (mine / "outline.kml").write_text("<kml/>")
    with pytest.raises(WriteError, match=r"outline\.kml") as exc:
        write(tmp_path / "lake.vtm", meshcore.GridSet((_grid(), _grid(shift=100.0))))
    assert "\n" not in str(exc.value)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["lake"]  # nothing written, no temporaries
    assert [p.name for p in mine.iterdir()] == ["outline.kml"]
    (tmp_path / "lake2").write_text("a file of the block folder's name")
    with pytest.raises(WriteError, match="replace a file"):
        write(tmp_path / "lake2.vtm", meshcore.GridSet((_grid(),)))
    assert (tmp_path / "lake2").read_text() == "a file of the block folder's name"
    # the folder of an earlier write is replaced (three blocks, then two: no third left behind)
    f = write(tmp_path / "g.vtm", meshcore.GridSet((_grid(), _grid(shift=100.0), _grid(shift=200.0))))
    write(f, meshcore.GridSet((_grid(), _grid(shift=100.0))))
    assert sorted(p.name for p in (tmp_path / "g").iterdir()) == ["g_0.vts", "g_1.vts"]
    assert len(read_blocks(f).blocks) == 2


def test_ddb_never_replaces_a_folder_of_a_block_files_name(tmp_path):
    """Delft3D DD writes a .grd and .enc per block beside the .ddb: a folder of such a name was
    moved aside and deleted with the staging folder."""
    s, t = np.meshgrid(np.linspace(0, 100, 6), np.linspace(0, 60, 4), indexing="ij")
    blocks = meshcore.GridSet((meshcore.StructuredGrid(s, t), meshcore.StructuredGrid(s + 100, t)))
    f = write(tmp_path / "g.ddb", blocks)
    names = sorted(p.name for p in tmp_path.iterdir())
    (tmp_path / names[1]).unlink()  # a block file's name ...
    (tmp_path / names[1]).mkdir()  # ... is a folder of the user's now
    (tmp_path / names[1] / "keep.txt").write_text("mine")
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir() if p.is_file()}
    with pytest.raises(WriteError, match="is a folder"):
        write(f, blocks)
    assert (tmp_path / names[1] / "keep.txt").read_text() == "mine"
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir() if p.is_file()} == before
    assert sorted(p.name for p in tmp_path.iterdir()) == names  # no temporaries


def test_stale_temporaries_of_killed_writes_are_removed(tmp_path):
    target = tmp_path / "g.vts"
    dead = tmp_path / f".g.vts.{_dead_pid()}.x1y2.tmp"  # a killed writer's (its process is gone)
    legacy = tmp_path / ".g.vts.ab12cd34.tmp"  # an older version's name, two hours old
    live = tmp_path / f".g.vts.{os.getppid()}.zz.tmp"  # a writer that is still running
    dead_dir = tmp_path / f".m.vtm.{_dead_pid()}.q.tmpdir"
    other = tmp_path / ".g.vts.notes.txt"  # not ours
    for p in (dead, legacy, live, other):
        p.write_bytes(b"x" * 1000)
    dead_dir.mkdir()
    (dead_dir / "m_0.vts").write_bytes(b"x")
    old = time.time() - 7200
    os.utime(legacy, (old, old))
    write(target, _grid())
    assert not dead.exists() and not legacy.exists()
    assert live.exists() and other.exists()
    write(tmp_path / "m.vtm", [_grid(), _grid(shift=100.0)])
    assert not dead_dir.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(["g.vts", "m.vtm", "m", live.name, other.name])


def test_no_temporary_is_left_by_a_failed_write(tmp_path, monkeypatch):
    _fail_on(monkeypatch, ".g.csv.")
    with pytest.raises(WriteError):
        write(tmp_path / "g.csv", _grid())
    assert list(tmp_path.iterdir()) == []


_FULL_AT = 4096  # bytes a file may grow to in the child below (RLIMIT_FSIZE: writes beyond fail like a full disk)


def _limit_file_size():  # runs in the child between fork and exec
    import resource
    import signal

    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a write beyond the limit fails (EFBIG) instead of killing
    resource.setrlimit(resource.RLIMIT_FSIZE, (_FULL_AT, _FULL_AT))


@pytest.mark.skipif(os.name != "posix", reason="file size limits are POSIX")
@pytest.mark.parametrize("name", ["g.cgns", "g.vtm", "g.grd", "g.nc"])
def test_a_write_that_runs_out_of_room_is_one_line_and_leaves_nothing(tmp_path, name):
    """The disk filling up in the middle of a file (here: a file size limit) is one clean error; the
    CGNS writer used to crash the process (HDF5 failing again while its objects were freed)."""
    if name.endswith(".cgns"):
        pytest.importorskip("h5py")
    import subprocess
    import sys

    src = write(tmp_path / "in.npz", _grid(30, 30))
    env = dict(os.environ, PYTHONPATH=str(pathlib.Path(meshcore.__file__).parents[1]))
    argv = [sys.executable, "-m", "meshcore", "convert", str(src), str(tmp_path / "out" / name)]
    (tmp_path / "out").mkdir()
    r = subprocess.run(argv, preexec_fn=_limit_file_size, capture_output=True, text=True, env=env, timeout=300)
    assert r.returncode == 2, r.stderr[-2000:]
    assert r.stderr.count("\n") == 1 and "cannot write (File too large)" in r.stderr, r.stderr[-2000:]
    assert list((tmp_path / "out").iterdir()) == []


# what h5py raised on a full tmpfs (one line here; HDF5 adds its diagnostics on more lines)
H5_DISK_FULL = (
    "Disable slist on flush dest failure failed (file write failed: time = Tue Dec  1 23:32:53 2026 , "
    "filename = '/tmp/tiny/.g.cgns.10599.z4lp5end.tmp', file descriptor = 3, errno = 28, error message = "
    "'No space left on device', buf = 0x55eb638ec8a1, total write size = 367, bytes this sub-write = 367, "
    "offset = 24576)"
)


@pytest.mark.parametrize("exc", [OSError(H5_DISK_FULL + "\n  HDF5-DIAG: Error detected"), RuntimeError(H5_DISK_FULL)])
def test_cgns_write_error_is_one_line(tmp_path, monkeypatch, exc):
    pytest.importorskip("h5py")
    from meshcore.io import cgns

    def boom(*a, **k):
        raise exc

    monkeypatch.setattr(cgns, "_zone_bcs", boom)
    with pytest.raises(WriteError) as err:
        write(tmp_path / "g.cgns", _grid())
    assert str(err.value) == f"{tmp_path / 'g.cgns'}: cannot write (No space left on device)"
    assert list(tmp_path.iterdir()) == []


NAMES = {"bottom": "Zürichsee, Ufer=Süd", "top": "岸边", "left": "inlet;1"}


def test_netcdf_keeps_non_ascii_border_names(tmp_path):
    f = write(tmp_path / "g.nc", _grid(names=NAMES), crs="EPSG:32632", origin=(480000.0, 5240000.0))
    assert read_blocks(f).blocks[0].names == NAMES
    netCDF4 = pytest.importorskip("netCDF4")
    with netCDF4.Dataset(f) as d:
        assert d.variables["grid"].border_bottom == NAMES["bottom"]


def test_cli_netcdf_non_ascii_names(tmp_path, capsys):
    from meshcore.cli import main

    src = write(tmp_path / "g.vts", _grid(names=NAMES), crs="EPSG:32632")
    assert main(["convert", str(src), str(tmp_path / "g.nc")]) == 0
    assert read_blocks(tmp_path / "g.nc").blocks[0].names == NAMES


@pytest.mark.parametrize("name", ["g.csv", "g.npz", "g.vts", "g.cgns", "g.su2", "g.msh"])
def test_names_in_any_language_round_trip(tmp_path, name):
    if name.endswith(".cgns"):
        pytest.importorskip("h5py")
    blocks = [_grid(names=NAMES), _grid(shift=100.0, names={"right": "Ausfluss"})]
    many = name.endswith((".csv", ".npz", ".cgns", ".su2", ".msh"))
    f = write(tmp_path / name, blocks if many else blocks[0], block_names=["Nord-See", "Süd"] if many else None)
    if name.endswith((".su2", ".msh")):
        text = f.read_text(encoding="utf-8")
        assert "Zürichsee" in text and "岸边" in text
        return
    gs = read_blocks(f)
    assert gs.blocks[0].names == NAMES
    if many:
        assert gs.block_names == ("Nord-See", "Süd")
        assert gs.blocks[1].names == {"right": "Ausfluss"}


# ----------------------------------------------------------------- DXF splines
def _dxf(tmp_path, fit_points, **spline):
    ezdxf = pytest.importorskip("ezdxf")
    doc = ezdxf.new()
    msp = doc.modelspace()
    msp.add_spline(fit_points=fit_points, **spline)
    f = tmp_path / "s.dxf"
    doc.saveas(f)
    return f


def test_dxf_fit_point_spline_uses_its_own_extent(tmp_path):
    """A 189-point spline over 28 km flattened to 23 666 points (a 1e-3 drawing-unit sagitta)."""
    t = np.linspace(0, 1, 189)
    fit = np.c_[28_000 * t, 900 * np.sin(7 * t)]
    ps = read_points(_dxf(tmp_path, fit))
    n = len(ps.polylines[0])
    # a sagitta of 1e-3 of the extent (28 m): ezdxf's minimum of 4 segments per knot span
    # (753 points) suffices; a 1e-3 drawing-unit sagitta needs 2483 here
    assert 189 <= n <= 4 * 188 + 1
    # the points lie on the curve through the fit points (within the sagitta of 28 m)
    assert np.interp(ps.polylines[0].points[:, 0], fit[:, 0], fit[:, 1]).shape == (n,)


def test_dxf_far_fit_point_is_bounded(tmp_path):
    fit = np.array([[0, 0], [10, 5], [20, 0], [1e9, 3e8], [30, 5], [40, 0]], float)
    ps = read_points(_dxf(tmp_path, fit))
    assert len(ps.polylines[0]) < 10_000


def test_dxf_spline_point_cap(tmp_path, monkeypatch):
    from meshcore.io import dxf

    t = np.linspace(0, 1, 40)
    f = _dxf(tmp_path, np.c_[1000 * t, 100 * np.sin(20 * t)])
    assert len(read_points(f, sagitta=0.01).polylines[0]) > 500
    monkeypatch.setattr(dxf, "SPLINE_MAX_POINTS", 500)
    with pytest.raises(ReadError, match=r"flattens to more than 500 points.*larger sagitta"):
        read_points(f, sagitta=0.01)


# --------------------------------------------------------------- messages
def test_csv_stray_delimiter_is_reported_on_its_line(tmp_path):
    rows = [f"{k}.0,{k % 3}.5" for k in range(20)]
    rows[14] = "14.0;2.5"  # line 16 (after the header)
    f = tmp_path / "p.csv"
    f.write_text("x,y\n" + "\n".join(rows) + "\n")
    with pytest.raises(ReadError, match=r"p\.csv: line 16: .*1 values separated by ','.*'14\.0;2\.5'"):
        read_points(f)


def test_utf16_point_file_is_read(tmp_path):
    text = "x,y\n0,0\n4,0\n4,3\n0,3\n"
    for enc in ("utf-16", "utf-16-le"):
        f = tmp_path / f"p-{enc}.csv"
        f.write_bytes(text.encode(enc))
        np.testing.assert_array_equal(read_points(f).polylines[0].points, [[0, 0], [4, 0], [4, 3], [0, 3]])


def test_garbage_header_is_shown_short_and_printable(tmp_path):
    f = tmp_path / "g.csv"
    f.write_bytes(b"\x01\x02\x03\xfe\xfd" * 30 + b"\nfoo,bar\n")
    with pytest.raises(ReadError) as exc:
        read_points(f)
    msg = str(exc.value)
    assert len(msg) < 300 and all(c.isprintable() for c in msg) and "g.csv" in msg


def test_vts_dtd_refusal_names_vtk(tmp_path):
    f = tmp_path / "d.vts"
    f.write_text('<?xml version="1.0"?>\n<!DOCTYPE x [<!ENTITY a "b">]>\n<VTKFile type="StructuredGrid"/>')
    with pytest.raises(ReadError, match="VTK files never need them"):
        read_blocks(f)
