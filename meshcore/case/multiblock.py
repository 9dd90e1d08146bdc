r"""Multiblock cases: from ``[[interfaces]]`` or ``[outline]`` sections to a topology.

Two ways to describe the blocks:

**Blocks with explicit interfaces** — ordinary ``[[blocks]]`` tables, glued by::

    [multiblock]
    mode = "smooth"              # smooth (interfaces solved) | frozen (paper: interfaces fixed)
    start = "algebraic"          # smooth mode: start from the algebraic grids | frozen solution

    [[interfaces]]
    a = "main.right"             # block.border, optionally a node range: "main.top[4:12]"
    b = "arm.left"
    reversed = false             # optional; default: read from the coordinates

**One outline split by cut lines** (the lake workflow, no ``[[blocks]]``)::

    [outline]
    points = "../lakes/shasta_lake.csv"   # closed shoreline (file or inline [[x, y], ...])
    crs = "utm"                  # lon/lat → metres: utm (pyproj, UTM zone of the centroid, local
                                 # origin; the writers store the CRS) | lonlat (local equirectangular
                                 # about the centroid, no pyproj) | "EPSG:nnnn" | xy (no projection)
                                 # | auto (default: utm for lon/lat input, else xy)
    cuts = [[15, 200], [[-122.3, 40.7], [-122.2, 40.8]]]   # outline indices or points
    snap = 10.0                  # optional snap distance (model units)
    multiple = 2                 # optional: every shared part gets a multiple of 2 cells (multigrid)
    single = true                # optional: counts that close every ring in one index space (EFDC)

    [[outline.blocks]]
    name = "main"
    corners = [15, 35, 99, 200]  # sw, se, ne, nw: outline indices or points
    cells = [48, 13]
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from ..boundary import BorderSpec
from ..errors import CaseFileError, InvalidInputError
from ..generate import block_borders
from ..grid import BORDER_NAMES
from ..multiblock.outline import BlockOutline, from_outline, project_lonlat
from ..multiblock.solver import MODES
from ..multiblock.topology import Block, Interface, MultiBlockTopology, parse_side
from ..spec import BlockSpec, SolverSpec
from .model import Case, InterfaceEntry, MultiblockSection, OutlineSection
from .parse import read_point_file

__all__ = ["case_frame", "case_layout", "case_topology", "cut_case", "layout_case", "outline_points", "topology_case"]


def _read_outline(outline: OutlineSection, base: Path | None, where: str) -> tuple[np.ndarray, Any]:
    """The outline points as given (no projection) and their CRS (None if unknown)."""
    if isinstance(outline.points, str):
        p = Path(outline.points)
        if not p.is_absolute() and base is not None:
            p = base / p
        ps = read_point_file(p, where)
        return np.asarray(ps.polylines[0].points, dtype=np.float64), ps.crs
    return np.asarray(outline.points, dtype=np.float64), None


def _project_outline(pts: np.ndarray, extra: list, crs: Any, origin: Any, where: str, src_crs: Any, case_frame: Any):
    """Project the outline and the extra points; return (xy, extra_xy, frame)."""
    from ..crs import LONLAT, Frame, project_arrays

    if crs == "lonlat":  # local equirectangular about the centroid (no pyproj)
        xy, org = project_lonlat(pts, origin=tuple(origin) if origin is not None else None)
        ex = project_lonlat(extra, origin=org)[0] if extra else np.zeros((0, 2))
        return xy, ex, Frame(None, (0.0, 0.0), LONLAT)
    target: Any = crs
    if crs in ("utm", "auto"):
        target = "auto"
        if case_frame is not None and case_frame.crs is not None:  # the case's [crs] table
            target = case_frame.crs
            if origin is None:
                origin = case_frame.origin
    try:
        (xy,), frame = project_arrays(
            [pts], target, source_crs=src_crs or LONLAT, origin="auto" if origin is None else origin, where=where
        )
        ex = np.asarray(extra, dtype=np.float64).reshape(-1, 2)
        (ex,), _ = project_arrays([ex], frame.crs, source_crs=frame.source_crs, origin=frame.origin, where=where)
    except InvalidInputError as exc:
        raise CaseFileError(f"{where}: {exc}") from None
    return xy, ex, frame


def _outline_geometry(case: Case) -> tuple[np.ndarray, list, list, Any, list]:
    """(outline xy, cuts, blocks, frame, island rings) of an ``[outline]`` case, in model units."""
    from ..crs import frame_from_case, is_geographic, looks_lonlat

    outline = case.outline
    assert outline is not None
    where = f"{case.source}: [outline]"
    pts, src_crs = _read_outline(outline, case.path.parent if case.path else None, f"{where} points")
    cuts = [list(c) for c in outline.cuts]
    blocks = list(outline.blocks)
    holes = [np.asarray(h, dtype=np.float64) for h in outline.holes]
    crs = outline.crs
    frame = None
    # like [[blocks]] point files: a lon/lat *file* is projected by default; inline points
    # only with an explicit crs
    geographic = isinstance(outline.points, str) and (
        (src_crs is not None and is_geographic(src_crs)) or (src_crs is None and looks_lonlat(pts))
    )
    if crs in ("xy", "none") or (crs == "auto" and not geographic):
        return pts, cuts, blocks, None, holes
    extra = [v for c in cuts for v in c if not isinstance(v, int)]
    extra += [v for b in blocks for v in b.corners if not isinstance(v, int)]
    extra += [v for h in holes for v in h.tolist()]
    xy, ex, frame = _project_outline(pts, extra, crs, outline.origin, where, src_crs, frame_from_case(case))
    it = iter(ex.tolist())
    cuts = [[v if isinstance(v, int) else next(it) for v in c] for c in cuts]
    blocks = [replace(b, corners=tuple(v if isinstance(v, int) else next(it) for v in b.corners)) for b in blocks]
    holes = [np.array([next(it) for _ in range(len(h))]) for h in holes]
    return xy, cuts, blocks, frame, holes


def outline_points(case: Case) -> np.ndarray:
    """The outline of an ``[outline]`` case in model units (projected like the grid)."""
    return _outline_geometry(case)[0]


def case_frame(case: Case) -> Any:
    """The :class:`meshcore.crs.Frame` of a case's grid coordinates (None if unknown)."""
    return _frame(case, _outline_geometry(case)[3] if case.outline is not None else None)


def _frame(case: Case, outline_frame: Any) -> Any:
    """:func:`case_frame` given the frame of the outline's projection (None if not projected)."""
    from ..crs import frame_from_case

    if outline_frame is not None and outline_frame.crs is not None:
        return outline_frame
    return frame_from_case(case)


def _outline_topology(case: Case) -> MultiBlockTopology:
    return _outline_topology_frame(case)[0]


def _outline_topology_frame(case: Case) -> tuple[MultiBlockTopology, Any]:
    """The topology of an ``[outline]`` case and its :func:`case_frame`, from one read and
    projection of the outline (the CLI needs both)."""
    assert case.outline is not None
    xy, cuts, blocks, frame, holes = _outline_geometry(case)
    o = case.outline
    try:
        topo = from_outline(
            xy,
            cuts=cuts,
            blocks=blocks,
            holes=holes,
            snap=o.snap,
            multiple=o.multiple,
            cell_size=o.cell_size,
            single=o.single,
        ).topology
    except InvalidInputError as exc:
        raise type(exc)(f"{case.source}: {exc}") from None
    return topo, _frame(case, frame)


def case_topology_frame(case: Case) -> tuple[MultiBlockTopology, Any]:
    """``(case_topology(case), case_frame(case))``, reading and projecting an outline once."""
    if case.outline is not None:
        return _outline_topology_frame(case)
    return _interface_topology(case), case_frame(case)


def case_layout(case: Case) -> Any:
    """The :class:`~meshcore.layout.Layout` of an ``[outline]`` case (for ``mode = "orthogonal"``)."""
    from ..layout import layout_from_outline

    if case.outline is None:
        raise CaseFileError(f'{case.source}: [multiblock] mode = "orthogonal" needs an [outline] section')
    xy, cuts, blocks, _, holes = _outline_geometry(case)
    o = case.outline
    try:
        return layout_from_outline(
            xy, cuts=cuts, blocks=blocks, holes=holes, cell_size=o.cell_size, multiple=o.multiple, single=o.single
        )
    except InvalidInputError as exc:
        raise type(exc)(f"{case.source}: {exc}") from None


def _interface_topology(case: Case) -> MultiBlockTopology:
    src = case.source
    blocks = []
    for b in case.blocks:
        try:
            bd, _ = block_borders(b, where=f"block {b.name!r}")
        except InvalidInputError as exc:
            raise type(exc)(f"{src}: {exc}") from None
        blocks.append(Block(b.name, bd, initial=b.initial, weights=b.weights, names=b.border_names()))
    itfs = []
    for k, t in enumerate(case.interfaces):
        try:
            itfs.append(Interface(parse_side(t.a), parse_side(t.b), t.reversed))
        except InvalidInputError as exc:
            raise type(exc)(f"{src}: [[interfaces]] #{k + 1}: {exc}") from None
    try:
        return MultiBlockTopology(tuple(blocks), tuple(itfs))
    except InvalidInputError as exc:
        raise type(exc)(f"{src}: {exc}") from None


def case_topology(case: Case) -> MultiBlockTopology:
    """The validated topology of a multiblock case."""
    if case.outline is not None:
        return _outline_topology(case)
    return _interface_topology(case)


def topology_case(
    topology: MultiBlockTopology,
    *,
    mode: str = "smooth",
    title: str = "",
    description: str = "",
    solver: SolverSpec | None = None,
) -> Case:
    """A case with explicit blocks (their boundary nodes) and ``[[interfaces]]``.

    This writes the block connectivity into the case file: e.g. an
    ``[outline]`` case's derived blocks and shared borders become explicit
    ``[[blocks]]`` + ``[[interfaces]]`` entries (node ranges and orientation),
    which :func:`meshcore.case.load_case` reads back to the same grid.
    """
    if mode not in MODES:
        raise InvalidInputError(f"mode must be one of {', '.join(MODES)}, got {mode!r}")
    blocks = []
    for b in topology.blocks:
        specs = {n: BorderSpec(name=v) for n, v in b.names.items() if n in BORDER_NAMES and v}
        blocks.append(
            BlockSpec(
                name=b.name,
                weights=b.weights,
                initial=b.initial,
                boundary=tuple(np.asarray(b.borders[n]) for n in BORDER_NAMES),
                borders=specs,
            )
        )
    itfs = [
        InterfaceEntry(
            a=f"{i.a.block}.{i.a.border}[{i.a.start}:{i.a.stop}]",
            b=f"{i.b.block}.{i.b.border}[{i.b.start}:{i.b.stop}]",
            reversed=bool(i.reversed),
        )
        for i in topology.interfaces
    ]
    return Case(
        blocks=tuple(blocks),
        title=title,
        description=description,
        solver=solver or SolverSpec(),
        multiblock=MultiblockSection(mode=mode),
        interfaces=tuple(itfs),
    )


def cut_case(
    outline: Any, cuts: list[Any], *, cells_across: int = 12, snap: float | None = None, title: str = ""
) -> Case:
    """An ``[outline]`` case splitting ``outline`` by ``cuts`` into a chain of blocks.

    See :func:`meshcore.multiblock.cutsplit.chain_blocks` (``cells_across`` η
    cells in every block); the outline is in model units (``crs = "xy"``).
    """
    from ..multiblock.cutsplit import chain_blocks

    ring, cut_lines, blocks = chain_blocks(outline, cuts, cells_across=cells_across, snap=snap)
    section = OutlineSection(
        points=ring,
        cuts=tuple(tuple((float(x), float(y)) for x, y in c) for c in cut_lines),
        blocks=tuple(blocks),
        crs="xy",
    )
    return Case(title=title or "split by cut lines", multiblock=MultiblockSection(mode="smooth"), outline=section)


def layout_case(layout: Any, *, title: str = "", description: str = "", crs: Any = None) -> Case:
    """An ``[outline]`` case of a :class:`~meshcore.layout.Layout` with ``[multiblock] mode =
    "orthogonal"``: the shore, the islands, every cut and each block's corners and cells, inline
    in the layout's coordinates.  ``meshcore generate`` of it gives the grid of
    :func:`meshcore.lakegrid.mesh_layout`; edit it (move a corner, change cells) and generate again.

    ``crs`` (a :class:`meshcore.crs.Frame` or ``None``) is written as the case's ``[crs]`` table,
    so the grid files say which CRS the coordinates are in.
    """
    from ..layout.outline import outline_parts

    parts = outline_parts(layout)
    section = OutlineSection(
        points=parts["outline"],
        cuts=tuple(tuple((float(x), float(y)) for x, y in c) for c in parts["cuts"]),
        blocks=tuple(
            BlockOutline(b["name"], tuple(tuple(c) for c in b["corners"]), tuple(b["cells"])) for b in parts["blocks"]
        ),
        crs="xy",
        multiple=layout.multiple,
        holes=tuple(parts["holes"]),
        cell_size=float(layout.cell_size),
        single=layout.single,
    )
    table = None
    if crs is not None and getattr(crs, "crs", None) is not None:
        table = {"crs": str(crs.crs), "origin": [float(v) for v in crs.origin]}
        if crs.source_crs is not None:
            table["source_crs"] = str(crs.source_crs)
    return Case(
        title=title or f"automatic layout: {len(layout.blocks)} blocks",
        description=description,
        multiblock=MultiblockSection(mode="orthogonal"),
        outline=section,
        crs=table,
    )
