"""What a third modeller's afternoon in the app (session 19, held-out GSHHG lakes under Xvfb) found,
each as it went wrong, on generated shapes."""

from __future__ import annotations

import pytest

from tests.app.test_modeller import _metres_lake

pytestmark = pytest.mark.gui


def test_a_lake_imported_over_a_saved_project_is_not_saved_over_its_file(qtbot, win, tmp_path, monkeypatch):
    """Open (or save) lake A's project, import lake B over it (B replaces A, one undo step), Ctrl+S:
    the title bar still named A's file and Save wrote lake B into it without a word; A's project
    was gone.  Save now asks for a file, offering B's name, and A's file is left as it was."""
    from PySide6 import QtWidgets

    assert win.io.import_points(_metres_lake(tmp_path / "Tarn.csv", 761901))
    first = tmp_path / "Tarn.toml"
    assert win.io.save_to(first)
    saved = first.read_text()
    assert win.io.import_points(_metres_lake(tmp_path / "Mere.csv", 761902))
    asked = []

    def dialog(_parent, _caption, directory, _filter):
        asked.append(directory)
        return "", ""

    monkeypatch.setattr(QtWidgets.QFileDialog, "getSaveFileName", dialog)
    assert not win.io.save()  # the dialog was cancelled
    assert first.read_text() == saved
    assert asked == [str(tmp_path / "Mere.toml")]
    assert "Tarn.toml" not in win.windowTitle()


def test_an_imported_lake_file_is_in_open_recent(qtbot, win, tmp_path):
    """File ▸ Open recent listed saved projects only: the lake file a modeller imported an hour ago
    had to be found again in the file dialog.  It is listed, and opening it imports it."""
    src = _metres_lake(tmp_path / "Tarn.csv", 761903)
    assert win.io.import_points(src)
    assert win.io.recent()[0] == str(src)
    texts = [a.text() for a in win.io.recent_menu.actions()]
    assert str(src) in texts


def test_a_file_that_cannot_be_imported_prints_no_traceback_in_the_terminal(qtbot, win, tmp_path, monkeypatch, capsys):
    """A CSV that is no point file: the dialog said why, and the terminal got the same at INFO level
    with a full traceback (the "app" logger's INFO records reached the terminal's handler).  The
    terminal gets warnings and errors only; the log file keeps the traceback."""
    import logging

    from PySide6 import QtCore

    import app.__main__ as entry

    root = logging.getLogger()
    monkeypatch.setattr(root, "handlers", [])  # as in a new process (pytest's own are put back after)
    monkeypatch.setattr(root, "level", root.level)
    monkeypatch.setattr(logging.getLogger("app"), "level", logging.getLogger("app").level)
    monkeypatch.setattr(QtCore.QStandardPaths, "writableLocation", lambda _loc: str(tmp_path / "data"))
    entry._logging()
    added = list(root.handlers)
    try:
        bad = tmp_path / "notes.csv"
        bad.write_text("hello,world\nfoo\n")
        assert not win.io.import_points(bad)
        for h in added:
            h.flush()
        err = capsys.readouterr().err
        assert "Traceback" not in err and "notes.csv" not in err
        assert "Traceback" in (tmp_path / "data" / "gcmesh.log").read_text()
        logging.getLogger("app.test").warning("a warning still shows")
        assert "a warning still shows" in capsys.readouterr().err
    finally:
        for h in added:
            h.close()
