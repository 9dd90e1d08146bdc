"""Interaction tools: small state machines turning mouse input into commands.

A tool receives model coordinates from the canvas (``click``, ``double_click``,
``drag(phase, xy, start)``, ``hover``, ``key``) and returns True when it used
the event (otherwise the canvas pans/zooms).  Geometry is done by the tested
helpers in :mod:`app.geometry`; edits go through :class:`app.commands.Editor`.

Here: the base :class:`Tool` and the tools of blocks and the view (pan, draw, edit points, pick
corners, calibrate a background); the tools of a lake's block layout (draw a cut line, drag the
layout's handles) are in :mod:`app.layout_tools`.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from PySide6 import QtCore

from . import geometry as geo
from .commands import LAYOUT_HINT

__all__ = ["CalibrateTool", "CornersTool", "DrawTool", "EditTool", "PanTool", "Tool"]

SHIFT = QtCore.Qt.KeyboardModifier.ShiftModifier
CTRL = QtCore.Qt.KeyboardModifier.ControlModifier


class Tool:
    """Base tool: uses nothing, so the canvas pans and zooms."""

    name = "pan"
    label = "Pan"
    shortcut = "P"
    tip = "Pan (drag) and zoom (wheel) the view"

    def __init__(self, doc, editor, canvas, status: Callable[[str], None] = lambda s: None) -> None:
        self.doc = doc
        self.editor = editor
        self.canvas = canvas
        self.status = status

    def tol(self) -> float:
        return self.canvas.tolerance(8.0) if self.canvas is not None else 1e-2

    def activate(self) -> None:
        self.status(self.tip)

    def deactivate(self) -> None:
        if self.canvas is not None:
            self.canvas.rubber_line.setData([], [])
            self.canvas.rubber_box.hide()

    def click(self, xy, modifiers=None) -> bool:
        return False

    def double_click(self, xy, modifiers=None) -> bool:
        return False

    def right_click(self, xy) -> bool:
        return False

    def drag(self, phase: str, xy, start, modifiers=None) -> bool:
        return False

    def hover(self, xy) -> None:
        pass

    def key(self, key: int) -> bool:
        return False

    def delete(self) -> bool:
        """Del (Edit ▸ Delete): True when the tool deleted what it points at (else the selected points go)."""
        return False

    @property
    def dragging(self) -> bool:
        """True while a drag of this tool edits the project (the autosave waits for its end)."""
        return False

    @property
    def in_drag(self) -> bool:
        """True while a drag of this tool is on (the mouse button still down), edit or not (default: an
        editing drag, :attr:`dragging`)."""
        return self.dragging

    def cancel_drag(self) -> bool:
        """Ctrl+Z or Esc in the middle of a drag: the drag is cancelled — the project goes back to what it was
        when the drag began, with no step of it in the history (undo or redo) — and the rest of the
        mouse's drag does nothing.  True when there was a drag to cancel (the undo is spent on it)."""
        return False


class PanTool(Tool):
    pass


class DrawTool(Tool):
    """Click to add boundary points; double-click, Enter or a click on the first point closes the loop."""

    name = "draw"
    label = "Draw"
    shortcut = "D"
    tip = "Draw: click to add points · double-click, Enter or click the first point to close · drag to pan"

    def _ensure_open_block(self) -> None:
        b = self.doc.block
        if b.closed or b.boundary is not None:
            self.editor.add_block()

    def click(self, xy, modifiers=None) -> bool:
        self._ensure_open_block()
        b = self.doc.block
        if len(b.points) >= 3 and geo.nearest_point(b.points[:1], xy, self.tol()) == 0:
            self.editor.close_loop()
            self.finish()
            return True
        self.editor.add_point(xy)
        return True

    def double_click(self, xy, modifiers=None) -> bool:
        self.editor.close_loop()
        self.finish()
        return True

    def key(self, key: int) -> bool:
        if key in (QtCore.Qt.Key.Key_Return, QtCore.Qt.Key.Key_Enter):
            self.editor.close_loop()
            self.finish()
            return True
        return False

    on_closed = None  # callback: the window switches to the Corners tool

    def finish(self) -> None:
        if self.canvas is not None:
            self.canvas.rubber_line.setData([], [])
        if self.doc.block.closed:
            if self.on_closed is not None:
                self.on_closed()
            self.status("Loop closed: click the four corners SW → SE → NE → NW, or press A for automatic corners")

    def hover(self, xy) -> None:
        b = self.doc.block
        if self.canvas is None:
            return
        if b.closed or b.boundary is not None or len(b.points) == 0:
            self.canvas.rubber_line.setData([], [])
            return
        p = b.points[-1]
        self.canvas.rubber_line.setData([p[0], xy[0]], [p[1], xy[1]])


class EditTool(Tool):
    """Drag points (Shift: snap), click a segment to insert, box-select, Del deletes."""

    name = "edit"
    label = "Edit"
    shortcut = "E"
    tip = (
        "Edit: drag points (Shift snaps) · click a segment to insert · drag on empty space to box-select · Del deletes"
    )

    def __init__(self, *a, **kw) -> None:
        super().__init__(*a, **kw)
        self._drag = None  # (kind, data)

    def click(self, xy, modifiers=None) -> bool:
        b = self.doc.block
        if self.doc.project.layout is not None:  # not "Convert to loop", which refuses a layout's block
            self.status(LAYOUT_HINT)
            return True
        if b.boundary is not None:
            self.status("This block is given by four border polylines; use Block ▸ Convert to loop to edit points")
            return True
        k = geo.nearest_point(b.points, xy, self.tol())
        add = modifiers is not None and bool(modifiers & (SHIFT | CTRL))
        if k is not None:
            sel = set(self.doc.selection) ^ {k} if add else {k}
            self.doc.set_selection(sel)
            return True
        seg = geo.nearest_segment(b.points, xy, self.tol(), closed=b.closed)
        if seg is not None:
            kseg, _t, foot = seg
            self.editor.insert_point(kseg, foot)
            self.doc.set_selection({kseg + 1})
            return True
        self.doc.set_selection(())
        return True

    def drag(self, phase, xy, start, modifiers=None) -> bool:
        b = self.doc.block
        if phase == "start" and self.doc.project.layout is not None:  # no points to drag or box-select
            self.status(LAYOUT_HINT)
            return False
        if phase != "start" and self._drag is not None and self._drag[0] == "cancelled":
            if phase == "finish":  # the rest of a cancelled drag did nothing (it panned the view)
                self._drag = None
            return True
        moving = phase != "start" and self._drag is not None and self._drag[0] == "move"
        if moving and self.editor.stack.index() != self._drag[1]["index"]:
            # the history moved under the drag (an undo from the history dock): its points are not the
            # ones it began with; it stops here (it moved them by indices that were gone)
            self._drag = ("cancelled", None)
            self.status("The points changed under the drag (undo or redo): the drag stops here")
            return True
        if phase == "start":
            k = geo.nearest_point(b.points, start, self.tol()) if b.boundary is None else None
            if k is not None:
                sel = self.doc.selection if k in self.doc.selection else frozenset({k})
                self.doc.set_selection(sel)
                self._drag = (
                    "move",
                    {
                        "idx": sorted(sel),
                        "origin": np.array(b.points[sorted(sel)]),
                        "anchor": k,
                        "id": self.editor.new_drag_id(),
                        "start": start,
                        "index": self.editor.stack.index(),  # where the history is, the drag's step on top
                    },
                )
            else:
                self._drag = ("box", {"start": start})
        if self._drag is None:
            return False
        kind, d = self._drag
        if kind == "move":
            target = xy
            if modifiers is not None and bool(modifiers & SHIFT):
                target = geo.snap(xy, np.asarray(b.points), self.tol(), exclude=d["idx"])
            anchor_origin = d["origin"][d["idx"].index(d["anchor"])]
            new = d["origin"] + (np.asarray(target) - anchor_origin)
            self.editor.set_points(d["idx"], new, drag_id=d["id"])
            d["index"] = self.editor.stack.index()  # (its first step pushed one; the others merge into it)
        else:
            x0, y0 = d["start"]
            if self.canvas is not None:
                self.canvas.rubber_box.setRect(
                    QtCore.QRectF(min(x0, xy[0]), min(y0, xy[1]), abs(xy[0] - x0), abs(xy[1] - y0))
                )
                self.canvas.rubber_box.show()
            if phase == "finish":
                idx = geo.points_in_box(np.asarray(b.points), x0, y0, xy[0], xy[1])
                add = modifiers is not None and bool(modifiers & (SHIFT | CTRL))
                self.doc.set_selection(set(idx) | (set(self.doc.selection) if add else set()))
                if self.canvas is not None:
                    self.canvas.rubber_box.hide()
        if phase == "finish":
            self._drag = None
        return True

    @property
    def dragging(self) -> bool:
        return self._drag is not None and self._drag[0] == "move"

    @property
    def in_drag(self) -> bool:
        return self._drag is not None and self._drag[0] != "cancelled"

    def cancel_drag(self) -> bool:
        """Ctrl+Z or Esc in a drag of points: they go back where the drag took them from (its step undone and
        out of the history); a box selection is dropped."""
        if not self.in_drag:
            return False
        kind, d = self._drag
        self._drag = ("cancelled", None)
        if kind == "move":
            self.editor.drop_merged(("move", d["id"]))
        elif self.canvas is not None:
            self.canvas.rubber_box.hide()
        return True

    def key(self, key: int) -> bool:
        if key in (QtCore.Qt.Key.Key_Delete, QtCore.Qt.Key.Key_Backspace):
            self.editor.delete_points(self.doc.selection)
            return True
        return False


class CornersTool(Tool):
    """Click four points in order SW, SE, NE, NW (bottom/right/top/left follow)."""

    name = "corners"
    label = "Corners"
    shortcut = "C"
    tip = "Corners: click four boundary points in order SW → SE → NE → NW"

    def __init__(self, *a, **kw) -> None:
        super().__init__(*a, **kw)
        self.picked: list[int] = []

    def activate(self) -> None:
        self.picked = []
        super().activate()

    def click(self, xy, modifiers=None) -> bool:
        b = self.doc.block
        if self.doc.project.layout is not None:  # ("draw or import one first" of an imported, laid-out lake)
            self.status(LAYOUT_HINT)
            return True
        if not b.closed or b.boundary is not None:
            self.status("Corners need a closed loop of points: draw or import one first")
            return True
        k = geo.nearest_point(b.points, xy, self.tol())
        if k is None or k in self.picked:
            return True
        self.picked.append(k)
        self.doc.set_selection(self.picked)
        names = ("SW", "SE", "NE", "NW")
        if len(self.picked) == 4:
            self.editor.set_corners(tuple(self.picked))
            self.picked = []
            self.doc.set_selection(())
            self.status("Corners set: bottom = SW→SE, right = SE→NE, top = NW→NE, left = SW→NW")
        else:  # points are numbered from 1, like the rows of a point file
            self.status(f"Corner {names[len(self.picked) - 1]} = point {k + 1}; now click {names[len(self.picked)]}")
        return True


class CalibrateTool(Tool):
    """Pick two points on the background image; the window asks for their true coordinates."""

    name = "calibrate"
    label = "Calibrate"
    shortcut = ""
    tip = "Calibrate background: click two points whose coordinates you know"

    def __init__(self, *a, on_pair=None, **kw) -> None:
        super().__init__(*a, **kw)
        self.on_pair = on_pair
        self.picked: list[tuple[float, float]] = []

    def activate(self) -> None:
        self.picked = []
        super().activate()

    def click(self, xy, modifiers=None) -> bool:
        self.picked.append(tuple(xy))
        if len(self.picked) == 2:
            pair, self.picked = self.picked, []
            if self.on_pair is not None:
                self.on_pair(pair)
        else:
            self.status("Calibrate: now click the second point")
        return True
