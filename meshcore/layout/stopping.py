"""A stop asked of :func:`~meshcore.layout.auto_layout` while it draws, heard between its stages.

A large lake's layout takes seconds before anything a caller can watch (Vänern at 10 000 cells: five
draws of about a second each before the first coarse reading of the layout choice): the app's Stop was
heard only there.  :func:`stoppable` (one :func:`~meshcore.layout.auto_layout` call, as
:func:`.memo.remembering`) holds the caller's stop event; :func:`check`, called between the stages of
a draw (the skeleton and chords, each region's split, the corners, the counts) and between draws, ends
the layout with :class:`~meshcore.errors.Stopped` once it is set.
"""

from __future__ import annotations

import contextlib
import contextvars
from collections.abc import Callable
from typing import Any

from ..errors import Stopped

__all__ = ["check", "stoppable"]

_asked: contextvars.ContextVar[Callable[[], bool] | None] = contextvars.ContextVar("layout_stop", default=None)


@contextlib.contextmanager
def stoppable(stop_event: Any):
    """Within this context :func:`check` raises :class:`~meshcore.errors.Stopped` once ``stop_event``
    (a :class:`threading.Event`, or anything with ``is_set()``; None: never) is set."""
    token = _asked.set(None if stop_event is None else stop_event.is_set)
    try:
        yield
    finally:
        _asked.reset(token)


def check() -> None:
    """Raise :class:`~meshcore.errors.Stopped` when the stop event of the :func:`stoppable` around is set."""
    asked = _asked.get()
    if asked is not None and asked():
        raise Stopped("the layout was stopped")
