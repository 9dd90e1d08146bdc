"""Readers and writers: point files in, grids out (and back in).

Point files → :class:`PointSet` (named polylines + CRS) with :func:`read_points`;
grid files → :class:`GridSet` with :func:`read_blocks` (or one grid with
:func:`read_grid`); any grid or list of blocks → any format with :func:`write`.
The format comes from the suffix or ``format=``; :data:`FORMATS` lists them
(``python -m meshcore.io`` prints the table).

Every writer is atomic (temporary file in the same directory, then
``os.replace``), raises :class:`~meshcore.errors.WriteError` on failure and
leaves nothing behind.  Every reader raises only
:class:`~meshcore.errors.ReadError`, naming the file and line or feature.
Heavy libraries (vtk, h5py, netCDF4, pyproj, ezdxf, pyshp, matplotlib) are
imported only inside the functions that need them.

Examples
--------
>>> import numpy as np, tempfile, os
>>> from meshcore import StructuredGrid
>>> from meshcore.io import write, read_grid
>>> xi, eta = np.meshgrid(np.linspace(0, 2, 5), np.linspace(0, 1, 3), indexing="ij")
>>> d = tempfile.mkdtemp()
>>> p = write(os.path.join(d, "g.xyz"), StructuredGrid(xi, eta))
>>> read_grid(os.path.join(d, "g.xyz"))[0].shape
(5, 3)
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..crs import Frame, as_frame
from ..errors import ReadError, WriteError
from ..grid import StructuredGrid
from ._base import (
    GridSet,
    Interface,
    PointSet,
    Polyline,
    as_blocks,
    atomic_path,
    coerce_interfaces,
    find_interfaces,
    read_guard,
)
from ._base import (
    block_names as _block_names,
)

__all__ = [
    "FORMATS",
    "Format",
    "GridSet",
    "Interface",
    "PointSet",
    "Polyline",
    "atomic_write_bytes",
    "atomic_write_text",
    "find_format",
    "find_interfaces",
    "read",
    "read_blocks",
    "read_grid",
    "read_points",
    "write",
]


@dataclass(frozen=True, slots=True)
class Format:
    """One file format: suffixes and the functions (``"module:function"``) that handle it."""

    name: str
    suffixes: tuple[str, ...]
    description: str
    writer: str | None = None
    grid_reader: str | None = None
    points_reader: str | None = None
    crs: bool = False
    markers: bool = False
    multiblock: bool = False
    #: ``(module, extra)`` of an optional dependency the format needs, e.g. ``("h5py", "io")``
    requires: tuple[str, str] | None = None

    def missing(self) -> str | None:
        """``None`` when the format can be used, else one line naming the extra to install."""
        if self.requires is None:
            return None
        import importlib.util

        module, extra = self.requires
        if importlib.util.find_spec(module) is not None:
            return None
        return f"{self.name} files need {module}: pip install 'gcmesh[{extra}]'"

    def _load(self, spec: str):
        mod, fn = spec.split(":")
        return getattr(importlib.import_module(f"{__name__}.{mod}"), fn)


FORMATS: dict[str, Format] = {}


def register_format(fmt: Format) -> None:
    """Add (or replace) a format in :data:`FORMATS` (meshio-style registry)."""
    FORMATS[fmt.name] = fmt


for _f in (
    Format(
        "points-csv",
        (".csv", ".txt", ".xy", ".dat", ".tsv"),
        "delimited x/y or lon/lat points",
        points_reader="points_csv:read_points_csv",
        crs=True,
    ),
    Format(
        "geojson",
        (".geojson", ".json"),
        "GeoJSON lines and polygons",
        points_reader="geojson:read_points_geojson",
        crs=True,
    ),
    Format("kml", (".kml",), "Google Earth KML", points_reader="kml:read_points_kml", crs=True),
    Format("kmz", (".kmz",), "Google Earth KMZ (zipped KML)", points_reader="kml:read_points_kmz", crs=True),
    Format("gpx", (".gpx",), "GPS tracks, routes and waypoints", points_reader="gpx:read_points_gpx", crs=True),
    Format(
        "shapefile", (".shp",), "ESRI shapefile (+ .shx, .dbf, .prj)", points_reader="shp:read_points_shp", crs=True
    ),
    Format("dxf", (".dxf",), "AutoCAD DXF polylines and splines", points_reader="dxf:read_points_dxf"),
    Format(
        "plot3d",
        (".xyz", ".x", ".p3d", ".g"),
        "PLOT3D 2-D grid (ASCII / binary)",
        writer="plot3d:write_plot3d",
        grid_reader="plot3d:read_plot3d",
        multiblock=True,
    ),
    Format(
        "vts", (".vts",), "VTK XML StructuredGrid", writer="vtk_xml:write_vts", grid_reader="vtk_xml:read_vts", crs=True
    ),
    Format(
        "vtm",
        (".vtm",),
        "VTK XML MultiBlock of .vts",
        writer="vtk_xml:write_vtm",
        grid_reader="vtk_xml:read_vtm",
        crs=True,
        multiblock=True,
    ),
    Format(
        "npz",
        (".npz",),
        "NumPy archive: coordinates, metrics, CRS",
        writer="native:write_npz",
        grid_reader="native:read_npz",
        crs=True,
        multiblock=True,
    ),
    Format(
        "metrics-csv",
        (".csv",),
        "metrics table per node (CSV)",
        writer="native:write_metrics_csv",
        grid_reader="native:read_metrics_csv",
        crs=True,
        multiblock=True,
    ),
    Format(
        "cgns",
        (".cgns",),
        "CGNS/HDF5 structured zones",
        writer="cgns:write_cgns",
        grid_reader="cgns:read_cgns",
        crs=True,
        markers=True,
        multiblock=True,
        requires=("h5py", "io"),
    ),
    Format(
        "gmsh",
        (".msh",),
        "Gmsh MSH 4.1 (quads + physical border lines)",
        writer="unstructured:write_msh",
        markers=True,
        multiblock=True,
    ),
    Format("su2", (".su2",), "SU2 mesh with markers", writer="unstructured:write_su2", markers=True, multiblock=True),
    Format(
        "delft3d",
        (".grd",),
        "Delft3D RGFGRID grid (+ .enc enclosure)",
        writer="delft3d:write_grd",
        grid_reader="delft3d_single:read_grd_any",
        crs=True,
    ),
    Format(
        "delft3d-single",
        (".grd",),
        "Delft3D single domain: the blocks merged into one .grd with inactive points (+ .enc)",
        writer="delft3d_single:write_grd_single",
        grid_reader="delft3d_single:read_grd_single",
        crs=True,
        multiblock=True,
    ),
    Format(
        "efdc",
        (".inp",),
        "EFDC/EFDC+ grid: cell.inp and, next to it, celllt.inp, dxdy.inp, lxly.inp, corners.inp",
        writer="efdc:write_efdc",
        grid_reader="efdc:read_efdc",
        crs=True,
        multiblock=True,
    ),
    Format(
        "delft3d-dd",
        (".ddb",),
        "Delft3D-FLOW domain decomposition (.grd + .enc per block, .ddb couplings)",
        writer="delft3d_dd:write_ddb",
        grid_reader="delft3d_dd:read_ddb",
        crs=True,
        multiblock=True,
    ),
    Format(
        "sgrid",
        (".nc",),
        "NetCDF (SGRID conventions, CF grid mapping)",
        writer="sgrid:write_sgrid",
        grid_reader="sgrid:read_sgrid",
        crs=True,
    ),
    Format(
        "figure",
        (".png", ".svg", ".pdf"),
        "figure (matplotlib)",
        writer="figure:write_figure",
        multiblock=True,
        requires=("matplotlib", "plot"),
    ),
):
    register_format(_f)


#: The files beside a shapefile's ``.shp`` (attributes, index, projection, code page, spatial index).
_SHAPEFILE_PARTS = (".dbf", ".shx", ".prj", ".cpg", ".sbn", ".sbx", ".qix", ".qmd")


def find_format(path: Any, format: str | None = None, *, role: str) -> Format:
    """The :class:`Format` for ``path`` (by suffix) or ``format`` (by name).

    ``role`` is ``"write"``, ``"grid"`` or ``"points"``; among formats sharing a
    suffix (``.csv``) the one that can play the role is chosen.
    """
    attr = {"write": "writer", "grid": "grid_reader", "points": "points_reader"}[role]
    if format is not None:
        fmt = FORMATS.get(format) or next(
            (
                f
                for f in FORMATS.values()
                if format.lower().lstrip(".") in (s.lstrip(".") for s in f.suffixes) and getattr(f, attr)
            ),
            None,
        )
        if fmt is None:
            raise (WriteError if role == "write" else ReadError)(
                f"unknown format {format!r} (known: {', '.join(FORMATS)})"
            )
        return fmt
    suffix = Path(str(path)).suffix.lower()
    cands = [f for f in FORMATS.values() if suffix in f.suffixes]
    for f in cands:
        if getattr(f, attr):
            return f
    can = sorted({s for f in FORMATS.values() if getattr(f, attr) for s in f.suffixes})
    shp = Path(str(path)).with_suffix(".shp")
    if role == "points" and suffix in _SHAPEFILE_PARTS and shp.exists():
        raise ReadError(f"{path}: one of the files of a shapefile: give its .shp ({shp})")
    verb = {"write": "write", "grid": "read grids from", "points": "read points from"}[role]
    what = f"{suffix} files" if suffix else "a file without a suffix"
    raise (WriteError if role == "write" else ReadError)(
        f"{path}: cannot {verb} {what} (known suffixes: {' '.join(can)})"
    )


# ------------------------------------------------------------------- reading
def read_points(
    path: Any,
    *,
    format: str | None = None,
    columns: Any = None,
    crs: Any = None,
    closed: bool | None = None,
    **options: Any,
) -> PointSet:
    """Read named polylines and their CRS from a point file.

    Parameters
    ----------
    path : path-like
        ``.csv/.txt/.xy/.dat``, ``.geojson/.json``, ``.kml``, ``.kmz``, ``.gpx``,
        ``.shp``, ``.dxf`` — or a grid file, whose four borders are returned.
    format : str, optional
        Format name (see :data:`FORMATS`) overriding the suffix.
    columns : (x, y), optional
        CSV: column names or 0-based indices.
    crs : optional
        Declared CRS of the coordinates (EPSG code or string).
    closed : bool, optional
        CSV: force rings / open lines.

    Returns
    -------
    PointSet
        ``.polylines`` (name, ``(n, 2)`` points, closed, orientation) and ``.crs``.

    Raises
    ------
    ReadError
        Naming the file and line or feature.
    """
    p = Path(path)
    fmt = find_format(p, format, role="points") if format or not _is_grid_suffix(p) else None
    with read_guard(p, "point file"):
        if fmt is None:  # a grid file: its borders
            return _grid_as_points(read_blocks(p), p)
        _check_file(p, "point file")
        fn = fmt._load(fmt.points_reader)
        return fn(p, columns=columns, crs=crs, closed=closed, **options)


def _check_file(p: Path, what: str) -> None:
    """A regular file, or one clear ReadError (a device or a pipe could be read for ever, by any reader)."""
    import stat

    if not p.exists():
        raise ReadError(f"{p}: no such file")
    if p.is_dir():
        raise ReadError(f"{p}: is a directory, not a {what}")
    if not stat.S_ISREG(p.stat().st_mode):
        raise ReadError(f"{p}: not a regular file (a device, pipe or socket): give the path of a {what}")


def _is_grid_suffix(p: Path) -> bool:
    s = p.suffix.lower()
    return any(s in f.suffixes and f.grid_reader and not f.points_reader for f in FORMATS.values()) and not any(
        s in f.suffixes and f.points_reader for f in FORMATS.values()
    )


def _grid_as_points(gs: GridSet, p: Path) -> PointSet:
    from ..grid import BORDER_NAMES

    pls = []
    for k, g in enumerate(gs.blocks):
        for b in BORDER_NAMES:
            nm = f"{gs.block_names[k]} {g.names.get(b, b)}" if len(gs.blocks) > 1 else g.names.get(b, b)
            pls.append(Polyline(nm, g.border(b)))
    return PointSet(tuple(pls), gs.frame.crs, str(p), {"frame": gs.frame})


def read_blocks(path: Any, *, format: str | None = None, **options: Any) -> GridSet:
    """Read every block of a grid file (PLOT3D, .vts, .vtm, .npz, .cgns, .grd, .ddb, .nc, EFDC cell.inp, metrics CSV).

    Returns a :class:`GridSet`: blocks in local coordinates, the frame (CRS,
    origin), block names and (where stored) connectivity.
    """
    p = Path(path)
    fmt = find_format(p, format, role="grid")
    with read_guard(p, f"{fmt.name} file"):
        _check_file(p, f"{fmt.name} file")
        missing = fmt.missing()
        if missing:
            raise ReadError(f"{p}: {missing}")
        return fmt._load(fmt.grid_reader)(p, **options)


def read_grid(path: Any, *, format: str | None = None, **options: Any) -> list[StructuredGrid]:
    """Read the blocks of a grid file as a list of grids in local coordinates.

    ``read_grid(path)[0]`` is the grid of a one-block file; use
    :func:`read_blocks` to get the CRS/origin and block names as well.
    """
    return list(read_blocks(path, format=format, **options).blocks)


def read(path: Any, **options: Any) -> StructuredGrid | GridSet | PointSet:
    """Read anything: a point file → PointSet, a one-block grid → StructuredGrid,
    a multi-block grid → GridSet."""
    p = Path(path)
    try:
        fmt = find_format(p, options.get("format"), role="points")
    except ReadError:
        fmt = None
    if fmt is not None and not (p.suffix.lower() == ".csv" and _is_metrics_csv(p)):
        return read_points(p, **options)
    gs = read_blocks(p, **options)
    return gs.blocks[0] if len(gs.blocks) == 1 else gs


def atomic_write_text(path: Any, text: str) -> None:
    """Write ``text`` (UTF-8) to ``path`` atomically (temporary file, then rename)."""
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")


def atomic_write_bytes(path: Any, data: bytes) -> None:
    """Write ``data`` to ``path`` atomically (temporary file, then rename)."""
    with atomic_path(path) as tmp:
        tmp.write_bytes(data)


def _is_metrics_csv(p: Path) -> bool:
    try:
        with open(p, encoding="utf-8", errors="replace") as f:
            for ln in f:
                if not ln.startswith("#"):
                    return ln.replace(" ", "").lower().startswith("block,i,j,x,y")
    except OSError:
        return False
    return False


# ------------------------------------------------------------------- writing
def write(
    path: Any,
    grid_or_blocks: Any,
    format: str | None = None,
    *,
    crs: Any = None,
    origin: Any = None,
    block_names: Any = None,
    connectivity: Any = None,
    **options: Any,
) -> Path:
    """Write a grid or a list of blocks; the format comes from the suffix or ``format``.

    Parameters
    ----------
    path : path-like
        Target file (see :data:`FORMATS` for suffixes).
    grid_or_blocks : StructuredGrid, sequence of StructuredGrid, GridSet or multiblock
        Grids in local coordinates.  Border names come from ``grid.names``
        (e.g. ``{"bottom": "inlet"}``; defaults ``bottom/right/top/left``).
    format : str, optional
        Format name overriding the suffix (``"plot3d"``, ``"vts"`` …).
    crs : Frame, EPSG int or CRS string, optional
        CRS of the world coordinates; stored by formats that can hold it.
    origin : (x0, y0), optional
        Local origin added to every coordinate on output.
    block_names : sequence of str, optional
    connectivity : sequence of Interface or dicts, optional
        1-to-1 interfaces between blocks; found from coordinates when omitted.
    **options
        Format options, e.g. PLOT3D ``mode="ascii"|"fortran"|"binary"``,
        ``lonlat=True`` (SGRID: also store lon/lat), figure options.

    Raises
    ------
    WriteError
        The file could not be written; nothing partial is left behind.
    """
    p = Path(path)
    fmt = find_format(p, format, role="write")
    if isinstance(grid_or_blocks, GridSet):
        gs = grid_or_blocks
        if crs is not None or origin is not None:
            gs = GridSet(
                gs.blocks,
                as_frame(crs if crs is not None else gs.frame, origin),
                gs.block_names,
                gs.connectivity,
                gs.source,
            )
    else:
        blocks = as_blocks(grid_or_blocks)
        names = tuple(block_names) if block_names is not None else _block_names(grid_or_blocks, len(blocks))
        if len(names) != len(blocks):
            raise WriteError(f"{p}: {len(names)} block names for {len(blocks)} blocks")
        conn_names = names
        if connectivity is None:
            connectivity = getattr(grid_or_blocks, "connectivity", None)
        if connectivity is None and hasattr(grid_or_blocks, "interfaces"):  # a MultiBlockGrid: declared parts
            connectivity = grid_or_blocks.interfaces
            conn_names = tuple(getattr(grid_or_blocks, "names", names))
        gs = GridSet(blocks, as_frame(crs, origin), names, coerce_interfaces(connectivity, blocks, conn_names))
    if len(gs.blocks) > 1 and not fmt.multiblock:
        raise WriteError(f"{p}: the {fmt.name} format holds one block, got {len(gs.blocks)}")
    missing = fmt.missing()
    if missing:
        raise WriteError(f"{p}: {missing}")
    fmt._load(fmt.writer)(p, gs, **options)
    return p


_ = Frame
