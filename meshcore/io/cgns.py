r"""CGNS files (HDF5 via h5py) in the SIDS-to-HDF5 node layout.

::

    /CGNSLibraryVersion            CGNSLibraryVersion_t   R4  [4.2]
    /Base                          CGNSBase_t             I4  [2, 2]
       CRS                         Descriptor_t           C1  CRS authority string / WKT
       LocalOrigin                 Descriptor_t           C1  "x0 y0" (coordinates are world = local + origin)
       <zone>                      Zone_t                 I4  [[ni+1, nj+1], [ni, nj], [0, 0]]
          ZoneType                 ZoneType_t             C1  "Structured"
          GridCoordinates          GridCoordinates_t      MT
             CoordinateX/Y         DataArray_t            R8  (ni+1) × (nj+1), i fastest
          ZoneBC                   ZoneBC_t               MT
             <border name>         BC_t                   C1  BCWall / BCInflow / … / UserDefined
                PointRange         IndexRange_t           I4  [[i0, j0], [i1, j1]] (1-based)
                GridLocation       GridLocation_t         C1  "Vertex"
          ZoneGridConnectivity     ZoneGridConnectivity_t MT
             <name>                GridConnectivity1to1_t C1  donor zone name
                PointRange, PointRangeDonor  IndexRange_t
                Transform          "int[IndexDimension]"  I4  [±1|±2, ±1|±2]

Every node is an HDF5 group with attributes ``name`` (S33), ``label`` (S33),
``type`` (S3) and ``flags`` (I4), its data in the dataset ``" data"``; the
root carries ``" format"`` and ``" hdf5version"``.  Fortran-ordered CGNS
arrays are stored with reversed HDF5 dimensions (CoordinateX has HDF5 shape
``(nj+1, ni+1)``).  Borders shared with another block become 1-to-1
connectivity instead of boundary conditions.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from ..crs import Frame
from ..errors import ReadError
from ..grid import BORDER_NAMES, StructuredGrid
from ._base import GridSet, Interface, atomic_path, border_names

__all__ = ["bc_type", "read_cgns", "write_cgns"]

_BC_TYPES = {
    "inlet": "BCInflow",
    "inflow": "BCInflow",
    "outlet": "BCOutflow",
    "outflow": "BCOutflow",
    "wall": "BCWall",
    "shore": "BCWall",
    "bank": "BCWall",
    "symmetry": "BCSymmetryPlane",
    "farfield": "BCFarfield",
    "far": "BCFarfield",
}


def bc_type(name: str) -> str:
    """CGNS BCType for a border name (``inlet`` → BCInflow, ``shore`` → BCWall …)."""
    return _BC_TYPES.get(name.strip().lower(), "UserDefined")


def _h5py():
    try:
        import h5py
    except ImportError as exc:  # pragma: no cover
        raise ReadError("CGNS needs h5py (pip install 'gcmesh[io]')") from exc
    return h5py


def _node(parent, name: str, label: str, dtype: str = "MT", data: Any = None):
    g = parent.create_group(name, track_order=True)
    g.attrs.create("name", np.array(name.encode()[:32], dtype="S33"))
    g.attrs.create("label", np.array(label.encode(), dtype="S33"))
    g.attrs.create("type", np.array(dtype.encode(), dtype="S3"))
    g.attrs.create("flags", np.array([1], dtype=np.int32))
    if data is not None:
        if dtype == "C1":
            arr = np.frombuffer(str(data).encode("utf-8"), dtype=np.int8)
        else:
            arr = np.asarray(data, dtype={"I4": np.int32, "I8": np.int64, "R4": np.float32, "R8": np.float64}[dtype])
            arr = arr.T.copy() if arr.ndim > 1 else arr  # Fortran order: reversed dims
        g.create_dataset(" data", data=arr)
    return g


_RANGES = {
    "bottom": lambda ni, nj: [[1, 1], [ni + 1, 1]],
    "top": lambda ni, nj: [[1, nj + 1], [ni + 1, nj + 1]],
    "left": lambda ni, nj: [[1, 1], [1, nj + 1]],
    "right": lambda ni, nj: [[ni + 1, 1], [ni + 1, nj + 1]],
}
# (normal axis, outward sign, tangential axis)
_AXES = {"bottom": (1, -1, 0), "top": (1, 1, 0), "left": (0, -1, 1), "right": (0, 1, 1)}


def transform(border_a: str, border_b: str, reversed_: bool) -> list[int]:
    """The SIDS ``Transform`` of a 1-to-1 interface between two borders.

    Index axis ``a`` of the zone maps to ``T[a]`` (1-based, signed) of the donor:
    the zone's outward normal maps to the donor's inward normal, and the
    tangential direction runs along (or, when ``reversed_``, against) the donor's.
    """
    na, sa, ta = _AXES[border_a]
    nb, sb, tb = _AXES[border_b]
    t = [0, 0]
    t[na] = sa * (-sb) * (nb + 1)
    t[ta] = (-1 if reversed_ else 1) * (tb + 1)
    return t


def write_cgns(path: Path, gs: GridSet, **_: Any) -> None:
    """Write blocks as CGNS structured zones (see module docstring)."""
    h5py = _h5py()
    zones = list(gs.block_names)
    iface: dict[tuple[int, str], list[tuple[Interface, bool]]] = {}
    for it in gs.connectivity:
        iface.setdefault((it.a, it.border_a), []).append((it, True))
        iface.setdefault((it.b, it.border_b), []).append((it, False))
    with atomic_path(path) as tmp, h5py.File(tmp, "w", track_order=True) as f:
        f.attrs.create("name", np.array(b"HDF5 MotherNode", dtype="S33"))
        f.attrs.create("label", np.array(b"Root Node of HDF5 File", dtype="S33"))
        f.attrs.create("type", np.array(b"MT", dtype="S3"))
        f.create_dataset(" format", data=np.frombuffer(b"IEEE_LITTLE_64\x00", dtype=np.int8))
        ver = f"HDF5 Version {h5py.version.hdf5_version}".encode().ljust(33, b"\x00")
        f.create_dataset(" hdf5version", data=np.frombuffer(ver, dtype=np.int8))
        _node(f, "CGNSLibraryVersion", "CGNSLibraryVersion_t", "R4", [4.2])
        base = _node(f, "Base", "CGNSBase_t", "I4", [2, 2])
        if gs.frame.crs:
            _node(base, "CRS", "Descriptor_t", "C1", gs.frame.crs)
        o = gs.frame.origin
        if o != (0.0, 0.0):
            _node(base, "LocalOrigin", "Descriptor_t", "C1", f"{o[0]!r} {o[1]!r}")
        for k, g in enumerate(gs.blocks):
            ni, nj = g.cells
            z = _node(base, zones[k], "Zone_t", "I4", np.array([[ni + 1, nj + 1], [ni, nj], [0, 0]]).T)
            _node(z, "ZoneType", "ZoneType_t", "C1", "Structured")
            gc = _node(z, "GridCoordinates", "GridCoordinates_t")
            X, Y = gs.world(k)
            _node(gc, "CoordinateX", "DataArray_t", "R8", X)
            _node(gc, "CoordinateY", "DataArray_t", "R8", Y)
            names = border_names(g)
            bcs = [b for b in BORDER_NAMES if (k, b) not in iface and not (g.periodic and b in ("left", "right"))]
            if bcs:
                zbc = _node(z, "ZoneBC", "ZoneBC_t")
                used: set[str] = set()
                for b in bcs:
                    nm = names[b] if names[b] not in used else f"{names[b]}_{b}"
                    used.add(nm)
                    bc = _node(zbc, nm, "BC_t", "C1", bc_type(names[b]))
                    _node(bc, "PointRange", "IndexRange_t", "I4", np.array(_RANGES[b](ni, nj)).T)
                    _node(bc, "GridLocation", "GridLocation_t", "C1", "Vertex")
            conns = [(b, it, first) for b in BORDER_NAMES for it, first in iface.get((k, b), [])]
            if conns:
                zgc = _node(z, "ZoneGridConnectivity", "ZoneGridConnectivity_t")
                for n_c, (b, it, first) in enumerate(conns):
                    other = it.b if first else it.a
                    ob = it.border_b if first else it.border_a
                    og = gs.blocks[other]
                    oni, onj = og.cells
                    nm = f"{zones[k]}_{b}_to_{zones[other]}"[:32]
                    if nm in zgc:
                        nm = f"{nm[:28]}_{n_c}"
                    c = _node(zgc, nm, "GridConnectivity1to1_t", "C1", zones[other])
                    _node(c, "PointRange", "IndexRange_t", "I4", np.array(_RANGES[b](ni, nj)).T)
                    dr = _RANGES[ob](oni, onj)
                    if it.reversed:
                        dr = [dr[1], dr[0]]
                    _node(c, "PointRangeDonor", "IndexRange_t", "I4", np.array(dr).T)
                    _node(c, "Transform", '"int[IndexDimension]"', "I4", transform(b, ob, it.reversed))


def _text(node) -> str:
    return bytes(np.asarray(node[" data"]).astype(np.uint8)).decode("utf-8", errors="replace")


def _label(node) -> str:
    v = node.attrs.get("label", b"")
    return (v.tobytes() if hasattr(v, "tobytes") else bytes(v)).split(b"\x00")[0].decode()


def read_cgns(path: Path, **_: Any) -> GridSet:
    """Read the structured zones of the first base of a CGNS/HDF5 file."""
    h5py = _h5py()
    try:
        f = h5py.File(path, "r")
    except OSError as exc:
        raise ReadError(f"{path}: not an HDF5/CGNS file ({exc})") from None
    with f:
        base = next((f[k] for k in f if isinstance(f[k], h5py.Group) and _label(f[k]) == "CGNSBase_t"), None)
        if base is None:
            raise ReadError(f"{path}: no CGNSBase_t node")
        crs, origin = None, (0.0, 0.0)
        blocks, names = [], []
        for k in base:
            node = base[k]
            if not isinstance(node, h5py.Group):
                continue
            lab = _label(node)
            if lab == "Descriptor_t" and k == "CRS":
                crs = _text(node)
            elif lab == "Descriptor_t" and k == "LocalOrigin":
                v = _text(node).split()
                origin = (float(v[0]), float(v[1]))
            elif lab == "Zone_t":
                zt = node.get("ZoneType")
                if zt is None or _text(zt) != "Structured":
                    raise ReadError(f"{path}: zone {k} is not Structured")
                gc = node.get("GridCoordinates")
                if gc is None or "CoordinateX" not in gc or "CoordinateY" not in gc:
                    raise ReadError(f"{path}: zone {k} has no CoordinateX/CoordinateY")
                X = np.asarray(gc["CoordinateX"][" data"], dtype=np.float64).T
                Y = np.asarray(gc["CoordinateY"][" data"], dtype=np.float64).T
                if X.ndim != 2 or X.shape != Y.shape:
                    raise ReadError(f"{path}: zone {k} coordinates are not 2-D arrays")
                bn = {}
                zbc = node.get("ZoneBC")
                if zbc is not None:
                    ni, nj = X.shape[0] - 1, X.shape[1] - 1
                    for nm in zbc:
                        pr = np.asarray(zbc[nm]["PointRange"][" data"]).tolist()
                        for b in BORDER_NAMES:
                            if pr == _RANGES[b](ni, nj) and nm != b:
                                bn[b] = nm
                blocks.append(StructuredGrid(X - origin[0], Y - origin[1], names=bn))
                names.append(k)
        if not blocks:
            raise ReadError(f"{path}: no structured zones")
    return GridSet(tuple(blocks), Frame(crs, origin), tuple(names), source=str(path))
