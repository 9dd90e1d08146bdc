"""One index space written out: a Delft3D single-domain .grd/.enc and EFDC's grid files,
each read back by an independent parser written here and compared with the blocks."""

from __future__ import annotations

import numpy as np
import pytest
import shapely

from meshcore.errors import WriteError
from meshcore.grid import StructuredGrid
from meshcore.io import write

from .test_indexspace import frame, oriented, quad

ROUND = 9  # decimals of a coordinate key


def key(p) -> tuple[float, float]:
    return (round(float(p[0]), ROUND), round(float(p[1]), ROUND))


def block_cells(blocks) -> set[frozenset]:
    out = set()
    for g in blocks:
        for i in range(g.cells[0]):
            for j in range(g.cells[1]):
                out.add(
                    frozenset(key((g.x[a, b], g.y[a, b])) for a, b in ((i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)))
                )
    return out


# ---------------------------------------------------------------- an independent Delft3D reader
def read_grd_with_missing(path):
    lines = path.read_text().splitlines()
    k = 0
    missing = None
    while lines[k].startswith("*") or "=" in lines[k]:
        if lines[k].lower().startswith("missing value"):
            missing = float(lines[k].split("=")[1])
        k += 1
    mmax, nmax = (int(v) for v in lines[k].split())
    vals = []
    for ln in lines[k + 2 :]:
        vals += [float(t) for t in (ln.split("=")[1].split()[1:] if "ETA=" in ln else ln.split())]
    a = np.array(vals)
    assert a.size == 2 * mmax * nmax
    X = a[: mmax * nmax].reshape(nmax, mmax).T
    Y = a[mmax * nmax :].reshape(nmax, mmax).T
    return X, Y, missing


def read_enc(path):
    polys, cur = [], []
    for ln in path.read_text().splitlines():
        p = tuple(int(v) for v in ln.split()[:2])
        cur.append(p)
        if len(cur) > 1 and p == cur[0]:
            polys.append(cur)
            cur = []
    assert not cur, "an enclosure polygon is not closed"
    return polys


def active_cells(polys, mmax, nmax) -> np.ndarray:
    """Water-level points (m, n) strictly inside the first polygon and not inside or on another."""
    outer = shapely.Polygon(polys[0])
    inner = [
        shapely.Polygon(p) if len(set(p)) > 2 else shapely.LineString(p) if len(set(p)) == 2 else shapely.Point(p[0])
        for p in polys[1:]
    ]
    act = np.zeros((mmax + 2, nmax + 2), bool)
    for m in range(1, mmax + 2):
        for n in range(1, nmax + 2):
            pt = shapely.Point(m, n)
            act[m, n] = outer.contains(pt) and not any(h.intersects(pt) for h in inner)
    return act


def grd_cells(X, Y, missing, act) -> set[frozenset]:
    """Cells of active water-level points (m, n): depth points m-1 … m, n-1 … n (1-based)."""
    out = set()
    for m, n in zip(*np.nonzero(act), strict=True):
        corners = [(m - 2, n - 2), (m - 1, n - 2), (m - 1, n - 1), (m - 2, n - 1)]  # 0-based depth points
        assert all(X[a, b] != missing and Y[a, b] != missing for a, b in corners), (
            f"active cell ({m}, {n}) has a missing corner"
        )
        out.add(frozenset(key((X[a, b], Y[a, b])) for a, b in corners))
    return out


def l_shape() -> list[StructuredGrid]:
    return [
        quad((0, 0), (2, 0), (2, 1), (0, 1), 4, 2),
        quad((2, 0), (3, 0), (3, 1), (2, 1), 2, 2),
        quad((2, 1), (3, 1), (3, 3), (2, 3), 2, 4),
    ]


def thin_hole() -> list[StructuredGrid]:
    """Blocks round an island one cell across in index space."""
    b = quad((0, 0), (3, 0), (3, 1), (0, 1), 6, 2)
    t = quad((0, 1.2), (3, 1.2), (3, 2.2), (0, 2.2), 6, 2)
    w = quad((0, 1), (1, 1), (1, 1.2), (0, 1.2), 2, 1)
    e = quad((2, 1), (3, 1), (3, 1.2), (2, 1.2), 2, 1)
    return [b, e, oriented(t, 2), w]


CASES = {
    "frame": frame(),
    "frame turned": [oriented(g, k) for g, k in zip(frame(), (2, 5, 1, 7), strict=True)],
    "L": l_shape(),
    "thin island": thin_hole(),
}


@pytest.mark.parametrize("case", list(CASES))
def test_delft3d_single_domain_read_back_node_for_node(tmp_path, case):
    blocks = CASES[case]
    path = tmp_path / "lake.grd"
    write(path, blocks, format="delft3d-single")
    X, Y, missing = read_grd_with_missing(path)
    assert missing == pytest.approx(-999.999)
    valid = np.not_equal(X, missing)
    assert (valid == np.not_equal(Y, missing)).all()
    nodes = {key(p) for p in zip(X[valid], Y[valid], strict=True)}
    assert nodes == {key(p) for g in blocks for p in g.points}  # every block node, nothing else
    polys = read_enc(path.with_suffix(".enc"))
    act = active_cells(polys, *X.shape)
    assert grd_cells(X, Y, missing, act) == block_cells(blocks)
    assert int(act.sum()) == sum(g.cells[0] * g.cells[1] for g in blocks)


def test_one_block_gives_the_full_enclosure(tmp_path):
    g = quad((0, 0), (2, 0), (2, 1), (0, 1), 5, 3)
    write(tmp_path / "one.grd", [g], format="delft3d-single")
    assert read_enc(tmp_path / "one.enc") == [[(1, 1), (7, 1), (7, 5), (1, 5), (1, 1)]]


def test_delft3d_single_refusals_leave_nothing(tmp_path):
    with pytest.raises(WriteError, match=r"do not add up.*\.ddb"):
        write(tmp_path / "a.grd", frame(2, 4), format="delft3d-single")
    a = quad((0, 0), (1, 0), (1, 1), (0, 1), 2, 2)
    b = quad((3, 0), (4, 0), (4, 1), (3, 1), 2, 2)
    with pytest.raises(WriteError, match="2 parts"):
        write(tmp_path / "b.grd", [a, b], format="delft3d-single")
    assert list(tmp_path.iterdir()) == []


# ---------------------------------------------------------------- an independent EFDC reader
def read_efdc(folder):
    rows = [ln for ln in (folder / "cell.inp").read_text().splitlines() if ln[:1] not in "Cc*#"]
    jc = int(rows[0][:4])
    ic = len(rows[0]) - 5
    types = np.zeros((ic + 1, jc + 1), int)
    for ln in rows:
        j = int(ln[:4])
        types[1:, j] = [int(ch) for ch in ln[5:]]

    def table(name):
        out = {}
        for ln in (folder / name).read_text().splitlines():
            if ln[:1] not in "Cc*#":
                v = ln.split()
                out[(int(v[0]), int(v[1]))] = np.array([float(t) for t in v[2:]])
        return out

    return types, table("dxdy.inp"), table("lxly.inp"), table("corners.inp")


@pytest.mark.parametrize("case", list(CASES))
def test_efdc_files_read_back(tmp_path, case):
    blocks = CASES[case]
    write(tmp_path / "cell.inp", blocks)
    types, dxdy, lxly, corners = read_efdc(tmp_path)
    assert (tmp_path / "celllt.inp").read_text().split("\n", 1)[1] == (tmp_path / "cell.inp").read_text().split(
        "\n", 1
    )[1]
    water = {ij for ij, t in np.ndenumerate(types) if t == 5}
    assert water == set(dxdy) == set(lxly) == set(corners)
    # the cells are the blocks' cells, corners SW, NW, NE, SE clockwise
    cells = {}
    for ij, c in corners.items():
        sw, nw, ne, se = c.reshape(4, 2)
        assert (se[0] - sw[0]) * (nw[1] - sw[1]) - (se[1] - sw[1]) * (nw[0] - sw[0]) > 0  # NW left of SW→SE
        cells[ij] = frozenset(key(p) for p in (sw, nw, ne, se))
    assert set(cells.values()) == block_cells(blocks) and len(cells) == len(block_cells(blocks))
    # neighbours in (I, J) share their face: east of (I, J) is west of (I+1, J), north of (I, J) south of (I, J+1)
    for (i, j), c in corners.items():
        sw, nw, ne, se = c.reshape(4, 2)
        if (i + 1, j) in corners:
            np.testing.assert_allclose(corners[(i + 1, j)].reshape(4, 2)[[0, 1]], [se, ne])
        if (i, j + 1) in corners:
            np.testing.assert_allclose(corners[(i, j + 1)].reshape(4, 2)[[0, 3]], [nw, ne])
        dx, dy, depth, bottom = dxdy[(i, j)][:4]
        assert dx == pytest.approx(np.hypot(*(0.5 * (se + ne) - 0.5 * (sw + nw))), abs=2e-6)
        assert dy == pytest.approx(np.hypot(*(0.5 * (nw + ne) - 0.5 * (sw + se))), abs=2e-6)
        assert depth > 0 and bottom == pytest.approx(-depth)
        x, y, cue, cve, cun, cvn, shelter = lxly[(i, j)]
        assert shelter == 1.0
        np.testing.assert_allclose([x, y], c.reshape(4, 2).mean(0), atol=2e-6)
        u = 0.5 * (se + ne) - 0.5 * (sw + nw)
        np.testing.assert_allclose([cue, cun], u / np.hypot(*u), atol=2e-6)
        assert cue * cvn - cun * cve > 0  # J to the left of I
    # land ring: 9 exactly on the land cells next to water (8 neighbours), 0 elsewhere, none at water
    ic, jc = types.shape[0] - 1, types.shape[1] - 1
    for i in range(1, ic + 1):
        for j in range(1, jc + 1):
            near = any((i + a, j + b) in water for a in (-1, 0, 1) for b in (-1, 0, 1))
            assert types[i, j] == (5 if (i, j) in water else 9 if near else 0)
    assert all(types[i, j] != 5 for i in (1, ic) for j in range(1, jc + 1))


def test_efdc_needs_cell_inp_and_an_index_space(tmp_path):
    with pytest.raises(WriteError, match=r"cell\.inp"):
        write(tmp_path / "grid.inp", frame())
    with pytest.raises(WriteError, match="do not add up"):
        write(tmp_path / "cell.inp", frame(2, 4))
    assert list(tmp_path.iterdir()) == []
