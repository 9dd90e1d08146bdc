#!/usr/bin/env bash
# Set up, then lint, type-check and run the whole test suite (headless Qt), doctests included.
# Arguments go to pytest: scripts/test.sh -m "not slow" is the fast tier (make test-fast).
# The tests run in parallel processes (pytest-xdist), one per core up to 4, a test file per process
# at a time (its module fixtures made once); GCMESH_TEST_WORKERS=1 runs them in this process.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
export QT_QPA_PLATFORM=offscreen
export OMP_WAIT_POLICY=passive
export NUMBA_NUM_THREADS=${NUMBA_NUM_THREADS:-2}
.venv/bin/ruff check meshcore app tests benchmarks tools scripts
.venv/bin/ruff format --check -q meshcore app tests benchmarks tools scripts
.venv/bin/python scripts/mypy_check.py   # never more type errors than .ci/mypy-baseline.txt
WORKERS=${GCMESH_TEST_WORKERS:-$(.venv/bin/python -c "import os; print(min(4, len(os.sched_getaffinity(0))))")}
PAR=()
if [ "$WORKERS" -gt 1 ]; then PAR=(-n "$WORKERS" --dist loadfile); fi
exec .venv/bin/python -m pytest -q -p no:cacheprovider "${PAR[@]}" "$@"
