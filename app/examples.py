"""The Examples menu: the paper's cases (``resources/examples/*.toml``) and real lakes.

Lakes (``app/resources/*.csv``, lon/lat) open as a lake file does (File ▸ Import): projected to
UTM metres, with the lake's shore kept for Auto layout, which is offered (``--solve`` takes it);
:func:`lake_file` names the file, the app's import reads it.
"""

from __future__ import annotations

import sys
from pathlib import Path

from .io_adapter import load_project
from .project import Project

__all__ = ["EXAMPLE_DIRS", "LAKES", "example_names", "lake_file", "load_example"]

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


def lake_file(name: str) -> Path | None:
    """The outline file of lake example ``name`` (None for the paper's cases)."""
    return _HERE / "resources" / LAKES[name][0] if name in LAKES else None


def load_example(name: str) -> tuple[Project, Path]:
    """The project of case example ``name`` and its case file (lakes: :func:`lake_file`)."""
    cases = _case_files()
    if name in cases:
        return load_project(cases[name]), cases[name]
    raise KeyError(f"unknown example {name!r}; known: {', '.join(example_names())}")
