"""Writing case files: :class:`~meshcore.case.model.Case` → TOML text (read back by :func:`loads_case`)."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import CaseFileError
from ..grid import BORDER_NAMES
from ..spec import BlockSpec, SolverSpec
from .model import Case, OutlineSection

__all__ = ["case_to_dict", "dumps_case", "save_case"]


def _clean(v: Any) -> Any:
    if isinstance(v, np.ndarray):
        if v.dtype.kind == "f":  # a point array: checked and converted whole (10^5 points in ms)
            bad = ~np.isfinite(v)
            if bad.any():
                _clean(float(v[bad].flat[0]))  # the error, naming the value
            return v.tolist()
        if v.dtype.kind in "iub":
            return v.tolist()
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


def _changed(obj: Any, default: Any) -> dict[str, Any]:
    """The fields of a dataclass that differ from ``default``."""
    return {
        f.name: getattr(obj, f.name)
        for f in dataclasses.fields(obj)
        if f.init and getattr(obj, f.name) != getattr(default, f.name)
    }


def _block_table(b: BlockSpec) -> dict[str, Any]:
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
    if b.p is not None or b.q is not None:
        raise CaseFileError(f"block {b.name!r}: source terms P, Q cannot be saved in a case file")
    if b.boundary is not None:
        t["boundary"] = dict(zip(BORDER_NAMES, b.boundary, strict=True))
    else:
        corners = b.corners
        if isinstance(corners, str):  # "auto": save the corners it chooses
            from ..corners import choose_corners

            corners = choose_corners(b.points)
        t["boundary"] = {"points": b.points, "corners": list(corners or ())}
    if b.borders:
        t["borders"] = {n: dataclasses.asdict(s) for n, s in b.border_specs().items()}
    if b.control is not None:
        c = b.control
        t["control"] = dict(c) if isinstance(c, Mapping) else dataclasses.asdict(c)
    return t


def _outline_table(o: OutlineSection) -> dict[str, Any]:
    t: dict[str, Any] = {"points": o.points, "crs": o.crs}
    if o.origin is not None:
        t["origin"] = list(o.origin)
    t["cuts"] = [list(c) for c in o.cuts]
    if o.snap is not None:
        t["snap"] = o.snap
    if o.multiple != 1:
        t["multiple"] = o.multiple
    if o.cell_size is not None:
        t["cell_size"] = o.cell_size
    if o.single:
        t["single"] = True
    if o.holes:
        t["holes"] = [np.asarray(h).tolist() for h in o.holes]
    t["blocks"] = [
        {"name": b.name, "corners": list(b.corners), "cells": list(b.cells), "initial": b.initial} for b in o.blocks
    ]
    return t


def case_to_dict(case: Case) -> dict[str, Any]:
    """The TOML-ready dictionary of a case (inverse of :func:`~meshcore.case.loads_case`)."""
    out: dict[str, Any] = {}
    if case.title:
        out["title"] = case.title
    if case.description:
        out["description"] = case.description
    solver = _changed(case.solver, SolverSpec())
    if solver:
        out["solver"] = solver
    if case.crs is not None:
        out["crs"] = dict(case.crs)
    if case.multiblock is not None:
        out["multiblock"] = {"mode": case.multiblock.mode} | (
            {"start": case.multiblock.start} if case.multiblock.start != "algebraic" else {}
        )
    if case.interfaces:
        out["interfaces"] = [
            {"a": i.a, "b": i.b} | ({"reversed": i.reversed} if i.reversed is not None else {}) for i in case.interfaces
        ]
    if case.outline is not None:
        out["outline"] = _outline_table(case.outline)
    if case.lake is not None:
        lk = case.lake
        out["lake"] = {"shore": lk.shore} | ({"islands": [np.asarray(h) for h in lk.islands]} if lk.islands else {})
        out["lake"] |= {"cell_size": lk.cell_size} if lk.cell_size is not None else {}
        out["lake"] |= {k: True for k in ("regular", "single") if getattr(lk, k)}
        out["lake"] |= {k: list(getattr(lk, k)) for k in ("notes", "details") if getattr(lk, k)}
    if case.blocks:
        out["blocks"] = [_block_table(b) for b in case.blocks]
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
            # point lists: one [x, y] pair per line (floats written at once: a shore of 10^5 points)
            if all(type(a) is float and type(b) is float for a, b in v):
                return "[\n" + "".join(f"    [{a!r}, {b!r}],\n" for a, b in v) + "]"
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
    out: list[str] = ["# gcmesh case file (format: meshcore/case/__init__.py)"]
    _toml_table(case_to_dict(case), "", out)
    return "\n".join(out).strip() + "\n"


def save_case(case: Case, path: str | Path) -> Path:
    """Write ``case`` as TOML (atomically: temporary file, then rename)."""
    from ..io import atomic_write_text

    p = Path(path)
    atomic_write_text(p, dumps_case(case))
    return p
