"""What the lake metrics share: :class:`Samples` (a metric's values with their places) and tables."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

__all__ = ["Samples", "format_table", "ok_percent"]


@dataclass(frozen=True, slots=True, eq=False)
class Samples:
    """The values of one metric wherever it is defined, each with its place.

    ``block`` indexes :attr:`LakeMetrics.names` (``-1``: the whole grid);
    ``i, j`` are node indices for node metrics and smoothness, cell indices
    for cell metrics and for side *a* of an interface pair (``partner``:
    ``(block, i, j)`` of the cell on side *b*); ``axis`` is 0 for ξ-lines and
    1 for η-lines (smoothness only).
    """

    metric: str
    values: np.ndarray
    block: np.ndarray
    i: np.ndarray
    j: np.ndarray
    x: np.ndarray
    y: np.ndarray
    partner: np.ndarray | None = None
    axis: np.ndarray | None = None

    def __len__(self) -> int:
        return len(self.values)


def format_table(head: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    """A Markdown table with padded columns."""
    rows = [[str(v).replace("|", "\\|") for v in r] for r in [head, *rows]]  # a | inside a cell is escaped
    w = [max(len(r[c]) for r in rows) for c in range(len(head))]
    line = lambda r: "| " + " | ".join(v.ljust(w[c]) for c, v in enumerate(r)) + " |"  # noqa: E731
    return "\n".join([line(rows[0]), "|" + "|".join("-" * (n + 2) for n in w) + "|"] + [line(r) for r in rows[1:]])


def ok_percent(fraction: float) -> str:
    """A share within a limit, in per cent to a tenth, rounded down: 1 node of 8598 over the EFDC limit
    read "FAIL (100.0 % ok)"; only a share of 1 reads 100.0.

    Examples
    --------
    >>> ok_percent(8597 / 8598), ok_percent(1.0), ok_percent(0.9785)
    ('99.9', '100.0', '97.8')
    """
    return f"{math.floor(1000 * float(fraction) + 1e-9) / 10:.1f}"
