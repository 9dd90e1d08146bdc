"""File I/O for the app: points, projects, meshes (thin adapters over meshcore).

Uses ``meshcore.io`` / ``meshcore.case`` when present; small built-in
fallbacks keep the app usable on their own (CSV/KML/GeoJSON points, TOML
project in the case-file layout, VTK ``.vts`` and CSV mesh output).
"""

from __future__ import annotations

import csv
import json
import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from meshcore import BORDER_NAMES, ReadError, StructuredGrid, WriteError

from .project import Block, Project, SolverSettings, boundary_to_loop

__all__ = [
    "PointData",
    "block_from_case",
    "load_project",
    "mesh_formats",
    "project_lonlat",
    "read_points",
    "save_project",
    "utm_epsg",
    "write_mesh",
]

POINT_FILTER = "Point files (*.csv *.txt *.xy *.dat *.kml *.geojson *.json *.shp *.dxf);;All files (*)"


@dataclass(frozen=True)
class PointData:
    """Points read from a file; ``lonlat`` when they are geographic degrees."""

    points: np.ndarray
    lonlat: bool
    path: str = ""


def _core_io():
    try:
        from meshcore import io as mio
    except ImportError:
        return None
    return mio


# ------------------------------------------------------------------- points
def read_points(path) -> PointData:
    """Read a boundary point file: meshcore.io.read_points, else the built-in readers.

    ``lonlat`` is True when the reader says so, for KML/GeoJSON (always
    WGS84 degrees) and for delimited text whose header starts with lon/lat.
    """
    path = Path(path)
    mio = _core_io()
    if mio is not None and hasattr(mio, "read_points"):
        try:
            res = mio.read_points(path)
        except (ReadError, ValueError):
            res = None
        if res is not None:
            return _from_core(res, path)
    return _read_points_builtin(path)


def _from_core(res, path: Path) -> PointData:
    geo_flag = None
    for attr in ("lonlat", "geographic", "is_geographic"):
        if hasattr(res, attr):
            geo_flag = bool(getattr(res, attr))
    crs = str(getattr(res, "crs", "") or "")
    if geo_flag is None and crs:
        geo_flag = crs.upper() in ("EPSG:4326", "WGS84", "OGC:CRS84")
    if hasattr(res, "polylines"):
        pl = res.polylines[0]
        pts = np.asarray(getattr(pl, "points", pl), float)
    else:
        pts = np.asarray(getattr(res, "points", res), float)
    pts = pts[:, :2]
    if geo_flag is None:
        geo_flag = path.suffix.lower() in (".kml", ".kmz", ".geojson") or _header_is_lonlat(path)
        if _header_is_latlon(path):
            pts = pts[:, ::-1].copy()
    return PointData(_drop_closing(pts), bool(geo_flag), str(path))


def _first_line(path: Path) -> list[str]:
    try:
        with path.open(encoding="utf-8-sig") as fh:
            line = fh.readline()
    except (OSError, UnicodeDecodeError):
        return []
    return [p.lower() for p in re.split(r"[,;\s]+", line.strip()) if p]


def _header_is_lonlat(path: Path) -> bool:
    h = _first_line(path)
    return (bool(h) and h[0] in ("lon", "long", "longitude", "lng")) or _header_is_latlon(path)


def _header_is_latlon(path: Path) -> bool:
    h = _first_line(path)
    return h[:2] in (["lat", "lon"], ["latitude", "longitude"], ["lat", "lng"])


def _read_points_builtin(path: Path) -> PointData:
    suf = path.suffix.lower()
    try:
        text = path.read_text(encoding="utf-8-sig")
    except OSError as exc:
        raise ReadError(f"{path}: cannot read ({exc.strerror})") from None
    if suf == ".kml":
        m = re.search(r"<coordinates>(.*?)</coordinates>", text, re.S)
        if not m:
            raise ReadError(f"{path}: no <coordinates> element found")
        pts = np.array([[float(v) for v in tok.split(",")[:2]] for tok in m.group(1).split()])
        return PointData(_drop_closing(pts), True, str(path))
    if suf in (".geojson", ".json"):
        try:
            obj = json.loads(text)
        except json.JSONDecodeError as exc:
            raise ReadError(f"{path}: line {exc.lineno}: invalid JSON ({exc.msg})") from None
        geom = obj
        if obj.get("type") == "FeatureCollection":
            geom = obj["features"][0]
        if geom.get("type") == "Feature":
            geom = geom["geometry"]
        coords = geom["coordinates"]
        if geom["type"] == "Polygon":
            coords = coords[0]
        elif geom["type"] == "MultiPolygon":
            coords = coords[0][0]
        pts = np.asarray(coords, float)[:, :2]
        return PointData(_drop_closing(pts), True, str(path))
    # delimited text: x,y or lon,lat with an optional header
    rows = []
    header = None
    for lineno, line in enumerate(text.splitlines(), 1):
        s = line.strip()
        if not s or s.startswith("#"):
            continue
        parts = [p for p in re.split(r"[,;\s]+", s) if p]
        try:
            rows.append([float(parts[0]), float(parts[1])])
        except (ValueError, IndexError):
            if not rows and header is None:
                header = [p.lower() for p in parts]
                continue
            raise ReadError(f"{path}: line {lineno}: expected two numbers, got {s!r}") from None
    if len(rows) < 3:
        raise ReadError(f"{path}: needs at least 3 points, found {len(rows)}")
    pts = np.array(rows)
    if header and header[:2] in (["lat", "lon"], ["latitude", "longitude"]):
        pts = pts[:, ::-1].copy()
        lonlat = True
    else:
        lonlat = bool(header and header[0] in ("lon", "long", "longitude", "lng"))
    return PointData(_drop_closing(pts), lonlat, str(path))


def _looks_lonlat(p: np.ndarray) -> bool:
    return bool(len(p) and np.all(np.abs(p[:, 0]) <= 180) and np.all(np.abs(p[:, 1]) <= 90))


def _drop_closing(p: np.ndarray) -> np.ndarray:
    if len(p) > 3 and np.allclose(p[0], p[-1]):
        return p[:-1].copy()
    return p


def utm_epsg(lon: float, lat: float) -> int:
    """EPSG code of the WGS84 UTM zone containing (lon, lat)."""
    zone = math.floor((lon + 180.0) / 6.0) % 60 + 1
    return (32600 if lat >= 0 else 32700) + zone


def project_lonlat(points: np.ndarray, epsg: int | None = None) -> tuple[np.ndarray, str]:
    """Project lon/lat degrees to metres (UTM of the centroid by default)."""
    from pyproj import Transformer

    lon0, lat0 = np.mean(points, axis=0)
    code = epsg or utm_epsg(float(lon0), float(lat0))
    tr = Transformer.from_crs("EPSG:4326", f"EPSG:{code}", always_xy=True)
    x, y = tr.transform(points[:, 0], points[:, 1])
    return np.column_stack([x, y]), f"EPSG:{code}"


# ------------------------------------------------------------------ project
def block_from_case(bc) -> Block:
    """A :class:`Block` from a :class:`meshcore.case.BlockCase`."""
    specs = tuple(dict(bc.border_specs).items())
    common = {
        "name": bc.name,
        "weights": tuple(bc.weights),
        "initial": bc.initial,
        "curve": bc.curve,
        "periodic": bool(bc.periodic),
        "borders": specs,
        "snap_angle": bc.snap_angle,
        "keep_nodes": bc.cells is None,
    }
    if bc.loop is not None:
        pts = np.asarray(bc.loop, float)
        if len(pts) > 3 and np.allclose(pts[0], pts[-1]):
            pts = pts[:-1]
        corners = tuple(int(c) % len(pts) for c in bc.corners)
        cells = bc.cells
        if cells is None:
            n = len(pts)
            sw, se, ne, _nw = corners
            cells = ((se - sw) % n, (ne - se) % n)
        return Block(points=pts, closed=True, corners=corners, cells=cells, **common)
    bd = tuple(np.asarray(bc.borders[n], float) for n in BORDER_NAMES)
    cells = bc.cells or (len(bd[0]) - 1, len(bd[3]) - 1)
    block = Block(boundary=bd, cells=cells, **common)
    # four separate borders become an editable loop unless left and right coincide (a cut/seam)
    cut = bd[1].shape == bd[3].shape and np.allclose(bd[1], bd[3])
    return block if (cut or bc.periodic) else boundary_to_loop(block)


def block_to_case(b: Block):
    from meshcore.case import BlockCase

    kw = {
        "name": b.name,
        "cells": None if b.keep_nodes else tuple(b.cells),
        "weights": tuple(b.weights),
        "initial": b.initial,
        "curve": b.curve,
        "periodic": b.periodic,
        "snap_angle": b.snap_angle,
        "border_specs": dict(b.borders),
    }
    if b.boundary is not None:
        return BlockCase(borders={n: np.asarray(p) for n, p in zip(BORDER_NAMES, b.boundary, strict=True)}, **kw)
    return BlockCase(loop=np.asarray(b.points), corners=tuple(b.corners), **kw)


def project_from_case(case) -> Project:
    s = case.solver
    solver = SolverSettings(method=s.method, tolerance=s.tolerance, max_iterations=s.max_iterations, omega=s.omega)
    return Project(
        blocks=tuple(block_from_case(b) for b in case.blocks),
        solver=solver,
        title=case.title,
        crs=str(dict(case.extra).get("crs", "")),
    )


def project_to_case(project: Project):
    """The :class:`meshcore.case.Case` of the ready blocks (raises ValueError when none is)."""
    from meshcore import EllipticConfig
    from meshcore.case import Case

    blocks = tuple(block_to_case(b) for b in project.blocks if b.ready)
    if not blocks:
        raise ValueError("nothing to save yet: no block has a closed boundary with four corners")
    s = project.solver
    solver = EllipticConfig(method=s.method, tolerance=s.tolerance, max_iterations=s.max_iterations, omega=s.omega)
    return Case(blocks=blocks, title=project.title, solver=solver)


def load_project(path) -> Project:
    """Read a case file into a project (meshcore.case.load_case)."""
    from meshcore.case import load_case

    return project_from_case(load_case(path))


def save_project(project: Project, path) -> None:
    """Write the project's ready blocks as a case file (meshcore.case.save_case)."""
    from meshcore.case import save_case

    save_case(project_to_case(project), path)


# --------------------------------------------------------------------- mesh
def mesh_formats() -> list[tuple[str, str]]:
    """``(description, pattern)`` pairs for the export dialog."""
    mio = _core_io()
    suffixes = getattr(mio, "_SUFFIX", None) if mio is not None else None
    if not isinstance(suffixes, dict) or not suffixes:
        return [("VTK structured grid", "*.vts"), ("CSV nodes i,j,x,y", "*.csv")]
    by_fmt: dict[str, list[str]] = {}
    for suf, fmt in suffixes.items():
        by_fmt.setdefault(fmt, []).append(f"*{suf}")
    return [(fmt, " ".join(pats)) for fmt, pats in by_fmt.items()]


def write_mesh(path, grids: list[StructuredGrid]) -> None:
    """Write the grid(s) with meshcore.io.write, or the built-in .vts/.csv writers."""
    path = Path(path)
    mio = _core_io()
    if mio is not None and hasattr(mio, "write"):
        mio.write(path, grids[0] if len(grids) == 1 else grids)
        return
    g = grids[0]
    suf = path.suffix.lower()
    try:
        if suf == ".vts":
            _write_vts(path, g)
        elif suf == ".csv":
            with path.open("w", newline="") as fh:
                w = csv.writer(fh)
                w.writerow(["i", "j", "x", "y"])
                ni1, nj1 = g.shape
                for j in range(nj1):
                    for i in range(ni1):
                        w.writerow([i, j, repr(float(g.x[i, j])), repr(float(g.y[i, j]))])
        else:
            raise WriteError(f"{path}: unknown mesh format {suf!r} (use .vts or .csv)")
    except OSError as exc:
        raise WriteError(f"{path}: cannot write ({exc.strerror})") from None


def _write_vts(path: Path, g: StructuredGrid) -> None:
    ni1, nj1 = g.shape
    pts = np.column_stack([g.x.T.ravel(), g.y.T.ravel(), np.zeros(ni1 * nj1)])  # i fastest
    body = "\n".join(" ".join(repr(float(v)) for v in row) for row in pts)
    ext = f"0 {ni1 - 1} 0 {nj1 - 1} 0 0"
    path.write_text(
        '<?xml version="1.0"?>\n'
        '<VTKFile type="StructuredGrid" version="1.0" byte_order="LittleEndian">\n'
        f'  <StructuredGrid WholeExtent="{ext}">\n    <Piece Extent="{ext}">\n'
        '      <Points>\n        <DataArray type="Float64" NumberOfComponents="3" format="ascii">\n'
        f"{body}\n        </DataArray>\n      </Points>\n    </Piece>\n  </StructuredGrid>\n</VTKFile>\n",
        encoding="utf-8",
    )
