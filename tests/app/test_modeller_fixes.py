"""What the modeller's afternoon in the app left (session 17): each as it went wrong, on generated shapes."""

from __future__ import annotations

import json

import numpy as np
import pytest
import shapely

from meshcore import testing
from tests.app.waits import answer_questions

pytestmark = pytest.mark.gui


def _metres_geojson(path, seed: int, x0: float = 512_000.0, y0: float = 5_603_000.0):
    """A generated lake with islands in projected metres (UTM-like numbers), as a GeoJSON without a CRS."""
    poly = shapely.affinity.affine_transform(testing.lake_with_islands(seed), [300, 0, 0, 300, x0, y0])
    feature = {"type": "Feature", "properties": {"name": path.stem}, "geometry": shapely.geometry.mapping(poly)}
    path.write_text(json.dumps({"type": "FeatureCollection", "features": [feature]}))
    return poly


def _ring(cx: float, cy: float, r: float, n: int = 40) -> np.ndarray:
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    return np.c_[cx + r * np.cos(t), cy + 1.3 * r * np.sin(t)]


def test_a_geojson_in_metres_without_a_crs_is_imported_as_local_metres(qtbot, win, tmp_path):
    """A GeoJSON of metres (no CRS) was refused with "give their CRS: --source-crs EPSG:nnnn", a
    command-line flag the app has no equivalent for; it is read as local metres, with a note."""
    src = tmp_path / "utm_lake.geojson"
    poly = _metres_geojson(src, 761301)
    said = []
    win.doc.reported.connect(lambda _level, text: said.append(text))
    assert win.io.import_points(src)
    p = win.doc.project
    assert p.crs == "" and p.lake is not None
    assert len(p.lake.holes) == len(poly.interiors)
    assert np.abs(p.lake.outline).max() == pytest.approx(np.abs(np.asarray(poly.exterior.coords)).max(), abs=0.01)
    said = " ".join(said) + win.statusBar().currentMessage()
    assert "--source-crs" not in said and "local metres" in said


def test_a_csv_headed_lon_lat_in_metres_is_imported_as_local_metres(qtbot, win, tmp_path):
    """The same for a CSV whose header says lon,lat but whose numbers are metres."""
    src = tmp_path / "mislabelled.csv"
    ring = _ring(300_000.0, 4_100_000.0, 1500.0)
    src.write_text("lon,lat\n" + "\n".join(f"{x:.2f},{y:.2f}" for x, y in ring) + "\n")
    assert win.io.import_points(src)
    assert win.doc.project.crs == ""
    np.testing.assert_allclose(win.doc.project.blocks[0].points, ring, atol=0.01)


def test_degrees_with_one_wrong_number_stay_an_error_without_the_cli_flag(qtbot, win, tmp_path):
    """Degrees with a typo are not metres: still refused, naming the point, and no --source-crs."""
    from app import io_adapter as fio
    from meshcore import ReadError

    ring = _ring(9.0, 47.0, 0.02)
    ring[5, 0] = 900.123
    coords = [*ring.tolist(), ring[0].tolist()]
    feature = {"type": "Feature", "properties": {}, "geometry": {"type": "Polygon", "coordinates": [coords]}}
    src = tmp_path / "typo.geojson"
    src.write_text(json.dumps(feature))
    with pytest.raises(ReadError, match="point 6") as info:
        fio.read_points(src)
    assert "--source-crs" not in str(info.value)


def test_a_file_that_is_not_one_lake_imports_its_largest_line(qtbot, win, tmp_path):
    """Two lakes side by side (not one lake: the small one lies outside the big one's shore): the
    first ring of the file, the small one, became the block; the largest is the lake wanted."""
    src = tmp_path / "two_lakes.csv"
    small, big = _ring(5000.0, 0.0, 300.0), _ring(0.0, 0.0, 2000.0)
    lines = ["x,y", *(f"{x:.2f},{y:.2f}" for x, y in small), "", *(f"{x:.2f},{y:.2f}" for x, y in big)]
    src.write_text("\n".join(lines) + "\n")
    said = []
    win.doc.reported.connect(lambda _level, text: said.append(text))
    assert win.io.import_points(src)
    np.testing.assert_allclose(win.doc.project.blocks[0].points, big, atol=0.01)
    assert any("the largest, part 1" in text and "left out" in text for text in said)


def test_the_save_dialog_offers_the_lake_file_name_and_the_case_is_titled_by_it(qtbot, win, tmp_path, monkeypatch):
    """Save As offered no file name, and a laid-out lake's case was titled "automatic layout: 61
    blocks": both are the imported lake's file name now."""
    from PySide6 import QtWidgets

    from app import io_adapter as fio
    from meshcore.layout import auto_layout
    from tests.app.test_modeller import _metres_lake

    src = _metres_lake(tmp_path / "Lake Tarn.csv", 761302)
    assert win.io.import_points(src)
    offered = []

    def dialog(_parent, _caption, directory, _filter):
        offered.append(directory)
        return str(tmp_path / "out.toml"), ""

    monkeypatch.setattr(QtWidgets.QFileDialog, "getSaveFileName", dialog)
    win.io.remember_dir(tmp_path / "x")
    assert win.io.save_as()
    assert offered == [str(tmp_path / "Lake Tarn.toml")]
    lake = win.doc.project.lake
    from app.lake import with_layout

    laid = with_layout(win.doc.project, lake.replaced(layout=auto_layout(shapely.Polygon(lake.outline, lake.holes))))
    assert 'title = "Lake Tarn"' in fio.dumps_project(laid)


def test_the_recovery_prompt_says_what_it_restores(qtbot, win, tmp_path, monkeypatch):
    """The prompt at start-up asked "Restore the autosaved project?" without saying which: it names
    the file (or the lake), its islands and blocks, and when it was autosaved."""
    import time

    from app import recovery
    from app.lake import with_layout
    from meshcore.layout import auto_layout
    from tests.app.test_modeller import _metres_lake

    assert win.io.import_points(_metres_lake(tmp_path / "Tarn.csv", 761303))
    lake = win.doc.project.lake
    layout = auto_layout(shapely.Polygon(lake.outline, lake.holes))
    project = with_layout(win.doc.project, lake.replaced(layout=layout))
    recovery.write(project, win.io.recovery_path, tmp_path / "tarn-case.toml")
    asked = answer_questions(monkeypatch, "No")
    assert not win.io.offer_recovery()
    (text,) = asked
    n = len(lake.holes)
    assert "tarn-case.toml" in text and f"{n} island" in text and f"{len(layout.blocks)} blocks" in text
    assert time.strftime("%Y-%m-%d", time.localtime()) in text and ("min ago" in text or "just now" in text)
    # never saved: the lake's file name (the project's title)
    assert "Tarn (never saved)" in recovery.describe(project, None, None)


def test_deleting_a_cut_line_updates_the_status_line_and_drops_the_ring(qtbot, win, tmp_path):
    """Del on a cut line (Layout tool): the status line kept the old "9 blocks" text, and the ring on
    the deleted cut's end stayed until the mouse moved."""
    from app.layout_edit import handles
    from tests.app.test_modeller import _laid_out
    from tests.app.waits import wait_for

    _laid_out(qtbot, win, tmp_path, 761304)
    lay = win.doc.project.layout
    win.set_tool("layout")
    h = next(h for h in handles(lay) if h.kind == "end")
    win.canvas.tool.hover(h.xy)
    assert len(win.canvas.lake_items.drag_point.data) == 1  # the end is ringed
    win.message(f"Lake grid: {len(lay.blocks)} blocks")  # what the status said after the grid
    win.a_delete.trigger()
    assert len(win.canvas.lake_items.drag_point.data) == 0  # the ring went with the cut
    wait_for(qtbot, win, lambda: win.doc.project.layout is not lay and not win.lake_ctl.editing)
    n = len(win.doc.project.layout.blocks)
    assert n == len(lay.blocks) - 1
    assert win._status.text().startswith(f"Delete cut line: {n} blocks")


def test_a_small_window_keeps_room_to_draw(qtbot, win):
    """At 640×420 the side panels kept their width (the Lake panel ~320 px, Quality ~290 px) and the
    drawing area shrank to ~70 px; the panels give way now (their contents scroll or wrap)."""
    win.resize(640, 420)
    qtbot.waitUntil(lambda: win.width() <= 640 and win.canvas.width() >= 0.4 * win.width(), timeout=20_000)
    left, right = win.docks["lake"], win.docks["quality"]
    assert left.isVisible() and right.isVisible() and 0 < left.width() <= 0.3 * win.width()
