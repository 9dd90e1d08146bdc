"""A message bar above the canvas: an offer with its buttons, clear of the drawing.

The Auto layout offer after importing a lake was a message box in the middle of the window, over
the lake it was about (its islands, the arms that make one block poor).  :class:`OfferBar` says the
same in a strip above the canvas: the canvas gives it the room, so the whole lake stays in view.
Keyboard: the first button has the focus when it is shown (Enter or Space takes it, Tab goes to the
next) and Esc is the last button ("Not now").  Its calls are those of the message box it replaces
(``text``, ``windowTitle``, ``buttons``, ``addButton``, ``close``).
"""

from __future__ import annotations

from PySide6 import QtCore, QtGui, QtWidgets

__all__ = ["OfferBar"]


class OfferBar(QtWidgets.QFrame):
    """A strip with a title, a text and buttons; a button's click closes it."""

    def __init__(self, title: str, text: str, parent=None) -> None:
        super().__init__(parent)
        self.setObjectName("offerBar")
        self.setFrameShape(QtWidgets.QFrame.Shape.StyledPanel)
        self.setStyleSheet("#offerBar { background: #fff8d8; border: 1px solid #d9c36a; }")
        self.setWindowTitle(title)
        lay = QtWidgets.QHBoxLayout(self)
        lay.setContentsMargins(8, 4, 8, 4)
        icon = QtWidgets.QLabel()
        icon.setPixmap(self.style().standardIcon(QtWidgets.QStyle.StandardPixmap.SP_MessageBoxQuestion).pixmap(20, 20))
        lay.addWidget(icon, 0, QtCore.Qt.AlignmentFlag.AlignTop)
        self._label = QtWidgets.QLabel()
        self._label.setWordWrap(True)
        self._label.setTextFormat(QtCore.Qt.TextFormat.PlainText)
        self._title = QtWidgets.QLabel(title)
        bold = self._title.font()
        bold.setBold(True)
        self._title.setFont(bold)
        words = QtWidgets.QVBoxLayout()
        words.setSpacing(0)
        words.addWidget(self._title)
        words.addWidget(self._label)
        lay.addLayout(words, 1)
        self._buttons: list[QtWidgets.QPushButton] = []
        self._row = QtWidgets.QHBoxLayout()
        lay.addLayout(self._row)
        self.setText(text)
        esc = QtGui.QShortcut(QtGui.QKeySequence(QtCore.Qt.Key.Key_Escape), self)
        esc.setContext(QtCore.Qt.ShortcutContext.WidgetWithChildrenShortcut)
        esc.activated.connect(lambda: self._buttons[-1].click() if self._buttons else self.close())

    def text(self) -> str:
        return self._label.text()

    def setText(self, text: str) -> None:
        self._label.setText(text)
        self.setAccessibleDescription(text)

    def buttons(self) -> list[QtWidgets.QPushButton]:
        return list(self._buttons)

    def addButton(self, text: str) -> QtWidgets.QPushButton:
        """A button (the first added is the default: it has the focus when the bar is shown)."""
        b = QtWidgets.QPushButton(text)
        b.setAutoDefault(True)
        b.clicked.connect(self.close)
        self._row.addWidget(b)
        self._buttons.append(b)
        return b

    def showEvent(self, event) -> None:
        super().showEvent(event)
        if self._buttons:  # the keyboard's way to it: Enter takes the offer, Esc declines
            self._buttons[0].setFocus(QtCore.Qt.FocusReason.OtherFocusReason)
