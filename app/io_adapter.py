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
import tomllib
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from meshcore import BORDER_NAMES, BorderSpec, ReadError, StructuredGrid, WriteError

from .project import Block, Project, SolverSettings

__all__ = [
    "PointData",
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
    """Read a boundary point file (meshcore.io.read_points when available)."""
    path = Path(path)
    mio = _core_io()
    if mio is not None and hasattr(mio, "read_points"):
        res = mio.read_points(path)
        pts = getattr(res, "points", res)
        lonlat = bool(getattr(res, "lonlat", getattr(res, "geographic", False)))
        pts = np.asarray(pts, float)[:, :2]
        if not lonlat:
            lonlat = _looks_lonlat(pts) and path.suffix.lower() in (".kml", ".geojson")
        return PointData(_drop_closing(pts), lonlat, str(path))
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
    zone = int(math.floor((lon + 180.0) / 6.0)) % 60 + 1
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
def _block_to_dict(b: Block) -> dict:
    d: dict = {"name": b.name, "cells": list(b.cells), "weights": list(b.weights),
               "initial": b.initial, "curve": b.curve}
    if b.periodic:
        d["periodic"] = True
    if b.boundary is not None:
        d["boundary"] = {n: np.asarray(p).tolist() for n, p in zip(BORDER_NAMES, b.boundary, strict=True)}
    else:
        d["points"] = np.asarray(b.points).tolist()
        if b.corners is not None:
            d["corners"] = list(b.corners)
    borders = {}
    for n, s in b.borders:
        e = {"distribution": s.distribution}
        for k in ("first", "last", "name"):
            if getattr(s, k) is not None:
                e[k] = getattr(s, k)
        if e != {"distribution": "uniform"}:
            borders[n] = e
    if borders:
        d["borders"] = borders
    return d


def project_to_dict(p: Project) -> dict:
    s = p.solver
    solver = {"method": s.method, "max_iterations": s.max_iterations}
    if s.tolerance is not None:
        solver["tolerance"] = s.tolerance
    if s.omega is not None:
        solver["omega"] = s.omega
    out: dict = {"solver": solver, "blocks": [_block_to_dict(b) for b in p.blocks if len(b.points) or b.boundary]}
    if p.title:
        out["title"] = p.title
    if p.crs:
        out["crs"] = p.crs
    return out


def project_from_dict(d: dict, where: str = "project") -> Project:
    blocks = []
    for k, bd in enumerate(d.get("blocks", [])):
        name = bd.get("name", f"block{k + 1}")
        boundary = None
        if "boundary" in bd:
            boundary = tuple(np.asarray(bd["boundary"][n], float) for n in BORDER_NAMES)
        borders = {n: BorderSpec(**v) for n, v in bd.get("borders", {}).items()}
        pts = np.asarray(bd.get("points", np.zeros((0, 2))), float).reshape(-1, 2)
        corners = bd.get("corners")
        blocks.append(Block(
            name=name, points=pts, closed=len(pts) >= 3, corners=tuple(corners) if corners else None,
            boundary=boundary, cells=tuple(bd.get("cells", (32, 16))), weights=tuple(bd.get("weights", (0.5, 0.5))),
            initial=bd.get("initial", "weighted"), curve=bd.get("curve", "linear"),
            periodic=bool(bd.get("periodic", False)), borders=tuple(borders.items()),
        ))
    sd = d.get("solver", {})
    solver = SolverSettings(method=sd.get("method", "auto"), tolerance=sd.get("tolerance"),
                            max_iterations=int(sd.get("max_iterations", 50_000)), omega=sd.get("omega"))
    return Project(blocks=tuple(blocks) or (Block(name="block"),), solver=solver,
                   crs=d.get("crs", ""), title=d.get("title", ""))


def load_project(path) -> Project:
    """Read a project/case TOML file."""
    path = Path(path)
    try:
        d = tomllib.loads(path.read_text(encoding="utf-8"))
    except OSError as exc:
        raise ReadError(f"{path}: cannot read ({exc.strerror})") from None
    except tomllib.TOMLDecodeError as exc:
        raise ReadError(f"{path}: {exc}") from None
    _resolve_files(d, path.parent)
    return project_from_dict(d, where=str(path))


def _resolve_files(d: dict, base: Path) -> None:
    """Case files may reference point files (``points = "file.csv"``)."""
    for bd in d.get("blocks", []):
        if isinstance(bd.get("points"), str):
            pd = read_points(base / bd["points"])
            pts = pd.points
            if pd.lonlat:
                pts, crs = project_lonlat(pts)
                d.setdefault("crs", crs)
            bd["points"] = pts.tolist()


def save_project(project: Project, path) -> None:
    """Write the project as a TOML case file (atomically)."""
    import tomli_w

    path = Path(path)
    data = tomli_w.dumps(project_to_dict(project))
    tmp = path.with_name(path.name + ".tmp")
    try:
        tmp.write_text(data, encoding="utf-8")
        tmp.replace(path)
    except OSError as exc:
        tmp.unlink(missing_ok=True)
        raise WriteError(f"{path}: cannot write ({exc.strerror})") from None


# --------------------------------------------------------------------- mesh
def mesh_formats() -> list[tuple[str, str]]:
    """``(description, pattern)`` pairs for the export dialog."""
    mio = _core_io()
    fmts = getattr(mio, "FORMATS", None) if mio is not None else None
    out = []
    if isinstance(fmts, dict):
        for name, exts in fmts.items():
            exts = exts if isinstance(exts, (list, tuple)) else [exts]
            out.append((name, " ".join(f"*{e}" for e in exts)))
    if not out:
        out = [("VTK structured grid", "*.vts"), ("CSV nodes i,j,x,y", "*.csv")]
    return out


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
