"""``meshcore examples [NAME DEST]`` — list or copy the bundled example cases."""

from __future__ import annotations

import argparse
import shutil
import tomllib
from pathlib import Path

from ..errors import InvalidInputError


def examples_dir() -> Path:
    """Folder of the bundled example case files."""
    here = Path(__file__).resolve().parent.parent
    for cand in (here.parent / "resources" / "examples", here / "resources" / "examples"):
        if cand.is_dir():
            return cand
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
    shutil.copy2(src, dest / src.name)
    for rel in _data_files(src):
        target = dest / rel
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(src.parent / rel, target)
    print(dest / src.name)
    return 0
