"""meshcore — structured, boundary-fitted 2-D grids in generalized coordinates.

The headless core of gcmesh: boundaries and borders, parametric splines,
point distributions, algebraic grids, the elliptic (Thompson–Thames–Mastin /
Winslow) solver, quality metrics, readers/writers and a CLI.  It never imports Qt.

>>> import meshcore
>>> g = meshcore.generate_block([[0, 0], [1, 0]], [[1, 0], [1, 1]],
...                             [[0, 1], [1, 1]], [[0, 0], [0, 1]], cells=(8, 8))
>>> meshcore.quality(g).n_folded
0
"""

from __future__ import annotations

from . import _numba_setup  # noqa: F401  (must run before numba compiles anything)
from .algebraic import algebraic_grid, tfi, weighted_average
from .boundary import Borders, BorderSpec, borders_from_loop, borders_from_polylines
from .control import ControlSpec, make_sources
from .corners import choose_corners
from .curves import LinearSpline, SmoothCurve, make_curve
from .distribution import distribute
from .elliptic import EllipticConfig, SolverProgress, iterate, solve
from .errors import (
    BorderMismatchError,
    BoundaryError,
    CaseFileError,
    FoldedGridError,
    InvalidInputError,
    MeshcoreError,
    MeshcoreWarning,
    ReadError,
    SolverError,
    TopologyError,
    WriteError,
)
from .generate import Done, Repaired, StartGrid, generate_block, initial_grid, prepare_borders, run_block
from .grid import BORDER_NAMES, SolveInfo, StructuredGrid
from .metrics import Metrics, metrics
from .quality import QualityReport, cell_quality, quality
from .spec import BlockSpec, SolverSpec

__version__ = "0.1.0"

__all__ = [
    "BORDER_NAMES",
    "BlockSpec",
    "BorderMismatchError",
    "BorderSpec",
    "Borders",
    "BoundaryError",
    "CaseFileError",
    "ControlSpec",
    "Done",
    "EllipticConfig",
    "FoldedGridError",
    "InvalidInputError",
    "LayoutOptions",
    "LinearSpline",
    "MeshcoreError",
    "MeshcoreWarning",
    "Metrics",
    "QualityReport",
    "ReadError",
    "Repaired",
    "SmoothCurve",
    "SolveInfo",
    "SolverError",
    "SolverProgress",
    "SolverSpec",
    "StartGrid",
    "StructuredGrid",
    "TopologyError",
    "WriteError",
    "__version__",
    "algebraic_grid",
    "auto_layout",
    "borders_from_loop",
    "borders_from_polylines",
    "cell_quality",
    "choose_corners",
    "distribute",
    "generate_block",
    "initial_grid",
    "iterate",
    "make_curve",
    "make_sources",
    "mesh_outline",
    "metrics",
    "prepare_borders",
    "quality",
    "run_block",
    "solve",
    "tfi",
    "weighted_average",
]


# Readers/writers are re-exported lazily so that ``import meshcore`` stays light
# (meshcore.io imports nothing heavy either, but keeps optional readers out).
_LAZY_IO = {"read_points", "read_grid", "read_blocks", "write", "PointSet", "GridSet"}
# The lake pipeline (shapely, scipy, the layout MILP) is loaded on first use as well.
_LAZY = {"auto_layout": "layout", "LayoutOptions": "layout", "mesh_outline": "lakegrid"}


def __getattr__(name: str):
    if name in _LAZY_IO:
        from . import io as _io

        return getattr(_io, name)
    if name in _LAZY:
        import importlib

        return getattr(importlib.import_module(f".{_LAZY[name]}", __name__), name)
    raise AttributeError(f"module 'meshcore' has no attribute {name!r}")
