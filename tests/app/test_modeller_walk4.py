"""What a fourth modeller's walk through the app (session 20, held-out GSHHG lakes and generated
ones under Xvfb) found, each as it went wrong, on generated shapes."""

from __future__ import annotations

import numpy as np
import pytest
import shapely

from tests.app.drawing import drag_shore_end_round
from tests.app.test_modeller import _laid_out
from tests.app.waits import wait_for, wait_idle

pytestmark = pytest.mark.gui


def _corners_by_name(layout) -> dict:
    return {b.name: np.round(np.asarray(b.corners, float), 6).tobytes() for b in layout.blocks}


def _cut_across(layout, name: str) -> np.ndarray:
    """A straight cut across block ``name`` through its middle, from shore or cut to shore or cut."""
    ring = shapely.Polygon(layout.pieces[[b.name for b in layout.blocks].index(name)].ring)
    c = ring.representative_point()
    x0, y0, x1, y1 = ring.bounds
    if x1 - x0 >= y1 - y0:  # across the block's long way round
        line = shapely.LineString([(c.x, y0 - 1), (c.x, y1 + 1)])
    else:
        line = shapely.LineString([(x0 - 1, c.y), (x1 + 1, c.y)])
    part = line.intersection(ring)
    part = max(getattr(part, "geoms", [part]), key=lambda g: g.length)
    return np.asarray(part.coords, float)


def test_a_cut_edit_leaves_the_names_of_the_blocks_it_did_not_touch(qtbot, win, tmp_path):
    """A cut drawn across one block of a laid-out lake, then deleted again: the blocks it never
    touched were renamed (the modeller's b3 became b2, b5 became b9 on held-out g181803), so a
    block noted by name was another block after any cut edit.  Blocks the edit did not change keep
    their names; the block cut in two keeps its name on its bigger part, the other part is new."""
    _laid_out(qtbot, win, tmp_path, 762011)
    lay0 = win.doc.project.layout
    big = max(lay0.blocks, key=lambda b: b.cells[0] * b.cells[1]).name
    before = _corners_by_name(lay0)
    win.set_tool("cut")
    tool = win.canvas.tool
    for xy in _cut_across(lay0, big):
        tool.click(tuple(xy))
    tool.double_click(tuple(xy))
    wait_for(qtbot, win, lambda: win.doc.project.layout is not lay0)
    wait_idle(qtbot, win)
    lay1 = win.doc.project.layout
    assert len(lay1.blocks) > len(lay0.blocks)
    after = _corners_by_name(lay1)
    same = [n for n, c in before.items() if c in after.values()]
    assert same and all(after.get(n) == before[n] for n in same)  # each untouched block by its own name
    names = [b.name for b in lay1.blocks]
    assert big in names and len(set(names)) == len(names)
    assert names == sorted(names, key=lambda n: int(n[1:]))  # the Lake panel lists b2 before b10
    # a cut of before deleted (Layout tool, its end ringed, Del): the blocks it did not bound keep theirs
    win.stack.undo()
    assert win.doc.project.layout is lay0
    win.set_tool("layout")
    ltool = win.canvas.tool
    ltool._hovered = (lay0, next(h for h in ltool._handles(lay0) if h.kind == "end"))
    assert ltool.delete()
    wait_for(qtbot, win, lambda: win.doc.project.layout is not lay0)
    wait_idle(qtbot, win)
    lay2 = win.doc.project.layout
    assert len(lay2.blocks) < len(lay0.blocks)
    after = _corners_by_name(lay2)
    same = [n for n, c in before.items() if c in after.values()]
    assert same and all(after.get(n) == before[n] for n in same)
    assert set(after) <= set(before)  # the joined block has the name of one of the two it joined


def test_corners_and_cut_ends_let_the_grid_show_where_cells_are_smaller_than_they(qtbot, win):
    """The whole lake in view (held-out g181803, 10 000 cells): the yellow corner squares and white
    cut-end circles, each wider than two or three cells on screen, hid the grid at every arm's end
    (where they gather).  A cell on screen narrower than them: they are drawn as outlines; zoomed in
    to a few cells, filled as before."""
    from PySide6 import QtCore

    from tests.app.test_canvas_lod import _laid_out as channels

    lay = channels(win, seed=762021, cells=10_000)
    items = win.canvas.lake_items
    h = lay.cell_size
    win.canvas.fit()
    assert items.corners.isVisible() or items.cut_ends.isVisible()
    assert h / win.canvas.pixel() < 8.0  # cells smaller than the corner squares
    for name in ("corners", "cut_ends"):
        item = getattr(items, name)
        if item.isVisible():
            assert item.opts["brush"].style() == QtCore.Qt.BrushStyle.NoBrush
    c = np.asarray(lay.blocks[0].corners[0], float)
    win.canvas.zoom_to((c[0] - 3 * h, c[1] - 3 * h, c[0] + 3 * h, c[1] + 3 * h), margin=0)
    assert h / win.canvas.pixel() > 8.0
    assert items.corners.isVisible() and items.corners.opts["brush"].style() != QtCore.Qt.BrushStyle.NoBrush
    assert items.cut_ends.opts["brush"].style() != QtCore.Qt.BrushStyle.NoBrush


def test_a_long_drag_of_a_cut_end_lets_the_stretched_blocks_cells_follow(qtbot, win):
    """A cut end of a ring lake's two-block layout dragged 40° round the shore: both blocks kept their
    cell counts, one block's cells along the ring stretched, the other's squeezed, with nothing said
    (under Xvfb: a drag of 70° left 40×72 and 40×204).  At the end of the drag the cells of a block
    the drag stretched or squeezed by more than a fifth follow the cell size, the Messages say so,
    and one undo step brings the layout of before back."""
    from app.drag_cells import STRETCH, cell_lengths
    from app.lake import Lake, compute_layout
    from meshcore import testing

    poly = testing.round_lake(762031, kind="ring", radius=2000.0)
    lake = Lake(
        outline=np.asarray(poly.exterior.coords)[:-1],
        holes=tuple(np.asarray(r.coords)[:-1] for r in poly.interiors),
        target_cells=3000,
    )
    lake = lake.replaced(layout=compute_layout(lake))
    win.lake_ctl.generate_after = False
    win.editor.set_lake(lake, "Auto layout")
    lay0 = win.doc.project.layout
    said = []
    win.doc.reported.connect(lambda level, text: said.append(text))
    n = win.stack.count()
    drag_shore_end_round(qtbot, win, lay0)
    lay1 = win.doc.project.layout
    assert win.lake_ctl.edit_error is None
    assert [b.cells for b in lay1.blocks] != [b.cells for b in lay0.blocks]
    ratio = cell_lengths(lay1) / cell_lengths(lay0)
    assert np.all(np.abs(np.log(ratio)) <= np.log1p(STRETCH) + 0.1)  # no block's cells stretched much now
    assert any("Cells follow the drag" in t for t in said)
    n_cells = f"{lay1.n_cells:,} cells"
    assert n_cells in win._status.text() and win._status.text().startswith("Move cut end")  # not the old count
    assert win.stack.count() == n + 1
    win.stack.undo()
    assert win.doc.project.layout is lay0


def test_the_worst_place_of_a_limit_brings_its_blocks_numbers(qtbot, win, tmp_path):
    """Double-click a failed limit: the view zoomed to its worst place (b4 on held-out g181803), but
    the block table under the verdict went on showing b0's numbers ('min Jacobian ratio 0.3766',
    'cells 8 × 8'), the block active before.  The worst place's block is the active block now."""
    from meshcore.quality.lake import Location

    _laid_out(qtbot, win, tmp_path, 762011)
    names = [b.name for b in win.doc.project.blocks]
    assert len(names) > 2 and win.doc.active == 0
    k = len(names) - 1
    lay = win.doc.project.layout
    x, y = np.mean(np.asarray(lay.blocks[k].corners, float), axis=0)
    win.lake_quality.go_to.emit(Location(0.5, names[k], 1, 1, float(x), float(y)), "node orthogonality")
    assert win.doc.active == k
    assert win.doc.block.name == names[k]
    assert win.doc.grids and win.doc.grid is win.doc.grids[k]  # the block table shows its grid


def test_the_quality_preset_chosen_stays_chosen_after_a_restart(qtbot, win, tmp_path):
    """efdc picked in the Quality dock, the app quit and started again, the project reopened: the
    verdict was delft3d's again (the preset was not remembered, as the View toggles are)."""
    from PySide6 import QtCore

    from app.main_window import MainWindow

    box = win.lake_quality.preset
    assert box.currentText() != "efdc"
    box.setCurrentText("efdc")
    assert win.close()
    settings = QtCore.QSettings(str(tmp_path / "settings.ini"), QtCore.QSettings.Format.IniFormat)
    again = MainWindow(settings=settings, recovery=tmp_path / "recovery2.gcmesh")
    again.quiet = True
    qtbot.addWidget(again)
    assert again.lake_quality.preset.currentText() == "efdc"
    again.solver.shutdown(msecs=10_000)


def test_a_lake_with_one_island_is_said_to_have_one_island(qtbot, win, tmp_path, monkeypatch):
    """A generated ring lake imported: the status bar and the Auto layout offer said '1 island(s)'."""
    from meshcore import testing

    poly = testing.round_lake(762051, kind="ring", radius=2000.0)
    rings = [poly.exterior, *poly.interiors]
    lines = ["x,y"]
    for k, ring in enumerate(rings):
        lines += [""] * bool(k) + [f"{x:.2f},{y:.2f}" for x, y in ring.coords]
    path = tmp_path / "ring.csv"
    path.write_text("\n".join(lines) + "\n")
    said = []
    shown = win.message
    monkeypatch.setattr(win, "message", lambda text, **kw: (said.append(text), shown(text, **kw)))
    assert win.io.import_points(path)
    assert len(win.doc.project.lake.holes) == 1
    box = win.lake_ctl.prompt
    assert box is not None and "1 island." in box.text() and "island(s)" not in box.text()
    assert any("and 1 island from" in t for t in said)


def test_block_names_are_kept_when_a_changed_block_touches_itself():
    """A layout's piece can be a ring that touches itself (the canvas makes such pieces valid to draw
    them); the overlap test of the names (shapely's intersection) raised GEOSException on one, and
    the cut edit ended as 'internal error'.  Such a block is made valid first."""
    from app.block_names import names_kept
    from meshcore.layout.blocks import Piece
    from meshcore.layout.model import Layout, LayoutBlock

    def lay(rings_names):
        pieces = tuple(Piece(np.asarray(r, float), (0, 1, 2, 3), n) for r, n in rings_names)
        blocks = tuple(LayoutBlock(n, tuple(map(tuple, np.asarray(r, float)[:4])), (4, 4)) for r, n in rings_names)
        return Layout(polygon=None, cell_size=1.0, cuts=(), pieces=pieces, blocks=blocks)

    square = [(0, 0), (1, 0), (1, 1), (0, 1)]
    before = lay([(square, "b0"), ([(1, 0), (3, 0), (3, 2), (1, 2)], "b1")])
    bow = [(1, 0), (3, 2), (3, 0), (1, 2)]  # b1 changed: its ring crosses itself at (2, 1)
    after = lay([(bow, "b0"), (square, "b1")])  # named in the order found
    out = names_kept(before, after)
    assert [b.name for b in out.blocks] == ["b0", "b1"]  # the square keeps b0, the changed block b1
    assert np.array_equal(out.pieces[0].ring, np.asarray(square, float))
