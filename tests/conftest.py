"""Test configuration: headless Qt, single-threaded numba, shared fixtures."""

from __future__ import annotations

import os

# Must happen before any QApplication exists (environment.md §5): a pytest run
# with no display and no platform aborts the interpreter instead of failing.
os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
# Parallel numba spin-waits under CPU contention (environment.md §2).
os.environ.setdefault("OMP_WAIT_POLICY", "passive")

import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import settings

# CI runs the same property-test examples every time (a failure there is reproducible and does
# not depend on the day); local runs draw new ones and keep finding cases (see
# tests/meshcore/test_layout.py for one CI found, now an @example).
settings.register_profile("ci", derandomize=True, print_blob=True)
if os.environ.get("CI"):
    settings.load_profile("ci")

ROOT = Path(__file__).resolve().parent.parent
DATA = Path(__file__).resolve().parent / "data"
SHARED_LAKES = ROOT.parent / "shared" / "data" / "lakes"


def benchmark_module(name: str):
    """The script ``benchmarks/<name>.py`` loaded as a module (``benchmarks/`` on the path for
    its own imports)."""
    import importlib.util
    import sys

    sys.path.insert(0, str(ROOT / "benchmarks"))
    spec = importlib.util.spec_from_file_location(name, ROOT / "benchmarks" / f"{name}.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def annulus_sector(ni: int, nj: int, r0: float = 1.0, r1: float = 3.0, th0: float = 0.0, th1: float = math.pi / 2):
    """Exact Winslow grid of an annulus sector: i along ln r (geometric), j along θ."""
    r = r0 * (r1 / r0) ** np.linspace(0.0, 1.0, ni + 1)
    th = np.linspace(th0, th1, nj + 1)
    R, T = np.meshgrid(r, th, indexing="ij")
    return R * np.cos(T), R * np.sin(T)


def borders_of(x: np.ndarray, y: np.ndarray):
    """The four borders (bottom, right, top, left) of node arrays."""
    return (
        np.column_stack([x[:, 0], y[:, 0]]),
        np.column_stack([x[-1, :], y[-1, :]]),
        np.column_stack([x[:, -1], y[:, -1]]),
        np.column_stack([x[0, :], y[0, :]]),
    )


def rectangle_borders(w: float = 2.0, h: float = 1.0, ni: int = 8, nj: int = 4):
    xi = np.linspace(0, w, ni + 1)
    eta = np.linspace(0, h, nj + 1)
    X, Y = np.meshgrid(xi, eta, indexing="ij")
    return borders_of(X, Y)


@pytest.fixture
def data_dir() -> Path:
    return DATA


def one_block_kwargs(poly, nodes: int) -> dict:
    """``generate_block`` keywords for a shape's outer ring as one block, with the corners and the
    cell ratio ``meshcore import`` chooses, scaled to about ``nodes`` nodes."""
    from meshcore.io.outline import guess_cells, guess_corners

    loop = np.asarray(poly.exterior.coords)[:-1]
    corners = guess_corners(loop)
    ci, cj = guess_cells(loop, corners)
    s = math.sqrt(nodes / ((ci + 1) * (cj + 1)))
    return {"loop": loop, "corners": corners, "cells": (max(4, round(ci * s)), max(4, round(cj * s)))}
