r"""The structured grid and the index/border convention used everywhere.

Convention (fixed once, here)
-----------------------------
A block of ``ni × nj`` cells has ``(ni + 1) × (nj + 1)`` nodes.  Coordinates
are two C-contiguous float64 arrays ``x, y`` of shape ``(ni + 1, nj + 1)``:
``i`` runs along ξ, ``j`` along η. ::

                         top = Γ2  (η = nj, j = nj), runs with increasing i
                  (0,nj) o-->--o-->--o-->--o (ni,nj)
                         |                 |
     left = Γ1  (ξ = 0)  ^     η ↑         ^   right = Γ3  (ξ = ni)
     runs with           |       o → ξ     |   runs with
     increasing j        ^                 ^   increasing j
                         |                 |
                   (0,0) o-->--o-->--o-->--o (ni,0)
                         bottom = Γ4  (η = 0, j = 0), runs with increasing i

* ``bottom = (x[:, 0], y[:, 0])``, ``top = (x[:, -1], y[:, -1])``,
  ``left = (x[0, :], y[0, :])``, ``right = (x[-1, :], y[-1, :])``.
* Shared corners: ``bottom[0] == left[0]``, ``bottom[-1] == right[0]``,
  ``top[0] == left[-1]``, ``top[-1] == right[-1]``.
* With this orientation a valid grid has a positive Jacobian
  ``x_ξ y_η − x_η y_ξ > 0``: walking along the bottom with increasing i, the
  interior lies on the left (the boundary loop bottom → right → top⁻¹ → left⁻¹
  is counter-clockwise).

The paper's names: Γ1 left (ξ = 0), Γ3 right (ξ = N), Γ4 lower (η = 0),
Γ2 upper (η = M); "N partitions" means N cells (N + 1 grid lines).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .errors import InvalidInputError

__all__ = ["BORDER_NAMES", "GAMMA", "SolveInfo", "StructuredGrid"]

#: The four borders in counter-clockwise order.
BORDER_NAMES: tuple[str, ...] = ("bottom", "right", "top", "left")
#: The paper's Γ numbering of the borders.
GAMMA: dict[str, str] = {"left": "Γ1", "top": "Γ2", "right": "Γ3", "bottom": "Γ4"}


def _frozen(a: Any, name: str) -> np.ndarray:
    arr = np.array(a, dtype=np.float64, order="C", copy=True)
    arr.setflags(write=False)
    return arr


@dataclass(frozen=True, slots=True)
class SolveInfo:
    """How a grid was obtained: method, convergence and residual history."""

    method: str = "algebraic"
    converged: bool = True
    iterations: int = 0
    residual: float = 0.0
    tolerance: float = 0.0
    residual_history: tuple[tuple[int, float], ...] = ()
    elapsed: float = 0.0
    message: str = ""


@dataclass(frozen=True, slots=True, eq=False)
class StructuredGrid:
    """An immutable structured grid of ``(ni + 1) × (nj + 1)`` nodes.

    Parameters
    ----------
    x, y : array_like
        Node coordinates, shape ``(ni + 1, nj + 1)`` (see module docstring).
    info : SolveInfo
        How the grid was produced (method, converged, iterations, residual).
    names : dict
        Optional border names, e.g. ``{"bottom": "inlet"}``.
    periodic : bool
        True when the ξ direction is periodic (O-grid): column ``ni`` repeats
        column ``0``.

    Examples
    --------
    >>> import numpy as np
    >>> from meshcore import StructuredGrid
    >>> xi, eta = np.meshgrid(np.linspace(0, 2, 3), np.linspace(0, 1, 2), indexing="ij")
    >>> g = StructuredGrid(xi, eta)
    >>> g.shape, g.cells
    ((3, 2), (2, 1))
    """

    x: np.ndarray
    y: np.ndarray
    info: SolveInfo = field(default_factory=SolveInfo)
    names: dict = field(default_factory=dict)
    periodic: bool = False

    def __post_init__(self) -> None:
        x = _frozen(self.x, "x")
        y = _frozen(self.y, "y")
        if x.ndim != 2 or x.shape != y.shape:
            raise InvalidInputError(f"grid x and y must be 2-D arrays of the same shape, got {x.shape} and {y.shape}")
        if x.shape[0] < 2 or x.shape[1] < 2:
            raise InvalidInputError(f"grid needs at least 2 × 2 nodes, got {x.shape}")
        object.__setattr__(self, "x", x)
        object.__setattr__(self, "y", y)
        object.__setattr__(self, "names", dict(self.names))

    # ----------------------------------------------------------------- shape
    @property
    def shape(self) -> tuple[int, int]:
        """Node counts ``(ni + 1, nj + 1)``."""
        return self.x.shape  # type: ignore[return-value]

    @property
    def cells(self) -> tuple[int, int]:
        """Cell counts ``(ni, nj)``."""
        return (self.x.shape[0] - 1, self.x.shape[1] - 1)

    @property
    def n_nodes(self) -> int:
        return int(self.x.size)

    # ------------------------------------------------------ solve delegation
    @property
    def converged(self) -> bool:
        return self.info.converged

    @property
    def iterations(self) -> int:
        return self.info.iterations

    @property
    def residual(self) -> float:
        return self.info.residual

    @property
    def method(self) -> str:
        return self.info.method

    # --------------------------------------------------------------- borders
    def border(self, name: str) -> np.ndarray:
        """Border nodes as an ``(k, 2)`` array in the convention's direction."""
        if name == "bottom":
            return np.column_stack([self.x[:, 0], self.y[:, 0]])
        if name == "top":
            return np.column_stack([self.x[:, -1], self.y[:, -1]])
        if name == "left":
            return np.column_stack([self.x[0, :], self.y[0, :]])
        if name == "right":
            return np.column_stack([self.x[-1, :], self.y[-1, :]])
        raise InvalidInputError(f"border must be one of {BORDER_NAMES}, got {name!r}")

    @property
    def points(self) -> np.ndarray:
        """All nodes as an ``(N, 2)`` array (C order: j fastest)."""
        return np.column_stack([self.x.ravel(), self.y.ravel()])

    def bounds(self) -> tuple[float, float, float, float]:
        """``(xmin, ymin, xmax, ymax)``."""
        return (
            float(self.x.min()),
            float(self.y.min()),
            float(self.x.max()),
            float(self.y.max()),
        )

    @property
    def size(self) -> float:
        """Length of the bounding-box diagonal (the length scale of tolerances)."""
        x0, y0, x1, y1 = self.bounds()
        return math.hypot(x1 - x0, y1 - y0)

    # ---------------------------------------------------- copy-returning ops
    def replaced(self, **changes: Any) -> StructuredGrid:
        """Return a copy with fields replaced (``dataclasses.replace``)."""
        return dataclasses.replace(self, **changes)

    def translated(self, dx: float, dy: float) -> StructuredGrid:
        return self.replaced(x=self.x + dx, y=self.y + dy)

    def scaled(self, factor: float) -> StructuredGrid:
        return self.replaced(x=self.x * factor, y=self.y * factor)

    def rotated(self, angle: float) -> StructuredGrid:
        """Rotate by ``angle`` radians about the origin."""
        c, s = math.cos(angle), math.sin(angle)
        return self.replaced(x=c * self.x - s * self.y, y=s * self.x + c * self.y)

    def transposed(self) -> StructuredGrid:
        """Swap ξ and η (keeps a positive orientation by mirroring i)."""
        return self.replaced(x=self.x.T[::-1].copy(), y=self.y.T[::-1].copy())

    def __repr__(self) -> str:
        ni, nj = self.cells
        return (
            f"StructuredGrid({ni}×{nj} cells, method={self.info.method!r}, "
            f"converged={self.info.converged}, iterations={self.info.iterations}, "
            f"residual={self.info.residual:.3g})"
        )

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, StructuredGrid):
            return NotImplemented
        return (
            self.x.shape == other.x.shape
            and bool(np.array_equal(self.x, other.x))
            and bool(np.array_equal(self.y, other.y))
        )

    __hash__ = None  # type: ignore[assignment]
