"""Session 39 (branch app39): what a lake modeller's walk left — the Lake panel's cell count of a cell size
set, the cut line Del deletes, Ctrl+Z in the middle of a drag."""

from __future__ import annotations

import numpy as np
import pytest

pytestmark = pytest.mark.gui


def _y_lake():
    """A Y junction of arms 1 km wide (a lake whose blocks are a few cells across at a coarse size)."""
    import shapely.affinity

    from app.lake import Lake
    from meshcore import testing

    poly = shapely.affinity.scale(testing.y_junction(), 1000.0, 1000.0, origin=(0, 0))
    return Lake(outline=np.asarray(poly.exterior.coords)[:-1]), poly.area


def test_the_lake_panel_gives_the_cells_of_the_layout_a_cell_size_makes(qtbot, win):
    """A cell size typed in the Lake panel over a laid-out lake: the panel said "Auto layout (Ctrl+L) makes
    them at 419.1 m (about 100 cells)" — the water's area over the cell size squared — and Auto layout
    made 256 (blocks of a few cells across: each side's count is a multiple of 4; on 50 lake/size pairs
    area ÷ h² was 0.26-1.49 × the layout's cells).  Now the layout is made in a worker when the size is set
    and the panel gives its cells and blocks; Auto layout then sets that layout at once."""
    from app.lake import compute_layout, expected_cells
    from tests.app.waits import wait_for, wait_idle

    lake, area = _y_lake()
    win.editor.set_lake(lake.replaced(layout=compute_layout(lake)), "Auto layout")
    h = float(np.sqrt(area / 100))
    want = compute_layout(lake.replaced(cell_size=h))
    rough = expected_cells(lake.replaced(cell_size=h))
    assert want.n_cells > 1.5 * rough  # what area / h² missed
    win.lake_ctl.set_cell_size(h)
    text = win.lake_panel.summary.text()
    assert f"about {rough:,} cells by area" in text and "counting" in text  # said to be rough while counted
    wait_for(qtbot, win, lambda: win.lake_ctl.layout_count(win.lake_ctl.lake()) is not None)
    n = len(want.blocks)
    assert f"makes them at {h:.4g} m: {want.n_cells:,} cells in {n} blocks" in win.lake_panel.summary.text()
    win.a_auto_layout.trigger()  # the layout counted is the one set, at once
    assert not win.lake_ctl.busy
    lay = win.doc.project.layout
    assert lay.n_cells == want.n_cells and [b.cells for b in lay.blocks] == [b.cells for b in want.blocks]
    wait_idle(qtbot, win)
    win.stack.undo()  # the layout before; a size typed before any layout is counted too
    win.editor.set_lake(lake, "Import")
    win.lake_ctl.set_cell_size(h)
    wait_for(qtbot, win, lambda: win.lake_ctl.layout_count(win.lake_ctl.lake()) is not None)
    assert f"(at {h:.4g} m: {want.n_cells:,} cells in {n} blocks)" in win.lake_panel.summary.text()
