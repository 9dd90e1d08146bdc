"""File I/O for the app: thin adapters over ``meshcore.io``, ``meshcore.crs`` and ``meshcore.case``.

Points come from :func:`meshcore.io.read_points` (every format it reads);
lon/lat outlines are projected by :func:`meshcore.crs.project` to local metric
coordinates (UTM minus a round origin) and the :class:`~meshcore.crs.Frame` is
kept in the project, saved in the case file and passed to every exporter.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from meshcore import BORDER_NAMES, BorderSpec, ReadError

from .project import Block, Project, SolverSettings, boundary_to_loop

__all__ = [
    "PointData",
    "block_from_case",
    "case_of_project",
    "dumps_project",
    "load_project",
    "lonlat_to_local",
    "mesh_formats",
    "project_frame",
    "read_points",
    "save_project",
    "to_local",
    "write_mesh",
]

POINT_FILTER = "Point files (*.csv *.txt *.xy *.dat *.tsv *.kml *.kmz *.geojson *.json *.shp *.dxf);;All files (*)"


@dataclass(frozen=True)
class PointData:
    """The first polyline of a point file; ``lonlat`` when it is in geographic degrees."""

    points: np.ndarray
    lonlat: bool
    path: str = ""
    pointset: object = None  # the meshcore.io.PointSet, when meshcore read the file


def read_points(path) -> PointData:
    """Read a boundary point file with :func:`meshcore.io.read_points` (every format it knows)."""
    from meshcore import crs as mcrs
    from meshcore import io as mio

    path = Path(path)
    ps = mio.read_points(path)
    if not ps.polylines:
        raise ReadError(f"{path}: the file holds no polyline")
    pts = np.asarray(ps.polylines[0].points, float)
    geographic = (ps.crs is not None and mcrs.is_geographic(ps.crs)) or (
        ps.crs is None and mcrs.looks_lonlat(pts) and path.suffix.lower() in (".kml", ".kmz", ".geojson")
    )
    return PointData(_drop_closing(pts), bool(geographic), str(path), ps)


def to_local(pd: PointData, frame=None) -> tuple[np.ndarray, object]:
    """Project lon/lat points to local metric coordinates.

    With ``frame`` (a :class:`meshcore.crs.Frame` already used by the project)
    the points go to that CRS and origin; otherwise to the UTM zone of their
    centroid with a round local origin (:func:`meshcore.crs.project`).
    Returns ``(points, frame)``.
    """
    from meshcore import crs as mcrs
    from meshcore.io import PointSet, Polyline

    ps = pd.pointset
    if ps is None:
        ps = PointSet((Polyline("points", pd.points, closed=True),), mcrs.LONLAT, pd.path)
    src = mcrs.LONLAT if pd.lonlat and ps.crs is None else None
    if frame is not None and frame.crs:
        local, fr = mcrs.project(ps, frame.crs, origin=frame.origin, source_crs=src)
    else:
        local, fr = mcrs.project(ps, "auto", source_crs=src)
    return _drop_closing(np.asarray(local.polylines[0].points, float)), fr


def lonlat_to_local(points, frame=None) -> tuple[np.ndarray, object]:
    """Longitude/latitude degrees (``(n, 2)``) to the project's local metric coordinates.

    With ``frame`` (the project's :class:`meshcore.crs.Frame`) the points go to
    its CRS minus its origin; without, to the UTM zone of their centroid with a
    round origin (the frame is returned so the project can adopt it).
    """
    from meshcore import crs as mcrs
    from meshcore.io import PointSet, Polyline

    ps = PointSet((Polyline("points", np.asarray(points, float).reshape(-1, 2), closed=False),), mcrs.LONLAT, "")
    if frame is not None and frame.crs:
        local, fr = mcrs.project(ps, frame.crs, origin=frame.origin)
    else:
        local, fr = mcrs.project(ps, "auto")
    return np.asarray(local.polylines[0].points, float), fr


def _drop_closing(p: np.ndarray) -> np.ndarray:
    if len(p) > 3 and np.allclose(p[0], p[-1]):
        return p[:-1].copy()
    return p


def project_frame(project: Project):
    """The :class:`meshcore.crs.Frame` of a project (None when it has no CRS)."""
    if not project.crs:
        return None
    from meshcore.crs import Frame

    return Frame(project.crs, tuple(project.origin), project.source_crs or None)


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
        "control": getattr(bc, "control", None),
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
    # or the block is a C-grid (its bottom folds back along the wake cut)
    cut = bd[1].shape == bd[3].shape and np.allclose(bd[1], bd[3])
    ctl = getattr(bc, "control", None)
    wake = (ctl.get("wake", 0) if isinstance(ctl, dict) else getattr(ctl, "wake", 0)) if ctl else 0
    return block if (cut or bc.periodic or wake) else boundary_to_loop(block)


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
    if b.control is not None:
        kw["control"] = b.control
    if b.boundary is not None:
        return BlockCase(borders={n: np.asarray(p) for n, p in zip(BORDER_NAMES, b.boundary, strict=True)}, **kw)
    return BlockCase(loop=np.asarray(b.points), corners=tuple(b.corners), **kw)


def project_from_case(case) -> Project:
    s = case.solver
    repair = str(getattr(case, "repair", "auto"))  # "strict" has no meaning in the app: auto
    solver = SolverSettings(
        method=s.method,
        tolerance=s.tolerance,
        max_iterations=s.max_iterations,
        omega=s.omega,
        repair="off" if repair == "off" else "auto",
    )
    frame = dict(case.extra).get("crs") or {}
    origin = frame.get("origin", (0.0, 0.0))
    return Project(
        blocks=tuple(block_from_case(b) for b in case.blocks),
        solver=solver,
        title=case.title,
        crs=str(frame.get("crs", "") or ""),
        origin=(float(origin[0]), float(origin[1])),
        source_crs=str(frame.get("source_crs", "") or ""),
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
    extra = {}
    frame = project_frame(project)
    if frame is not None:
        extra["crs"] = frame.as_dict()
    return Case(blocks=blocks, title=project.title, solver=solver, extra=extra, repair=s.repair)


def load_project(path) -> Project:
    """Read a case file into a project (meshcore.case.load_case); multiblock cases too."""
    from meshcore.case import load_case

    case = load_case(path)
    try:
        from meshcore.multiblock.case import is_multiblock_case
    except ImportError:  # older meshcore
        return project_from_case(case)
    if is_multiblock_case(case):
        return project_from_multiblock_case(case)
    return project_from_case(case)


def project_from_multiblock_case(case) -> Project:
    """A project showing a multiblock case: one boundary block per topology block."""
    from meshcore.multiblock.case import case_frame, case_topology

    topo = case_topology(case)
    blocks = []
    for b in topo.blocks:
        bd = tuple(np.asarray(b.borders[n], float) for n in BORDER_NAMES)
        names = {n: BorderSpec(name=v) for n, v in dict(b.names).items() if n in BORDER_NAMES and v}
        blocks.append(
            Block(
                name=b.name,
                boundary=bd,
                cells=(len(bd[0]) - 1, len(bd[3]) - 1),
                keep_nodes=True,
                weights=tuple(b.weights),
                initial=b.initial,
                borders=tuple(names.items()),
            )
        )
    s = case.solver
    frame = case_frame(case)
    return Project(
        blocks=tuple(blocks),
        solver=SolverSettings(method=s.method, tolerance=s.tolerance, max_iterations=s.max_iterations, omega=s.omega),
        title=case.title,
        crs=(frame.crs or "") if frame is not None else "",
        origin=tuple(frame.origin) if frame is not None else (0.0, 0.0),
        source_crs=(frame.source_crs or "") if frame is not None else "",
        multiblock=case,
    )


def case_of_project(project: Project):
    """The :class:`meshcore.case.Case` a project is saved as.

    A multiblock case is written back as read, with the app's solver settings;
    otherwise the ready blocks (:func:`project_to_case`; ValueError when none is).
    """
    from meshcore import EllipticConfig

    if project.multiblock is None:
        return project_to_case(project)
    s = project.solver
    cfg = EllipticConfig(
        method="auto" if s.method == "foldfree" else s.method,
        tolerance=s.tolerance,
        max_iterations=s.max_iterations,
        omega=s.omega,
    )
    case = project.multiblock
    if "outline" in case.extra:
        # written as explicit [[blocks]] + [[interfaces]] (meshcore's dump of an [outline]
        # case does not load back: it writes ``blocks = []``)
        from meshcore.multiblock.case import _settings, case_topology, topology_case

        mode, _start = _settings(case)
        case = topology_case(case_topology(case), mode=mode, title=case.title, description=case.description, solver=cfg)
        frame = project_frame(project)
        if frame is not None:
            case = case.replaced(extra={**dict(case.extra), "crs": frame.as_dict()})
    return case.replaced(solver=cfg, path=None)


def save_project(project: Project, path) -> None:
    """Write the project as a case file (:func:`meshcore.case.save_case` of :func:`case_of_project`)."""
    from meshcore.case import save_case

    save_case(case_of_project(project), path)


def dumps_project(project: Project) -> str:
    """The case-file text of a project (what :func:`save_project` writes)."""
    from meshcore.case import dumps_case

    return dumps_case(case_of_project(project))


# --------------------------------------------------------------------- mesh
def mesh_formats() -> list[tuple[str, str]]:
    """``(description, pattern)`` pairs of every format meshcore writes (export dialog)."""
    from meshcore.io import FORMATS

    out = []
    for f in FORMATS.values():
        if f.writer:
            out.append((f"{f.description} [{f.name}]", " ".join(f"*{x}" for x in f.suffixes)))
    return out


def write_mesh(path, grids, frame=None) -> None:
    """Write the block grid(s) (a list, or a MultiBlockGrid) with :func:`meshcore.io.write`."""
    from meshcore.io import write

    if isinstance(grids, (list, tuple)):
        grids = grids[0] if len(grids) == 1 else list(grids)
    write(Path(path), grids, crs=frame)
