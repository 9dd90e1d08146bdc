r"""NetCDF grids following the SGRID conventions, with a CF grid mapping.

Written as NetCDF-3 (64-bit offset) with :mod:`scipy.io` (no libnetcdf needed)::

    dimensions:  inode = ni+1 ; jnode = nj+1 ; iface = ni ; jface = nj
    int grid            cf_role = "grid_topology", topology_dimension = 2,
                        node_dimensions = "inode jnode",
                        face_dimensions = "iface: inode (padding: none) jface: jnode (padding: none)",
                        node_coordinates = "x y" (+ " lon lat"), border names, local origin
    double x(jnode, inode), y(jnode, inode)   projection_x/y_coordinate, grid_mapping = "crs"
    double lon(jnode, inode), lat(jnode, inode)  when the CRS is known (``lonlat=True`` default)
    double jacobian(jnode, inode)             x_ξ y_η − x_η y_ξ
    int crs             the CF grid-mapping attributes of ``pyproj.CRS.to_cf()`` (crs_wkt …)

Arrays are stored ``(jnode, inode)`` (η slowest), the usual (y, x) order.
"""

from __future__ import annotations

import io
from pathlib import Path
from typing import Any

import numpy as np

from ..crs import Frame, normalize_crs
from ..errors import ReadError
from ..grid import BORDER_NAMES
from ._base import GridSet, atomic_path, border_names, check_nodes, grid_from_world, read_bytes

__all__ = ["read_sgrid", "write_sgrid"]


def _cf_attrs(crs: str) -> dict[str, Any]:
    from ..crs import crs_cf

    out = {}
    for k, v in crs_cf(crs).items():
        if isinstance(v, str):
            # NetCDF-3 text attributes are ASCII; WKT area names may hold "°"
            out[k] = v.replace("°", " deg").encode("ascii", "replace").decode("ascii")
        elif isinstance(v, (int, float)):
            out[k] = v
        elif isinstance(v, (list, tuple)) and all(isinstance(t, (int, float)) for t in v):
            out[k] = np.array(v, dtype=np.float64)
    return out


def write_sgrid(path: Path, gs: GridSet, *, lonlat: bool | None = None, **_: Any) -> None:
    """Write a NetCDF SGRID file (see module docstring)."""
    from scipy.io import netcdf_file

    from ..metrics import metrics

    g = gs.blocks[0]
    X, Y = gs.world(0)
    crs = gs.frame.crs
    with_ll = (crs is not None) if lonlat is None else bool(lonlat)
    buf = io.BytesIO()
    with netcdf_file(buf, "w", version=2) as f:
        f.Conventions = "CF-1.8 SGRID-0.3"
        f.title = "structured boundary-fitted grid (meshcore / gcmesh)"
        f.createDimension("inode", g.shape[0])
        f.createDimension("jnode", g.shape[1])
        f.createDimension("iface", g.cells[0])
        f.createDimension("jface", g.cells[1])
        t = f.createVariable("grid", "i", ())
        t.cf_role = "grid_topology"
        t.topology_dimension = 2
        t.node_dimensions = "inode jnode"
        t.face_dimensions = "iface: inode (padding: none) jface: jnode (padding: none)"
        t.node_coordinates = "x y" + (" lon lat" if with_ll else "")
        names = border_names(g)
        for b in BORDER_NAMES:
            # NetCDF-3 text attributes are bytes: names are stored as UTF-8 (any language)
            setattr(t, f"border_{b}", names[b].encode("utf-8"))
        t.local_origin = np.array(gs.frame.origin, dtype=np.float64)
        proj = crs is not None and not crs.upper().startswith("EPSG:4326")
        for name, arr, std, units in (
            (
                "x",
                X,
                "projection_x_coordinate" if proj else "longitude" if crs else "",
                "m" if proj else "degrees_east" if crs else "1",
            ),
            (
                "y",
                Y,
                "projection_y_coordinate" if proj else "latitude" if crs else "",
                "m" if proj else "degrees_north" if crs else "1",
            ),
        ):
            v = f.createVariable(name, "d", ("jnode", "inode"))
            v[:] = arr.T
            if std:
                v.standard_name = std
            v.units = units
            v.location = "node"
            v.mesh = "grid"
            if crs:
                v.grid_mapping = "crs"
        if with_ll:
            lon, lat = gs.frame.to_lonlat(g.x, g.y)
            for name, arr, std, units in (
                ("lon", lon, "longitude", "degrees_east"),
                ("lat", lat, "latitude", "degrees_north"),
            ):
                v = f.createVariable(name, "d", ("jnode", "inode"))
                v[:] = arr.T
                v.standard_name = std
                v.units = units
                v.location = "node"
                v.mesh = "grid"
        v = f.createVariable("jacobian", "d", ("jnode", "inode"))
        v[:] = metrics(g).jacobian.T
        v.long_name = "x_xi*y_eta - x_eta*y_xi"
        v.location = "node"
        v.mesh = "grid"
        v.coordinates = "x y"
        if crs:
            c = f.createVariable("crs", "i", ())
            for k, val in _cf_attrs(crs).items():
                setattr(c, k, val)
            c.crs_authority = crs.encode("utf-8")
        f.flush()
        data = buf.getvalue()
    with atomic_path(path) as tmp:
        tmp.write_bytes(data)


def read_sgrid(path: Path, **_: Any) -> GridSet:
    """Read the node coordinates of an SGRID file (NetCDF-3; NetCDF-4 via netCDF4)."""
    data = read_bytes(path)
    if data[:3] == b"CDF":
        from scipy.io import netcdf_file

        with netcdf_file(io.BytesIO(data), "r", mmap=False) as f:
            return _from_vars(path, f.variables)
    if data[:4] == b"\x89HDF":
        try:
            import netCDF4
        except ImportError as exc:  # pragma: no cover
            raise ReadError(f"{path}: NetCDF-4 files need netCDF4: pip install 'gcmesh[io]'") from exc
        with netCDF4.Dataset(str(path)) as f:
            f.set_auto_mask(False)
            return _from_vars(path, f.variables)
    raise ReadError(f"{path}: not a NetCDF file")


def _attr(v, name, default=None):
    val = getattr(v, name, default)
    if isinstance(val, bytes):
        val = val.decode("utf-8", errors="replace")
    return val


def _from_vars(path: Path, variables) -> GridSet:
    topo = next((v for v in variables.values() if _attr(v, "cf_role") == "grid_topology"), None)
    if topo is None:
        raise ReadError(f"{path}: no SGRID grid_topology variable")
    coords = str(_attr(topo, "node_coordinates", "")).split()
    if len(coords) < 2 or coords[0] not in variables or coords[1] not in variables:
        raise ReadError(f"{path}: node_coordinates {coords} not found")
    vx, vy = variables[coords[0]], variables[coords[1]]
    shape = tuple(getattr(vx, "shape", ()))
    if len(shape) != 2 or tuple(getattr(vy, "shape", ())) != shape:
        raise ReadError(f"{path}: node coordinates are not 2-D arrays of one shape")
    check_nodes(shape[::-1], path)
    X = np.array(vx[:], dtype=np.float64).T
    Y = np.array(vy[:], dtype=np.float64).T
    o = _attr(topo, "local_origin", None)
    try:
        origin = (float(o[0]), float(o[1])) if o is not None and len(o) >= 2 else (0.0, 0.0)
    except (TypeError, ValueError):
        raise ReadError(f"{path}: local_origin {str(o)[:40]!r} is not two numbers") from None
    names = {}
    for b in BORDER_NAMES:
        nm = _attr(topo, f"border_{b}")
        if nm and nm != b:
            names[b] = str(nm)
    crs = None
    gm = _attr(variables[coords[0]], "grid_mapping")
    if gm and gm in variables:
        auth = _attr(variables[gm], "crs_authority")
        wkt = _attr(variables[gm], "crs_wkt")
        crs = normalize_crs(auth or wkt) if (auth or wkt) else None
    g = grid_from_world(X, Y, origin, path, names=names)
    return GridSet((g,), Frame(crs, origin), source=str(path))
