"""Session 41 (branch tidy41): one wording of a cell far smaller than the rest (the quality table, ``meshcore
mesh``'s note, the app's lake verdict), and Auto layout stoppable from its start."""

from __future__ import annotations

import math
import threading

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


def test_auto_layout_stopped_at_its_first_check_ends_without_a_layout(qtbot, win, monkeypatch):
    """Stop (Esc) during Auto layout was heard only at the layout choice's first coarse reading, after the
    first draws (~4.4 s on Vänern at 10 000 cells).  Now the worker looks at the stop from the start of
    :func:`meshcore.layout.auto_layout` (:mod:`meshcore.layout.stopping`): held at its first look while
    Stop is pressed, it ends there — nothing drawn, nothing read, no layout, the document as it was."""
    import meshcore.layout as lay
    from app import lake_controller as lc
    from meshcore.lakegrid import CoarseReadings
    from tests.app.test_app39 import _y_lake
    from tests.app.waits import wait_for, wait_idle

    entered, go, drawn, read, ended, looks = threading.Event(), threading.Event(), [], [], [], []
    real_job, real_pieces = lc._layout_job, lay.layout_pieces

    class Held:
        """The worker's stop event, held at its first look until Stop has been pressed."""

        def __init__(self, event) -> None:
            self.event = event

        def is_set(self) -> bool:
            looks.append(1)
            if len(looks) == 1:
                entered.set()
                go.wait(60)
            return self.event.is_set()

    def job(lake, cuts=None, stop_event=None):
        ended.append(real_job(lake, cuts, Held(stop_event)))
        return ended[-1]

    monkeypatch.setattr(lc, "_layout_job", job)
    monkeypatch.setattr(lay, "layout_pieces", lambda *a, **kw: drawn.append(1) or real_pieces(*a, **kw))
    monkeypatch.setattr(CoarseReadings, "__call__", lambda self, layout: read.append(layout))
    lake, _ = _y_lake()
    win.editor.set_lake(lake, "Import")
    before, steps = win.doc.project, win.stack.count()
    assert win.lake_ctl.auto_layout()
    wait_for(qtbot, win, entered.is_set)
    win.a_stop.trigger()  # Esc
    go.set()
    wait_for(qtbot, win, lambda: not win.lake_ctl.busy)
    wait_idle(qtbot, win)
    assert ended == [None] and len(looks) == 1  # stopped at the look it was held at
    assert drawn == [] and read == []  # before anything was drawn or read
    assert win.doc.project is before and win.stack.count() == steps and win.doc.project.layout is None
    assert not win.solver.running and win.doc.grids == {}
    assert "Auto layout stopped" in win._status.text()
