"""Side panels that give way on a small screen: scrollable dock contents, docks narrowed on resize.

At 640×420 the docks kept their contents' minimum widths (the Lake panel ~320 px, Quality ~290 px)
and the drawing area shrank to ~70 px.  Each dock's widget sits in a :class:`QScrollArea`, so a
dock can be narrower than its contents (they scroll), and :func:`fit_docks` narrows the left and
right docks to :data:`DOCK_SHARE` of the window each when the drawing area would be less than
:data:`MIN_CANVAS_SHARE` of it; when the window grows again they get back the widths they had
(session 18: a window snapped to half a 1366 px screen, then maximized, kept docks of 170 px that
cut the Lake and Quality panels).  Views only: nothing here edits the project.
"""

from __future__ import annotations

from PySide6 import QtCore, QtWidgets

__all__ = ["DOCK_SHARE", "MIN_CANVAS_SHARE", "fit_docks", "narrowable", "scrolled"]

#: the share of the window's width the drawing area keeps at least (when the docks can give way)
MIN_CANVAS_SHARE = 0.45
#: the share of the window's width a side dock is narrowed to then
DOCK_SHARE = 0.25
#: dock properties: its width when the window last had room for it, and whether fit_docks narrowed it
WIDE_WIDTH, NARROWED = "gcmesh_wide_width", "gcmesh_narrowed"
#: pixels short of its old width at which a dock counts as given back (resizeDocks rounds, splits)
BACK_SLACK = 12


def scrolled(widget: QtWidgets.QWidget) -> QtWidgets.QScrollArea:
    """``widget`` in a frameless scroll area that fills the dock (scroll bars only when it is too small)."""
    area = QtWidgets.QScrollArea()
    area.setWidget(widget)
    area.setWidgetResizable(True)
    area.setFrameShape(QtWidgets.QFrame.Shape.NoFrame)
    area.setMinimumWidth(40)
    return area


def narrowable(widget: QtWidgets.QWidget) -> QtWidgets.QWidget:
    """``widget`` with its combo boxes, group boxes and one-line labels allowed narrower than their text (for a
    panel that is not put in a scroll area: the Quality panel's plots crash PySide 6.10 in one)."""
    for combo in widget.findChildren(QtWidgets.QComboBox):
        combo.setSizeAdjustPolicy(QtWidgets.QComboBox.SizeAdjustPolicy.AdjustToMinimumContentsLengthWithIcon)
        combo.setMinimumContentsLength(6)
    for box in widget.findChildren(QtWidgets.QGroupBox):  # a title longer than the panel is cut, not kept whole
        box.setMinimumWidth(100)
    for label in widget.findChildren(QtWidgets.QLabel):
        if label.text() and not label.wordWrap():
            label.setWordWrap(True)
    return widget


def fit_docks(window: QtWidgets.QMainWindow, canvas: QtWidgets.QWidget, docks) -> bool:
    """Narrow the visible left and right docks when the drawing area is too narrow, or widen the
    docks it narrowed back towards their widths of before when there is room again; True if it did."""
    width = window.width()
    if width <= 0:
        return False
    area = window.dockWidgetArea
    sides = (QtCore.Qt.DockWidgetArea.LeftDockWidgetArea, QtCore.Qt.DockWidgetArea.RightDockWidgetArea)
    shown = [d for d in docks if d.isVisible() and not d.isFloating() and area(d) in sides]
    if canvas.width() >= MIN_CANVAS_SHARE * width:
        return _widen(window, shown, canvas.width() - MIN_CANVAS_SHARE * width)
    wide = [d for d in shown if d.width() > DOCK_SHARE * width]
    if not wide:
        return False
    for d in wide:
        if d.property(WIDE_WIDTH) is None:  # narrowed at the first fit: the width it gets back is this one
            d.setProperty(WIDE_WIDTH, d.width())
        d.setProperty(NARROWED, True)
    window.resizeDocks(wide, [int(DOCK_SHARE * width)] * len(wide), QtCore.Qt.Orientation.Horizontal)
    return True


def _widen(window: QtWidgets.QMainWindow, shown, spare: float) -> bool:
    """Give the docks narrowed up to ``spare`` pixels of the drawing area, towards their old widths;
    remember the width of every other dock (a window with room: as it is, or as set by hand)."""
    narrowed = []
    for d in shown:
        old = d.property(WIDE_WIDTH)
        if d.property(NARROWED) and old is not None and d.width() < int(old) - BACK_SLACK:
            narrowed.append((d, int(old)))
        else:
            d.setProperty(NARROWED, None)
            d.setProperty(WIDE_WIDTH, d.width())
    if not narrowed or spare < 1:
        return False
    want: dict = {}  # the docks of one side are one column: the most any of them lacks
    for d, old in narrowed:
        side = window.dockWidgetArea(d)
        want[side] = max(want.get(side, 0), old - d.width())
    f = min(1.0, spare / sum(want.values()))
    window.resizeDocks(
        [d for d, _ in narrowed],
        [d.width() + int(f * (old - d.width())) for d, old in narrowed],
        QtCore.Qt.Orientation.Horizontal,
    )
    return True
