"""Lake actions of the window: Auto layout in a worker thread, the layout settings, the import offer.

:class:`LakeController` computes :func:`app.lake.compute_layout` off the GUI thread (a
superqt function worker), then sets the layout by one undoable command
(:meth:`app.commands.Editor.set_lake`) and starts the grid.  Settings (cell size, regular)
are undoable edits of the project's :class:`~app.lake.Lake`.  After importing a branched
outline it offers Auto layout in a strip above the canvas (never shown with ``window.quiet``).
"""

from __future__ import annotations

import logging
import math
import threading
import time

import numpy as np
from PySide6 import QtCore, QtWidgets
from superqt.utils import create_worker

from meshcore import MeshcoreError
from meshcore.cellsize import SMALL_BLOCKS, finer_for_small_blocks, small_blocks_reason
from meshcore.errors import Stopped

from .lake import Lake, compute_layout
from .lake_solve import layout_topology
from .views.offer_bar import OfferBar

__all__ = ["EDIT_GAP_S", "LakeController"]

#: seconds between the starts of two layouts of a drag (the grid re-solves from each; see
#: LakeController.edit_layout): five a second, each left a few smoothed frames of the grid
EDIT_GAP_S = 0.2
#: Auto layout of more cells than this asks first (20 x the default 10 000): the layout and its grid
#: take minutes and much memory (a cell size of 20 m typed for 200: 3.7 million cells)
LARGE_LAYOUT = 200_000
#: milliseconds after a cell size is set before its layout is counted (LakeController.layout_count): a
#: size typed and laid out at once (Ctrl+L) is laid out once
COUNT_DELAY_MS = 400

log = logging.getLogger(__name__)


def _layout_job(lake: Lake, cuts=None, stop_event: threading.Event | None = None):
    """The worker body: the layout (of the cut lines drawn, if any), or the message of why there is none;
    None when ``stop_event`` stopped it (:func:`app.lake.compute_layout`)."""
    try:
        layout = compute_layout(lake, cuts, stop_event=stop_event)
        if stop_event is not None and stop_event.is_set():
            return None
        layout_topology(layout)
        return lake, layout, None
    except Stopped:
        return None
    except MeshcoreError as exc:
        return lake, None, str(exc)
    except Exception as exc:  # a bug must not kill the window: report it, log where it happened
        log.exception("the layout worker failed")
        return lake, None, f"internal error: {type(exc).__name__}: {exc} (the traceback is in the log)"


def _edit_job(make):
    """The worker body of a layout edit: ``(the new layout, None)``, or ``(None or the layout that
    stays instead, why there is no new one)``."""
    try:
        layout = make()
        layout_topology(layout)  # here, off the GUI thread: the solve that follows finds it ready
        return layout, None
    except MeshcoreError as exc:
        return getattr(exc, "layout", None), str(exc)  # (layout_edit.MoveRefused: the drag's last good one)
    except Exception as exc:  # a bug must not kill the window
        log.exception("a layout edit failed")
        return None, f"internal error: {type(exc).__name__}: {exc} (the traceback is in the log)"


class LakeController(QtCore.QObject):
    """Auto layout and the lake settings of a :class:`~app.main_window.MainWindow`."""

    layout_done = QtCore.Signal(object)  # the Layout, or None when it failed
    busy_changed = QtCore.Signal(bool)
    counted = QtCore.Signal()  # the layout of a cell size set but not laid out was counted (layout_count)
    ticked = QtCore.Signal(int)  # seconds a layout has been computing (each second)

    def __init__(self, window) -> None:
        super().__init__(window)
        self.win = window
        self.doc = window.doc
        self.editor = window.editor
        self._worker = None
        # while a layout is computed (20-30 s for a branched lake of 20 000 cells, the layout drawn at
        # three scales): the status line counts the seconds; a still "Computing…" read as a hang
        self._ticker = QtCore.QTimer(self)
        self._ticker.setInterval(1000)
        self._ticker.timeout.connect(self._tick)
        self._busy_text = ""
        self._busy_since = 0.0
        self.generate_after = True  # start the grid when a layout is set
        self.prompt: OfferBar | None = None  # the offer after importing a branched lake
        self._prompt_shore = None  # the shore the offer is for: another lake closes it (_other_lake)
        self.doc.project_changed.connect(self._other_lake)
        self.last_error: str | None = None
        self._edit_worker = None
        self._pending = None  # (make, text, merge key, shore) of the newest layout edit not yet computed
        # a drag's next layout starts EDIT_GAP_S after the last one started (it is made while the grid
        # re-solves from the last): each new layout restarts the grid's solve, which needs that long
        # to set up and redraw a few smoothed grids
        self._edit_timer = QtCore.QTimer(self)
        self._edit_timer.setSingleShot(True)
        self._edit_timer.timeout.connect(self._next_edit)
        self._edit_started = 0.0  # when the last layout edit was started
        self.edit_error: str | None = None
        self._dragging = False  # a drag of the layout is on (the layout tool says so)
        self._cancelled = None  # the merge key of the last drag cancelled (Ctrl+Z in it)
        # the layout changed by anything but an edit landing (an undo, a redo, Auto layout, an open) counts
        # up: an edit asked for before it is of a layout no longer shown and is not set (it was, over the
        # undo: Set cells then Ctrl+Z at once undid Auto layout, then set the layout again with the cells)
        self._generation = 0
        self._seen_layout = self.doc.project.layout
        self._applying = False  # an edit is landing (its own change of the layout)
        self.doc.project_changed.connect(self._layout_changed)
        # a cell size set and not laid out yet: the layout Auto layout would make is made in a worker and
        # the Lake panel gives its cells (it gave area / h²; the layout had 0.67-3.8 x that on lakes whose blocks
        # are a few cells across); Auto layout then takes that layout (or the count still running) as its own
        self._count: tuple | None = None  # (lake without layout, its layout or None, the error or None)
        self._count_worker = None
        self._count_lake: Lake | None = None  # the lake being counted
        # set when the lake being counted is no longer the one wanted (another cell size, an undo): the count
        # stops at its next check (it ran to its end: 3.8 s of a core on Shasta Lake at 26 m after
        # the size was typed twice more), and the count wanted starts when it has stopped (2 cores)
        self._count_stop = threading.Event()
        self._adopted = None  # the water Auto layout asked for, when it took over the running count
        self._count_timer = QtCore.QTimer(self)
        self._count_timer.setSingleShot(True)
        self._count_timer.setInterval(COUNT_DELAY_MS)
        self._count_timer.timeout.connect(self._count_now)
        self.doc.project_changed.connect(lambda _p: self._want_count())
        # Auto layout's own worker stops at its next check once this is set (Stop, Esc, the window
        # closed: on a big lake it ran on for seconds, and after the window); a worker taken over from the count
        # stops by the count's event
        self._stop = threading.Event()
        self._stopping = False  # Stop was asked of the running Auto layout: what it returns is not set
        self._busy_kind = "Auto layout"  # what is computed: "Auto layout", "the split by cut lines"
        self._stopped_lake: Lake | None = None  # the lake whose Auto layout was stopped: not counted again unasked

    @property
    def busy(self) -> bool:
        return self._worker is not None

    @property
    def stopping(self) -> bool:
        """Stop was asked of the layout being computed (it ends at its next check)."""
        return self._worker is not None and self._stopping

    def stop_layout(self) -> bool:
        """Stop (Esc) while Auto layout computes: the layout stops at its next check (between the stages of a
        draw and between draws, :mod:`meshcore.layout.stopping`; a coarse reading under way, at its next sweep)
        and nothing is set (a split by cut lines, a second or so, runs to its end and is not set); False when
        no layout is being computed."""
        if self._worker is None:
            return False
        if self._adopted is not None:  # the Lake panel's count, taken over
            self._count_stop.set()
        else:
            self._stop.set()
        self._stopping = True  # (a layout it returns all the same, made before the stop was seen, is not set)
        self._busy_text = f"Stopping {self._busy_kind}…"
        self.win.message(self._busy_text)
        self.ticked.emit(int(time.monotonic() - self._busy_since))
        return True

    # ------------------------------------------------------------ the lake
    def lake(self) -> Lake | None:
        """The lake to lay out: the project's, with the shore as edited (the active loop), or the loop."""
        p = self.doc.project
        if p.lake is not None and p.layout is not None:
            return p.lake
        b = self.doc.block
        loop = b.points if b.closed and b.boundary is None and len(b.points) >= 3 else None
        if p.lake is not None:
            return p.lake if loop is None or len(p.blocks) > 1 else p.lake.replaced(outline=loop)
        return None if loop is None else Lake(outline=loop)

    # ---------------------------------------------------------- settings
    def set_cell_size(self, h: float | None) -> None:
        """The wanted cell size (None: about 10 000 cells), an undoable edit."""
        lake = self.lake()
        if lake is None:
            self.win.message("Import or draw a lake outline first")
            return
        h = None if h is None or h <= 0 else float(h)
        if h != lake.cell_size:
            self.editor.set_lake(lake.replaced(cell_size=h), "Set cell size", merge_key=("lake", "h"))

    def set_regular(self, on: bool) -> None:
        lake = self.lake()
        if lake is not None and bool(on) != lake.regular:
            kw = {"regular": True} if on else {"regular": False, "single": False}
            self.editor.set_lake(lake.replaced(**kw), "Regular layout" if on else "Any layout")

    # ------------------------------------------------------- auto layout
    def auto_layout(self, *, regular: bool | None = None, single: bool | None = None) -> bool:
        """Compute the layout of the lake in a worker; it is set (undoable) and gridded when done
        (``single``: a regular layout whose rings round islands close in one index space)."""
        lake = self.lake()
        if lake is None:
            self.win.message("Auto layout needs a lake: import an outline (Ctrl+I) or draw and close a loop")
            return False
        if regular is not None:
            lake = lake.replaced(regular=bool(regular), single=False)  # Delft3D DD: any multiple of 4 turns
        if single is not None:
            lake = lake.replaced(single=bool(single), regular=bool(single) or lake.regular)
        if not self._large_ok(lake):
            return False
        kind = "regular layout (no 3- or 5-block corners)" if lake.regular else "layout"
        if lake.single:
            kind = "layout for one index space (Delft3D single domain, EFDC)"
        return self._start(lake, None, f"Computing the block {kind} of the lake…")

    def _large_ok(self, lake: Lake) -> bool:
        """True unless the layout would have over :data:`LARGE_LAYOUT` cells and the user says no (no dialog
        when quiet: refused, said in the status line)."""
        from .lake import expected_cells

        n = expected_cells(lake)
        if n <= LARGE_LAYOUT:
            return True
        text = (
            f"About {n:,} cells at {lake.cell_size:.4g} m ({n / 10_000:.0f}× the default): the layout and its grid "
            "take minutes and much memory."
        )
        if not self.win.quiet:
            ask = QtWidgets.QMessageBox.question(
                self.win,
                "Auto layout",
                f"{text}\n\nLay out the lake at this cell size?",
                QtWidgets.QMessageBox.StandardButton.Yes | QtWidgets.QMessageBox.StandardButton.No,
                QtWidgets.QMessageBox.StandardButton.No,
            )
            if ask == QtWidgets.QMessageBox.StandardButton.Yes:
                return True
        self.win.message(f"Auto layout not started: {text} Set a larger cell size in the Lake panel.")
        return False

    def split_by_cuts(self, cuts) -> bool:
        """Blocks between the cut lines drawn by hand, in any topology (worker; set undoable, then gridded).

        Cuts may end on the shore, on an island or on another cut (a T), meet at a point, or
        bound a region on any number of sides; each region gets four corners where it turns and
        cell counts that agree across every cut (:func:`meshcore.layout.layout_from_cuts`).  A
        region that cannot be four-sided is a message naming it.
        """
        lake = self.lake()
        if lake is None:
            self.win.message("Splitting a lake needs its outline: import it (Ctrl+I) or draw and close a loop")
            return False
        n = len(cuts)
        return self._start(lake, tuple(cuts), f"Splitting the lake by {n} cut line{'s' * (n != 1)}…")

    def _start(self, lake: Lake, cuts, text: str) -> bool:
        if self.busy:
            return False
        self._stopping, self._stopped_lake = False, None
        self._busy_kind = "Auto layout" if cuts is None else "the split by cut lines"
        self.close_prompt()
        self.win.solver.stop()
        self.last_error = None
        p = self.doc.project
        water = (lake.outline, lake.holes, p.crs, tuple(p.origin))  # what the layout is of (_same_water)
        if cuts is None and self._take_count(lake, water, text):
            return True
        self._stop = threading.Event()
        worker = create_worker(_layout_job, lake.replaced(layout=None), cuts, self._stop, _start_thread=False)
        worker.returned.connect(lambda value: self._on_returned(value, cuts, water))
        worker.errored.connect(self._on_errored)
        self._worker = worker
        self.busy_changed.emit(True)
        self.win.message(text)
        self._busy_text, self._busy_since = text, time.monotonic()
        self._ticker.start()
        worker.start()
        return True

    def _take_count(self, lake: Lake, water, text: str) -> bool:
        """Auto layout of ``lake`` takes the layout counted for the Lake panel (made already: set at once;
        being made: its worker becomes Auto layout's).  False when there is none of this lake."""
        bare = lake.replaced(layout=None)
        done = self._count
        if done is not None and done[0] == bare:
            self._count = None  # a layout is set once (its held coarse readings are its grid's start)
            self.win.message(text)
            self._on_returned(done, None, water)
            return True
        if self._count_worker is None or self._count_lake != bare or self._count_stop.is_set():
            return False
        self._adopted, self._worker = water, self._count_worker
        self.busy_changed.emit(True)
        self.win.message(text)
        self._busy_text, self._busy_since = text, time.monotonic()
        self._ticker.start()
        return True

    # ------------------------------------------------- the panel's count
    def count_wanted(self) -> Lake | None:
        """The lake (without layout) whose layout the Lake panel counts: a cell size set and not laid out
        yet, of at most :data:`LARGE_LAYOUT` cells by area; else None."""
        from meshcore.cli.mesh_steps import MIN_CELLS

        from .lake import expected_cells

        lake = self.lake()
        if lake is None or lake.cell_size is None:
            return None
        lay = self.doc.project.layout
        if lay is not None and math.isclose(lake.cell_size, lay.cell_size, rel_tol=1e-6):
            return None
        if not MIN_CELLS <= expected_cells(lake) <= LARGE_LAYOUT:  # refused, or asked about first
            return None
        return lake.replaced(layout=None)

    def layout_count(self, lake: Lake) -> tuple[int, int] | str | None:
        """``(cells, blocks)`` of the layout Auto layout makes of ``lake`` at its cell size (made in a
        worker when the size was set), the reason it makes none, or None when not counted (yet)."""
        done, bare = self._count, lake.replaced(layout=None)
        if done is None or done[0] != bare:
            return None
        return (done[1].n_cells, len(done[1].blocks)) if done[1] is not None else str(done[2])

    def counting(self, lake: Lake) -> bool:
        """True while the layout of ``lake`` is being counted (or about to be: the size just set, or a count
        no longer wanted still stopping)."""
        bare = lake.replaced(layout=None)
        if self._count_lake == bare and not self._count_stop.is_set():
            return True
        waits = self._count_timer.isActive() or (self._count_worker is not None and self._count_stop.is_set())
        return waits and self.count_wanted() == bare

    def _want_count(self) -> None:
        lake = self.count_wanted()
        if lake is not None and lake == self._stopped_lake:  # its Auto layout was stopped: not made again unasked
            lake = None
        if self._count_worker is not None and self._adopted is None and self._count_lake != lake:
            self._count_stop.set()  # stale: it stops at its next check, then the one wanted starts
        if lake is None or self.layout_count(lake) is not None:
            return
        if self._count_lake == lake and not self._count_stop.is_set():
            return
        self._count_timer.start()  # (again: the last size typed is counted)

    def _count_now(self) -> None:
        lake = self.count_wanted()
        if lake is None or self.busy or self._count_worker is not None or self.layout_count(lake) is not None:
            return  # (a count running: the next is started when it ends)
        self._count_stop = threading.Event()
        worker = create_worker(_layout_job, lake, None, self._count_stop, _start_thread=False)
        worker.returned.connect(self._counted)
        worker.errored.connect(self._count_errored)
        self._count_worker, self._count_lake = worker, lake
        worker.start()

    def stop_count(self) -> None:
        """The window closes: a count being made stops at its next check (the close waits for the
        workers: it waited 2 s for a count of Shasta Lake at 26 m, then the process 6 s more, and the count's
        worker, ending after the window, printed a traceback); Auto layout's too."""
        self._count_timer.stop()
        if self._count_worker is not None:
            self._count_stop.set()
        self._stop.set()

    def _counted(self, value) -> None:
        self._count_worker, self._count_lake = None, None
        if value is None and self._adopted is not None:  # Auto layout took it over, then was stopped
            self._adopted = None
            self._on_returned(None)
            return
        if value is None:  # stopped (stale): the count wanted now, if any
            self._want_count()
            return
        if self._adopted is not None:  # Auto layout took it over
            water, self._adopted = self._adopted, None
            self._on_returned(value, None, water)
            return
        self._count = value
        self.counted.emit()
        self._want_count()

    def _count_errored(self, exc) -> None:
        self._count_worker, self._count_lake = None, None
        if self._adopted is not None:
            self._adopted = None
            self._on_errored(exc)
            return
        log.error("the count of a layout failed", exc_info=exc)

    def _tick(self) -> None:
        """The seconds the layout has taken so far, in the status line and the Auto layout button."""
        if self._worker is None:
            self._ticker.stop()
            return
        k = int(time.monotonic() - self._busy_since)
        self.win.message(f"{self._busy_text} {k} s")
        self.ticked.emit(k)

    def _same_water(self, water) -> bool:
        """The project's lake is still the water (shore, islands, frame) a layout was asked for."""
        now = self.lake()
        if water is None or now is None:
            return water is None
        outline, holes, crs, origin = water
        p = self.doc.project
        return (
            (p.crs, tuple(p.origin)) == (crs, origin)
            and np.array_equal(now.outline, outline)
            and len(now.holes) == len(holes)
            and all(np.array_equal(a, b) for a, b in zip(now.holes, holes, strict=True))
        )

    def _on_returned(self, value, cuts=None, water=None) -> None:
        self._worker = None
        self._ticker.stop()
        self.busy_changed.emit(False)
        stopped, self._stopping = self._stopping, False
        if value is None or stopped:  # stopped (stop_layout): the document as it was
            self._stopped_lake = self.count_wanted()  # (its count would make the layout again, unasked)
            again = " (Ctrl+L lays it out)" if self._busy_kind == "Auto layout" else ""
            kind = self._busy_kind[0].upper() + self._busy_kind[1:]
            self.win.message(f"{kind} stopped: the lake is as it was{again}")
            self.layout_done.emit(None)
            return
        lake, layout, err = value
        if layout is not None and not self._same_water(water):
            # another lake imported (or opened, or the shore edited) while it was made: it was set, the first
            # lake's outline and blocks in the second's frame under the second's name
            self.win.message(
                "The layout made is not set: the lake changed (another lake, or the shore edited) while it was "
                "made — Auto layout (Ctrl+L) lays out this one",
                error=True,
            )
            self.layout_done.emit(None)
            return
        if layout is None:
            self.last_error = err
            self.win.error("Cannot split the lake by its cut lines" if cuts else "Cannot lay out the lake", err)
            self.layout_done.emit(None)
            return
        n = len(layout.blocks)
        if cuts:  # the drawn cut lines become the layout's: one undo step brings them back
            from .lake import with_layout

            after = with_layout(self.doc.project, lake.replaced(layout=layout)).replaced(cut_lines=())
            self.editor.replace_project(after, f"Split into {n} blocks by cut lines")
        else:
            self.editor.set_lake(lake.replaced(layout=layout), "Auto layout")
        for note in layout.notes:  # what meshcore mesh prints as notes (the Lake panel counts them)
            self.doc.report("info", f"layout: {note}")
        for note in layout.details:  # each island a note above sums up
            self.doc.report("info", f"layout (detail): {note}")
        finer = finer_for_small_blocks(n, layout.n_cells, layout.cell_size)
        if finer is not None:  # (meshcore mesh says it too, in --cells)
            self.doc.report(
                "info",
                f"layout: {small_blocks_reason(n, layout.n_cells)}; a cell size of {finer[1]:.4g} m (about "
                f"{finer[0]:,} cells) gives each block about {SMALL_BLOCKS}",
            )
        kind = " for one index space" if layout.single else ""
        self.win.message(
            f"Layout{kind}: {n} block{'s' * (n != 1)}, {layout.n_cells:,} cells at {layout.cell_size:.4g} m — "
            "generating the orthogonal grid (Ctrl+Z undoes the layout)"
        )
        self.layout_done.emit(layout)
        self.win.set_tool("layout")
        self.win.show_lake()  # its blocks, cells and cell size (Parameters stayed in front: ξ, η of a block it locks)
        if self.generate_after:  # a new layout's grid, coarse to fine as meshcore mesh makes it
            self.win.generate(cold=True)

    def _on_errored(self, exc) -> None:
        self._worker = None
        self._ticker.stop()
        self.busy_changed.emit(False)
        log.error("the layout worker failed", exc_info=exc)
        self.last_error = str(exc)
        self.win.error("Cannot lay out the lake", exc)
        self.layout_done.emit(None)

    # ------------------------------------------------------ layout edits
    def edit_layout(self, make, text: str, merge_key=None, *, shore: bool = False) -> None:
        """Make a new layout with ``make()`` in a worker and set it (undoable); the newest request wins.

        ``make`` builds the layout from immutable inputs (e.g. the parts of the layout at the
        start of a drag with one point moved); while one is computed, later requests replace
        each other and only the last one runs next.  Each result is shown when it arrives (a
        drag's steps merge into one undo step by ``merge_key``); a refusal is reported only
        when no newer request waits.  ``shore``: the edit moves the shore (the lake's outline
        and islands become those of the new layout).
        """
        self._pending = (make, text, merge_key, shore, self._generation)
        if self._edit_worker is None:
            self._next_edit()

    def _layout_changed(self, project) -> None:
        if project.layout is self._seen_layout:
            return
        self._seen_layout = project.layout
        if not self._applying:
            self._generation += 1

    def _next_edit(self) -> None:
        if self._pending is None or self._edit_worker is not None:
            return
        make, text, key, shore, gen = self._pending
        if gen != self._generation:  # of a layout undone (or replaced) since it was asked for
            self._pending = None
            self._dropped(text, key)
            return
        wait = self._edit_started + EDIT_GAP_S - time.perf_counter()
        if key is not None and wait > 0:  # a drag's step: later (the newest step then)
            if not self._edit_timer.isActive():
                self._edit_timer.start(max(1, int(1000 * wait)))
            return
        self._pending = None
        worker = create_worker(_edit_job, make, _start_thread=False)
        worker.returned.connect(lambda value, text=text, key=key: self._edited(value, text, key, shore, gen))
        worker.errored.connect(lambda exc: self._edited((None, f"internal error: {exc}"), text, key, shore, gen))
        self._edit_worker = worker
        self._edit_started = time.perf_counter()
        worker.start()

    def _dropped(self, text: str, key=None) -> None:
        """An edit of a layout changed since it was asked for is not set: said, once nothing else waits
        (not for a step of a drag cancelled: the cancel said it)."""
        if self._pending is None and (key is None or key != self._cancelled):
            self.win.message(f"{text}: not made — the layout changed (an undo or another layout) before it was done")
        self._end_live()

    @property
    def generation(self) -> int:
        """Counts the changes of the project's layout by anything but a layout edit landing (an undo, a
        redo, Auto layout, an open): a drag begun before one is of a layout no longer shown."""
        return self._generation

    def cancel_drag(self, key) -> None:
        """Ctrl+Z or Esc in a drag of the layout (steps merged under ``key``): the step it made is undone and leaves
        the history, its steps asked for or being made are dropped (they were set after the undo: the
        dragged layout came back over it), and the grid goes to the end from the layout before the drag."""
        self._cancelled = key
        if self._pending is not None and self._pending[2] == key:
            self._pending = None
        self._generation += 1  # a step in the worker now is of the layout the drag made: dropped when done
        self.editor.drop_merged(key)
        self._dragging = False
        self._end_live()

    def _edited(self, value, text: str, key, shore: bool = False, gen: int | None = None) -> None:
        self._edit_worker = None
        if gen is not None and gen != self._generation:  # the layout it was made from is gone (undone)
            self._dropped(text, key)
            self._next_edit()
            return
        layout, err = value
        lake = self.doc.project.lake
        if layout is not None and lake is not None:  # newer than what is shown: show it, even mid-drag
            self.edit_error = None
            if shore:  # the lake's shore is the layout's now (Clear layout keeps the edit)
                poly = layout.polygon
                rings = tuple(np.asarray(r.coords)[:-1] for r in poly.interiors)
                lake = lake.replaced(outline=np.asarray(poly.exterior.coords)[:-1], holes=rings)
            self._applying = True
            try:
                self.editor.set_lake(lake.replaced(layout=layout), text, merge_key=key)
            finally:
                self._applying = False
            self.layout_done.emit(layout)
            # one edit (a cut deleted, a block's cells), or a drag's last layout: the status line says the
            # new layout (after a drag it went on showing the grid of before's cell count)
            if key is None or (not self._dragging and self._pending is None):
                n = len(layout.blocks)
                self.win.message(f"{text}: {n} block{'s' * (n != 1)}, {layout.n_cells:,} cells (Ctrl+Z undoes it)")
        if err is not None and self._pending is None:  # a refusal only counts for the last request
            self.edit_error = err
            if self._dragging and key is not None:
                # a step of a drag still on: the status line says why not here; Messages get the refusal
                # only if the drag ends there (one drag over a bay put six errors in Messages, red)
                self.win.message(f"Not here: {err} — the layout of the last good place stays")
            else:
                self.win.message(f"Cannot change the layout: {err}", error=True)
            if layout is None:
                self.layout_done.emit(None)
        self._next_edit()
        self._end_live()  # the drag's last layout is shown (or refused): its grid goes to the end

    def begin_drag(self) -> None:
        """A drag of the layout begins: until it ends, the grid's solves stop after their live frames."""
        self._dragging = True
        self.win.solver.set_live(True)

    def end_drag(self) -> None:
        """The drag ends: the grid of its last layout is made to the end (once that layout is shown)."""
        self._dragging = False
        self._end_live()

    def _end_live(self) -> None:
        if not self._dragging and not self.editing:
            self.win.solver.set_live(False)

    def set_block_cells(self, index: int, cells: tuple[int, int]) -> None:
        """Give block ``index`` of the layout ``cells``; the blocks sharing its sides follow (undoable)."""
        lay = self.doc.project.layout
        if lay is None or not 0 <= index < len(lay.blocks):
            return
        name = lay.blocks[index].name
        cells = (int(cells[0]), int(cells[1]))
        if cells == tuple(lay.blocks[index].cells):
            return

        def make():
            from meshcore.errors import TopologyError
            from meshcore.layout import with_cells

            out = with_cells(lay, name, cells)
            try:
                out.topology()
            except TopologyError as exc:  # the counts agree on the blocks' pieces but not on the case's borders
                raise TopologyError(f"block {name} cannot have {cells[0]}×{cells[1]} cells: {exc}") from None
            return out

        self.edit_layout(make, f"Cells of {name}: {cells[0]}×{cells[1]}")

    @property
    def editing(self) -> bool:
        """True while a layout edit is being computed or waits to be."""
        return self._edit_worker is not None or self._pending is not None

    # ------------------------------------------------------------- offer
    def offer(self, name: str, why: str | None) -> None:
        """After importing a lake: say why one block is poor, offer Auto layout (non-modal).
        ``why``: what makes one block poor (islands, arms); None: a compact lake outline, whose one
        block with automatic corners is still far from a model grid."""
        if why is None:
            text = (
                f"{name}: a lake outline. One block with automatic corners is far from a model grid "
                "(cells well off orthogonal); Auto layout lays the lake out in blocks, as meshcore mesh does."
            )
        else:
            text = f"{name}: {why}. One block would give a poor grid; Auto layout splits the lake into blocks."
        self.doc.report("info", text)
        # what the message says is poor about one block (it was "A branched lake" over "6 island(s)")
        if why is None:
            title = "A lake outline"
        else:
            title = "Islands in the lake" if "island" in why and "arm" not in why else "A branched lake"
        # a strip above the canvas (a message box in the middle of the window covered the lake it is about)
        bar = OfferBar(title, f"{text} (Ctrl+L; Esc: not now)", self.win)
        go = bar.addButton("Auto layout")
        bar.addButton("Not now").clicked.connect(self.close_prompt)
        go.clicked.connect(lambda: self.auto_layout())
        self.close_prompt()
        self.prompt = bar
        lake = self.doc.project.lake
        self._prompt_shore = lake.outline if lake is not None else None
        if getattr(self.win, "quiet", False):
            bar.hide()
        else:
            self.win.place_offer(bar)

    def _other_lake(self, project) -> None:
        """Another lake (File ▸ New, Open, an import not offered, its undo): the offer goes with its
        lake (it stayed open, and its button laid out whatever lake was there then)."""
        if self.prompt is None:
            return
        shore = project.lake.outline if project.lake is not None else None
        if shore is None or self._prompt_shore is None or not np.array_equal(shore, self._prompt_shore):
            self.close_prompt()

    def close_prompt(self) -> None:
        if self.prompt is not None:
            focus = QtWidgets.QApplication.focusWidget()
            if focus is not None and self.prompt.isAncestorOf(focus):  # the keys go back to the canvas
                self.win.canvas.setFocus()
            self.prompt.close()
            self.prompt.deleteLater()
            self.prompt = None
