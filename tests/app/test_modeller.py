"""What a modeller's afternoon in the app (under Xvfb, driven by xdotool) found, each as it went wrong."""

from __future__ import annotations

import json

import numpy as np
import pytest
import shapely

from meshcore import testing
from tests.app.waits import drag_a_cut_end, wait_for, wait_idle

pytestmark = pytest.mark.gui


def _lonlat_lake(path, seed: int, lon: float, lat: float = 50.0):
    """A generated lake with islands, about 4 km across, written as a lon/lat GeoJSON at (lon, lat)."""
    poly = testing.lake_with_islands(seed)
    poly = shapely.affinity.affine_transform(poly, [0.002, 0, 0, 0.002, lon, lat])
    feature = {"type": "Feature", "properties": {"name": path.stem}, "geometry": shapely.geometry.mapping(poly)}
    path.write_text(json.dumps({"type": "FeatureCollection", "features": [feature]}))
    return path


def _metres_lake(path, seed: int):
    """A generated lake with islands in plain metres (no CRS), written as a CSV of rings."""
    poly = shapely.affinity.scale(testing.lake_with_islands(seed), 300, 300, origin=(0, 0))
    rings = [poly.exterior, *poly.interiors]
    lines = ["x,y"]
    for k, ring in enumerate(rings):
        if k:
            lines.append("")
        lines += [f"{x:.2f},{y:.2f}" for x, y in ring.coords]
    path.write_text("\n".join(lines) + "\n")
    return path


def test_a_second_lake_replaces_the_first_in_its_own_frame(qtbot, win, tmp_path):
    """A lake imported over another (no File ▸ New) was added as a second block in the first
    lake's CRS and origin: Lake Zurich over Windermere went into UTM zone 30 at x ≈ 880 km, and
    the offer on it ("3 island(s) … Auto layout") laid out the first lake and dropped the new one."""
    first = _lonlat_lake(tmp_path / "west.geojson", 761201, lon=-3.0)
    second = _lonlat_lake(tmp_path / "east.geojson", 761202, lon=9.0)
    assert win.io.import_points(first, project_lonlat=True)
    assert win.doc.project.crs == "EPSG:32630"
    west = win.doc.project
    assert win.io.import_points(second, project_lonlat=True)
    p = win.doc.project
    assert p.crs == "EPSG:32632"  # the UTM zone of the new lake, as meshcore mesh projects it
    assert len(p.blocks) == 1 and p.blocks[0].name == "east"
    assert p.lake is not None and len(p.lake.holes) == len(testing.lake_with_islands(761202).interiors)
    np.testing.assert_array_equal(p.blocks[0].points, p.lake.outline)
    assert np.abs(p.lake.outline).max() < 10_000  # about a round local origin, not 1000 km off
    win.stack.undo()  # one step brings the first lake back
    assert win.doc.project is west


def test_a_lake_in_metres_over_a_projected_one_has_no_crs(qtbot, win, tmp_path):
    """A CSV of metres (no CRS) imported over a lon/lat lake took that lake's UTM zone and origin:
    exported, its grid lay at E 500 000 + x in a zone it has nothing to do with."""
    assert win.io.import_points(_lonlat_lake(tmp_path / "west.geojson", 761203, lon=-3.0), project_lonlat=True)
    src = _metres_lake(tmp_path / "plain.csv", 761204)
    assert win.io.import_points(src)
    p = win.doc.project
    assert p.crs == "" and tuple(p.origin) == (0.0, 0.0)
    assert len(p.blocks) == 1 and p.lake is not None
    ring = np.asarray(
        shapely.affinity.scale(testing.lake_with_islands(761204), 300, 300, origin=(0, 0)).exterior.coords
    )
    assert np.abs(p.lake.outline).max() == pytest.approx(np.abs(ring).max(), abs=0.01)  # the file's own numbers


def _laid_out(qtbot, win, tmp_path, seed: int):
    """A generated lake in metres, laid out coarse (20 cells to the square root of its area) and gridded."""
    assert win.io.import_points(_metres_lake(tmp_path / f"lake{seed}.csv", seed))
    area = shapely.Polygon(win.doc.project.lake.outline, win.doc.project.lake.holes).area
    win.lake_ctl.set_cell_size(np.sqrt(area) / 20)
    win.a_auto_layout.trigger()
    wait_for(qtbot, win, lambda: win.doc.project.layout is not None or bool(win.lake_ctl.last_error))
    assert win.lake_ctl.last_error is None
    wait_idle(qtbot, win)
    return win.doc.project


def test_undo_back_to_the_gridded_layout_makes_its_grid_current_again(qtbot, win, tmp_path):
    """Drag a cut end (auto-generate off: the grid greyed, "of before the last edit"), then undo:
    the layout is the one the grid was made for, yet the grid stayed greyed, its verdict marked
    old, and Export refused it ("generate it (F5)") until a solve made the same grid again.  And
    the other way: an edit (a redo) while F5 solves; the grid that arrives is of the layout before
    it, but it was shown, and exported, as current."""
    solved = _laid_out(qtbot, win, tmp_path, 761205)
    grids = dict(win.doc.grids)
    pen = lambda: win.canvas.grid_curve.opts["pen"].color().name()  # noqa: E731
    drag_a_cut_end(qtbot, win)
    dragged = win.doc.project
    assert pen() == "#b0b0b0" and "before the last edit" in win.lake_quality.headline.text()
    win.stack.undo()
    assert win.doc.project is solved and win.doc.grids == grids
    assert not win.doc.stale and pen() == "#303030"
    assert "before" not in win.lake_quality.headline.text() and "F5" not in win.solve_status.label.text()
    assert win.io.export_mesh(tmp_path / "lake.vtm")
    win.generate()  # F5 on the layout of before the drag ...
    assert win.solver.running
    win.stack.redo()  # ... and the drag again while it solves
    assert win.doc.project is dragged
    wait_idle(qtbot, win)
    assert win.doc.stale and pen() == "#b0b0b0" and "before the last edit" in win.lake_quality.headline.text()
    assert not win.io.export_mesh(tmp_path / "dragged.vtm")


def test_a_file_that_fails_to_open_leaves_the_window_open(qtbot, tmp_path, monkeypatch):
    """``gcmesh lake.geojson`` (a double-clicked file) whose file fails: the error dialog named the
    place, and on its OK the window vanished (exit 2, as for ``--solve``/``--screenshot``)."""
    from PySide6 import QtCore, QtWidgets

    import app.__main__ as entry
    import app.main_window as mw

    bad = tmp_path / "lake.geojson"
    bad.write_text('{"type": "FeatureCollection", "features": [')
    made, said, ran = [], [], []
    real = mw.MainWindow

    def window(**kw):
        settings = QtCore.QSettings(str(tmp_path / "settings.ini"), QtCore.QSettings.Format.IniFormat)
        w = real(settings=settings, recovery=tmp_path / "recovery.gcmesh", **kw)
        qtbot.addWidget(w)
        made.append(w)
        return w

    monkeypatch.setattr(mw, "MainWindow", window)
    monkeypatch.setattr(entry, "_logging", lambda: None)
    monkeypatch.setattr(entry.sys, "excepthook", entry.sys.excepthook)
    monkeypatch.setattr(QtWidgets.QMessageBox, "warning", lambda _w, title, text: said.append(text))
    monkeypatch.setattr(QtWidgets.QApplication, "exec", lambda *_a: ran.append(True) or 0)
    assert entry.main([str(bad)]) == 0
    assert ran and made and made[0].isVisible()  # the event loop ran: the window is there to use
    assert len(said) == 1 and str(bad) in said[0]
    assert any(str(bad) in t for lv, t in made[0].messages_panel.messages() if lv == "error")
    made[0].close()


def test_a_new_cell_size_is_for_auto_layout_and_leaves_the_grid_current(qtbot, win, tmp_path):
    """Cell size 2 h typed in the Lake panel: the grid went grey, "grid of before the last edit (F5
    makes the new one)", yet F5 solved the same layout again (the same cells at h): the cell size
    is applied by Auto layout.  With auto-generate on, every change of it re-solved the same grid."""
    _laid_out(qtbot, win, tmp_path, 761207)
    lay, grids = win.doc.project.layout, dict(win.doc.grids)
    h = lay.cell_size
    win.lake_panel.cell_size.setValue(2 * h)
    win.lake_panel.cell_size.editingFinished.emit()
    h2 = win.lake_panel.cell_size.value()  # as the spin box rounds it
    assert h2 == pytest.approx(2 * h, abs=0.1)
    assert win.doc.project.lake.cell_size == h2 and win.doc.project.layout is lay
    assert not win.doc.stale and win.canvas.grid_curve.opts["pen"].color().name() == "#303030"
    assert "before" not in win.lake_quality.headline.text() and "F5" not in win.solve_status.label.text()
    assert "Auto layout" in win.lake_panel.summary.text()  # where the new cell size goes
    assert win.io.export_mesh(tmp_path / "lake.vtm")
    win.solver.set_auto(True)
    win.lake_panel.regular.setChecked(True)  # also a setting of the next Auto layout
    assert not win.solver.running and not win.solver._debounce.isActive()
    assert win.doc.grids == grids
    win.a_auto_layout.trigger()  # the cell size applied
    wait_for(qtbot, win, lambda: win.doc.project.layout is not lay)
    wait_idle(qtbot, win)
    assert win.doc.project.layout.cell_size == h2
    assert "Auto layout" not in win.lake_panel.summary.text()


def test_del_with_the_layout_tool_deletes_the_cut_line_pointed_at(qtbot, win, tmp_path):
    """A modeller who wants two blocks as one had no way to remove a cut line of the layout (Del
    deleted selected shore points only; Auto layout again made the same cuts).  Now Del, with the
    Layout tool pointing at a cut's end or point, removes that cut: one undo step."""
    from app.layout_edit import handles

    _laid_out(qtbot, win, tmp_path, 761205)
    lay = win.doc.project.layout
    win.set_tool("layout")
    h = next(h for h in handles(lay) if h.kind == "end")
    win.canvas.tool.hover(h.xy)  # the end is ringed
    win.a_delete.trigger()
    assert win.lake_ctl.editing  # the layout without the cut is being made
    wait_for(qtbot, win, lambda: win.doc.project.layout is not lay and not win.lake_ctl.editing)
    new = win.doc.project.layout
    assert len(new.cuts) == len(lay.cuts) - 1 and len(new.blocks) == len(lay.blocks) - 1
    assert not any(np.array_equal(c, lay.cuts[h.cut]) for c in new.cuts)
    kept = [b for b in lay.blocks if any(np.allclose(b.corners, c.corners) for c in new.blocks)]
    assert len(kept) == len(lay.blocks) - 2  # only the two blocks it parted changed
    assert win.stack.undoText() == "Delete cut line"
    wait_idle(qtbot, win)
    win.stack.undo()
    assert win.doc.project.layout is lay
    win.canvas.tool.hover((1e9, 1e9))  # pointing at nothing: Del says how, and deletes nothing
    win.a_delete.trigger()
    assert win.doc.project.layout is lay and "point at" in win.statusBar().currentMessage() + win._status.text()


def test_the_status_says_solving_from_the_start_of_a_solve(qtbot, win, tmp_path):
    """The first Auto layout's grid after an install took a minute (its kernels compiling) with Pause
    and Stop lit and the solver's status reading "idle" until the first progress came."""
    assert win.io.import_points(_metres_lake(tmp_path / "lake.csv", 761209))
    assert win.solve_status.label.text() == "idle"
    win.generate()
    assert win.solver.running and win.solve_status.label.text() == "solving…"
    wait_idle(qtbot, win)
    assert "solving" not in win.solve_status.label.text()


@pytest.mark.parametrize("then", ["resume", "stop"])
def test_space_twice_or_space_then_esc_right_after_f5_does_not_hang_the_solve(qtbot, win, tmp_path, then):
    """superqt takes a pause at the worker's next yield and ignored a resume asked before it: F5,
    Space, Space (or Esc) at once left the solve paused for good with the status saying it ran;
    Stop could not end it, and closing the window waited for it."""
    assert win.io.import_points(_metres_lake(tmp_path / "lake.csv", 761210))
    win.generate()
    win.solver.toggle_pause()
    assert win.solver.state == "paused"
    win.solver.toggle_pause() if then == "resume" else win.solver.stop()
    wait_for(qtbot, win, lambda: not win.solver.running, timeout=120_000)
    assert win.doc.grids


def test_the_lake_verdict_box_goes_with_the_layout(qtbot, win, tmp_path):
    """A cut deleted (the grid dropped: "the verdict follows when the grid of this layout is made"),
    then File ▸ New or an example without a layout: the lake's verdict box stayed in the Quality dock."""
    from app.layout_edit import without_cut

    _laid_out(qtbot, win, tmp_path, 761211)
    box = win.lake_quality
    assert box.isVisible()
    lake = win.doc.project.lake
    win.editor.set_lake(lake.replaced(layout=without_cut(lake.layout, 0)), "Delete cut line")
    assert not win.doc.grids and box.isVisible()  # the new layout's verdict is still to come
    win.stack.setClean()
    win.io.new_project()
    assert win.doc.project.layout is None and not box.isVisible()
