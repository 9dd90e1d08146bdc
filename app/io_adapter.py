"""File I/O for the app: thin adapters over ``meshcore.io``, ``meshcore.crs`` and ``meshcore.case``.

Points come from :func:`meshcore.io.read_points` (every format it reads);
lon/lat outlines are projected by :func:`meshcore.crs.project` to local metric
coordinates (UTM minus a round origin) and the :class:`~meshcore.crs.Frame` is
kept in the project, saved in the case file and passed to every exporter.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from meshcore import BORDER_NAMES, BorderSpec, MeshcoreError, ReadError

from .project import Block, Project, boundary_to_loop

__all__ = [
    "PointData",
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

POINT_FILTER = (
    "Point files (*.csv *.txt *.xy *.dat *.tsv *.kml *.kmz *.gpx *.geojson *.json *.shp *.dxf);;All files (*)"
)


@dataclass(frozen=True)
class PointData:
    """The largest polyline of a point file (``index`` in the file); ``lonlat`` when it is in degrees.

    ``note``: how the file was read when that is not what it says (metres in a lon/lat format).
    """

    points: np.ndarray
    lonlat: bool
    path: str = ""
    pointset: object = None  # the meshcore.io.PointSet, when meshcore read the file
    index: int = 0
    note: str = ""


def largest_polyline(ps) -> int:
    """The index of the polyline that encloses the largest area (of its closed ring), then the longest.

    A file that is not one lake (a shore drawn in pieces, or rings that do not nest) is imported
    as one block: the largest line, not whatever line comes first (a jetty, a small island).
    """
    best, key = 0, None
    for k, pl in enumerate(ps.polylines):
        p = np.asarray(pl.points, float).reshape(-1, 2)
        if len(p) < 2:
            continue
        x, y = p[:, 0] - p[:, 0].mean(), p[:, 1] - p[:, 1].mean()
        area = 0.5 * abs(float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))))
        length = float(np.hypot(*np.diff(p, axis=0).T).sum())
        if key is None or (area, length) > key:
            best, key = k, (area, length)
    return best


def _read_metres_or_raise(path: Path, exc: Exception):
    """A file of a lon/lat format (GeoJSON, a CSV headed lon/lat) whose numbers are out of the degrees'
    range: read again as local metres without a CRS, with a note; the error (without the command line's
    flag, which the app has no use for) when it still cannot be read or its numbers are degrees."""
    from meshcore import io as mio
    from meshcore.crs import looks_lonlat, looks_swapped

    try:
        ps = mio.read_points(path, crs="local")
    except (MeshcoreError, ValueError):
        ps = None
    lines = [np.asarray(pl.points, float).reshape(-1, 2) for pl in (ps.polylines if ps is not None else ())]
    pts = np.vstack(lines) if lines else np.zeros((0, 2))
    out = (np.abs(pts[:, 0]) > 180) | (np.abs(pts[:, 1]) > 90)
    # degrees with a few wrong numbers (a typo) stay an error naming the first wrong point
    typo = out.any() and out.mean() < 0.1 and looks_lonlat(pts[~out])
    # latitude, longitude under a lon/lat header (or in GeoJSON): the error says so; was read as metres
    if ps is None or not out.any() or typo or looks_swapped(pts):
        raise ReadError(str(exc).split(" — GeoJSON positions are lon/lat")[0]) from None
    k = int(np.flatnonzero(out)[0])
    note = (
        f"{path.name}: point {k + 1} ({pts[k, 0]:g}, {pts[k, 1]:g}) is no longitude/latitude: "
        "the file is read as local metres without a CRS (a grid in metres, not placed on the map)"
    )
    return ps, note


def read_points(path) -> PointData:
    """Read a boundary point file with :func:`meshcore.io.read_points` (every format it knows).

    ``lonlat`` follows the rule of ``meshcore mesh`` (:func:`meshcore.cli.lakefile.is_lonlat`): the
    file says so, or it says nothing and its numbers look like degrees (a headerless CSV).  A file
    whose format says lon/lat but whose numbers are metres is read as metres without a CRS (``note``).
    The points are those of the largest polyline (:func:`largest_polyline`).
    """
    from meshcore import io as mio
    from meshcore.cli.lakefile import is_lonlat

    path = Path(path)
    note = ""
    try:
        ps = mio.read_points(path)
    except ReadError as exc:
        ps, note = _read_metres_or_raise(path, exc)
    if not ps.polylines:
        raise ReadError(f"{path}: the file holds no polyline")
    k = largest_polyline(ps)
    pts = np.asarray(ps.polylines[k].points, float)
    return PointData(_drop_closing(pts), is_lonlat(ps), str(path), ps, k, note)


def to_local(pd: PointData, frame=None) -> tuple[np.ndarray, object]:
    """Project lon/lat points to local metric coordinates.

    With ``frame`` (a :class:`meshcore.crs.Frame` already used by the project)
    the points go to that CRS and origin; otherwise to the UTM zone of their
    centroid with a round local origin (:func:`meshcore.crs.project`).
    Returns ``(points, frame)`` (those of the polyline ``pd.index``).
    """
    from meshcore import crs as mcrs
    from meshcore.io import PointSet, Polyline

    ps = pd.pointset
    k = pd.index
    if ps is None:
        ps, k = PointSet((Polyline("points", pd.points, closed=True),), mcrs.LONLAT, pd.path), 0
    src = mcrs.LONLAT if pd.lonlat and ps.crs is None else None
    if frame is not None and frame.crs:
        local, fr = mcrs.project(ps, frame.crs, origin=frame.origin, source_crs=src)
    else:
        local, fr = mcrs.project(ps, "auto", source_crs=src)
    return _drop_closing(np.asarray(local.polylines[k].points, float)), fr


def projection_named(pd: PointData, frame=None) -> str:
    """What :func:`to_local` projects ``pd`` to, for the lon/lat question: "EPSG:32610, WGS 84 / UTM zone
    10N" (it said "the UTM zone of the outline"; which one showed only on the axes afterwards)."""
    from meshcore.crs import crs_name

    try:
        crs = frame.crs if frame is not None else to_local(pd, None)[1].crs
        return f"{crs}, {crs_name(crs)}"
    except (MeshcoreError, ValueError, AttributeError):
        return frame.crs if frame is not None else "the UTM zone of the outline"


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
def _editable(spec) -> Block:
    """A case block as an editable block: four separate borders become a loop + corners,
    unless left and right coincide (a cut/seam) or the block is a C-grid (its bottom folds
    back along the wake cut)."""
    block = Block.of(spec)
    if spec.boundary is None:
        return block
    _b, r, _t, l = spec.boundary
    cut = r.shape == l.shape and np.allclose(r, l)
    return block if (cut or spec.periodic or spec.wake) else boundary_to_loop(block)


def _frame_fields(frame) -> dict:
    if frame is None:
        return {}
    return {"crs": frame.crs or "", "origin": tuple(frame.origin), "source_crs": frame.source_crs or ""}


def project_from_case(case) -> Project:
    from meshcore.crs import frame_from_case

    project = Project(
        blocks=tuple(_editable(b) for b in case.blocks),
        solver=case.solver,
        title=case.title,
        **_frame_fields(frame_from_case(case)),
    )
    if case.lake is not None and len(project.blocks) == 1:  # a lake saved before Auto layout: its islands
        project = project.replaced(lake=_lake_of(case.lake))
    return project


def lake_section(lake):
    """The ``[lake]`` table of a project's lake (:class:`meshcore.case.LakeSection`): the water as
    imported and the Lake panel's settings; None without a lake."""
    if lake is None:
        return None
    from meshcore.case import LakeSection

    lay = lake.layout  # what the layout changed in the water: the saved blocks cannot tell it again
    return LakeSection(
        shore=lake.outline,
        islands=lake.holes,
        cell_size=lake.cell_size,
        regular=lake.regular,
        single=lake.single,
        notes=lay.notes if lay is not None else (),
        details=lay.details if lay is not None else (),
    )


def _lake_of(section, layout=None):
    from .lake import Lake

    return Lake(
        outline=section.shore,
        holes=section.islands,
        cell_size=section.cell_size,
        regular=section.regular,
        single=section.single,
        layout=layout,
    )


def project_to_case(project: Project):
    """The :class:`meshcore.case.Case` of the ready blocks (raises ValueError when none is)."""
    from meshcore.case import Case

    blocks = tuple(b for b in project.blocks if b.ready)
    if not blocks:
        raise ValueError("nothing to save yet: no block has a closed boundary with four corners")
    frame = project_frame(project)
    crs = frame.as_dict() if frame is not None else None
    # a lake not laid out yet: the one block, and the water (islands) and settings in [lake] (they were lost)
    lake = lake_section(project.lake) if len(blocks) == 1 else None
    return Case(blocks=blocks, title=project.title, solver=project.solver, crs=crs, lake=lake)


def load_project(path) -> Project:
    """Read a case file into a project (meshcore.case.load_case); multiblock cases too."""
    from meshcore.case import load_case

    case = load_case(path)
    if case.outline is not None and case.multiblock is not None and case.multiblock.mode == "orthogonal":
        return project_from_layout_case(case)
    if case.is_multiblock:
        return project_from_multiblock_case(case)
    return project_from_case(case)


def project_from_multiblock_case(case) -> Project:
    """A project showing a multiblock case: one boundary block per topology block."""
    from meshcore.case import case_frame, case_topology

    topo = case_topology(case)
    blocks = []
    for b in topo.blocks:
        names = {n: BorderSpec(name=v) for n, v in dict(b.names).items() if n in BORDER_NAMES and v}
        blocks.append(
            Block(
                name=b.name,
                boundary=tuple(b.borders[n] for n in BORDER_NAMES),
                cells=None,
                weights=tuple(b.weights),
                initial=b.initial,
                borders=names,
            )
        )
    return Project(
        blocks=tuple(blocks),
        solver=case.solver,
        title=case.title,
        multiblock=case,
        **_frame_fields(case_frame(case)),
    )


def case_of_project(project: Project):
    """The :class:`meshcore.case.Case` a project is saved as.

    A multiblock case is written back as read, with the app's solver settings;
    otherwise the ready blocks (:func:`project_to_case`; ValueError when none is).
    """
    if project.layout is not None:
        return _layout_case(project)
    if project.multiblock is None:
        return project_to_case(project)
    case = project.multiblock
    if case.outline is not None:
        # written as explicit [[blocks]] + [[interfaces]]: the outline's point file is
        # relative to the case file it came from
        from meshcore.case import case_topology, topology_case

        case = topology_case(
            case_topology(case), mode=case.settings.mode, title=case.title, description=case.description
        )
        frame = project_frame(project)
        if frame is not None:
            case = case.replaced(crs=frame.as_dict())
    return case.replaced(solver=project.solver, path=None)


def _layout_case(project: Project):
    """A lake layout as an ``[outline]`` case with ``mode = "orthogonal"`` (:func:`meshcore.case.layout_case`).

    The shore, the islands, every cut line and each block's corners and cells: it opens again
    as the same layout, and ``meshcore generate`` makes its grid.
    """
    from meshcore.case import layout_case

    case = layout_case(project.layout, title=project.title, crs=project_frame(project))
    # the water as imported and the settings in [lake]: it opens again as such
    return case.replaced(solver=project.solver, path=None, lake=lake_section(project.lake))


def project_from_layout_case(case) -> Project:
    """A project of an orthogonal ``[outline]`` case: the lake (shore, islands, layout) and its blocks."""
    from meshcore.case import case_frame, case_layout

    from .lake import Lake, with_layout

    layout = case_layout(case)
    if case.lake is not None and (case.lake.notes or case.lake.details):  # lost on reopening: Lake panel, Messages
        layout = dataclasses.replace(layout, notes=case.lake.notes, details=case.lake.details)
    base = Project(solver=case.solver, title=case.title, **_frame_fields(case_frame(case)))
    if case.lake is not None:  # the water as imported (a case the app saved) and the Lake panel's settings
        return with_layout(base, _lake_of(case.lake, layout))
    # else the water as the layout has it (every vertex its blocks put on the shore)
    poly = layout.polygon
    lake = Lake(
        outline=np.asarray(poly.exterior.coords)[:-1],
        holes=tuple(np.asarray(r.coords)[:-1] for r in poly.interiors),
        cell_size=_cell_size_read(float(layout.cell_size), poly.area),
        layout=layout,
    )
    return with_layout(base, lake)


def _cell_size_read(h: float, area: float) -> float | None:
    """The lake's cell size as a case file gives it back: None ("auto", the Lake panel's about
    10 000 cells) when it is the automatic size of that water to 9 digits.  The case holds the
    layout's size only, so a project saved with "auto" came back as "32.3 m" and kept that size
    when the shore was dragged or the water changed."""
    from .lake import default_cell_size

    return None if math.isclose(h, default_cell_size(area), rel_tol=1e-9) else h


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


def write_mesh(path, grids, frame=None, format=None) -> None:
    """Write the block grid(s) (a list, or a MultiBlockGrid) with :func:`meshcore.io.write`
    (``format``: a format name, else the suffix decides)."""
    from meshcore.io import write

    if isinstance(grids, (list, tuple)):
        grids = grids[0] if len(grids) == 1 else list(grids)
    write(Path(path), grids, format, crs=frame)
