"""Dock panels: blocks/borders tree, convergence plot, quality (parameters: :mod:`.params_panel`).

Panels draw the document and issue commands through the
:class:`~app.commands.Editor`; they never own state.
"""

from __future__ import annotations

import math

import numpy as np
import pyqtgraph as pg
from PySide6 import QtCore, QtGui, QtWidgets

from meshcore import BORDER_NAMES

from ..document import METRICS, Document
from .canvas import BORDER_COLOURS
from .params_panel import ParamsPanel

__all__ = ["BlocksPanel", "ConvergencePanel", "ParamsPanel", "QualityPanel"]


class BlocksPanel(QtWidgets.QTreeWidget):
    """Blocks and their borders (node counts, distributions, names)."""

    border_selected = QtCore.Signal(str)

    def __init__(self, doc: Document, parent=None) -> None:
        super().__init__(parent)
        self.doc = doc
        self.setHeaderLabels(["Block / border", "nodes", "distribution"])
        self.setRootIsDecorated(True)
        self.setColumnWidth(0, 120)
        self.setColumnWidth(1, 60)
        self.itemClicked.connect(self._clicked)
        doc.project_changed.connect(lambda _p: self.refresh())
        doc.active_changed.connect(lambda _k: self.refresh())
        self.refresh()

    def refresh(self) -> None:
        """List the blocks and their borders; the same rows as shown: nothing done (a drag of a lake
        layout changes the project several times a second and keeps every block and its cells)."""
        rows = []
        for b in self.doc.project.blocks:
            status = "ready" if b.ready else "closed, needs corners" if b.closed else f"{len(b.points)} points, open"
            ni, nj = b.cell_counts or (0, 0)
            borders = []
            for name in BORDER_NAMES:
                s = b.spec(name)
                dist = s.distribution
                if s.first or s.last:
                    dist += f" ({'first ' + format(s.first, '.3g') if s.first else ''}"
                    dist += f"{' ' if s.first and s.last else ''}{'last ' + format(s.last, '.3g') if s.last else ''})"
                label = name + (f" “{s.name}”" if s.name else "")
                borders.append((name, label, str(b.node_count(name)), dist))
            rows.append((b.name, f"{ni + 1}×{nj + 1}", status, tuple(borders)))
        shown = (tuple(rows), self.doc.active)
        if shown == getattr(self, "_shown", None):
            return
        self._shown = shown
        self.blockSignals(True)
        self.clear()
        for k, (name, nodes, status, borders) in enumerate(rows):
            it = QtWidgets.QTreeWidgetItem([name, nodes, status])
            it.setData(0, QtCore.Qt.ItemDataRole.UserRole, ("block", k))
            f = it.font(0)
            f.setBold(k == self.doc.active)
            it.setFont(0, f)
            self.addTopLevelItem(it)
            for border, label, count, dist in borders:
                c = QtWidgets.QTreeWidgetItem([label, count, dist])
                c.setForeground(0, QtGui.QBrush(QtGui.QColor(BORDER_COLOURS[border])))
                c.setData(0, QtCore.Qt.ItemDataRole.UserRole, ("border", k, border))
                it.addChild(c)
            it.setExpanded(k == self.doc.active)
        active = self.topLevelItem(min(self.doc.active, self.topLevelItemCount() - 1))
        if active is not None:  # a lake's worst place in b20 of 76 made it active out of sight, at the list's top
            self.scrollToItem(active)
        self.blockSignals(False)

    def _clicked(self, item, _col) -> None:
        data = item.data(0, QtCore.Qt.ItemDataRole.UserRole)
        if not data:
            return
        self.doc.set_active(data[1])
        if data[0] == "border":
            self.border_selected.emit(data[2])


class ConvergencePanel(pg.PlotWidget):
    """log10(residual) against iteration, growing live; the levels of a lake grid marked.

    A lake grid is made coarse to fine: its change per sweep rises where a finer level
    begins.  :meth:`set_history` with ``levels`` draws a dashed line and the level's name
    at each level's first sweep, so the rise is read as what it is.
    """

    LEVEL_PEN = pg.mkPen("#7f7f7f", width=1, style=QtCore.Qt.PenStyle.DashLine)

    def __init__(self, parent=None) -> None:
        super().__init__(parent=parent, background="w")
        self.setLogMode(y=True)
        self.setLabel("left", "residual / L")
        self.setLabel("bottom", "iteration")
        self.showGrid(x=True, y=True, alpha=0.3)
        self.curve = self.plot([], [], pen=pg.mkPen("#1f77b4", width=1))
        self.tol_line = pg.InfiniteLine(angle=0, pen=pg.mkPen("#d62728", style=QtCore.Qt.PenStyle.DashLine))
        self.addItem(self.tol_line)
        self.tol_line.hide()
        self.level_lines: list[pg.InfiniteLine] = []
        self.levels: tuple[tuple[int, str], ...] = ()  # the marked levels: (first sweep, name)
        self._ranges: tuple | None = None  # the x and y ranges shown (step_ranges)
        self.setMinimumHeight(120)
        self._show_empty()
        for ax in ("left", "bottom"):
            axis = self.getAxis(ax)
            axis.enableAutoSIPrefix(False)
            # painted into a pixmap once per range: with the grid on, an axis covers the whole plot, and it
            # drew its grid lines and labels again for every new point of the curve
            axis.setCacheMode(QtWidgets.QGraphicsItem.CacheMode.DeviceCoordinateCache)

    def set_history(self, history, tolerance: float | None = None, levels=()) -> None:
        """Plot ``(iteration, residual)`` pairs; ``levels``: ``(first sweep, name)`` of each level begun.

        With levels (a lake grid) the axes say what is plotted: sweeps, and the largest move of
        a node per sweep over the cell size.
        """
        self._set_levels(tuple((int(k), str(name)) for k, name in levels))
        if not history:
            self.curve.setData([], [])
            return
        h = np.asarray(history, dtype=float)
        ok = h[:, 1] > 0
        self.curve.setData(h[ok, 0], h[ok, 1])
        if tolerance:
            self.tol_line.setValue(math.log10(tolerance))
            self.tol_line.show()
        self._fit(h[ok], tolerance)

    def _fit(self, h: np.ndarray, tolerance: float | None) -> None:
        """Show the curve and the tolerance in ranges that change in steps (:func:`step_ranges`): the axes,
        cached as pictures, are drawn again only when a step is passed, not for every new point of a
        live solve (with autorange they were, their labels and grid lines: most of a live frame's cost)."""
        ranges = step_ranges(h, tolerance)
        if ranges is not None and ranges != self._ranges:
            self._ranges = ranges
            self.setRange(xRange=ranges[0], yRange=ranges[1], padding=0.02)

    def _set_levels(self, levels: tuple[tuple[int, str], ...]) -> None:
        if levels == self.levels:
            return
        self.levels = levels
        while len(self.level_lines) < len(levels):
            line = pg.InfiniteLine(
                angle=90,
                pen=self.LEVEL_PEN,
                label="",
                labelOpts={"position": 0.92, "color": "#555", "anchors": [(0, 0), (0, 0)]},
            )
            self.addItem(line)
            self.level_lines.append(line)
        for k, line in enumerate(self.level_lines):
            if k < len(levels):
                line.label.setPosition(0.93 if k % 2 == 0 else 0.78)  # neighbours' names do not overlap
                line.setValue(levels[k][0])
                line.label.setFormat(levels[k][1])
                line.show()
            else:
                line.hide()
        lake = bool(levels)
        self.setLabel("left", "largest move / cell" if lake else "residual / L")
        self.setLabel("bottom", "sweep" if lake else "iteration")

    def clear_history(self) -> None:
        self.curve.setData([], [])
        self.tol_line.hide()
        self._set_levels(())
        self._show_empty()

    def _show_empty(self) -> None:
        """The axes of an empty plot: whole decades (pyqtgraph's default, one decade, labelled its
        minor ticks 2 … 9 in a crowd) and sweeps from 0; the next history sets the ranges."""
        self._ranges = None
        self.setRange(xRange=EMPTY_RANGES[0], yRange=EMPTY_RANGES[1], padding=0.02)


#: the ranges of an empty convergence plot: iterations 0-10, residuals 1e-6 … 1 (log10)
EMPTY_RANGES = ((0.0, 10.0), (-6.0, 0.0))
#: the steps of the iteration axis's end, times a power of ten (each at most 1.5 × the one before)
X_STEPS = (1.0, 1.5, 2.0, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0)
#: the smallest heights of the Quality panel's table and histogram: with a lake's verdict above
#: them the panel's minimum was 593 px and the window's 779-794 px, taller than a 1366×768
#: screen (its status bar and the docks' bottoms off the screen); they grow when there is room
MIN_TABLE_HEIGHT = 52
MIN_HIST_HEIGHT = 44


def step_ranges(h: np.ndarray, tolerance: float | None = None):
    """``((0, x1), (y0, y1))`` of a convergence plot of ``(iteration, residual)`` rows ``h`` (residuals > 0;
    y in decades, log10): x1 the least of :data:`X_STEPS` × 10^k at or above the last iteration, y0 and y1
    whole decades around the residuals and the tolerance.  None when ``h`` is empty."""
    fin = np.isfinite(h).all(axis=1) if len(h) else np.zeros(0, bool)
    if not fin.any():
        return None
    h = h[fin]
    top = max(float(h[:, 0].max()), 1.0)
    scale = 10.0 ** math.floor(math.log10(top))
    x1 = next(f * scale for f in X_STEPS if f * scale >= top)
    logs = np.log10(h[:, 1])
    lo, hi = float(logs.min()), float(logs.max())
    if tolerance:
        lo, hi = min(lo, math.log10(tolerance)), max(hi, math.log10(tolerance))
    y0, y1 = math.floor(lo), math.ceil(hi)
    return (0.0, x1), (float(y0), float(max(y1, y0 + 1)))


class QualityPanel(QtWidgets.QWidget):
    """Summary table, histogram, colouring choice and the list of folded cells.

    It draws the document's quality report (:attr:`Document.quality`) and sets
    the metric the canvas colours cells by (:meth:`Document.set_colour_by`).
    """

    zoom_to_cell = QtCore.Signal(int, int)

    def __init__(self, doc: Document, parent=None) -> None:
        super().__init__(parent)
        self.doc = doc
        lay = QtWidgets.QVBoxLayout(self)
        top = QtWidgets.QHBoxLayout()
        top.addWidget(QtWidgets.QLabel("Colour cells by"))
        self.metric = QtWidgets.QComboBox()
        self.metric.addItems(list(METRICS))
        self.metric.setCurrentText(doc.colour_by)
        top.addWidget(self.metric, 1)
        lay.addLayout(top)
        self.table = QtWidgets.QTableWidget(0, 2)
        self.table.setHorizontalHeaderLabels(["metric", "value"])
        self.table.horizontalHeader().setStretchLastSection(True)
        self.table.verticalHeader().hide()
        self.table.verticalHeader().setDefaultSectionSize(20)
        self.table.setMinimumHeight(MIN_TABLE_HEIGHT)
        self.table.setEditTriggers(QtWidgets.QAbstractItemView.EditTrigger.NoEditTriggers)
        lay.addWidget(self.table, 2)
        self.hist = pg.PlotWidget(background="w")
        self.hist.setMinimumHeight(MIN_HIST_HEIGHT)
        self.hist.setLabel("left", "cells")
        for ax in ("left", "bottom"):
            self.hist.getAxis(ax).enableAutoSIPrefix(False)
        self.hist_curve = pg.PlotCurveItem(
            [0.0, 1.0], [0.0], stepMode="center", fillLevel=0, brush=(31, 119, 180, 120), pen=pg.mkPen("#1f77b4")
        )
        self.hist.addItem(self.hist_curve)
        lay.addWidget(self.hist, 2)
        self.hist.hide()
        self.folded_label = QtWidgets.QLabel()
        lay.addWidget(self.folded_label)
        self.folded = QtWidgets.QListWidget()
        self.folded.setMaximumHeight(110)
        self.folded.hide()  # shown when there is a cell to list (the list's height is room the others need)
        self.folded.itemClicked.connect(self._folded_clicked)
        lay.addWidget(self.folded, 1)
        self.metric.currentTextChanged.connect(doc.set_colour_by)
        doc.quality_changed.connect(self.refresh)
        doc.colour_changed.connect(self._on_colour)
        self.refresh()

    @property
    def report(self):
        """The quality report shown (the document's)."""
        return self.doc.quality

    def refresh(self) -> None:
        """Show the document's quality report (or nothing)."""
        r, grid = self.doc.quality, self.doc.quality_grid
        self.folded.clear()
        self._show_folded()
        if r is None:
            self.table.setRowCount(0)
            self.hist_curve.setData([0, 1], [0])
            self.hist.hide()
            if self.doc.measuring:  # a large grid, measured in a worker: the report fills in when it is
                self.folded_label.setText("Measuring the grid's quality…")
            return
        self.hist.show()
        rows = [
            *([("block", self._block_name())] if self._block_name() else []),
            ("cells (ξ × η)", f"{r.cells[0]} × {r.cells[1]}"),
            ("folded cells", f"{r.n_folded}"),
            ("non-convex cells", f"{r.n_nonconvex}"),
            ("min Jacobian ratio", f"{r.min_jacobian_ratio:.4f}"),
            ("orthogonality max / mean", f"{r.max_orthogonality:.2f}° / {r.mean_orthogonality:.2f}°"),
            ("skewness max / mean", f"{r.max_skewness:.4f} / {r.mean_skewness:.4f}"),
            ("aspect ratio max / mean", f"{r.max_aspect_ratio:.3f} / {r.mean_aspect_ratio:.3f}"),
            ("size ratio max / mean", f"{r.max_size_ratio:.3f} / {r.mean_size_ratio:.3f}"),
            ("cell area min / max", f"{r.min_area:.4g} / {r.max_area:.4g}"),
            ("solver", f"{grid.info.method}, {grid.info.iterations} it, {grid.info.message or '-'}"),
        ]
        self.table.setRowCount(len(rows))
        for k, (a, b) in enumerate(rows):
            ia, ib = QtWidgets.QTableWidgetItem(a), QtWidgets.QTableWidgetItem(b)
            if a in ("folded cells", "non-convex cells") and b != "0":
                ib.setForeground(QtGui.QBrush(QtGui.QColor("#d00")))
            self.table.setItem(k, 0, ia)
            self.table.setItem(k, 1, ib)
        self.table.resizeColumnToContents(0)
        self.table.resizeRowsToContents()
        bad = {tuple(c) for c in r.nonconvex.tolist()}
        fold = {tuple(c) for c in r.folded.tolist()}
        for c in sorted(bad | fold, key=lambda c: (c not in fold, c))[:500]:
            it = QtWidgets.QListWidgetItem(f"cell ({c[0]}, {c[1]})  {'folded' if c in fold else 'non-convex'}")
            it.setForeground(QtGui.QBrush(QtGui.QColor("#d00" if c in fold else "#a60")))
            it.setData(QtCore.Qt.ItemDataRole.UserRole, c)
            self.folded.addItem(it)
        self._show_folded()
        self._histogram()

    def _block_name(self) -> str:
        """The name of the block the report is of, when the project has several (a lake's layout): its
        "folded cells: none" read as the lake's beside a verdict of 4 folded in another block."""
        p = self.doc.project
        return self.doc.block.name if len(p.blocks) > 1 and self.doc.quality is not None else ""

    def _show_folded(self) -> None:
        """The list of folded / non-convex cells, or one line saying there are none."""
        n = self.folded.count()
        self.folded.setVisible(n > 0)
        name = self._block_name()
        where = f" in {name}" if name else ""
        self.folded_label.setText(
            f"Folded / non-convex cells{where} (click to zoom):" if n else f"Folded / non-convex cells{where}: none"
        )

    def _on_colour(self, label: str) -> None:
        if self.metric.currentText() != label:
            self.metric.setCurrentText(label)
        self._histogram()

    def _histogram(self) -> None:
        """The histogram of the colouring metric (skewness when the cells are not coloured)."""
        r = self.doc.quality
        if r is None:
            return
        m = METRICS.get(self.doc.colour_by)
        key, label = (m[0], self.doc.colour_by) if m is not None else ("skewness", "skewness")
        if key in r.arrays:
            a = np.asarray(r.arrays[key], float).ravel()
        else:  # a measure of the lake metrics: every coloured block's cells
            a = np.concatenate([np.ravel(v) for _g, v in self.doc.colour_layers()] or [np.zeros(0)])
        a = a[np.isfinite(a)]
        if a.size:
            y, x = np.histogram(a, bins=40)
            self.hist_curve.setData(x, y)
            self.hist.setLabel("bottom", label)

    def _folded_clicked(self, item) -> None:
        i, j = item.data(QtCore.Qt.ItemDataRole.UserRole)
        self.zoom_to_cell.emit(int(i), int(j))
