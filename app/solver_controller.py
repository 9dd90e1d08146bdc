"""Runs the solver in a worker thread and feeds the document at a bounded rate.

The worker (superqt ``GeneratorWorker``) iterates :func:`app.pipeline.solve_project`
(meshcore's typed events per block) and only emits signals; the slots here run
in the GUI thread.  Snapshots are
kept as the *latest* one per block and pushed to the document by a ~30 Hz
timer, so stale frames are dropped, never queued.  A solve started by *Generate* keeps the
GUI thread's share of the CPU time small: a live frame is drawn only once the process has spent
``1 / DRAW_BUDGET`` times the GUI thread's CPU time since the last frame (its drawing included), and the
first one only once it has spent that many times the cost of the last frame measured: a solve shorter
than that draws only its final grid.  The GUI thread's drawing is not free while the solver runs: Qt's
painting calls keep the GIL (PySide6 6.10: a Python thread got no CPU time during a ``QPainter.drawLines``
call), so at low load the app's solve takes the solver's CPU time plus the GUI thread's (on a busy
two-core machine 40 redraws/s of a large grid had made the app's solve 2–3× as long as the CLI's).
Edits with auto-generate, and a drag of a lake layout, keep the full frame rate (the grid follows the
hand).  Stop sets a
``threading.Event`` checked by meshcore after every sweep/cycle, so it takes
effect within one sweep.  With ``auto`` on, every project edit restarts the
solve (coalesced in one event-loop pass), warm-started from the last grid.  While a drag is
on (:meth:`SolverController.set_live`), a lake solve waits after its live frames instead of making
the final grid that the drag's next step would stop unseen.
"""

from __future__ import annotations

import logging
import threading
import time

from PySide6 import QtCore
from superqt.utils import create_worker

from meshcore import Done, MeshcoreError, Repaired, SolverProgress, StartGrid, StructuredGrid

from .document import Document
from .pipeline import ALL_BLOCKS, solve_project

__all__ = ["SolverController"]

log = logging.getLogger(__name__)

#: Share of the process's CPU time the GUI thread may spend drawing live frames of a solve started
#: by Generate (the rest is the solver's).
DRAW_BUDGET = 0.08
#: The longest gap between two live frames of such a solve (seconds).
MAX_FRAME_GAP = 1.0
#: The GUI thread's CPU time for a live frame until one was measured (seconds): the first frame of a
#: solve waits until the process has spent this over :data:`DRAW_BUDGET`.
FRAME_COST = 0.005


def _stopped(result) -> bool:
    """A lake solve's result that was stopped: no grid (a coarse level), or its grid said to be stopped."""
    if result is None:
        return False
    info = getattr(getattr(result, "multiblock", None), "info", None)
    return not result.grids or (info is not None and not info.converged and info.message == "stopped")


def _another_lake(a, b) -> bool:
    """Two projects of other water: another frame or title (an import, its undo or redo)."""
    return (a.crs, tuple(a.origin)) != (b.crs, tuple(b.origin)) or bool(a.title and b.title and a.title != b.title)


def _run(run_id, project, warm, stop_event, smooth, hold=None, notify=None):
    """The worker body: tag every item with the run id; errors become results."""
    gen = solve_project(project, warm=warm, stop_event=stop_event, smooth=smooth, hold=hold, notify=notify)
    try:
        while True:
            k, event = next(gen)
            yield run_id, k, event
    except StopIteration as fin:
        return run_id, fin.value, None
    except MeshcoreError as exc:
        return run_id, None, str(exc)
    except Exception as exc:  # a bug must not kill the window: report it, and log where it happened
        log.exception("the solver worker failed")
        return run_id, None, f"internal error: {type(exc).__name__}: {exc} (the traceback is in the log)"


class SolverController(QtCore.QObject):
    """Start/pause/stop the solver; throttle snapshots into the document."""

    state_changed = QtCore.Signal(str)  # "idle" | "running" | "paused"
    progress = QtCore.Signal(int, object)  # block index, SolverProgress (throttled)
    finished = QtCore.Signal(object)  # BlockResult, or None on error/stop
    error = QtCore.Signal(str)
    redrawn = QtCore.Signal()
    #: a lake grid being made again, unseen, because its levels left bad cells (``kind`` of
    #: :func:`meshcore.lakegrid.iterate_layout`'s report: "retry", "again level", "again equalize", "retried";
    #: the words of :func:`meshcore.lakegrid.retry_words`): seconds on a large lake in which no frame comes
    retry_said = QtCore.Signal(str, str)
    _noted = QtCore.Signal(int, str, str)  # (run, kind, text) from the worker's thread: queued to retry_said

    def __init__(self, doc: Document, parent=None, *, frame_interval_ms: int = 25) -> None:
        super().__init__(parent)
        self.doc = doc
        self.auto = False
        self.smooth = True
        self._worker = None
        self._run = 0
        self._stop_event: threading.Event | None = None
        self.live = False  # a drag is on: a lake solve holds after its live frames (set_live)
        self._hold: threading.Event | None = None  # set: the running solve may go on to its final grid
        self._latest: dict[int, object] = {}  # the latest event per block
        self._algebraic: dict[int, StructuredGrid] = {}  # the algebraic grid per block (warm starts)
        self._smoothed: set[int] = set()
        self._dirty = False
        self._drawn = False  # a live frame of the running solve was drawn
        self.state = "idle"
        self.t_start = 0.0
        self.t_done = 0.0
        self._t_before = (0.0, 0.0)
        self.last_result = None
        self.last_error: str | None = None
        #: the last lake solve was stopped before its full level: no grid of the layout (its coarse frames greyed)
        self.stopped_coarse = False
        #: that stopped solve left the finished grid shown before it (F5 on it, stopped on a coarse level)
        self.kept_grid = False
        #: the level it stopped on ("cells ÷2") and whether its frames were drawn (else the grid of before)
        self.coarse_level, self.coarse_drawn = "", False
        self._restart_pending = False
        self._restart_as = (False, False)  # (edit, cold) of the solve the pending restart starts
        self._edit_run = False  # the running solve was started by an edit (Live), not by Generate
        self._dropped = False  # the running solve is of no use now (an undo or redo brought a kept grid back)
        self._project = None  # the project the running solve was started for
        self._resume_wanted = False  # a resume waits for the worker to take its pause
        self.gui_thread = QtCore.QThread.currentThread()
        self.thread_violations = 0  # slots found running outside the GUI thread (tests)
        # leading-edge throttle: draw a snapshot at once unless the last frame was
        # less than `frame_interval_ms` ago; then draw the latest one when the gap is over
        self.frame_interval = frame_interval_ms / 1000.0
        self._last_flush = 0.0
        self._gui_cpu = 0.0  # GUI thread CPU time at the last frame
        self._proc_cpu = 0.0  # the process's CPU time (every thread) at the last frame
        self.frame_cost = FRAME_COST  # the GUI thread's CPU time between the last two live frames
        self._timer = QtCore.QTimer(self)
        self._timer.setSingleShot(True)
        self._timer.timeout.connect(self._on_timer)
        self._debounce = QtCore.QTimer(self)
        self._debounce.setSingleShot(True)
        self._debounce.setInterval(0)
        self._debounce.timeout.connect(self._start_edit)
        doc.project_changed.connect(self._on_project_changed)
        self._noted.connect(self._on_noted, QtCore.Qt.ConnectionType.QueuedConnection)

    # ------------------------------------------------------------ control
    @property
    def running(self) -> bool:
        return self.state in ("running", "paused")

    def set_auto(self, on: bool) -> None:
        self.auto = bool(on)
        if self.auto and self.doc.stale:
            self._debounce.start()

    def skip_auto(self) -> None:
        """The auto-generate solve due for the edit just made does not start (F5 starts it)."""
        self._debounce.stop()

    def _on_project_changed(self, _project) -> None:
        if not self.running:  # the last solve's error was of the project before this edit (an undo
            self.last_error = None  # back to a gridded one: its grid is current, not held back as failed)
            # nor is a grid shown now "the grid of before kept" by a stopped solve (Ctrl+Z, Ctrl+Y after a
            # stopped F5 said so of the grid the redo brought back, its convergence plot empty)
            if self.kept_grid:  # (stopped_coarse with it: that stopped solve's level, not a grid missing)
                self.kept_grid = self.stopped_coarse = False
        elif self.doc.restored is self.doc.project and self._project is not self.doc.project:
            self._drop()  # an undo or redo back to a grid the document kept: the solve of before it is of no use
        elif self._project is not None and _another_lake(self._project, self.doc.project):
            self._drop()  # an import undone or redone while its lake solved: that grid is of no block here
        if self.auto and self.doc.stale:  # not for an edit the grid is not made of (a lake's cell size)
            p = self.doc.project
            if p.lake is not None and p.layout is None and len(p.lake.holes) and len(p.blocks) == 1:
                # a lake with islands as one block: its grid goes across the islands, the grid the import's
                # Auto layout offer calls poor (an undo of Auto layout solved it, repairs and all); F5 makes it
                self._debounce.stop()
                self.doc.message.emit(
                    "Auto-generate leaves a lake with islands as one block ungridded: Auto layout (Ctrl+L), "
                    "or F5 for the one block"
                )
                return
            self._debounce.start()

    def _start_edit(self) -> None:
        """The solve of an edit just made (Live on): the grid follows it at the full frame rate."""
        self.start(edit=True)

    def start(self, *, edit: bool = False, cold: bool = False) -> bool:
        """(Re)start solving the current project; returns False when nothing is ready.

        ``edit``: the solve of an edit with Live on (every frame drawn); else a solve asked for by Generate
        (F5, Auto layout's grid), whose live frames keep to :data:`DRAW_BUDGET` whether Live is on or not.
        ``cold``: no warm start from the grids shown (a lake layout's grid made coarse to fine from its start,
        as ``meshcore mesh`` makes it).  Generate on a lake layout whose finished grid is shown is cold too:
        a warm phase from that grid would only come before the same coarse-to-fine remake.
        """
        self._debounce.stop()
        project = self.doc.project
        if not any(b.ready for b in project.blocks):
            self.stop()
            self.doc.clear_grids()
            return False
        if self._worker is not None:
            # chain: stop the running solve (within one sweep) and restart from its
            # latest iterate when it returns, so that a drag's corrections accumulate
            self._restart_pending = True
            self._restart_as = (edit, cold)
            self._interrupt()
            return True
        self._restart_pending = False
        self._run += 1
        self.last_error = None
        self.stopped_coarse = False
        self.kept_grid = False
        self._edit_run = edit
        if not edit and project.layout is not None and self.doc.final_of(project) is not None:
            cold = True
        warm = {}
        for k, g in self.doc.grids.items() if not cold else ():
            a = self.doc.initial.get(k)
            if a is not None and a.shape == g.shape:
                warm[k] = (a, g)
        ev = threading.Event()
        self._stop_event = ev
        hold = threading.Event()
        if not self.live:
            hold.set()
        self._hold = hold
        self._latest = {}
        self._algebraic = {}
        self._smoothed = set()  # blocks whose snapshots of this run are on screen
        self._drawn = False
        self._project = project  # what this run solves (an edit may come before it ends)
        notify = self._notifier(self._run)
        worker = create_worker(_run, self._run, project, warm, ev, self.smooth, hold, notify, _start_thread=False)
        worker.yielded.connect(self._on_yielded)
        worker.returned.connect(self._on_returned)
        worker.errored.connect(self._on_errored)
        worker.finished.connect(self._on_finished)
        self._worker = worker
        self._t_before = (self.t_start, self.t_done)  # the times said again if this solve is dropped
        self.t_start = time.perf_counter()
        self._last_flush, self._proc_cpu = self.t_start, time.process_time()
        if self._full_rate():  # the first frame at once (a drag's redraw does not wait)
            self._last_flush, self._gui_cpu = self.t_start - self.frame_interval, time.thread_time()
        else:  # as if a frame had just been drawn: a solve shorter than its budget draws none
            self._gui_cpu = time.thread_time() - self.frame_cost
        self._set_state("running")
        worker.start()
        return True

    def _notifier(self, run: int):
        """``notify(kind, text)`` of run ``run``'s worker (its thread): the words reach :attr:`retry_said` in the
        GUI thread (a window closed meanwhile: they go nowhere, the solve ends as told)."""
        noted = self._noted

        def notify(kind: str, text: str) -> None:
            try:
                noted.emit(run, kind, text)
            except RuntimeError:  # the controller is gone (the window closed while the grid was made again)
                pass

        return notify

    @QtCore.Slot(int, str, str)
    def _on_noted(self, run: int, kind: str, text: str) -> None:
        self._check_thread()
        if run == self._run and self._worker is not None and not (self._dropped or self._restart_pending):
            self.retry_said.emit(kind, text)

    def set_live(self, on: bool) -> None:
        """A drag of the layout begins (True) or ends.  While it is on, a lake solve waits after its live
        frames (the drag's next step restarts it); when it ends, a waiting solve goes on to the final grid
        unless a restart is already due (the drag's last step: that solve makes the final grid)."""
        self.live = bool(on)
        if not self.live and not self._debounce.isActive() and self._hold is not None:
            self._hold.set()

    def drop(self) -> None:
        """The running solve (if any) is of a project no longer open (another lake imported, a project
        opened or started): it stops and its frames and grid are thrown away.  A stopped solve left its grid
        to the new project: the first lake's block measured in the Quality dock, exported as the second's."""
        if self._worker is not None:
            self._drop()

    def _drop(self) -> None:
        """Stop the running solve and throw its frames and grids away: the document shows a kept grid of
        the project now (Redo of Auto layout while the undo's solve of the one block ran: that solve went
        on, then the layout was solved again from scratch, though its grid was kept)."""
        self._dropped = True
        self._debounce.stop()
        self._timer.stop()
        self._latest = {}
        self._dirty = False
        self.stop()

    def stop(self) -> None:
        """Ask the solver to stop; it returns the current grid at the next sweep."""
        self._restart_pending = False
        self._interrupt()

    def _interrupt(self) -> None:
        if self._stop_event is not None:
            self._stop_event.set()
        if self._hold is not None:  # a solve waiting for the end of a drag: it stops now
            self._hold.set()
        # no worker.quit(): an aborted superqt worker never emits `returned`; the
        # generator sees the event after the current sweep and returns the grid itself
        self.resume()

    def pause(self) -> None:
        if self._worker is not None and self.state == "running":
            self._resume_wanted = False
            self._worker.pause()
            self._set_state("paused")

    def resume(self) -> None:
        if self._worker is not None and self.state == "paused":
            self._resume_wanted = True
            self._set_state("running")
            self._resume_worker(self._worker)

    def _resume_worker(self, worker) -> None:
        """superqt's worker takes a pause at its next yield and ignores a resume before that (Space
        twice right after F5 left it paused for good, Stop too): the resume waits for the pause."""
        if worker is not self._worker or not self._resume_wanted:
            return
        if worker.is_paused:
            self._resume_wanted = False
            worker.resume()
        else:
            QtCore.QTimer.singleShot(5, lambda: self._resume_worker(worker))

    def toggle_pause(self) -> None:
        self.resume() if self.state == "paused" else self.pause()

    def wait(self, timeout_s: float = 5.0) -> bool:
        """Process events until idle (for scripts/tests); True when idle."""
        app = QtCore.QCoreApplication.instance()
        t0 = time.perf_counter()
        while self.running or self._debounce.isActive():
            app.processEvents(QtCore.QEventLoop.ProcessEventsFlag.AllEvents, 10)
            if time.perf_counter() - t0 > timeout_s:
                return False
        return True

    def shutdown(self, msecs: int = 2000) -> bool:
        """Stop and wait up to ``msecs`` for every worker (window close); False if one is still busy.

        A worker still in its sweep after the wait has been told to stop and ends by itself.
        """
        self._abandon()
        from superqt.utils._qthreading import WorkerBase

        try:
            WorkerBase.await_workers(msecs=msecs)
        except RuntimeError:  # superqt: "Workers did not quit gracefully in the time allotted"
            return False
        return True

    def _abandon(self) -> None:
        if self._stop_event is not None:
            self._stop_event.set()
        if self._hold is not None:
            self._hold.set()
        if self._worker is not None:
            try:
                self._worker.resume()
                self._worker.quit()
            except RuntimeError:
                pass
        self._worker = None

    def _set_state(self, s: str) -> None:
        if s != self.state:
            self.state = s
            self.state_changed.emit(s)

    def _check_thread(self) -> None:
        if QtCore.QThread.currentThread() is not self.gui_thread:
            self.thread_violations += 1

    # -------------------------------------------------------------- slots
    @QtCore.Slot(object)
    def _on_yielded(self, value) -> None:
        self._check_thread()
        run, k, event = value
        if run != self._run or self._dropped:
            return
        if isinstance(event, StartGrid):
            self._algebraic[k] = event.algebraic
        self._latest[k] = event
        self._dirty = True
        if not self._timer.isActive():
            self._on_timer()

    def _on_timer(self) -> None:
        """Draw the latest snapshot now if its time has come, else come back when it will have."""
        wait = self._wait()
        if wait <= 0:
            self._flush()
        elif self._dirty:  # checked again at least once a second (the CPU time due is only a guess in wall time)
            self._timer.start(max(1, int(min(wait, 1.0) * 1000)))

    def _full_rate(self) -> bool:
        """Every frame the machine can draw: the solve of an edit with Live (auto-generate) on, or a drag of
        the layout.  A solve started by Generate keeps to the budget with Live on too (a lake's layout has
        Live on by default: its Auto layout grid drew 40 frames a second, a quarter of the process's CPU)."""
        return self.live or (self.auto and self._edit_run)

    def _wait(self) -> float:
        """Seconds until the next live frame may be drawn (≤ 0: now).

        At most one frame per ``frame_interval``; for a solve started by Generate, not before the process
        has spent ``1 / DRAW_BUDGET`` times the GUI thread's CPU time since the last frame (CPU time, not
        wall time: on a loaded machine the solver thread gets a fraction of a core, and a budget per wall
        second would let the drawing take a growing share of what the process gets), nor later than
        :data:`MAX_FRAME_GAP` after it.  The CPU time still due is waited as wall time and checked again.
        """
        now = time.perf_counter()
        wait = self._last_flush + self.frame_interval - now
        if self._full_rate():
            return wait
        gui = time.thread_time() - self._gui_cpu
        due = gui / DRAW_BUDGET - (time.process_time() - self._proc_cpu)
        return max(wait, min(due, self._last_flush + MAX_FRAME_GAP - now))

    def _flush(self, *, draw: bool = True) -> None:
        """Push the latest snapshots to the document; ``draw`` False: the data and the progress only (the
        final grids are drawn next: a frame of the stale snapshot would only cost the GUI thread)."""
        if not self._dirty:
            return
        self._dirty = False
        if draw:
            self._frame_started()
        drawn = False  # a frame only when a grid changed (a lake grid made again unseen sends none)
        for k, event in self._latest.items():
            if k == ALL_BLOCKS and isinstance(event, SolverProgress):  # a multiblock solve: every block
                for i, g in enumerate(event.grids):
                    # a coarse level of a lake grid never replaces an earlier solve's grid on screen (nor the
                    # greyed grid of before an edit of the cells: a Stop on that level left a coarse grid)
                    if i in self._smoothed or not (self._showing_other(i, g) or self._covers_earlier(i, g)):
                        self.doc.grids[i] = g
                        self._smoothed.add(i)
                        drawn = True
                self.progress.emit(k, event)
                continue
            drawn = True
            if not isinstance(event, (StartGrid, SolverProgress, Repaired, Done)):
                continue
            if isinstance(event, StartGrid) and self._showing(k, event.grid):
                continue  # a start grid never replaces a smoothed grid on screen (no flicker in a drag)
            self.doc.grids[k] = event.grid
            if k in self._algebraic:
                self.doc.initial[k] = self._algebraic[k]
            if isinstance(event, SolverProgress):
                self._smoothed.add(k)
                self.progress.emit(k, event)
        if drawn and draw:
            self.doc.grids_changed.emit()
            self.redrawn.emit()

    def _frame_started(self) -> None:
        """A live frame starts: the GUI thread's CPU time since the last one is what that one cost."""
        now, cpu = time.perf_counter(), time.thread_time()
        if self._drawn:  # not the first frame of a solve (before it: the estimate the solve began with)
            self.frame_cost = cpu - self._gui_cpu
        self._drawn = True
        self._last_flush, self._gui_cpu, self._proc_cpu = now, cpu, time.process_time()

    def _showing(self, k: int, grid: StructuredGrid) -> bool:
        """True when block ``k`` already shows a grid of this shape (from an earlier solve)."""
        old = self.doc.grids.get(k)
        return old is not None and old.shape == grid.shape

    def _covers_earlier(self, k: int, grid: StructuredGrid) -> bool:
        """True when ``grid`` is a coarse level's frame of lake block ``k`` and the greyed grid of before an
        edit is on screen (no grid of this project yet): it would replace that grid with a coarse one."""
        lay = self._project.layout
        if lay is None or self.doc.grids or k not in self.doc.before_grids or k >= len(lay.blocks):
            return False
        return grid.cells != tuple(lay.blocks[k].cells)

    def _showing_other(self, k: int, grid: StructuredGrid) -> bool:
        """True when block ``k`` shows a grid of another shape (from an earlier solve)."""
        old = self.doc.grids.get(k)
        return old is not None and old.shape != grid.shape

    @QtCore.Slot(object)
    def _on_returned(self, value) -> None:
        self._check_thread()
        run, result, err = value
        if run != self._run:
            return
        self._timer.stop()
        self._worker = None
        self._drawn = False
        if self._dropped:  # its grids are of no project shown now (_drop): another solve, or none
            self._dropped = False
            if self._restart_pending:
                self.start(edit=self._restart_as[0], cold=self._restart_as[1])
                return
            self.t_start, self.t_done = self._t_before  # (the status line's time: not of the solve dropped)
            self._set_state("idle")
            self.finished.emit(None)
            return
        self.t_done = time.perf_counter()
        if self._restart_pending:
            # an edit arrived while solving: keep this iterate as the warm start, go again
            if result is not None:
                for k, g in result.grids.items():
                    # only an iterate that was already on screen: one stopped right after its start
                    # is close to the algebraic grid, and the shown (A, G) pair stays the warm start
                    if k in result.initial and (k in self._smoothed or k not in self.doc.grids):
                        self.doc.grids[k] = g
                        self.doc.initial[k] = result.initial[k]
                self.doc.grids_changed.emit()
            self.start(edit=self._restart_as[0], cold=self._restart_as[1])
            return
        self.last_error = err
        if err is not None:
            self._dirty = False
            self.error.emit(err)
            self._set_state("idle")
            self.finished.emit(None)
            return
        self._flush(draw=False)  # its progress (the convergence history ends on it), not a frame
        if self._project.layout is not None and _stopped(result) and self.doc.final_of(self._project) is not None:
            # F5 on a finished lake grid, then Stop: that grid stays (a grid of a few sweeps "stopped before it
            # was finished" replaced it, or on a coarse level no grid was left: the user lost the one they had)
            self.stopped_coarse = not result.grids
            self.kept_grid = True
            self.doc.restore_final(self._project)
            self.last_result = result
            self._set_state("idle")
            self.finished.emit(result)
            return
        if self._project.layout is not None and not result.grids:
            self._stopped_coarse(result)
            return
        grids = dict(self.doc.grids)
        grids.update(result.grids)
        initial = dict(self.doc.initial)
        initial.update(result.initial)
        ready = {k for k, b in enumerate(self.doc.project.blocks) if b.ready}
        grids = {k: g for k, g in grids.items() if k in ready}
        mb = getattr(result, "multiblock", None)
        metrics = getattr(result, "metrics", None)
        initial = {k: g for k, g in initial.items() if k in ready}
        self.doc.set_grids(grids, initial, multiblock=mb, metrics=metrics, project=self._project)
        self.last_result = result
        for w in result.warnings:  # what meshcore warned about (e.g. dropped duplicate points)
            self.doc.report("warning", w)
        self._set_state("idle")
        self.finished.emit(result)

    def _stopped_coarse(self, result) -> None:
        """A lake solve stopped before its full level (``app.lake_solve`` returns no grid then): its coarse
        frames were kept as the final grids, neither stale nor greyed ("Grid 8×12 cells: converged" of a
        block of 16×24, measured and exported so).  Now the document holds no grid of the layout and draws
        the last coarse frames greyed; the status says so (F5 makes the grid)."""
        cells = {k: tuple(b.cells) for k, b in enumerate(self._project.layout.blocks)}
        # an earlier grid the coarse frames never replaced on screen (of another shape): what the user saw
        earlier = {k: g for k, g in self.doc.grids.items() if k not in self._smoothed}
        self.stopped_coarse = True
        last = self._latest.get(ALL_BLOCKS)
        levels = getattr(last, "levels", ())
        self.coarse_level = "cells " + levels[-1][1].removeprefix("cells ") if levels else ""
        self.coarse_drawn = any(g.cells != cells.get(k) for k, g in self.doc.grids.items() if k in self._smoothed)
        frames = {k: g for k, g in self.doc.grids.items() if k in self._smoothed and g.cells != cells.get(k)}
        # an earlier grid still on screen stays drawn (greyed) with the coarse frames of the other blocks
        self.doc.set_stopped_coarse(earlier | frames)
        self.last_result = result
        self._set_state("idle")
        self.finished.emit(result)

    @QtCore.Slot()
    def _on_finished(self) -> None:
        # fallback: a worker that ended without returning (aborted) must not leave us "running"
        if self._worker is not None and self.sender() is self._worker.signals:
            self._timer.stop()
            self._worker = None
            self._set_state("idle")
            self.finished.emit(None)

    @QtCore.Slot(object)
    def _on_errored(self, exc) -> None:
        self._check_thread()
        self._timer.stop()
        self._worker = None
        log.error("the solver worker failed", exc_info=exc)
        msg = f"solver failed: {exc}"
        self.last_error = msg
        self.error.emit(msg)
        self._set_state("idle")
        self.finished.emit(None)
