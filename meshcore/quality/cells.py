"""Cell quality: folds, corner Jacobians, orthogonality, skewness, aspect, growth.

Per cell ``(i, j)`` with corners ``00 = (i, j)``, ``10 = (i+1, j)``,
``11 = (i+1, j+1)``, ``01 = (i, j+1)``:

* ``area`` — signed area (shoelace); ``≤ 0`` means the cell is **folded**;
* ``corner_jacobians`` — the cross products of the two edges at each corner
  (shape ``(4, ni, nj)``); a cell is **valid** (convex, not inverted) when
  all four are ``> 0`` — up to rounding: a corner whose sine is within
  :data:`STRAIGHT_SINE` of 0 is **straight** (a triangle cell with a 180°
  angle), reported apart and not counted non-convex, whatever the frame.
  On real shorelines non-convex cells outnumber folded ones;
* ``jacobian_ratio`` — min / max of the four corner Jacobians (1 for a parallelogram);
* ``orthogonality`` — largest deviation of a corner angle from 90°, degrees;
* ``skewness`` — equiangle skewness ``max((θmax − 90)/90, (90 − θmin)/90)``;
* ``aspect_ratio`` — longer / shorter of the mean ξ- and η-edge lengths;
* ``size_ratio`` — largest area ratio (≥ 1) to a neighbour cell in ξ or η
  (across the seam too for periodic grids).

All metrics are invariant under translation, rotation and uniform scaling
(except ``area`` and the corner Jacobians, which scale with the square).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..grid import StructuredGrid

__all__ = ["STRAIGHT_SINE", "QualityReport", "cell_quality", "corner_sines", "quality"]

#: A cell corner whose sine (the corner Jacobian over its two edges' lengths) is within this of 0
#: is straight up to rounding: a triangle cell with a 180° angle.  Its Jacobian's sign is the
#: rounding's (the same grid was fold-free in a lake's local frame and non-convex after the move
#: to UTM, where coordinates of 5e6 m leave ~1e-9 m of each difference); 1e-7 stays above that for
#: cells down to ~0.1 m in world coordinates.  Straight corners are reported apart, neither
#: convex nor folded (:mod:`meshcore.quality.lake`'s ``straight``).
STRAIGHT_SINE = 1e-7


def corner_sines(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """``(4, ni, nj)`` sine of every cell corner (CCW: 00, 10, 11, 01); −1 at a zero-length edge
    (a collapsed cell counts as folded)."""
    p = [(x[:-1, :-1], y[:-1, :-1]), (x[1:, :-1], y[1:, :-1]), (x[1:, 1:], y[1:, 1:]), (x[:-1, 1:], y[:-1, 1:])]
    out = []
    for k in range(4):
        (px, py), (nx, ny), (bx, by) = p[k], p[(k + 1) % 4], p[(k - 1) % 4]
        ux, uy, vx, vy = nx - px, ny - py, bx - px, by - py
        den = np.hypot(ux, uy) * np.hypot(vx, vy)
        with np.errstate(divide="ignore", invalid="ignore"):
            out.append(np.where(den > 0, (ux * vy - uy * vx) / np.where(den > 0, den, 1.0), -1.0))
    return np.stack(out)


def cell_quality(grid: StructuredGrid) -> dict[str, np.ndarray]:
    """Per-cell quality arrays of shape ``(ni, nj)`` (see module docstring)."""
    x, y = grid.x, grid.y
    p = [
        (x[:-1, :-1], y[:-1, :-1]),  # 00
        (x[1:, :-1], y[1:, :-1]),  # 10
        (x[1:, 1:], y[1:, 1:]),  # 11
        (x[:-1, 1:], y[:-1, 1:]),  # 01
    ]
    cj = []
    angles = []
    lengths = []
    for k in range(4):
        px, py = p[k]
        nx, ny = p[(k + 1) % 4]
        bx, by = p[(k - 1) % 4]
        ax_, ay_ = nx - px, ny - py
        bx_, by_ = bx - px, by - py
        cross = ax_ * by_ - ay_ * bx_
        dot = ax_ * bx_ + ay_ * by_
        cj.append(cross)
        angles.append(np.degrees(np.arctan2(cross, dot)))  # signed, (−180, 180]
        lengths.append(np.hypot(ax_, ay_))
    cj_arr = np.stack(cj)
    ang = np.stack(angles)
    area = 0.5 * ((p[2][0] - p[0][0]) * (p[3][1] - p[1][1]) - (p[3][0] - p[1][0]) * (p[2][1] - p[0][1]))
    # angles of inverted corners are negative; use |angle| for deviation measures
    absang = np.where(ang < 0, 360.0 + ang, ang)
    orth = np.max(np.abs(absang - 90.0), axis=0)
    skew = np.maximum((absang.max(axis=0) - 90.0) / 90.0, (90.0 - absang.min(axis=0)) / 90.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        cmax = cj_arr.max(axis=0)
        jr = np.where(cmax > 0, cj_arr.min(axis=0) / np.where(cmax > 0, cmax, 1.0), -np.inf)
        lxi = 0.5 * (lengths[0] + lengths[2])  # edges 00→10 and 11→01
        leta = 0.5 * (lengths[1] + lengths[3])
        ar = np.maximum(lxi, leta) / np.minimum(lxi, leta)
        a = np.abs(area)
        sr = np.ones_like(area)
        for axis in (0, 1):
            if area.shape[axis] > 1:
                a0 = np.take(a, range(a.shape[axis] - 1), axis=axis)
                a1 = np.take(a, range(1, a.shape[axis]), axis=axis)
                r = np.maximum(a0 / a1, a1 / a0)
                pad = [(0, 0), (0, 0)]
                pad[axis] = (0, 1)
                sr = np.maximum(sr, np.pad(r, pad, constant_values=1.0))
                pad[axis] = (1, 0)
                sr = np.maximum(sr, np.pad(r, pad, constant_values=1.0))
        if grid.periodic and area.shape[0] > 1:
            r = np.maximum(a[0] / a[-1], a[-1] / a[0])
            sr[0] = np.maximum(sr[0], r)
            sr[-1] = np.maximum(sr[-1], r)
    sr = np.where(np.isfinite(sr), sr, np.inf)
    return {
        "area": area,
        "corner_jacobians": cj_arr,
        "jacobian_ratio": jr,
        "orthogonality": orth,
        "skewness": skew,
        "aspect_ratio": ar,
        "size_ratio": sr,
    }


@dataclass(frozen=True, slots=True, eq=False)
class QualityReport:
    """Summary of a grid's quality; ``str(report)`` prints a table."""

    cells: tuple[int, int]
    n_folded: int
    n_nonconvex: int
    folded: np.ndarray = field(repr=False)
    nonconvex: np.ndarray = field(repr=False)
    min_area: float
    max_area: float
    min_jacobian_ratio: float
    max_orthogonality: float
    mean_orthogonality: float
    max_skewness: float
    mean_skewness: float
    max_aspect_ratio: float
    mean_aspect_ratio: float
    max_size_ratio: float
    mean_size_ratio: float
    arrays: dict = field(repr=False, default_factory=dict)

    @property
    def ok(self) -> bool:
        """True when no cell is folded or non-convex."""
        return self.n_folded == 0 and self.n_nonconvex == 0

    def as_dict(self) -> dict[str, float | int]:
        return {
            "cells": f"{self.cells[0]}x{self.cells[1]}",
            "folded_cells": self.n_folded,
            "nonconvex_cells": self.n_nonconvex,
            "min_area": self.min_area,
            "max_area": self.max_area,
            "min_jacobian_ratio": self.min_jacobian_ratio,
            "max_orthogonality_deg": self.max_orthogonality,
            "mean_orthogonality_deg": self.mean_orthogonality,
            "max_skewness": self.max_skewness,
            "mean_skewness": self.mean_skewness,
            "max_aspect_ratio": self.max_aspect_ratio,
            "mean_aspect_ratio": self.mean_aspect_ratio,
            "max_size_ratio": self.max_size_ratio,
            "mean_size_ratio": self.mean_size_ratio,
        }

    def table(self) -> str:
        rows = [
            ("cells (ξ × η)", f"{self.cells[0]} × {self.cells[1]}", ""),
            ("folded cells", str(self.n_folded), "area ≤ 0"),
            ("non-convex cells", str(self.n_nonconvex), "a corner Jacobian ≤ 0"),
            ("cell area min / max", f"{self.min_area:.4g} / {self.max_area:.4g}", ""),
            ("min Jacobian ratio", f"{self.min_jacobian_ratio:.4f}", "min/max corner J, 1 = ideal"),
            (
                "orthogonality max / mean",
                f"{self.max_orthogonality:.2f}° / {self.mean_orthogonality:.2f}°",
                "deviation from 90°",
            ),
            ("skewness max / mean", f"{self.max_skewness:.4f} / {self.mean_skewness:.4f}", "equiangle, 0 = ideal"),
            ("aspect ratio max / mean", f"{self.max_aspect_ratio:.3f} / {self.mean_aspect_ratio:.3f}", ""),
            ("adjacent size ratio max / mean", f"{self.max_size_ratio:.3f} / {self.mean_size_ratio:.3f}", "≥ 1"),
        ]
        w0 = max(len(r[0]) for r in rows)
        w1 = max(len(r[1]) for r in rows)
        lines = [
            f"| {'metric'.ljust(w0)} | {'value'.ljust(w1)} | note |",
            f"|{'-' * (w0 + 2)}|{'-' * (w1 + 2)}|------|",
        ]
        lines += [f"| {a.ljust(w0)} | {b.ljust(w1)} | {c} |" for a, b, c in rows]
        return "\n".join(lines)

    def __str__(self) -> str:
        return self.table()


def quality(grid: StructuredGrid) -> QualityReport:
    """Quality report of ``grid``.

    Examples
    --------
    >>> import numpy as np
    >>> from meshcore import StructuredGrid
    >>> xi, eta = np.meshgrid(np.arange(4.0), np.arange(3.0), indexing="ij")
    >>> r = quality(StructuredGrid(xi, eta))
    >>> r.n_folded, r.max_orthogonality, r.max_aspect_ratio
    (0, 0.0, 1.0)
    """
    q = cell_quality(grid)
    area = q["area"]
    folded = np.argwhere(area <= 0)
    nonconvex = np.argwhere((corner_sines(grid.x, grid.y) < -STRAIGHT_SINE).any(axis=0))
    finite = lambda a: a[np.isfinite(a)] if np.isfinite(a).any() else np.array([np.inf])  # noqa: E731
    return QualityReport(
        cells=grid.cells,
        n_folded=len(folded),
        n_nonconvex=len(nonconvex),
        folded=folded,
        nonconvex=nonconvex,
        min_area=float(area.min()),
        max_area=float(area.max()),
        min_jacobian_ratio=float(q["jacobian_ratio"].min()),
        max_orthogonality=float(q["orthogonality"].max()),
        mean_orthogonality=float(q["orthogonality"].mean()),
        max_skewness=float(q["skewness"].max()),
        mean_skewness=float(q["skewness"].mean()),
        max_aspect_ratio=float(finite(q["aspect_ratio"]).max()),
        mean_aspect_ratio=float(finite(q["aspect_ratio"]).mean()),
        max_size_ratio=float(finite(q["size_ratio"]).max()),
        mean_size_ratio=float(finite(q["size_ratio"]).mean()),
        arrays=q,
    )
