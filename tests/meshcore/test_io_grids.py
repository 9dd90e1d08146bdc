"""Grid exports read back by independent real readers (VTK, gmsh, meshio, netCDF4, h5py)."""

from __future__ import annotations

import json
import math
import os
import re

import numpy as np
import pytest

import meshcore
from meshcore.crs import Frame
from meshcore.errors import ReadError, WriteError
from meshcore.io import find_interfaces, read_blocks, read_grid, write
from meshcore.metrics import metrics
from meshcore.quality import cell_quality

ORIGIN = (480000.0, 5240000.0)
CRS = "EPSG:32632"


def _curved(ni=7, nj=4, x0=0.0, w=2000.0, names=None):
    """A smooth non-orthogonal grid (metres), ξ along x, η along y."""
    s, t = np.meshgrid(np.linspace(0, 1, ni + 1), np.linspace(0, 1, nj + 1), indexing="ij")
    x = x0 + w * s + 150.0 * np.sin(math.pi * t) * s * (1 - s) * 4 / 3
    y = 900.0 * t + 120.0 * np.sin(math.pi * s) * (1 - t) + 13.0 * s * t
    return meshcore.StructuredGrid(x, y, names=names or {})


@pytest.fixture
def grid():
    return _curved(names={"bottom": "inlet", "top": "shore"})


@pytest.fixture
def blocks():
    a = _curved(6, 4, names={"left": "inlet"})
    # block b shares a's right border node for node (ξ continues)
    s, t = np.meshgrid(np.linspace(0, 1, 4), np.linspace(0, 1, 5), indexing="ij")
    right = a.border("right")
    bx = right[:, 0][None, :] + 900.0 * s
    by = right[:, 1][None, :] * (1 - s) + (900.0 * t) * s
    b = meshcore.StructuredGrid(bx, by, names={"right": "outlet"})
    return [a, b]


def _world(g):
    return g.x + ORIGIN[0], g.y + ORIGIN[1]


def _rel(a, b, scale):
    return float(np.max(np.abs(np.asarray(a) - np.asarray(b)))) / scale


# ------------------------------------------------------------------ VTK XML
def test_vts_read_by_vtk(tmp_path, grid):
    vtk = pytest.importorskip("vtk")
    from vtk.util.numpy_support import vtk_to_numpy

    f = write(tmp_path / "g.vts", grid, crs=CRS, origin=ORIGIN)
    r = vtk.vtkXMLStructuredGridReader()
    r.SetFileName(str(f))
    r.Update()
    o = r.GetOutput()
    assert o.GetExtent() == (0, grid.cells[0], 0, grid.cells[1], 0, 0)
    pts = vtk_to_numpy(o.GetPoints().GetData())
    X, Y = _world(grid)
    np.testing.assert_array_equal(pts[:, 0], X.ravel(order="F"))
    np.testing.assert_array_equal(pts[:, 1], Y.ravel(order="F"))
    m = metrics(grid)
    for name in ("jacobian", "alpha", "beta", "gamma", "xi_x", "eta_y"):
        np.testing.assert_array_equal(vtk_to_numpy(o.GetPointData().GetArray(name)), getattr(m, name).ravel(order="F"))
    cq = cell_quality(grid)
    assert o.GetNumberOfCells() == grid.cells[0] * grid.cells[1]
    for name in ("skewness", "orthogonality", "aspect_ratio", "area"):
        np.testing.assert_array_equal(vtk_to_numpy(o.GetCellData().GetArray(name)), cq[name].ravel(order="F"))
    fd = o.GetFieldData()
    assert fd.GetAbstractArray("crs").GetValue(0) == CRS
    assert json.loads(fd.GetAbstractArray("border_names").GetValue(0))["bottom"] == "inlet"
    np.testing.assert_array_equal(vtk_to_numpy(fd.GetArray("origin")), [ORIGIN])
    # our reader: local coordinates, frame and names come back
    gs = read_blocks(f)
    assert gs.frame == Frame(CRS, ORIGIN)
    assert gs.blocks[0].names == grid.names
    assert _rel(gs.blocks[0].x, grid.x, grid.size) < 1e-12


def test_vts_written_by_vtk_is_read(tmp_path, grid):
    """Our reader accepts what VTK writes (zlib-compressed appended base64, ascii, binary)."""
    vtk = pytest.importorskip("vtk")
    sg = vtk.vtkStructuredGrid()
    sg.SetDimensions(grid.shape[0], grid.shape[1], 1)
    pts = vtk.vtkPoints()
    pts.SetDataTypeToDouble()
    for j in range(grid.shape[1]):
        for i in range(grid.shape[0]):
            pts.InsertNextPoint(grid.x[i, j], grid.y[i, j], 0.0)
    sg.SetPoints(pts)
    for mode in ("appended", "ascii", "binary"):
        for compress in (True, False):
            f = tmp_path / f"vtk_{mode}_{compress}.vts"
            w = vtk.vtkXMLStructuredGridWriter()
            w.SetFileName(str(f))
            w.SetInputData(sg)
            getattr(w, f"SetDataModeTo{mode.capitalize()}")()
            if not compress:
                w.SetCompressorTypeToNone()
            if mode == "appended":
                w.SetEncodeAppendedData(compress)
            assert w.Write() == 1
            (g,) = read_grid(f)
            assert _rel(g.x, grid.x, grid.size) <= (1e-12 if mode != "ascii" else 1e-6)
            assert _rel(g.y, grid.y, grid.size) <= (1e-12 if mode != "ascii" else 1e-6)


def test_vtm_read_by_vtk(tmp_path, blocks):
    vtk = pytest.importorskip("vtk")
    from vtk.util.numpy_support import vtk_to_numpy

    f = write(tmp_path / "m.vtm", blocks, block_names=["west", "east"], crs=CRS, origin=ORIGIN)
    assert sorted(os.listdir(tmp_path)) == ["m", "m.vtm"]
    r = vtk.vtkXMLMultiBlockDataReader()
    r.SetFileName(str(f))
    r.Update()
    mb = r.GetOutput()
    assert mb.GetNumberOfBlocks() == 2
    for k, g in enumerate(blocks):
        assert mb.GetMetaData(k).Get(vtk.vtkCompositeDataSet.NAME()) == ["west", "east"][k]
        pts = vtk_to_numpy(mb.GetBlock(k).GetPoints().GetData())
        X, Y = _world(g)
        np.testing.assert_array_equal(pts[:, 0], X.ravel(order="F"))
        np.testing.assert_array_equal(pts[:, 1], Y.ravel(order="F"))
    gs = read_blocks(f)
    assert gs.block_names == ("west", "east") and gs.frame.crs == CRS
    # overwriting replaces the block directory atomically
    write(f, blocks[:1], crs=CRS)
    assert len(read_blocks(f)) == 1 and sorted(os.listdir(tmp_path / "m")) == ["m_0.vts"]


# ------------------------------------------------------------------ PLOT3D
def _vtk_plot3d(path, *, multi, binary, byte_count, double=True):
    vtk = pytest.importorskip("vtk")
    from vtk.util.numpy_support import vtk_to_numpy

    r = vtk.vtkMultiBlockPLOT3DReader()
    r.SetXYZFileName(str(path))
    r.AutoDetectFormatOff()
    r.SetMultiGrid(multi)
    r.SetBinaryFile(binary)
    r.SetHasByteCount(byte_count)
    r.SetTwoDimensionalGeometry(1)
    r.SetDoublePrecision(double)
    r.SetIBlanking(0)
    r.SetByteOrderToLittleEndian()
    r.Update()
    mb = r.GetOutput()
    out = []
    for k in range(mb.GetNumberOfBlocks()):
        b = mb.GetBlock(k)
        e = b.GetExtent()
        pts = vtk_to_numpy(b.GetPoints().GetData())
        shape = (e[1] - e[0] + 1, e[3] - e[2] + 1)
        out.append((pts[:, 0].reshape(shape, order="F"), pts[:, 1].reshape(shape, order="F")))
    return out


@pytest.mark.parametrize("mode", ["ascii", "fortran", "binary"])
@pytest.mark.parametrize("multi", [False, True])
def test_plot3d_read_by_vtk(tmp_path, grid, blocks, mode, multi):
    grids = blocks if multi else [grid]
    f = write(tmp_path / "g.xyz", grids if multi else grid, mode=mode, crs=CRS, origin=ORIGIN)
    got = _vtk_plot3d(f, multi=multi, binary=mode != "ascii", byte_count=mode == "fortran")
    assert len(got) == len(grids)
    for (x, y), g in zip(got, grids, strict=True):
        X, Y = _world(g)
        assert x.shape == g.shape
        # binary: exact; ASCII: 17 significant digits print exactly too
        assert _rel(x, X, g.size) <= 1e-12 and _rel(y, Y, g.size) <= 1e-12
    # and our reader detects the encoding by itself (world coordinates; PLOT3D has no CRS)
    back = read_grid(f)
    for b, g in zip(back, grids, strict=True):
        assert _rel(b.x - ORIGIN[0], g.x, g.size) <= 1e-12


def test_plot3d_single_precision_big_endian(tmp_path, grid):
    f = write(tmp_path / "g.x", grid, mode="fortran", precision="single", byte_order="big")
    (g,) = read_grid(f)
    assert _rel(g.x, grid.x, grid.size) < 1e-6 and _rel(g.y, grid.y, grid.size) < 1e-6


# ------------------------------------------------------------------ CGNS
def _s(a):
    return bytes(np.asarray(a)).split(b"\x00")[0].decode()


def test_cgns_sids_layout_and_vtk_reader(tmp_path, blocks):
    h5py = pytest.importorskip("h5py")
    conn = find_interfaces(blocks)
    assert [(c.a, c.border_a, c.b, c.border_b, c.reversed) for c in conn] == [(0, "right", 1, "left", False)]
    f = write(tmp_path / "m.cgns", blocks, block_names=["west", "east"], crs=CRS, origin=ORIGIN)
    with h5py.File(f, "r") as h:
        assert _s(h.attrs["label"]) == "Root Node of HDF5 File"
        assert " format" in h and " hdf5version" in h
        assert _s(h["CGNSLibraryVersion"].attrs["label"]) == "CGNSLibraryVersion_t"
        base = h["Base"]
        assert _s(base.attrs["label"]) == "CGNSBase_t" and _s(base.attrs["type"]) == "I4"
        assert base[" data"][:].tolist() == [2, 2]
        assert bytes(base["CRS"][" data"][:].astype(np.uint8)).decode() == CRS
        for k, (name, g) in enumerate(zip(["west", "east"], blocks, strict=True)):
            z = base[name]
            assert _s(z.attrs["label"]) == "Zone_t"
            ni, nj = g.cells
            assert z[" data"][:].tolist() == [[ni + 1, nj + 1], [ni, nj], [0, 0]]
            assert bytes(z["ZoneType"][" data"][:].astype(np.uint8)) == b"Structured"
            X = z["GridCoordinates/CoordinateX/ data"][:]
            assert X.shape == (nj + 1, ni + 1)  # Fortran order: HDF5 dims reversed
            np.testing.assert_array_equal(X.T, _world(g)[0])
            assert _s(z["GridCoordinates/CoordinateY"].attrs["type"]) == "R8"
            bcs = {n: z["ZoneBC"][n] for n in z["ZoneBC"]}
            for n in bcs:
                assert _s(bcs[n].attrs["label"]) == "BC_t"
                assert _s(bcs[n]["PointRange"].attrs["label"]) == "IndexRange_t"
            zgc = z["ZoneGridConnectivity"]
            (cn,) = list(zgc)
            c = zgc[cn]
            assert _s(c.attrs["label"]) == "GridConnectivity1to1_t"
            donor = bytes(c[" data"][:].astype(np.uint8)).decode()
            assert donor == ["east", "west"][k]
            assert c["Transform/ data"][:].tolist() == [1, 2]
        west, east = base["west"], base["east"]
        # the inlet is west's left border (i = 1), a BCInflow; the interface is not a BC
        assert set(west["ZoneBC"]) == {"inlet", "bottom", "top"}
        assert bytes(west["ZoneBC/inlet/ data"][:].astype(np.uint8)) == b"BCInflow"
        assert west["ZoneBC/inlet/PointRange/ data"][:].tolist() == [[1, 1], [1, 5]]
        assert bytes(east["ZoneBC/outlet/ data"][:].astype(np.uint8)) == b"BCOutflow"
        c = west["ZoneGridConnectivity"][next(iter(west["ZoneGridConnectivity"]))]
        assert c["PointRange/ data"][:].tolist() == [[7, 1], [7, 5]]
        assert c["PointRangeDonor/ data"][:].tolist() == [[1, 1], [1, 5]]
    # the independent reader: VTK's CGNS reader (built on the CGNS library)
    vtk = pytest.importorskip("vtk")
    from vtk.util.numpy_support import vtk_to_numpy

    r = vtk.vtkCGNSReader()
    r.SetFileName(str(f))
    r.UpdateInformation()
    r.EnableAllBases()
    r.Update()
    base_mb = r.GetOutput().GetBlock(0)
    assert base_mb.GetNumberOfBlocks() == 2
    for k, g in enumerate(blocks):
        b = base_mb.GetBlock(k)
        assert base_mb.GetMetaData(k).Get(vtk.vtkCompositeDataSet.NAME()) == ["west", "east"][k]
        pts = vtk_to_numpy(b.GetPoints().GetData())
        X, Y = _world(g)
        assert _rel(pts[:, 0], X.ravel(order="F"), g.size) <= 1e-12
        assert _rel(pts[:, 1], Y.ravel(order="F"), g.size) <= 1e-12
    gs = read_blocks(f)
    assert gs.frame == Frame(CRS, ORIGIN) and gs.blocks[0].names == {"left": "inlet"}


def test_cgns_transform_of_reversed_interfaces():
    from meshcore.io.cgns import transform

    assert transform("right", "left", False) == [1, 2]
    assert transform("top", "bottom", False) == [1, 2]
    assert transform("right", "right", True) == [-1, -2]  # mirrored neighbour
    assert transform("top", "left", True) == [-2, 1]
    # a transform maps an index step to a unit vector; it is a signed permutation
    for a in ("bottom", "right", "top", "left"):
        for b in ("bottom", "right", "top", "left"):
            t = transform(a, b, False)
            assert sorted(abs(v) for v in t) == [1, 2]


# ------------------------------------------------------------------ gmsh, SU2
def test_msh_read_by_gmsh(tmp_path, blocks):
    gmsh = pytest.importorskip("gmsh")
    f = write(tmp_path / "m.msh", blocks, block_names=["west", "east"], crs=CRS, origin=ORIGIN)
    gmsh.initialize(interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.open(str(f))
        groups = {gmsh.model.getPhysicalName(d, t): (d, t) for d, t in gmsh.model.getPhysicalGroups()}
        assert set(groups) == {"inlet", "outlet", "bottom", "top", "west", "east"}
        tags, coords, _ = gmsh.model.mesh.getNodes()
        shared = blocks[0].shape[1]
        assert len(tags) == sum(g.n_nodes for g in blocks) - shared  # interface nodes merged
        xyz = coords.reshape(-1, 3)
        X, Y = _world(blocks[0])
        lookup = dict(zip(tags.tolist(), xyz[:, :2].tolist(), strict=True))
        quads, qnodes = gmsh.model.mesh.getElementsByType(3)
        assert len(quads) == sum(g.cells[0] * g.cells[1] for g in blocks)
        # the first quad of block west is its cell (0, 0), counter-clockwise
        first = qnodes[:4]
        np.testing.assert_array_equal(
            [lookup[int(t)] for t in first],
            [[X[0, 0], Y[0, 0]], [X[1, 0], Y[1, 0]], [X[1, 1], Y[1, 1]], [X[0, 1], Y[0, 1]]],
        )
        _, c = gmsh.model.mesh.getNodesForPhysicalGroup(*groups["inlet"])
        np.testing.assert_array_equal(np.sort(c.reshape(-1, 3)[:, 1]), np.sort(Y[0, :]))
        bottom_nodes, _ = gmsh.model.mesh.getNodesForPhysicalGroup(*groups["bottom"])
        # "bottom" spans both blocks (names shared across blocks share one group)
        assert len(bottom_nodes) == blocks[0].shape[0] + blocks[1].shape[0] - 1
    finally:
        gmsh.finalize()


def test_su2_read_by_meshio(tmp_path, blocks):
    meshio = pytest.importorskip("meshio")
    f = write(tmp_path / "m.su2", blocks, crs=CRS, origin=ORIGIN)
    text = f.read_text()
    assert re.findall(r"MARKER_TAG= (\S+)", text) == ["bottom", "top", "inlet", "outlet"]
    import logging

    logging.getLogger("meshio").setLevel(logging.ERROR)
    m = meshio.read(f)
    quads = m.get_cells_type("quad")
    assert len(m.get_cells_type("line")) == 2 * (6 + 3) + 4 + 4
    assert len(quads) == sum(g.cells[0] * g.cells[1] for g in blocks)
    assert len(m.points) == sum(g.n_nodes for g in blocks) - blocks[0].shape[1]
    tags = m.cell_data_dict["su2:tag"]["line"]
    na, nb = blocks[0].cells, blocks[1].cells
    assert np.bincount(tags)[1:].tolist() == [na[0] + nb[0], na[0] + nb[0], na[1], nb[1]]
    X, Y = _world(blocks[0])
    assert _rel(m.points[quads[0], 0], [X[0, 0], X[1, 0], X[1, 1], X[0, 1]], 1.0) <= 1e-12 * 1e6
    np.testing.assert_array_equal(m.points[quads[0], 1], [Y[0, 0], Y[1, 0], Y[1, 1], Y[0, 1]])
    # every quad is counter-clockwise (positive shoelace area)
    p = m.points[quads][:, :, :2]
    area = 0.5 * np.sum(p[:, :, 0] * np.roll(p[:, :, 1], -1, 1) - np.roll(p[:, :, 0], -1, 1) * p[:, :, 1], axis=1)
    assert (area > 0).all()


def test_periodic_grid_seam_is_merged(tmp_path):
    th = np.linspace(0, 2 * np.pi, 13)
    r = np.linspace(1, 2, 4)
    R, T = np.meshgrid(r, th, indexing="xy")
    # i along θ (periodic), j along r
    x, y = (R * np.cos(T)), (R * np.sin(T))
    x[-1], y[-1] = x[0], y[0]
    g = meshcore.StructuredGrid(x, y, periodic=True)
    f = write(tmp_path / "o.su2", g)
    meshio = pytest.importorskip("meshio")
    m = meshio.read(f)
    assert len(m.points) == 12 * 4
    assert "left" not in f.read_text() and "MARKER_TAG= bottom" in f.read_text()


# ------------------------------------------------------------------ SGRID, Delft3D
def test_sgrid_read_by_netcdf4(tmp_path, grid):
    netCDF4 = pytest.importorskip("netCDF4")
    pyproj = pytest.importorskip("pyproj")
    f = write(tmp_path / "g.nc", grid, crs=CRS, origin=ORIGIN)
    with netCDF4.Dataset(f) as ds:
        t = ds["grid"]
        assert t.cf_role == "grid_topology" and t.topology_dimension == 2
        assert t.node_dimensions == "inode jnode"
        assert t.node_coordinates == "x y lon lat"
        assert t.border_bottom == "inlet" and t.border_left == "left"
        assert ds.dimensions["inode"].size == grid.shape[0]
        X, Y = _world(grid)
        np.testing.assert_array_equal(ds["x"][:].T, X)
        np.testing.assert_array_equal(ds["y"][:].T, Y)
        assert ds["x"].standard_name == "projection_x_coordinate" and ds["x"].units == "m"
        assert ds["x"].grid_mapping == "crs"
        crs = pyproj.CRS.from_cf(ds["crs"].__dict__)
        assert crs.to_epsg() == 32632
        tr = pyproj.Transformer.from_crs(CRS, "EPSG:4326", always_xy=True)
        lon, lat = tr.transform(X, Y)
        np.testing.assert_allclose(ds["lon"][:].T, lon, rtol=0, atol=1e-12)
        np.testing.assert_allclose(ds["lat"][:].T, lat, rtol=0, atol=1e-12)
        np.testing.assert_array_equal(ds["jacobian"][:].T, metrics(grid).jacobian)
    gs = read_blocks(f)
    assert gs.frame == Frame(CRS, ORIGIN) and gs.blocks[0].names == grid.names
    assert _rel(gs.blocks[0].x, grid.x, grid.size) < 1e-12


def test_delft3d_grd_and_enc(tmp_path, grid):
    f = write(tmp_path / "g.grd", grid, crs=CRS, origin=ORIGIN)
    text = f.read_text().splitlines()
    assert "Coordinate System = Cartesian" in text
    assert any(ln.startswith("* Projection: EPSG:32632") for ln in text)
    k = next(i for i, ln in enumerate(text) if ln.startswith(" ETA="))
    mmax, nmax = (int(v) for v in text[k - 2].split())
    assert (mmax, nmax) == grid.shape
    # independent parse of the RGFGRID layout: ETA=n records, 5 values per line
    body = "\n".join(text[k:])
    recs = re.split(r"\s*ETA=\s*(\d+)", body)[1:]
    numbers = [(int(recs[i]), np.array(recs[i + 1].split(), dtype=float)) for i in range(0, len(recs), 2)]
    assert [n for n, _ in numbers] == list(range(1, nmax + 1)) * 2
    assert all(len(v) == mmax for _, v in numbers)
    assert all(len(ln.split()) <= 5 + 2 for ln in text[k:])
    X, Y = _world(grid)
    np.testing.assert_array_equal(np.array([v for _, v in numbers[:nmax]]).T, X)
    np.testing.assert_array_equal(np.array([v for _, v in numbers[nmax:]]).T, Y)
    enc = np.loadtxt(tmp_path / "g.enc", dtype=int)
    assert enc.tolist() == [[1, 1], [mmax + 1, 1], [mmax + 1, nmax + 1], [1, nmax + 1], [1, 1]]
    gs = read_blocks(f)
    assert gs.frame.crs == CRS
    np.testing.assert_array_equal(gs.blocks[0].x, X)


def test_delft3d_spherical(tmp_path, grid):
    pyproj = pytest.importorskip("pyproj")
    f = write(tmp_path / "ll.grd", grid, crs=CRS, origin=ORIGIN, lonlat=True)
    assert "Coordinate System = Spherical" in f.read_text()
    gs = read_blocks(f)
    lon, lat = pyproj.Transformer.from_crs(CRS, "EPSG:4326", always_xy=True).transform(*_world(grid))
    assert gs.frame.crs == "EPSG:4326"
    np.testing.assert_allclose(gs.blocks[0].x, lon, atol=1e-13)
    np.testing.assert_allclose(gs.blocks[0].y, lat, atol=1e-13)


# ------------------------------------------------------------------ metrics, npz, figures
def test_metrics_csv_columns(tmp_path, grid):
    import csv

    f = write(tmp_path / "m.csv", grid, crs=CRS, origin=ORIGIN)
    lines = f.read_text().splitlines()
    doc = [ln for ln in lines if ln.startswith("# column ")]
    header = next(ln for ln in lines if not ln.startswith("#")).split(",")
    assert header == [
        "block",
        "i",
        "j",
        "x",
        "y",
        "x_xi",
        "x_eta",
        "y_xi",
        "y_eta",
        "J",
        "alpha",
        "beta",
        "gamma",
        "xi_x",
        "xi_y",
        "eta_x",
        "eta_y",
    ]
    assert [d.split(":")[0].removeprefix("# column ") for d in doc] == header
    rows = list(csv.DictReader(ln for ln in lines if not ln.startswith("#")))
    assert len(rows) == grid.n_nodes
    m = metrics(grid)
    X, Y = _world(grid)
    for r in rows[::7]:
        i, j = int(r["i"]), int(r["j"])
        assert float(r["x"]) == X[i, j] and float(r["y"]) == Y[i, j]
        assert float(r["J"]) == m.jacobian[i, j]
        for c in ("x_xi", "x_eta", "y_xi", "y_eta", "alpha", "beta", "gamma", "xi_x", "xi_y", "eta_x", "eta_y"):
            assert float(r[c]) == getattr(m, c)[i, j]
    # consistency of the columns themselves: ξ_x x_ξ + ξ_y y_ξ = 1
    a = np.array([[float(r[c]) for c in ("xi_x", "xi_y", "x_xi", "y_xi")] for r in rows])
    np.testing.assert_allclose(a[:, 0] * a[:, 2] + a[:, 1] * a[:, 3], 1.0, rtol=1e-12)
    gs = read_blocks(f)
    assert gs.frame == Frame(CRS, ORIGIN)


def test_npz(tmp_path, blocks):
    f = write(tmp_path / "m.npz", blocks, crs=CRS, origin=ORIGIN)
    with np.load(f) as z:
        np.testing.assert_array_equal(z["b1_x"], blocks[1].x + ORIGIN[0])
        np.testing.assert_array_equal(z["b0_J"], metrics(blocks[0]).jacobian)
        assert str(z["crs"]) == CRS
    gs = read_blocks(f)
    assert len(gs) == 2 and gs.blocks[0].names == {"left": "inlet"}


@pytest.mark.parametrize("suffix", [".png", ".svg", ".pdf"])
def test_figures(tmp_path, blocks, suffix):
    pytest.importorskip("matplotlib")
    f = write(tmp_path / f"m{suffix}", blocks, crs=CRS, origin=ORIGIN)
    data = f.read_bytes()
    if suffix == ".png":
        from matplotlib.image import imread

        img = imread(f)
        assert img.shape[0] > 100 and img.shape[1] > 100
        assert (img[..., :3] < 0.5).any()  # grid lines were drawn
    elif suffix == ".svg":
        assert b"<svg" in data[:1000]
    else:
        assert data.startswith(b"%PDF")
    assert os.listdir(tmp_path) == [f.name]


# ------------------------------------------------------------------ atomicity, errors
def test_unwritable_path_leaves_nothing(tmp_path, grid):
    with pytest.raises(WriteError) as exc:
        write(tmp_path / "missing_dir" / "g.vts", grid)
    assert "missing_dir" in str(exc.value) and "\n" not in str(exc.value)
    (tmp_path / "adir.xyz").mkdir()
    with pytest.raises(WriteError):
        write(tmp_path / "adir.xyz", grid)
    assert sorted(os.listdir(tmp_path)) == ["adir.xyz"]
    assert os.listdir(tmp_path / "adir.xyz") == []


@pytest.mark.parametrize("name", ["g.vts", "g.cgns", "g.npz", "g.nc", "g.msh", "g.xyz"])
def test_failure_mid_write_keeps_the_old_file(tmp_path, grid, monkeypatch, name):
    f = tmp_path / name
    f.write_bytes(b"old contents")
    import meshcore.io._atomic as atomic

    real = atomic.os.replace

    def boom(src, dst):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(atomic.os, "replace", boom)
    with pytest.raises(WriteError, match="No space left"):
        write(f, grid)
    monkeypatch.setattr(atomic.os, "replace", real)
    assert f.read_bytes() == b"old contents"
    assert os.listdir(tmp_path) == [name]


def test_unknown_formats_and_block_counts(tmp_path, grid, blocks):
    with pytest.raises(WriteError, match=r"cannot write \.foo"):
        write(tmp_path / "g.foo", grid)
    with pytest.raises(WriteError, match="holds one block"):
        write(tmp_path / "g.vts", blocks)
    with pytest.raises(WriteError, match="StructuredGrid"):
        write(tmp_path / "g.vts", "not a grid")
    with pytest.raises(ReadError, match=r"cannot read grids from \.su2"):
        read_grid(tmp_path / "g.su2")
    write(tmp_path / "g.dat", grid, format="plot3d", mode="ascii")
    assert read_grid(tmp_path / "g.dat", format="plot3d")[0].shape == grid.shape


def test_generate_and_rewrite_a_lake_grid(tmp_path):
    """Read a grid back and re-smooth it: the round trip of an existing grid."""
    g0 = _curved(10, 6)
    write(tmp_path / "in.xyz", g0, mode="binary")
    (g,) = read_grid(tmp_path / "in.xyz")
    g2 = meshcore.solve(g)
    assert g2.converged and g2.shape == g0.shape
    np.testing.assert_array_equal(g2.border("bottom"), g0.border("bottom"))


def test_explicit_connectivity_records_and_grid_borders_as_points(tmp_path, blocks):
    f = write(tmp_path / "m.su2", blocks, connectivity=[{"a": 0, "border_a": "right", "b": 1, "border_b": "left"}])
    assert "MARKER_TAG= right" not in f.read_text()
    with pytest.raises(WriteError, match="unknown block or border"):
        write(tmp_path / "x.su2", blocks, connectivity=[{"a": 0, "border_a": "east", "b": 1, "border_b": "left"}])
    # a grid file read as points gives its borders, named
    from meshcore.io import read_points

    g = write(tmp_path / "g.vts", blocks[0], crs=CRS, origin=ORIGIN)
    ps = read_points(g)
    assert ps.names == ("bottom", "right", "top", "inlet") and ps.crs == CRS
    np.testing.assert_allclose(ps["inlet"].points, blocks[0].border("left"), atol=1e-9)


def test_vtm_with_missing_block_file(tmp_path, blocks):
    f = write(tmp_path / "m.vtm", blocks)
    (tmp_path / "m" / "m_1.vts").unlink()
    with pytest.raises(ReadError, match=r"m_1\.vts.*not found"):
        read_blocks(f)
