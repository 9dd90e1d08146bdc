#!/usr/bin/env bash
# Set up, then lint, type-check and run the whole test suite (headless Qt), doctests included.
# Arguments go to pytest: scripts/test.sh -m "not slow" is the fast tier (make test-fast).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
export QT_QPA_PLATFORM=offscreen
export OMP_WAIT_POLICY=passive
export NUMBA_NUM_THREADS=${NUMBA_NUM_THREADS:-2}
.venv/bin/ruff check meshcore app tests benchmarks tools scripts
.venv/bin/ruff format --check -q meshcore app tests benchmarks tools scripts
.venv/bin/python scripts/mypy_check.py   # never more type errors than .ci/mypy-baseline.txt
exec .venv/bin/python -m pytest -q -p no:cacheprovider "$@"
