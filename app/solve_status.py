"""What the window shows about solving: the convergence plot, the solver label, notes.

:class:`SolveStatus` listens to the solver controller and the document and
updates the convergence plot, the solver label in the status bar, the
Pause/Stop actions and the status line; it reports the solver's notes
(repairs, corner advice) in full to the message panel.
"""

from __future__ import annotations

import time

from PySide6 import QtCore, QtWidgets

from .document import KEPT_SOLVES
from .pipeline import ALL_BLOCKS

__all__ = ["SolveStatus"]

#: what the message of a lake grid made again with sliding ends (meshcore.lakegrid.FOLD_RETRY) says
MADE_AGAIN = "made again with block corners and cut ends sliding along the shore"
#: seconds between two updates of the convergence plot during a multiblock or lake solve
HISTORY_EVERY = 1.0
#: seconds between two updates of the solver label during such a solve: each one lays out and repaints
#: the status bar (2–3 ms of the GUI thread, a tenth of a drag's redraw; four a second are read as well)
LABEL_EVERY = 0.25


class SolveStatus(QtCore.QObject):
    """The solving part of a :class:`~app.main_window.MainWindow` (label: ``self.label``)."""

    def __init__(self, window) -> None:
        super().__init__(window)
        self.win = window
        self.doc = window.doc
        self.solver = window.solver
        self.conv = window.conv_panel
        self.label = QtWidgets.QLabel("idle")
        self.frames: list[float] = []  # times of the last redraws (for the redraws/s read-out)
        self._history_at = 0.0  # when the convergence plot was last drawn
        self._label_at = 0.0  # when the solver label was last set during a multiblock solve
        self._label_text = ""  # the latest progress text (shown by the timer when it came too soon)
        self._label_timer = QtCore.QTimer(self)
        self._label_timer.setSingleShot(True)
        self._label_timer.timeout.connect(self._show_label)
        self._last_history: tuple | None = None  # (history, tolerance, levels) of the last multiblock snapshot
        # the solve time and history of the lake grids the document keeps: an undo or redo that brings one back
        # said the last solve's time beside its sweeps, and left the plot empty or of another grid
        self._kept: dict[int, tuple] = {}  # id of the MultiBlockGrid -> (it, seconds, history)
        self._due: set[str] = set()  # "summary", "notes": said once the large grid's quality is measured
        self.doc.grids_changed.connect(lambda: self.frames.append(time.perf_counter()))
        self.doc.active_changed.connect(lambda _k: self.on_final())
        self.doc.opened.connect(self.on_opened)
        self.doc.project_changed.connect(self.on_edited)
        self.solver.state_changed.connect(self.on_state)
        self.solver.error.connect(self.on_error)
        self.solver.progress.connect(self.on_progress)
        self.solver.finished.connect(self.on_finished)
        self.solver.retry_said.connect(self.on_retry)
        window.lake_ctl.busy_changed.connect(lambda _b: self._stop_enabled())  # Stop ends Auto layout too
        self.doc.quality_changed.connect(self.on_measured)

    def reset(self) -> None:
        """A solve is about to start."""
        self.conv.clear_history()
        self._last_history = None
        self.frames = []

    def on_opened(self) -> None:
        self.conv.clear_history()
        self._show_previous(False)
        self.label.setText("idle")

    def on_edited(self, _project) -> None:
        """An edit with auto-generate off: the grid on screen is the one of before it (a dragged
        junction's cut lines no longer on its block borders), so it is greyed and said to be, with
        its verdict, until a solve makes the new one (F5).  An undo back to the project the grid was
        made for makes it current again (no F5, and it exports)."""
        if self.solver.running:
            return
        if (
            not self.doc.grids and not self.doc.before_grids
        ):  # another lake, a new layout: the summary is of nothing here
            self.label.setText("idle")
            self.conv.clear_history()  # nor the convergence of the grid of before (another lake's, shown on)
            self._last_history = None
            return
        if not self.doc.stale:  # (auto-generate on too: after a failed solve the grid was greyed)
            self.on_final()
            return
        if self.solver.auto:
            return
        self._show_previous(True)
        self.label.setText("grid of before the edit (F5 makes the new one)")

    def _show_previous(self, on: bool) -> None:
        self.win.canvas.set_grid_stale(on)
        box = getattr(self.win, "lake_quality", None)
        if box is not None:
            box.set_previous(on)

    def on_progress(self, k: int, snap) -> None:
        if k == ALL_BLOCKS:  # a multiblock solve: every block at once
            now = time.perf_counter()
            # the plot at most every HISTORY_EVERY s: it repaints its axes (costly in a drag's redraws); not
            # at all while a drag is on (each step restarts the sweeps: the whole history is drawn at the end)
            levels = getattr(snap, "levels", ())  # a lake grid's levels (app.lake_solve.LakeProgress)
            if snap.history:
                self._last_history = (snap.history, snap.tolerance, levels)
            if snap.history and now - self._history_at >= HISTORY_EVERY and not self.solver.live:
                self._history_at = now
                self.conv.set_history(list(snap.history), snap.tolerance, levels)
            if levels:  # a lake grid: the words of its convergence plot (sweeps, the largest move / cell)
                self._label_text = f"lake grid: sweep {snap.iteration}, largest move {snap.residual:.2e} of a cell"
            else:
                self._label_text = f"multiblock: iteration {snap.iteration}, residual {snap.residual:.2e}"
            wait = self._label_at + LABEL_EVERY - now
            if wait <= 0:
                self._show_label()
            elif not self._label_timer.isActive():  # the latest text, once the gap is over
                self._label_timer.start(max(1, int(1000 * wait)))
            return
        if k == self.doc.active:  # history and residual are relative to the grid size
            self.conv.set_history(list(snap.history), snap.tolerance)
        fr = [t for t in self.frames if t > self.frames[-1] - 1.0] if self.frames else []
        self.label.setText(
            f"{snap.method}: iteration {snap.iteration}, residual {snap.residual:.2e} "
            f"(tol {snap.tolerance:.1e}), {len(fr)} redraws/s"
        )

    def on_retry(self, kind: str, text: str) -> None:
        """The lake grid is being made again (its levels left folded or non-convex cells): seconds without a
        frame (8 s on Vänern), in which the status sat on the last sweep of the first grid.  The solver label
        follows its steps; its start and its end (which grid was kept) go to the status line and the Messages,
        the end ahead of the grid's line that follows."""
        self._label_timer.stop()  # (a sweep's text due would write over it)
        self._label_text = f"lake {text}"
        self._show_label()
        if kind not in ("retry", "retried"):
            return
        line = text[0].upper() + text[1:]
        self.doc.report("info", f"lake {text}")
        self.win.message(line, note=kind == "retried")

    def _show_label(self) -> None:
        """The latest progress text, while the solve runs (never over "paused" or the final summary)."""
        if self.solver.state == "running":
            self._label_at = time.perf_counter()
            self.label.setText(self._label_text)

    def on_state(self, state: str) -> None:
        running = state != "idle"
        self.doc.set_solving(running)
        self.win.a_pause.setEnabled(running)
        self._stop_enabled()
        self.win.a_pause.setChecked(state == "paused")
        if state == "paused":
            self.label.setText("paused")
        elif state == "running":  # until its first progress (a minute when the first solve compiles its kernels)
            self.label.setText("solving…")

    def _stop_enabled(self) -> None:
        """Stop (Esc) is on while the solver runs or Auto layout computes (:meth:`MainWindow.stop`)."""
        self.win.a_stop.setEnabled(self.solver.running or self.win.lake_ctl.busy)

    def on_error(self, text: str) -> None:
        # the boundary cannot be gridded as it is: keep the old grid, greyed, and say why
        self._show_previous(True)
        self.win.message(f"Cannot generate: {text}", error=True)
        self.label.setText("error")

    def on_finished(self, result) -> None:
        made = not (self.solver.last_error or self.solver.stopped_coarse or self.solver.kept_grid)
        if result is not None and made:
            # a grid was made: "Cannot generate" and the folded cells of the grid before are not of it (the
            # message panel's count kept them: "1 error(s)" beside a grid without a fault)
            self.doc.superseded.emit()
        if result is not None and self.doc.project.multiblock is not None:
            self.doc.set_multiblock(getattr(result, "multiblock", None))
        self.on_final()
        if self.doc.stale and not self.solver.stopped_coarse:  # an edit came while it solved (auto-generate
            self.on_edited(self.doc.project)  # off): the grid of before it
        if result is not None and not self.solver.last_error:
            self.report_notes()

    def on_measured(self) -> None:
        """A large grid's quality, measured in a worker (:attr:`Document.measuring`), came: what waited
        for it (the summary with its folded cells or mean deviation, the lake grid's notes) is said now."""
        if self.doc.measuring or not self._due:
            return
        due, self._due = self._due, set()
        if self.solver.running or self.doc.quality is None:  # another solve, or another grid, came first
            return
        if "summary" in due:
            self.on_final()
        if "notes" in due:
            self.report_notes()

    def on_final(self) -> None:
        """The solve ended (or another block became active): the summary of the active grid (said again
        when the quality of a large grid, measured in a worker, comes)."""
        g = self.doc.grid
        if self.solver.running or self.solver.last_error:
            return
        if self.doc.measuring:
            self._due.add("summary")
        self._show_previous(False)
        if self.solver.kept_grid and self.doc.project.layout is not None:
            self._kept_final()
            return
        if g is None and self.solver.stopped_coarse and self.doc.project.layout is not None:
            self._coarse_final()
            return
        if g is None:
            self.label.setText("idle")
            return
        info = g.info
        mb = self.doc.multiblock
        if self.doc.project.layout is not None and mb is not None:  # a lake grid: what was done to all blocks
            self._lake_final(mb)
            return
        if info.residual_history:
            self.conv.set_history(list(info.residual_history), info.tolerance)
        r = self.doc.quality
        dt = self.solver.t_done - self.solver.t_start
        state = "converged" if info.converged else info.message or "not converged"
        warn = f" — {r.n_folded} FOLDED cells (red ×)" if r is not None and r.n_folded else ""
        if info.method.endswith("+foldfree") and info.message:
            warn += " — invalid cells repaired (what was done: View ▸ Messages)"
        if self.doc.measuring:
            warn += " — measuring its quality…"
        self.label.setText(f"{info.method}: {state}, {info.iterations} iterations, {dt * 1000:.0f} ms")
        self.win.message(f"Grid {g.cells[0]}×{g.cells[1]} cells: {state}{warn}", summary=True)

    def _lake_final(self, mb) -> None:
        info = mb.info
        kept = self._kept.get(id(mb))
        again = MADE_AGAIN in info.message  # the grid made again (FOLD_RETRY): its sweeps are not in the plot
        if kept is None or kept[0] is not mb:  # the solve just ended: its time and history, kept for an undo
            history = self._last_history
            if again and history is not None and history[0]:  # where the plotted sweeps end and it was made again
                history = (*history[:2], (*history[2], (int(history[0][-1][0]), "made again")))
            kept = (mb, self.solver.t_done - self.solver.t_start, history)
            self._kept = dict(list(self._kept.items())[-(KEPT_SOLVES - 1) :])
            self._kept[id(mb)] = kept
        if kept[2] is not None:  # the whole history (the plot is throttled while solving)
            self.conv.set_history(list(kept[2][0]), *kept[2][1:])
        m = self.doc.lake_metrics
        dt = kept[1]
        cells = sum(g.cells[0] * g.cells[1] for g in mb.grids)
        # stopped (Stop, Esc): the grid as the sweeps left it, without the finest level's repair and the
        # interface equalizing; it was summed up as a finished grid, nothing said it was not
        stopped = not info.converged and info.message == "stopped"
        done = f"stopped after {info.iterations} sweeps" if stopped else f"{info.iterations} sweeps"
        # (a grid made again: its own sweeps, made after those plotted; it said "1170 sweeps" beside a plot of 1325)
        self.label.setText(f"orthogonal: {done}{' (made again)' if again else ''}, {dt:.1f} s")
        folded = int(m.values("folded").sum()) if m is not None else 0
        warn = f" — {folded} FOLDED or non-convex cells" if folded else ""
        mean = f", mean deviation from 90° {m.mean('deviation'):.2f}°" if m is not None else ""
        if m is None and self.doc.measuring:
            mean = " — measuring its quality…"
        what = "Lake grid, stopped before it was finished (F5 makes it again)" if stopped else "Lake grid"
        self.win.message(
            f"{what}: {len(mb.grids)} blocks, {cells:,} cells{mean}{warn}", error=bool(folded), summary=True
        )

    def _kept_final(self) -> None:
        """A solve of a finished lake grid's layout stopped (F5 on it, then Stop): that grid is kept, and the
        convergence plot is its own (it was the stopped solve's, of a grid no longer shown)."""
        mb = self.doc.multiblock
        kept = self._kept.get(id(mb)) if mb is not None else None
        history = kept[2] if kept is not None and kept[0] is mb else self._last_history
        if history is not None:
            self.conv.set_history(list(history[0]), *history[1:])
        where = " on a coarse level" if self.solver.stopped_coarse else ""
        self.label.setText(f"stopped{where}: the grid of before kept")
        self.win.message(
            f"Lake grid solve stopped{where}: the finished grid of before stays (F5 solves again)", summary=True
        )

    def _coarse_final(self) -> None:
        """A lake solve stopped before its full level: no grid of the layout; its last coarse level, greyed."""
        level = self.solver.coarse_level
        if self._last_history is not None:
            self.conv.set_history(list(self._last_history[0]), *self._last_history[1:])
        shown = bool(self.doc.before_grids)
        self._show_previous(shown)
        self.label.setText(f"stopped on a coarse level{f' ({level})' if level else ''}: no grid")
        if self.solver.coarse_drawn:
            grey = f"the greyed grid is a coarse level's ({level}), not the layout's"
        else:  # the grid of before an edit of the cells, left on screen through the coarse levels
            grey = "the greyed grid is of before the last edit" if shown else "nothing was drawn"
        self.win.message(
            f"Lake grid stopped before its full level: no grid of this layout ({grey}); F5 makes it", summary=True
        )

    def report_notes(self) -> None:
        """Repairs, corner advice and other notes of the solver, in full, in the message panel."""
        blocks = self.doc.project.blocks
        mb = self.doc.multiblock
        if self.solver.stopped_coarse or self.solver.kept_grid:  # no new grid: nothing of it to note
            return
        if self.doc.project.layout is not None and mb is not None:
            if self.doc.measuring:  # its coverage warnings: once measured
                self._due.add("notes")
                return
            self.doc.report("info", f"lake grid: {mb.info.message}")
            m = self.doc.lake_metrics
            cov = getattr(m, "coverage", None)
            for w in cov.warnings() if cov is not None else ():  # islands under the grid: as meshcore mesh warns
                self.doc.report("warning", f"lake grid: {w}")
            return
        for k, g in sorted(self.doc.grids.items()):
            note = (g.info.message or "").strip()
            if not note or note in ("converged", "stopped"):
                continue
            name = blocks[k].name if k < len(blocks) else f"block {k + 1}"
            bad = "move corner" in note or "cannot" in note or not g.converged
            self.doc.report("warning" if bad else "info", f"{name}: {note}")
