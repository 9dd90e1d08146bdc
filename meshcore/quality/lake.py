r"""Grid quality in lake modellers' terms (definitions: ``shared/design/lake-grids.md``).

Per block, on the node arrays ``x, y`` of shape ``(ni + 1, nj + 1)``:

* ``cos`` — node orthogonality at every **block-interior** node,
  ``|x_ξ·x_η| / (|x_ξ||x_η|)`` with central differences
  ``x_ξ = P[i+1, j] − P[i−1, j]``, ``x_η = P[i, j+1] − P[i, j−1]``
  (Delft3D/RGFGRID quote ``< 0.02``);
* ``deviation`` — ``asin(cos)`` in degrees at the same nodes (EFDC: ``< 3°``);
* ``smoothness`` — at every node inside a grid line, ``max(l₂/l₁, l₁/l₂)`` of
  the two consecutive edges along the line, for ξ-lines and η-lines
  (RGFGRID: 1.1–1.2);
* ``aspect_ratio`` — per cell, the longer over the shorter of its two edges
  from the ``(i, j)`` corner;
* ``shrink`` — per cell, the grid's mean cell size ``h = sqrt(grid area / cells)`` (or the
  ``cell_size`` given) over the cell's shortest edge: by about this factor a cell shortens the
  time step an explicit model may take there (Courant), against a grid of cells of size ``h``;
* ``folded`` — per cell, 1 when any of its four corner Jacobians is ``< 0``
  relative to the block's orientation beyond rounding (folded or non-convex:
  a corner sine below ``−``:data:`~.cells.STRAIGHT_SINE`), else 0;
* ``straight`` — per cell, 1 when it is not folded and a corner is straight up
  to rounding (a triangle with a 180° angle: its Jacobian's sign would be the
  rounding's, read one way in local and the other in world coordinates);
* ``interface_ratio`` — for two cells of different blocks that share an edge,
  ``max(A₁/A₂, A₂/A₁)``.  Shared edges are found from the coordinates (both
  end nodes coincide within ``1e-7`` of the domain size), so the same code
  serves a :class:`~meshcore.multiblock.MultiBlockGrid`, the blocks read from
  a file and partial (T-junction) interfaces.

Node-shaped arrays hold NaN where a metric is not defined (border nodes for
``cos``; line ends for smoothness).  For an O-grid (``periodic``) the ξ seam is
interior: nodes ``i = 0`` get central differences across it and column
``i = ni`` (a copy of column 0) is NaN.  Every metric is invariant under
translation, rotation and uniform scaling.  Coverage against the water
polygon is in :mod:`.coverage`; limits and verdicts in :mod:`.presets`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import InvalidInputError
from ..grid import StructuredGrid
from .cells import STRAIGHT_SINE, corner_sines
from .interfaces import interface_pairs, no_pairs, ratio, signed_area
from .samples import Samples, format_table, ok_percent

__all__ = [
    "METRICS",
    "SHRINK_NOTE",
    "BlockMetrics",
    "LakeMetrics",
    "Location",
    "Samples",
    "block_metrics",
    "cell_shrink",
    "corner_edges",
    "corner_jacobians",
    "interface_pairs",
    "lake_metrics",
    "mean_cell_size",
    "node_cos",
    "shortest_edge_words",
    "small_edge",
]

#: metric → (what it is measured on, description, unit); "worst" is always the largest value.
METRICS: dict[str, tuple[str, str, str]] = {
    "cos": ("nodes", "node orthogonality |cos|", ""),
    "deviation": ("nodes", "deviation from 90°", "°"),
    "smoothness": ("edge pairs", "consecutive edge-length ratio", ""),
    "aspect_ratio": ("cells", "aspect ratio", ""),
    "shrink": ("cells", "mean cell size ÷ the cell's shortest edge", ""),
    "folded": ("cells", "folded or non-convex (1) cells", ""),
    "straight": ("cells", "cells with a straight (180°) corner (1)", ""),
    "interface_ratio": ("cell pairs", "cross-interface cell-area ratio", ""),
    "area_error": ("grid", "|grid area / polygon area − 1|", ""),
    "shore_distance": ("grid", "Hausdorff distance grid boundary ↔ shoreline", " cells"),
}


#: A cell whose shortest edge is under the mean cell size over this is told on its own (``meshcore
#: mesh`` on stderr, :meth:`LakeMetrics.small_cell_note`): there an explicit model's time step is
#: this many times shorter than on the rest of the grid.  Held-out lakes at 10 000 cells: 3 of 28
#: in set 27 (fans of a block into a short side, session 40).
SHRINK_NOTE = 50.0


def small_edge(least: float | None, limit: float | None = None) -> bool:
    """A grid's shortest edge ``least``, in mean cell sizes (the summary's ``min_edge_cells``; None or NaN
    without cells or area), is at most ``1 / limit`` (default :data:`SHRINK_NOTE`): its cell is told on
    its own (:meth:`LakeMetrics.small_cell_note`, the app's lake verdict)."""
    limit = SHRINK_NOTE if limit is None else limit
    return least is not None and bool(least <= 1.0 / limit)


def shortest_edge_words(least: float | None) -> str:
    """A grid's shortest edge ``least`` in mean cell sizes (the summary's ``min_edge_cells``) and what it
    costs an explicit model's time step: the one wording of the quality table's row, of ``meshcore
    mesh``'s note (:meth:`LakeMetrics.small_cell_note`) and of the app's lake verdict.

    >>> shortest_edge_words(0.0123)
    '0.0123 cells (explicit time step ÷ 81.3)'
    >>> shortest_edge_words(0.0)
    '0 cells (a collapsed edge: an explicit model cannot step there)'
    >>> shortest_edge_words(None)  # no cells, or no area to measure them by
    '—'
    """
    if least is None or not least >= 0.0:
        return "—"
    if least == 0.0:
        return "0 cells (a collapsed edge: an explicit model cannot step there)"
    return f"{least:.3g} cells (explicit time step ÷ {1.0 / least:.3g})"


@dataclass(frozen=True, slots=True)
class Location:
    """One value of a metric and where it is: block, ``(i, j)`` (node or cell), ``(x, y)``."""

    value: float
    block: str
    i: int
    j: int
    x: float
    y: float
    note: str = ""  # e.g. "ξ-line", or the partner cell of an interface pair

    def __str__(self) -> str:
        where = f"{self.block}({self.i},{self.j})" if self.block else "grid"
        extra = f" {self.note}" if self.note else ""
        return f"{self.value:.4g} at {where}{extra} ({self.x:.8g}, {self.y:.8g})"


@dataclass(frozen=True, slots=True, eq=False)
class BlockMetrics:
    """Per-node and per-cell arrays of one block (see module docstring)."""

    name: str
    cos: np.ndarray  # (ni+1, nj+1), NaN off block-interior nodes
    deviation: np.ndarray  # degrees, same shape
    smooth_xi: np.ndarray  # (ni+1, nj+1): ratio of the two ξ-edges meeting at the node
    smooth_eta: np.ndarray  # (ni+1, nj+1): the same along η
    aspect_ratio: np.ndarray  # (ni, nj)
    area: np.ndarray  # (ni, nj) signed area, positive in the block's orientation
    folded: np.ndarray  # (ni, nj) bool: a corner Jacobian < 0 beyond rounding
    straight: np.ndarray  # (ni, nj) bool: not folded, a corner straight up to rounding
    shortest: np.ndarray  # (ni, nj) the shortest of the cell's four edges


def node_cos(x: np.ndarray, y: np.ndarray, periodic: bool = False) -> np.ndarray:
    """|cos| of the angle between the grid lines at every node (central differences), NaN where
    it is not defined (block borders; a periodic block's seam wraps); 1 at a collapsed node."""
    cos = np.full(x.shape, np.nan)
    if x.shape[1] < 3 or (x.shape[0] < 3 and not periodic):
        return cos
    if periodic:  # core columns 0..ni-1, wrapping over the seam
        cx, cy = x[:-1], y[:-1]
        ax = np.roll(cx, -1, axis=0) - np.roll(cx, 1, axis=0)
        ay = np.roll(cy, -1, axis=0) - np.roll(cy, 1, axis=0)
        ax, ay = ax[:, 1:-1], ay[:, 1:-1]
        bx, by = cx[:, 2:] - cx[:, :-2], cy[:, 2:] - cy[:, :-2]
        target = (slice(0, -1), slice(1, -1))
    else:
        ax, ay = x[2:, 1:-1] - x[:-2, 1:-1], y[2:, 1:-1] - y[:-2, 1:-1]
        bx, by = x[1:-1, 2:] - x[1:-1, :-2], y[1:-1, 2:] - y[1:-1, :-2]
        target = (slice(1, -1), slice(1, -1))
    norm = np.hypot(ax, ay) * np.hypot(bx, by)
    with np.errstate(divide="ignore", invalid="ignore"):
        c = np.abs(ax * bx + ay * by) / norm
    cos[target] = np.where(norm > 0, np.minimum(c, 1.0), 1.0)  # a collapsed node counts as worst
    return cos


def _smoothness(x: np.ndarray, y: np.ndarray, periodic: bool) -> tuple[np.ndarray, np.ndarray]:
    sxi = np.full(x.shape, np.nan)
    seta = np.full(x.shape, np.nan)
    lxi = np.hypot(np.diff(x, axis=0), np.diff(y, axis=0))  # (ni, nj+1): edge i from node i to i+1
    leta = np.hypot(np.diff(x, axis=1), np.diff(y, axis=1))  # (ni+1, nj)
    sxi[1:-1] = ratio(lxi[:-1], lxi[1:])
    if periodic:  # node 0 (= node ni) sits between the last and the first edge
        sxi[0] = ratio(lxi[-1], lxi[0])
    seta[:, 1:-1] = ratio(leta[:, :-1], leta[:, 1:])
    return sxi, seta


def corner_edges(x: np.ndarray, y: np.ndarray) -> list[tuple[Any, Any, Any, Any]]:
    """The two edges at each cell corner (CCW: 00, 10, 11, 01), to the next corner and from the
    one before: four ``(ux, uy, vx, vy)`` of ``(ni, nj)`` arrays."""
    p = [(x[:-1, :-1], y[:-1, :-1]), (x[1:, :-1], y[1:, :-1]), (x[1:, 1:], y[1:, 1:]), (x[:-1, 1:], y[:-1, 1:])]
    out = []
    for k in range(4):
        (px, py), (nx, ny), (bx, by) = p[k], p[(k + 1) % 4], p[(k - 1) % 4]
        out.append((nx - px, ny - py, bx - px, by - py))
    return out


def corner_jacobians(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """``(4, ni, nj)`` cross products of the two edges at each corner (CCW: 00, 10, 11, 01)."""
    return np.stack([ux * vy - uy * vx for ux, uy, vx, vy in corner_edges(x, y)])


def block_metrics(grid: StructuredGrid, name: str = "block1") -> BlockMetrics:
    """All per-block arrays of ``grid`` (see the module docstring for the definitions)."""
    x, y = np.asarray(grid.x), np.asarray(grid.y)
    cos = node_cos(x, y, grid.periodic)
    dev = np.degrees(np.arcsin(cos))
    sxi, seta = _smoothness(x, y, grid.periodic)
    exi = np.hypot(np.diff(x, axis=0), np.diff(y, axis=0))  # (ni, nj + 1): every ξ-edge
    eeta = np.hypot(np.diff(x, axis=1), np.diff(y, axis=1))  # (ni + 1, nj): every η-edge
    lxi, leta = exi[:, :-1], eeta[:-1]  # the two edges from each cell's (i, j) corner
    area = signed_area(x, y)
    orient = -1.0 if area.sum() < 0 else 1.0  # a mirrored (clockwise) block is judged in its own sense
    sines = orient * corner_sines(x, y)
    folded = np.asarray((sines < -STRAIGHT_SINE).any(axis=0))
    straight = np.asarray((sines <= STRAIGHT_SINE).any(axis=0)) & ~folded
    shortest = np.minimum(np.minimum(exi[:, :-1], exi[:, 1:]), np.minimum(eeta[:-1], eeta[1:]))
    return BlockMetrics(name, cos, dev, sxi, seta, ratio(lxi, leta), orient * area, folded, straight, shortest)


def _names(obj: Any, n: int) -> tuple[str, ...]:
    names = getattr(obj, "names", None)
    if not isinstance(names, (tuple, list)):
        names = getattr(obj, "block_names", None)
    if isinstance(names, (tuple, list)) and len(names) == n:
        return tuple(str(s) for s in names)
    return tuple(f"block{k + 1}" for k in range(n))


def as_grids(obj: Any) -> tuple[tuple[StructuredGrid, ...], tuple[str, ...]]:
    """A grid, a sequence or ``{name: grid}`` of grids, a MultiBlockGrid or a GridSet → (grids, names)."""
    if isinstance(obj, StructuredGrid):
        return (obj,), (str(obj.names.get("block", "block1")),)
    if isinstance(obj, Mapping):
        return as_grids(list(obj.values()))[0], tuple(str(k) for k in obj)
    seq = getattr(obj, "grids", None) or getattr(obj, "blocks", None) or obj
    try:
        grids = tuple(seq)
    except TypeError:
        raise InvalidInputError(f"expected a grid or a multiblock grid, got {type(obj).__name__}") from None
    if not grids or not all(isinstance(g, StructuredGrid) for g in grids):
        raise InvalidInputError(f"expected a grid or a sequence of grids, got {type(obj).__name__}")
    return grids, _names(obj, len(grids))


def _collect(metric: str, parts: list[tuple], axis: list | None = None) -> Samples:
    """Stack per-block ``(k, values, x, y)`` arrays (NaN = undefined) into one :class:`Samples`."""
    vals, blk, ii, jj, xs, ys, ax = [], [], [], [], [], [], []
    for n, (k, arr, x, y) in enumerate(parts):
        i, j = np.nonzero(~np.isnan(arr))  # NaN: not defined there; inf (collapsed) is kept
        vals.append(arr[i, j])
        blk.append(np.full(len(i), k))
        ii.append(i)
        jj.append(j)
        xs.append(x[i, j])
        ys.append(y[i, j])
        if axis is not None:
            ax.append(np.full(len(i), axis[n]))
    cat = lambda a, dt=float: np.concatenate(a).astype(dt) if a else np.zeros(0, dt)  # noqa: E731
    return Samples(
        metric,
        cat(vals),
        cat(blk, np.int64),
        cat(ii, np.int64),
        cat(jj, np.int64),
        cat(xs),
        cat(ys),
        axis=cat(ax, np.int8) if axis is not None else None,
    )


def mean_cell_size(bms: Sequence[BlockMetrics]) -> float:
    """``sqrt(grid area / cells)`` of the blocks' metrics (0 for no cells)."""
    cells = sum(b.area.size for b in bms)
    return float(np.sqrt(sum(float(np.abs(b.area).sum()) for b in bms) / cells)) if cells else 0.0


def cell_shrink(shortest: np.ndarray, h: float) -> np.ndarray:
    """``shrink`` of cells whose shortest edges are ``shortest`` in a grid of mean cell size ``h``:
    ``h / shortest`` (inf for a collapsed edge)."""
    with np.errstate(divide="ignore"):
        return np.where(shortest > 0, h / np.where(shortest > 0, shortest, 1.0), np.inf)


def _samples(grids: Sequence[StructuredGrid], bms: Sequence[BlockMetrics], pairs: dict, h: float) -> dict[str, Samples]:
    nodes = [(k, np.asarray(g.x), np.asarray(g.y)) for k, g in enumerate(grids)]
    cents = []
    for k, g in enumerate(grids):
        x, y = np.asarray(g.x), np.asarray(g.y)
        cx = 0.25 * (x[:-1, :-1] + x[1:, :-1] + x[1:, 1:] + x[:-1, 1:])
        cy = 0.25 * (y[:-1, :-1] + y[1:, :-1] + y[1:, 1:] + y[:-1, 1:])
        cents.append((k, cx, cy))
    out = {
        "cos": _collect("cos", [(k, b.cos, x, y) for (k, x, y), b in zip(nodes, bms, strict=True)]),
        "deviation": _collect("deviation", [(k, b.deviation, x, y) for (k, x, y), b in zip(nodes, bms, strict=True)]),
        "smoothness": _collect(
            "smoothness",
            [(k, a, x, y) for (k, x, y), b in zip(nodes, bms, strict=True) for a in (b.smooth_xi, b.smooth_eta)],
            axis=[ax for _ in bms for ax in (0, 1)],
        ),
        "aspect_ratio": _collect(
            "aspect_ratio", [(k, b.aspect_ratio, cx, cy) for (k, cx, cy), b in zip(cents, bms, strict=True)]
        ),
        "shrink": _collect(
            "shrink", [(k, cell_shrink(b.shortest, h), cx, cy) for (k, cx, cy), b in zip(cents, bms, strict=True)]
        ),
        "folded": _collect(
            "folded", [(k, b.folded.astype(float), cx, cy) for (k, cx, cy), b in zip(cents, bms, strict=True)]
        ),
        "straight": _collect(
            "straight", [(k, b.straight.astype(float), cx, cy) for (k, cx, cy), b in zip(cents, bms, strict=True)]
        ),
    }
    ca = pairs["cell_a"]
    out["interface_ratio"] = Samples(
        "interface_ratio",
        pairs["ratio"],
        ca[:, 0],
        ca[:, 1],
        ca[:, 2],
        pairs["mid"][:, 0],
        pairs["mid"][:, 1],
        partner=pairs["cell_b"],
    )
    return out


@dataclass(frozen=True, slots=True, eq=False)
class LakeMetrics:
    """The lake-grid metrics of a single- or multiblock grid (see :func:`lake_metrics`).

    ``blocks`` holds the per-node/per-cell arrays of each block (for colouring
    a figure); ``samples`` every value of every metric with its place (for
    shares and worst places); ``coverage`` is ``None`` without a polygon.
    """

    names: tuple[str, ...]
    blocks: tuple[BlockMetrics, ...]
    samples: dict[str, Samples] = field(repr=False)
    coverage: Any = None  # meshcore.quality.coverage.Coverage
    cell_size: float = 0.0  # the unit of ``shrink``: as given, or ``sqrt(grid area / cells)``

    def values(self, metric: str) -> np.ndarray:
        """Every value of ``metric`` (a key of :data:`METRICS`)."""
        if metric not in METRICS:
            raise InvalidInputError(f"unknown metric {metric!r}; known: {', '.join(METRICS)}")
        s = self.samples.get(metric)
        return s.values if s is not None else np.zeros(0)

    def share(self, metric: str, limit: float) -> float:
        """Share (0…1) of the values of ``metric`` that are ``≤ limit``; NaN when there are none."""
        v = self.values(metric)
        return float(np.mean(v <= limit)) if len(v) else float("nan")

    def mean(self, metric: str) -> float:
        v = self.values(metric)
        return float(np.mean(v)) if len(v) else float("nan")

    def max(self, metric: str) -> float:
        v = self.values(metric)
        return float(np.max(v)) if len(v) else float("nan")

    def worst(self, metric: str, k: int = 5, *, above: float | None = None) -> tuple[Location, ...]:
        """The ``k`` largest values of ``metric`` (only those ``> above`` if given), worst first."""
        v = self.values(metric)
        s = self.samples.get(metric)
        if s is None or not len(v):
            return ()
        idx = np.flatnonzero(v > above) if above is not None else np.arange(len(v))
        if k is not None and len(idx) > k:
            idx = idx[np.argpartition(-v[idx], k - 1)[:k]]
        idx = idx[np.lexsort((idx, -v[idx]))]
        return tuple(self._location(s, int(n)) for n in idx)

    def _location(self, s: Samples, n: int) -> Location:
        b = int(s.block[n])
        note = ""
        if s.axis is not None:
            note = "ξ-line" if s.axis[n] == 0 else "η-line"
        if s.partner is not None:
            pb, pi, pj = (int(t) for t in s.partner[n])
            note = f"| {self.names[pb]}({pi},{pj})"
        name = self.names[b] if b >= 0 else ""
        return Location(float(s.values[n]), name, int(s.i[n]), int(s.j[n]), float(s.x[n]), float(s.y[n]), note)

    def summary(self) -> dict[str, float | None]:
        """The headline numbers (shares in %, angles in degrees; None where undefined)."""
        out = {
            "blocks": len(self.blocks),
            "cells": int(sum(b.area.size for b in self.blocks)),
            "interior_nodes": len(self.values("cos")),
            "mean_deviation_deg": self.mean("deviation"),
            "max_deviation_deg": self.max("deviation"),
            "pct_nodes_within_3deg": 100 * self.share("deviation", 3.0),
            "pct_nodes_cos_le_0.02": 100 * self.share("cos", 0.02),
            "pct_nodes_cos_le_0.05": 100 * self.share("cos", 0.05),
            "pct_smoothness_le_1.2": 100 * self.share("smoothness", 1.2),
            "max_smoothness": self.max("smoothness"),
            "max_aspect_ratio": self.max("aspect_ratio"),
            "mean_aspect_ratio": self.mean("aspect_ratio"),
            "min_edge_cells": self._min_edge_cells(),
            "folded_cells": int(self.values("folded").sum()),
            "straight_angle_cells": int(self.values("straight").sum()),
            "interface_cell_pairs": len(self.values("interface_ratio")),
            "max_interface_ratio": self.max("interface_ratio"),
        }
        if self.coverage is not None:
            out.update(self.coverage.as_dict())
        return {k: (None if isinstance(v, float) and np.isnan(v) else v) for k, v in out.items()}

    def table(self) -> str:
        """A short Markdown table of the headline numbers with the worst places."""

        def w(metric: str) -> str:
            loc = self.worst(metric, 1)
            return str(loc[0]) if loc else "—"

        n_folded = int(self.values("folded").sum())
        rows = [
            (
                "blocks / cells / interior nodes",
                f"{len(self.blocks)} / {self.summary()['cells']} / {len(self.values('cos'))}",
                "",
            ),
            (
                "deviation from 90°, mean / max",
                f"{self.mean('deviation'):.2f}° / {self.max('deviation'):.2f}°",
                w("deviation"),
            ),
            (  # shares within a limit rounded down, as the verdicts print them (94.98 % is not 95.0)
                "nodes within 3° / |cos| ≤ 0.02 / ≤ 0.05",
                f"{self._ok('deviation', 3.0)} % / {self._ok('cos', 0.02)} % / {self._ok('cos', 0.05)} %",
                "",
            ),
            (
                "edge pairs with ratio ≤ 1.2 / max",
                f"{self._ok('smoothness', 1.2)} % / {self.max('smoothness'):.3g}",
                w("smoothness"),
            ),
            (
                "aspect ratio mean / max",
                f"{self.mean('aspect_ratio'):.3g} / {self.max('aspect_ratio'):.3g}",
                w("aspect_ratio"),
            ),
            self._shortest_row(w),
            ("folded or non-convex cells", str(n_folded), w("folded") if n_folded else ""),
        ]
        n_straight = int(self.values("straight").sum())
        if n_straight:  # triangles: not folded, but no model grid wants them
            rows.append(("cells with a straight (180°) corner", str(n_straight), w("straight")))
        if len(self.values("interface_ratio")):
            rows.append(("cross-interface area ratio max", f"{self.max('interface_ratio'):.3g}", w("interface_ratio")))
        if self.coverage is not None:
            rows += self.coverage.rows()
        return format_table(("metric", "value", "worst at"), rows)

    def _ok(self, metric: str, limit: float) -> str:
        """:meth:`share` in per cent, rounded down to a tenth (:func:`~.samples.ok_percent`)."""
        share = self.share(metric, limit)
        return "—" if np.isnan(share) else ok_percent(share)

    def _min_edge_cells(self) -> float:
        """The shortest edge of the grid over the mean cell size (NaN without cells or area)."""
        shortest = [float(b.shortest.min()) for b in self.blocks if b.shortest.size]
        if not shortest or not self.cell_size > 0:
            return float("nan")
        return min(shortest) / self.cell_size

    def _shortest_row(self, w) -> tuple[str, str, str]:
        """The table's row of the shortest edge: in mean cell sizes, and what it costs an explicit
        model's time step (:func:`shortest_edge_words`; its worst place is the cell with the largest
        ``shrink``)."""
        value = shortest_edge_words(self._min_edge_cells())
        return ("shortest edge (in mean cell sizes)", value, w("shrink") if len(self.values("shrink")) else "")

    def small_cell_note(self, limit: float | None = None) -> str | None:
        """A sentence about the cell with the shortest edge when that edge is at most ``1 / limit`` of
        the mean cell size (default :data:`SHRINK_NOTE`, :func:`small_edge`), else None."""
        least = self._min_edge_cells()
        worst = self.worst("shrink", 1)
        if not worst or not small_edge(least, limit):
            return None
        w = worst[0]
        return (
            f"cell {w.block}({w.i},{w.j}) near ({w.x:.8g}, {w.y:.8g}) has the grid's shortest edge, "
            f"{shortest_edge_words(least)}: the grid's lines crowd into a short side or a corner; another cell "
            f"size or an edit of the layout there moves them"
        )

    def __str__(self) -> str:
        return self.table()


def lake_metrics(
    grid: Any,
    *,
    polygon: Any = None,
    holes: Sequence[Any] = (),
    cell_size: float | None = None,
    arms: Sequence[Any] | None = None,
) -> LakeMetrics:
    """Measure a grid the way lake modellers do (``shared/design/lake-grids.md``).

    Parameters
    ----------
    grid : StructuredGrid, MultiBlockGrid, GridSet, sequence or ``{name: grid}`` of StructuredGrid
    polygon : shapely Polygon/MultiPolygon or (n, 2) array, optional
        The water polygon, in the grid's coordinates; with it the report has
        the coverage (area ratio, Hausdorff distance of the shoreline).
    holes : sequence of (m, 2) arrays
        Islands, when ``polygon`` is given as the outer ring's points.
    cell_size : float, optional
        Unit of the shoreline distance and of ``shrink``; default ``sqrt(grid area / cells)``.
    arms : sequence of shapely Polygons, optional
        The dead-end arms the layout left out (:class:`meshcore.layout.Layout` ``arms``, in the grid's
        coordinates): the shoreline distance is measured across their mouths.  By default a
        MultiBlockGrid's own (``grid.arms``), else the layout's rule finds them again on ``polygon``
        (:func:`meshcore.layout.shore.without_narrow_arms`).

    Returns
    -------
    LakeMetrics

    Examples
    --------
    >>> import numpy as np
    >>> from meshcore import StructuredGrid
    >>> xi, eta = np.meshgrid(np.arange(5.0), np.arange(4.0), indexing="ij")
    >>> m = lake_metrics(StructuredGrid(xi + 0.5 * eta, eta))   # sheared: cos = 1/√5
    >>> round(m.max("cos"), 6), m.share("deviation", 3.0), m.max("smoothness")
    (0.447214, 0.0, 1.0)
    """
    grids, names = as_grids(grid)
    bms = tuple(block_metrics(g, n) for g, n in zip(grids, names, strict=True))
    h = float(cell_size) if cell_size else mean_cell_size(bms)
    samples = _samples(grids, bms, interface_pairs(grids) if len(grids) > 1 else no_pairs(), h)
    cov = None
    if polygon is not None:
        from .coverage import coverage

        if arms is None:
            arms = getattr(grid, "arms", None)  # a lake grid's (MultiBlockGrid)
        cov = coverage(grids, bms, polygon, holes=holes, cell_size=cell_size, arms=arms)
        samples["area_error"] = cov.samples("area_error")
        samples["shore_distance"] = cov.samples("shore_distance")
    return LakeMetrics(names, bms, samples, cov, h)
