"""Type-check meshcore with mypy; fail when there are more errors than the baseline.

The baseline (``.ci/mypy-baseline.txt``, one number) is the error count the
project started from; fixing errors lowers it (this script says when), adding
one fails CI.  Configuration: ``[tool.mypy]`` in pyproject.toml.
"""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
BASELINE = ROOT / ".ci" / "mypy-baseline.txt"


def count_errors() -> tuple[int, str]:
    """``(number of mypy errors in meshcore, mypy's output)``."""
    r = subprocess.run([sys.executable, "-m", "mypy"], cwd=ROOT, capture_output=True, text=True)
    out = r.stdout + r.stderr
    if "No module named mypy" in out:
        raise SystemExit("mypy is not installed: pip install 'mypy>=1.10' (it is in the dev extra)")
    m = re.search(r"Found (\d+) errors? in", out)
    if m:
        return int(m.group(1)), out
    if "Success: no issues found" in out:
        return 0, out
    raise SystemExit(f"mypy did not run:\n{out}")


def main() -> int:
    baseline = int(BASELINE.read_text(encoding="utf-8").split()[0])
    n, out = count_errors()
    if n > baseline:
        print(out)
        print(f"mypy: {n} errors in meshcore, more than the baseline {baseline} ({BASELINE.name}): fix the new ones")
        return 1
    if n < baseline:
        print(f"mypy: {n} errors in meshcore (baseline {baseline}): lower .ci/mypy-baseline.txt to {n}")
    else:
        print(f"mypy: {n} errors in meshcore (= baseline)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
