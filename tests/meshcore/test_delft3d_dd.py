"""Delft3D domain decomposition: .grd/.enc per block + .ddb, written as a set and read back."""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import pytest

from meshcore import StructuredGrid
from meshcore.errors import ReadError, WriteError
from meshcore.io import delft3d_dd as dd
from meshcore.io import read_blocks, write
from tests.conftest import ROOT

EXAMPLES = ROOT / "resources" / "examples"


# ------------------------------------------------------------- independent parsers
def parse_grd(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """x, y of shape (MMAX, NMAX) from an RGFGRID file, without meshcore's reader."""
    lines = path.read_text().splitlines()
    k = next(i for i, ln in enumerate(lines) if not ln.startswith("*") and "=" not in ln)
    mmax, nmax = map(int, lines[k].split())
    vals = []
    for ln in lines[k + 2 :]:
        vals += [float(t) for t in (ln.split("=", 1)[1].split()[1:] if "ETA=" in ln else ln.split())]
    a = np.array(vals)
    assert a.size == 2 * mmax * nmax
    return a[: mmax * nmax].reshape(nmax, mmax).T, a[mmax * nmax :].reshape(nmax, mmax).T


def parse_ddb(path: Path) -> list[tuple[str, list[int], str, list[int]]]:
    out = []
    for ln in path.read_text().splitlines():
        t = ln.split()
        out.append((t[0], [int(v) for v in t[1:5]], t[5], [int(v) for v in t[6:10]]))
    return out


def segment(x, y, mn):
    """Points (m1,n1) … (m2,n2) of a grid line, 1-based indices, begin to end."""
    m1, n1, m2, n2 = mn
    if m1 == m2:
        n = np.arange(n1, n2 + (1 if n2 >= n1 else -1), 1 if n2 >= n1 else -1)
        return np.column_stack([x[m1 - 1, n - 1], y[m1 - 1, n - 1]])
    assert n1 == n2
    m = np.arange(m1, m2 + (1 if m2 >= m1 else -1), 1 if m2 >= m1 else -1)
    return np.column_stack([x[m - 1, n1 - 1], y[m - 1, n1 - 1]])


def node_runs(grids: dict[str, StructuredGrid], interfaces, origin=(0.0, 0.0)) -> set:
    """Each interface as {block names} + the rounded world coordinates of its nodes."""
    out = set()
    for itf in interfaces:
        pts = grids[itf.a.block].border(itf.a.border)[itf.a.start : itf.a.stop + 1] + origin
        out.add((frozenset((itf.a.block, itf.b.block)), frozenset(map(tuple, np.round(pts, 4)))))
    return out


# -------------------------------------------------------------------- the lake
@pytest.fixture(scope="module")
def shasta():
    from meshcore.case import generate_case, load_case

    return generate_case(load_case(EXAMPLES / "shasta-multiblock-coarse.toml"))


def test_shasta_writes_a_complete_set_and_reads_back(shasta, tmp_path):
    mb = shasta
    write(tmp_path / "lake.ddb", mb, crs=mb.frame)
    names = sorted(p.name for p in tmp_path.iterdir())
    assert names == sorted(["lake.ddb"] + [f"lake_{n}.{s}" for n in mb.names for s in ("grd", "enc")])
    back = dd.read_dd(tmp_path / "lake.ddb")
    assert back.blocks.block_names == mb.names and back.blocks.frame.crs == mb.frame.crs
    origin = np.asarray(mb.frame.origin)
    for name, g in zip(mb.names, back.blocks.blocks, strict=True):
        orig = mb[name]
        hits = [r for r in range(4) if dd.turned(orig, r).shape == g.shape]
        ok = [r for r in hits if np.allclose(dd.turned(orig, r).x + origin[0], g.x, rtol=0, atol=1e-8)]
        assert ok, name  # the same nodes, possibly turned by quarter turns of the index space
    # the same coupling as the topology's interfaces, node for node
    world = dict(zip(mb.names, back.blocks.blocks, strict=True))
    mine = {n: mb[n] for n in mb.names}
    assert node_runs(world, back.interfaces) == node_runs(mine, mb.interfaces, origin)
    # and a valid topology with as many unique nodes as the original
    topo = back.topology()
    assert topo.node_map.n_nodes == mb.topology.node_map.n_nodes
    assert read_blocks(tmp_path / "lake.ddb").block_names == mb.names


def test_ddb_lines_couple_coinciding_grid_points_in_independently_parsed_grd_files(shasta, tmp_path):
    write(tmp_path / "lake.ddb", shasta, crs=shasta.frame)
    lines = parse_ddb(tmp_path / "lake.ddb")
    assert len(lines) == len(shasta.interfaces)
    for fa, mna, fb, mnb in lines:
        xa, ya = parse_grd(tmp_path / fa)
        xb, yb = parse_grd(tmp_path / fb)
        for x, (m1, n1, m2, n2) in ((xa, mna), (xb, mnb)):
            # a segment of one grid line on the grid's outer boundary
            assert (m1 == m2 and m1 in (1, x.shape[0])) or (n1 == n2 and n1 in (1, x.shape[1]))
        # M-lines couple to M-lines, N-lines to N-lines, begin to begin
        assert (mna[0] == mna[2]) == (mnb[0] == mnb[2])
        pa, pb = segment(xa, ya, mna), segment(xb, yb, mnb)
        assert len(pa) == len(pb) >= 2
        assert np.abs(pa - pb).max() < 1e-6 * math.hypot(np.ptp(xa), np.ptp(ya))


# -------------------------------------------------------------- hand-built cases
def product(xs, ys) -> StructuredGrid:
    X, Y = np.meshgrid(np.asarray(xs, float), np.asarray(ys, float), indexing="ij")
    return StructuredGrid(X, Y)


def test_partial_interface_indices_follow_the_grid_point_convention(tmp_path):
    main = product(np.linspace(0, 4, 9), np.linspace(0, 1, 3))  # 9 × 3 points
    arm = product(np.linspace(1, 3, 5), np.linspace(1, 2, 4))  # on main's top nodes i = 2 … 6
    write(tmp_path / "t.ddb", [main, arm], block_names=["main", "arm"])
    ((fa, mna, fb, mnb),) = parse_ddb(tmp_path / "t.ddb")
    # node (i, j) is grid point (m, n) = (i + 1, j + 1); main's top is n = NMAX = 3
    assert (fa, mna, fb, mnb) == ("t_main.grd", [3, 3, 7, 3], "t_arm.grd", [1, 1, 5, 1])
    (itf,) = dd.read_dd(tmp_path / "t.ddb").interfaces
    assert (itf.a.block, itf.a.border, itf.a.start, itf.a.stop) == ("main", "top", 2, 6)
    assert (itf.b.block, itf.b.border, itf.b.start, itf.b.stop, itf.reversed) == ("arm", "bottom", 0, 4, False)


def test_a_block_joined_along_the_wrong_line_kind_is_turned(tmp_path):
    a = product(np.linspace(0, 2, 5), np.linspace(0, 1, 3))
    b0 = product(np.linspace(2, 3, 3), np.linspace(0, 1, 3))
    b = dd.turned(b0, 1)  # a's right border now meets b's bottom border: M-line against N-line
    assert {c.border_b for c in dd.find_couplings([a, b])} == {"bottom"}
    write(tmp_path / "r.ddb", [a, b], block_names=["a", "b"])
    ((_, mna, _, mnb),) = parse_ddb(tmp_path / "r.ddb")
    assert mna[0] == mna[2] == 5 and mnb[0] == mnb[2] == 1  # a.right ↔ b.left, both M-lines
    xb, yb = parse_grd(tmp_path / "r_b.grd")
    np.testing.assert_allclose(xb, b0.x, atol=1e-12)  # one more quarter turn brought b back
    np.testing.assert_allclose(yb, b0.y, atol=1e-12)
    xa, _ = parse_grd(tmp_path / "r_a.grd")
    np.testing.assert_array_equal(xa, a.x)  # the fewest blocks are turned


def star(k: int, n: int = 4) -> list[StructuredGrid]:
    """A regular 2k-gon in k quads meeting at the centre (q.left ↔ next.bottom)."""
    verts = [np.array([math.cos(a), math.sin(a)]) for a in math.pi / k * np.arange(2 * k)]
    t = np.linspace(0, 1, n + 1)
    S, T = np.meshgrid(t, t, indexing="ij")
    out = []
    for q in range(k):
        sw, se, ne, nw = np.zeros(2), verts[(2 * q - 1) % (2 * k)], verts[2 * q], verts[(2 * q + 1) % (2 * k)]
        P = (1 - S)[..., None] * (1 - T)[..., None] * sw + S[..., None] * (1 - T)[..., None] * se
        P = P + S[..., None] * T[..., None] * ne + (1 - S)[..., None] * T[..., None] * nw
        out.append(StructuredGrid(P[..., 0], P[..., 1]))
    return out


def test_four_blocks_at_a_corner_are_turned_into_one_orientation(tmp_path):
    write(tmp_path / "s.ddb", star(4))
    back = dd.read_dd(tmp_path / "s.ddb")
    assert len(back.interfaces) == 4
    for itf in back.interfaces:
        assert {itf.a.border, itf.b.border} in ({"left", "right"}, {"bottom", "top"}) and not itf.reversed
    assert back.topology().node_map.n_nodes == 81  # 4 × 25 nodes, 4 interfaces of 5, the centre once


@pytest.mark.parametrize("k", [3, 5])
def test_corner_of_three_or_five_blocks_is_a_clear_error_and_writes_nothing(tmp_path, k):
    with pytest.raises(WriteError, match="3 or 5 blocks"):
        write(tmp_path / "s.ddb", star(k))
    assert list(tmp_path.iterdir()) == []


def test_one_block_or_an_uncoupled_block_is_refused(tmp_path):
    a = product(np.linspace(0, 1, 3), np.linspace(0, 1, 3))
    with pytest.raises(WriteError, match="at least two blocks"):
        write(tmp_path / "one.ddb", a)
    with pytest.raises(WriteError, match="shares no border"):
        write(tmp_path / "two.ddb", [a, a.translated(1, 0), a.translated(5, 5)])
    assert list(tmp_path.iterdir()) == []


# ------------------------------------------------------------------ all or none
def test_failure_while_writing_leaves_no_file(tmp_path, monkeypatch):
    from meshcore.io import delft3d

    calls = []
    real = delft3d.write_grd

    def flaky(path, gs, **kw):
        calls.append(path)
        if len(calls) == 3:
            raise WriteError(f"{path}: disk full (simulated)")
        return real(path, gs, **kw)

    monkeypatch.setattr(delft3d, "write_grd", flaky)
    with pytest.raises(WriteError, match="simulated"):
        write(tmp_path / "s.ddb", star(4))
    assert list(tmp_path.iterdir()) == []


def test_failure_while_moving_into_place_restores_the_previous_set(tmp_path, monkeypatch):
    write(tmp_path / "s.ddb", star(4, n=2))
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    real, n = os.replace, []

    def failing(src, dst):  # the third move from the staging folder into place fails
        if Path(dst).parent == tmp_path and Path(src).parent.name.startswith(".s.ddb."):
            n.append(dst)
            if len(n) == 3:
                raise OSError(28, "No space left on device")
        return real(src, dst)

    monkeypatch.setattr(dd.os, "replace", failing)
    with pytest.raises(WriteError, match="No space left"):
        write(tmp_path / "s.ddb", star(4, n=6))
    monkeypatch.setattr(dd.os, "replace", real)
    assert len(n) == 3  # two files were in place already and were rolled back
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before


def test_non_finite_coordinates_are_refused(tmp_path):
    a = product(np.linspace(0, 1, 3), np.linspace(0, 1, 3))
    x = a.x.copy()
    x[1, 1] = np.nan
    with pytest.raises(WriteError, match=r"'block2'.*node \(1, 1\)"):
        write(tmp_path / "n.ddb", [a.translated(-1, 0), StructuredGrid(x, a.y)])
    assert list(tmp_path.iterdir()) == []


# -------------------------------------------------------------------- bad input
@pytest.fixture
def pair_files(tmp_path):
    a = product(np.linspace(0, 2, 5), np.linspace(0, 1, 3))
    write(tmp_path / "p.ddb", [a, a.translated(2, 0)], block_names=["w", "e"])
    return tmp_path


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ("", "empty"),
        ("# only a comment\n", "no couplings"),
        ("p_w.grd 5 1 5 3 p_e.grd 1 1 1\n", "line 1: a coupling needs 10 fields"),
        ("p_w.grd 5 1 5 x p_e.grd 1 1 1 3\n", "line 1: grid indices must be integers"),
        ("p_w.grd 5 1 5 3 p_none.grd 1 1 1 3\n", "p_none.grd not found"),
        ("p_w.grd 3 1 3 3 p_e.grd 1 1 1 3\n", "not part of the grid's outer boundary"),
        ("p_w.grd 5 1 5 9 p_e.grd 1 1 1 3\n", "outside the grid"),
        ("# comment\np_w.grd 5 1 5 3 p_e.grd 1 1 1 2\n", "line 2: 2 cells on p_w.grd but 1 on p_e.grd"),
    ],
)
def test_bad_ddb_is_a_clear_read_error(pair_files, text, match):
    (pair_files / "p.ddb").write_text(text)
    with pytest.raises(ReadError, match=match):
        dd.read_dd(pair_files / "p.ddb")
    with pytest.raises(ReadError):
        read_blocks(pair_files / "p.ddb")


def test_reversed_segment_in_a_hand_written_ddb_reads_as_a_reversed_interface(pair_files):
    (pair_files / "p.ddb").write_text("p_w.grd 5 3 5 1 ; begin at the top\np_e.grd 1 1 1 3\n")
    (itf,) = dd.read_dd(pair_files / "p.ddb").interfaces
    assert itf.reversed and (itf.a.start, itf.a.stop) == (0, 2)
    with pytest.raises(Exception, match="do not coincide"):
        dd.read_dd(pair_files / "p.ddb").topology()
