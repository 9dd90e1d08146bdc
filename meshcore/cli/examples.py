"""``meshcore examples [NAME DEST]`` — list or copy the bundled example cases."""

from __future__ import annotations

import argparse
import shutil
import tomllib
from pathlib import Path

from ..errors import InvalidInputError


def resources_dir() -> Path | None:
    """The bundled ``resources`` folder: the source tree's, or ``<prefix>/share/gcmesh`` when installed."""
    import sys

    here = Path(__file__).resolve().parent.parent
    for cand in (here.parent / "resources", Path(sys.prefix) / "share" / "gcmesh"):
        if (cand / "examples").is_dir():
            return cand
    return None


def examples_dir() -> Path:
    """Folder of the bundled example case files."""
    res = resources_dir()
    if res is not None:
        return res / "examples"
    raise InvalidInputError("bundled examples not found (resources/examples is missing from this install)")


def list_examples() -> list[str]:
    return sorted(p.stem for p in examples_dir().glob("*.toml"))


def example_path(name: str) -> Path:
    p = examples_dir() / f"{name}.toml"
    if not p.exists():
        raise InvalidInputError(f"no example named {name!r}; available: {', '.join(list_examples())}")
    return p


def _data_files(case_file: Path) -> list[str]:
    """Relative data files a case refers to (point files)."""
    data = tomllib.loads(case_file.read_text(encoding="utf-8"))
    out = []

    def visit(v):
        if isinstance(v, dict):
            for vv in v.values():
                visit(vv)
        elif isinstance(v, list):
            for vv in v:
                visit(vv)
        elif isinstance(v, str) and (case_file.parent / v).is_file():
            out.append(v)

    visit(data)
    return sorted(set(out))


def add_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("name", nargs="?", help="example to copy")
    p.add_argument("dest", nargs="?", help="destination folder")


def run(args: argparse.Namespace) -> int:
    if args.name is None:
        for n in list_examples():
            print(n)
        return 0
    if args.dest is None:
        raise InvalidInputError("examples NAME DEST: give a destination folder")
    src = example_path(args.name)
    dest = Path(args.dest)
    dest.mkdir(parents=True, exist_ok=True)
    text = src.read_text(encoding="utf-8")
    for rel in _data_files(src):
        origin = (src.parent / rel).resolve()
        target_rel = rel
        if Path(rel).is_absolute() or ".." in Path(rel).parts:
            # keep everything inside DEST: copy next to the case and point the case at the copy
            target_rel = origin.name
            text = text.replace(f'"{rel}"', f'"{target_rel}"')
        target = dest / target_rel
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(origin, target)
        # data files travel with their licence
        for lic in origin.parent.glob("LICENSE*"):
            shutil.copy2(lic, target.parent / lic.name)
    (dest / src.name).write_text(text, encoding="utf-8")
    print(dest / src.name)
    return 0
