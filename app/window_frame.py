"""The window's frame: its title, files dropped on it, closing, its size on the screen, the dock
layout of the last session, and the Help menu's windows.

:class:`WindowFrame` is a part of :class:`app.main_window.MainWindow` (a mixin: it uses the
window's ``doc``, ``stack``, ``io``, ``solver``, ``settings``, ``actions``, ``canvas`` and
``docks``); the window builds and connects everything else.
"""

from __future__ import annotations

import contextlib
from pathlib import Path

from PySide6 import QtCore, QtGui, QtWidgets

from .views.docks import fit_docks

__all__ = ["APP_NAME", "LIVE", "PRESET_KEY", "REMEMBERED_TOGGLES", "VIEW_TOGGLES", "WindowFrame"]

APP_NAME = "gcmesh"
VIEW_TOGGLES = ("grid_lines", "markers")  # checkable View actions remembered between sessions
# every checkable action remembered between sessions → its settings key
REMEMBERED_TOGGLES = {k: f"view/{k}" for k in VIEW_TOGGLES}
#: Generate ▸ Auto-generate on edit (Live) per kind of document: its settings key and its state until the
#: user switches it.  A lake's layout: on.  A cut end dragged on Como (10 272 cells, ``python -m app.bench
#: lake --live-off``, load 10-12 on 2 cores): Live on, the grid follows at 6.5-7.3 redraws/s (22.9 at load
#: 2, session 13) and is final 2.3-5.9 s after the release; off, the old grid stays greyed under "F5 makes
#: the new one" and F5 at the release makes it in 2.7-3.6 s.  Blocks: off (one block of 1.7 million cells
#: re-solved on every edit).  Remembered apart: a modeller who turns it off for lakes keeps it off for lakes.
LIVE = {"block": ("generate/auto", False), "lake": ("generate/auto_lake", True)}
PRESET_KEY = "quality/preset"  # the lake quality preset chosen last (settings key)


class WindowFrame:
    """Title, drops, close, size and dock layout, help windows of the main window."""

    def _update_title(self, *_a) -> None:
        try:
            clean = self.stack.isClean()
        except RuntimeError:  # the stack is gone while the window is being destroyed
            return
        name = self.doc.path.name if self.doc.path else (self.doc.project.title or "untitled")
        self.setWindowTitle(f"{name}{'' if clean else ' *'} — {APP_NAME}")

    def dragEnterEvent(self, ev: QtGui.QDragEnterEvent) -> None:
        if ev.mimeData().hasUrls():
            ev.acceptProposedAction()

    def dropEvent(self, ev: QtGui.QDropEvent) -> None:
        for url in ev.mimeData().urls():
            if url.isLocalFile():
                path = Path(url.toLocalFile())
                # a project replaces the work without undo (as File ▸ Open, which asks); a point file is an import
                if path.suffix.lower() != ".toml" or self.io.maybe_save():
                    self.io.open_path(path)
                break

    def closeEvent(self, ev: QtGui.QCloseEvent) -> None:
        if not self.io.maybe_save():
            ev.ignore()
            return
        self.lake_ctl.stop_count()  # (before the solver's shutdown, which waits for every worker)
        self.solver.shutdown()
        self.io.shutdown()
        self.settings.setValue("geometry", self.saveGeometry())
        self.settings.setValue("window_state", self.saveState())
        for action, key in REMEMBERED_TOGGLES.items():
            self.settings.setValue(key, self.actions[action].isChecked())
        ev.accept()

    # --------------------------------------------------------------- Live
    def _live_kind(self) -> str:
        return "lake" if self.doc.project.layout is not None else "block"

    def live_for_document(self, *_a) -> None:
        """Live (auto-generate) as the user left it for this kind of document (:data:`LIVE`): a lake's
        layout set (Auto layout, a laid-out project opened) turns it on unless the user turned it off for
        lakes; back to one block, the block's state."""
        kind = self._live_kind()
        if kind == self._live_seen:
            return
        self._live_seen = kind
        key, default = LIVE[kind]
        on = self.settings.value(key, None)
        on = default if on is None else str(on).lower() == "true"
        if on != self.a_auto.isChecked():
            self.a_auto.setChecked(on)
            self.solver.set_auto(on)

    def _live_chosen(self, on: bool) -> None:
        """The user switched Live: remembered for this kind of document."""
        self.settings.setValue(LIVE[self._live_kind()][0], bool(on))

    def resizeEvent(self, ev: QtGui.QResizeEvent) -> None:
        super().resizeEvent(ev)
        QtCore.QTimer.singleShot(0, self, lambda: fit_docks(self, self.canvas, self.docks.values()))

    def showEvent(self, ev: QtGui.QShowEvent) -> None:
        super().showEvent(ev)
        if not self._shown:  # the window frame is known now: fit it, decoration included
            self._shown = True
            if self.fit_on_show:
                QtCore.QTimer.singleShot(0, self.fit_to_screen)

    def fit_to_screen(self) -> None:
        """Keep the whole window (docks and status bar included) on its screen."""
        screen = self.screen() or QtGui.QGuiApplication.primaryScreen()
        if screen is None:
            return
        avail = screen.availableGeometry()
        frame = self.frameGeometry().size() - self.geometry().size()  # the window manager's decoration
        w = min(self.width(), avail.width() - frame.width())
        h = min(self.height(), avail.height() - frame.height())
        if (w, h) != (self.width(), self.height()):
            self.resize(w, h)
        x = min(max(self.x(), avail.left()), avail.right() - self.frameGeometry().width() + 1)
        y = min(max(self.y(), avail.top()), avail.bottom() - self.frameGeometry().height() + 1)
        if (x, y) != (self.x(), self.y()):
            self.move(max(x, avail.left()), max(y, avail.top()))

    def _restore_layout(self) -> None:
        """Window size, dock layout, View toggles, auto-generate and quality preset from the last
        session (if any)."""
        geom = self.settings.value("geometry")
        state = self.settings.value("window_state")
        with contextlib.suppress(TypeError):
            if geom is not None:
                self.restoreGeometry(geom)
            if state is not None:
                self.restoreState(state)
        for action, key in REMEMBERED_TOGGLES.items():
            on = self.settings.value(key, None)
            if on is not None and (str(on).lower() == "true") != self.actions[action].isChecked():
                self.actions[action].trigger()
        preset = self.settings.value(PRESET_KEY, None)
        box = self.lake_quality.preset
        if preset is not None and box.findText(str(preset)) >= 0:
            box.setCurrentText(str(preset))

    # --------------------------------------------------------------- help
    def show_shortcuts(self) -> QtWidgets.QDialog:
        """Help ▸ Keyboard shortcuts (:func:`app.views.help.shortcuts_dialog`)."""
        from .views.help import shortcuts_dialog

        self.shortcuts_dialog = shortcuts_dialog(self)
        return self.shortcuts_dialog

    def show_about(self) -> None:
        """Help ▸ About (:func:`app.views.help.show_about`)."""
        from .views.help import show_about

        show_about(self)
