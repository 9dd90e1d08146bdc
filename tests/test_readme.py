"""The README's Python example runs as written and prints what its comments say."""

from __future__ import annotations

import contextlib
import io
import re
from pathlib import Path

README = Path(__file__).resolve().parent.parent / "README.md"


def test_readme_python_example_runs():
    text = README.read_text(encoding="utf-8")
    block = re.search(r"```python\n(.*?)```", text, re.S).group(1)
    assert len(block.strip().splitlines()) <= 10
    out = io.StringIO()
    ns: dict = {}
    with contextlib.redirect_stdout(out):
        exec(compile(block, "README.md", "exec"), ns)
    printed = out.getvalue()
    assert "converged=True" in printed and "folded cells" in printed
    assert ns["grid"].x.shape == (33, 13)


def test_readme_first_lines_give_the_two_commands():
    head = "\n".join(README.read_text(encoding="utf-8").splitlines()[:10])
    assert "make run" in head and "make test" in head
    # CI runs exactly what `make test` runs
    assert "bash scripts/test.sh" in (README.parent / ".ci" / "run").read_text()
    assert "bash scripts/test.sh" in (README.parent / "Makefile").read_text()
