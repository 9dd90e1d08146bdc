"""The import contract of the layers, read from the source (AST; nothing is imported).

* ``meshcore`` never imports the app or Qt;
* the app's views never import the solver controller;
* no import cycles, inside ``meshcore`` or ``app`` (function-level imports count too);
* no private name is imported from another package (numba kernel modules excepted).

The layer map is in CONTRIBUTING.md.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
QT = ("PySide6", "pyqtgraph", "superqt", "psygnal", "shiboken6")


def _modules(*packages: str) -> dict[str, tuple[Path, bool]]:
    out = {}
    for pkg in packages:
        for f in sorted((ROOT / pkg).rglob("*.py")):
            parts = list(f.relative_to(ROOT).with_suffix("").parts)
            is_pkg = parts[-1] == "__init__"
            out[".".join(parts[:-1] if is_pkg else parts)] = (f, is_pkg)
    return out


MODULES = _modules("meshcore", "app")


def _imports(module: str) -> list[tuple[str, list[str], int]]:
    """``(imported module, imported names, line)`` of every import statement of ``module``."""
    path, is_pkg = MODULES[module]
    base = module if is_pkg else module.rpartition(".")[0]
    out = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            out += [(a.name, [], node.lineno) for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                b = base
                for _ in range(node.level - 1):
                    b = b.rpartition(".")[0]
                mod = b + ("." + node.module if node.module else "")
            else:
                mod = node.module or ""
            out.append((mod, [a.name for a in node.names], node.lineno))
    return out


def _resolve(name: str) -> str | None:
    while name and name not in MODULES:
        name = name.rpartition(".")[0]
    return name or None


def _graph() -> dict[str, set[str]]:
    g: dict[str, set[str]] = {m: set() for m in MODULES}
    for m in MODULES:
        for mod, names, _ in _imports(m):
            # `from pkg import sub` imports the submodule pkg.sub when there is one
            targets = [_resolve(f"{mod}.{n}") for n in names] or [_resolve(mod)]
            for t in targets:
                if t is not None and t != m:
                    g[m].add(t)
    return g


def _cycles(g: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components with more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    out: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in sorted(g[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in sorted(g):
        if v not in index:
            visit(v)
    return out


def test_no_import_cycles():
    assert _cycles(_graph()) == []


def test_the_checker_finds_a_cycle():
    assert _cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]


@pytest.mark.parametrize("module", sorted(m for m in MODULES if m.startswith("meshcore")))
def test_meshcore_never_imports_the_app_or_qt(module):
    bad = [(mod, line) for mod, _, line in _imports(module) if mod.split(".")[0] in ("app", *QT)]
    assert not bad, f"{module} imports {bad}"


@pytest.mark.parametrize("module", sorted(m for m in MODULES if m.startswith("app.views")))
def test_views_never_import_the_solver_controller(module):
    bad = [line for mod, names, line in _imports(module) if "solver_controller" in mod or "solver_controller" in names]
    assert not bad, f"{module} imports app.solver_controller (line {bad[0]})"


def test_no_private_names_across_packages():
    found = []
    for m, (_, is_pkg) in MODULES.items():
        pkg = m if is_pkg else m.rpartition(".")[0]
        for mod, names, line in _imports(m):
            for n in names:
                private = n.startswith("_") and not n.startswith("__")
                same_package = mod == pkg or (mod.startswith(pkg + ".") and pkg.count(".") >= 1)
                if private and not same_package and n != "_kernels":
                    found.append(f"{m}:{line} imports {n} from {mod}")
    assert not found
