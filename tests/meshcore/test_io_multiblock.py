"""Multiblock exports keep their connectivity: every format that can hold it writes it.

SU2 and Gmsh merge the nodes of every interface — also of interfaces that cover
only part of a border — so the mesh is conforming (no internal walls, no marker
along a cut); CGNS stores 1-to-1 connectivity with node ranges; ``.vtm`` blocks
carry the connectivity and the reader checks that shared nodes coincide.  Each
file is read back by the real reader (meshio, the gmsh API, h5py, VTK).
"""

from __future__ import annotations

import logging

import numpy as np
import pytest
import shapely

from meshcore.boundary import Borders
from meshcore.errors import ReadError
from meshcore.io import read_blocks, write
from meshcore.multiblock import Block, Interface, MultiBlockTopology, Side, solve_multiblock

logging.getLogger("meshio").setLevel(logging.ERROR)


def quad(sw, se, ne, nw, ni, nj) -> Borders:
    sw, se, ne, nw = (np.asarray(v, dtype=float) for v in (sw, se, ne, nw))
    li, lj = np.linspace(0, 1, ni + 1)[:, None], np.linspace(0, 1, nj + 1)[:, None]
    return Borders(
        bottom=sw + li * (se - sw), right=se + lj * (ne - se), top=nw + li * (ne - nw), left=sw + lj * (nw - sw)
    )


@pytest.fixture(scope="module")
def tee():
    """A wide block under two narrow ones: each covers half of its top border (a T-junction).

    ::

        +-----+-----+
        |  b  |  c  |
        +-----+-----+     a.top[0:2] = b.bottom, a.top[2:4] = c.bottom, b.right = c.left
        |     a     |
        +-----------+
    """
    blocks = (
        Block("a", quad([0, 0], [2, 0], [2, 1], [0, 1], 4, 2), names={"bottom": "bed"}),
        Block("b", quad([0, 1], [1, 1], [1, 2], [0, 2], 2, 3), names={"top": "shore"}),
        Block("c", quad([1, 1], [2, 1], [2, 2], [1, 2], 2, 3), names={"top": "shore"}),
    )
    itf = (
        Interface(Side("a", "top", 0, 2), Side("b", "bottom")),
        Interface(Side("a", "top", 2, 4), Side("c", "bottom")),
        Interface(Side("b", "right"), Side("c", "left")),
    )
    return solve_multiblock(MultiBlockTopology(blocks, itf))


def _distinct(points: np.ndarray) -> int:
    return len(np.unique(np.round(points[:, :2], 9), axis=0))


def _outer_boundary(mb):
    loops = [
        np.vstack([g.border("bottom"), g.border("right"), g.border("top")[::-1], g.border("left")[::-1]]) for g in mb
    ]
    return shapely.union_all([shapely.Polygon(p) for p in loops]).boundary


def _assert_conforming(points, quads, lines, mb, origin=(0.0, 0.0)):
    """Every node distinct; an edge is in ≤ 2 quads; the marker lines are exactly the edges of one quad,
    and all of them lie on the outer boundary (no wall along an interface)."""
    assert len(points) == _distinct(points) == mb.n_nodes
    e = np.stack([quads, np.roll(quads, -1, axis=1)], axis=-1).reshape(-1, 2)
    key, cnt = np.unique(np.sort(e, axis=1), axis=0, return_counts=True)
    assert cnt.max() == 2
    once = {tuple(k) for k in key[cnt == 1].tolist()}
    assert {tuple(sorted(ln)) for ln in lines.tolist()} == once
    outer = _outer_boundary(mb)
    mid = 0.5 * (points[lines[:, 0], :2] + points[lines[:, 1], :2]) - np.asarray(origin)
    assert all(outer.distance(shapely.Point(*m)) < 1e-9 for m in mid)


def test_su2_merges_partial_border_interfaces(tmp_path, tee):
    meshio = pytest.importorskip("meshio")
    f = write(tmp_path / "t.su2", tee)
    m = meshio.read(f)
    _assert_conforming(m.points, m.get_cells_type("quad"), m.get_cells_type("line"), tee)
    # markers: the named borders, and nothing on a.top (covered by b and c) or on b.right/c.left
    tags = [ln.split("=")[1].strip() for ln in f.read_text().splitlines() if ln.startswith("MARKER_TAG")]
    assert sorted(tags) == ["bed", "left", "right", "shore"]


def test_gmsh_merges_partial_border_interfaces(tmp_path, tee):
    gmsh = pytest.importorskip("gmsh")
    f = write(tmp_path / "t.msh", tee)
    gmsh.initialize(interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.open(str(f))
        tags, coords, _ = gmsh.model.mesh.getNodes()
        pos = {int(t): k for k, t in enumerate(tags)}
        pts = coords.reshape(-1, 3)
        _, qn = gmsh.model.mesh.getElementsByType(3)
        _, ln = gmsh.model.mesh.getElementsByType(1)
        quads = np.array([pos[int(t)] for t in qn]).reshape(-1, 4)
        lines = np.array([pos[int(t)] for t in ln]).reshape(-1, 2)
        _assert_conforming(pts, quads, lines, tee)
        groups = {gmsh.model.getPhysicalName(d, t) for d, t in gmsh.model.getPhysicalGroups(1)}
        assert groups == {"bed", "left", "right", "shore"}
    finally:
        gmsh.finalize()


def test_interfaces_found_from_coordinates_include_border_parts(tmp_path, tee):
    """Blocks without declared connectivity (a list of grids): the parts are found by coordinates."""
    meshio = pytest.importorskip("meshio")
    f = write(tmp_path / "t.su2", list(tee.blocks))
    m = meshio.read(f)
    _assert_conforming(m.points, m.get_cells_type("quad"), m.get_cells_type("line"), tee)


def _cgns_range_nodes(zone, rng):
    X = zone["GridCoordinates/CoordinateX/ data"][()].T
    Y = zone["GridCoordinates/CoordinateY/ data"][()].T
    (i0, j0), (i1, j1) = rng
    n = max(abs(i1 - i0), abs(j1 - j0)) + 1
    ii = np.linspace(i0, i1, n).round().astype(int) - 1
    jj = np.linspace(j0, j1, n).round().astype(int) - 1
    return np.column_stack([X[ii, jj], Y[ii, jj]])


def test_cgns_one_to_one_with_node_ranges_read_by_h5py(tmp_path, tee):
    h5py = pytest.importorskip("h5py")
    f = write(tmp_path / "t.cgns", tee)
    with h5py.File(f, "r") as h:
        base = h["Base"]
        n_links = 0
        for zname in ("a", "b", "c"):
            z = base[zname]
            zgc = z["ZoneGridConnectivity"]
            for c in zgc.values():
                donor = bytes(c[" data"][()].astype(np.uint8)).decode()
                mine = _cgns_range_nodes(z, c["PointRange/ data"][()].tolist())
                theirs = _cgns_range_nodes(base[donor], c["PointRangeDonor/ data"][()].tolist())
                np.testing.assert_allclose(mine, theirs, atol=1e-12)  # the shared nodes coincide
                n_links += 1
        assert n_links == 6  # three interfaces, stored by both zones
        # a.top is covered by interfaces: no boundary condition there
        for bc in base["a/ZoneBC"].values():
            (_, j0), (_, j1) = bc["PointRange/ data"][()].tolist()
            assert not (j0 == j1 == 3)
    back = read_blocks(f)
    assert len(back.connectivity) == 3
    assert {it.range_a for it in back.connectivity} >= {(0, 2), (2, 4)}
    assert back.blocks[0].names == {"bottom": "bed"} and back.blocks[1].names == {"top": "shore"}
    # and the round trip CGNS → SU2 stays conforming
    meshio = pytest.importorskip("meshio")
    m = meshio.read(write(tmp_path / "t2.su2", back))
    _assert_conforming(m.points, m.get_cells_type("quad"), m.get_cells_type("line"), tee)


def test_ddb_couplings_become_connectivity(tmp_path, tee):
    """Delft3D domain decomposition → SU2: the partial couplings keep the mesh conforming."""
    meshio = pytest.importorskip("meshio")
    gs = read_blocks(write(tmp_path / "t.ddb", tee))
    assert len(gs.connectivity) == 3
    m = meshio.read(write(tmp_path / "t.su2", gs))
    assert len(m.points) == _distinct(m.points) == tee.n_nodes


def test_cgns_read_by_vtk(tmp_path, tee):
    vtk = pytest.importorskip("vtk")
    f = write(tmp_path / "t.cgns", tee)
    r = vtk.vtkCGNSReader()
    r.SetFileName(str(f))
    r.UpdateInformation()
    r.EnableAllBases()
    r.Update()
    assert r.GetOutput().GetBlock(0).GetNumberOfBlocks() == 3


def test_vtm_carries_connectivity_and_shares_nodes(tmp_path, tee):
    vtk = pytest.importorskip("vtk")
    from vtk.util.numpy_support import vtk_to_numpy

    f = write(tmp_path / "t.vtm", tee)
    r = vtk.vtkXMLMultiBlockDataReader()
    r.SetFileName(str(f))
    r.Update()
    out = r.GetOutput()
    pts = np.vstack([vtk_to_numpy(out.GetBlock(k).GetPoints().GetData()) for k in range(out.GetNumberOfBlocks())])
    assert len(pts) == sum(g.n_nodes for g in tee.blocks) and _distinct(pts) == tee.n_nodes
    conn = out.GetBlock(0).GetFieldData().GetAbstractArray("connectivity").GetValue(0)
    assert '"top", 1, "bottom"' in conn
    back = read_blocks(f)
    assert len(back.connectivity) == 3


def test_vtm_reader_checks_the_shared_nodes(tmp_path, tee):
    f = write(tmp_path / "t.vtm", tee)
    blk = tmp_path / "t" / "t_1.vts"
    data = blk.read_bytes()
    # move block b by editing its origin field: its bottom no longer meets a.top[0:2]
    start = data.index(b'Name="origin"')
    a, b = data.index(b">", start) + 1, data.index(b"</Array>", start)
    blk.write_bytes(data[:a] + b"0.25 0.0" + data[b:])
    with pytest.raises(ReadError, match=r"t\.vtm.*interface 0.*does not coincide"):
        read_blocks(f)


def test_vtm_from_another_write_is_refused(tmp_path, tee):
    """A crash between the renames of the block folder and of the .vtm: old .vtm, new folder."""
    f = write(tmp_path / "t.vtm", list(tee.blocks)[:2])  # the old file lists 2 blocks
    old_vtm = f.read_bytes()
    write(f, tee)  # the new write has 3 blocks
    f.write_bytes(old_vtm)  # … and the old .vtm is still there
    with pytest.raises(ReadError, match=r"does not belong to this \.vtm"):
        read_blocks(f)


def test_cli_generate_shasta_multiblock_every_connected_format(tmp_path):
    """The issue's command: `meshcore generate shasta-multiblock-coarse.toml -o s.su2` (and .msh, .cgns, .vtm)."""
    meshio = pytest.importorskip("meshio")
    from meshcore.case import generate_case, load_case
    from meshcore.cli import main
    from meshcore.cli.examples import example_path

    case = example_path("shasta-multiblock-coarse")
    assert main(["generate", str(case), "-o", str(tmp_path / "s.su2"), "-q"]) == 0
    mb = generate_case(load_case(case))
    m = meshio.read(tmp_path / "s.su2")
    assert len(m.points) == _distinct(m.points) == mb.n_nodes  # 3063, not 3109
    _assert_conforming(m.points, m.get_cells_type("quad"), m.get_cells_type("line"), mb, mb.frame.origin)
    gs = read_blocks(write(tmp_path / "s.cgns", mb, crs=mb.frame))
    assert len(gs.connectivity) == len(mb.interfaces)
    gv = read_blocks(write(tmp_path / "s.vtm", mb, crs=mb.frame))
    assert len(gv.connectivity) == len(mb.interfaces)
