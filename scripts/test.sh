#!/usr/bin/env bash
# Set up, then run the whole test suite (headless Qt, single-threaded numba).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
export QT_QPA_PLATFORM=offscreen
export OMP_WAIT_POLICY=passive
export NUMBA_NUM_THREADS=${NUMBA_NUM_THREADS:-2}
.venv/bin/ruff check meshcore app tests benchmarks tools scripts
.venv/bin/ruff format --check -q meshcore app tests benchmarks tools scripts
exec .venv/bin/python -m pytest -q -p no:cacheprovider "$@"
