"""Dock panels: blocks/borders tree, parameters, convergence plot, quality.

Panels read the document and issue commands through the :class:`Editor`; they
never own state.  Invalid input is shown at once (red field + tooltip) and
not applied.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np
import pyqtgraph as pg
from PySide6 import QtCore, QtGui, QtWidgets

from meshcore import BORDER_NAMES, BorderSpec, InvalidInputError, quality
from meshcore.elliptic import METHODS

from ..commands import Editor
from ..document import Document
from .canvas import BORDER_COLOURS

__all__ = ["BlocksPanel", "ConvergencePanel", "ParamsPanel", "QualityPanel"]

_BAD = "background: #ffd6d6;"


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
        self.blockSignals(True)
        self.clear()
        for k, b in enumerate(self.doc.project.blocks):
            status = "ready" if b.ready else "closed, needs corners" if b.closed else f"{len(b.points)} points, open"
            it = QtWidgets.QTreeWidgetItem([b.name, f"{b.cells[0] + 1}×{b.cells[1] + 1}", status])
            it.setData(0, QtCore.Qt.ItemDataRole.UserRole, ("block", k))
            f = it.font(0)
            f.setBold(k == self.doc.active)
            it.setFont(0, f)
            self.addTopLevelItem(it)
            for name in BORDER_NAMES:
                s = b.spec(name)
                dist = s.distribution
                if s.first or s.last:
                    dist += f" ({'first ' + format(s.first, '.3g') if s.first else ''}"
                    dist += f"{' ' if s.first and s.last else ''}{'last ' + format(s.last, '.3g') if s.last else ''})"
                label = name + (f" “{s.name}”" if s.name else "")
                c = QtWidgets.QTreeWidgetItem([label, str(b.node_count(name)), dist])
                c.setForeground(0, QtGui.QBrush(QtGui.QColor(BORDER_COLOURS[name])))
                c.setData(0, QtCore.Qt.ItemDataRole.UserRole, ("border", k, name))
                it.addChild(c)
            it.setExpanded(k == self.doc.active)
        self.blockSignals(False)

    def _clicked(self, item, _col) -> None:
        data = item.data(0, QtCore.Qt.ItemDataRole.UserRole)
        if not data:
            return
        self.doc.set_active(data[1])
        if data[0] == "border":
            self.border_selected.emit(data[2])


class ParamsPanel(QtWidgets.QScrollArea):
    """Cells, weights, initial grid, per-border distribution, solver settings."""

    def __init__(self, doc: Document, editor: Editor, parent=None) -> None:
        super().__init__(parent)
        self.doc = doc
        self.editor = editor
        self.setWidgetResizable(True)
        self.setHorizontalScrollBarPolicy(QtCore.Qt.ScrollBarPolicy.ScrollBarAlwaysOff)
        w = QtWidgets.QWidget()
        self.setWidget(w)
        lay = QtWidgets.QVBoxLayout(w)

        g = QtWidgets.QGroupBox("Block")
        f = QtWidgets.QFormLayout(g)
        self.ni = QtWidgets.QSpinBox(minimum=1, maximum=4096, toolTip="cells along ξ (bottom/top)")
        self.nj = QtWidgets.QSpinBox(minimum=1, maximum=4096, toolTip="cells along η (left/right)")
        cells = QtWidgets.QHBoxLayout()
        cells.addWidget(QtWidgets.QLabel("ξ"))
        cells.addWidget(self.ni)
        cells.addWidget(QtWidgets.QLabel("η"))
        cells.addWidget(self.nj)
        f.addRow("Cells", cells)
        self.wx = QtWidgets.QDoubleSpinBox(
            minimum=0.0,
            maximum=1.0,
            singleStep=0.05,
            decimals=3,
            toolTip="p13_x: weight of the left/right interpolation (paper eq. 34)",
        )
        self.wy = QtWidgets.QDoubleSpinBox(minimum=0.0, maximum=1.0, singleStep=0.05, decimals=3, toolTip="p13_y")
        wts = QtWidgets.QHBoxLayout()
        wts.addWidget(self.wx)
        wts.addWidget(self.wy)
        f.addRow("Weights p13 x/y", wts)
        self.initial = QtWidgets.QComboBox()
        self.initial.addItems(["weighted", "tfi"])
        self.initial.setToolTip("algebraic start grid: paper's weighted average (eq. 34) or TFI")
        f.addRow("Initial grid", self.initial)
        self.curve = QtWidgets.QComboBox()
        self.curve.addItems(["linear", "cubic", "catmull-rom"])
        self.curve.setToolTip("curve through the boundary points used to re-sample the borders")
        f.addRow("Boundary curve", self.curve)
        lay.addWidget(g)

        g = QtWidgets.QGroupBox("Border")
        f = QtWidgets.QFormLayout(g)
        self.border = QtWidgets.QComboBox()
        self.border.addItems(list(BORDER_NAMES))
        f.addRow("Border", self.border)
        self.dist = QtWidgets.QComboBox()
        self.dist.addItems(["uniform", "tanh", "vinokur"])
        self.dist.setToolTip("uniform in arc length; tanh one-sided or vinokur two-sided clustering")
        f.addRow("Distribution", self.dist)
        self.first = QtWidgets.QLineEdit(placeholderText="first spacing (model units)")
        self.last = QtWidgets.QLineEdit(placeholderText="last spacing (model units)")
        self.bname = QtWidgets.QLineEdit(placeholderText="e.g. inlet, wall, shore")
        f.addRow("First spacing", self.first)
        f.addRow("Last spacing", self.last)
        f.addRow("Name", self.bname)
        self.border_msg = QtWidgets.QLabel(wordWrap=True)
        self.border_msg.setStyleSheet("color: #b00;")
        f.addRow(self.border_msg)
        lay.addWidget(g)

        g = QtWidgets.QGroupBox("Solver")
        f = QtWidgets.QFormLayout(g)
        self.method = QtWidgets.QComboBox()
        self.method.addItems(["auto", *sorted(METHODS), "foldfree"])
        self.method.setToolTip(
            "auto = multigrid when available and the grid is large enough, else SOR; "
            "foldfree = elliptic solve, then fold-free barrier smoothing of the whole block"
        )
        f.addRow("Method", self.method)
        self.repair = QtWidgets.QComboBox()
        self.repair.addItems(["auto", "off"])
        self.repair.setToolTip("auto: repair folded / non-convex cells after the solve (fold-free barrier method)")
        f.addRow("Repair folds", self.repair)
        self.tol = QtWidgets.QLineEdit(placeholderText="default (scale-aware)")
        self.tol.setToolTip("relative tolerance: largest Jacobi update ≤ tol · bbox diagonal")
        f.addRow("Tolerance", self.tol)
        self.maxit = QtWidgets.QSpinBox(minimum=1, maximum=10_000_000, singleStep=1000)
        f.addRow("Max iterations", self.maxit)
        self.omega = QtWidgets.QLineEdit(placeholderText="auto")
        self.omega.setToolTip("SOR relaxation factor in (0, 2); empty = automatic")
        f.addRow("ω (SOR)", self.omega)
        self.solver_msg = QtWidgets.QLabel(wordWrap=True)
        self.solver_msg.setStyleSheet("color: #b00;")
        f.addRow(self.solver_msg)
        lay.addWidget(g)
        g = QtWidgets.QGroupBox("Control functions (P, Q)")
        g.setToolTip(
            "meshcore.control: boundary orthogonality with a first-cell height (Hilgenstock–White), "
            "interior following the boundary spacing (Thomas–Middlecoff)"
        )
        f = QtWidgets.QFormLayout(g)
        self.ctl_summary = QtWidgets.QLabel(wordWrap=True)
        f.addRow(self.ctl_summary)
        row = QtWidgets.QGridLayout()
        self.ctl_borders = {}
        for k, name in enumerate(BORDER_NAMES):
            cb = QtWidgets.QCheckBox(name)
            cb.setStyleSheet(f"color: {BORDER_COLOURS[name]};")
            cb.toggled.connect(lambda _on: self._control_edit())
            row.addWidget(cb, k // 2, k % 2)
            self.ctl_borders[name] = cb
        f.addRow("Orthogonal at", row)
        self.ctl_spacing = QtWidgets.QLineEdit(placeholderText="empty: angle only")
        self.ctl_spacing.setToolTip("first-cell height at the orthogonal borders (model units)")
        self.ctl_spacing.editingFinished.connect(self._control_edit)
        f.addRow("First cell", self.ctl_spacing)
        self.ctl_tm = QtWidgets.QCheckBox("Thomas–Middlecoff")
        self.ctl_tm.setToolTip("the interior follows the boundary point spacing")
        self.ctl_tm.toggled.connect(lambda _on: self._control_edit())
        f.addRow(self.ctl_tm)
        self.ctl_msg = QtWidgets.QLabel(wordWrap=True)
        self.ctl_msg.setStyleSheet("color: #b00;")
        f.addRow(self.ctl_msg)
        lay.addWidget(g)
        lay.addStretch(1)

        self._updating = False
        self.ni.valueChanged.connect(lambda v: self._block(cells=(v, self.nj.value())))
        self.nj.valueChanged.connect(lambda v: self._block(cells=(self.ni.value(), v)))
        self.wx.valueChanged.connect(lambda v: self._block(weights=(v, self.wy.value())))
        self.wy.valueChanged.connect(lambda v: self._block(weights=(self.wx.value(), v)))
        self.initial.currentTextChanged.connect(lambda s: self._block(initial=s))
        self.curve.currentTextChanged.connect(lambda s: self._block(curve=s))
        self.border.currentTextChanged.connect(lambda _s: self.refresh())
        self.dist.currentTextChanged.connect(lambda _s: self._border_edit())
        for e in (self.first, self.last, self.bname):
            e.editingFinished.connect(self._border_edit)
        self.method.currentTextChanged.connect(lambda s: self._solver(method=s))
        self.repair.currentTextChanged.connect(lambda s: self._solver(repair=s))
        self.tol.editingFinished.connect(self._solver_text)
        self.omega.editingFinished.connect(self._solver_text)
        self.maxit.valueChanged.connect(lambda v: self._solver(max_iterations=v))
        doc.project_changed.connect(lambda _p: self.refresh())
        doc.active_changed.connect(lambda _k: self.refresh())
        self.refresh()

    def select_border(self, name: str) -> None:
        self.border.setCurrentText(name)

    # ---------------------------------------------------------- refresh
    def refresh(self) -> None:
        self._updating = True
        try:
            b = self.doc.block
            self.ni.setValue(b.cells[0])
            self.nj.setValue(b.cells[1])
            self.wx.setValue(b.weights[0])
            self.wy.setValue(b.weights[1])
            self.initial.setCurrentText(b.initial)
            self.curve.setCurrentText(b.curve)
            s = b.spec(self.border.currentText())
            self.dist.setCurrentText(s.distribution)
            self.first.setText("" if s.first is None else f"{s.first:.6g}")
            self.last.setText("" if s.last is None else f"{s.last:.6g}")
            self.bname.setText(s.name or "")
            for e in (self.first, self.last, self.tol, self.omega):
                e.setStyleSheet("")
            self.border_msg.setText("")
            self.solver_msg.setText("")
            self._refresh_control(b)
            sv = self.doc.project.solver
            self.method.setCurrentText(sv.method)
            self.repair.setCurrentText(sv.repair)
            self.tol.setText("" if sv.tolerance is None else f"{sv.tolerance:.6g}")
            self.maxit.setValue(sv.max_iterations)
            self.omega.setText("" if sv.omega is None else f"{sv.omega:.6g}")
        finally:
            self._updating = False

    # ------------------------------------------------------------ edits
    def _block(self, **kw) -> None:
        if self._updating:
            return
        self.editor.set_block_options(merge_key="panel", **kw)

    @staticmethod
    def _number(edit: QtWidgets.QLineEdit):
        t = edit.text().strip()
        if not t:
            return None
        v = float(t)  # ValueError on garbage
        if not math.isfinite(v):
            raise ValueError(f"{t!r} is not a finite number")
        return v

    def _border_edit(self) -> None:
        if self._updating:
            return
        for e in (self.first, self.last):
            e.setStyleSheet("")
        try:
            first = self._number(self.first)
        except ValueError:
            self.first.setStyleSheet(_BAD)
            self.border_msg.setText(f"first spacing: {self.first.text()!r} is not a number")
            return
        try:
            last = self._number(self.last)
        except ValueError:
            self.last.setStyleSheet(_BAD)
            self.border_msg.setText(f"last spacing: {self.last.text()!r} is not a number")
            return
        dist = self.dist.currentText()
        if dist == "uniform":
            first = last = None
        try:
            spec = BorderSpec(distribution=dist, first=first, last=last, name=self.bname.text().strip() or None)
        except InvalidInputError as exc:
            self.border_msg.setText(str(exc))
            (self.first if first is None or "first" in str(exc) else self.last).setStyleSheet(_BAD)
            return
        self.border_msg.setText("")
        self.editor.set_border_spec(self.border.currentText(), spec)

    # ------------------------------------------------------------ control
    def _refresh_control(self, b) -> None:
        c = b.control
        if c is None:
            self.ctl_summary.setText("none")
        elif isinstance(c, Mapping):
            kind = c.get("kind", "hilgenstock-white")
            parts = [
                f"{n} ⟂" + (f" {v['spacing']:.3g}" if isinstance(v, Mapping) and v.get("spacing") else "")
                for n, v in dict(c.get("borders", {})).items()
            ]
            extra = sorted(k for k in c if k not in ("kind", "borders", "thomas-middlecoff", "thomas_middlecoff"))
            tm = c.get("thomas-middlecoff", c.get("thomas_middlecoff", False))
            self.ctl_summary.setText(
                f"{kind}: "
                + (", ".join(parts) or "no borders")
                + (" · Thomas–Middlecoff" if tm else "")
                + (f" · also {', '.join(extra)} (from the case file)" if extra else "")
            )
        else:
            self.ctl_summary.setText(f"{type(c).__name__} (set in code; not editable here)")
        borders = dict(c.get("borders", {})) if isinstance(c, Mapping) else {}
        for name, cb in self.ctl_borders.items():
            cb.setChecked(name in borders)
            cb.setEnabled(c is None or isinstance(c, Mapping))
        sp = [v.get("spacing") for v in borders.values() if isinstance(v, Mapping) and v.get("spacing")]
        self.ctl_spacing.setText(f"{sp[0]:.6g}" if sp else "")
        self.ctl_spacing.setStyleSheet("")
        tm = bool(c.get("thomas-middlecoff", c.get("thomas_middlecoff", False))) if isinstance(c, Mapping) else False
        self.ctl_tm.setChecked(tm)
        self.ctl_msg.setText("")

    def _control_edit(self) -> None:
        if self._updating:
            return
        from meshcore.control import control_from_mapping

        old = self.doc.block.control
        if old is not None and not isinstance(old, Mapping):
            return
        self.ctl_spacing.setStyleSheet("")
        try:
            spacing = self._number(self.ctl_spacing)
            if spacing is not None and spacing <= 0:
                raise ValueError("the first cell height must be positive")
        except ValueError as exc:
            self.ctl_spacing.setStyleSheet(_BAD)
            self.ctl_msg.setText(f"first cell: {exc}")
            return
        new = {k: v for k, v in dict(old or {}).items() if k not in ("borders", "thomas_middlecoff")}
        old_borders = dict((old or {}).get("borders", {}))
        borders = {}
        for name, cb in self.ctl_borders.items():
            if cb.isChecked():
                entry = dict(old_borders.get(name, {}))
                entry["angle"] = 90.0
                if spacing is None:
                    entry.pop("spacing", None)
                else:
                    entry["spacing"] = spacing
                borders[name] = entry
        if borders:
            new["borders"] = borders
        new["thomas-middlecoff"] = self.ctl_tm.isChecked()
        if not borders and not new["thomas-middlecoff"] and set(new) <= {"kind", "thomas-middlecoff"}:
            control = None
        else:
            control = new
            try:
                control_from_mapping(control)
            except InvalidInputError as exc:
                self.ctl_msg.setText(str(exc))
                return
        self.ctl_msg.setText("")
        if control != old:
            self.editor.set_block_options(control=control)

    def _solver(self, **kw) -> None:
        if self._updating:
            return
        self.editor.set_solver(**kw)

    def _solver_text(self) -> None:
        if self._updating:
            return
        kw = {}
        for key, e, lo, hi in (("tolerance", self.tol, 0.0, math.inf), ("omega", self.omega, 0.0, 2.0)):
            e.setStyleSheet("")
            try:
                v = self._number(e)
            except ValueError:
                e.setStyleSheet(_BAD)
                self.solver_msg.setText(f"{key}: {e.text()!r} is not a number")
                return
            if v is not None and not (lo < v < hi):
                e.setStyleSheet(_BAD)
                self.solver_msg.setText(f"{key} must be in ({lo:g}, {hi:g}), got {v:g}")
                return
            kw[key] = v
        self.solver_msg.setText("")
        self._solver(**kw)


class ConvergencePanel(pg.PlotWidget):
    """log10(residual) against iteration, growing live."""

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
        self.setMinimumHeight(120)
        for ax in ("left", "bottom"):
            self.getAxis(ax).enableAutoSIPrefix(False)

    def set_history(self, history, tolerance: float | None = None) -> None:
        if not history:
            self.curve.setData([], [])
            return
        h = np.asarray(history, dtype=float)
        ok = h[:, 1] > 0
        self.curve.setData(h[ok, 0], h[ok, 1])
        if tolerance:
            self.tol_line.setValue(math.log10(tolerance))
            self.tol_line.show()

    def clear_history(self) -> None:
        self.curve.setData([], [])
        self.tol_line.hide()


METRICS = {
    "none": None,
    "Jacobian ratio": ("jacobian_ratio", "viridis"),
    "skewness": ("skewness", "viridis"),
    "orthogonality (deg)": ("orthogonality", "viridis"),
    "aspect ratio": ("aspect_ratio", "viridis"),
    "cell area": ("area", "viridis"),
    "size ratio": ("size_ratio", "viridis"),
}


class QualityPanel(QtWidgets.QWidget):
    """Summary table, histogram, colouring choice and the list of folded cells."""

    colour_requested = QtCore.Signal(object, object, str)  # grid, values or None, label
    zoom_to_cell = QtCore.Signal(int, int)

    def __init__(self, doc: Document, parent=None) -> None:
        super().__init__(parent)
        self.doc = doc
        self.report = None
        self._grid = None
        lay = QtWidgets.QVBoxLayout(self)
        top = QtWidgets.QHBoxLayout()
        top.addWidget(QtWidgets.QLabel("Colour cells by"))
        self.metric = QtWidgets.QComboBox()
        self.metric.addItems(list(METRICS))
        top.addWidget(self.metric, 1)
        lay.addLayout(top)
        self.table = QtWidgets.QTableWidget(0, 2)
        self.table.setHorizontalHeaderLabels(["metric", "value"])
        self.table.horizontalHeader().setStretchLastSection(True)
        self.table.verticalHeader().hide()
        self.table.verticalHeader().setDefaultSectionSize(20)
        self.table.setMinimumHeight(150)
        self.table.setEditTriggers(QtWidgets.QAbstractItemView.EditTrigger.NoEditTriggers)
        lay.addWidget(self.table, 2)
        self.hist = pg.PlotWidget(background="w")
        self.hist.setMinimumHeight(110)
        self.hist.setLabel("left", "cells")
        for ax in ("left", "bottom"):
            self.hist.getAxis(ax).enableAutoSIPrefix(False)
        self.hist_curve = pg.PlotCurveItem(
            [0.0, 1.0], [0.0], stepMode="center", fillLevel=0, brush=(31, 119, 180, 120), pen=pg.mkPen("#1f77b4")
        )
        self.hist.addItem(self.hist_curve)
        lay.addWidget(self.hist, 2)
        self.hist.hide()
        lay.addWidget(QtWidgets.QLabel("Folded / non-convex cells (click to zoom):"))
        self.folded = QtWidgets.QListWidget()
        self.folded.setMaximumHeight(110)
        self.folded.itemClicked.connect(self._folded_clicked)
        lay.addWidget(self.folded, 1)
        self.metric.currentTextChanged.connect(lambda _s: self._recolour())

    def update_grid(self, grid) -> None:
        """Recompute the report for ``grid`` (the active block's final grid)."""
        self._grid = grid
        if grid is None:
            self.report = None
            self.table.setRowCount(0)
            self.hist_curve.setData([0, 1], [0])
            self.hist.hide()
            self.folded.clear()
            self.colour_requested.emit(None, None, "")
            return
        r = quality(grid)
        self.report = r
        self.hist.show()
        rows = [
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
        self.folded.clear()
        bad = {tuple(c) for c in r.nonconvex.tolist()}
        fold = {tuple(c) for c in r.folded.tolist()}
        for c in sorted(bad | fold, key=lambda c: (c not in fold, c))[:500]:
            it = QtWidgets.QListWidgetItem(f"cell ({c[0]}, {c[1]})  {'folded' if c in fold else 'non-convex'}")
            it.setForeground(QtGui.QBrush(QtGui.QColor("#d00" if c in fold else "#a60")))
            it.setData(QtCore.Qt.ItemDataRole.UserRole, c)
            self.folded.addItem(it)
        self._recolour()

    def _values(self):
        m = METRICS.get(self.metric.currentText())
        if m is None or self.report is None:
            return None, ""
        return self.report.arrays[m[0]], self.metric.currentText()

    def _recolour(self) -> None:
        v, label = self._values()
        key = v if v is not None else (self.report.arrays["skewness"] if self.report is not None else None)
        if key is not None:
            a = np.asarray(key, float).ravel()
            a = a[np.isfinite(a)]
            if a.size:
                y, x = np.histogram(a, bins=40)
                self.hist_curve.setData(x, y)
                self.hist.setLabel("bottom", label or "skewness")
        self.colour_requested.emit(self._grid if v is not None else None, v, label)

    def _folded_clicked(self, item) -> None:
        i, j = item.data(QtCore.Qt.ItemDataRole.UserRole)
        self.zoom_to_cell.emit(int(i), int(j))
