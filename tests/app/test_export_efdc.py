"""Export mesh as EFDC: its files have fixed names, so a name the user typed becomes cell.inp in its folder."""

from __future__ import annotations

import pytest

from tests.app.drawing import box_csv
from tests.app.waits import wait_for, wait_idle

pytestmark = pytest.mark.gui

FILES = ("cell.inp", "celllt.inp", "dxdy.inp", "lxly.inp", "corners.inp")


def _laid_out_box(qtbot, win, tmp_path):
    assert win.io.import_points(box_csv(tmp_path / "box.csv"))
    win.lake_ctl.set_cell_size(1000.0)
    win.a_auto_layout.trigger()
    wait_for(qtbot, win, lambda: win.doc.project.layout is not None or bool(win.lake_ctl.last_error))
    assert win.lake_ctl.last_error is None
    win.a_generate.trigger()
    wait_for(qtbot, win, lambda: win.doc.multiblock is not None and not win.doc.stale)
    wait_idle(qtbot, win)


def test_an_efdc_export_named_by_the_user_writes_the_fixed_names(qtbot, win, tmp_path, monkeypatch):
    """Before: "lake.inp" (what the dialog gives for a typed "lake") was refused by the writer, so the
    format the dialog offered could not be written from the app at all."""
    from PySide6 import QtWidgets

    _laid_out_box(qtbot, win, tmp_path)
    out = tmp_path / "run"
    out.mkdir()
    assert win.io.export_mesh(out / "lake.inp"), win._status.text()
    assert sorted(p.name for p in out.iterdir()) == sorted(FILES)
    cells = [ln for ln in (out / "dxdy.inp").read_text().splitlines() if not ln.startswith("C")]
    assert len(cells) == win.doc.lake_metrics.summary()["cells"]
    # files of those names there already: replaced only when the user says so
    win.quiet = False
    (out / "cell.inp").write_text("mine\n")
    asked = []

    def answer(*args):
        asked.append(args[2])
        return QtWidgets.QMessageBox.StandardButton.No

    monkeypatch.setattr(QtWidgets.QMessageBox, "question", answer)
    assert not win.io.export_mesh(out / "lake.inp")
    assert (out / "cell.inp").read_text() == "mine\n" and "cell.inp" in asked[0]
    monkeypatch.setattr(QtWidgets.QMessageBox, "question", lambda *a: QtWidgets.QMessageBox.StandardButton.Yes)
    assert win.io.export_mesh(out / "lake.inp")
    assert (out / "cell.inp").read_text().startswith("C cell.inp")
