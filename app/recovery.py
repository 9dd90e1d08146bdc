"""Crash recovery through the case format (no pickle, no Qt).

The autosave writes two files:

* ``recovery.toml`` — a case file (:func:`app.io_adapter.save_project`) with
  every block that a case can hold (closed loops with corners, border
  blocks, or the whole multiblock case).  It opens in the app and in
  ``meshcore generate`` like any case.
* ``recovery.toml.json`` — what a case file cannot hold: blocks still being
  drawn, cut lines, the background image, the solver settings as the app
  keeps them, a lake's water and layout settings (a layout itself is in
  the case file), and the path the project was last saved to.  It names the
  SHA-256 of the case text it belongs to; a sidecar that does not match (a
  crash between the two writes) is ignored and the case alone is recovered.

:func:`write` and :func:`read` are inverses: ``read(write(p)) == p``.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from meshcore import BorderSpec, MeshcoreError
from meshcore.io import atomic_write_text

from .project import Background, Block, Project, SolverSettings

__all__ = ["describe", "discard", "exists", "read", "saved_at", "sidecar", "write"]

FORMAT = "gcmesh-recovery"
VERSION = 1


def sidecar(path) -> Path:
    """The JSON file beside the recovery case file ``path``."""
    p = Path(path)
    return p.with_name(p.name + ".json")


def exists(path) -> bool:
    return Path(path).exists() or sidecar(path).exists()


def discard(path) -> None:
    """Remove the recovery files (after a clean save or a clean exit)."""
    for p in (Path(path), sidecar(path)):
        p.unlink(missing_ok=True)


def write(project: Project, path, saved_as: Path | None = None) -> None:
    """Write ``project`` as the recovery case file ``path`` plus its JSON sidecar.

    Raises OSError when a file cannot be written.
    """
    from .io_adapter import dumps_project

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    solver = project.solver
    if solver.method == "foldfree":  # not an EllipticConfig method; the sidecar keeps it
        project = project.replaced(solver=dataclasses.replace(solver, method="auto"))
    try:
        text = dumps_project(project)
    except (MeshcoreError, ValueError):  # nothing a case can hold yet (a loop still being drawn)
        text = None
    state = {
        "format": FORMAT,
        "version": VERSION,
        "case_sha256": _sha(text) if text is not None else None,
        "path": str(saved_as) if saved_as else None,
        "title": project.title,
        "crs": project.crs,
        "origin": list(project.origin),
        "source_crs": project.source_crs,
        "solver": dataclasses.asdict(solver),
        "cut_lines": [np.asarray(c).tolist() for c in project.cut_lines],
        "background": _background(project.background),
        "blocks": None if project.multiblock is not None or project.layout is not None else _blocks(project),
        "lake": _lake_state(project.lake),
    }
    if text is None:
        path.unlink(missing_ok=True)
    else:
        atomic_write_text(path, text)
    atomic_write_text(sidecar(path), json.dumps(state, indent=1))


def read(path) -> tuple[Project, Path | None]:
    """The recovered project and the path it was saved to (None if never saved).

    Raises
    ------
    MeshcoreError, OSError, ValueError
        When neither file can be read back.
    """
    from .io_adapter import load_project

    path = Path(path)
    case_project = load_project(path) if path.exists() else None
    state = _state(sidecar(path), path if case_project is not None else None)
    if state is None:
        if case_project is None:
            raise ValueError(f"{path}: no recovery file")
        return case_project, None
    base = case_project or Project()
    if state["blocks"] is not None:
        blocks = tuple(base.blocks[b["case"]] if "case" in b else _block_from_state(b) for b in state["blocks"]) or (
            Block(),
        )
        base = base.replaced(blocks=blocks)
    bg = state.get("background")
    project = base.replaced(
        title=state.get("title", ""),
        crs=state.get("crs", ""),
        origin=tuple(state.get("origin", (0.0, 0.0))),
        source_crs=state.get("source_crs", ""),
        solver=SolverSettings(**state["solver"]),
        cut_lines=tuple(np.asarray(c, float).reshape(-1, 2) for c in state.get("cut_lines", ())),
        background=Background(bg["path"], tuple(bg["transform"])) if bg else None,
    )
    if state.get("lake"):
        project = _with_lake(project, state["lake"])
    return project, Path(state["path"]) if state.get("path") else None


def saved_at(path) -> float | None:
    """When the recovery files were last written (seconds since the epoch), None if there are none."""
    times = [p.stat().st_mtime for p in (Path(path), sidecar(path)) if p.exists()]
    return max(times) if times else None


def describe(project: Project, saved_as: Path | None, when: float | None, now: float | None = None) -> str:
    """What a recovery restores, for the prompt at start-up: the file (or lake) name, its blocks,
    when it was autosaved; e.g. ``"Lake Tarn.toml: a lake with 3 islands, laid out in 12 blocks —
    autosaved 2026-12-03 19:02 (14 min ago)"``."""
    import time

    name = saved_as.name if saved_as is not None else (f"{project.title} (never saved)" if project.title else "")
    name = name or "an unsaved project"
    if project.lake is not None:
        n = len(project.lake.holes)
        what = "a lake" + (f" with {n} island{'s' * (n != 1)}" if n else "")
        if project.layout is not None:
            k = len(project.layout.blocks)
            what += f", laid out in {k} block{'s' * (k != 1)}"
    else:
        k = sum(1 for b in project.blocks if len(b.points) or b.boundary is not None)
        what = f"{k} block{'s' * (k != 1)}" if k else "no blocks"
    if len(project.cut_lines):
        what += f", {len(project.cut_lines)} cut line{'s' * (len(project.cut_lines) != 1)}"
    if when is None:
        return f"{name}: {what}"
    now = time.time() if now is None else now
    ago = max(0.0, now - when)
    age = (
        "just now"
        if ago < 60
        else f"{int(ago // 60)} min ago"
        if ago < 3600
        else (f"{ago / 3600:.1f} h ago" if ago < 48 * 3600 else "")
    )
    stamp = time.strftime("%Y-%m-%d %H:%M", time.localtime(when))
    return f"{name}: {what} — autosaved {stamp}" + (f" ({age})" if age else "")


# ----------------------------------------------------------------- helpers
def _sha(text: str) -> str:
    return hashlib.sha256(text.encode("utf-8")).hexdigest()


def _state(p: Path, case_path: Path | None) -> dict | None:
    """The sidecar's state when it is readable and belongs to the case file next to it."""
    try:
        state = json.loads(p.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    if not isinstance(state, dict) or state.get("format") != FORMAT or state.get("version") != VERSION:
        return None
    text = case_path.read_text(encoding="utf-8") if case_path is not None else None
    if state.get("case_sha256") != (_sha(text) if text is not None else None):
        return None
    return state


def _background(bg: Background | None):
    return None if bg is None else {"path": bg.path, "transform": list(bg.transform)}


def _lake_state(lake) -> dict | None:
    """The lake's water and settings (a layout itself is in the case file, hand edits included)."""
    if lake is None:
        return None
    return {
        "outline": np.asarray(lake.outline).tolist(),
        "holes": [np.asarray(h).tolist() for h in lake.holes],
        "cell_size": lake.cell_size,
        "target_cells": lake.target_cells,
        "regular": lake.regular,
        "single": lake.single,
    }


def _with_lake(project: Project, d: Mapping) -> Project:
    from .lake import Lake

    settings = {
        "cell_size": d.get("cell_size"),
        "target_cells": int(d.get("target_cells", 10_000)),
        "regular": bool(d.get("regular", False)),
        "single": bool(d.get("single", False)),
    }
    if project.lake is not None:  # the case held the layout: only the settings come from here
        return project.replaced(lake=project.lake.replaced(**settings))
    lake = Lake(
        outline=np.asarray(d["outline"], float).reshape(-1, 2),
        holes=tuple(np.asarray(h, float).reshape(-1, 2) for h in d.get("holes", ())),
        **settings,
    )
    return project.replaced(lake=lake)


def _blocks(project: Project) -> list[dict]:
    """Each block: its index among the case's blocks (the ready ones), or its full state."""
    out, k = [], 0
    for b in project.blocks:
        if b.ready:
            out.append({"case": k})
            k += 1
        else:
            out.append(_block_state(b))
    return out


def _block_state(b: Block) -> dict:
    control = b.control if b.control is None or isinstance(b.control, Mapping) else None
    return {
        "name": b.name,
        "points": np.asarray(b.points).tolist(),
        "closed": b.closed,
        "corners": list(b.corners) if b.corners is not None else None,
        "cells": list(b.cells) if b.cells is not None else None,
        "weights": list(b.weights),
        "initial": b.initial,
        "curve": b.curve,
        "periodic": b.periodic,
        "borders": {n: dataclasses.asdict(s) for n, s in b.borders},
        "snap_angle": b.snap_angle,
        "control": control,
    }


def _block_from_state(d: Mapping) -> Block:
    kw = dict(d)
    kw["points"] = np.asarray(kw["points"], float).reshape(-1, 2)
    kw["corners"] = tuple(kw["corners"]) if kw.get("corners") is not None else None
    kw["cells"] = tuple(kw["cells"]) if kw.get("cells") is not None else None
    kw["weights"] = tuple(kw["weights"])
    kw["borders"] = tuple((n, BorderSpec(**s)) for n, s in dict(kw.get("borders", {})).items())
    return Block(**kw)
