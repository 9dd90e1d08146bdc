"""What the canvas draws of a lake: shore and islands, the layout's cut lines, block corners and
per-block cell counts, and the places that miss a quality preset.

:class:`LakeOverlay` owns its pyqtgraph items (made once, updated with ``setData``); the
canvas calls :meth:`LakeOverlay.refresh` when the project changes and
:meth:`LakeOverlay.set_misses` when the quality verdict changes.  It only draws the document.
"""

from __future__ import annotations

import numpy as np
import pyqtgraph as pg
from PySide6 import QtCore, QtGui

from .items import Scatter, set_points, set_polylines

__all__ = ["LakeOverlay", "block_label_points"]

CUT_COLOUR = "#9467bd"
SHORE_COLOUR = "#1f5fa8"
MISS_COLOUR = "#ff7f0e"
#: more places that miss a preset than this: drawn smaller and fainter
MANY_MISSES = 1000


def block_label_points(layout) -> np.ndarray:
    """A point inside each layout block (where its cell count is written)."""
    from shapely.geometry import Polygon

    out = []
    for pc in layout.pieces:
        p = Polygon(np.asarray(pc.ring, float)).representative_point()
        out.append((p.x, p.y))
    return np.asarray(out, float).reshape(-1, 2)


class LakeOverlay:
    """The lake's items on a canvas (a :class:`pyqtgraph.PlotWidget`)."""

    def __init__(self, canvas) -> None:
        self.canvas = canvas
        # width 1: a wider pen is several times slower to paint, and the shore repaints with every grid
        self.shore = pg.PlotCurveItem(pen=pg.mkPen(SHORE_COLOUR, width=1), connect="finite")
        self.shore.setZValue(4)
        self.cuts = pg.PlotCurveItem(pen=pg.mkPen(CUT_COLOUR, width=2.5), connect="finite")
        self.cuts.setZValue(7)
        self.cut_ends = Scatter(size=9, symbol="o", pen=pg.mkPen(CUT_COLOUR, width=1.5), brush=pg.mkBrush("#fff"))
        self.cut_ends.setZValue(24)
        self.corners = Scatter(size=8, symbol="s", pen=pg.mkPen("#000", width=1), brush=pg.mkBrush("#ffd700"))
        self.corners.setZValue(23)
        self.misses = Scatter(size=5, symbol="o", pen=None, brush=pg.mkBrush(255, 127, 14, 170))
        self.misses_on = True  # View ▸ Preset misses (off by itself while a metric colours the cells)
        self.misses_over_colours = False  # cells coloured: the misses are drawn as thin rings
        self.misses.setZValue(31)
        self.drag_point = Scatter(size=13, symbol="o", pen=pg.mkPen("#d62728", width=2), brush=None)
        self.drag_point.setZValue(43)
        for it in (self.shore, self.cuts, self.cut_ends, self.corners, self.misses, self.drag_point):
            canvas.addItem(it)
            it.setAcceptedMouseButtons(QtCore.Qt.MouseButton.NoButton)
        self.labels: list[pg.TextItem] = []
        self.markers_visible = True
        self.labels_on = True  # False during a drag
        self.shown_labels: list[str] = []  # the texts on screen (tests read them)

    # ------------------------------------------------------------ drawing
    def refresh(self, project) -> None:
        """Draw the project's lake (nothing when it has none)."""
        lake = project.lake
        if lake is None:
            set_polylines(self.shore, [])
            self._draw_layout(None)
            return
        rings = [lake.outline, *lake.holes]
        set_polylines(self.shore, [np.vstack([r, r[:1]]) for r in rings if len(r)])
        self._draw_layout(lake.layout)

    def _draw_layout(self, layout) -> None:
        if layout is None:
            set_polylines(self.cuts, [])
            set_points(self.cut_ends, None)
            set_points(self.corners, None)
            self._set_labels([], np.zeros((0, 2)))
            return
        cuts = [np.asarray(c, float) for c in layout.cuts]
        set_polylines(self.cuts, cuts)
        ends = [c[[0, -1]] for c in cuts if len(c) >= 2]
        set_points(self.cut_ends, np.vstack(ends) if ends else None)
        corners = np.array([p for b in layout.blocks for p in b.corners], float).reshape(-1, 2)
        set_points(self.corners, np.unique(corners, axis=0) if len(corners) else None)
        texts = [f"{b.name}\n{b.cells[0]}×{b.cells[1]}" for b in layout.blocks]
        self._set_labels(texts, block_label_points(layout))

    def _set_labels(self, texts: list[str], at: np.ndarray) -> None:
        font = QtGui.QFont()
        font.setPointSize(8)
        while len(self.labels) < len(texts):
            t = pg.TextItem("", color="#3a1f5c", anchor=(0.5, 0.5), fill=pg.mkBrush(255, 255, 255, 170))
            t.setFont(font)
            t.setZValue(25)
            t.setAcceptedMouseButtons(QtCore.Qt.MouseButton.NoButton)
            self.canvas.addItem(t)
            self.labels.append(t)
        for k, t in enumerate(self.labels):
            if k < len(texts):
                t.setText(texts[k])
                t.setPos(float(at[k, 0]), float(at[k, 1]))
                t.setVisible(self.markers_visible and self.labels_on)
            else:
                t.setText("")
        self.shown_labels = list(texts)

    def set_misses(self, points: np.ndarray | None) -> None:
        """Ring the places that miss the chosen quality preset (None: none).

        The same points again are not set again (a refresh selects the first failed limit and
        reports it twice; thousands of scatter points take a tenth of a second each time).
        """
        old = getattr(self, "_misses_shown", None)
        if old is not None and points is not None and old.shape == np.shape(points) and np.array_equal(old, points):
            return
        self._misses_shown = None if points is None else np.array(points, float)
        self._misses_many = points is not None and len(points) > MANY_MISSES
        self._style_misses()
        set_points(self.misses, points)

    def set_drag_point(self, xy) -> None:
        """Ring the handle being dragged where it will go (None: no drag)."""
        set_points(self.drag_point, None if xy is None else np.asarray(xy, float).reshape(1, 2))

    def set_markers_visible(self, on: bool) -> None:
        self.markers_visible = bool(on)
        for it in (self.cut_ends, self.corners):
            it.setVisible(self.markers_visible)
        for t in self.labels:
            t.setVisible(self.markers_visible and self.labels_on)

    def set_labels_visible(self, on: bool) -> None:
        """Show or hide the blocks' cell counts (hidden during a drag: they repaint with every grid)."""
        self.labels_on = bool(on)
        for t in self.labels:
            t.setVisible(self.labels_on and self.markers_visible)

    def set_solving(self, solving: bool) -> None:
        """The places that miss a preset belong to the last grid: hidden while a new one is made."""
        self._solving = bool(solving)
        self._show_misses()

    def set_misses_visible(self, on: bool) -> None:
        """Show or hide the places that miss the preset (View ▸ Preset misses)."""
        self.misses_on = bool(on)
        self._show_misses()

    def set_misses_style(self, over_colours: bool) -> None:
        """Filled orange dots on a plain grid; thin dark rings over coloured cells (the colour shows through)."""
        if bool(over_colours) != self.misses_over_colours:
            self.misses_over_colours = bool(over_colours)
            self._style_misses()

    def _style_misses(self) -> None:
        """Dots, or rings over colours; smaller and fainter when there are many (they would paint the lake orange)."""
        many = getattr(self, "_misses_many", False)
        key = (self.misses_over_colours, many)
        if key == getattr(self, "_misses_style", None):
            return
        self._misses_style = key
        if self.misses_over_colours:
            self.misses.setPen(pg.mkPen(0, 0, 0, 110 if many else 200, width=1))
            self.misses.setBrush(None)
            self.misses.setSize(4 if many else 6)
        else:
            self.misses.setPen(None)
            self.misses.setBrush(pg.mkBrush(255, 127, 14, 110 if many else 170))
            self.misses.setSize(3 if many else 5)

    def _show_misses(self) -> None:
        self.misses.setVisible(self.misses_on and not getattr(self, "_solving", False))
