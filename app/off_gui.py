"""A step of a GUI action computed in a thread of its own while the window keeps drawing.

:func:`off_gui` runs a pure function (no Qt: reading a file, projecting it, the corners and cells of a
block) in a new thread and runs the GUI thread's event loop until it returns: the window repaints,
timers and the other workers' signals go on, the user's input (mouse, keys, shortcuts, drops, closing
the window) waits behind a busy cursor.  The caller gets the result, or the function's exception, as
from a plain call: an action with dialogs between its steps (File ▸ Import asks about lon/lat and
the part of water) keeps its order, one step at a time off the GUI thread.

A thread of its own, not the pool of the solver and layout workers: the pool's two threads may both
be busy (a solve and a measure), and an import would wait for them.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import Any, TypeVar

from PySide6 import QtCore, QtGui, QtWidgets

__all__ = ["HELD", "off_gui"]

T = TypeVar("T")

_E = QtCore.QEvent.Type
#: the user's input held back while a step runs off the GUI thread
HELD = frozenset(
    {
        _E.MouseButtonPress,
        _E.MouseButtonRelease,
        _E.MouseButtonDblClick,
        _E.Wheel,
        _E.KeyPress,
        _E.KeyRelease,
        _E.Shortcut,
        _E.ShortcutOverride,
        _E.DragEnter,
        _E.DragMove,
        _E.Drop,
        _E.Close,
        _E.ContextMenu,
    }
)


class _Hold(QtCore.QObject):
    """An application event filter that drops the user's input (a window's close is refused).  A modal
    dialog opened meanwhile (an error of another worker) gets its input: it blocks the window's anyway,
    and held it would never close."""

    def eventFilter(self, obj: QtCore.QObject, ev: QtCore.QEvent) -> bool:
        if ev.type() not in HELD or QtWidgets.QApplication.activeModalWidget() is not None:
            return False
        if ev.type() == _E.Close and not (isinstance(obj, QtWidgets.QWidget) and obj.isWindow()):
            return False  # a part of the window closed by the program (an offer bar), not the user
        ev.ignore()
        return True


class _Done(QtCore.QObject):
    done = QtCore.Signal()


def off_gui(fn: Callable[..., T], *args: Any, **kwargs: Any) -> T:
    """``fn(*args, **kwargs)`` in a thread of its own, the GUI thread's events processed meanwhile
    (input held); its result, or its exception raised here.  Called outside the GUI thread, or
    without an application: a plain call."""
    app = QtCore.QCoreApplication.instance()
    if app is None or QtCore.QThread.currentThread() is not app.thread():
        return fn(*args, **kwargs)
    box: dict[str, Any] = {}
    loop = QtCore.QEventLoop()
    done = _Done()
    done.done.connect(loop.quit, QtCore.Qt.ConnectionType.QueuedConnection)

    def body() -> None:
        try:
            box["value"] = fn(*args, **kwargs)
        except BaseException as exc:  # (raised again in the GUI thread)
            box["error"] = exc
        finally:
            box["done"] = True
            done.done.emit()

    hold = _Hold()
    app.installEventFilter(hold)
    busy = isinstance(app, QtGui.QGuiApplication)
    if busy:
        QtWidgets.QApplication.setOverrideCursor(QtCore.Qt.CursorShape.WaitCursor)
    thread = threading.Thread(target=body, name="gcmesh-off-gui", daemon=True)
    try:
        thread.start()
        if not box.get("done"):  # (a quit posted before exec is delivered inside it)
            loop.exec()
        thread.join()
    finally:
        if busy:
            QtWidgets.QApplication.restoreOverrideCursor()
        app.removeEventFilter(hold)
    if "error" in box:
        raise box["error"]
    return box["value"]
