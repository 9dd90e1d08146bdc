#!/usr/bin/env bash
# Set up, then run the main job: the app on an example; with no display, a lake outline in,
# a model-ready multiblock grid out (meshcore mesh: out/<lake>.vtm, .cgns, .png, layout .toml).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
EXAMPLE=${EXAMPLE:-bottle-fine}
if [ -n "${DISPLAY:-}${WAYLAND_DISPLAY:-}" ]; then
  exec .venv/bin/python -m app --example "$EXAMPLE" --solve "$@"
fi
echo "[run] no display: meshing a lake with the CLI (the app needs a display)" >&2
mkdir -p out
LAKE=${LAKE:-benchmarks/lakes/lake_iseo.geojson}
name=$(basename "${LAKE%.*}")
.venv/bin/meshcore mesh "$LAKE" -o "out/$name.vtm" -o "out/$name.cgns" --png "out/$name.png" --colour deviation \
  --preset delft3d --preset efdc --case "out/$name-layout.toml"
echo "[run] wrote out/$name.vtm, out/$name.cgns, out/$name.png and the editable layout out/$name-layout.toml" >&2
