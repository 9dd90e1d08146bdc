"""The message panel and the status-bar label: problems in full, never cut off.

:class:`MessagePanel` lists what the document reports (:meth:`Document.report`):
solver errors, repairs of folded cells, corner advice, refused inputs — each
in full, word-wrapped, newest first.  :class:`ElidedLabel` shows one line in
the status bar, shortened with "…" to fit, the whole text in its tooltip.
"""

from __future__ import annotations

import collections
import time

from PySide6 import QtCore, QtGui, QtWidgets

from ..document import Document

__all__ = ["ElidedLabel", "MessagePanel"]

_COLOURS = {"info": "#333333", "warning": "#a05a00", "error": "#b00000"}
_SIGNS = {"info": "ℹ", "warning": "⚠", "error": "✖"}
_EARLIER = QtCore.Qt.ItemDataRole.UserRole + 1  # an item's flag: of an earlier grid or project
_EARLIER_COLOUR = "#9a9a9a"


class MessagePanel(QtWidgets.QWidget):
    """Every reported problem and note, in full (newest first), with a Clear button.

    Signals
    -------
    attention()
        A warning or an error arrived: the window raises the dock.
    """

    attention = QtCore.Signal()
    MAX_ITEMS = 200

    def __init__(self, doc: Document, parent=None) -> None:
        super().__init__(parent)
        lay = QtWidgets.QVBoxLayout(self)
        lay.setContentsMargins(2, 2, 2, 2)
        self.list = QtWidgets.QListWidget()
        self.list.setWordWrap(True)
        self.list.setTextElideMode(QtCore.Qt.TextElideMode.ElideNone)
        self.list.setHorizontalScrollBarPolicy(QtCore.Qt.ScrollBarPolicy.ScrollBarAlwaysOff)
        self.list.setSelectionMode(QtWidgets.QAbstractItemView.SelectionMode.ExtendedSelection)
        self.list.setMinimumHeight(60)
        lay.addWidget(self.list, 1)
        row = QtWidgets.QHBoxLayout()
        # shortened with "…" when the dock is narrow: "(1 earlier, greyed)" widened the panel past its
        # dock, the Clear button out of sight
        self.count = ElidedLabel()
        row.addWidget(self.count, 1)
        copy = QtWidgets.QPushButton("Copy")
        copy.setToolTip("copy the selected messages (all when none is selected)")
        copy.clicked.connect(self.copy)
        clear = QtWidgets.QPushButton("Clear")
        clear.clicked.connect(self.clear)
        row.addWidget(copy)
        row.addWidget(clear)
        lay.addLayout(row)
        doc.reported.connect(self.add)
        doc.superseded.connect(self.mark_earlier)
        doc.opened.connect(self.mark_earlier)
        self._levels: collections.Counter[str] = collections.Counter()  # level -> listed current messages
        self._earlier = 0  # errors and warnings listed of an earlier grid or project (greyed, not counted)
        self._update_count()

    def add(self, level: str, text: str) -> None:
        """List ``text`` (newest first; the same message again only refreshes its time, current again)."""
        if self.list.count() and self.list.item(0).data(QtCore.Qt.ItemDataRole.UserRole) == (level, text):
            self._take(0)
        it = QtWidgets.QListWidgetItem(f"{_SIGNS.get(level, '')} {time.strftime('%H:%M:%S')}  {text}")
        it.setForeground(QtGui.QBrush(QtGui.QColor(_COLOURS.get(level, "#333333"))))
        it.setToolTip(text)
        it.setData(QtCore.Qt.ItemDataRole.UserRole, (level, text))
        self.list.insertItem(0, it)
        self._levels[level] += 1
        while self.list.count() > self.MAX_ITEMS:
            self._take(self.list.count() - 1)
        self._update_count()
        if level != "info":
            self.attention.emit()

    def messages(self) -> list[tuple[str, str]]:
        """``(level, text)`` of every listed message, newest first."""
        return [self.list.item(k).data(QtCore.Qt.ItemDataRole.UserRole) for k in range(self.list.count())]

    def clear(self) -> None:
        self.list.clear()
        self._levels.clear()
        self._earlier = 0
        self._update_count()

    def mark_earlier(self) -> None:
        """The errors and warnings listed so far are of an earlier grid or project: greyed, no longer
        counted (a grid made after "Cannot generate", or with its folded cells gone, still read
        "1 error(s)").  Notes (info) stay as they are: a layout's notes hold for the new grid too."""
        for k in range(self.list.count()):
            it = self.list.item(k)
            level = it.data(QtCore.Qt.ItemDataRole.UserRole)[0]
            if level == "info" or it.data(_EARLIER):
                continue
            it.setData(_EARLIER, True)
            it.setForeground(QtGui.QBrush(QtGui.QColor(_EARLIER_COLOUR)))
            it.setToolTip(f"(of an earlier grid or project) {it.data(QtCore.Qt.ItemDataRole.UserRole)[1]}")
            self._levels[level] -= 1
            self._earlier += 1
        self._update_count()

    def _take(self, row: int) -> None:
        it = self.list.takeItem(row)
        if it.data(_EARLIER):
            self._earlier -= 1
        else:
            self._levels[it.data(QtCore.Qt.ItemDataRole.UserRole)[0]] -= 1

    def copy(self) -> None:
        items = self.list.selectedItems() or [self.list.item(k) for k in range(self.list.count())]
        QtWidgets.QApplication.clipboard().setText("\n".join(it.text() for it in items))

    def _update_count(self) -> None:
        """The counts of the listed messages, kept as they come and go (reading every item back for each
        new message took ~4 ms of the GUI thread at the end of every solve once the list was full)."""
        n_err, n_warn = self._levels["error"], self._levels["warning"]
        text = f"{n_err} error(s), {n_warn} warning(s)" if self.list.count() else "no messages"
        if self._earlier:
            text += f" ({self._earlier} earlier, greyed)"
        self.count.setText(text)
        self.count.setToolTip(
            f"{text}: errors and warnings since the last grid was made (or the project opened); those of "
            "earlier grids stay listed, greyed"
        )


class ElidedLabel(QtWidgets.QLabel):
    """A one-line label that shortens its text with "…" to fit (full text in the tooltip).

    A long message neither widens the window nor disappears past its edge.
    """

    def __init__(self, text: str = "", parent=None) -> None:
        super().__init__(parent)
        self._full = ""
        self.setSizePolicy(QtWidgets.QSizePolicy.Policy.Ignored, QtWidgets.QSizePolicy.Policy.Preferred)
        self.setMinimumWidth(40)
        self.setText(text)

    def setText(self, text: str) -> None:
        self._full = str(text)
        self.setToolTip(self._full)
        self._elide()

    def text(self) -> str:
        """The full text (not the shortened one shown)."""
        return self._full

    def resizeEvent(self, ev: QtGui.QResizeEvent) -> None:
        super().resizeEvent(ev)
        self._elide()

    def _elide(self) -> None:
        line = self._full.replace("\n", "  ")
        shown = self.fontMetrics().elidedText(line, QtCore.Qt.TextElideMode.ElideRight, max(self.width(), 40))
        super().setText(shown)
