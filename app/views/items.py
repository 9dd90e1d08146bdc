"""Small pyqtgraph pieces of the canvas: picture-only scatters, the tool-aware view box, setters."""

from __future__ import annotations

import numpy as np
import pyqtgraph as pg
from PySide6 import QtCore

__all__ = ["Scatter", "ToolViewBox", "set_points", "set_polylines"]


class Scatter(pg.ScatterPlotItem):
    """A scatter that is only a picture: clicks on its spots go to the ViewBox (the tool).

    Without points it has no extent and paints nothing (an empty pyqtgraph scatter is still
    painted, at the origin, every frame: a few ms each while the grid redraws).
    """

    def boundingRect(self) -> QtCore.QRectF:
        if self.data is None or len(self.data) == 0:
            return QtCore.QRectF()
        return super().boundingRect()

    def paint(self, p, *args) -> None:
        if self.data is not None and len(self.data):
            super().paint(p, *args)

    def mouseClickEvent(self, ev) -> None:
        ev.ignore()

    def hoverEvent(self, ev) -> None:
        pass


class ToolViewBox(pg.ViewBox):
    """A ViewBox that offers mouse events to the active tool before panning."""

    def __init__(self, canvas) -> None:
        super().__init__(lockAspect=True, enableMenu=False)
        self._canvas = canvas

    def mouseClickEvent(self, ev) -> None:
        tool = self._canvas.tool
        if tool is not None and ev.button() == QtCore.Qt.MouseButton.LeftButton:
            xy = self._canvas.to_model(ev.scenePos())
            handled = tool.double_click(xy, ev.modifiers()) if ev.double() else tool.click(xy, ev.modifiers())
            if handled:
                ev.accept()
                return
        right = ev.button() == QtCore.Qt.MouseButton.RightButton
        if right and tool is not None and tool.right_click(self._canvas.to_model(ev.scenePos())):
            ev.accept()
            return
        super().mouseClickEvent(ev)

    def mouseDragEvent(self, ev, axis=None) -> None:
        tool = self._canvas.tool
        if tool is not None and ev.button() == QtCore.Qt.MouseButton.LeftButton:
            xy = self._canvas.to_model(ev.scenePos())
            start = self._canvas.to_model(ev.buttonDownScenePos())
            phase = "start" if ev.isStart() else "finish" if ev.isFinish() else "move"
            if tool.drag(phase, xy, start, ev.modifiers()):
                ev.accept()
                return
        super().mouseDragEvent(ev, axis)


def set_points(item, points) -> None:
    """Show ``(n, 2)`` points in a scatter item (None or empty: none)."""
    if points is None or len(points) == 0:
        item.setData([], [])
    else:
        item.setData(points[:, 0], points[:, 1])


def set_polylines(item, lines) -> None:
    """Show polylines as one NaN-separated curve (``connect="finite"``)."""
    parts = []
    for line in lines:
        parts += [np.asarray(line, float).reshape(-1, 2), np.full((1, 2), np.nan)]
    if parts:
        a = np.vstack(parts)
        item.setData(a[:, 0], a[:, 1], connect="finite")
    else:
        item.setData([], [])
