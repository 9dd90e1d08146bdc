"""The parameters dock: cells, weights, initial grid, per-border distribution, solver, control.

Edits become undo commands through the :class:`~app.commands.Editor`; the
panel shows the document and never owns state.  Invalid input is shown at
once (red field and a message under the group) and not applied.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

from PySide6 import QtCore, QtGui, QtWidgets

from meshcore import BORDER_NAMES, BorderSpec, InvalidInputError
from meshcore.elliptic import METHODS

from ..commands import Editor
from ..document import Document
from .canvas import BORDER_COLOURS

__all__ = ["ParamsPanel"]

_BAD = QtGui.QColor("#ffd6d6")


def _mark(field: QtWidgets.QWidget, bad: bool) -> None:
    """Colour a field whose value was refused (the palette, not a style sheet: same size)."""
    field.setProperty("refused", bool(bad))
    pal = field.palette()
    pal.setColor(
        QtGui.QPalette.ColorRole.Base,
        _BAD if bad else QtWidgets.QApplication.palette().color(QtGui.QPalette.ColorRole.Base),
    )
    field.setPalette(pal)


def _message_label() -> QtWidgets.QLabel:
    """A red, word-wrapped label for the problems of a group."""
    label = QtWidgets.QLabel(wordWrap=True)
    label.setStyleSheet("color: #b00;")
    # wrap to the width the panel has; never widen the panel (its fields would go off the edge)
    label.setSizePolicy(QtWidgets.QSizePolicy.Policy.Ignored, QtWidgets.QSizePolicy.Policy.Preferred)
    return label


class ParamsPanel(QtWidgets.QScrollArea):
    """Cells, weights, initial grid, per-border distribution, solver settings.

    Signals
    -------
    committed()
        An edit was committed with Enter, a pick from a list or a click (not by
        moving on to another field): the window gives the keyboard back to the canvas.
    """

    committed = QtCore.Signal()

    def __init__(self, doc: Document, editor: Editor, parent=None) -> None:
        super().__init__(parent)
        self.doc = doc
        self.editor = editor
        self._updating = False
        self.setWidgetResizable(True)
        self.setHorizontalScrollBarPolicy(QtCore.Qt.ScrollBarPolicy.ScrollBarAlwaysOff)
        w = QtWidgets.QWidget()
        self.setWidget(w)
        lay = QtWidgets.QVBoxLayout(w)
        for group in (self._block_group(), self._border_group(), self._solver_group(), self._control_group()):
            lay.addWidget(group)
        lay.addStretch(1)
        self._connect()
        doc.project_changed.connect(lambda _p: self.refresh())
        doc.active_changed.connect(lambda _k: self.refresh())
        self.refresh()

    # ---------------------------------------------------------- building
    def _block_group(self) -> QtWidgets.QGroupBox:
        g = QtWidgets.QGroupBox("Block")
        f = QtWidgets.QFormLayout(g)
        # the range lets a wrong count (0, −5) be typed so that it can be refused visibly, not
        # corrected silently; values apply on Enter, focus change or the arrows (no keyboard tracking)
        self.ni = QtWidgets.QSpinBox(minimum=-9999, maximum=4096, toolTip="cells along ξ (bottom/top)")
        self.nj = QtWidgets.QSpinBox(minimum=-9999, maximum=4096, toolTip="cells along η (left/right)")
        for box in (self.ni, self.nj):
            box.setKeyboardTracking(False)
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
        self.block_msg = _message_label()
        f.addRow(self.block_msg)
        return g

    def _border_group(self) -> QtWidgets.QGroupBox:
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
        self.border_msg = _message_label()
        f.addRow(self.border_msg)
        return g

    def _solver_group(self) -> QtWidgets.QGroupBox:
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
        self.repair.addItems(["auto", "strict", "off"])
        self.repair.setToolTip(
            "auto: repair folded / non-convex cells after the solve (fold-free barrier method); "
            "strict: an error when no fold-free grid exists; off: keep the elliptic grid"
        )
        f.addRow("Repair folds", self.repair)
        self.tol = QtWidgets.QLineEdit(placeholderText="default (scale-aware)")
        self.tol.setToolTip("relative tolerance: largest Jacobi update ≤ tol · bbox diagonal")
        f.addRow("Tolerance", self.tol)
        self.maxit = QtWidgets.QSpinBox(minimum=1, maximum=10_000_000, singleStep=1000)
        f.addRow("Max iterations", self.maxit)
        self.omega = QtWidgets.QLineEdit(placeholderText="auto")
        self.omega.setToolTip("SOR relaxation factor in (0, 2); empty = automatic")
        f.addRow("ω (SOR)", self.omega)
        self.solver_msg = _message_label()
        f.addRow(self.solver_msg)
        return g

    def _control_group(self) -> QtWidgets.QGroupBox:
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
            row.addWidget(cb, k // 2, k % 2)
            self.ctl_borders[name] = cb
        f.addRow("Orthogonal at", row)
        self.ctl_spacing = QtWidgets.QLineEdit(placeholderText="empty: angle only")
        self.ctl_spacing.setToolTip("first-cell height at the orthogonal borders (model units)")
        f.addRow("First cell", self.ctl_spacing)
        self.ctl_tm = QtWidgets.QCheckBox("Thomas–Middlecoff")
        self.ctl_tm.setToolTip("the interior follows the boundary point spacing")
        f.addRow(self.ctl_tm)
        self.ctl_msg = _message_label()
        f.addRow(self.ctl_msg)
        return g

    def _connect(self) -> None:
        self.ni.valueChanged.connect(lambda _v: self._cells())
        self.nj.valueChanged.connect(lambda _v: self._cells())
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
        for cb in self.ctl_borders.values():
            cb.toggled.connect(lambda _on: self._control_edit())
        self.ctl_spacing.editingFinished.connect(self._control_edit)
        self.ctl_tm.toggled.connect(lambda _on: self._control_edit())
        self._watch_commits()

    def _watch_commits(self) -> None:
        for box in (self.ni, self.nj, self.wx, self.wy, self.maxit):
            box.editingFinished.connect(lambda w=box: self._commit_from(w))
        for e in (self.first, self.last, self.bname, self.tol, self.omega, self.ctl_spacing):
            e.returnPressed.connect(lambda w=e: self._commit_from(w))
        for c in (self.initial, self.curve, self.border, self.dist, self.method, self.repair):
            c.activated.connect(lambda _i, w=c: self._commit_from(w))
        for cb in (*self.ctl_borders.values(), self.ctl_tm):
            cb.clicked.connect(lambda _on=False, w=cb: self._commit_from(w))

    def _commit_from(self, widget: QtWidgets.QWidget) -> None:
        # after the edit has been applied (the same event), and only if the keyboard is still
        # there: Tab to the next field is not a reason to leave the panel
        QtCore.QTimer.singleShot(0, lambda: self._committed(widget))

    def _committed(self, widget: QtWidgets.QWidget) -> None:
        if widget.hasFocus() and not widget.property("refused"):  # a refused value keeps the focus for fixing
            self.committed.emit()

    def select_border(self, name: str) -> None:
        self.border.setCurrentText(name)

    # ---------------------------------------------------------- refresh
    def refresh(self) -> None:
        self._updating = True
        try:
            b = self.doc.block
            ni, nj = b.cell_counts or (32, 16)
            self.ni.setValue(ni)
            self.nj.setValue(nj)
            self.wx.setValue(b.weights[0])
            self.wy.setValue(b.weights[1])
            self.initial.setCurrentText(b.initial)
            self.curve.setCurrentText(b.curve)
            s = b.spec(self.border.currentText())
            self.dist.setCurrentText(s.distribution)
            self.first.setText("" if s.first is None else f"{s.first:.6g}")
            self.last.setText("" if s.last is None else f"{s.last:.6g}")
            self.bname.setText(s.name or "")
            for e in (self.first, self.last, self.tol, self.omega, self.ni, self.nj):
                _mark(e, False)
            self.block_msg.setText("")
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

    def _cells(self) -> None:
        """Apply the typed cell counts, or refuse them with a message (never corrected silently)."""
        if self._updating:
            return
        for box in (self.ni, self.nj):
            _mark(box, False)
        for box, name in ((self.ni, "ξ"), (self.nj, "η")):
            if box.value() < 1:
                self._refuse(box, self.block_msg, f"cells {name} must be at least 1, got {box.value()}: not applied")
                return
        self.block_msg.setText("")
        self._block(cells=(self.ni.value(), self.nj.value()))

    def _refuse(self, field, label: QtWidgets.QLabel, text: str) -> None:
        """Show why an input is not applied: red field, the text under its group, the message panel."""
        if field is not None:
            _mark(field, True)
        label.setText(text)
        self.ensureWidgetVisible(label)  # never below the fold of the scroll area
        if field is not None:
            self.ensureWidgetVisible(field)
        self.doc.report("warning", text)

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
            _mark(e, False)
        try:
            first = self._number(self.first)
        except ValueError:
            self._refuse(self.first, self.border_msg, f"first spacing: {self.first.text()!r} is not a number")
            return
        try:
            last = self._number(self.last)
        except ValueError:
            self._refuse(self.last, self.border_msg, f"last spacing: {self.last.text()!r} is not a number")
            return
        dist = self.dist.currentText()
        if dist == "uniform":
            first = last = None
        try:
            spec = BorderSpec(distribution=dist, first=first, last=last, name=self.bname.text().strip() or None)
        except InvalidInputError as exc:
            field = self.first if first is None or "first" in str(exc) else self.last
            self._refuse(field, self.border_msg, f"{self.border.currentText()} border: {exc}")
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
        _mark(self.ctl_spacing, False)
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
        _mark(self.ctl_spacing, False)
        try:
            spacing = self._number(self.ctl_spacing)
            if spacing is not None and spacing <= 0:
                raise ValueError("the first cell height must be positive")
        except ValueError as exc:
            self._refuse(self.ctl_spacing, self.ctl_msg, f"first cell: {exc}")
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
                self._refuse(None, self.ctl_msg, f"control functions: {exc}")
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
            _mark(e, False)
            try:
                v = self._number(e)
            except ValueError:
                self._refuse(e, self.solver_msg, f"{key}: {e.text()!r} is not a number")
                return
            if v is not None and not (lo < v < hi):
                self._refuse(e, self.solver_msg, f"{key} must be in ({lo:g}, {hi:g}), got {v:g}: not applied")
                return
            kw[key] = v
        self.solver_msg.setText("")
        self._solver(**kw)
