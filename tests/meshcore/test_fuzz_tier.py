"""Fuzz tier: mutated real files through every reader.

Each case takes a seed — a real lake file (CSV, KML, KMZ, GeoJSON, shapefile,
DXF) or a grid file of every format meshcore reads, written by meshcore (and a
VTK-written compressed ``.vts``) — applies one to four random mutations (byte
flips, inserted or deleted runs, truncation, a duplicated chunk, a number
replaced by ``nan``/``inf``/``1e308``/a huge integer, a float or an int32 in a
binary file overwritten, an HDF5 dataset re-declared far larger or filled with
NaN) and reads it.  A case passes when the read

* returns, and every coordinate it returns is finite, or
* raises one :class:`~meshcore.errors.ReadError` whose message is one line naming the file.

Anything else — another exception, a NaN grid accepted — fails the test (a hang
fails it through the suite's timeout).  The CI runs ``MESHCORE_FUZZ_CASES``
cases in all (default 540, 30 per seed); ``MESHCORE_FUZZ_CASES=150000`` is the big run.

Each seed's line (``-s``) reports its cases, reads, ReadErrors and slowest read.
"""

from __future__ import annotations

import os
import re
import shutil
import time
from pathlib import Path

import numpy as np
import pytest

import meshcore
from meshcore.errors import ReadError
from meshcore.io import read_blocks, read_points, write
from tests.conftest import DATA

TOTAL = int(os.environ.get("MESHCORE_FUZZ_CASES", "540"))

#: (seed name, files of the seed, the file read, reader)
POINT_SEEDS = {
    "csv": ["lake_zurich_sparse.csv"],
    "kml": ["lake_zurich_sparse.kml"],
    "kmz": ["lake_zurich_sparse.kmz"],
    "geojson": ["lake_zurich_sparse.geojson"],
    "shp": ["windermere_sparse.shp", "windermere_sparse.shx", "windermere_sparse.dbf", "windermere_sparse.prj"],
    "dxf": ["lake_zurich_sparse_utm32.dxf"],
}
GRID_SEEDS = {
    "xyz-ascii": ("g.xyz", {"mode": "ascii"}),
    "xyz-fortran": ("g.xyz", {"mode": "fortran"}),
    "xyz-binary": ("g.xyz", {"mode": "binary"}),
    "vts": ("g.vts", {}),
    "vtm": ("g.vtm", {}),
    "npz": ("g.npz", {}),
    "cgns": ("g.cgns", {}),
    "grd": ("g.grd", {}),
    "nc": ("g.nc", {}),
    "metrics-csv": ("g.csv", {}),
    "ddb": ("g.ddb", {}),
    "vtk-written-vts": ("c.vts", None),
}
SEEDS = list(POINT_SEEDS) + list(GRID_SEEDS)
PER_SEED = max(1, TOTAL // len(SEEDS))


def _blocks():
    s, t = np.meshgrid(np.linspace(0, 1, 9), np.linspace(0, 1, 5), indexing="ij")
    a = meshcore.StructuredGrid(1000 * s + 50 * t, 600 * t + 30 * s * s, names={"top": "shore", "left": "inlet"})
    b = meshcore.StructuredGrid(1000 * s + 1000 + 50 * t, 600 * t + 30 * (s + 1) ** 2, names={"right": "outlet"})
    return [a, b]


@pytest.fixture(scope="module")
def seeds(tmp_path_factory):
    """Seed folders: one per seed, holding every file the read needs."""
    root = tmp_path_factory.mktemp("seeds")
    out = {}
    for name, files in POINT_SEEDS.items():
        d = root / name
        d.mkdir()
        for f in files:
            shutil.copy(DATA / f, d / f)
        out[name] = d / files[0]
    blocks = _blocks()
    frame = {"crs": "EPSG:32632", "origin": (480000.0, 5240000.0)}
    for name, (fn, opts) in GRID_SEEDS.items():
        d = root / name
        d.mkdir()
        if opts is None:  # a compressed .vts written by VTK itself
            vtk = pytest.importorskip("vtk")
            from vtk.util.numpy_support import numpy_to_vtk

            g = blocks[0]
            sg = vtk.vtkStructuredGrid()
            sg.SetDimensions(g.shape[0], g.shape[1], 1)
            pts = vtk.vtkPoints()
            pts.SetData(numpy_to_vtk(np.column_stack([g.x.ravel("F"), g.y.ravel("F"), 0 * g.x.ravel()]), deep=True))
            sg.SetPoints(pts)
            w = vtk.vtkXMLStructuredGridWriter()
            w.SetFileName(str(d / fn))
            w.SetInputData(sg)
            w.SetCompressorTypeToZLib()
            w.SetDataModeToAppended()
            w.EncodeAppendedDataOff()
            assert w.Write() == 1
        elif name in ("vtm", "npz", "cgns", "metrics-csv", "ddb"):
            if name == "cgns":
                pytest.importorskip("h5py")
            write(d / fn, blocks, **frame)
        else:
            write(d / fn, blocks[0], **opts, **frame)
        out[name] = d / fn
    return out


# ------------------------------------------------------------------ mutations
_NUMBER = re.compile(rb"-?\d+(\.\d+)?([eE][-+]?\d+)?")
_HOSTILE = [b"nan", b"inf", b"-inf", b"1e308", b"1e400", b"-0", b"99999999999999999999", b"0", b"-1", b"1e-320"]


def _mutate_bytes(data: bytes, rng: np.random.Generator) -> bytes:
    b = bytearray(data)
    kind = rng.integers(0, 8)
    n = len(b)
    if n == 0:
        return bytes(rng.integers(0, 256, 16, dtype=np.uint8))
    pos = int(rng.integers(0, n))
    if kind == 0:  # flip a few bytes
        for _ in range(int(rng.integers(1, 17))):
            b[int(rng.integers(0, n))] = int(rng.integers(0, 256))
    elif kind == 1:  # insert random bytes
        b[pos:pos] = bytes(rng.integers(0, 256, int(rng.integers(1, 64)), dtype=np.uint8))
    elif kind == 2:  # delete a run
        del b[pos : pos + int(rng.integers(1, 256))]
    elif kind == 3:  # truncate
        del b[pos:]
    elif kind == 4:  # duplicate a chunk
        b[pos:pos] = b[pos : pos + int(rng.integers(1, 512))]
    elif kind == 5:  # a number → a hostile number (text)
        hits = list(_NUMBER.finditer(bytes(b)))
        if hits:
            m = hits[int(rng.integers(0, len(hits)))]
            b[m.start() : m.end()] = _HOSTILE[int(rng.integers(0, len(_HOSTILE)))]
    elif kind == 6:  # a float64 in a binary file → nan / inf / huge
        v = [np.nan, np.inf, -np.inf, 1e308, -1e300, 5e-324][int(rng.integers(0, 6))]
        pos -= pos % 8
        b[pos : pos + 8] = np.float64(v).tobytes()
    else:  # an int32 (a dimension, a count, an offset) → hostile
        v = [0, -1, 2**31 - 1, 65536, 1 << 24, 3][int(rng.integers(0, 6))]
        pos -= pos % 4
        b[pos : pos + 4] = np.int32(v).tobytes()
    return bytes(b)


def _mutate_hdf5(path: Path, rng: np.random.Generator) -> bool:
    """Semantic HDF5 mutations of a CGNS file; False when the file is no longer HDF5."""
    import h5py

    try:
        with h5py.File(path, "r+") as h:
            zone = h["Base"][sorted(k for k in h["Base"] if k.startswith("block"))[int(rng.integers(0, 2))]]
            gc = zone["GridCoordinates"]
            c = gc["CoordinateX" if rng.integers(0, 2) else "CoordinateY"]
            if rng.integers(0, 2):  # declared far larger, chunks never written (read as zeros)
                del c[" data"]
                shape = tuple(int(v) for v in rng.integers(2, 60000, 2))
                c.create_dataset(" data", shape=shape, dtype="f8", chunks=(min(64, shape[0]), min(64, shape[1])))
            else:  # a NaN (or inf) inside the coordinates
                a = c[" data"][()]
                a.flat[int(rng.integers(0, a.size))] = [np.nan, np.inf][int(rng.integers(0, 2))]
                c[" data"][...] = a
    except (OSError, KeyError, ValueError, IndexError):
        return False
    return True


def _mutate(target: Path, files: list[Path], rng: np.random.Generator) -> None:
    """Mutate one or more files of a seed folder in place (the caller restores them)."""
    if target.suffix == ".cgns" and rng.integers(0, 3) == 0 and _mutate_hdf5(target, rng):
        return
    for _ in range(int(rng.integers(1, 5))):
        victim = target if (len(files) == 1 or rng.integers(0, 2)) else files[int(rng.integers(0, len(files)))]
        victim.write_bytes(_mutate_bytes(victim.read_bytes(), rng))


def _finite(result) -> bool:
    if hasattr(result, "polylines"):
        return all(np.isfinite(pl.points).all() for pl in result.polylines)
    return all(np.isfinite(g.x).all() and np.isfinite(g.y).all() for g in result.blocks)


@pytest.mark.parametrize("name", SEEDS)
def test_mutated_files_read_or_raise_one_read_error(seeds, tmp_path, name):
    seed = seeds[name]
    reader = read_points if name in POINT_SEEDS else read_blocks
    stats = {"ok": 0, "ReadError": 0}
    failures = []
    slowest = 0.0
    work = tmp_path / "work"
    shutil.copytree(seed.parent, work)
    path = work / seed.name
    files = sorted(p for p in work.rglob("*") if p.is_file())
    original = {p: p.read_bytes() for p in files}
    rng_root = np.random.SeedSequence([20260, SEEDS.index(name)])
    for case, child in enumerate(rng_root.spawn(PER_SEED)):
        rng = np.random.default_rng(child)
        _mutate(path, files, rng)
        t0 = time.perf_counter()
        try:
            with np.errstate(all="ignore"):
                res = reader(path)
        except ReadError as exc:
            msg = str(exc)
            if "\n" in msg or not (path.name in msg or path.stem in msg):
                failures.append((case, f"ReadError not one line naming the file: {msg[:200]!r}"))
            stats["ReadError"] += 1
        except Exception as exc:  # the property under test
            failures.append((case, f"{type(exc).__name__}: {str(exc)[:200]}"))
        else:
            if not _finite(res):
                failures.append((case, "non-finite coordinates accepted"))
            stats["ok"] += 1
        slowest = max(slowest, time.perf_counter() - t0)
        for p, data in original.items():  # back to the seed for the next case
            if not p.exists() or p.stat().st_size != len(data) or p.read_bytes() != data:
                p.write_bytes(data)
        for p in work.rglob("*"):
            if p.is_file() and p not in original:
                p.unlink()
    print(f"\nfuzz {name}: {PER_SEED} cases, {stats}, slowest read {slowest:.3f} s, failures {len(failures)}")
    assert not failures, f"{name}: {len(failures)} of {PER_SEED} cases failed, e.g. {failures[:5]}"
