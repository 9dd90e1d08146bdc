"""Reading case files: TOML text → :class:`~meshcore.case.model.Case`.

Every table becomes a frozen dataclass through one helper
(:func:`meshcore._tables.from_table`), so the valid keys are the dataclass
fields.  Every error is a :class:`~meshcore.errors.CaseFileError` naming the
file, the block or table and the key.
"""

from __future__ import annotations

import tomllib
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import numpy as np

from .._tables import check_keys, from_table, table_keys
from .._validation import read_file_bytes
from ..boundary import BorderSpec
from ..errors import CaseFileError, InvalidInputError, MeshcoreError
from ..grid import BORDER_NAMES
from ..multiblock.outline import BlockOutline
from ..spec import REPAIR_CHOICES, BlockSpec, SolverSpec
from .model import Case, InterfaceEntry, LakeSection, MultiblockSection, OutlineSection, outline_point

__all__ = ["load_case", "loads_case", "read_point_file", "xy_pairs"]

#: Top-level keys: the fields of :class:`Case` (``path`` is not a key).
TOP_KEYS = table_keys(Case, exclude=("path",))
#: Keys of the top-level ``crs`` table.
CRS_KEYS = {"crs", "origin", "source_crs", "source"}
#: BlockSpec fields that the ``[blocks.boundary]`` table (or nothing) sets.
_NOT_BLOCK_KEYS = ("points", "corners", "boundary", "p", "q")


# ------------------------------------------------------------------ points
def xy_pairs(value: Any, where: str) -> np.ndarray:
    """Points given inline in a case file: an ``(n, 2)`` float array, or a CaseFileError."""
    try:
        arr = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise CaseFileError(f"{where}: expected a list of [x, y] pairs or a file name") from None
    if arr.ndim != 2 or arr.shape[1] != 2:
        raise CaseFileError(f"{where}: expected a list of [x, y] pairs, got shape {arr.shape}")
    return arr


def read_point_file(path: Path, where: str) -> Any:
    """The :class:`~meshcore.io.PointSet` of a point file (CaseFileError naming ``where`` if unreadable)."""
    from ..io import read_points

    if not path.exists():
        raise CaseFileError(f"{where}: point file {str(path)!r} not found")
    try:
        ps = read_points(path)
    except MeshcoreError as exc:
        raise CaseFileError(f"{where}: {exc}") from None
    if not ps.polylines:
        raise CaseFileError(f"{where}: {path} holds no polyline")
    return ps


def _projected(path: Path, where: str, ctx: dict[str, Any]) -> np.ndarray:
    """The first polyline of a point file, projected into the case's frame.

    Lon/lat files are projected to the case's ``crs`` (and shifted by its
    origin); with no ``crs`` table the first lon/lat file picks the UTM zone of
    its centroid and a local origin, recorded in ``ctx["crs"]`` so that the
    case (and every export) keeps it.
    """
    from .. import crs as _crs

    ps = read_point_file(path, where)
    try:
        geographic = (ps.crs is not None and _crs.is_geographic(ps.crs)) or (
            ps.crs is None and _crs.looks_lonlat(ps.all_points())
        )
        frame = ctx.get("frame")
        if geographic or (frame is not None and ps.crs is not None and ps.crs != frame.crs):
            if frame is None:
                local, frame = _crs.project(ps, "auto")
                ctx["frame"] = frame
                ctx["crs"] = frame.as_dict() | {"source": path.name}
            else:
                local, _ = _crs.project(ps, frame.crs or "auto", origin=frame.origin)
            ps = local
        elif frame is not None and frame.origin != (0.0, 0.0):
            # a projected file in the case's CRS: shift to the local origin
            local, _ = _crs.project(ps, None, origin=frame.origin)
            ps = local
    except InvalidInputError as exc:
        raise CaseFileError(f"{where}: {exc}") from None
    return np.asarray(ps.polylines[0].points, dtype=np.float64)


def _points(value: Any, base: Path | None, where: str, ctx: dict[str, Any]) -> np.ndarray:
    if isinstance(value, str):
        p = Path(value)
        if not p.is_absolute() and base is not None:
            p = base / p
        return _projected(p, where, ctx)
    return xy_pairs(value, where)


# ------------------------------------------------------------------ values
def _pair(conv: Callable[[Any], Any]) -> Callable[[Any, str], tuple]:
    def read(value: Any, where: str) -> tuple:
        if not isinstance(value, (list, tuple)) or len(value) != 2:
            raise CaseFileError(f"{where}: expected a pair [a, b], got {value!r}")
        try:
            return (conv(value[0]), conv(value[1]))
        except (TypeError, ValueError):
            raise CaseFileError(f"{where}: expected a pair of numbers, got {value!r}") from None

    return read


def _int(v: Any) -> int:
    if isinstance(v, bool) or not isinstance(v, int):
        raise ValueError(v)
    return v


def _bool(value: Any, where: str) -> bool:
    if not isinstance(value, bool):
        raise CaseFileError(f"{where} must be true or false")
    return value


def _snap_angle(v: Any, where: str) -> float:
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not 0 < v < 180:
        raise CaseFileError(f"{where} must be an angle in degrees in (0, 180), got {v!r}")
    return float(v)


def _border_specs(tbl: Any, where: str) -> dict[str, BorderSpec]:
    if not isinstance(tbl, Mapping):
        raise CaseFileError(f"{where} must be a table")
    check_keys(tbl, BORDER_NAMES, where, error=CaseFileError)
    out = {}
    for n, spec in tbl.items():
        if not isinstance(spec, Mapping):
            raise CaseFileError(f"{where}.{n} must be a table")
        out[n] = from_table(BorderSpec, spec, where=f"{where}.{n}", error=CaseFileError)
    return out


def _control(tbl: Any, where: str) -> dict[str, Any]:
    from ..control import control_from_mapping

    try:
        control_from_mapping(tbl, where=where)
    except InvalidInputError as exc:
        raise CaseFileError(str(exc)) from None
    return dict(tbl)


_BLOCK_CONVERT: dict[str, Callable[[Any, str], Any]] = {
    "name": lambda v, w: str(v),
    "cells": _pair(_int),
    "weights": _pair(float),
    "initial": lambda v, w: str(v),
    "curve": lambda v, w: str(v),
    "periodic": _bool,
    "snap_angle": _snap_angle,
    "borders": _border_specs,
    "control": _control,
}


# ------------------------------------------------------------------ blocks
def _boundary(bnd: Any, base: Path | None, where: str, ctx: dict[str, Any]) -> dict[str, Any]:
    """The BlockSpec fields of a ``[blocks.boundary]`` table: points + corners, or four borders."""
    if not isinstance(bnd, Mapping):
        raise CaseFileError(f"{where}: missing [blocks.boundary] table (four borders or points + corners)")
    check_keys(bnd, {*BORDER_NAMES, "points", "corners"}, f"{where}: boundary", error=CaseFileError)
    if "points" in bnd:
        if any(n in bnd for n in BORDER_NAMES):
            raise CaseFileError(f"{where}: boundary: give either points + corners or four borders, not both")
        if "corners" not in bnd:
            raise CaseFileError(f"{where}: boundary: points need corners = [sw, se, ne, nw]")
        c = bnd["corners"]
        if not isinstance(c, list) or len(c) != 4 or not all(isinstance(v, int) and not isinstance(v, bool) for v in c):
            raise CaseFileError(f"{where}: boundary.corners must be 4 integer point indices, got {c!r}")
        return {"points": _points(bnd["points"], base, f"{where}: boundary.points", ctx), "corners": tuple(c)}
    missing = [n for n in BORDER_NAMES if n not in bnd]
    if missing:
        raise CaseFileError(f"{where}: boundary: missing border(s) {', '.join(missing)}")
    return {"boundary": tuple(_points(bnd[n], base, f"{where}: boundary.{n}", ctx) for n in BORDER_NAMES)}


def _parse_block(tbl: Any, k: int, base: Path | None, src: str, ctx: dict[str, Any]) -> BlockSpec:
    where = f"{src}: [[blocks]] #{k + 1}"
    if not isinstance(tbl, Mapping):
        raise CaseFileError(f"{where}: expected a table")
    check_keys(tbl, table_keys(BlockSpec, exclude=_NOT_BLOCK_KEYS) | {"boundary"}, where, error=CaseFileError)
    name = str(tbl.get("name", f"block{k + 1}"))
    where = f"{src}: block {name!r}"
    geometry = _boundary(tbl.get("boundary"), base, where, ctx)
    return from_table(
        BlockSpec,
        {**tbl, "name": name},
        where=where,
        error=CaseFileError,
        convert=_BLOCK_CONVERT,
        exclude=_NOT_BLOCK_KEYS,
        ignore=("boundary",),
        **geometry,
    )


def _repair(value: Any, where: str) -> str:
    if value not in REPAIR_CHOICES:
        raise CaseFileError(f"{where} must be one of {', '.join(REPAIR_CHOICES)}; got {value!r}")
    return str(value)


def _parse_solver(tbl: Any, src: str) -> SolverSpec:
    if not isinstance(tbl, Mapping):
        raise CaseFileError(f"{src}: [solver] must be a table")
    return from_table(SolverSpec, tbl, where=f"{src}: [solver]", error=CaseFileError, convert={"repair": _repair})


def _crs_frame(tbl: Any, src: str) -> Any:
    from ..crs import frame_from_table

    if not isinstance(tbl, Mapping):
        raise CaseFileError(f"{src}: crs must be a table (crs, origin, source_crs)")
    check_keys(tbl, CRS_KEYS, f"{src}: crs", error=CaseFileError)
    try:
        return frame_from_table(tbl)
    except InvalidInputError as exc:
        raise CaseFileError(f"{src}: {exc}") from None


# -------------------------------------------------------- multiblock tables
def parse_multiblock(tbl: Any, src: str) -> MultiblockSection:
    """The ``[multiblock]`` table."""
    if not isinstance(tbl, Mapping):
        raise CaseFileError(f"{src}: [multiblock] must be a table")
    return from_table(MultiblockSection, tbl, where=f"{src}: [multiblock]", error=CaseFileError)


def parse_interfaces(raw: Any, src: str) -> tuple[InterfaceEntry, ...]:
    """The ``[[interfaces]]`` tables."""
    if not isinstance(raw, list):
        raise CaseFileError(f"{src}: interfaces must be an array of tables [[interfaces]]")
    out = []
    for k, t in enumerate(raw):
        where = f"{src}: [[interfaces]] #{k + 1}"
        if isinstance(t, Mapping) and ("a" not in t or "b" not in t):
            check_keys(t, table_keys(InterfaceEntry), where, error=CaseFileError)
            raise CaseFileError(f"{where}: needs a = 'block.border' and b = 'block.border'")
        out.append(from_table(InterfaceEntry, t, where=where, error=CaseFileError, convert={"a": _str, "b": _str}))
    return tuple(out)


def _str(value: Any, where: str) -> str:
    return str(value)


def _outline_blocks(raw: Any, src: str) -> tuple[BlockOutline, ...]:
    if not isinstance(raw, list) or not raw:
        raise CaseFileError(f"{src}: [outline]: needs [[outline.blocks]] tables")
    out = []
    for k, b in enumerate(raw):
        where = f"{src}: [[outline.blocks]] #{k + 1}"
        blk = from_table(
            BlockOutline,
            b,
            where=where,
            error=CaseFileError,
            required=("name", "corners", "cells"),
            convert={"name": _str, "corners": _corners, "cells": lambda v, w: tuple(v), "initial": _str},
        )
        out.append(blk)
    return tuple(out)


def _corners(value: Any, where: str) -> tuple:
    if not isinstance(value, list) or len(value) != 4:
        raise CaseFileError(f"{where} must be 4 points (sw, se, ne, nw)")
    try:
        return tuple(outline_point(v) for v in value)
    except InvalidInputError as exc:
        raise CaseFileError(f"{where}: {exc}") from None


def _holes(value: Any, where: str, name: str = "holes") -> tuple:
    if not isinstance(value, list):
        raise CaseFileError(f"{where} {name} must be a list of rings (lists of [x, y] points)")
    return tuple(xy_pairs(r, f"{where} {name}[{k}]") for k, r in enumerate(value))


def parse_outline(tbl: Any, src: str) -> OutlineSection:
    """The ``[outline]`` table (its point file is read when the blocks are built)."""
    where = f"{src}: [outline]"
    if not isinstance(tbl, Mapping):
        raise CaseFileError(f"{where} must be a table")
    return from_table(
        OutlineSection,
        tbl,
        where=where,
        error=CaseFileError,
        required=("points", "cuts", "blocks"),
        convert={
            "points": lambda v, w: v if isinstance(v, str) else xy_pairs(v, f"{where} points"),
            "blocks": lambda v, w: _outline_blocks(v, src),
            "holes": lambda v, w: _holes(v, where),
        },
    )


def parse_lake(tbl: Any, src: str) -> LakeSection:
    """The ``[lake]`` table: the water as imported and its layout settings."""
    where = f"{src}: [lake]"
    if not isinstance(tbl, Mapping):
        raise CaseFileError(f"{where} must be a table")
    return from_table(
        LakeSection,
        tbl,
        where=where,
        error=CaseFileError,
        required=("shore",),
        convert={
            "shore": lambda v, w: xy_pairs(v, f"{where} shore"),
            "islands": lambda v, w: _holes(v, where, "islands"),
            "notes": lambda v, w: _texts(v, f"{where} notes"),
            "details": lambda v, w: _texts(v, f"{where} details"),
        },
    )


def _texts(value: Any, where: str) -> tuple[str, ...]:
    if not isinstance(value, list) or not all(isinstance(t, str) for t in value):
        raise CaseFileError(f"{where} must be a list of strings")
    return tuple(value)


# ---------------------------------------------------------------- the case
def loads_case(text: str, *, base: Path | None = None, source: str = "<case>") -> Case:
    """Parse a case from TOML text (``base`` resolves relative point files)."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise CaseFileError(f"{source}: invalid TOML: {exc}") from None
    except RecursionError:  # tomllib recurses once per nested array or inline table
        raise CaseFileError(f"{source}: invalid TOML: arrays or tables nested too deep to read") from None
    check_keys(data, TOP_KEYS, source, error=CaseFileError)
    blocks_raw = data.get("blocks")
    if "outline" in data and blocks_raw is None:
        blocks_raw = []  # multiblock outline cases list their blocks in [[outline.blocks]]
    elif not isinstance(blocks_raw, list) or not blocks_raw:
        raise CaseFileError(f"{source}: needs at least one [[blocks]] table")
    ctx: dict[str, Any] = {}
    if "crs" in data:
        ctx["frame"] = _crs_frame(data["crs"], source)
    blocks = tuple(_parse_block(b, k, base, source, ctx) for k, b in enumerate(blocks_raw))
    names = [b.name for b in blocks]
    dup = {n for n in names if names.count(n) > 1}
    if dup:
        raise CaseFileError(f"{source}: block name {sorted(dup)[0]!r} is used twice")
    crs = data.get("crs", ctx.get("crs"))
    case = Case(
        blocks=blocks,
        title=str(data.get("title", "")),
        description=str(data.get("description", "")),
        solver=_parse_solver(data.get("solver", {}), source),
        crs=dict(crs) if crs is not None else None,
        multiblock=parse_multiblock(data["multiblock"], source) if "multiblock" in data else None,
        interfaces=parse_interfaces(data.get("interfaces", []), source),
        outline=parse_outline(data["outline"], source) if "outline" in data else None,
        lake=parse_lake(data["lake"], source) if "lake" in data else None,
    )
    if case.settings.mode == "orthogonal" and case.outline is None:
        raise CaseFileError(f'{source}: [multiblock] mode = "orthogonal" needs an [outline] section (the shore)')
    if case.outline is not None and case.blocks:
        raise CaseFileError(f"{source}: an [outline] case defines its blocks in [[outline.blocks]]; remove [[blocks]]")
    return case


def load_case(path: str | Path) -> Case:
    """Read a case file.

    Raises
    ------
    CaseFileError
        Missing file, invalid TOML, unknown keys, bad values (the message names
        the file, the block and the key).
    """
    p = Path(path)
    try:  # a regular file of at most MESHCORE_MAX_BYTES (a fifo or /dev/zero would be read for ever)
        raw = read_file_bytes(p, error=CaseFileError)
        # an editor may save a byte order mark (Notepad: UTF-8 or "Unicode", UTF-16): TOML is UTF-8 without
        text = raw.decode("utf-16") if raw[:2] in (b"\xff\xfe", b"\xfe\xff") else raw.decode("utf-8-sig")
    except FileNotFoundError:
        raise CaseFileError(f"{p}: case file not found") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise CaseFileError(f"{p}: cannot read case file ({exc})") from None
    return loads_case(text, base=p.parent, source=str(p)).replaced(path=p)
