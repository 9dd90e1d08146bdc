"""What the canvas draws of a lake: shore and islands, the layout's cut lines, block corners and
per-block cell counts, and the places that miss a quality preset.

:class:`LakeOverlay` owns its pyqtgraph items (made once, updated with ``setData``); the
canvas calls :meth:`LakeOverlay.refresh` when the project changes and
:meth:`LakeOverlay.set_misses` when the quality verdict changes.  It only draws the document.
"""

from __future__ import annotations

import numpy as np
import pyqtgraph as pg
from PySide6 import QtCore, QtGui, QtWidgets

from .items import Scatter, set_points, set_polylines
from .miss_marks import MissMarks

__all__ = ["LakeOverlay", "block_label_points", "left_out_islands"]

CUT_COLOUR = "#9467bd"
SHORE_COLOUR = "#1f5fa8"
MISS_COLOUR = "#ff7f0e"
#: the cut line Del would delete: the drag ring's red, translucent (the cut's own line shows inside it)
DEL_COLOUR = (214, 39, 40, 150)
#: a label may stick out of its block when the block's area is at least this many times the label's
#: (half of a long arm's block stays in sight, and its cell counts are read at full view)
LABEL_ROOM = 2.0
#: full symbol sizes (pixels) of the cut ends and the block corners
_FULL = {"cut_ends": 9.0, "corners": 8.0}
#: their fills, and their outlines when drawn hollow (a cell on screen smaller than the symbol: the
#: filled symbols hid the cells at an arm's end, where corners and cut ends gather)
_FILL = {"cut_ends": "#fff", "corners": "#ffd700"}
_HOLLOW_PEN = {"cut_ends": pg.mkPen(CUT_COLOUR, width=1.5), "corners": pg.mkPen("#b8860b", width=1.5)}


def _block_polygons(layout) -> list:
    """Each layout block's region as a shapely Polygon (made valid)."""
    from shapely.geometry import Polygon

    out = []
    for pc in layout.pieces:
        poly = Polygon(np.asarray(pc.ring, float))
        out.append(poly if poly.is_valid else poly.buffer(0))
    return out


def block_label_points(layout, polygons=None) -> np.ndarray:
    """A point inside each layout block where its label has the most room (the pole of inaccessibility)."""
    from shapely.ops import polylabel

    out = []
    for poly in polygons if polygons is not None else _block_polygons(layout):
        if poly.geom_type != "Polygon" or poly.is_empty:  # a piece made invalid: any point inside
            p = poly.representative_point()
        else:
            p = polylabel(poly, tolerance=0.02 * max(np.sqrt(poly.area), 1e-300))
        out.append((p.x, p.y))
    return np.asarray(out, float).reshape(-1, 2)


def left_out_islands(holes, layout) -> list[int]:
    """Indices of the islands ``layout`` left out (its water covers them: narrower than two cells)."""
    if layout is None or not len(holes):
        return []
    from shapely.geometry import Polygon
    from shapely.prepared import prep

    water = prep(layout.polygon)
    out = []
    for k, h in enumerate(holes):
        try:
            inside = len(h) >= 3 and water.contains(Polygon(h).representative_point())
        except Exception:  # a ring shapely cannot make a polygon of: drawn as shore, as before
            inside = False
        if inside:
            out.append(k)
    return out


class LakeOverlay:
    """The lake's items on a canvas (a :class:`pyqtgraph.PlotWidget`)."""

    def __init__(self, canvas) -> None:
        self.canvas = canvas
        # width 1: a wider pen is several times slower to paint, and the shore repaints with every grid
        self.shore = pg.PlotCurveItem(pen=pg.mkPen(SHORE_COLOUR, width=1), connect="finite")
        self.shore.setZValue(4)
        # drawn again only when the shore or the view changes, not with every frame of a drag (as the grid)
        self.shore.setCacheMode(QtWidgets.QGraphicsItem.CacheMode.DeviceCoordinateCache)
        # islands the layout left out (narrower than two cells): dashed, under the grid's lines, as
        # ``meshcore mesh --png`` draws them; drawn as shore they sat over the grid as if it went round them
        self.left_out = pg.PlotCurveItem(
            pen=pg.mkPen(SHORE_COLOUR, width=1, style=QtCore.Qt.PenStyle.DashLine), connect="finite"
        )
        self.left_out.setZValue(-1)
        self.cuts = pg.PlotCurveItem(pen=pg.mkPen(CUT_COLOUR, width=2.5), connect="finite")
        self.cuts.setZValue(7)
        self.cut_ends = Scatter(
            size=_FULL["cut_ends"], symbol="o", pen=pg.mkPen(CUT_COLOUR, width=1.5), brush=pg.mkBrush(_FILL["cut_ends"])
        )
        self.cut_ends.setZValue(24)
        self.corners = Scatter(
            size=_FULL["corners"], symbol="s", pen=pg.mkPen("#000", width=1), brush=pg.mkBrush(_FILL["corners"])
        )
        self.corners.setZValue(23)
        # the places that miss a preset: the worst per patch of the screen, the worst of all ringed
        self.miss_marks = MissMarks(canvas)
        self.misses = self.miss_marks.dots
        self.misses_on = True  # View ▸ Preset misses (off by itself while a metric colours the cells)
        self.misses_over_colours = False  # cells coloured: the misses are drawn as thin rings
        self.drag_point = Scatter(size=13, symbol="o", pen=pg.mkPen("#d62728", width=2), brush=None)
        self.drag_point.setZValue(43)
        # the cut line Del would delete (the Layout tool's cursor on it): a wide red band under its line
        self.del_cut = pg.PlotCurveItem(pen=pg.mkPen(DEL_COLOUR, width=8), connect="finite")
        self.del_cut.setZValue(6.5)
        self._del_shown = None  # the line marked
        self._layout_drawn = None  # the layout the cut lines drawn are of
        for it in (
            self.shore,
            self.left_out,
            self.cuts,
            self.cut_ends,
            self.corners,
            *self.miss_marks.items(),
            self.drag_point,
            self.del_cut,
        ):
            canvas.addItem(it)
            it.setAcceptedMouseButtons(QtCore.Qt.MouseButton.NoButton)
        self.labels: list[pg.TextItem] = []
        self.markers_visible = True
        self.labels_on = True  # False during a drag
        self.shown_labels: list[str] = []  # the texts on screen (tests read them)
        # level of detail of the block labels: per block its texts (name and cells, cells only),
        # their size in pixels, its region and where its label goes
        self._label_texts: list[tuple[str, ...]] = []
        self._label_px = np.zeros((0, 2, 2))
        self._label_polys: list = []
        self._label_area = np.zeros(0)
        self._label_at = np.zeros((0, 2))
        self._label_order = np.zeros(0, dtype=int)
        self._label_level = np.zeros(0, dtype=int)
        self._label_pixel = 0.0  # the pixel size the levels were chosen for
        self._marker_spacing = np.inf  # typical distance between the corners and cut ends (model units)
        self._marker_scale = 1.0  # their size now, a share of the full size
        self._cell_size = 0.0  # the layout's cell size (model units): markers wider than a cell are hollow
        self.markers_hollow = False  # drawn as outlines, the grid showing through
        self._labels_due = None  # a layout whose labels are made when they are shown again

    # ------------------------------------------------------------ drawing
    def refresh(self, project) -> None:
        """Draw the project's lake (nothing when it has none)."""
        lake = project.lake
        if lake is None:
            set_polylines(self.shore, [])
            set_polylines(self.left_out, [])
            self._draw_layout(None)
            return
        out = left_out_islands(lake.holes, lake.layout)
        rings = [lake.outline, *(h for k, h in enumerate(lake.holes) if k not in out)]
        set_polylines(self.shore, [np.vstack([r, r[:1]]) for r in rings if len(r)])
        set_polylines(self.left_out, [np.vstack([lake.holes[k], lake.holes[k][:1]]) for k in out])
        self._draw_layout(lake.layout)

    def _draw_layout(self, layout) -> None:
        self._labels_due = None
        if layout is not self._layout_drawn:  # the cut marked was of the layout before (the tool marks one of
            self.set_del_cut(None)  # this one when the mouse moves)
        self._layout_drawn = layout
        if layout is None:
            set_polylines(self.cuts, [])
            set_points(self.cut_ends, None)
            set_points(self.corners, None)
            self._marker_spacing = np.inf
            self._cell_size = 0.0
            self._set_labels([], np.zeros((0, 2)))
            return
        self._cell_size = float(layout.cell_size)
        cuts = [np.asarray(c, float) for c in layout.cuts]
        set_polylines(self.cuts, cuts)
        ends = [c[[0, -1]] for c in cuts if len(c) >= 2]
        set_points(self.cut_ends, np.vstack(ends) if ends else None)
        corners = np.array([p for b in layout.blocks for p in b.corners], float).reshape(-1, 2)
        set_points(self.corners, np.unique(corners, axis=0) if len(corners) else None)
        from ..geometry import typical_spacing

        self._marker_spacing = typical_spacing(np.vstack([corners, *ends]))
        # the labels' places and sizes (a pole of inaccessibility per block, a text measured per label:
        # 20-30 ms on Como) only when they are shown: a drag hides them and shows four layouts a second
        self._labels_due = layout
        if self.labels_on:
            self._make_labels()

    def _make_labels(self) -> None:
        """The block labels of the layout drawn last, if not made yet."""
        layout, self._labels_due = self._labels_due, None
        if layout is None:
            return
        texts = [(f"{b.name}\n{b.cells[0]}×{b.cells[1]}", f"{b.cells[0]}×{b.cells[1]}") for b in layout.blocks]
        polys = _block_polygons(layout)
        self._set_labels(texts, block_label_points(layout, polys), polys)

    def _set_labels(self, texts: list[tuple[str, ...]], at: np.ndarray, polys=()) -> None:
        """The blocks' labels: each with its texts (most detailed first), shown as the view allows."""
        import shapely

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
                t.setPos(float(at[k, 0]), float(at[k, 1]))
            else:
                t.setText("")
                t.setVisible(False)
        probe = QtWidgets.QGraphicsTextItem()  # measures a text as a TextItem shows it (its margins too)
        probe.setFont(font)
        px = np.zeros((len(texts), max((len(t) for t in texts), default=0), 2))
        for k, alts in enumerate(texts):
            for lev, text in enumerate(alts):
                probe.setPlainText(text)
                r = probe.boundingRect()
                px[k, lev] = (r.width(), r.height())
        self._label_texts = list(texts)
        self._label_px = px
        self._label_polys = list(polys)
        for p in self._label_polys:
            shapely.prepare(p)
        self._label_area = np.array([p.area for p in self._label_polys]) if self._label_polys else np.zeros(0)
        self._label_at = np.asarray(at, float).reshape(-1, 2)
        areas = np.array([p.area for p in self._label_polys]) if len(self._label_polys) == len(texts) else None
        # the biggest blocks first: they keep their labels when labels would overlap
        self._label_order = np.argsort(-areas, kind="stable") if areas is not None else np.arange(len(texts))
        self._label_level = np.full(len(texts), -2, dtype=int)  # none chosen yet
        self._label_pixel = 0.0
        self.apply_level_of_detail(force=True)

    def apply_level_of_detail(self, force: bool = False) -> None:
        """Show each block label as detailed as its block's size on screen allows (name and cells, cells
        only, or nothing), never two overlapping: a zoomed-out lake of 80 blocks is not covered in text.

        A text fits its block when it lies inside it, or when it covers at most 1 / :data:`LABEL_ROOM`
        of the block's area (a long narrow arm: the label may cross its shore, the block still shows).
        Called when the view's range changes; cheap (one vectorised containment test per text).
        """
        import shapely

        pixel = self.canvas.pixel()
        self._size_markers(pixel)
        self.miss_marks.update()
        n = len(self._label_texts)
        if n == 0 or not (self.labels_on and self.markers_visible):
            self.shown_labels = []
            return
        if not force and pixel == self._label_pixel:
            return
        self._label_pixel = pixel
        margin = 2.0  # pixels between a label and its block's border
        half = 0.5 * (self._label_px + margin * 2) * pixel
        if len(self._label_polys) == n:
            fits = np.zeros(half.shape[:2], bool)
            polys = np.array(self._label_polys, dtype=object)
            for lev in range(half.shape[1]):
                x, y = self._label_at[:, 0], self._label_at[:, 1]
                boxes = shapely.box(x - half[:, lev, 0], y - half[:, lev, 1], x + half[:, lev, 0], y + half[:, lev, 1])
                roomy = self._label_area >= LABEL_ROOM * 4 * half[:, lev, 0] * half[:, lev, 1]
                fits[:, lev] = (shapely.contains(polys, boxes) | roomy) & (self._label_px[:, lev, 0] > 0)
        else:
            fits = self._label_px[:, :, 0] > 0
        from ..geometry import label_levels

        # the active block's border labels are drawn above: a block label keeps clear of them
        taken = getattr(self.canvas, "border_label_boxes", None)
        levels = label_levels(self._label_at, half, fits, self._label_order, taken=taken)
        shown = []
        for k, (t, lev) in enumerate(zip(self.labels, levels, strict=False)):
            if lev != self._label_level[k]:
                if lev >= 0:
                    t.setText(self._label_texts[k][lev])
                t.setVisible(bool(lev >= 0))
            if lev >= 0:
                shown.append(self._label_texts[k][lev])
        self._label_level = levels
        self.shown_labels = shown

    def _size_markers(self, pixel: float) -> None:
        """Corners and cut ends shrink where they crowd on screen, and hide where they would touch
        (:func:`app.geometry.marker_size`): a zoomed-out lake of 80 blocks is not dotted over."""
        from ..geometry import marker_size

        full = max(_FULL.values())
        scale = marker_size(self._marker_spacing / pixel, full) / full
        if scale != self._marker_scale:
            self._marker_scale = scale
            for name, size in _FULL.items():
                item = getattr(self, name)
                if scale > 0:
                    item.setSize(size * scale)
        for name in _FULL:
            getattr(self, name).setVisible(self.markers_visible and scale > 0)
        # a cell on screen narrower than the symbols: outlines only, the cells under them stay in sight
        hollow = self._cell_size / pixel < full * scale if pixel > 0 else False
        if hollow != self.markers_hollow:
            self.markers_hollow = hollow
            for name in _FULL:
                item = getattr(self, name)
                item.setBrush(None if hollow else pg.mkBrush(_FILL[name]))
                if name == "corners":  # a thin black square would read as a grid cell
                    item.setPen(_HOLLOW_PEN[name] if hollow else pg.mkPen("#000", width=1))

    def set_misses(self, points: np.ndarray | None) -> None:
        """Mark the places that miss the chosen quality preset (None: none): ``(k, 2)``, or ``(k, 3)``
        with how far each is beyond its limit (:class:`~app.views.miss_marks.MissMarks` thins them).

        The same points again are not set again (a refresh selects the first failed limit and
        reports it twice; thousands of points take a tenth of a second each time).
        """
        old = getattr(self, "_misses_shown", None)
        if old is not None and points is not None and old.shape == np.shape(points) and np.array_equal(old, points):
            return
        self._misses_shown = None if points is None else np.array(points, float)
        self.miss_marks.set(points)

    def set_drag_point(self, xy) -> None:
        """Ring the handle being dragged where it will go (None: no drag)."""
        set_points(self.drag_point, None if xy is None else np.asarray(xy, float).reshape(1, 2))

    def set_del_cut(self, line) -> None:
        """Mark the cut line (a ``(k, 2)`` polyline) that Del would delete; None: none.  The same line
        again is not set again (the tool says it with every mouse move)."""
        if line is self._del_shown:
            return
        self._del_shown = line
        set_polylines(self.del_cut, [] if line is None else [line])

    def editing_items(self) -> list:
        """The layout's editing marks (cut lines and ends, block corners and labels, preset misses, the
        drag ring, the cut Del would delete): left out of an exported figure, which keeps the shore."""
        return [
            self.cuts,
            self.cut_ends,
            self.corners,
            *self.miss_marks.items(),
            self.drag_point,
            self.del_cut,
            *self.labels,
        ]

    def set_markers_visible(self, on: bool) -> None:
        self.markers_visible = bool(on)
        self._size_markers(self.canvas.pixel())
        self._show_labels()

    def set_labels_visible(self, on: bool) -> None:
        """Show or hide the blocks' cell counts (hidden during a drag: they repaint with every grid)."""
        self.labels_on = bool(on)
        self._show_labels()

    def _show_labels(self) -> None:
        if self.labels_on:
            self._make_labels()  # the layout's labels, if it came while they were hidden
        if self.labels_on and self.markers_visible:
            self._label_level = np.full(len(self._label_texts), -2, dtype=int)  # every label set again
            self.apply_level_of_detail(force=True)
        else:
            for t in self.labels:
                t.setVisible(False)
            self.shown_labels = []

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
            self.miss_marks.set_over_colours(self.misses_over_colours)

    def _show_misses(self) -> None:
        self.miss_marks.set_visible(self.misses_on and not getattr(self, "_solving", False))
