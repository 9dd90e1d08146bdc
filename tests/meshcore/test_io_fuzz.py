"""Fuzzing the readers: corrupted, truncated and random files raise only ReadError."""

from __future__ import annotations

import shutil
import tempfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import meshcore
from meshcore.errors import ReadError
from meshcore.io import read_blocks, read_points, write
from tests.conftest import DATA

POINT_FILES = [
    "lake_zurich_sparse.csv",
    "lake_zurich_sparse.kml",
    "lake_zurich_sparse.kmz",
    "lake_zurich_sparse.geojson",
    "windermere_sparse.shp",
    "lake_zurich_sparse_utm32.dxf",
]
GRID_SUFFIXES = [
    ("g.xyz", {"mode": "ascii"}),
    ("f.xyz", {"mode": "fortran"}),
    ("b.xyz", {"mode": "binary"}),
    ("g.vts", {}),
    ("g.npz", {}),
    ("g.cgns", {}),
    ("g.grd", {}),
    ("g.nc", {}),
    ("g.csv", {}),
]

FUZZ = settings(
    max_examples=25,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)


@st.composite
def corruption(draw, n: int):
    """A list of edits: ("flip", pos, byte) / ("cut", pos) / ("insert", pos, bytes)."""
    kind = draw(st.sampled_from(["flip", "cut", "insert", "flips"]))
    if kind == "cut":
        return [("cut", draw(st.integers(0, max(0, n - 1))))]
    if kind == "insert":
        return [("insert", draw(st.integers(0, n)), draw(st.binary(min_size=1, max_size=16)))]
    k = 1 if kind == "flip" else draw(st.integers(2, 12))
    return [("flip", draw(st.integers(0, max(0, n - 1))), draw(st.integers(0, 255))) for _ in range(k)]


def _apply(data: bytes, edits) -> bytes:
    b = bytearray(data)
    for e in edits:
        if e[0] == "cut":
            b = b[: e[1]]
        elif e[0] == "insert":
            b[e[1] : e[1]] = e[2]
        elif b:
            b[e[1] % len(b)] = e[2]
    return bytes(b)


def _expect_only_read_error(fn, path: Path) -> None:
    try:
        fn(path)
    except ReadError as exc:
        msg = str(exc)
        assert "\n" not in msg, msg
        assert path.name in msg or path.stem in msg, msg
    # reading successfully is fine too: many flips land in a number


@pytest.mark.parametrize("name", POINT_FILES)
@FUZZ
@given(data=st.data())
def test_point_readers_survive_corruption(name, data):
    src = DATA / name
    with tempfile.TemporaryDirectory() as d:
        d = Path(d)
        target = d / name
        for sib in src.parent.glob(f"{src.stem}.*"):
            shutil.copy(sib, d / sib.name)
        # corrupt the main file (for shapefiles: one of its three parts)
        victim = target
        if src.suffix == ".shp":
            victim = d / f"{src.stem}{data.draw(st.sampled_from(['.shp', '.shx', '.dbf']))}"
        raw = victim.read_bytes()
        victim.write_bytes(_apply(raw, data.draw(corruption(len(raw)))))
        _expect_only_read_error(read_points, target)


@pytest.mark.parametrize(
    "suffix",
    [
        ".csv",
        ".kml",
        ".kmz",
        ".gpx",
        ".geojson",
        ".shp",
        ".dxf",
        ".xyz",
        ".vts",
        ".vtm",
        ".npz",
        ".cgns",
        ".grd",
        ".nc",
    ],
)
@FUZZ
@given(blob=st.binary(max_size=600))
def test_random_bytes(suffix, blob):
    with tempfile.TemporaryDirectory() as d:
        f = Path(d) / f"r{suffix}"
        f.write_bytes(blob)
        if suffix == ".shp":
            (Path(d) / "r.shx").write_bytes(blob[::-1])
            (Path(d) / "r.dbf").write_bytes(blob[:50])
        fn = read_blocks if suffix in (".xyz", ".vts", ".vtm", ".npz", ".cgns", ".grd", ".nc") else read_points
        _expect_only_read_error(fn, f)


@pytest.fixture(scope="module")
def grid_files(tmp_path_factory):
    d = tmp_path_factory.mktemp("grids")
    s, t = np.meshgrid(np.linspace(0, 1, 6), np.linspace(0, 1, 4), indexing="ij")
    g = meshcore.StructuredGrid(1000 * s + 50 * t, 600 * t + 30 * s * s, names={"top": "shore"})
    for name, opts in GRID_SUFFIXES:
        write(d / name, g, crs="EPSG:32632", origin=(480000.0, 5240000.0), **opts)
    return d


@pytest.mark.parametrize(("name", "opts"), GRID_SUFFIXES)
@FUZZ
@given(data=st.data())
def test_grid_readers_survive_corruption(grid_files, name, opts, data):
    raw = (grid_files / name).read_bytes()
    with tempfile.TemporaryDirectory() as d:
        f = Path(d) / name
        f.write_bytes(_apply(raw, data.draw(corruption(len(raw)))))
        _expect_only_read_error(read_blocks, f)


@pytest.mark.parametrize(("name", "opts"), GRID_SUFFIXES)
def test_truncated_grid_files(grid_files, name, opts, tmp_path):
    raw = (grid_files / name).read_bytes()
    # a text file cut inside its very last number is still a valid file: not tested
    text = name in ("g.xyz", "g.grd", "g.csv")
    for frac in (0.0, 0.1, 0.5, 0.9) if text else (0.0, 0.1, 0.5, 0.9, 0.99):
        f = tmp_path / name
        f.write_bytes(raw[: int(len(raw) * frac)])
        with pytest.raises(ReadError):
            read_blocks(f)
