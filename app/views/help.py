"""Help ▸ Keyboard shortcuts and Help ▸ About of the main window (views: they only show text)."""

from __future__ import annotations

from pathlib import Path

from PySide6 import QtCore, QtGui, QtWidgets

from .. import actions

__all__ = ["shortcuts_dialog", "show_about"]


def shortcuts_dialog(window: QtWidgets.QMainWindow) -> QtWidgets.QDialog:
    """The keys and gestures in two columns, in a window that scrolls and stays open beside the work
    (a message box of one column was 620-814 px tall: its OK button below a 600 px screen)."""
    rows = actions.shortcut_rows()
    half = (len(rows) + 1) // 2
    cell = "<td><b>{}</b></td><td>&nbsp;&nbsp;{}&nbsp;&nbsp;&nbsp;&nbsp;</td>"
    lines = []
    for k in range(half):
        right = rows[half + k] if half + k < len(rows) else ("", "")
        lines.append(f"<tr>{cell.format(*rows[k])}{cell.format(*right)}</tr>")
    label = QtWidgets.QLabel(f"<table>{''.join(lines)}</table>")
    label.setTextInteractionFlags(QtCore.Qt.TextInteractionFlag.TextSelectableByMouse)
    label.setWordWrap(True)  # long lines wrap in their column (no sideways scrolling)
    dlg = QtWidgets.QDialog(window)
    dlg.setWindowTitle("Keyboard shortcuts")
    area = QtWidgets.QScrollArea()
    area.setWidget(label)
    area.setWidgetResizable(True)
    ok = QtWidgets.QDialogButtonBox(QtWidgets.QDialogButtonBox.StandardButton.Ok)
    ok.accepted.connect(dlg.accept)
    lay = QtWidgets.QVBoxLayout(dlg)
    lay.addWidget(area)
    lay.addWidget(ok)
    screen = (window.screen() or QtGui.QGuiApplication.primaryScreen()).availableGeometry()
    width = min(900, int(0.9 * screen.width()))
    dlg.resize(width, min(label.heightForWidth(width - 60) + 90, int(0.85 * screen.height())))
    dlg.show()
    return dlg


def show_about(window: QtWidgets.QMainWindow) -> None:
    """What the app is for, its version, and where its log is (what a bug report wants): it said only
    the paper's method, not lakes, nor where to look when something went wrong."""
    import meshcore

    loc = QtCore.QStandardPaths.StandardLocation.AppDataLocation
    log_file = Path(QtCore.QStandardPaths.writableLocation(loc)) / "gcmesh.log"
    QtWidgets.QMessageBox.about(
        window,
        "About gcmesh",
        f"<b>gcmesh</b> {meshcore.__version__}<br>Structured boundary-fitted grids in generalized "
        "coordinates: algebraic start grid + Thompson–Thames–Mastin / Winslow elliptic smoothing."
        "<br><br>Lake grids: import an outline with its islands (File ▸ Import boundary points, Ctrl+I), "
        "Lake ▸ Auto layout (Ctrl+L), adjust the blocks with the Layout tool (Y) and cut lines (L), "
        "check the Quality panel against your model's preset, File ▸ Export mesh (Ctrl+E)."
        f"<br><br>Log (attach it to a bug report): {log_file}",
    )
