"""Measures a large grid's quality in a worker thread (the document's :attr:`~app.document.Document.measure_async`).

The quality report of a single block of 1.75 million cells (and a lake's metrics with the coverage of
the water) takes seconds; measured in the GUI thread after the solve it froze the window that long.
:class:`Measurer` runs one measure at a time in a superqt worker and hands its value back in the GUI
thread; a measure asked for while one runs waits, and only the latest one waiting is run (the document
takes a value only while no newer grid came: the ones in between would be thrown away).
"""

from __future__ import annotations

import logging
from collections.abc import Callable

from PySide6 import QtCore
from superqt.utils import create_worker

__all__ = ["Measurer"]

log = logging.getLogger(__name__)


def _run(job: Callable[[], object]) -> object:
    return job()


class Measurer(QtCore.QObject):
    """``measurer(job, done)``: ``job()`` in a worker, then ``done(value)`` in the GUI thread (``None`` if
    the job raised: logged).  A job asked for while another runs replaces any job still waiting."""

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self._worker = None
        self._next: tuple[Callable[[], object], Callable[[object], None]] | None = None
        self.runs = 0  # jobs run (tests)

    @property
    def busy(self) -> bool:
        return self._worker is not None or self._next is not None

    def __call__(self, job: Callable[[], object], done: Callable[[object], None]) -> None:
        if self._worker is not None:
            _job, skipped = self._next or (None, None)
            self._next = (job, done)
            if skipped is not None:  # never run: its caller hears that it got nothing
                skipped(None)
            return
        self._start(job, done)

    def _start(self, job: Callable[[], object], done: Callable[[object], None]) -> None:
        self.runs += 1
        worker = create_worker(_run, job, _start_thread=False, _ignore_errors=True)  # errors: logged below
        result: list = [None]
        worker.returned.connect(lambda value: result.__setitem__(0, value))
        worker.errored.connect(lambda exc: log.error("measuring the grid failed", exc_info=exc))
        worker.finished.connect(lambda: self._finished(worker, done, result[0]))
        self._worker = worker
        worker.start()

    def _finished(self, worker, done: Callable[[object], None], value: object) -> None:
        if worker is not self._worker:
            return
        self._worker = None
        waiting, self._next = self._next, None
        done(value)
        if waiting is not None and self._worker is None:
            self._start(*waiting)

    def wait(self, timeout_s: float = 60.0) -> bool:
        """Process events until no measure runs or waits (scripts, tests); True when none does."""
        import time

        app = QtCore.QCoreApplication.instance()
        t0 = time.perf_counter()
        while self.busy:
            app.processEvents(QtCore.QEventLoop.ProcessEventsFlag.AllEvents, 10)
            if time.perf_counter() - t0 > timeout_s:
                return False
        return True
