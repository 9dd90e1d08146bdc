"""Sixth walk of a lake modeller (session 24): development lakes with islands imported, laid out,
gridded, exported to Delft3D DD and VTK, the layout undone and redone, the project reopened."""

from __future__ import annotations

import numpy as np
import pytest

from tests.app.test_lake import lay_out
from tests.app.waits import answer_questions, wait_for, wait_idle

pytestmark = pytest.mark.gui


def _y_lake(tmp_path):
    """A symmetric Y in metres: its default layout has a star (six blocks meet) that Delft3D's
    domain decomposition cannot couple."""
    from meshcore import testing

    shore = 1000.0 * np.asarray(testing.y_junction().exterior.coords)[:-1]
    src = tmp_path / "y.csv"
    np.savetxt(src, shore, delimiter=",", header="x,y", comments="")
    return src


def test_a_ddb_refused_is_written_once_the_regular_layout_asked_for_is_gridded(qtbot, win, tmp_path, monkeypatch):
    """Export ▸ .ddb of a layout Delft3D cannot couple asks "Make a regular layout now?"; Yes made the
    layout and its grid, and the user had to export again (the dialog, the file name).  The file is
    written when the regular layout's grid is done."""
    from meshcore.io import read

    lay_out(qtbot, win, _y_lake(tmp_path), cell_size=100.0)
    asked = answer_questions(monkeypatch, "Yes")
    out = tmp_path / "y.ddb"
    win.quiet = False  # the question is asked (answered above); no other dialog comes
    try:
        assert not win.io.export_mesh(out)
    finally:
        win.quiet = True
    wait_for(qtbot, win, lambda: out.exists() or getattr(win.io, "_pending_export", None) is None)
    wait_idle(qtbot, win)
    lay = win.doc.project.layout
    assert win.doc.project.lake.regular and lay is not None
    assert out.exists(), win._status.text()
    assert asked and "regular layout" in asked[-1] and "y.ddb is written" in asked[-1]
    back = read(out)
    assert len(back.blocks) == len(lay.blocks)
    assert sum(g.cells[0] * g.cells[1] for g in back.blocks) == lay.n_cells
    assert win._status.text().startswith("Exported")


def test_undo_and_redo_say_what_they_did(qtbot, win, tmp_path):
    """Ctrl+Z after Auto layout took the layout back and the status line kept the message of before
    (here "Exported … .vtm"): what was undone showed only in the Undo history dock."""
    lay_out(qtbot, win, _y_lake(tmp_path), cell_size=100.0)
    assert win.io.export_mesh(tmp_path / "y.vtm")
    win.a_undo.trigger()
    assert win.doc.project.layout is None
    assert win._status.text() == "Undone: Auto layout (Ctrl+Y redoes it)"
    win.a_redo.trigger()
    assert win.doc.project.layout is not None
    assert win._status.text() == "Redone: Auto layout (Ctrl+Z undoes it)"
    wait_idle(qtbot, win)
