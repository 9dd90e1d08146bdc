"""The Lake dock: cell size, regular layout, Auto layout, and the layout's blocks with their cells;
and the lake-grid quality box (presets with pass/fail) of the Quality dock.

Both draw the document; edits go through the lake controller (:mod:`app.lake_controller`),
whose settings are undoable commands.
"""

from __future__ import annotations

import math

import numpy as np
from PySide6 import QtCore, QtGui, QtWidgets

from meshcore.quality.presets import ok_percent

from ..document import Document

__all__ = ["LakePanel", "LakeQualityBox", "miss_points", "worst_miss"]

AUTO_TEXT = "auto (≈10 000 cells)"


class LakePanel(QtWidgets.QWidget):
    """Settings and result of the lake's block layout."""

    committed = QtCore.Signal()  # an edit was made: the keyboard goes back to the canvas

    def __init__(self, doc: Document, controller, parent=None) -> None:
        super().__init__(parent)
        self.doc = doc
        self.ctl = controller
        form = QtWidgets.QFormLayout()
        self.cell_size = QtWidgets.QDoubleSpinBox()
        self.cell_size.setRange(0.0, 1e7)
        self.cell_size.setDecimals(1)
        self.cell_size.setSingleStep(10.0)
        self.cell_size.setSuffix(" m")
        self.cell_size.setSpecialValueText(AUTO_TEXT)
        self.cell_size.setKeyboardTracking(False)
        self.cell_size.setToolTip("the size of the cells; 0 = sqrt(water area / 10 000), as meshcore mesh")
        form.addRow("Cell size", self.cell_size)
        self.regular = QtWidgets.QCheckBox("regular: no 3- or 5-block corners (Delft3D DD)")
        form.addRow(self.regular)
        self.button = QtWidgets.QPushButton("Auto layout")
        self.button.setToolTip("split the lake into four-sided blocks that follow its arms, then generate (Ctrl+L)")
        self.split = QtWidgets.QPushButton("Split by cuts")
        self.split.setToolTip(
            "blocks between cut lines drawn by hand (Cut line tool, L): cuts may end on the shore, an island or "
            "another cut, or meet at a point (Ctrl+K)"
        )
        buttons = QtWidgets.QHBoxLayout()
        buttons.addWidget(self.button, 1)
        buttons.addWidget(self.split, 1)
        form.addRow(buttons)
        self.summary = QtWidgets.QLabel()
        self.summary.setWordWrap(True)
        form.addRow(self.summary)
        lay = QtWidgets.QVBoxLayout(self)
        lay.addLayout(form)
        self.table = QtWidgets.QTableWidget(0, 2)
        self.table.setHorizontalHeaderLabels(["block", "cells ξ × η"])
        self.table.horizontalHeader().setStretchLastSection(True)
        self.table.verticalHeader().hide()
        self.table.verticalHeader().setDefaultSectionSize(20)
        self.table.setEditTriggers(QtWidgets.QAbstractItemView.EditTrigger.NoEditTriggers)
        self.table.itemClicked.connect(lambda it: self.doc.set_active(it.row()))
        lay.addWidget(self.table, 1)
        row = QtWidgets.QHBoxLayout()
        self.block_label = QtWidgets.QLabel("cells")
        row.addWidget(self.block_label)
        self.ni = QtWidgets.QSpinBox()
        self.nj = QtWidgets.QSpinBox()
        for w, tip in ((self.ni, "cells along ξ"), (self.nj, "cells along η")):
            w.setRange(1, 100_000)
            w.setToolTip(f"{tip} of the selected block; its neighbours follow")
            row.addWidget(w, 1)
        self.set_cells = QtWidgets.QPushButton("Set")
        self.set_cells.setToolTip("give the selected block these cells; the blocks that share its sides follow")
        row.addWidget(self.set_cells)
        lay.addLayout(row)
        self.set_cells.clicked.connect(self._set_cells)
        for w in (self.ni, self.nj):  # Enter in either box sets the cells, as the button does
            w.lineEdit().returnPressed.connect(self._set_cells)
        doc.active_changed.connect(lambda _k: self._show_active())
        self.cell_size.editingFinished.connect(self._cell_size_edited)
        self.regular.toggled.connect(self._regular_toggled)
        self.button.clicked.connect(lambda: self.ctl.auto_layout())
        self.split.clicked.connect(lambda: self.ctl.win.split_by_cuts())
        controller.busy_changed.connect(self._busy)
        controller.ticked.connect(self._ticked)
        controller.counted.connect(self.refresh)
        doc.project_changed.connect(lambda _p: self.refresh())
        self.refresh()

    def refresh(self) -> None:
        lake = self.ctl.lake()
        p = self.doc.project
        for w in (self.cell_size, self.regular):
            w.blockSignals(True)
        self._fit_cell_size(lake)
        self.cell_size.setValue((lake.cell_size or 0.0) if lake is not None else 0.0)
        self.regular.setChecked(bool(lake is not None and lake.regular))
        for w in (self.cell_size, self.regular):
            w.blockSignals(False)
        self.setEnabled(lake is not None)
        lay = p.layout
        self.split.setEnabled(lay is None and bool(p.cut_lines) and not self.ctl.busy)
        if lay is None:
            at = self._count_text(lake) if lake is not None and lake.cell_size is not None else ""
            at = f" (at {lake.cell_size:.4g} m: {at})" if at else ""
            self.summary.setText(
                f"No layout yet: Auto layout splits the lake into blocks{at}, or draw cut lines (L) and split by them."
                if lake is not None
                else "Import a lake outline (Ctrl+I) or draw and close a loop."
            )
            self.summary.setToolTip("")
            self.table.setRowCount(0)
            self._show_active()
            return
        n, k = len(lay.blocks), len(lay.notes)
        # what the layout changed in the water (an island left out, a shore smoothed): in full in Messages
        notes = f" — {k} note{'s' * (k != 1)} on the water (Messages)" if k else ""
        h = lake.cell_size if lake is not None else None
        if h is not None and not math.isclose(h, lay.cell_size, rel_tol=1e-6):  # set since: not applied yet
            notes += f" — Auto layout (Ctrl+L) makes them at {h:.4g} m: {self._count_text(lake)}"
        kind = " for one index space (EFDC, Delft3D single domain)" if lay.single else ""
        self.summary.setText(f"{n} block{'s' * (n != 1)}{kind}, {lay.n_cells:,} cells at {lay.cell_size:.4g} m{notes}")
        self.summary.setToolTip("\n\n".join(lay.notes))
        self.table.setRowCount(n)
        for k, b in enumerate(lay.blocks):
            self.table.setItem(k, 0, QtWidgets.QTableWidgetItem(b.name))
            self.table.setItem(k, 1, QtWidgets.QTableWidgetItem(f"{b.cells[0]} × {b.cells[1]}"))
        self._show_active()

    def _fit_cell_size(self, lake) -> None:
        """The cell size's decimals and step for the lake's extent: a lake under 1 000 units across (cells of
        about a hundredth of it and less) gets 3 significant digits of such a cell and a step of a tenth of
        its decade; larger ones one decimal and steps of 10, as before.  With one decimal always, a lake in
        plain numbers a few units across (a generated shape, a CSV in km) could not be given a cell size below
        0.1: 0.0704 typed became "auto" (0.0)."""
        outline = np.asarray(lake.outline, dtype=float) if lake is not None else np.zeros((0, 2))
        span = float(np.max(np.ptp(outline, axis=0))) if len(outline) >= 2 else 0.0
        if not (span > 0 and math.isfinite(span)):
            return
        e = math.floor(math.log10(span / 100))  # the decade of a cell a hundredth of the extent
        small = e < 1
        self.cell_size.setDecimals(min(8, 3 - e) if small else 1)
        self.cell_size.setSingleStep(10.0 ** (e - 1) if small else 10.0)

    def _count_text(self, lake) -> str:
        """The cells of the layout Auto layout makes of ``lake`` at its cell size, as counted by the
        controller (the layout made in a worker); while it is made, or for a lake too large to count, the
        water's area over the cell size squared, said to be that (the layout's cells come out 0.67-3.8 x
        it where blocks are a few cells across: each side's count is a multiple of 4)."""
        from ..lake import expected_cells

        got = self.ctl.layout_count(lake)
        if isinstance(got, tuple):
            n, k = got
            return f"{n:,} cells in {k} block{'s' * (k != 1)}"
        if isinstance(got, str):
            return f"no layout ({got})"
        rough = f"about {expected_cells(lake):,} cells by area ÷ cell size²"
        return f"{rough}; counting the layout's…" if self.ctl.counting(lake) else rough

    def _show_active(self) -> None:
        """The selected (active) block's cells in the spin boxes, in steps of the layout's multiple."""
        lay = self.doc.project.layout
        on = lay is not None and self.doc.active < len(lay.blocks)
        for w in (self.ni, self.nj, self.set_cells):
            w.setEnabled(on)
        if not on:
            self.block_label.setText("cells")
            return
        b = lay.blocks[self.doc.active]
        if self.table.rowCount() > self.doc.active and self.table.currentRow() != self.doc.active:
            # its row too (a worst place made b18 active: the table went on showing b0 selected)
            self.table.setCurrentCell(self.doc.active, 0)
            self.table.scrollToItem(self.table.item(self.doc.active, 0))
        self.block_label.setText(f"{b.name}:")
        for w, v in ((self.ni, b.cells[0]), (self.nj, b.cells[1])):
            w.setSingleStep(lay.multiple)
            w.setValue(int(v))

    def _set_cells(self) -> None:
        self.ctl.set_block_cells(self.doc.active, (self.ni.value(), self.nj.value()))
        self.committed.emit()

    def _cell_size_edited(self) -> None:
        v = float(self.cell_size.value())
        self.ctl.set_cell_size(v if v > 0 else None)
        self.committed.emit()

    def _regular_toggled(self, on: bool) -> None:
        self.ctl.set_regular(on)
        self.committed.emit()

    def _busy(self, busy: bool) -> None:
        self.button.setEnabled(not busy)
        self.split.setEnabled(not busy and self.doc.project.layout is None and bool(self.doc.project.cut_lines))
        self.button.setText("Computing the layout…" if busy else "Auto layout")

    def _ticked(self, seconds: int) -> None:
        # (Stop asked: the layout ends at its next check, a tenth of a second or so on a big lake)
        self.button.setText("Stopping the layout…" if self.ctl.stopping else f"Computing the layout… {seconds} s")


def miss_points(verdict, row: int | None = None) -> np.ndarray:
    """``(k, 3)`` places (nodes, cells, edge pairs) that miss a failed limit (only limit ``row`` if given):
    x, y and how far beyond the limit (the value over the limit; NaN where the value is not a number)."""
    m = verdict.metrics
    out = []
    results = verdict.results if row is None else verdict.results[row : row + 1]
    for r in results:
        if r.passed is not False:
            continue
        s = m.samples.get(r.limit.metric)
        if s is None or not len(s) or r.limit.statistic != "each":
            continue
        bad = ~(s.values <= r.limit.max)
        v = np.asarray(s.values, float)[bad]
        over = v / r.limit.max if r.limit.max > 0 else v - r.limit.max
        out.append(np.column_stack([s.x[bad], s.y[bad], over]))
    return np.vstack(out) if out else np.zeros((0, 3))


def _same_measure(a: tuple, b: tuple) -> bool:
    """Two ``(metrics, preset name)`` of :meth:`LakeQualityBox._measured` of one measure."""
    return bool(a) and bool(b) and a[0] is b[0] and a[1] == b[1]


def worst_miss(verdict, row: int):
    """The worst place (a :class:`meshcore.quality.lake.Location`) of failed limit ``row``, or None."""
    if verdict is None or not 0 <= row < len(verdict.results):
        return None
    r = verdict.results[row]
    return r.worst[0] if r.passed is False and r.worst else None


class LakeQualityBox(QtWidgets.QGroupBox):
    """A model's limits (Delft3D, EFDC, …) against the lake grid: pass/fail per limit.

    ``misses`` carries the places that miss the selected limit (the canvas rings them); a new
    verdict selects its first failed limit.  A click (or Enter) on a failed limit sends its worst
    place by ``go_to`` (the window zooms to it): the worst cell could be found only by scanning
    hundreds of orange dots.
    """

    misses = QtCore.Signal(object)
    go_to = QtCore.Signal(object, str)  # the worst Location of a limit, what it misses

    def __init__(self, doc: Document, parent=None) -> None:
        super().__init__("Lake grid against a model's limits", parent)
        from meshcore.quality import PRESETS

        self.doc = doc
        self.verdict = None
        self.previous = False  # the verdict is of the grid before the last edit (auto-generate off)
        lay = QtWidgets.QVBoxLayout(self)
        row = QtWidgets.QHBoxLayout()
        row.addWidget(QtWidgets.QLabel("Preset"))
        self.preset = QtWidgets.QComboBox()
        self.preset.addItems(list(PRESETS))
        row.addWidget(self.preset, 1)
        lay.addLayout(row)
        self.headline = QtWidgets.QLabel()
        self.headline.setWordWrap(True)
        lay.addWidget(self.headline)
        self.table = QtWidgets.QTableWidget(0, 3)
        self.table.setHorizontalHeaderLabels(["verdict", "miss", "limit"])
        self.table.horizontalHeader().setStretchLastSection(True)
        self.table.verticalHeader().hide()
        self.table.verticalHeader().setDefaultSectionSize(20)
        self.table.setEditTriggers(QtWidgets.QAbstractItemView.EditTrigger.NoEditTriggers)
        self.table.setToolTip(
            "click a limit: the places that miss it are marked on the canvas (orange: the worst in each "
            "patch of the screen, so the grid stays in sight; ringed red: the worst of all) and the view "
            "goes to the worst (Enter too); a click again goes to the next worst"
        )
        lay.addWidget(self.table)
        self.table.setSelectionBehavior(QtWidgets.QAbstractItemView.SelectionBehavior.SelectRows)
        self.table.setSelectionMode(QtWidgets.QAbstractItemView.SelectionMode.SingleSelection)
        self.table.itemSelectionChanged.connect(self._row_selected)
        # a click on a failed limit goes to its worst place (a new user clicked, saw dots somewhere
        # and did not guess that a double-click would go there); Enter (activated) too.  Only the
        # user's click: a new verdict selects its first failed limit without moving the view
        # a click again on the same limit goes to its next worst place (of the few the verdict keeps, then
        # round again); Enter shows the place gone to last again.  It went to the worst only: the next
        # worst, which meshcore quality prints, could be found only among the orange dots
        self._visit: tuple | None = None  # (what the verdict is of, row, k): the k-th worst of limit row, gone to
        self.table.clicked.connect(lambda index: self.go_to_worst(index.row(), step=True))
        self.table.activated.connect(lambda index: self.go_to_worst(index.row()))
        self.preset.currentTextChanged.connect(lambda _t: self.refresh())
        doc.quality_changed.connect(self.refresh)
        # a project without a layout (New, an example) hides the box even when no grid went with it; one
        # with a layout and no grid yet (a laid-out case opened first thing) says F5, not "Auto layout"
        doc.project_changed.connect(self._project_changed)
        self.refresh()

    def _project_changed(self, _project) -> None:
        if self.doc.lake_metrics is None:  # its text (cheap); a verdict is redone when the quality changes
            self.refresh()
        else:
            self.setVisible(self.doc.project.layout is not None)

    def set_previous(self, on: bool) -> None:
        """Say (or stop saying) that the verdict is of the grid before the last edit."""
        if bool(on) != self.previous:
            self.previous = bool(on)
            self.refresh()

    def refresh(self) -> None:
        from meshcore.quality import check

        m = self.doc.lake_metrics
        self.setVisible(self.doc.project.layout is not None)
        if m is None:
            self.verdict = None
            self.headline.setText(
                "No lake grid yet (Auto layout, then it generates)."
                if self.doc.project.layout is None
                else "Measuring the grid: the verdict follows."
                if self.doc.measuring
                else "The verdict follows when the grid of this layout is made (F5 if it is not being made)."
            )
            self.table.setRowCount(0)
            self.table.hide()  # an empty table (its header, an empty box) stood under the text
            self.misses.emit(None)
            return
        self.table.show()
        rows = self.table.selectionModel().selectedRows() if self.verdict is not None else []
        # the limit the user chose stays chosen (a click on the second went to its worst place in another
        # block; that block's quality, made active, selected the first again: its misses on the canvas)
        chosen = (self.verdict.preset.name, rows[0].row()) if rows else None
        v = check(m, self.preset.currentText())
        self.verdict = v
        s = m.summary()
        n_fail = len(v.failed)
        word = "PASS" if v.passed else f"FAIL ({n_fail} of {len(v.results)} limits missed)"
        before = "<i>Grid of before the last edit</i> (F5 makes the new one) — " if self.previous else ""
        info = getattr(self.doc.multiblock, "info", None)
        if not before and info is not None and not info.converged and info.message == "stopped":
            # Stop (Esc): said once in the status line (a button's tip replaced it); the verdict read as final
            before = "<i>Grid stopped before it was finished</i> (F5 makes it again) — "
        self.headline.setText(
            f"{before}<b>{v.preset.name}: {word}</b> — {s['cells']:,} cells, mean deviation from 90° "
            f"{s['mean_deviation_deg']:.2f}°, {s['folded_cells']} folded{_small_cell(s)}"
        )
        self.table.setRowCount(len(v.results))
        for k, r in enumerate(v.results):
            if r.passed is None:
                text, colour = "not checked", "#666"
            else:
                stat = f"mean {r.value:.3g}" if r.limit.statistic == "mean" else f"{ok_percent(r.value)} % ok"
                text, colour = (f"pass ({stat})", "#070") if r.passed else (f"FAIL ({stat})", "#c00")
            # a limit on the mean has no misses of its own (its 'miss' was the count over the value,
            # 653 beside 'pass (mean 1.67)' with efdc): a dash; the tooltip keeps the count
            miss = str(r.n_failed) if r.limit.statistic == "each" else "–"
            cells = [text, miss, r.limit.label]
            for c, t in enumerate(cells):
                it = QtWidgets.QTableWidgetItem(t)
                over = "" if r.limit.statistic == "each" else f" (over {r.limit.max:g} each: {r.n_failed})"
                it.setToolTip(
                    f"{r.limit.label}: {text}{over}" if over else f"{r.limit.label}: {text}, {r.n_failed} miss"
                )
                if c == 0:
                    it.setForeground(QtGui.QBrush(QtGui.QColor(colour)))
                self.table.setItem(k, c, it)
        self.table.resizeColumnToContents(0)
        self.table.resizeColumnToContents(1)
        # all the limits when there is room, at least one (it scrolls): a fixed height of all of them
        # made the window's minimum taller than a laptop's screen (with the Quality panel below)
        head = self.table.horizontalHeader().height() + 4
        self.table.setMinimumHeight(head + 21 * min(len(v.results), 1))
        self.table.setMaximumHeight(head + 21 * len(v.results))
        first = next((k for k, r in enumerate(v.results) if r.passed is False), None)
        kept = chosen is not None and chosen[0] == v.preset.name and 0 <= chosen[1] < len(v.results)
        if kept and v.results[chosen[1]].passed is False:
            first = chosen[1]
        if first is None:
            self.table.clearSelection()
            self.misses.emit(None)
        else:
            self.table.selectRow(first)
            self._row_selected()

    def go_to_worst(self, row: int, step: bool = False) -> bool:
        """Send the worst place of failed limit ``row`` (``go_to``); False if it has none.  ``step`` (a
        click): when that limit was the one gone to last, its next worst place (round again after the
        last the verdict keeps); else the place gone to last again (the worst, the first time)."""
        if worst_miss(self.verdict, row) is None:
            return False
        worst = self.verdict.results[row].worst
        k = 0
        last, key = self._visit, self._measured()
        if last is not None and _same_measure(last[0], key) and last[1] == row:
            k = (last[2] + (1 if step else 0)) % len(worst)
        self._visit = (key, row, k)
        self.go_to.emit(worst[k], self.verdict.results[row].limit.label)
        return True

    def rank(self, where) -> tuple[int, int]:
        """``(k, n)``: ``where`` is the ``k``-th (0: the worst) of the ``n`` worst places kept of the limit
        gone to last; ``(0, 1)`` for a place that is not one of them."""
        last = self._visit
        if last is None or not _same_measure(last[0], self._measured()) or self.verdict is None:
            return 0, 1
        worst = self.verdict.results[last[1]].worst
        return (last[2], len(worst)) if last[2] < len(worst) and worst[last[2]] == where else (0, 1)

    def _measured(self) -> tuple:
        """What the verdict is of: the grid's metrics and the preset (a verdict is made again, alike, when
        the block gone to becomes the active one)."""
        return (self.verdict.metrics, self.verdict.preset.name) if self.verdict is not None else ()

    def _row_selected(self) -> None:
        rows = self.table.selectionModel().selectedRows() if self.verdict is not None else []
        self.misses.emit(miss_points(self.verdict, rows[0].row()) if rows else None)


def _small_cell(s: dict) -> str:
    """The headline's word on a cell far smaller than the rest (``s``: the lake metrics' summary; its
    shortest edge at most 1/:data:`meshcore.quality.lake.SHRINK_NOTE` of the cell size,
    :func:`~meshcore.quality.lake.small_edge`), or nothing: where an explicit model's time step would be
    set (the Quality panel colours them all, "time step cost").  In the words of the quality table and
    ``meshcore mesh`` (:func:`~meshcore.quality.lake.shortest_edge_words`)."""
    from meshcore.quality.lake import shortest_edge_words, small_edge

    least = s.get("min_edge_cells")
    return f", shortest edge {shortest_edge_words(least)}" if small_edge(least) else ""
