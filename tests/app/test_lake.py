"""A lake in the app: import with islands, Auto layout, the orthogonal grid, presets, export, undo."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from tests.app.waits import wait_for, wait_idle

pytestmark = pytest.mark.gui

LAKES = Path(__file__).resolve().parents[2] / "benchmarks" / "lakes"
ISEO = LAKES / "lake_iseo_sparse.geojson"  # one island (Monte Isola)
COMO = LAKES / "lake_como.geojson"  # Y-shaped, three arms


def lay_out(qtbot, win, path, cell_size=None):
    """Import ``path`` and run Auto layout as a user does (panel, then the toolbar action)."""
    assert win.io.import_points(path, project_lonlat=True)
    if cell_size is not None:
        win.lake_panel.cell_size.setValue(cell_size)
        win.lake_panel.cell_size.editingFinished.emit()
    win.a_auto_layout.trigger()
    wait_for(qtbot, win, lambda: win.doc.project.layout is not None or bool(win.lake_ctl.last_error))
    assert win.lake_ctl.last_error is None
    wait_idle(qtbot, win)
    return win.doc.project.layout


def test_import_reads_islands_and_offers_auto_layout(qtbot, win):
    assert win.io.import_points(ISEO, project_lonlat=True)
    p = win.doc.project
    assert p.lake is not None and len(p.lake.holes) == 1  # Monte Isola
    np.testing.assert_array_equal(win.doc.block.points, p.lake.outline)  # the shore is the editable block
    assert p.crs.startswith("EPSG:326")
    prompt = win.lake_ctl.prompt
    assert prompt is not None and not prompt.isVisible()  # quiet: offered, not shown
    assert "island" in prompt.text()
    assert win.docks["lake"].isVisible()
    # the island is drawn (shore and island rings)
    x, _y = win.canvas.lake_items.shore.getData()
    assert np.isnan(x).sum() == 2
    # the offer's button runs Auto layout, and the grid follows
    go = next(b for b in prompt.buttons() if b.text() == "Auto layout")
    win.lake_panel.cell_size.setValue(300.0)
    win.lake_panel.cell_size.editingFinished.emit()
    go.click()
    wait_for(qtbot, win, lambda: win.doc.project.layout is not None)
    wait_idle(qtbot, win)
    lay = win.doc.project.layout
    assert lay.cell_size == 300.0 and len(lay.polygon.interiors) == 1
    assert win.lake_ctl.prompt is None


def test_one_block_over_islands_warns_and_the_command_line_lays_out(qtbot, win):
    """Generate on the imported shore alone covers the island: a warning says so; ``--solve``
    on a lake file does what the import offer proposes (Auto layout, then the grid)."""
    from PySide6 import QtWidgets

    from app.__main__ import solve_as_opened

    assert win.io.import_points(ISEO, project_lonlat=True)
    win.generate()
    wait_idle(qtbot, win)
    warned = [t for lv, t in win.messages_panel.messages() if lv == "warning" and "island" in t]
    assert warned and "Auto layout" in warned[0]
    win.lake_panel.cell_size.setValue(600.0)
    win.lake_panel.cell_size.editingFinished.emit()
    solve_as_opened(QtWidgets.QApplication.instance(), win)
    wait_idle(qtbot, win)
    lay = win.doc.project.layout
    assert lay is not None and len(lay.blocks) > 1 and len(lay.polygon.interiors) == 1
    assert len(win.doc.project.blocks) == len(lay.blocks)


def test_auto_layout_draws_blocks_and_generates_an_orthogonal_grid(qtbot, win):
    lay = lay_out(qtbot, win, ISEO, cell_size=300.0)
    n = len(lay.blocks)
    doc = win.doc
    assert len(doc.project.blocks) == n and n > 1
    # the canvas: cut lines, block corners and a "name / ni×nj" (or "ni×nj") label per block with room
    # on screen (test_canvas_lod.py: the labels as the view zooms)
    items = win.canvas.lake_items
    texts = {f"{b.name}\n{b.cells[0]}×{b.cells[1]}" for b in lay.blocks} | {
        f"{b.cells[0]}×{b.cells[1]}" for b in lay.blocks
    }
    assert len(items.labels) >= n and set(items.shown_labels) <= texts
    assert len(items.cuts.getData()[0]) > 0 and len(items.corners.getData()[0]) >= 4
    # the panel lists the blocks and their cells
    assert win.lake_panel.table.rowCount() == n
    assert win.lake_panel.table.item(0, 1).text() == f"{lay.blocks[0].cells[0]} × {lay.blocks[0].cells[1]}"
    # every block gridded with its layout cells, as one orthogonal multiblock grid
    assert sorted(doc.grids) == list(range(n))
    assert [doc.grids[k].cells for k in range(n)] == [tuple(b.cells) for b in lay.blocks]
    assert doc.multiblock is not None and doc.multiblock.mode == "orthogonal"
    # the quality dock: lake metrics against a preset, pass/fail per limit, misses ringed
    box = win.lake_quality
    assert box.isVisible() and doc.lake_metrics is not None
    assert doc.lake_metrics.summary()["folded_cells"] == 0
    assert doc.lake_metrics is win.solver.last_result.metrics  # measured in the worker, not the GUI thread
    for preset in ("delft3d", "efdc"):
        box.preset.setCurrentText(preset)
        v = box.verdict
        assert v is not None and v.preset.name == preset
        assert box.table.rowCount() == len(v.results)
        words = {box.table.item(k, 0).text().split()[0] for k in range(box.table.rowCount())}
        assert words <= {"pass", "FAIL", "not"}
        misses = win.canvas.lake_items.misses.getData()[0]
        assert (len(misses) > 0) == any(r.limit.statistic == "each" for r in v.failed)


def _far_synthetic_rings() -> list[np.ndarray]:
    """A lobed lake with islands (about 16 km across) in lon/lat, far from any UTM origin."""
    import pyproj

    from meshcore.testing import lake_with_islands

    poly = lake_with_islands(3, radius=8000.0, n_islands=2)
    to_lonlat = pyproj.Transformer.from_crs("EPSG:32610", "EPSG:4326", always_xy=True)
    rings = []
    for ring in [poly.exterior, *poly.interiors]:
        xy = np.asarray(ring.coords) + (687_654.321, 5_432_109.876)  # UTM 10 N, near the zone's edge
        rings.append(np.column_stack(to_lonlat.transform(xy[:, 0], xy[:, 1])).round(7))
    return rings


def _far_synthetic_lake(path: Path) -> Path:
    """:func:`_far_synthetic_rings` as lon/lat GeoJSON."""
    import json

    path.write_text(json.dumps({"type": "Polygon", "coordinates": [r.tolist() for r in _far_synthetic_rings()]}))
    return path


def _headerless_csv(path: Path) -> Path:
    """:func:`_far_synthetic_rings` as a CSV of bare lon, lat numbers (no header, no CRS), rings
    separated by blank lines, and an open line from the shore into the water (a drawn inlet)."""
    rings = _far_synthetic_rings()
    shore = rings[0]
    k = len(shore) // 3
    inlet = np.vstack([shore[k], shore[k] + 0.3 * (rings[1].mean(axis=0) - shore[k])])
    blocks = ["\n".join(f"{x:.7f},{y:.7f}" for x, y in r) for r in [*rings, inlet]]
    path.write_text("\n\n".join(blocks) + "\n")
    return path


@pytest.mark.parametrize(
    "name", ["taal_lake.kml", "lake_iseo_sparse.geojson", "lake_como.csv", "far synthetic", "headerless csv"]
)
def test_the_same_layout_and_grid_as_meshcore_mesh(qtbot, win, tmp_path, name):
    """The app's layout and grid of a file are the CLI's: same blocks, cells and nodes to the last bit.

    A CSV of bare lon/lat numbers is projected by both (one rule, :func:`meshcore.cli.lakefile.is_lonlat`),
    and an open line touching its shore is dropped by both (:func:`meshcore.cli.lakefile.lake_rings`).
    The layout's discrete choices change with the last bits of the coordinates (a lake
    shifted by a round number can get another block count), so both compute in the same
    local frame; the CLI writes world coordinates = local + origin, as the app exports them.
    """
    import contextlib
    import io

    from app.lake import water
    from meshcore.cli import main
    from meshcore.io import read_blocks

    made = {"far synthetic": _far_synthetic_lake, "headerless csv": _headerless_csv}
    path = made[name](tmp_path / f"made{'.csv' if 'csv' in name else '.geojson'}") if name in made else LAKES / name
    win.lake_ctl.generate_after = False
    assert win.io.import_points(path, project_lonlat=True)
    lake = win.doc.project.lake
    assert win.doc.project.crs.startswith("EPSG:32")  # lon/lat recognised and projected, header or not
    if name == "headerless csv":  # the inlet line dropped with a note, as the CLI does
        assert len(lake.holes) == 2
        notes = [t for lv, t in win.messages_panel.messages() if "touching the shore" in t]
        assert len(notes) == 1 and "not an island" in notes[0]
    h = math.sqrt(water(lake.outline, lake.holes)[0].area / 1500)  # ~1500 cells: quick, several blocks
    win.lake_ctl.set_cell_size(h)
    win.a_auto_layout.trigger()
    wait_for(qtbot, win, lambda: win.doc.project.layout is not None or bool(win.lake_ctl.last_error))
    assert win.lake_ctl.last_error is None
    win.generate()
    wait_idle(qtbot, win)
    app_mb = win.doc.multiblock
    assert app_mb is not None and win.doc.lake_metrics is not None
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()) as err:
        rc = main(["mesh", str(path), "--cell-size", repr(h), "-o", str(tmp_path / "cli.npz")])
    assert rc in (0, 3), err.getvalue()
    assert ("touching the shore" in err.getvalue()) == (name == "headerless csv")
    cli = read_blocks(tmp_path / "cli.npz")
    lay = win.doc.project.layout
    assert len(lay.blocks) > 1
    assert [g.cells for g in cli.blocks] == [tuple(b.cells) for b in lay.blocks]
    p = win.doc.project
    assert cli.frame.crs == p.crs and cli.frame.origin == (0.0, 0.0)  # the CLI writes world coordinates
    for k, g in enumerate(app_mb.grids):
        X, Y = cli.world(k)
        np.testing.assert_array_equal(g.x + p.origin[0], X)
        np.testing.assert_array_equal(g.y + p.origin[1], Y)


def test_layout_undo_redo_and_clear(qtbot, win):
    win.lake_ctl.generate_after = False
    assert win.io.import_points(ISEO, project_lonlat=True)
    shore = win.doc.project
    win.lake_ctl.set_cell_size(300.0)
    win.a_auto_layout.trigger()
    wait_for(qtbot, win, lambda: win.doc.project.layout is not None)
    laid = win.doc.project
    # the block points are not editable in a layout: a clear message instead
    win.editor.move_points([0], (10.0, 0.0))
    assert win.doc.project is laid and "Lake panel" in win._status.text()
    win.stack.undo()
    assert win.doc.project.layout is None and len(win.doc.project.blocks) == 1
    assert win.canvas.lake_items.shown_labels == []
    win.stack.undo()  # the cell size
    assert win.doc.project.lake.cell_size is None
    win.stack.redo()
    win.stack.redo()
    assert win.doc.project is laid
    win.a_clear_layout.trigger()
    p = win.doc.project
    assert p.layout is None and p.lake.cell_size == 300.0 and len(p.blocks) == 1
    np.testing.assert_array_equal(p.blocks[0].points, shore.lake.outline)
    # another lake imported over a laid-out one replaces it (one undo step brings it back)
    win.stack.undo()
    assert win.doc.project is laid
    assert win.io.import_points(COMO, project_lonlat=True)
    p = win.doc.project
    assert p.layout is None and len(p.blocks) == 1 and p.lake.holes == () and len(p.lake.outline) > 300
    win.stack.undo()
    assert win.doc.project is laid


def test_export_como_to_delft3d_dd_and_vtm(qtbot, win, tmp_path):
    """The issue's target: Como in, Auto layout, generate, a Delft3D DD file out."""
    from meshcore.io import read

    lay = lay_out(qtbot, win, COMO)
    assert 8_000 < lay.n_cells < 12_000
    assert win.doc.lake_metrics.summary()["folded_cells"] == 0
    # the lake-grid issue's targets, as the user reads them: the gcmesh-lake preset in the quality dock
    box = win.lake_quality
    box.preset.setCurrentText("gcmesh-lake")
    rows = [box.table.item(k, 0).text() for k in range(box.table.rowCount())]
    assert "gcmesh-lake: PASS" in box.headline.text() and len(rows) == 8, (box.headline.text(), rows)
    assert all(t.startswith("pass") for t in rows), rows
    from app.io_controller import export_default

    assert export_default(win.doc.project) == "delft3d-dd"  # the export dialog offers it first
    out = tmp_path / "como.ddb"
    assert win.io.export_mesh(out), win._status.text()
    back = read(out)
    assert len(back.blocks) == len(lay.blocks)
    assert sum(g.cells[0] * g.cells[1] for g in back.blocks) == lay.n_cells
    assert win.io.export_mesh(tmp_path / "como.vtm")
    assert (tmp_path / "como.vtm").exists()
    # the same file through `meshcore mesh` (a .ddb asks it for a regular layout): the same blocks,
    # cells and nodes as the app's export (the same layout in the app and the CLI)
    from meshcore.cli import main

    cli = tmp_path / "cli" / "como.ddb"
    cli.parent.mkdir()
    assert main(["mesh", str(COMO), "-o", str(cli), "-q"]) == 0
    want = read(cli)
    assert [g.cells for g in back.blocks] == [g.cells for g in want.blocks]
    for g, h in zip(back.blocks, want.blocks, strict=True):
        np.testing.assert_array_equal(g.x, h.x)
        np.testing.assert_array_equal(g.y, h.y)
    assert sorted(p.name for p in out.parent.glob("como*.grd")) == sorted(p.name for p in cli.parent.glob("*.grd"))


def test_a_ddb_that_delft3d_cannot_couple_says_what_to_do(qtbot, win, tmp_path):
    """A symmetric Y gets a star at its junction (six blocks meet at its centre), which Delft3D's
    domain decomposition cannot couple: export says so and offers the regular layout.  (Como
    at 300 m was used here until its default layout became one Delft3D can couple.)"""
    from meshcore import testing

    shore = 1000.0 * np.asarray(testing.y_junction().exterior.coords)[:-1]  # metres, not degrees
    src = tmp_path / "y.csv"
    np.savetxt(src, shore, delimiter=",", header="x,y", comments="")
    lay_out(qtbot, win, src, cell_size=100.0)
    m = win.doc.project.layout.topology().node_map
    assert any(c.free and c.valence != 4 for c in m.corners)  # the star
    out = tmp_path / "x.ddb"
    assert not win.io.export_mesh(out)
    assert not out.exists()
    assert "regular" in win._status.text()
    win.a_auto_layout_regular.trigger()
    wait_for(qtbot, win, lambda: win.doc.project.lake.regular and win.doc.project.layout is not None)
    wait_idle(qtbot, win)
    if not win.io.export_mesh(out):
        assert "Cannot export" in win._status.text() and not out.exists()


def test_save_and_recover_a_lake_layout(qtbot, win, tmp_path):
    from app import recovery

    lay = lay_out(qtbot, win, ISEO, cell_size=300.0)
    path = tmp_path / "iseo.toml"
    assert win.io.save_to(path)
    # the case file holds the layout: it opens as the same lake layout (shore, island, cuts, cells)
    assert win.io.open_path(path)
    opened = win.doc.project.layout
    assert opened is not None and len(opened.polygon.interiors) == 1
    assert [(b.name, b.cells) for b in opened.blocks] == [(b.name, b.cells) for b in lay.blocks]
    assert win.doc.project.crs and opened.cell_size == pytest.approx(lay.cell_size)
    win.generate()
    wait_idle(qtbot, win)
    assert win.doc.multiblock is not None and len(win.doc.multiblock.grids) == len(lay.blocks)
    # the autosave keeps the lake: the recovered project has the same layout and settings
    recovery.write(win.doc.project, tmp_path / "rec.toml")
    back, _ = recovery.read(tmp_path / "rec.toml")
    got = back.layout
    assert got is not None and back.lake.cell_size == 300.0
    assert [b.cells for b in got.blocks] == [b.cells for b in lay.blocks]
    assert len(back.blocks) == len(lay.blocks)
    # a lake not laid out yet: its shore, islands and settings
    win.a_clear_layout.trigger()
    recovery.write(win.doc.project, tmp_path / "rec2.toml")
    back, _ = recovery.read(tmp_path / "rec2.toml")
    assert back.layout is None and len(back.lake.holes) == 1 and back.lake.cell_size == 300.0


def test_a_lake_refused_is_a_message(qtbot, win):
    assert win.io.import_points(ISEO, project_lonlat=True)
    win.lake_ctl.set_cell_size(1e6)  # a few cells for the whole lake
    win.a_auto_layout.trigger()
    wait_for(qtbot, win, lambda: not win.lake_ctl.busy)
    assert win.doc.project.layout is None
    assert "Cannot lay out the lake" in win._status.text() and "cell size" in win._status.text()


def test_colour_by_time_step_cost_covers_every_block_of_a_lake(qtbot, win, monkeypatch):
    """``--quality "time step"`` colours every block by the lake metrics' ``shrink`` (the cell size over
    the cell's shortest edge: where an explicit model must step shortest), on a fixed scale from 1."""
    from app.__main__ import quality_label
    from app.document import SHRINK, SHRINK_LEVELS

    lay = lay_out(qtbot, win, ISEO, cell_size=600.0)
    assert quality_label("time step") == SHRINK == quality_label("shortest")
    win.quality_panel.metric.setCurrentText(SHRINK)
    assert win.doc.colour_by == SHRINK
    m = win.doc.lake_metrics
    layers = win.doc.colour_blocks()
    assert len(layers) == len(lay.blocks) and len(win.canvas.quality_items) == len(lay.blocks) - 1
    every = np.concatenate([np.ravel(v) for _k, _g, v in layers])
    assert np.sort(every) == pytest.approx(np.sort(m.values("shrink")))  # the report's own numbers
    for k, g, values in layers:  # each the cell size over the cell's shortest edge, measured here
        e1 = np.hypot(np.diff(g.x, axis=0), np.diff(g.y, axis=0))
        e2 = np.hypot(np.diff(g.x, axis=1), np.diff(g.y, axis=1))
        shortest = np.minimum(np.minimum(e1[:, :-1], e1[:, 1:]), np.minimum(e2[:-1], e2[1:]))
        assert values == pytest.approx(lay.cell_size / shortest), k
    bar = win.canvas.colorbar
    assert bar is not None and tuple(bar.levels()) == pytest.approx(SHRINK_LEVELS)
    g = layers[0][1]
    assert SHRINK in win._cell_readout(g.x[1:3, 1:3].mean(), g.y[1:3, 1:3].mean())
    win.quality_panel.metric.setCurrentText("none")
    # the verdict's headline names the smallest cell when it is far smaller than the rest
    from meshcore.quality import lake

    assert "shortest edge" not in win.lake_quality.headline.text()  # Iseo at 600 m: no such cell
    monkeypatch.setattr(lake, "SHRINK_NOTE", 1.0)
    win.lake_quality.refresh()
    worst = m.max("shrink")
    assert f"shortest edge {1 / worst:.3g} cells (explicit time step ÷ {worst:.3g})" in win.lake_quality.headline.text()


def test_colour_by_deviation_covers_every_block_of_a_lake(qtbot, win):
    """``--quality deviation`` (and the Quality panel's combo) colours all blocks by the largest
    deviation from 90° at each cell's nodes, as ``meshcore mesh --colour deviation`` draws it."""
    from app.__main__ import quality_label
    from app.document import DEVIATION

    lay = lay_out(qtbot, win, ISEO, cell_size=600.0)
    assert quality_label("deviation") == DEVIATION and quality_label("Skew") == "skewness"
    win.quality_panel.metric.setCurrentText(quality_label("deviation"))
    assert win.doc.colour_by == DEVIATION
    canvas, m = win.canvas, win.doc.lake_metrics
    assert canvas.quality_item is not None and len(canvas.quality_items) == len(lay.blocks) - 1
    layers = win.doc.colour_layers()
    assert len(layers) == len(lay.blocks)
    for (g, values), b in zip(layers, [m.blocks[win.doc.active], *m.blocks[1:]], strict=True):
        d = b.deviation
        assert values.shape == g.cells
        i, j = np.unravel_index(np.nanargmax(values), values.shape)
        assert values[i, j] == np.nanmax(d[i : i + 2, j : j + 2]) == np.nanmax(values)
        assert np.nanmax(values) == np.nanmax(d)  # every interior node's value is some cell's
    # the readout under the cursor names the active block's cell
    g = layers[0][0]
    cx, cy = g.x[1:3, 1:3].mean(), g.y[1:3, 1:3].mean()
    assert DEVIATION in win._cell_readout(cx, cy)
    win.quality_panel.metric.setCurrentText("none")
    assert canvas.quality_item is None and canvas.quality_items == []


def test_an_unknown_quality_metric_on_the_command_line_is_refused(capsys):
    from app.__main__ import main, quality_label

    with pytest.raises(ValueError, match="known: none, Jacobian ratio"):
        quality_label("deviaton")
    with pytest.raises(ValueError, match="names 3 metrics"):
        quality_label("ratio")
    with pytest.raises(SystemExit) as exc:
        main(["--quality", "deviaton", "--screenshot", "never.png"])
    assert exc.value.code == 2 and "no such metric" in capsys.readouterr().err


def test_an_open_line_on_the_shore_is_not_an_island_in_the_app_either(qtbot, win):
    """The DXF of ``meshcore mesh``'s inlet test (UTM metres, no CRS in the file): its open inlet
    line drawn from the shore is dropped with the CLI's note; the shore alone is the lake."""
    pytest.importorskip("ezdxf")
    src = Path(__file__).resolve().parents[2] / "tests" / "data" / "lake_zurich_sparse_utm32.dxf"
    from meshcore.cli.lakefile import lake_rings
    from meshcore.io import read_points

    shore, islands, notes = lake_rings(read_points(src))
    assert islands == [] and len(notes) == 1
    assert win.io.import_points(src)
    lake = win.doc.project.lake
    assert lake is not None and lake.holes == ()
    np.testing.assert_array_equal(lake.outline, shore)
    assert win.doc.project.crs == ""  # metres without a CRS: not mistaken for degrees
    said = [t for lv, t in win.messages_panel.messages() if lv == "warning" and "touching the shore" in t]
    assert said == [f"{src.name}: {notes[0]}"]


def test_convergence_plot_marks_the_levels_and_misses_step_aside_for_colours(qtbot, win):
    """The lake grid is made coarse to fine: the convergence plot marks where each level begins
    (every live snapshot before a mark has the coarser level's cells, every one after it the
    finer's).  Cells coloured by a metric: the preset's misses are hidden (they would cover the
    colours), View ▸ Preset misses (Q) brings them back as thin rings; no colouring, dots again."""
    from app.document import DEVIATION
    from app.pipeline import ALL_BLOCKS

    seen = []  # (sweep, cells of all blocks) of every live snapshot
    win.solver.progress.connect(
        lambda k, snap: (
            seen.append((snap.iteration, sum(g.cells[0] * g.cells[1] for g in snap.grids)))
            if k == ALL_BLOCKS and snap.grids
            else None
        )
    )
    lay = lay_out(qtbot, win, ISEO, cell_size=600.0)
    conv = win.conv_panel
    names = [name for _k, name in conv.levels]
    assert names == ["cells ÷4", "÷2", "full"] and lay.multiple == 4
    starts = [k for k, _name in conv.levels]
    assert starts[0] == 0 and starts[1] < starts[2] < win.doc.multiblock.info.iterations
    lines = [ln for ln in conv.level_lines if ln.isVisible()]
    assert [ln.value() for ln in lines] == starts and [ln.label.format for ln in lines] == names
    full = sum(b.cells[0] * b.cells[1] for b in lay.blocks)
    for it, cells in seen:  # each snapshot has the cells of the level its sweep lies in
        lev = sum(it > k for k in starts[1:])
        assert cells == full // 4 ** (2 - lev), (it, cells, starts)
    # which levels get a live snapshot depends on the redraw budget (a share of CPU time: a
    # fast level may pass between two redraws; a clean clone's CI saw none on "÷2")
    assert seen
    assert conv.getAxis("bottom").labelText == "sweep"
    # the status label in the plot's words (it said "iteration …, residual …" of a lake's sweeps)
    assert win.solve_status._label_text.startswith("lake grid: sweep ")
    assert "largest move" in win.solve_status._label_text and "residual" not in win.solve_status._label_text

    from PySide6 import QtCore

    items, pts = win.canvas.lake_items, np.array([[0.0, 0.0], [100.0, 50.0]])

    def filled():
        return items.misses.opts["brush"].style() != QtCore.Qt.BrushStyle.NoBrush

    win.lake_quality.misses.emit(pts)
    assert items.misses.isVisible() and win.a_misses.isChecked() and filled()
    win.quality_panel.metric.setCurrentText(DEVIATION)
    assert not items.misses.isVisible() and not win.a_misses.isChecked()
    assert "Preset misses" in win._status.text() or win.lake_quality.verdict.passed
    win.a_misses.trigger()  # Q: over the colours, as thin rings
    assert items.misses.isVisible() and items.misses_over_colours and not filled()
    win.a_misses.trigger()
    assert not items.misses.isVisible()
    win.lake_quality.table.clicked.emit(win.lake_quality.table.model().index(0, 0))  # a limit picked: where?
    assert items.misses.isVisible() and win.a_misses.isChecked()
    win.quality_panel.metric.setCurrentText("none")
    assert items.misses.isVisible() and not items.misses_over_colours and filled()
    # a click on a failed limit also goes to its worst place, and shows that limit's misses
    from app.views.lake_panel import miss_points, worst_miss

    v = win.lake_quality.verdict
    shown = pts if worst_miss(v, 0) is None else miss_points(v, 0)[:, :2]
    drawn = np.column_stack(items.misses.getData())  # the worst per patch of the screen (test_appwalk27)
    assert len(drawn) and {tuple(p) for p in drawn} <= {tuple(p) for p in shown}
    # thousands of misses (a poor hand layout): one mark per patch of the screen, not an orange lake
    win.lake_quality.misses.emit(np.random.default_rng(0).uniform(0, 1000, (5000, 2)))
    assert 0 < len(items.misses.getData()[0]) < 5000


def _thin_island_lake(path, h: float = 500.0, needles: int = 1):
    """A round lake (lon/lat, 20 cells of ``h`` metres in radius) with ``needles`` islands 1.2 cells
    wide (the layout leaves them out) and one 4 cells wide."""
    import json

    from shapely import affinity
    from shapely.geometry import LineString, Point, Polygon, mapping

    lake = Point(0, 0).buffer(20 * h, quad_segs=32)
    thin = [
        LineString([(-5 * h, -6 * k * h), (5 * h, -6 * k * h)]).buffer(0.6 * h, quad_segs=8) for k in range(needles)
    ]
    blob = Point(8 * h, 8 * h).buffer(2.0 * h, quad_segs=8)
    metres = Polygon(lake.exterior, [*(n.exterior for n in thin), blob.exterior])
    lat = 46.0  # degrees of a metre there: the widths change by < 1 % in UTM
    poly = affinity.affine_transform(metres, [1 / (111_320 * math.cos(math.radians(lat))), 0, 0, 1 / 111_320, 9.0, lat])
    path.write_text(json.dumps({"type": "Feature", "properties": {}, "geometry": mapping(poly)}))
    return path


def test_layout_notes_reach_the_message_panel_and_the_status_line(qtbot, win, tmp_path):
    """An island narrower than two cells is left out by the layout: its note, naming it, is in the
    message panel (as ``meshcore mesh`` prints it), and the Lake panel's summary counts the notes."""
    from meshcore.layout import auto_layout

    src = _thin_island_lake(tmp_path / "thin.geojson")
    lay = lay_out(qtbot, win, src, cell_size=500.0)
    assert len(win.doc.project.lake.holes) == 2 and len(lay.polygon.interiors) == 1  # the needle left out
    lake = win.doc.project.lake
    assert lay.notes == auto_layout(lake.outline, holes=lake.holes, cell_size=500.0, multiple=4).notes
    shown = [t for _lv, t in win.messages_panel.messages()]
    for note in lay.notes:
        assert f"layout: {note}" in shown
    assert any("left out" in t and t.startswith("layout: island 1 near (") for t in shown), shown
    k = len(lay.notes)
    summary = win.lake_panel.summary
    assert f"{k} note{'s' * (k != 1)} on the water" in summary.text()
    assert all(note in summary.toolTip() for note in lay.notes)


def test_many_left_out_islands_one_note_and_each_in_the_message_panel(qtbot, win, tmp_path):
    """Four islands too narrow for the grid: one note for them all, and each island's own note
    (``Layout.details``) in the message panel."""
    src = _thin_island_lake(tmp_path / "thin4.geojson", needles=4)
    lay = lay_out(qtbot, win, src, cell_size=500.0)
    assert len(lay.polygon.interiors) == 1 and len(lay.details) == 4
    assert sum("islands are less than" in n for n in lay.notes) == 1
    shown = [t for _lv, t in win.messages_panel.messages()]
    for note in lay.details:
        assert f"layout (detail): {note}" in shown


def test_islands_under_the_grid_are_warned_of(qtbot, win, tmp_path, monkeypatch):
    """What ``meshcore mesh`` warns of after the grid (an island under it, cells across one) is a
    warning in the message panel, not only a number in the quality table."""
    from meshcore.quality import coverage

    said = ["island 1 near (1, 2) is under the grid although the layout goes round it: the grid lost it"]
    monkeypatch.setattr(coverage.Coverage, "warnings", lambda self: list(said))
    lay_out(qtbot, win, _thin_island_lake(tmp_path / "thin.geojson"), cell_size=500.0)
    assert win.doc.lake_metrics is not None
    warned = [t for lv, t in win.messages_panel.messages() if lv == "warning"]
    assert f"lake grid: {said[0]}" in warned


def test_islands_that_touch_are_joined_with_a_note_on_import(qtbot, win, tmp_path):
    """Two islands that touch are one island to the layout: the import says so, as ``meshcore mesh``
    does on reading the file (the layout, made from the joined water, has no note of it)."""
    import json

    from shapely import affinity
    from shapely.geometry import Point, Polygon, box, mapping

    h = 500.0
    lake = Point(0, 0).buffer(20 * h, quad_segs=32)
    a, b = box(-4 * h, -2 * h, 0, 2 * h), box(0, -1 * h, 3 * h, 1 * h)  # sharing a side
    metres = Polygon(lake.exterior, [a.exterior, b.exterior])
    poly = affinity.affine_transform(metres, [1 / (111_320 * math.cos(math.radians(46))), 0, 0, 1 / 111_320, 9.0, 46.0])
    src = tmp_path / "two_islands.geojson"
    src.write_text(json.dumps({"type": "Feature", "properties": {}, "geometry": mapping(poly)}))
    assert win.io.import_points(src, project_lonlat=True)
    said = [t for lv, t in win.messages_panel.messages() if lv == "warning"]
    assert f"{src.name}: islands 1 and 2 touch: joined into one" in said, said


def test_a_point_clicked_before_the_import_does_not_drop_its_islands(qtbot, win):
    """A stray click in Draw made an open one-point block 0; the lake imported next went to
    block 1 and its islands were dropped: Auto layout laid out the shore alone (the grid over
    the island, the cell size from the area with it), while the status said '1 island(s)'."""
    win.editor.add_point((0.0, 0.0))
    assert len(win.doc.project.blocks[0].points) == 1
    lay = lay_out(qtbot, win, ISEO, cell_size=300.0)
    assert len(lay.polygon.interiors) == 1  # Monte Isola
    assert win.doc.project.lake is not None and len(win.doc.project.lake.holes) == 1
