#!/usr/bin/env bash
# Set up, then run the main job: the app on an example; with no display, the CLI
# on the same example, writing out/bottle.vts and out/bottle.png.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
EXAMPLE=${EXAMPLE:-bottle-fine}
if [ -n "${DISPLAY:-}${WAYLAND_DISPLAY:-}" ]; then
  exec .venv/bin/python -m app --example "$EXAMPLE" --solve "$@"
fi
echo "[run] no display: running the CLI on example '$EXAMPLE'" >&2
mkdir -p out
.venv/bin/meshcore examples "$EXAMPLE" out/
.venv/bin/meshcore generate "out/$EXAMPLE.toml" -o "out/$EXAMPLE.vts" --png "out/$EXAMPLE.png"
.venv/bin/meshcore quality "out/$EXAMPLE.vts"
echo "[run] wrote out/$EXAMPLE.vts and out/$EXAMPLE.png" >&2
