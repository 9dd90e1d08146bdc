"""Session 41 (branch tidy41): one wording of a cell far smaller than the rest (the quality table, ``meshcore
mesh``'s note, the app's lake verdict), and Auto layout stoppable from its start."""

from __future__ import annotations

import math

import numpy as np
import pytest

from meshcore import StructuredGrid
from meshcore.quality import lake_metrics

pytestmark = pytest.mark.gui


def _thin_column(width: float) -> StructuredGrid:
    """Columns 1, 1, ``width``, 1, 2 wide and three rows 1 high: one column of cells far thinner."""
    X, Y = np.meshgrid(np.cumsum([0.0, 1, 1, width, 1, 2]), np.arange(4.0), indexing="ij")
    return StructuredGrid(X, Y)


def _collapsed() -> StructuredGrid:
    X, Y = np.meshgrid([0.0, 1.0, 2.0], [0.0, 1.0, 2.0], indexing="ij")
    X[1, 2], Y[1, 2] = X[0, 2], Y[0, 2]  # top row: its first edge has length 0
    return StructuredGrid(X, Y)


@pytest.mark.parametrize(
    ("grid", "words"),
    [
        # mean cell size sqrt(5.001 * 3 / 15): the thin column's edge 0.001 / h cells, the time step ÷ h / 0.001
        (
            _thin_column(1e-3),
            f"{1e-3 / math.sqrt(5.001 / 5):.3g} cells (explicit time step ÷ {1e3 * math.sqrt(5.001 / 5):.3g})",
        ),
        (_collapsed(), "0 cells (a collapsed edge: an explicit model cannot step there)"),
    ],
)
def test_the_quality_table_the_cli_note_and_the_lake_verdict_word_the_small_cell_alike(grid, words):
    """The cell far smaller than the rest was worded three ways: the table's "0.000999 cells (explicit time
    step ÷ 1e+03)", ``meshcore mesh``'s "an edge of 0.001 cells: an explicit model's time step there is
    1e+03 times shorter" and the verdict's "shortest edge 0.001 cells (time step ÷ 1e+03)" (a collapsed
    edge: "0 (a collapsed edge)", "a collapsed edge: an explicit model cannot step there", "a collapsed
    edge").  Now all three say :func:`meshcore.quality.lake.shortest_edge_words` of the same number."""
    from app.views.lake_panel import _small_cell

    m = lake_metrics(grid)
    row = next(line for line in m.table().splitlines() if line.startswith("| shortest edge"))
    assert row.split("|")[2].strip() == words
    note = m.small_cell_note()
    assert note is not None and note.startswith("cell block1(") and f"has the grid's shortest edge, {words}: " in note
    assert _small_cell(m.summary()) == f", shortest edge {words}"
