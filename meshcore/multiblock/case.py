r"""Multiblock case files: ``[multiblock]``, ``[[interfaces]]`` and ``[outline]``.

Registered with :mod:`meshcore.case` (extra top-level keys and a case
generator), so ``meshcore generate`` handles multiblock cases.  Two ways to
describe the blocks:

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

    [[outline.blocks]]
    name = "main"
    corners = [15, 35, 99, 200]  # sw, se, ne, nw: outline indices or points
    cells = [48, 13]

Unknown keys are :class:`~meshcore.errors.CaseFileError` naming the key and
the valid ones.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from ..boundary import BorderSpec
from ..case import (
    BlockCase,
    Case,
    _check_keys,
    register_case_generator,
    register_keys,
    xy_pairs,
)
from ..elliptic import EllipticConfig
from ..errors import CaseFileError, InvalidInputError
from ..grid import BORDER_NAMES
from .outline import from_outline, project_lonlat
from .solver import MODES, MultiBlockGrid, solve_multiblock
from .topology import Block, Interface, MultiBlockTopology, parse_side

__all__ = [
    "case_frame",
    "case_topology",
    "generate_multiblock_case",
    "is_multiblock_case",
    "outline_points",
    "topology_case",
]

MULTIBLOCK_KEYS = {"mode", "start"}
INTERFACE_KEYS = {"a", "b", "reversed"}
OUTLINE_KEYS = {"points", "crs", "origin", "cuts", "snap", "multiple", "blocks"}
OUTLINE_BLOCK_KEYS = {"name", "corners", "cells", "initial"}
#: ``crs`` of an outline: no projection, local equirectangular, UTM of the centroid (pyproj);
#: any other value is a target CRS for pyproj (``"EPSG:32610"``, ``32610``).
OUTLINE_CRS = ("xy", "none", "lonlat", "utm", "auto")

register_keys(top=("multiblock", "interfaces", "outline"))


def is_multiblock_case(case: Case) -> bool:
    return any(k in case.extra for k in ("multiblock", "interfaces", "outline"))


def _src(case: Case) -> str:
    return str(case.path) if case.path else "<case>"


def _settings(case: Case) -> tuple[str, str]:
    src = _src(case)
    mb = case.extra.get("multiblock", {})
    if not isinstance(mb, Mapping):
        raise CaseFileError(f"{src}: [multiblock] must be a table")
    _check_keys(mb, MULTIBLOCK_KEYS, f"{src}: [multiblock]")
    mode = str(mb.get("mode", "smooth"))
    if mode not in MODES:
        raise CaseFileError(f"{src}: [multiblock] mode must be one of {', '.join(MODES)}, got {mode!r}")
    start = str(mb.get("start", "algebraic"))
    if start not in ("frozen", "algebraic"):
        raise CaseFileError(f"{src}: [multiblock] start must be frozen or algebraic, got {start!r}")
    return mode, start


def _outline_point(v: Any, where: str) -> Any:
    if isinstance(v, int) and not isinstance(v, bool):
        return v
    if isinstance(v, list) and len(v) == 2 and all(isinstance(e, (int, float)) for e in v):
        return [float(e) for e in v]
    raise CaseFileError(f"{where}: expected an outline point index or an [x, y] pair, got {v!r}")


def _read_outline(value: Any, base: Any, where: str) -> tuple[np.ndarray, Any]:
    """The outline points as given (no projection) and their CRS (None if unknown)."""
    if isinstance(value, str):
        from pathlib import Path

        from ..errors import MeshcoreError
        from ..io import read_points

        p = Path(value)
        if not p.is_absolute() and base is not None:
            p = base / p
        if not p.exists():
            raise CaseFileError(f"{where}: point file {str(p)!r} not found")
        try:
            ps = read_points(p)
        except MeshcoreError as exc:
            raise CaseFileError(f"{where}: {exc}") from None
        if not ps.polylines:
            raise CaseFileError(f"{where}: {p} holds no polyline")
        return np.asarray(ps.polylines[0].points, dtype=np.float64), ps.crs
    return xy_pairs(value, where), None


def _project_outline(pts: np.ndarray, extra: list, crs: Any, origin: Any, where: str, src_crs: Any, case_frame: Any):
    """Project the outline and the extra points; return (xy, extra_xy, frame)."""
    from ..crs import LONLAT, Frame, _pyproj, project
    from ..io._base import PointSet, Polyline

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
    ps = PointSet((Polyline("outline", pts, closed=True),), src_crs or LONLAT, source=where)
    try:
        local, frame = project(ps, target, origin="auto" if origin is None else origin)
    except InvalidInputError as exc:
        raise CaseFileError(f"{where}: {exc}") from None
    ex = np.zeros((0, 2))
    if extra:
        e = np.asarray(extra, dtype=np.float64)
        if frame.crs != frame.source_crs:
            t = _pyproj().Transformer.from_crs(frame.source_crs, frame.crs, always_xy=True)
            X, Y = t.transform(e[:, 0], e[:, 1])
            e = np.column_stack([X, Y])
        ex = e - np.asarray(frame.origin)
    return local.polylines[0].points, ex, frame


def _outline_geometry(case: Case) -> tuple[np.ndarray, list, list, Any, Any]:
    """(outline xy, cuts, blocks, snap, frame) of an ``[outline]`` case, in model units."""
    src = _src(case)
    base = case.path.parent if case.path else None
    tbl = case.extra["outline"]
    where = f"{src}: [outline]"
    if not isinstance(tbl, Mapping):
        raise CaseFileError(f"{where} must be a table")
    _check_keys(tbl, OUTLINE_KEYS, where)
    if case.blocks:
        raise CaseFileError(f"{src}: an [outline] case defines its blocks in [[outline.blocks]]; remove [[blocks]]")
    for key in ("points", "cuts", "blocks"):
        if key not in tbl:
            raise CaseFileError(f"{where}: missing key {key!r}")
    pts, src_crs = _read_outline(tbl["points"], base, f"{where} points")
    crs = tbl.get("crs", "auto")
    if isinstance(crs, bool) or not isinstance(crs, (str, int)):
        raise CaseFileError(f"{where}: crs must be a string or an EPSG code, got {crs!r}")
    if isinstance(crs, str):
        crs = crs.strip().lower() if crs.strip().lower() in OUTLINE_CRS else crs.strip()
    cuts_raw = tbl["cuts"]
    if not isinstance(cuts_raw, list) or not cuts_raw:
        raise CaseFileError(f"{where}: cuts must be a list of polylines")
    cuts = []
    for k, c in enumerate(cuts_raw):
        if not isinstance(c, list) or len(c) < 2:
            raise CaseFileError(f"{where}: cut {k} must list at least two points")
        cuts.append([_outline_point(v, f"{where}: cut {k}") for v in c])
    blocks_raw = tbl["blocks"]
    if not isinstance(blocks_raw, list) or not blocks_raw:
        raise CaseFileError(f"{where}: needs [[outline.blocks]] tables")
    blocks = []
    for k, b in enumerate(blocks_raw):
        bw = f"{src}: [[outline.blocks]] #{k + 1}"
        if not isinstance(b, Mapping):
            raise CaseFileError(f"{bw}: expected a table")
        _check_keys(b, OUTLINE_BLOCK_KEYS, bw)
        for key in ("name", "corners", "cells"):
            if key not in b:
                raise CaseFileError(f"{bw}: missing key {key!r}")
        corners = b["corners"]
        if not isinstance(corners, list) or len(corners) != 4:
            raise CaseFileError(f"{bw}: corners must be 4 points (sw, se, ne, nw)")
        blocks.append(
            {
                "name": str(b["name"]),
                "corners": [_outline_point(v, f"{bw}: corners") for v in corners],
                "cells": list(b["cells"]),
                "initial": str(b.get("initial", "tfi")),
            }
        )
    from ..crs import frame_from_case, is_geographic, looks_lonlat

    frame = None
    # like [[blocks]] point files: a lon/lat *file* is projected by default; inline points
    # only with an explicit crs
    geographic = isinstance(tbl["points"], str) and (
        (src_crs is not None and is_geographic(src_crs)) or (src_crs is None and looks_lonlat(pts))
    )
    if crs not in ("xy", "none") and (crs != "auto" or geographic):
        extra = [v for c in cuts for v in c if not isinstance(v, int)]
        extra += [v for b in blocks for v in b["corners"] if not isinstance(v, int)]
        xy, ex, frame = _project_outline(pts, extra, crs, tbl.get("origin"), where, src_crs, frame_from_case(case))
        it = iter(ex.tolist())
        cuts = [[v if isinstance(v, int) else next(it) for v in c] for c in cuts]
        for b in blocks:
            b["corners"] = [v if isinstance(v, int) else next(it) for v in b["corners"]]
    else:
        xy = pts
    return xy, cuts, blocks, tbl.get("snap"), frame


def outline_points(case: Case) -> np.ndarray:
    """The outline of an ``[outline]`` case in model units (projected like the grid)."""
    return _outline_geometry(case)[0]


def case_frame(case: Case) -> Any:
    """The :class:`meshcore.crs.Frame` of a case's grid coordinates (None if unknown)."""
    from ..crs import frame_from_case

    if "outline" in case.extra:
        fr = _outline_geometry(case)[4]
        if fr is not None and fr.crs is not None:
            return fr
    return frame_from_case(case)


def _outline_topology(case: Case) -> MultiBlockTopology:
    xy, cuts, blocks, snap, _ = _outline_geometry(case)
    multiple = case.extra["outline"].get("multiple", 1)
    if isinstance(multiple, bool) or not isinstance(multiple, int) or multiple < 1:
        raise CaseFileError(f"{_src(case)}: [outline] multiple must be a positive integer")
    try:
        return from_outline(xy, cuts=cuts, blocks=blocks, snap=snap, multiple=multiple).topology
    except InvalidInputError as exc:
        raise type(exc)(f"{_src(case)}: {exc}") from None


def _interface_topology(case: Case) -> MultiBlockTopology:
    from ..generate import prepare_borders

    src = _src(case)
    raw = case.extra.get("interfaces", [])
    if not isinstance(raw, list):
        raise CaseFileError(f"{src}: interfaces must be an array of tables [[interfaces]]")
    blocks = []
    for b in case.blocks:
        kw = b.generate_kwargs()
        kw.pop("weights")
        kw.pop("initial")
        try:
            bd = prepare_borders(**kw, where=f"block {b.name!r}")
        except InvalidInputError as exc:
            raise type(exc)(f"{src}: {exc}") from None
        names = {k: s.name for k, s in b.border_specs.items() if s.name}
        blocks.append(Block(b.name, bd, initial=b.initial, weights=b.weights, names=names))
    itfs = []
    for k, t in enumerate(raw):
        where = f"{src}: [[interfaces]] #{k + 1}"
        if not isinstance(t, Mapping):
            raise CaseFileError(f"{where}: expected a table")
        _check_keys(t, INTERFACE_KEYS, where)
        if "a" not in t or "b" not in t:
            raise CaseFileError(f"{where}: needs a = 'block.border' and b = 'block.border'")
        rev = t.get("reversed")
        if rev is not None and not isinstance(rev, bool):
            raise CaseFileError(f"{where}: reversed must be true or false")
        try:
            itfs.append(Interface(parse_side(str(t["a"])), parse_side(str(t["b"])), rev))
        except InvalidInputError as exc:
            raise type(exc)(f"{where}: {exc}") from None
    try:
        return MultiBlockTopology(tuple(blocks), tuple(itfs))
    except InvalidInputError as exc:
        raise type(exc)(f"{src}: {exc}") from None


def case_topology(case: Case) -> MultiBlockTopology:
    """The validated topology of a multiblock case."""
    _settings(case)
    if "outline" in case.extra:
        return _outline_topology(case)
    return _interface_topology(case)


def generate_multiblock_case(
    case: Case,
    *,
    callback: Callable[..., Any] | None = None,
    config: EllipticConfig | None = None,
) -> MultiBlockGrid:
    """Generate a multiblock case (the hook :func:`meshcore.case.generate_case` calls)."""
    del callback  # progress snapshots are per block; the multiblock solve reports at the end
    mode, start = _settings(case)
    topo = case_topology(case)
    mb = solve_multiblock(topo, mode=mode, start=start, config=config or case.solver)
    return dataclasses.replace(mb, frame=case_frame(case))


def topology_case(
    topology: MultiBlockTopology,
    *,
    mode: str = "smooth",
    title: str = "",
    description: str = "",
    solver: EllipticConfig | None = None,
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
            BlockCase(
                name=b.name,
                cells=None,
                weights=tuple(b.weights),
                initial=b.initial,
                borders={n: np.asarray(b.borders[n]) for n in BORDER_NAMES},
                border_specs=specs,
            )
        )
    itfs = [
        {
            "a": f"{i.a.block}.{i.a.border}[{i.a.start}:{i.a.stop}]",
            "b": f"{i.b.block}.{i.b.border}[{i.b.start}:{i.b.stop}]",
            "reversed": bool(i.reversed),
        }
        for i in topology.interfaces
    ]
    return Case(
        blocks=tuple(blocks),
        title=title,
        description=description,
        solver=solver or EllipticConfig(),
        extra={"multiblock": {"mode": mode}, "interfaces": itfs},
    )


register_case_generator(is_multiblock_case, generate_multiblock_case)
