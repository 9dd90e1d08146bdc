"""The Cut line tool over a laid-out lake: an end landing a cell or two from a cut end snaps onto it."""

from __future__ import annotations

import numpy as np
import pytest

from tests.app.drawing import box_csv, draw_cut
from tests.app.waits import wait_for, wait_idle

pytestmark = pytest.mark.gui

H = 500.0  # cell size (m): the 20 × 10 km lake is 40 × 20 cells


def _t_layout(qtbot, win, tmp_path):
    """The box split by a cut across it (x = 10 km) and a T from the west shore to it (y = 5 km)."""
    assert win.io.import_points(box_csv(tmp_path / "box.csv"))
    win.lake_ctl.set_cell_size(H)
    draw_cut(win, [(10000.0, -300.0), (10000.0, 10300.0)])
    draw_cut(win, [(-300.0, 5000.0), (10100.0, 5000.0)])
    win.a_split.trigger()
    wait_for(qtbot, win, lambda: win.doc.project.layout is not None or bool(win.lake_ctl.last_error))
    assert win.lake_ctl.last_error is None
    wait_idle(qtbot, win)
    return win.doc.project.layout


def _junctions(lay) -> list:
    ends = [c[k] for c in lay.cuts for k in (0, -1)]
    inside = [e for e in ends if 1.0 < e[0] < 19999.0 and 1.0 < e[1] < 9999.0]
    return np.unique(np.round(inside, 3), axis=0).tolist()


@pytest.mark.parametrize(("off", "snapped"), [(1.5, True), (4.0, False)])
def test_a_cut_end_near_a_cut_end_snaps_onto_it(qtbot, win, tmp_path, off, snapped):
    """A cut from the east shore to the first cut, landing 1.5 cells above the T's end there, ends
    on it (one 4-way junction; the Messages say where); landing 4 cells
    away it stays where drawn (two T's).  One undo step either way."""
    lay0 = _t_layout(qtbot, win, tmp_path)
    assert _junctions(lay0) == [[10000.0, 5000.0]]
    said = []
    win.doc.reported.connect(lambda level, text: said.append((level, text)))
    y = 5000.0 + off * H
    draw_cut(win, [(20300.0, y), (9900.0, y)])
    wait_for(qtbot, win, lambda: win.doc.project.layout is not lay0 and not win.lake_ctl.editing)
    wait_idle(qtbot, win)
    lay = win.doc.project.layout
    assert win.lake_ctl.edit_error is None and len(lay.blocks) == 4
    assert win.stack.undoText() == "Add cut line"
    notes = [t for lv, t in said if "snapped" in t]
    if snapped:
        assert _junctions(lay) == [[10000.0, 5000.0]]
        assert len(notes) == 1 and "(10000, 5000)" in notes[0] and "cut end" in notes[0]
    else:
        assert _junctions(lay) == [[10000.0, 5000.0], [10000.0, y]]
        assert notes == []
    win.stack.undo()
    assert win.doc.project.layout is lay0


def test_a_snapped_cut_that_gives_no_layout_is_taken_as_drawn(monkeypatch):
    """with_drawn_cut: when the snapped cut gives no layout, the cut as drawn is taken and the
    Messages say its ends stayed; no message of a snap that did not happen."""
    from shapely.geometry import box

    from app import layout_edit
    from meshcore.errors import TopologyError
    from meshcore.layout import layout_from_cuts

    lay = layout_from_cuts(
        box(0.0, 0.0, 20.0, 10.0),
        [np.array([[10.0, -0.5], [10.0, 10.5]]), np.array([[-0.5, 5.0], [10.2, 5.0]])],
        cell_size=0.5,
    )
    drawn = np.array([[20.5, 5.75], [9.8, 5.75]])
    real = layout_edit.with_cut

    def refuse_snapped(layout, cut):
        if np.any(np.all(np.isclose(np.asarray(cut), [10.0, 5.0]), axis=1)):
            raise TopologyError("made up")
        return real(layout, cut)

    said = []
    assert layout_edit.with_drawn_cut(lay, drawn, lambda lv, t: said.append(t)).cuts[-1][-1].tolist() == [10.0, 5.0]
    assert len(said) == 1 and "snapped" in said[0]
    said.clear()
    monkeypatch.setattr(layout_edit, "with_cut", refuse_snapped)
    out = layout_edit.with_drawn_cut(lay, drawn, lambda lv, t: said.append(t))
    assert len(out.blocks) == 4 and np.round(out.cuts[-1][-1], 6).tolist() == [10.0, 5.75]
    assert len(said) == 1 and "stay where drawn" in said[0] and "made up" in said[0]
