"""The Examples menu: the paper's cases (``resources/examples/*.toml``) and real lakes.

Lakes (``app/resources/*.csv``, lon/lat) are projected to UTM metres, given
corners and cell counts by :func:`app.project.block_from_points` (the choice
of ``meshcore import``).
"""

from __future__ import annotations

import sys
from pathlib import Path

from .io_adapter import load_project, read_points, to_local
from .project import Project, block_from_points

__all__ = ["EXAMPLE_DIRS", "LAKES", "example_names", "load_example"]

_HERE = Path(__file__).resolve().parent
EXAMPLE_DIRS = (
    _HERE.parent / "resources" / "examples",
    _HERE / "resources" / "examples",
    Path(sys.prefix) / "share" / "gcmesh" / "examples",  # non-editable installs
)
LAKES = {
    "lake-bolsena": ("lake_bolsena.csv", "Lake Bolsena, Italy (GSHHG)"),
    "lake-zurich": ("lake_zurich.csv", "Lake Zurich, Switzerland (GSHHG)"),
    "windermere": ("windermere.csv", "Windermere, England (GSHHG)"),
}


def _case_files() -> dict[str, Path]:
    out: dict[str, Path] = {}
    for d in EXAMPLE_DIRS:
        if d.is_dir():
            for f in sorted(d.glob("*.toml")):
                out.setdefault(f.stem, f)
    return out


def example_names() -> list[str]:
    """Names for ``--example`` and the Examples menu (cases first, then lakes)."""
    return [*_case_files(), *[k for k, (f, _t) in LAKES.items() if (_HERE / "resources" / f).exists()]]


def lake_project(csv_path: Path, title: str = "", cells: int = 48) -> Project:
    """A lake: projected shoreline, auto corners, cells by shape."""
    pd = read_points(csv_path)
    if pd.lonlat:
        pts, frame = to_local(pd)
        crs, origin, src = frame.crs or "", frame.origin, frame.source_crs or ""
    else:
        pts, crs, origin, src = pd.points, "", (0.0, 0.0), ""
    block = block_from_points(pts, csv_path.stem, total=cells, minimum=12)  # a dozen cells across narrow lakes
    return Project(blocks=(block,), crs=crs, origin=origin, source_crs=src, title=title)


def load_example(name: str) -> tuple[Project, Path | None]:
    """The project of example ``name`` and its case file (None for lakes)."""
    cases = _case_files()
    if name in cases:
        return load_project(cases[name]), cases[name]
    if name in LAKES:
        f, title = LAKES[name]
        return lake_project(_HERE / "resources" / f, title), None
    raise KeyError(f"unknown example {name!r}; known: {', '.join(example_names())}")
