"""Undoable edits: QUndoCommand subclasses that swap immutable project states.

Each command stores the project before and after; ``redo`` sets *after*,
``undo`` sets *before*, so undo returns the exact previous state.  Commands
with a merge key (a drag, typing in a spin box) merge consecutive pushes into
one undo step.  :class:`Editor` is the facade the tools and panels call.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable

from PySide6.QtGui import QUndoCommand, QUndoStack

from meshcore import BorderSpec

from . import project as pj
from .document import Document
from .project import Block, Project

__all__ = [
    "DRAWN_TITLE",
    "LAYOUT_CUT_HINT",
    "LAYOUT_HINT",
    "AddBlock",
    "AddCutLine",
    "AddPoint",
    "CloseLoop",
    "DeletePoints",
    "Editor",
    "InsertPoint",
    "MovePoints",
    "ProjectCommand",
    "SetBlockOptions",
    "SetBorderSpec",
    "SetCorners",
    "SetLake",
    "SetSolver",
    "drawn_title",
]

_MERGE_ID = 4711


#: what edits the blocks of a lake's layout (said where a block tool cannot: Edit, Convert to loop, Delete)
#: Split (Ctrl+K) over a lake's layout: a cut drawn over it goes into it at once
LAYOUT_CUT_HINT = "A cut line drawn over the layout (Cut line tool, L) splits the blocks it crosses at once: no Split"
LAYOUT_HINT = (
    "These blocks are the lake's layout: drag its shore points, cut ends, junctions and corners with the "
    "Layout tool (Y); the Lake panel sets cells and cell size (Auto layout lays it out again); "
    "Lake ▸ Clear layout gives the shore back as one loop of points"
)


class ProjectCommand(QUndoCommand):
    """Swap the document's project between ``before`` and ``after``."""

    def __init__(
        self, doc: Document, after: Project, text: str, *, merge_key=None, before: Project | None = None
    ) -> None:
        super().__init__(text)
        self.doc = doc
        self.before = before if before is not None else doc.project
        self.after = after
        self.merge_key = merge_key
        self.discard = False  # undone once more, it leaves the history (a drag cancelled half way)

    def redo(self) -> None:
        self.doc.set_project(self.after)

    def undo(self) -> None:
        self.doc.set_project(self.before)
        if self.discard:  # QUndoStack deletes an obsolete command once undone: no redo of half a drag
            self.setObsolete(True)

    def id(self) -> int:
        return _MERGE_ID if self.merge_key is not None else -1

    def mergeWith(self, other: QUndoCommand) -> bool:
        if not isinstance(other, ProjectCommand) or other.merge_key != self.merge_key:
            return False
        self.after = other.after
        return True


class AddPoint(ProjectCommand):
    """Append a point to the block being drawn."""


class CloseLoop(ProjectCommand):
    """Close the drawn polyline into a loop."""


class MovePoints(ProjectCommand):
    """Move points (a drag merges into one step)."""


class InsertPoint(ProjectCommand):
    """Insert a point on a segment."""


class DeletePoints(ProjectCommand):
    """Delete the selected points."""


class SetCorners(ProjectCommand):
    """Set the four corners (sw, se, ne, nw)."""


class SetBlockOptions(ProjectCommand):
    """Cells, weights, initial method, curve of a block."""


class SetBorderSpec(ProjectCommand):
    """Distribution/clustering/name of one border."""


class SetSolver(ProjectCommand):
    """Solver method, tolerance, iterations, omega."""


class AddBlock(ProjectCommand):
    """Add a new (empty) block."""


class AddCutLine(ProjectCommand):
    """Add a cut line (multiblock)."""


class SetLake(ProjectCommand):
    """The lake's settings or its block layout (Auto layout, a layout edit, Clear layout)."""


_drag_ids = itertools.count(1)

#: the title of a project whose outline was drawn by clicking (no file named it, no background image)
DRAWN_TITLE = "drawn lake"


def drawn_title(project: Project) -> str:
    """The title of a drawn outline: the background image it was traced on (its file name), else
    :data:`DRAWN_TITLE`."""
    from pathlib import Path

    bg = project.background
    stem = Path(bg.path).stem.strip() if bg is not None and bg.path else ""
    return stem or DRAWN_TITLE


class Editor:
    """Turns intentions into commands pushed on the undo stack."""

    def __init__(self, doc: Document, stack: QUndoStack) -> None:
        self.doc = doc
        self.stack = stack

    def new_drag_id(self) -> int:
        return next(_drag_ids)

    def drop_merged(self, merge_key) -> bool:
        """Undo the last step when it is the one merged under ``merge_key`` (a drag's steps, the drag
        cancelled half way) and leave no redo of it; False, and nothing done, when the last step is
        another (the drag made none yet)."""
        stack = self.stack
        top = stack.command(stack.index() - 1) if stack.index() > 0 else None
        if merge_key is None or not isinstance(top, ProjectCommand) or top.merge_key != merge_key:
            return False
        top.discard = True
        stack.undo()
        return True

    def _push(self, cls: type[ProjectCommand], after: Project, text: str, merge_key=None) -> None:
        if after == self.doc.project:
            return
        self.stack.push(cls(self.doc, after, text, merge_key=merge_key))

    def _locked(self) -> bool:
        """Multiblock cases are solved as read; their geometry is not edited in the app."""
        if self.doc.project.multiblock is not None:
            self.doc.message.emit(
                "This is a multiblock case: its blocks and interfaces come from the case file and "
                "cannot be edited here (solver settings can); edit the case file, or start a new project"
            )
            return True
        if self.doc.project.layout is not None:
            self.doc.message.emit(LAYOUT_HINT)
            return True
        return False

    def _edit_block(
        self, cls, fn: Callable[[Block], Block], text: str, merge_key=None, index: int | None = None
    ) -> None:
        if self._locked():
            return
        k = self.doc.active if index is None else index
        p = self.doc.project
        self._push(cls, p.with_block(k, fn(p.blocks[k])), text, merge_key)

    # ----------------------------------------------------------- points
    def add_point(self, xy) -> None:
        self._edit_block(AddPoint, lambda b: pj.with_point_added(b, xy), "Add point")

    def close_loop(self) -> None:
        """Close the drawn loop; a project without a title is titled by it (:func:`drawn_title`),
        in the same step: a lake drawn by clicking was "untitled" in the window and the Save name."""
        b = self.doc.block
        if b.closed or len(b.points) < 3 or self._locked():
            return
        p = self.doc.project
        after = p.with_block(self.doc.active, pj.with_loop_closed(b))
        self._push(CloseLoop, after if p.title else after.replaced(title=drawn_title(p)), "Close boundary")

    def move_points(self, indices, delta, drag_id=None) -> None:
        key = ("move", drag_id) if drag_id is not None else None
        self._edit_block(
            MovePoints,
            lambda b: pj.with_points_moved(b, indices, delta),
            "Move point" if len(indices) == 1 else f"Move {len(indices)} points",
            key,
        )

    def set_points(self, indices, positions, drag_id=None) -> None:
        key = ("move", drag_id) if drag_id is not None else None
        idx = list(indices)
        self._edit_block(
            MovePoints,
            lambda b: pj.with_points_set(b, idx, positions),
            "Move point" if len(idx) == 1 else f"Move {len(idx)} points",
            key,
        )

    def set_point(self, index, xy, drag_id=None) -> None:
        key = ("move", drag_id) if drag_id is not None else None
        self._edit_block(MovePoints, lambda b: pj.with_point_set(b, index, xy), "Move point", key)

    def insert_point(self, after: int, xy) -> None:
        self._edit_block(InsertPoint, lambda b: pj.with_point_inserted(b, after, xy), "Insert point")

    def delete_points(self, indices) -> None:
        idx = sorted(indices)
        if not idx:
            return
        self.doc.set_selection(())
        self._edit_block(
            DeletePoints,
            lambda b: pj.with_points_deleted(b, idx),
            "Delete point" if len(idx) == 1 else f"Delete {len(idx)} points",
        )

    def set_corners(self, corners) -> None:
        """Set the corners; the first corners of a block still at the default cell counts give it
        counts in proportion to its borders (said in the status bar), typed counts are kept."""
        b = self.doc.block
        cells = b.cells
        if corners is not None and b.corners is None and b.boundary is None and b.cells == Block().cells:
            cells = pj.default_cells(b.points, tuple(corners), total=max(b.cells or (32, 16)))
        self._edit_block(SetCorners, lambda bb: pj.with_corners(bb, corners).replaced(cells=cells), "Set corners")
        if cells != b.cells and self.doc.block.cells == cells:
            text = (
                f"Cells {cells[0]}×{cells[1]} in proportion to the borders (were {b.cells[0]}×{b.cells[1]}); "
                "type other counts in Parameters — typed counts are kept"
            )
            self.doc.message.emit(text)
            self.doc.report("info", f"{b.name}: {text}")

    # ---------------------------------------------------------- options
    def set_block_options(self, merge_key=None, index: int | None = None, **kw) -> None:
        names = ", ".join(kw)
        self._edit_block(
            SetBlockOptions,
            lambda b: b.replaced(**kw),
            f"Set {names}",
            merge_key=("opt", names, merge_key) if merge_key else None,
            index=index,
        )

    def set_border_spec(self, border: str, spec: BorderSpec, index: int | None = None) -> None:
        self._edit_block(
            SetBorderSpec, lambda b: pj.with_border_spec(b, border, spec), f"Set {border} border", index=index
        )

    def set_solver(self, merge_key=None, **kw) -> None:
        p = self.doc.project
        s = p.solver.replaced(**kw)
        self._push(
            SetSolver,
            p.replaced(solver=s),
            "Set solver " + ", ".join(kw),
            ("solver", tuple(kw), merge_key) if merge_key else None,
        )

    def add_block(self) -> None:
        if self._locked():
            return
        p = self.doc.project
        after = p.replaced(blocks=(*p.blocks, Block(name=pj.next_block_name(p))))
        self._push(AddBlock, after, "Add block")
        self.doc.set_active(len(after.blocks) - 1)

    def delete_block(self, index: int | None = None) -> None:
        """Remove a block (the last one is replaced by an empty block)."""
        if self._locked():
            return
        p = self.doc.project
        k = self.doc.active if index is None else index
        blocks = [b for j, b in enumerate(p.blocks) if j != k] or [Block(name="block")]
        self._push(AddBlock, p.replaced(blocks=tuple(blocks)), f"Delete block {p.blocks[k].name}")

    def add_cut_line(self, points) -> None:
        if self._locked():
            return
        p = self.doc.project
        self._push(AddCutLine, p.replaced(cut_lines=(*p.cut_lines, pj.frozen_points(points))), "Add cut line")

    def set_lake(self, lake, text: str, merge_key=None) -> None:
        """Set the project's lake (with a layout: its blocks become the project's blocks)."""
        from .lake import with_layout

        p = self.doc.project
        self._push(SetLake, with_layout(p, lake), text, merge_key)

    def clear_layout(self) -> None:
        """Back to the lake's shore as one editable block (the layout is dropped; undoable)."""
        from .project import block_from_points

        p = self.doc.project
        if p.layout is None:
            return
        block = block_from_points(p.lake.outline, p.title or "lake")
        self._push(SetLake, p.replaced(lake=p.lake.replaced(layout=None), blocks=(block,)), "Clear layout")

    def replace_project(self, after: Project, text: str) -> None:
        self._push(ProjectCommand, after, text)
