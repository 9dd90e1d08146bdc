r"""Limits that hydrodynamic models put on a grid, and a verdict against them.

A :class:`Preset` is frozen data: a name, the limits, and where they come from.
:func:`check` measures a grid (:func:`~.lake.lake_metrics`) and says, for each
limit, how many nodes, cells or edge pairs miss it and where, worst first:

>>> import numpy as np
>>> from meshcore import StructuredGrid
>>> xi, eta = np.meshgrid(np.arange(6.0), np.arange(5.0), indexing="ij")
>>> v = check(StructuredGrid(xi + 0.01 * eta**2, eta), "delft3d")  # |cos| ≈ 0.02 j at row j
>>> v.passed, [(r.limit.metric, r.n_checked, r.n_failed) for r in v.results]
(False, [('cos', 12, 8), ('smoothness', 38, 0), ('folded', 20, 0)])
>>> print(v)  # doctest: +ELLIPSIS
delft3d: Delft3D-FLOW / RGFGRID curvilinear grids
| limit ...

A limit applies to every item (``statistic="each"``; ``share`` is the fraction
that must meet it, 1.0 = all) or to the mean (``statistic="mean"``).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._validation import validate_choice
from ..errors import InvalidInputError
from .lake import METRICS, LakeMetrics, Location, lake_metrics
from .samples import format_table, ok_percent

__all__ = ["PRESETS", "Limit", "LimitResult", "Preset", "Verdict", "check", "format_table", "ok_percent"]


@dataclass(frozen=True, slots=True)
class Limit:
    """``metric ≤ max`` for ``share`` of the items (or for their mean)."""

    metric: str
    max: float
    share: float = 1.0
    statistic: str = "each"  # "each" | "mean"

    def __post_init__(self) -> None:
        if self.metric not in METRICS:
            raise InvalidInputError(f"limit: unknown metric {self.metric!r}; known: {', '.join(METRICS)}")
        validate_choice(self.statistic, ("each", "mean"), name="statistic")

    @property
    def applies_to(self) -> str:
        return METRICS[self.metric][0]

    @property
    def label(self) -> str:
        _, what, unit = METRICS[self.metric]
        if self.metric == "folded":
            return "folded or non-convex cells: none"
        if self.statistic == "mean":
            return f"mean {what} ≤ {self.max:g}{unit}"
        share = "" if self.share >= 1.0 else f" at ≥ {100 * self.share:g} %"
        return f"{what} ≤ {self.max:g}{unit}{share}"


@dataclass(frozen=True, slots=True)
class Preset:
    """A named set of limits with the source that states them."""

    name: str
    title: str
    limits: tuple[Limit, ...]
    source: str


PRESETS: dict[str, Preset] = {
    p.name: p
    for p in (
        Preset(
            "delft3d",
            "Delft3D-FLOW / RGFGRID curvilinear grids",
            (Limit("cos", 0.02), Limit("smoothness", 1.2), Limit("folded", 0.0)),
            "Deltares, Introductory course Delft3D-RGFGRID: grids must be 'orthogonal (< 0.02)' and "
            "'smooth w.r.t. consecutive grid cells (10 - 20 %)'",
        ),
        Preset(
            "efdc",
            "EFDC / EFDC+ curvilinear orthogonal grids",
            (Limit("deviation", 3.0), Limit("deviation", 3.0, statistic="mean"), Limit("folded", 0.0)),
            "EFDC+ Explorer reference, Grid Tools: deviation angles 'as low as practical (e.g. < 3 degrees)'; "
            "CVLGrid knowledge base, Introduction: 'the average orthogonal deviation ... should be less than 3°'",
        ),
        Preset(
            "gcmesh-lake",
            "gcmesh lake-grid targets (issue 12)",
            (
                Limit("deviation", 3.0, share=0.9),
                Limit("deviation", 3.0, statistic="mean"),
                Limit("cos", 0.02, share=0.8),
                Limit("smoothness", 1.2, share=0.95),
                Limit("interface_ratio", 2.0),
                Limit("folded", 0.0),
                Limit("area_error", 0.01),
                Limit("shore_distance", 0.5),
            ),
            "gcmesh issue 12, 'Targets': ≥ 90 % of block-interior nodes within 3° and mean ≤ 3°, "
            "|cos| ≤ 0.02 at ≥ 80 %, ≥ 95 % of edge pairs ≤ 1.2, cross-interface area ratio ≤ 2, "
            "0 folded cells, grid area within 1 % of the polygon's, shoreline within 0.5 cells",
        ),
    )
}


@dataclass(frozen=True, slots=True)
class LimitResult:
    """How one limit fared: counts, the statistic, and the worst places."""

    limit: Limit
    n_checked: int
    n_failed: int
    value: float  # share of items meeting the limit (each), or the mean (mean); NaN when unchecked
    passed: bool | None  # None: nothing to check (e.g. no polygon, no interface)
    worst: tuple[Location, ...]

    def as_dict(self) -> dict[str, Any]:
        return {
            "limit": self.limit.label,
            "metric": self.limit.metric,
            "applies_to": self.limit.applies_to,
            "checked": self.n_checked,
            "failed": self.n_failed,
            "value": None if math.isnan(self.value) else self.value,
            "passed": self.passed,
            "worst": [
                {"value": w.value, "block": w.block, "i": w.i, "j": w.j, "x": w.x, "y": w.y, "note": w.note}
                for w in self.worst
            ],
        }


@dataclass(frozen=True, slots=True, eq=False)
class Verdict:
    """The result of :func:`check`; ``str(verdict)`` prints a short table."""

    preset: Preset
    results: tuple[LimitResult, ...]
    metrics: LakeMetrics

    @property
    def passed(self) -> bool:
        """True when every limit that could be checked is met."""
        return all(r.passed is not False for r in self.results)

    @property
    def failed(self) -> tuple[LimitResult, ...]:
        return tuple(r for r in self.results if r.passed is False)

    def as_dict(self) -> dict[str, Any]:
        return {
            "preset": self.preset.name,
            "source": self.preset.source,
            "passed": self.passed,
            "limits": [r.as_dict() for r in self.results],
        }

    def table(self, places: int = 3) -> str:
        rows = []
        for r in self.results:
            if r.passed is None:
                rows.append((r.limit.label, r.limit.applies_to, "—", "—", "not checked", ""))
                continue
            stat = f"mean {r.value:.4g}" if r.limit.statistic == "mean" else f"{ok_percent(r.value)} % ok"
            rows.append(
                (
                    r.limit.label,
                    r.limit.applies_to,
                    str(r.n_checked),
                    str(r.n_failed),
                    f"{'pass' if r.passed else 'FAIL'} ({stat})",
                    str(r.worst[0]) if r.worst else "",
                )
            )
        head = f"{self.preset.name}: {self.preset.title}\n"
        body = format_table(("limit", "applies to", "checked", "miss", "verdict", "worst at"), rows)
        more = []
        for r in self.failed:
            if len(r.worst) > 1 and r.limit.statistic == "each":
                more.append(f"  {r.limit.label}, next worst: " + "; ".join(str(w) for w in r.worst[1:places]))
        n_fail = len(self.failed)
        tail = f"verdict: {'PASS' if self.passed else f'FAIL ({n_fail} of {len(self.results)} limits missed)'}"
        return head + body + "\n" + "\n".join(more + [tail, f"source: {self.preset.source}"])

    def __str__(self) -> str:
        return self.table()


def _result(m: LakeMetrics, lim: Limit, k: int) -> LimitResult:
    v = m.values(lim.metric)
    if not len(v):
        return LimitResult(lim, 0, 0, math.nan, None, ())
    bad = ~(v <= lim.max)  # NaN never passes
    n_bad = int(bad.sum())
    worst = m.worst(lim.metric, k, above=lim.max) if n_bad else ()
    if lim.statistic == "mean":
        mean = float(np.mean(v))
        return LimitResult(lim, len(v), n_bad, mean, bool(mean <= lim.max), worst)
    ok = 1.0 - n_bad / len(v)
    return LimitResult(lim, len(v), n_bad, ok, bool(ok >= lim.share - 1e-12), worst)


def check(
    grid: Any,
    preset: str | Preset = "delft3d",
    *,
    polygon: Any = None,
    holes: Sequence[Any] = (),
    worst: int = 5,
) -> Verdict:
    """Check a grid against a preset's limits.

    Parameters
    ----------
    grid : StructuredGrid, MultiBlockGrid, GridSet, sequence of grids, or LakeMetrics
        A :class:`~.lake.LakeMetrics` is used as it is (measure once, check many).
    preset : str or Preset
        A name in :data:`PRESETS` (``"delft3d"``, ``"efdc"``, ``"gcmesh-lake"``) or your own.
    polygon, holes : optional
        The water polygon for the coverage limits (see :func:`~.lake.lake_metrics`).
    worst : int
        How many of the worst places to keep per limit.

    Returns
    -------
    Verdict
    """
    if isinstance(preset, str):
        if preset not in PRESETS:
            raise InvalidInputError(f"unknown quality preset {preset!r}; known: {', '.join(PRESETS)}")
        preset = PRESETS[preset]
    m = grid if isinstance(grid, LakeMetrics) else lake_metrics(grid, polygon=polygon, holes=holes)
    return Verdict(preset, tuple(_result(m, lim, worst) for lim in preset.limits), m)
