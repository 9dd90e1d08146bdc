#!/usr/bin/env bash
# Set up everything gcmesh needs on a fresh Debian/Ubuntu machine with Python 3.11+:
# the Debian libraries Qt needs (offscreen and xcb), Xvfb tools, a virtualenv in
# .venv and the package with all extras.  Idempotent: a second run is quick.
set -euo pipefail
cd "$(dirname "$0")/.."
PY=${PYTHON:-python3}
SUDO=""
if [ "$(id -u)" != "0" ] && command -v sudo >/dev/null; then SUDO="sudo"; fi
DEB_PKGS="libglib2.0-0 libgl1 libegl1 libfontconfig1 libxkbcommon0 libdbus-1-3 \
  libxkbcommon-x11-0 libxcb-cursor0 libxcb-icccm4 libxcb-keysyms1 libxcb-image0 \
  libxcb-render-util0 libxcb-xkb1 libxcb-randr0 libxcb-shape0 libxcb-xfixes0 libxcb-sync1 \
  libxcb-shm0 libx11-xcb1 xvfb xdotool x11-utils"
if command -v apt-get >/dev/null; then
  missing=""
  for p in $DEB_PKGS; do dpkg -s "$p" >/dev/null 2>&1 || missing="$missing $p"; done
  if [ -n "$missing" ]; then
    echo "[setup] installing Debian packages:$missing" >&2
    $SUDO apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends $missing >/dev/null
  fi
  if ! $PY -c "import venv, ensurepip" >/dev/null 2>&1; then
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq python3-venv >/dev/null
  fi
fi
if [ ! -x .venv/bin/python ]; then
  echo "[setup] creating .venv" >&2
  $PY -m venv .venv
fi
STAMP=.venv/.gcmesh-installed
if [ ! -f "$STAMP" ] || [ pyproject.toml -nt "$STAMP" ]; then
  echo "[setup] installing gcmesh[dev] into .venv" >&2
  .venv/bin/python -m pip install -q --upgrade pip >/dev/null
  .venv/bin/python -m pip install -q -e ".[dev]"
  touch "$STAMP"
fi
# Compile every numba kernel once (cached on disk, see meshcore/_numba_setup.py), so that the
# first solve loads them instead of compiling (50 s on a quiet 2-core machine, two processes side by side);
# a second run only loads them (~1 s).
.venv/bin/python -c "from meshcore._numba_setup import compile_all, cache_dir; \
print(f'[setup] numba kernels ready in {compile_all():.1f} s (cache: {cache_dir()})')" >&2
