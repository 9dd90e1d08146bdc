"""Tools of a lake's block layout: draw a cut line (:class:`CutTool`), drag the layout's cut
ends, junctions, corners and shore points (:class:`LayoutTool`).

Small state machines as in :mod:`app.tools` (their base :class:`~app.tools.Tool`); the layout
edits go through the window's :class:`~app.lake_controller.LakeController` (computed off the GUI
thread, one undo step each) and the geometry through :mod:`app.layout_edit`.
"""

from __future__ import annotations

import numpy as np
from PySide6 import QtCore

from .tools import Tool

__all__ = ["CutTool", "LayoutTool"]


class CutTool(Tool):
    """Draw a cut polyline across a region (multiblock); double-click/Enter finishes it."""

    name = "cut"
    label = "Cut line"
    shortcut = "L"
    tip = (
        "Cut line: click a polyline from shore to shore, double-click or Enter to finish; "
        "then Block ▸ Split into blocks by cut lines (Ctrl+K) — over a lake's layout it parts the blocks it crosses"
    )

    def __init__(self, *a, **kw) -> None:
        super().__init__(*a, **kw)
        self.points: list[tuple[float, float]] = []

    def click(self, xy, modifiers=None) -> bool:
        self.points.append(tuple(xy))
        self._show()
        return True

    def double_click(self, xy, modifiers=None) -> bool:
        self._finish()
        return True

    def key(self, key: int) -> bool:
        if key in (QtCore.Qt.Key.Key_Return, QtCore.Qt.Key.Key_Enter):
            self._finish()
            return True
        if key == QtCore.Qt.Key.Key_Escape:
            self.points = []
            self._show()
            return True
        return False

    controller = None  # the window's LakeController: a cut drawn over a lake's layout goes into it

    def _finish(self) -> None:
        if len(self.points) >= 2:
            lay = self.doc.project.layout
            if lay is not None and self.controller is not None:  # it was refused ("change it in the Lake panel")
                from .block_names import names_kept
                from .layout_edit import with_drawn_cut

                # an end a user meant to put on a cut end, corner or tip lands a cell or two off: it
                # goes onto it (else a thin wedge block); the Messages say where, one undo step as before
                cut, report = np.array(self.points), self.doc.report
                self.controller.edit_layout(lambda: names_kept(lay, with_drawn_cut(lay, cut, report)), "Add cut line")
            else:
                self.editor.add_cut_line(np.array(self.points))
        self.points = []
        self._show()

    def _show(self, extra=None) -> None:
        if self.canvas is None:
            return
        pts = self.points + ([extra] if extra is not None and self.points else [])
        if pts:
            a = np.array(pts)
            self.canvas.rubber_line.setData(a[:, 0], a[:, 1])
        else:
            self.canvas.rubber_line.setData([], [])

    def hover(self, xy) -> None:
        if self.points:
            self._show(tuple(xy))


class LayoutTool(Tool):
    """Drag the lake layout's handles: cut ends along the shore, junctions and cut points, block corners."""

    name = "layout"
    label = "Layout"
    shortcut = "Y"
    tip = (
        "Layout: drag a cut line's end along the shore, a cut's point, a junction, a block corner or a shore point; "
        "the layout follows (its cells kept; at the end, a block stretched by over a fifth gets new ones) and, "
        "with auto-generate, the grid; Del deletes the cut line pointed at"
    )
    controller = None  # the window's LakeController (it computes new layouts off the GUI thread)

    def __init__(self, *a, **kw) -> None:
        super().__init__(*a, **kw)
        self._handle = None
        self._base = None
        self._parts: dict | None = None
        self._drag = None
        self._steps = None  # what the steps of the drag share (layout_edit.DragSteps)
        self._last_xy = None  # where the drag's last step went (None: no step yet)
        self._cache: tuple | None = None  # (layout, its handles)
        self._hovered: tuple | None = None  # (layout, the handle ringed under the cursor)
        self._hover_xy: tuple | None = None  # (layout, where the cursor was over it)
        self._cancelled = False  # the drag was cancelled (Ctrl+Z): the rest of the mouse's drag does nothing
        self._generation = 0  # the controller's count of layout changes when the drag began

    def activate(self) -> None:
        if self.doc.project.layout is None:
            self.status("Layout: no layout yet — Lake ▸ Auto layout (Ctrl+L) first")
        else:
            super().activate()

    @property
    def dragging(self) -> bool:
        return self._handle is not None

    def _handles(self, lay) -> list:
        """The handles of ``lay`` (remembered for the last layout: hovering asks often)."""
        from .layout_edit import handles

        if self._cache is None or self._cache[0] is not lay:
            import shapely

            hs = handles(lay)
            lines = np.array(
                [shapely.linestrings(np.asarray(c, float)) if len(c) >= 2 else None for c in lay.cuts], dtype=object
            )
            self._cache = (lay, hs, np.array([h.xy for h in hs], float).reshape(-1, 2), lines)
        return self._cache[1]

    def _near(self, lay, xy) -> list:
        """The handles of ``lay`` within the pick tolerance of ``xy`` (a hover asks with every mouse move)."""
        hs = self._handles(lay)
        d = np.hypot(*(self._cache[2] - np.asarray(xy, float)).T)
        return [hs[k] for k in np.flatnonzero(d <= self.tol())]

    def hover(self, xy) -> None:
        """Ring the handle a drag would take (shore points are not drawn: this shows them)."""
        from .layout_edit import nearest_handle

        lay = self.doc.project.layout
        if self.canvas is None or self._handle is not None:
            return
        h = nearest_handle(self._near(lay, xy), xy, self.tol()) if lay is not None else None
        self._hovered = (lay, h)
        self._hover_xy = (lay, (float(xy[0]), float(xy[1])))
        self.canvas.lake_items.set_drag_point(None if h is None else h.xy)
        # the cut line Del would delete, highlighted (it was said only by the tip: a user pointing near a
        # junction could not tell which of three cuts would go, or that none would)
        k = self._del_target(lay) if lay is not None else None
        self.canvas.lake_items.set_del_cut(None if k is None else lay.cuts[k])

    def _del_target(self, lay) -> int | None:
        """The cut line of ``lay`` that Del deletes: the one whose end or point is ringed, else the one under
        the cursor along its line (:meth:`_cut_under`); None for none."""
        was, h = self._hovered or (None, None)
        if was is lay and h is not None and h.kind in ("end", "cut"):
            return h.cut
        return self._cut_under(lay)

    def delete(self) -> bool:
        """Del: the cut line pointed at goes (its end or point ringed, or the cursor on the line between
        them); the two blocks it parted become one.  Only a ringed end or point took: a cut from one
        junction to another, straight, had none and could not be deleted; the tip says "the cut line
        pointed at", and the cursor on a cut's line did nothing."""
        lay = self.doc.project.layout
        if lay is None or self.controller is None or self._handle is not None:
            return False
        k = self._del_target(lay)
        if k is None:
            self.status(
                "Delete a cut line: point at it (along its line, away from where cut lines meet, or at its end "
                "on the shore), then Del"
            )
            return True
        from .block_names import names_kept
        from .layout_edit import without_cut

        # (the blocks the cut did not bound keep their names)
        self.controller.edit_layout(lambda: names_kept(lay, without_cut(lay, k)), "Delete cut line")
        self._hovered = None  # the ringed end goes with its cut: no ring left until the mouse moves
        if self.canvas is not None:
            self.canvas.lake_items.set_drag_point(None)
            self.canvas.lake_items.set_del_cut(None)
        return True

    def _cut_under(self, lay) -> int | None:
        """The cut line of ``lay`` under the cursor (within the pick tolerance of its line), None when
        there is none or the cursor is where two of them are as near (a junction)."""
        was, xy = self._hover_xy or (None, None)
        if was is not lay or xy is None:
            return None
        import shapely

        self._handles(lay)  # (the cuts' lines are remembered with the handles)
        d = shapely.distance(self._cache[3], shapely.points(xy)) if len(lay.cuts) else np.zeros(0)
        tol = self.tol()
        near = sorted((float(d[k]), k) for k, c in enumerate(lay.cuts) if len(c) >= 2 and d[k] <= tol)
        if not near or (len(near) > 1 and near[1][0] - near[0][0] <= 0.25 * tol):
            return None
        return near[0][1]

    def deactivate(self) -> None:
        super().deactivate()
        if self._handle is not None and self.controller.generation != self._generation:
            self.cancel_drag()  # (the layout changed under it: as in drag)
        elif self._handle is not None:  # switched away in the middle of a drag: it ends here
            self._end_drag()
        if self.canvas is not None:
            self.canvas.lake_items.set_drag_point(None)
            self.canvas.lake_items.set_del_cut(None)

    def cancel_drag(self) -> bool:
        """Ctrl+Z or Esc in a drag of the layout: the layout goes back to the one the drag began with, its step
        out of the history and its steps still being made dropped (they landed after the undo: the layout
        of an undone Auto layout came back, the redo history gone)."""
        if self._handle is None:
            return False
        self._handle, self._cancelled = None, True
        self.controller.cancel_drag(("layout", self._drag))
        if self.canvas is not None:
            self.canvas.lake_items.set_drag_point(None)
            self.canvas.lake_items.set_labels_visible(True)
        return True

    def drag(self, phase: str, xy, start, modifiers=None) -> bool:
        from .layout_edit import nearest_handle

        lay = self.doc.project.layout
        if phase == "start":
            self._handle, self._cancelled = None, False
            if lay is None or self.controller is None:
                return False
            h = nearest_handle(self._near(lay, start), start, self.tol())
            if h is None:
                return False
            from meshcore.layout.outline import outline_parts

            from .layout_edit import DragSteps

            self._handle, self._base, self._parts = h, lay, outline_parts(lay)
            self._steps, self._last_xy = DragSteps(), None
            self._drag = self.editor.new_drag_id()
            self._generation = self.controller.generation
            self.controller.begin_drag()
            if self.canvas is not None:  # the cell counts stay; they need not repaint with every grid
                self.canvas.lake_items.set_labels_visible(False)
                self.canvas.lake_items.set_del_cut(None)
        if self._handle is None:
            if self._cancelled:  # the rest of a drag cancelled by Ctrl+Z does nothing (it panned the view)
                self._cancelled = phase != "finish"
                return True
            return False
        if self.controller.generation != self._generation:
            # the layout changed under the drag by other than its own steps (an undo from the history,
            # Auto layout): its steps, made from the layout it began with, would undo that change
            self.cancel_drag()
            self.status("The layout changed under the drag (an undo or another layout): the drag stops here")
            return True
        if phase == "move":
            self._move(xy)
        if phase == "finish":
            self._end_drag(xy)
        return True

    def _end_drag(self, xy=None) -> None:
        """The drag ends (at ``xy``, else where its last step went): its last layout is made as a
        case of it gives it (the steps before kept the chains' cells of the first)."""
        xy = self._last_xy if xy is None else xy
        if xy is not None:
            self._move(xy, final=True)
        self._handle = None
        self.controller.end_drag()
        if self.canvas is not None:
            self.canvas.lake_items.set_drag_point(None)
            self.canvas.lake_items.set_labels_visible(True)

    def _move(self, xy, final: bool = False) -> None:
        """A step of the drag to ``xy``; ``final``: its last, made without the kept cells (and made
        even where it began, when steps went elsewhere: the layout goes back to the start's)."""
        from .layout_edit import KIND_NAMES, moved_layout, moved_parts, place, settled_layout, shore_points

        base, h, steps = self._base, self._handle, self._steps
        q = place(base, h, xy, self._parts)
        if self.canvas is not None:
            self.canvas.lake_items.set_drag_point(q)
        tol = 1e-9 * max(1.0, float(np.sqrt(base.polygon.area)))
        back = bool(np.hypot(q[0] - h.xy[0], q[1] - h.xy[1]) <= tol)  # where it began
        if back and not (final and self._last_xy is not None):
            return
        self._last_xy = xy
        before, shore = self._parts, shore_points(base) if h.kind == "shore" else None
        report = self.doc.report

        def make():  # in the layout worker: the GUI thread only places the handle (most steps are dropped)
            from meshcore.errors import InvalidInputError

            if final and back:  # the layout it began with
                return base
            parts = moved_parts(before, h.xy, q, tol, shore=shore)
            if shore is not None and not _shore_moved(before, parts):
                raise InvalidInputError("this shore point is not on the layout's shore: it cannot be dragged")
            if not final:
                return moved_layout(base, parts, steps)
            from .drag_cells import cells_followed

            # the steps kept every block's cells; at the end they follow a block the drag stretched
            return cells_followed(base, settled_layout(base, parts, steps), report)

        what = KIND_NAMES[h.kind]
        self.controller.edit_layout(make, f"Move {what}", merge_key=("layout", self._drag), shore=h.kind == "shore")


def _shore_moved(before: dict, after: dict) -> bool:
    """True when the shore or an island of the ``[outline]`` parts moved."""
    rings = [(before["outline"], after["outline"]), *zip(before["holes"], after["holes"], strict=True)]
    return any(not np.array_equal(a, b) for a, b in rings)
