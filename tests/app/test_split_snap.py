"""Split into blocks by cut lines snaps the drawn cuts' ends as the Cut line tool does over a layout."""

from __future__ import annotations

import numpy as np
import pytest

from tests.app.drawing import box_csv, draw_cut
from tests.app.waits import wait_for, wait_idle

pytestmark = pytest.mark.gui

H = 500.0  # cell size (m): the 20 × 10 km lake is 40 × 20 cells


@pytest.mark.parametrize(("off", "snapped"), [(1.5, True), (4.0, False)])
def test_split_snaps_a_cut_end_near_another_cut_end(qtbot, win, tmp_path, off, snapped):
    """A cut across the lake (x = 10 km) and a second one from the south shore ``off`` cells east
    of its end, slanting to the east shore: at 1.5 cells the second starts on the first's end (a
    three-cut junction on the shore; the Messages say what moved), at 4 cells where drawn.  The
    split is one undo step, which brings the drawn cut lines back."""
    assert win.io.import_points(box_csv(tmp_path / "box.csv"))
    win.lake_ctl.set_cell_size(H)
    draw_cut(win, [(10000.0, -300.0), (10000.0, 10300.0)])
    x0 = 10000.0 + off * H
    d = np.array([20000.0 - x0, 6000.0])
    draw_cut(win, [np.array([x0, 0.0]) - 0.05 * d, np.array([20000.0, 6000.0]) + 0.03 * d])
    drawn = win.doc.project.cut_lines
    said = []
    win.doc.reported.connect(lambda level, text: said.append((level, text)))
    win.a_split.trigger()
    wait_for(qtbot, win, lambda: win.doc.project.layout is not None or bool(win.lake_ctl.last_error))
    assert win.lake_ctl.last_error is None
    wait_idle(qtbot, win)
    lay = win.doc.project.layout
    assert len(lay.blocks) == 3
    starts = [np.round(np.asarray(c, float)[e], 3).tolist() for c in lay.cuts for e in (0, -1)]
    notes = [t for _lv, t in said if "snapped" in t]
    if snapped:
        assert starts.count([10000.0, 0.0]) == 2  # both cuts end there
        assert len(notes) == 1 and "(10000, 0)" in notes[0] and "cut end" in notes[0]
    else:
        assert starts.count([10000.0, 0.0]) == 1 and [x0, 0.0] in starts
        assert notes == []
    lay.topology()
    assert win.stack.undoText() == "Split into 3 blocks by cut lines"
    win.stack.undo()
    assert win.doc.project.layout is None and len(win.doc.project.cut_lines) == len(drawn) == 2


@pytest.mark.parametrize("refuse", [False, True])
def test_a_snapped_split_that_gives_no_layout_is_taken_as_drawn(monkeypatch, refuse):
    """split_layout: the snapped cuts' layout and its note; when the snapped cuts give no layout, the
    cuts as drawn and a note that their ends stayed (with the snapped cuts' error)."""
    from shapely.geometry import box

    import meshcore.layout
    from app.lake import split_layout
    from meshcore.errors import TopologyError

    real = meshcore.layout.layout_from_cuts

    def refuse_snapped(*args, snap=0.0, **kw):
        if snap and refuse:
            raise TopologyError("made up")
        return real(*args, snap=snap, **kw)

    monkeypatch.setattr(meshcore.layout, "layout_from_cuts", refuse_snapped)
    a = np.array([[10.0, -0.5], [10.0, 10.5]])
    c = np.array([[10.0, -0.5], [20.5, 6.0]])  # enters the water 0.81 m (1.6 cells) east of a's end
    lay = split_layout(box(0.0, 0.0, 20.0, 10.0), [a, c], 0.5, 1)
    firsts = [np.round(np.asarray(k, float)[0], 6).tolist() for k in lay.cuts]
    if refuse:
        assert firsts[1] != [10.0, 0.0]
        assert len(lay.notes) == 1 and "stay where drawn" in lay.notes[0] and "made up" in lay.notes[0]
    else:
        assert firsts[1] == [10.0, 0.0]
        assert len(lay.notes) == 1 and "snapped" in lay.notes[0]
