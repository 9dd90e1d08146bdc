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

import io
from pathlib import Path
from typing import Any

import numpy as np

from .._validation import check_allocation, max_nodes
from ..crs import Frame
from ..errors import ReadError, WriteError
from ..grid import BORDER_NAMES
from ._base import (
    GridSet,
    Interface,
    atomic_path,
    border_names,
    check_interface,
    check_nodes,
    grid_from_world,
    one_line,
)

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


def _h5py(path: Any, error: type[Exception] = ReadError):
    try:
        import h5py
    except ImportError:
        raise error(f"{path}: CGNS files need h5py: pip install 'gcmesh[io]'") from None
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


def _range(border: str, ni: int, nj: int, s: int, e: int) -> list[list[int]]:
    """1-based ``[[i0, j0], [i1, j1]]`` of nodes ``s … e`` (0-based, in the border's direction)."""
    if border == "bottom":
        return [[s + 1, 1], [e + 1, 1]]
    if border == "top":
        return [[s + 1, nj + 1], [e + 1, nj + 1]]
    if border == "left":
        return [[1, s + 1], [1, e + 1]]
    return [[ni + 1, s + 1], [ni + 1, e + 1]]


def _on_border(pr: list[list[int]], ni: int, nj: int) -> tuple[str, int, int] | None:
    """The border a 1-based point range lies on and its 0-based ``(first, last)`` node along it."""
    p0, p1 = pr
    for border, axis, value in (("bottom", 1, 1), ("top", 1, nj + 1), ("left", 0, 1), ("right", 0, ni + 1)):
        if p0[axis] == value and p1[axis] == value:
            return border, p0[1 - axis] - 1, p1[1 - axis] - 1
    return None


def _whole(border: str, ni: int, nj: int) -> list[list[int]]:
    return _range(border, ni, nj, 0, (ni if border in ("bottom", "top") else nj))


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


def _free_segments(n_nodes: int, spans: list[tuple[int, int]]) -> list[tuple[int, int]]:
    """Node ranges of a border not covered by interface spans (edge-wise)."""
    covered = np.zeros(n_nodes - 1, dtype=bool)
    for s, e in spans:
        covered[s:e] = True
    out, k = [], 0
    while k < n_nodes - 1:
        if covered[k]:
            k += 1
            continue
        start = k
        while k < n_nodes - 1 and not covered[k]:
            k += 1
        out.append((start, k))
    return out


def _zone_bcs(z, gs: GridSet, k: int, spans: dict[str, list[tuple[int, int]]]) -> None:
    """Boundary conditions of zone ``k``: every border part no interface covers.

    A border cut by interfaces gives one BC per free part; each BC holds a
    ``BorderName`` descriptor so the border names survive a round trip.
    """
    g = gs.blocks[k]
    ni, nj = g.cells
    names = border_names(g)
    parts = []
    for b in BORDER_NAMES:
        if g.periodic and b in ("left", "right"):
            continue
        n = ni + 1 if b in ("bottom", "top") else nj + 1
        segs = _free_segments(n, spans.get(b, []))
        parts += [(b, s, e, len(segs) > 1 or (s, e) != (0, n - 1)) for s, e in segs]
    if not parts:
        return
    zbc = _node(z, "ZoneBC", "ZoneBC_t")
    used: set[str] = set()
    for b, s, e, partial in parts:
        nm = names[b] if names[b] not in used else f"{names[b]}_{b}"
        if partial or nm in used:
            nm = f"{names[b]}_{b}_{s}"
        used.add(nm)
        bc = _node(zbc, nm, "BC_t", "C1", bc_type(names[b]))
        _node(bc, "PointRange", "IndexRange_t", "I4", np.array(_range(b, ni, nj, s, e)).T)
        _node(bc, "GridLocation", "GridLocation_t", "C1", "Vertex")
        if nm != names[b]:
            _node(bc, "BorderName", "Descriptor_t", "C1", names[b])


def _zone_connectivity(z, gs: GridSet, k: int, conns: list[tuple[Interface, bool]], zones: list[str]) -> None:
    """The GridConnectivity1to1_t nodes of zone ``k`` (``conns``: interfaces and whether k is side a)."""
    ni, nj = gs.blocks[k].cells
    zgc = _node(z, "ZoneGridConnectivity", "ZoneGridConnectivity_t")
    for n_c, (it, first) in enumerate(conns):
        me, other = ("a", "b") if first else ("b", "a")
        b, ob = (it.border_a, it.border_b) if first else (it.border_b, it.border_a)
        o = it.b if first else it.a
        oni, onj = gs.blocks[o].cells
        (s, e), (os_, oe) = it.span(me, gs.blocks), it.span(other, gs.blocks)
        nm = f"{zones[k]}_{b}_to_{zones[o]}"[:32]
        if nm in zgc:
            nm = f"{nm[:27]}_{n_c}"
        c = _node(zgc, nm, "GridConnectivity1to1_t", "C1", zones[o])
        _node(c, "PointRange", "IndexRange_t", "I4", np.array(_range(b, ni, nj, s, e)).T)
        dr = _range(ob, oni, onj, os_, oe)
        if it.reversed:
            dr = [dr[1], dr[0]]
        _node(c, "PointRangeDonor", "IndexRange_t", "I4", np.array(dr).T)
        _node(c, "Transform", '"int[IndexDimension]"', "I4", transform(b, ob, it.reversed))


def write_cgns(path: Path, gs: GridSet, **_: Any) -> None:
    """Write blocks as CGNS structured zones (see module docstring).

    The file is built in memory and written in one piece: a full disk is one
    clean ``OSError`` (HDF5 failing in the middle of a file raised again while
    its objects were freed, and could crash the interpreter's exit).
    """
    h5py = _h5py(path, WriteError)
    with atomic_path(path) as tmp:
        image = io.BytesIO()
        with h5py.File(image, "w", track_order=True) as f:
            _write_tree(f, gs, h5py)
        tmp.write_bytes(image.getbuffer())


def _write_tree(f: Any, gs: GridSet, h5py: Any) -> None:
    """The CGNS node tree of ``gs`` in the open HDF5 file ``f``."""
    zones = list(gs.block_names)
    iface: dict[int, list[tuple[Interface, bool]]] = {}
    spans: dict[int, dict[str, list[tuple[int, int]]]] = {}
    for it in gs.connectivity:
        for side, k, b in (("a", it.a, it.border_a), ("b", it.b, it.border_b)):
            iface.setdefault(k, []).append((it, side == "a"))
            spans.setdefault(k, {}).setdefault(b, []).append(it.span(side, gs.blocks))
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
        _zone_bcs(z, gs, k, spans.get(k, {}))
        conns = sorted(iface.get(k, []), key=lambda c: BORDER_NAMES.index(c[0].border_a if c[1] else c[0].border_b))
        if conns:
            _zone_connectivity(z, gs, k, conns, zones)


#: Longest text node read (a CRS WKT is a few kB).
_TEXT_LIMIT = 2**20


def _text(node) -> str:
    ds = node.get(" data") if hasattr(node, "get") else None
    if ds is None or not hasattr(ds, "size"):
        return ""
    if ds.size > _TEXT_LIMIT or ds.dtype.kind not in "iu":
        raise ReadError(f"{node.file.filename}: {node.name}: not a text node (type {ds.dtype}, {ds.size} values)")
    return bytes(np.asarray(ds).astype(np.uint8)).decode("utf-8", errors="replace")


def _label(node) -> str:
    v = node.attrs.get("label", b"")
    return (v.tobytes() if hasattr(v, "tobytes") else bytes(v)).split(b"\x00")[0].decode()


def _coordinate(gc, name: str, path: Path, zone: str, shape: tuple[int, ...] | None) -> np.ndarray:
    """One coordinate array, its shape and type checked before a byte is read."""
    node = gc[name]
    ds = node.get(" data") if hasattr(node, "get") else None
    if ds is None or not hasattr(ds, "shape"):
        raise ReadError(f"{path}: zone {zone}: {name} holds no data array")
    if ds.dtype.kind not in "fiu":
        raise ReadError(f"{path}: zone {zone}: {name} is not numeric (HDF5 type {ds.dtype})")
    if len(ds.shape) != 2:
        raise ReadError(f"{path}: zone {zone}: {name} is not a 2-D array (shape {ds.shape})")
    if shape is not None and tuple(ds.shape) != shape:
        raise ReadError(f"{path}: zone {zone}: CoordinateX and CoordinateY differ in shape ({shape}, {ds.shape})")
    check_nodes(ds.shape[::-1], path, f"zone {zone}")
    return np.asarray(ds[()], dtype=np.float64).T


def _index_range(node, name: str) -> list[list[int]] | None:
    """A small 2 × 2 IndexRange_t child as ``[[i0, j0], [i1, j1]]`` (None when absent or malformed)."""
    child = node.get(name) if hasattr(node, "get") else None
    ds = child.get(" data") if child is not None and hasattr(child, "get") else None
    if ds is None or not hasattr(ds, "shape") or tuple(ds.shape) != (2, 2) or ds.dtype.kind not in "iu":
        return None
    return np.asarray(ds).astype(np.int64).tolist()


def _zone_names(zbc, ni: int, nj: int) -> dict[str, str]:
    """Border names from a ZoneBC: a BorderName descriptor, or the BC name of a whole border."""
    bn: dict[str, str] = {}
    for nm in zbc:
        pr = _index_range(zbc[nm], "PointRange")
        where = _on_border(pr, ni, nj) if pr is not None else None
        if where is None:
            continue
        b = where[0]
        label = zbc[nm].get("BorderName") if hasattr(zbc[nm], "get") else None
        if label is not None:
            text = _text(label)
            if text and text != b:
                bn[b] = text
        elif pr == _whole(b, ni, nj) and nm != b:
            bn[b] = nm
    return bn


def _zone_links(zgc, zone: str, ni: int, nj: int) -> list[tuple[str, str, int, int, str, list[list[int]]]]:
    """``(zone, border, first, last, donor zone, donor range)`` of each 1-to-1 connection."""
    out = []
    for nm in zgc:
        node = zgc[nm]
        if _label(node) != "GridConnectivity1to1_t":
            continue
        pr, dr = _index_range(node, "PointRange"), _index_range(node, "PointRangeDonor")
        where = _on_border(pr, ni, nj) if pr is not None else None
        if where is None or dr is None:
            raise ReadError(f"{node.file.filename}: zone {zone}: connectivity {nm} has no usable point ranges")
        out.append((zone, where[0], where[1], where[2], _text(node), dr))
    return out


def _interfaces(path: Path, links, names: list[str], blocks: list) -> tuple[Interface, ...]:
    """Interfaces from the 1-to-1 records (each is stored by both zones; one copy is kept)."""
    out, seen = [], set()
    for zone, b, s, e, donor, dr in links:
        if donor not in names:
            raise ReadError(f"{path}: zone {zone}: connectivity to an unknown zone {donor[:40]!r}")
        ka, kb = names.index(zone), names.index(donor)
        oni, onj = blocks[kb][0].shape[0] - 1, blocks[kb][0].shape[1] - 1
        where = _on_border(dr, oni, onj)
        if where is None:
            raise ReadError(f"{path}: zone {zone}: the donor range {dr} is not on a border of zone {donor}")
        ob, os_, oe = where
        rev = (oe - os_) * (e - s) < 0
        ra, rb = (min(s, e), max(s, e)), (min(os_, oe), max(os_, oe))
        key = frozenset([(ka, b, ra), (kb, ob, rb)])
        if key in seen:
            continue
        seen.add(key)
        out.append(Interface(ka, b, kb, ob, rev, ra, rb))
    return tuple(out)


def read_cgns(path: Path, **_: Any) -> GridSet:
    """Read the structured zones of the first base of a CGNS/HDF5 file.

    Array sizes are checked against :func:`~meshcore._validation.max_nodes`
    before reading (HDF5 datasets may declare sizes far beyond the file:
    unwritten chunks read as zeros), every coordinate must be finite, and the
    nodes of every 1-to-1 connection must coincide (the shared-node check).
    """
    h5py = _h5py(path)
    try:
        f = h5py.File(path, "r")
    except OSError as exc:
        raise ReadError(one_line(f"{path}: not an HDF5/CGNS file ({exc})")) from None
    with f:
        base = next((f[k] for k in f if isinstance(f[k], h5py.Group) and _label(f[k]) == "CGNSBase_t"), None)
        if base is None:
            raise ReadError(f"{path}: no CGNSBase_t node")
        crs, origin = None, (0.0, 0.0)
        blocks, names, links = [], [], []
        total = 0
        for k in base:
            node = base[k]
            if not isinstance(node, h5py.Group):
                continue
            lab = _label(node)
            if lab == "Descriptor_t" and k == "CRS":
                crs = _text(node)
            elif lab == "Descriptor_t" and k == "LocalOrigin":
                v = _text(node).split()
                try:
                    origin = (float(v[0]), float(v[1]))
                except (IndexError, ValueError):
                    raise ReadError(f"{path}: LocalOrigin {' '.join(v)[:40]!r} is not two numbers") from None
            elif lab == "Zone_t":
                zt = node.get("ZoneType")
                if zt is None or _text(zt) != "Structured":
                    raise ReadError(f"{path}: zone {k} is not Structured")
                gc = node.get("GridCoordinates")
                if gc is None or "CoordinateX" not in gc or "CoordinateY" not in gc:
                    raise ReadError(f"{path}: zone {k} has no CoordinateX/CoordinateY")
                X = _coordinate(gc, "CoordinateX", path, k, None)
                total += X.size
                check_allocation(
                    total, max_nodes(), what=f"{path}: nodes of all zones", env="MESHCORE_MAX_NODES", error=ReadError
                )
                Y = _coordinate(gc, "CoordinateY", path, k, X.shape[::-1])
                ni, nj = X.shape[0] - 1, X.shape[1] - 1
                zbc, zgc = node.get("ZoneBC"), node.get("ZoneGridConnectivity")
                bn = _zone_names(zbc, ni, nj) if zbc is not None else {}
                if zgc is not None:
                    links += _zone_links(zgc, k, ni, nj)
                blocks.append((X, Y, bn))
                names.append(k)
        if not blocks:
            raise ReadError(f"{path}: no structured zones")
        grids = tuple(
            grid_from_world(X, Y, origin, path, f"zone {nm}", bn) for (X, Y, bn), nm in zip(blocks, names, strict=True)
        )
        conn = _interfaces(path, links, names, blocks)
    for it in conn:
        check_interface(it, grids, str(path), ReadError)
    return GridSet(grids, Frame(crs, origin), tuple(names), conn, source=str(path))
