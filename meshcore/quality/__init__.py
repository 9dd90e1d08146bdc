"""Grid quality: cell metrics, the lake modellers' metrics, and model presets.

* :mod:`.cells` — per-cell folds, corner Jacobians, skewness, aspect, growth;
  :func:`quality` → :class:`QualityReport` (the app's quality table).
* :mod:`.lake` — the metrics of ``shared/design/lake-grids.md`` (node
  orthogonality, deviation from 90°, smoothness, aspect ratio, folds,
  cross-interface area ratio) for single and multiblock grids:
  :func:`lake_metrics` → :class:`LakeMetrics`.
* :mod:`.coverage` — grid area against the water polygon, Hausdorff distance
  of the shoreline.
* :mod:`.presets` — :data:`PRESETS` (``delft3d``, ``efdc``, ``gcmesh-lake``)
  and :func:`check` → :class:`Verdict`: how many nodes, cells or edge pairs
  miss which limit, and where.
"""

from __future__ import annotations

from .cells import QualityReport, cell_quality, quality
from .coverage import Coverage
from .lake import METRICS, BlockMetrics, LakeMetrics, Location, Samples, block_metrics, interface_pairs, lake_metrics
from .presets import PRESETS, Limit, LimitResult, Preset, Verdict, check

__all__ = [
    "METRICS",
    "PRESETS",
    "BlockMetrics",
    "Coverage",
    "LakeMetrics",
    "Limit",
    "LimitResult",
    "Location",
    "Preset",
    "QualityReport",
    "Samples",
    "Verdict",
    "block_metrics",
    "cell_quality",
    "check",
    "interface_pairs",
    "lake_metrics",
    "quality",
]
