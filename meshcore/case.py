r"""Case files: a documented TOML format for one or more blocks.

A case file describes everything needed to generate a grid.  Paths inside it
are relative to the case file.  Unknown keys are errors that name the key and
list the valid ones.  Example (the paper's bottle, refinement 1)::

    title = "Bottle (paper, refinement 1)"

    [solver]                      # optional; fields of meshcore.EllipticConfig
    method = "auto"               # auto | sor | multigrid | foldfree
    repair = "auto"               # auto | strict | off: fold-free repair of invalid cells
    tolerance = 1e-6              # relative to the bounding-box diagonal (omit: scale-aware default)
    max_iterations = 50000

    [[blocks]]
    name = "bottle"
    cells = [6, 15]               # ni × nj cells (omit: the given points are the nodes)
    weights = [1.0, 0.5]          # paper eq. 34: p13_x, p13_y (left/right weight; p24 = 1 − p13)
    initial = "weighted"          # weighted (paper) | tfi
    curve = "linear"              # linear (paper) | cubic | catmull-rom
    periodic = false              # true: O-grid, left = right is a seam solved like the interior
    snap_angle = 30               # optional: input vertices turning > 30° get a node exactly

    [blocks.boundary]             # either four borders (inline points or a point-file name) ...
    bottom = [[-3.0, 0.0], [-1.0, 0.0], [1.0, 0.0], [3.0, 0.0]]
    right  = [[3.0, 0.0], ..., [1.1, 8.0]]
    top    = [[-1.1, 8.0], ..., [1.1, 8.0]]
    left   = [[-3.0, 0.0], ..., [-1.1, 8.0]]
    # ... or a closed loop plus four corner indices (sw, se, ne, nw):
    # points = "shore.csv"        # or inline [[x, y], ...]
    # corners = [0, 40, 90, 130]

    [blocks.borders.bottom]       # optional, per border: distribution and a name
    distribution = "tanh"         # uniform | tanh | vinokur
    first = 0.05                  # absolute first spacing (model units)
    last = 0.05                   # absolute last spacing
    name = "wall"                 # boundary-condition name carried to exports

    [blocks.control]              # optional grid control (meshcore.control)
    kind = "hilgenstock-white"    # or "steger-sorenson" (Taylor targets + feedback)
    thomas-middlecoff = false     # interior follows the boundary point distribution
    relaxation = 0.1              # under-relaxation of the boundary sources
    floating = []                 # borders whose nodes slide along the boundary curve
    attractors = [{ kind = "xi", xi = 0.5, amplitude = 0.2, decay = 0.3 }]
    [blocks.control.borders]      # per wall: first-cell height and angle (degrees)
    bottom = { spacing = 0.05, angle = 90 }

Other features add their own tables (``[[interfaces]]``/``[multiblock]``
multiblock, ``crs``); they register their keys with :func:`register_keys` so
that validation stays strict.
"""

from __future__ import annotations

import dataclasses
import math
import tomllib
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .boundary import BorderSpec
from .elliptic import EllipticConfig
from .errors import CaseFileError, InvalidInputError, MeshcoreError
from .grid import BORDER_NAMES, StructuredGrid

__all__ = [
    "BlockCase",
    "Case",
    "generate_case",
    "load_case",
    "loads_case",
    "register_keys",
    "save_case",
]

TOP_KEYS = {"title", "description", "solver", "blocks", "crs"}
CRS_KEYS = {"crs", "origin", "source_crs", "source"}
BLOCK_KEYS = {
    "name",
    "cells",
    "weights",
    "initial",
    "curve",
    "periodic",
    "snap_angle",
    "boundary",
    "borders",
    "control",
}
BOUNDARY_KEYS = {"bottom", "right", "top", "left", "points", "corners"}
BORDER_KEYS = {"distribution", "first", "last", "name"}
SOLVER_KEYS = {f.name for f in dataclasses.fields(EllipticConfig)} | {"repair"}
REPAIR_CHOICES = ("auto", "strict", "off")

#: Extension hooks: extra top-level / per-block keys registered by other modules.
_EXTRA_TOP: set[str] = set()
_EXTRA_BLOCK: set[str] = set()


def register_keys(*, top: Sequence[str] = (), block: Sequence[str] = ()) -> None:
    """Allow extra top-level or per-block keys (kept raw in ``extra``)."""
    _EXTRA_TOP.update(top)
    _EXTRA_BLOCK.update(block)


@dataclass(frozen=True, eq=False)
class BlockCase:
    """One block of a case: boundary, counts, weights and per-border options."""

    name: str = "block"
    cells: tuple[int, int] | None = None
    weights: tuple[float, float] = (0.5, 0.5)
    initial: str = "weighted"
    curve: str = "linear"
    periodic: bool = False
    snap_angle: float | None = None
    borders: Mapping[str, np.ndarray] | None = None  # four polylines
    loop: np.ndarray | None = None  # or a closed loop ...
    corners: tuple[int, int, int, int] | None = None  # ... with corners (sw, se, ne, nw)
    border_specs: Mapping[str, BorderSpec] = field(default_factory=dict)
    control: Mapping[str, Any] | None = None  # [blocks.control] table (meshcore.control)
    extra: Mapping[str, Any] = field(default_factory=dict)

    def replaced(self, **kw: Any) -> BlockCase:
        return dataclasses.replace(self, **kw)

    def generate_kwargs(self) -> dict[str, Any]:
        kw: dict[str, Any] = {
            "cells": self.cells,
            "weights": self.weights,
            "initial": self.initial,
            "curve": self.curve,
            "periodic": self.periodic,
            "snap_angle": self.snap_angle,
            "borders": {
                k: {kk: vv for kk, vv in dataclasses.asdict(v).items() if vv is not None}
                for k, v in self.border_specs.items()
            },
        }
        if self.control is not None:
            kw["control"] = self.control
        if self.loop is not None:
            kw["loop"] = self.loop
            kw["corners"] = self.corners
        else:
            assert self.borders is not None
            for n in BORDER_NAMES:
                kw[n] = self.borders[n]
        return kw


@dataclass(frozen=True, eq=False)
class Case:
    """A whole case: title, blocks and solver settings."""

    blocks: tuple[BlockCase, ...]
    title: str = ""
    description: str = ""
    solver: EllipticConfig = field(default_factory=EllipticConfig)
    repair: str = "auto"
    path: Path | None = None
    extra: Mapping[str, Any] = field(default_factory=dict)

    def replaced(self, **kw: Any) -> Case:
        return dataclasses.replace(self, **kw)


# ---------------------------------------------------------------- parsing ---
def _check_keys(table: Mapping[str, Any], valid: set[str], where: str) -> None:
    unknown = [k for k in table if k not in valid]
    if unknown:
        raise CaseFileError(f"{where}: unknown key {unknown[0]!r}; valid keys: {', '.join(sorted(valid))}")


def _read_point_file(path: Path, where: str, ctx: dict[str, Any]) -> np.ndarray:
    """Read the first polyline of a point file, projected into the case's frame.

    Lon/lat files are projected to the case's ``crs`` (and shifted by its
    origin); with no ``crs`` table the first lon/lat file picks the UTM zone of
    its centroid and a local origin, recorded in ``ctx["crs"]`` so that the
    case (and every export) keeps it.
    """
    if not path.exists():
        raise CaseFileError(f"{where}: point file {str(path)!r} not found")
    from . import crs as _crs
    from . import io as _io

    try:
        ps = _io.read_points(path)
        if not ps.polylines:
            raise CaseFileError(f"{where}: {path} holds no polyline")
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
    except MeshcoreError as exc:
        if isinstance(exc, CaseFileError):
            raise
        raise CaseFileError(f"{where}: {exc}") from None
    return np.asarray(ps.polylines[0].points, dtype=np.float64)


def _points(value: Any, base: Path | None, where: str, ctx: dict[str, Any]) -> np.ndarray:
    if isinstance(value, str):
        p = Path(value)
        if not p.is_absolute() and base is not None:
            p = base / p
        return _read_point_file(p, where, ctx)
    return xy_pairs(value, where)


def xy_pairs(value: Any, where: str) -> np.ndarray:
    """Points given inline in a case file: an ``(n, 2)`` float array, or a CaseFileError."""
    try:
        arr = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise CaseFileError(f"{where}: expected a list of [x, y] pairs or a file name") from None
    if arr.ndim != 2 or arr.shape[1] != 2:
        raise CaseFileError(f"{where}: expected a list of [x, y] pairs, got shape {arr.shape}")
    return arr


def _pair(value: Any, where: str, conv: Callable[[Any], Any]) -> tuple:
    if not isinstance(value, (list, tuple)) or len(value) != 2:
        raise CaseFileError(f"{where}: expected a pair [a, b], got {value!r}")
    try:
        return (conv(value[0]), conv(value[1]))
    except (TypeError, ValueError):
        raise CaseFileError(f"{where}: expected a pair of numbers, got {value!r}") from None


def _int(v: Any) -> int:
    if isinstance(v, bool) or not isinstance(v, int):
        raise ValueError(v)
    return v


def _parse_block(tbl: Mapping[str, Any], k: int, base: Path | None, src: str, ctx: dict[str, Any]) -> BlockCase:
    where = f"{src}: [[blocks]] #{k + 1}"
    if not isinstance(tbl, Mapping):
        raise CaseFileError(f"{where}: expected a table")
    _check_keys(tbl, BLOCK_KEYS | _EXTRA_BLOCK, where)
    name = str(tbl.get("name", f"block{k + 1}"))
    where = f"{src}: block {name!r}"
    kw: dict[str, Any] = {"name": name}
    if "cells" in tbl:
        kw["cells"] = _pair(tbl["cells"], f"{where}: cells", _int)
    if "weights" in tbl:
        kw["weights"] = _pair(tbl["weights"], f"{where}: weights", float)
    for key in ("initial", "curve"):
        if key in tbl:
            kw[key] = str(tbl[key])
    if "periodic" in tbl:
        if not isinstance(tbl["periodic"], bool):
            raise CaseFileError(f"{where}: periodic must be true or false")
        kw["periodic"] = tbl["periodic"]
    if "snap_angle" in tbl:
        v = tbl["snap_angle"]
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not 0 < v < 180:
            raise CaseFileError(f"{where}: snap_angle must be an angle in degrees in (0, 180), got {v!r}")
        kw["snap_angle"] = float(v)
    bnd = tbl.get("boundary")
    if not isinstance(bnd, Mapping):
        raise CaseFileError(f"{where}: missing [blocks.boundary] table (four borders or points + corners)")
    _check_keys(bnd, BOUNDARY_KEYS, f"{where}: boundary")
    if "points" in bnd:
        if any(n in bnd for n in BORDER_NAMES):
            raise CaseFileError(f"{where}: boundary: give either points + corners or four borders, not both")
        if "corners" not in bnd:
            raise CaseFileError(f"{where}: boundary: points need corners = [sw, se, ne, nw]")
        kw["loop"] = _points(bnd["points"], base, f"{where}: boundary.points", ctx)
        c = bnd["corners"]
        if not isinstance(c, list) or len(c) != 4 or not all(isinstance(v, int) and not isinstance(v, bool) for v in c):
            raise CaseFileError(f"{where}: boundary.corners must be 4 integer point indices, got {c!r}")
        kw["corners"] = tuple(c)
    else:
        missing = [n for n in BORDER_NAMES if n not in bnd]
        if missing:
            raise CaseFileError(f"{where}: boundary: missing border(s) {', '.join(missing)}")
        kw["borders"] = {n: _points(bnd[n], base, f"{where}: boundary.{n}", ctx) for n in BORDER_NAMES}
    specs = {}
    borders_tbl = tbl.get("borders", {})
    if not isinstance(borders_tbl, Mapping):
        raise CaseFileError(f"{where}: borders must be a table")
    _check_keys(borders_tbl, set(BORDER_NAMES), f"{where}: borders")
    for n, spec in borders_tbl.items():
        if not isinstance(spec, Mapping):
            raise CaseFileError(f"{where}: borders.{n} must be a table")
        _check_keys(spec, BORDER_KEYS, f"{where}: borders.{n}")
        try:
            specs[n] = BorderSpec(**dict(spec))
        except InvalidInputError as exc:
            raise CaseFileError(f"{where}: borders.{n}: {exc}") from None
        except TypeError as exc:
            raise CaseFileError(f"{where}: borders.{n}: {exc}") from None
    kw["border_specs"] = specs
    if "control" in tbl:
        from .control import control_from_mapping

        try:
            control_from_mapping(tbl["control"], where=f"{where}: control")
        except InvalidInputError as exc:
            raise CaseFileError(str(exc)) from None
        kw["control"] = dict(tbl["control"])
    kw["extra"] = {k2: tbl[k2] for k2 in _EXTRA_BLOCK if k2 in tbl}
    return BlockCase(**kw)


def loads_case(text: str, *, base: Path | None = None, source: str = "<case>") -> Case:
    """Parse a case from TOML text (``base`` resolves relative point files)."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise CaseFileError(f"{source}: invalid TOML: {exc}") from None
    _check_keys(data, TOP_KEYS | _EXTRA_TOP, source)
    blocks_raw = data.get("blocks")
    if "outline" in data and blocks_raw is None:
        blocks_raw = []  # multiblock outline cases list their blocks in [[outline.blocks]]
    elif not isinstance(blocks_raw, list) or not blocks_raw:
        raise CaseFileError(f"{source}: needs at least one [[blocks]] table")
    ctx: dict[str, Any] = {}
    if "crs" in data:
        tbl = data["crs"]
        if not isinstance(tbl, Mapping):
            raise CaseFileError(f"{source}: crs must be a table (crs, origin, source_crs)")
        _check_keys(tbl, CRS_KEYS, f"{source}: crs")
        from .crs import frame_from_case

        try:
            ctx["frame"] = frame_from_case(Case(blocks=(), extra={"crs": dict(tbl)}))
        except InvalidInputError as exc:
            raise CaseFileError(f"{source}: {exc}") from None
    blocks = tuple(_parse_block(b, k, base, source, ctx) for k, b in enumerate(blocks_raw))
    names = [b.name for b in blocks]
    dup = {n for n in names if names.count(n) > 1}
    if dup:
        raise CaseFileError(f"{source}: block name {sorted(dup)[0]!r} is used twice")
    solver_tbl = data.get("solver", {})
    if not isinstance(solver_tbl, Mapping):
        raise CaseFileError(f"{source}: [solver] must be a table")
    _check_keys(solver_tbl, SOLVER_KEYS, f"{source}: [solver]")
    solver_tbl = dict(solver_tbl)
    repair = solver_tbl.pop("repair", "auto")
    if repair not in REPAIR_CHOICES:
        raise CaseFileError(f"{source}: [solver]: repair must be one of {', '.join(REPAIR_CHOICES)}; got {repair!r}")
    try:
        solver = EllipticConfig(**solver_tbl)
    except InvalidInputError as exc:
        raise CaseFileError(f"{source}: [solver]: {exc}") from None
    return Case(
        blocks=blocks,
        title=str(data.get("title", "")),
        description=str(data.get("description", "")),
        solver=solver,
        repair=repair,
        path=None,
        extra={k: data[k] for k in (_EXTRA_TOP | {"crs"}) if k in data} | ({"crs": ctx["crs"]} if "crs" in ctx else {}),
    )


def load_case(path: str | Path) -> Case:
    """Read a case file.

    Raises
    ------
    CaseFileError
        Missing file, invalid TOML, unknown keys, bad values (the message names
        the file, the block and the key).
    """
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise CaseFileError(f"{p}: case file not found") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise CaseFileError(f"{p}: cannot read case file ({exc})") from None
    case = loads_case(text, base=p.parent, source=str(p))
    return case.replaced(path=p)


# ---------------------------------------------------------------- writing ---
def _clean(v: Any) -> Any:
    if isinstance(v, np.ndarray):
        return [_clean(r) for r in v.tolist()]
    if isinstance(v, (list, tuple)):
        return [_clean(r) for r in v]
    if isinstance(v, Mapping):
        return {str(k): _clean(vv) for k, vv in v.items() if vv is not None}
    if isinstance(v, (np.floating, float)):
        f = float(v)
        if not math.isfinite(f):
            raise CaseFileError(f"cannot save a non-finite number ({f}) in a case file")
        return f
    if isinstance(v, np.integer):
        return int(v)
    return v


def case_to_dict(case: Case) -> dict[str, Any]:
    """The TOML-ready dictionary of a case (inverse of :func:`loads_case`)."""
    out: dict[str, Any] = {}
    if case.title:
        out["title"] = case.title
    if case.description:
        out["description"] = case.description
    default = EllipticConfig()
    solver = {
        f.name: getattr(case.solver, f.name)
        for f in dataclasses.fields(EllipticConfig)
        if getattr(case.solver, f.name) != getattr(default, f.name)
    }
    if case.repair != "auto":
        solver["repair"] = case.repair
    if solver:
        out["solver"] = solver
    blocks = []
    for b in case.blocks:
        t: dict[str, Any] = {"name": b.name}
        if b.cells is not None:
            t["cells"] = list(b.cells)
        t["weights"] = list(b.weights)
        t["initial"] = b.initial
        t["curve"] = b.curve
        if b.periodic:
            t["periodic"] = True
        if b.snap_angle is not None:
            t["snap_angle"] = b.snap_angle
        if b.loop is not None:
            t["boundary"] = {"points": b.loop, "corners": list(b.corners or ())}
        else:
            t["boundary"] = {n: b.borders[n] for n in BORDER_NAMES}  # type: ignore[index]
        if b.border_specs:
            t["borders"] = {n: dataclasses.asdict(s) for n, s in b.border_specs.items()}
        if b.control is not None:
            t["control"] = dict(b.control)
        t.update(b.extra)
        blocks.append(t)
    out.update(case.extra)
    if blocks:
        out["blocks"] = blocks
    return _clean(out)


def _toml_key(k: str) -> str:
    import re

    return k if re.fullmatch(r"[A-Za-z0-9_-]+", k) else _toml_value(k)


def _toml_value(v: Any) -> str:
    import json

    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v, ensure_ascii=False)
    if isinstance(v, list):
        if v and all(isinstance(e, list) and len(e) == 2 for e in v):
            # point lists: one [x, y] pair per line
            return "[\n" + "".join(f"    {_toml_value(e)},\n" for e in v) + "]"
        return "[" + ", ".join(_toml_value(e) for e in v) + "]"
    if isinstance(v, Mapping):
        return "{ " + ", ".join(f"{_toml_key(k)} = {_toml_value(e)}" for k, e in v.items()) + " }"
    raise CaseFileError(f"cannot save value {v!r} in a case file")


def _toml_table(d: Mapping[str, Any], prefix: str, out: list[str]) -> None:
    def is_table_array(v: Any) -> bool:
        return isinstance(v, list) and bool(v) and all(isinstance(e, Mapping) for e in v)

    scalars = {k: v for k, v in d.items() if not isinstance(v, Mapping) and not is_table_array(v)}
    for k, v in scalars.items():
        out.append(f"{_toml_key(k)} = {_toml_value(v)}")
    for k, v in d.items():
        if k in scalars:
            continue
        name = f"{prefix}.{_toml_key(k)}" if prefix else _toml_key(k)
        if isinstance(v, Mapping):
            out.append(f"\n[{name}]")
            _toml_table(v, name, out)
        else:
            for e in v:
                out.append(f"\n[[{name}]]")
                _toml_table(e, name, out)


def dumps_case(case: Case) -> str:
    """TOML text of a case: compact, one point per line, readable by :func:`loads_case`."""
    out: list[str] = ["# gcmesh case file (format: meshcore/case.py)"]
    _toml_table(case_to_dict(case), "", out)
    return "\n".join(out).strip() + "\n"


def save_case(case: Case, path: str | Path) -> Path:
    """Write ``case`` as TOML (atomically: temporary file, then rename)."""
    from .io import atomic_write_text

    p = Path(path)
    atomic_write_text(p, dumps_case(case))
    return p


# ------------------------------------------------------------- generation ---
#: Hook for multiblock cases: fn(case, callback) -> result, used when it claims the case.
_CASE_GENERATORS: list[tuple[Callable[[Case], bool], Callable[..., Any]]] = []


def register_case_generator(claims: Callable[[Case], bool], fn: Callable[..., Any]) -> None:
    _CASE_GENERATORS.append((claims, fn))


def generate_case(
    case: Case, *, callback: Callable[..., Any] | None = None, config: EllipticConfig | None = None
) -> list[StructuredGrid]:
    """Generate every block of ``case`` (independently, unless a multiblock hook claims it)."""
    from .generate import generate_block

    for claims, fn in _CASE_GENERATORS:
        if claims(case):
            return fn(case, callback=callback, config=config)
    cfg = config or case.solver
    grids = []
    for b in case.blocks:
        src = str(case.path) if case.path else "<case>"
        try:
            g = generate_block(**b.generate_kwargs(), config=cfg, callback=callback, repair=case.repair)
        except CaseFileError:
            raise
        except InvalidInputError as exc:
            raise type(exc)(f"{src}: block {b.name!r}: {exc}") from None
        grids.append(g)
    return grids


# Multiblock cases ([multiblock], [[interfaces]], [outline]) register their keys
# and generator on import.
from .multiblock import case as _multiblock_case  # noqa: E402, F401
