"""The pyqtgraph canvas: fixed items updated with ``setData``; mouse → active tool.

Items (created once): background image, quality colouring (PColorMeshItem),
the grid as ONE PlotCurveItem of line segments (width-1 cosmetic pen,
``connect="pairs"``, segmented line mode, ``skipFiniteCheck=True``), the
boundary loop, four coloured border curves with direction arrows and node
counts, the points, the selection, corner labels, cut lines, folded cells,
and the tool overlay (rubber band / rubber line).
"""

from __future__ import annotations

import copy
import logging

import numpy as np
import pyqtgraph as pg
from PySide6 import QtCore, QtGui
from PySide6.QtWidgets import QGraphicsItem, QGraphicsRectItem

from meshcore import StructuredGrid

from .. import geometry as geo
from ..document import Document
from .items import Scatter, ToolViewBox, set_points, set_polylines
from .lake_items import LakeOverlay

__all__ = ["BORDER_COLOURS", "Canvas"]

log = logging.getLogger(__name__)

BORDER_COLOURS = {
    "bottom": "#1f77b4",  # blue
    "right": "#d62728",  # red
    "top": "#2ca02c",  # green
    "left": "#ff7f0e",  # orange
}
CORNER_LABELS = ("SW", "SE", "NE", "NW")
#: outward normal = this sign × the left-hand normal of the border direction
#: (bottom/right have the interior on their left, top/left on their right)
_OUTWARD = {"bottom": -1.0, "right": -1.0, "top": 1.0, "left": 1.0}
#: the point scatters' full symbol sizes (pixels), as made in Canvas._make_point_items
_MARKER_FULL = {"points": 7.0, "other": 5.0}
#: boundary points a hidden marker item is given at once; more wait until it is shown (zoomed in)
MARKERS_AT_ONCE = 2000


#: the most cells a frame draws every line of; a larger grid is drawn every few lines, and the part in view in full
#: once it has no more (at 1000 pixels across, ~400 x 400 cells: 2.5 pixels each, which the lines' fading hides)
MAX_DRAWN_CELLS = 150_000
#: the most cells the quality colouring paints (each is a polygon painted from Python, ~30 µs: a grid of
#: 1.75 million cells coloured froze the window for ~1 min); more are merged, showing the worst value of each
MAX_COLOURED_CELLS = 40_000
#: milliseconds a zoom or pan must pause before the part in view of a grid drawn in part is drawn in full
WINDOW_DELAY_MS = 150


class Canvas(pg.PlotWidget):
    """The drawing area.  ``tool`` receives mouse events in model coordinates."""

    hovered = QtCore.Signal(float, float)
    #: the cursor's point is not known any more (the view moved while the mouse was off the canvas)
    unhovered = QtCore.Signal()

    def __init__(self, doc: Document, parent=None) -> None:
        self._vb = ToolViewBox(self)
        super().__init__(parent=parent, viewBox=self._vb, background="w")
        self.doc = doc
        self.tool = None
        self.setAntialiasing(False)
        pi = self.getPlotItem()
        pi.showGrid(x=True, y=True, alpha=0.15)
        self._background_grid = True
        for ax in ("left", "bottom"):
            pi.getAxis(ax).setPen(pg.mkPen("#666"))
            pi.getAxis(ax).setTextPen(pg.mkPen("#333"))
        self.setMouseTracking(True)
        self._make_shape_items()
        self._make_border_items()
        self._make_point_items()
        self._make_overlays()
        self.lake_items = LakeOverlay(self)
        # items are pictures only: every click goes to the ViewBox and so to the tool
        for it in self.getPlotItem().items:
            it.setAcceptedMouseButtons(QtCore.Qt.MouseButton.NoButton)
        self._label_at: dict[str, tuple[float, float, float]] = {}
        #: the border labels shown, (x0, y0, x1, y1) in model units: the block labels keep clear of them
        self.border_label_boxes = np.zeros((0, 4))
        self.markers_visible = True
        # level of detail of the point markers: their typical spacing (model units), their size shown
        self._spacing: dict[str, float] = {"points": np.inf, "other": np.inf}
        self._marker_sizes: dict[str, float] = {}
        self._marker_points: dict[str, np.ndarray | None] = {}  # the points each marker item shows when shown
        self._marker_given: set[str] = set()  # the marker items that hold their points
        self._bg_transform = (1.0, 0.0, 0.0, 0.0)
        self._vb.sigRangeChanged.connect(self._place_labels)
        self._vb.sigRangeChanged.connect(self._apply_level_of_detail)
        self._vb.sigRangeChanged.connect(
            lambda *_a: self._window_timer.start() if self._partial() or self._colour is not None else None
        )
        self.scene().sigMouseMoved.connect(self._on_mouse_moved)
        self._hover_pos = None  # the scene position of the mouse over the plot (None: off the canvas)
        # a fit or zoom moves the model under a still mouse: the read-out follows (it showed the point the
        # mouse was over before the fit until the mouse moved)
        self._vb.sigRangeChanged.connect(self._rehover)
        doc.project_changed.connect(self.refresh_boundary)
        doc.project_changed.connect(self.lake_items.refresh)
        doc.opened.connect(lambda: self.lake_items.set_misses(None))
        doc.selection_changed.connect(lambda _: self.refresh_selection())
        doc.active_changed.connect(lambda _: self.refresh_boundary())
        doc.grids_changed.connect(self.refresh_grids)
        doc.quality_changed.connect(self.refresh_quality)
        doc.colour_changed.connect(lambda _label: self.refresh_quality())
        doc.opened.connect(self.clear_highlight)
        self.refresh_boundary()

    # ----------------------------------------------------------- building
    def _make_shape_items(self) -> None:
        """Background image, quality colouring, grid, loops and cut lines."""
        self.background_item = pg.ImageItem()
        self.background_item.setZValue(-100)
        self.background_item.setOpacity(0.6)
        self.background_item.hide()
        self.addItem(self.background_item)

        self.quality_item: pg.PColorMeshItem | None = None  # the active block's colouring
        self.quality_items: list[pg.PColorMeshItem] = []  # the other blocks' (a lake coloured by deviation)
        self.quality_window_items: list[pg.PColorMeshItem] = []  # the cells in view of a merged colouring, one by one
        self._colour: tuple | None = None  # (layers, step, levels, colour map) of a colouring drawn merged
        self.colorbar: pg.ColorBarItem | None = None

        # every cell edge once, drawn as line segments (faster to paint than polylines)
        self.grid_curve = pg.PlotCurveItem(
            pen=pg.mkPen("#303030", width=1, cosmetic=True), connect="pairs", skipFiniteCheck=True
        )
        self.grid_curve.setSegmentedLineMode("on")
        self.grid_curve.setZValue(0)
        # painted once per new grid into a pixmap of the view (Qt keeps it to the viewport when zoomed in):
        # a repaint for anything else over it (the ring that follows the mouse in a drag, a marker) copies
        # the pixmap instead of drawing every cell edge again (Como, 1400x880 under Xvfb: 7.8 -> 5.0 ms of
        # the GUI thread per mouse move; a new grid costs ~2 ms more)
        self.grid_curve.setCacheMode(QGraphicsItem.CacheMode.DeviceCoordinateCache)
        self._edges: tuple = ((), np.zeros(0, dtype=np.intp))  # (grid shapes, their edges' node indices)
        #: the lines drawn (``app.geometry.drawn_lines``) of the shapes and view windows in ``_edges[0]``
        self._lines: list = []
        self._shown: list = []  # the grids drawn (a zoom of a grid drawn in part draws it again)
        self._windows: tuple = ((), {})  # (grid shapes, their node boxes in view) of a grid drawn in part
        self._window_timer = QtCore.QTimer(self)  # the boxes in view, once a zoom or pan has paused
        self._window_timer.setSingleShot(True)
        self._window_timer.setInterval(WINDOW_DELAY_MS)
        self._window_timer.timeout.connect(self._update_windows)
        self.addItem(self.grid_curve)
        self._grid_colour = "#303030"
        self._cell_size = 0.0  # typical cell size of the grids (model units), for the level of detail
        self._sized_shapes: tuple = ()

        self.loop_curve = pg.PlotCurveItem(pen=pg.mkPen("#888", width=1, style=QtCore.Qt.PenStyle.DashLine))
        self.loop_curve.setZValue(5)
        self.addItem(self.loop_curve)

        self.cut_curve = pg.PlotCurveItem(
            pen=pg.mkPen("#9467bd", width=2, style=QtCore.Qt.PenStyle.DashDotLine), connect="finite"
        )
        self.cut_curve.setZValue(6)
        self.addItem(self.cut_curve)

    def _make_border_items(self) -> None:
        """The four coloured borders of the active block, their arrows and labels."""
        self.border_curves = {}
        self.border_arrows = {}
        self.border_labels = {}
        for name, col in BORDER_COLOURS.items():
            c = pg.PlotCurveItem(pen=pg.mkPen(col, width=3))
            c.setZValue(10)
            self.addItem(c)
            self.border_curves[name] = c
            a = pg.ArrowItem(headLen=14, tipAngle=35, tailLen=0, brush=col, pen=pg.mkPen(col))
            a.setZValue(11)
            a.hide()
            self.addItem(a)
            self.border_arrows[name] = a
            # on a white ground, above the block labels (25): a lake block's inner border has its label
            # over the next block's grid lines, which crossed it out, and under a block label, which hid it
            t = pg.TextItem("", color=col, anchor=(0.5, 0.5), fill=pg.mkBrush(255, 255, 255, 210))
            t.setZValue(26)
            f = QtGui.QFont()
            f.setBold(True)
            t.setFont(f)
            self.addItem(t)
            self.border_labels[name] = t

    def _make_point_items(self) -> None:
        """Points, other blocks' points, selection, corners, folded-cell markers."""
        self.points_item = Scatter(size=_MARKER_FULL["points"], pen=pg.mkPen("#222"), brush=pg.mkBrush("#ffffff"))
        self.points_item.setZValue(20)
        self.addItem(self.points_item)
        self.other_points_item = Scatter(size=_MARKER_FULL["other"], pen=pg.mkPen("#999"), brush=pg.mkBrush("#ddd"))
        self.other_points_item.setZValue(19)
        self.addItem(self.other_points_item)
        self.selected_item = Scatter(size=11, pen=pg.mkPen("#d62728", width=2), brush=None)
        self.selected_item.setZValue(21)
        self.addItem(self.selected_item)
        self.corner_item = Scatter(size=13, symbol="s", pen=pg.mkPen("#000", width=2), brush=pg.mkBrush("#ffd700"))
        self.corner_item.setZValue(22)
        self.addItem(self.corner_item)
        self.corner_labels = []
        for _name in CORNER_LABELS:
            # never hidden (a TextItem shown again only repaints after a view change): empty text instead
            t = pg.TextItem("", color="#000", anchor=(-0.2, 1.2))
            t.setZValue(23)
            self.addItem(t)
            self.corner_labels.append(t)

        self.folded_item = Scatter(size=9, symbol="x", pen=pg.mkPen("#ff0000", width=2))
        self.folded_item.setZValue(30)
        self.addItem(self.folded_item)

    def _make_overlays(self) -> None:
        """The tools' rubber line and box, and the ring around a cell picked in the quality list."""
        self.rubber_line = pg.PlotCurveItem(pen=pg.mkPen("#1f77b4", width=1, style=QtCore.Qt.PenStyle.DashLine))
        self.rubber_line.setZValue(40)
        self.addItem(self.rubber_line)
        self.rubber_box = QGraphicsRectItem()
        self.rubber_box.setPen(pg.mkPen("#1f77b4", width=1, style=QtCore.Qt.PenStyle.DashLine, cosmetic=True))
        self.rubber_box.setBrush(pg.mkBrush(31, 119, 180, 30))
        self.rubber_box.setZValue(41)
        self.rubber_box.hide()
        self.addItem(self.rubber_box)
        self.highlight_item = Scatter(size=16, symbol="o", pen=pg.mkPen("#ff00ff", width=2), brush=None)
        self.highlight_item.setZValue(42)
        self.addItem(self.highlight_item)

    # ------------------------------------------------------------ helpers
    def to_model(self, scene_pos) -> tuple[float, float]:
        p = self._vb.mapSceneToView(scene_pos)
        return (float(p.x()), float(p.y()))

    def pixel(self) -> float:
        """Size of one screen pixel in model units."""
        px = self._vb.viewPixelSize()
        return float(max(px[0], px[1])) if px[0] > 0 else 1.0

    def tolerance(self, pixels: float = 8.0) -> float:
        return pixels * self.pixel()

    def _on_mouse_moved(self, pos) -> None:
        if self._vb.sceneBoundingRect().contains(pos):
            self._hover_pos = QtCore.QPointF(pos)
            xy = self.to_model(pos)
            self.hovered.emit(*xy)
            if self.tool is not None:
                self.tool.hover(xy)

    def leaveEvent(self, ev) -> None:
        self._hover_pos = None
        super().leaveEvent(ev)

    def _rehover(self, *_args) -> None:
        """The view changed under the mouse: the read-out names the point now under it, or nothing when
        the mouse is off the canvas (a click on Fit in the toolbar)."""
        pos = self._hover_pos
        if pos is not None and self._vb.sceneBoundingRect().contains(pos):
            self.hovered.emit(*self.to_model(pos))
        else:
            self._hover_pos = None
            self.unhovered.emit()

    def zoom_to(self, bounds, margin: float = 0.16) -> None:
        if bounds is None:
            return
        x0, y0, x1, y1 = bounds
        w, h = max(x1 - x0, 1e-12), max(y1 - y0, 1e-12)
        self._vb.setRange(
            xRange=(x0 - margin * w, x1 + margin * w), yRange=(y0 - margin * h, y1 + margin * h), padding=0
        )

    def shows_any_of(self, bounds) -> bool:
        """True when the view shows some of ``bounds`` (x0, y0, x1, y1)."""
        (vx0, vx1), (vy0, vy1) = self._vb.viewRange()
        x0, y0, x1, y1 = bounds
        return x0 <= vx1 and x1 >= vx0 and y0 <= vy1 and y1 >= vy0

    def fit(self) -> None:
        """Show the outline, the grids and the background image."""
        boxes = [self.doc.project.bounds(), *(g.bounds() for g in self.doc.grids.values())]
        if self.background_item.isVisible() and self.background_item.image is not None:
            h, w = self.background_item.image.shape[:2]
            boxes.append(geo.image_bounds(w, h, self._bg_transform))
        self.zoom_to(geo.union_bounds(*boxes) or (0.0, 0.0, 1.0, 1.0))

    # ------------------------------------------------------------ drawing
    def refresh_boundary(self, *_args) -> None:
        """Draw the project's outlines: loops, the active block's borders, points, corners, cuts."""
        self._draw_loops()
        self._draw_borders()
        self._draw_points()
        set_polylines(self.cut_curve, self.doc.project.cut_lines)
        self.refresh_selection()
        self._size_markers()

    def _draw_loops(self) -> None:
        """Other blocks' points, faint, and every block's loop as a dashed line."""
        doc = self.doc
        others = [b for k, b in enumerate(doc.project.blocks) if k != doc.active]
        # boundary nodes of a multiblock case or a lake layout, not editable points
        multiblock = doc.project.multiblock is not None or doc.project.layout is not None
        op = [b.points for b in others if len(b.points)]
        if not multiblock:
            op += [np.vstack(b.boundary) for b in others if b.boundary is not None]
        self._set_markers("other", np.vstack(op) if op else None)
        self._spacing["other"] = min((geo.typical_spacing(p, along=True) for p in op), default=np.inf)
        loops = []
        # a lake layout's blocks are its shore and cuts, drawn by the lake overlay: a dashed copy of every
        # block's loop would repaint (slowly: a dashed pen) with every frame of a drag
        blocks = () if doc.project.layout is not None else doc.project.blocks
        for b in blocks:
            if b.boundary is not None:
                p = np.vstack([b.boundary[0], b.boundary[1], b.boundary[2][::-1], b.boundary[3][::-1]])
            else:
                p = b.points
            if len(p):
                loops.append(np.vstack([p, p[:1]]) if b.closed or b.boundary is not None else p)
        set_polylines(self.loop_curve, loops)

    def _draw_borders(self) -> None:
        """The active block's four borders, each with an arrow and a label at its middle."""
        block = self.doc.block
        pts = block.points
        borders = None
        if block.boundary is not None:
            borders = dict(zip(("bottom", "right", "top", "left"), block.boundary, strict=True))
        elif block.closed and block.corners is not None and len(pts) >= 4:
            try:
                borders = geo.border_polylines(pts, block.corners)
            except (IndexError, ValueError):
                borders = None
        for name in ("bottom", "right", "top", "left"):
            c, a, t = self.border_curves[name], self.border_arrows[name], self.border_labels[name]
            p = borders[name] if borders is not None else np.zeros((0, 2))
            c.setData(p[:, 0], p[:, 1])
            m = geo.arrow_at_middle(p)
            if m is None:
                a.hide()
                t.setText("")
                self._label_at.pop(name, None)
                continue
            x, y, ang = m
            a.setPos(x, y)
            a.setStyle(angle=180.0 - ang)  # ArrowItem points along −x at angle 0, y down in screen
            t.setText(f"{name} · {block.node_count(name)}")
            self._label_at[name] = (x, y, ang, geo.polyline_length(p))
        self._place_labels()

    def _draw_points(self) -> None:
        """The active block's points (or border nodes) and its corners."""
        block = self.doc.block
        pts = block.points
        if block.boundary is None:
            disp = pts
        else:
            solved_together = self.doc.project.multiblock is not None or self.doc.project.layout is not None
            disp = None if solved_together else np.vstack(block.boundary)
        self._set_markers("points", disp)
        self._spacing["points"] = geo.typical_spacing(disp, along=True) if disp is not None else np.inf
        if block.corners is not None and block.boundary is None and all(c < len(pts) for c in block.corners):
            cp = pts[list(block.corners)]
            self.corner_item.setData(cp[:, 0], cp[:, 1])
            for lab, name, p in zip(self.corner_labels, CORNER_LABELS, cp, strict=True):
                lab.setPos(float(p[0]), float(p[1]))
                lab.setText(name)
        else:
            self.corner_item.setData([], [])
            for lab in self.corner_labels:
                lab.setText("")

    def _place_labels(self, *_args) -> None:
        """Put each border label just outside the middle of its border (any orientation); a border
        shorter on screen than its label shows neither label nor arrow (they would hide the block)."""
        px = self.pixel()
        for name, (x, y, ang, length) in self._label_at.items():
            a = np.radians(ang)
            sgn = _OUTWARD[name]
            nx, ny = -np.sin(a) * sgn, np.cos(a) * sgn
            t = self.border_labels[name]
            r = t.textItem.boundingRect()  # pixels (the text ignores the view transform)
            off = (8.0 + 0.5 * r.width() * abs(nx) + 0.5 * r.height() * abs(ny)) * px
            t.setAnchor((0.5, 0.5))
            t.setPos(x + off * nx, y + off * ny)
            roomy = length / px >= max(r.width(), 3 * 14.0)  # the label's width, three arrow heads
            t.setVisible(self.markers_visible and roomy)
            self.border_arrows[name].setVisible(self.markers_visible and roomy)
        boxes = []
        for name in self._label_at:
            t = self.border_labels[name]
            if t.isVisible():
                r, p = t.textItem.boundingRect(), t.pos()
                hw, hh = 0.5 * r.width() * px, 0.5 * r.height() * px
                boxes.append((p.x() - hw, p.y() - hh, p.x() + hw, p.y() + hh))
        boxes = np.array(boxes, float).reshape(-1, 4)
        if boxes.shape != self.border_label_boxes.shape or not np.allclose(boxes, self.border_label_boxes):
            self.border_label_boxes = boxes
            self.lake_items.apply_level_of_detail(force=True)  # the block labels round the new ones

    def refresh_selection(self) -> None:
        pts = self.doc.block.points
        sel = [i for i in sorted(self.doc.selection) if i < len(pts)]
        if sel:
            self.selected_item.setData(pts[sel, 0], pts[sel, 1])
        else:
            self.selected_item.setData([], [])

    def refresh_grids(self) -> None:
        """Draw the document's grids (none: the grid of before an edit that gave the blocks new cells,
        greyed); while solving, the colouring of the old grid is hidden."""
        self.set_grids(self.doc.grids or self.doc.before_grids)
        if self.doc.solving and self.quality_item is not None:
            self.set_quality(None, None)
        self.lake_items.set_solving(self.doc.solving)

    def refresh_quality(self) -> None:
        """Colour the cells and mark the folded ones as the document says."""
        from ..document import LEVELS, LOW_IS_WORSE, METRICS

        layers = self.doc.colour_layers()
        label = self.doc.colour_by if layers else ""
        grid, values = layers[0] if layers else (None, None)
        kw = {"levels": LEVELS[label], "cmap": METRICS[label][1]} if label in LEVELS else {}
        try:
            self.set_quality(grid, values, label=label, more=layers[1:], low=label in LOW_IS_WORSE, **kw)
        except Exception:  # a drawing problem must not kill the window
            log.exception("cannot colour the cells by %s", label)
            self.doc.message.emit(f"cannot colour cells by {label} (details in the log)")
        r = self.doc.quality
        self.set_folded(self.doc.quality_grid, r.folded if r is not None else None)
        self.clear_highlight()
        self.lake_items.set_misses_style(over_colours=bool(layers))
        self.lake_items.set_solving(self.doc.solving)

    def zoom_to_cell(self, i: int, j: int) -> None:
        """Zoom to cell ``(i, j)`` of the active grid and ring it."""
        g = self.doc.grid
        if g is None or not (0 <= i < g.cells[0] and 0 <= j < g.cells[1]):
            return
        ni, nj = g.cells
        i0, i1 = max(i - 3, 0), min(i + 4, ni)
        j0, j1 = max(j - 3, 0), min(j + 4, nj)
        xs, ys = g.x[i0 : i1 + 1, j0 : j1 + 1], g.y[i0 : i1 + 1, j0 : j1 + 1]
        self.zoom_to((xs.min(), ys.min(), xs.max(), ys.max()), margin=0.1)
        cx = 0.25 * (g.x[i, j] + g.x[i + 1, j] + g.x[i + 1, j + 1] + g.x[i, j + 1])
        cy = 0.25 * (g.y[i, j] + g.y[i + 1, j] + g.y[i + 1, j + 1] + g.y[i, j + 1])
        self.highlight_item.setData([cx], [cy])

    def zoom_to_point(self, x: float, y: float, radius: float) -> None:
        """Zoom to the square of half-width ``radius`` round ``(x, y)`` and ring the point."""
        self.zoom_to((x - radius, y - radius, x + radius, y + radius), margin=0.0)
        self.highlight_item.setData([x], [y])

    def clear_highlight(self) -> None:
        self.highlight_item.setData([], [])

    def set_grids(self, grids: dict[int, StructuredGrid]) -> None:
        """Draw all block grids as one curve of line segments: every frame one gather of the grids' nodes
        by the edges' node indices (:func:`app.geometry.edge_pairs`, made again only when a shape changes).

        Grids of more than :data:`MAX_DRAWN_CELLS` cells are drawn in part (:func:`app.geometry.drawn_lines`):
        every few lines, and every line of the part in view once it has few enough cells (a grid of 1.75
        million cells took 2-4 s of the GUI thread per frame, its first one 3-10 s)."""
        self._show_background_grid(not grids)
        self._shown = list(grids.values())
        if not grids:
            self.grid_curve.setData([], [])
            self._edges = ((), np.zeros(0, dtype=np.intp))
            self._lines = []
            self._cell_size, self._sized_shapes = 0.0, ()
            return
        shapes = tuple(g.shape for g in grids.values())
        windows = self._windows[1] if self._windows[0] == shapes else {}
        key = (shapes, tuple(sorted(windows.items())))
        if key != self._edges[0]:
            self._lines = geo.drawn_lines(shapes, MAX_DRAWN_CELLS, windows)
            self._edges = (key, geo.edge_pairs([(len(i), len(j)) for _k, i, j in self._lines]))
        pairs = self._edges[1]
        gs = self._shown
        if not self._partial() and len(grids) == 1:
            x, y = np.asarray(gs[0].x, float).ravel(), np.asarray(gs[0].y, float).ravel()
        elif not self._partial():
            x = np.concatenate([np.asarray(g.x, float).ravel() for g in gs])
            y = np.concatenate([np.asarray(g.y, float).ravel() for g in gs])
        else:
            x = np.concatenate([np.asarray(gs[k].x, float)[np.ix_(i, j)].ravel() for k, i, j in self._lines])
            y = np.concatenate([np.asarray(gs[k].y, float)[np.ix_(i, j)].ravel() for k, i, j in self._lines])
        self.grid_curve.setData(x[pairs], y[pairs], connect="pairs", skipFiniteCheck=True)
        if shapes != self._sized_shapes:  # the cell size only moves with the shape (cheap enough anyway)
            self._sized_shapes = shapes
            self._cell_size = geo.typical_cell_size(grids.values())
            self._apply_level_of_detail()
            if self._partial():
                self._window_timer.start()

    def _partial(self) -> bool:
        """The grids are drawn in part (too many cells for every line)."""
        return len(self._lines) > len(self._shown) or any(
            len(i) < g.shape[0] or len(j) < g.shape[1] for (_k, i, j), g in zip(self._lines, self._shown, strict=False)
        )

    def _update_windows(self) -> None:
        """The parts of a grid drawn in part that are in view: drawn with every line their cells allow (and
        of a colouring drawn merged, coloured cell by cell)."""
        if self._colour is not None:
            self._colour_window()
        if not self._shown or not self._partial():
            return
        (x0, x1), (y0, y1) = self._vb.viewRange()
        shapes = tuple(g.shape for g in self._shown)
        coarse = self._lines[: len(self._shown)]
        windows = geo.in_view(self._shown, coarse, (x0, y0, x1, y1))
        if (shapes, windows) != self._windows:
            self._windows = (shapes, windows)
            self.set_grids(dict(enumerate(self._shown)))

    def _show_background_grid(self, on: bool) -> None:
        """The faint coordinate grid behind an outline; off under a grid (its axes would then repaint,
        and regenerate their ticks, with every redraw of the grid: the costliest part of a frame)."""
        if on != self._background_grid:
            self._background_grid = on
            self.getPlotItem().showGrid(x=on, y=on, alpha=0.15)

    def set_grid_stale(self, stale: bool) -> None:
        """Grey the grid when it no longer matches the boundary (the last solve failed)."""
        self._grid_colour = "#b0b0b0" if stale else "#303030"
        self._apply_level_of_detail()

    def _apply_level_of_detail(self, *_args) -> None:
        """Fade the grid lines when the cells are only a few pixels wide on screen; show the block
        labels as the blocks' size on screen allows."""
        self.lake_items.apply_level_of_detail()
        self._size_markers()
        alpha = geo.line_alpha(self._cell_size / self.pixel()) if self._cell_size > 0 else 1.0
        colour = QtGui.QColor(self._grid_colour)
        colour.setAlphaF(alpha)
        if self.grid_curve.opts["pen"].color() != colour:
            self.grid_curve.setPen(pg.mkPen(colour, width=1, cosmetic=True))

    def _set_markers(self, name: str, points) -> None:
        """The boundary points of marker item ``name`` ("points", "other"), handed to it when it is shown
        (:meth:`_size_markers`): a scatter item of 40 000 points took 0.5 s of the import of such an
        outline, shown zoomed out as its line only (its markers hidden where they would touch)."""
        self._marker_points[name] = points
        self._marker_given.discard(name)

    def _size_markers(self) -> None:
        """Shrink the boundary points where they crowd on screen, hide them where they would touch
        (:func:`app.geometry.marker_size`): a zoomed-out outline of thousands of points is its line."""
        px = self.pixel()
        items = {"points": self.points_item, "other": self.other_points_item}
        for name, item in items.items():
            size = geo.marker_size(self._spacing[name] / px, _MARKER_FULL[name])
            if size != self._marker_sizes.get(name):
                self._marker_sizes[name] = size
                if size > 0:
                    item.setSize(size)
            shown = self.markers_visible and size > 0
            pts = self._marker_points.get(name)
            if name not in self._marker_given:
                if pts is None or len(pts) <= MARKERS_AT_ONCE:
                    set_points(item, pts)
                    self._marker_given.add(name)
                elif shown:  # after this event-loop pass: an import zooms to the new outline right after drawing it
                    QtCore.QTimer.singleShot(0, self._give_markers)
            item.setVisible(shown)

    def _give_markers(self) -> None:
        """Hand the marker items that are shown the points they wait for (:meth:`_set_markers`)."""
        for name, item in (("points", self.points_item), ("other", self.other_points_item)):
            if name not in self._marker_given and item.isVisible():
                set_points(item, self._marker_points.get(name))
                self._marker_given.add(name)

    def set_grid_visible(self, on: bool) -> None:
        """Show or hide the grid lines (View ▸ Grid lines)."""
        self.grid_curve.setVisible(bool(on))

    def set_markers_visible(self, on: bool) -> None:
        """Show or hide the boundary points, corners, arrows and labels (View ▸ Boundary markers)."""
        on = bool(on)
        self.markers_visible = on
        items = [self.corner_item, self.selected_item]
        items += [*self.corner_labels, *self.border_arrows.values(), *self.border_labels.values()]
        for it in items:
            it.setVisible(on)
        self._size_markers()
        self._place_labels()  # the border labels and arrows: only where their border has room
        self.lake_items.set_markers_visible(on)

    def set_folded(self, grid: StructuredGrid | None, cells: np.ndarray | None) -> None:
        if grid is None or cells is None or len(cells) == 0:
            self.folded_item.setData([], [])
            return
        i, j = cells[:, 0], cells[:, 1]
        cx = 0.25 * (grid.x[i, j] + grid.x[i + 1, j] + grid.x[i + 1, j + 1] + grid.x[i, j + 1])
        cy = 0.25 * (grid.y[i, j] + grid.y[i + 1, j] + grid.y[i + 1, j + 1] + grid.y[i, j + 1])
        self.folded_item.setData(cx, cy)

    def set_quality(
        self,
        grid: StructuredGrid | None,
        values: np.ndarray | None,
        *,
        levels=None,
        cmap: str = "viridis",
        label: str = "",
        more=(),
        low: bool = False,
    ) -> None:
        """Colour the cells of ``grid`` by ``values`` (shape (ni, nj)); None hides it.

        ``more``: further ``(grid, values)`` pairs coloured on the same scale (the other blocks); ``low``: the
        smallest values are the worst (cells merged for colouring show their smallest, else their largest).
        """
        for old in ([self.quality_item] if self.quality_item is not None else []) + self.quality_items:
            self.removeItem(old)
        self.quality_item, self.quality_items = None, []
        self._colour = None
        self._colour_window()
        if grid is None or values is None:
            if self.colorbar is not None:
                self.colorbar.hide()
            return
        v = np.where(np.isfinite(values), values, np.nan)
        if levels is None:
            finite = np.concatenate([v[np.isfinite(v)]] + [np.ravel(w)[np.isfinite(np.ravel(w))] for _g, w in more])
            levels = (float(finite.min()), float(finite.max())) if finite.size else (0.0, 1.0)
            if levels[0] == levels[1]:
                levels = (levels[0] - 0.5, levels[1] + 0.5)
        cm = pg.colormap.get(cmap.removesuffix("_r"))
        if cmap.endswith("_r"):  # a copy: pyqtgraph hands out one cached map, and reverse() turns it in place
            cm = copy.deepcopy(cm)  # (every other colouring had its colours upside down: after an undo, a redo)
            cm.reverse()

        cells = sum(np.size(w) for w in (v, *(w for _g, w in more)))
        step = int(np.ceil(np.sqrt(cells / MAX_COLOURED_CELLS))) if cells > MAX_COLOURED_CELLS else 1

        def mesh(g, w):
            x, y = g.x, g.y
            if step > 1:  # pyqtgraph paints each cell as a polygon from Python: merged cells, the worst value
                x, y, w = geo.coarse_cells(x, y, w, step, low=low)
            return self._mesh(x, y, w, levels, cm, -10)

        item = mesh(grid, v)
        self.quality_item = item
        self.quality_items = [mesh(g, w) for g, w in more]
        if self.colorbar is None:
            self.colorbar = pg.ColorBarItem(values=levels, colorMap=cm, interactive=False, width=15, label=label)
            self.colorbar.setImageItem(item, insert_in=self.getPlotItem())
        else:
            self.colorbar.setColorMap(cm)
            self.colorbar.setLevels(levels)
            self.colorbar.setImageItem(item)
            self.colorbar.getAxis("left").setLabel(label)  # where ColorBarItem puts the label of a vertical bar
            self.colorbar.show()
        if step > 1:  # zoomed in on few enough cells, they are coloured one by one over the merged ones
            self._colour = ([(grid, v), *more], step, levels, cm)
            self._colour_window()

    def _mesh(self, x, y, w, levels, cm, z: float):
        """A colour mesh of cells (nodes ``x``, ``y``; values ``w``) on the canvas."""
        w = np.nan_to_num(np.where(np.isfinite(w), w, np.nan), nan=levels[1])
        it = pg.PColorMeshItem(
            x, y, w, colorMap=cm, levels=levels, enableAutoLevels=False, edgecolors=None, antialiasing=False
        )
        it.setZValue(z)
        it.setAcceptedMouseButtons(QtCore.Qt.MouseButton.NoButton)
        self.addItem(it)
        return it

    def _colour_window(self) -> None:
        """The cells in view of a colouring drawn merged, each coloured by its own value when there are at
        most :data:`MAX_COLOURED_CELLS` of them (over the merged ones); none otherwise."""
        for old in self.quality_window_items:
            self.removeItem(old)
        self.quality_window_items = []
        if self._colour is None:
            return
        layers, step, levels, cm = self._colour
        (x0, x1), (y0, y1) = self._vb.viewRange()
        boxes = []
        for g, w in layers:
            ni, nj = g.shape
            box = geo.in_view([g], [(0, geo.lattice(ni, step), geo.lattice(nj, step))], (x0, y0, x1, y1))
            if box:
                boxes.append((g, w, box[0]))
        if not boxes or sum((i1 - i0) * (j1 - j0) for _g, _w, (i0, i1, j0, j1) in boxes) > MAX_COLOURED_CELLS:
            return
        for g, w, (i0, i1, j0, j1) in boxes:
            x, y = np.asarray(g.x)[i0 : i1 + 1, j0 : j1 + 1], np.asarray(g.y)[i0 : i1 + 1, j0 : j1 + 1]
            self.quality_window_items.append(self._mesh(x, y, np.asarray(w)[i0:i1, j0:j1], levels, cm, -9.5))

    def set_background(self, image: np.ndarray | None, transform=None) -> None:
        """Show an RGB(A) image (row 0 = bottom row) placed by the similarity ``transform``."""
        if image is None:
            self.background_item.hide()
            return
        a, b, tx, ty = transform or (1.0, 0.0, 0.0, 0.0)
        self._bg_transform = (a, b, tx, ty)
        self.background_item.setImage(image, axisOrder="row-major")
        tr = QtGui.QTransform(a, b, -b, a, tx, ty)  # pixel (u, v), v up → (a u − b v + tx, b u + a v + ty)
        self.background_item.setTransform(tr)
        self.background_item.show()

    def editing_items(self) -> list:
        """The items that serve editing, not the figure: boundary points, the selection, corners and their
        labels, the active block's coloured borders with their arrows and labels, block loops and cut
        lines, folded-cell crosses, the tools' rubber line and box, the ring of the last click, and the
        lake's layout marks (cut lines and ends, block corners and labels, preset misses, the drag ring)."""
        items = [self.loop_curve, self.cut_curve, *self.border_curves.values(), *self.border_arrows.values()]
        items += [*self.border_labels.values(), self.points_item, self.other_points_item, self.selected_item]
        items += [self.corner_item, *self.corner_labels, self.folded_item]
        items += [self.rubber_line, self.rubber_box, self.highlight_item]
        return items + self.lake_items.editing_items()

    def export_image(self, path: str) -> None:
        """Write the canvas to PNG (raster) or SVG (vector) by the file suffix: the grid and what colours
        it, the shore, the background image and the axes, without the editing marks (:meth:`editing_items`)."""
        import pyqtgraph.exporters as ex

        hidden = [it for it in self.editing_items() if it.isVisible()]
        for it in hidden:
            it.hide()
        try:
            if str(path).lower().endswith(".svg"):
                ex.SVGExporter(self.getPlotItem()).export(str(path))
            elif not self.grab().save(str(path)):
                raise OSError(f"{path}: cannot write the image")
        finally:
            for it in hidden:
                it.show()
