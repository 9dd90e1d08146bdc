"""The main window: composition of canvas, docks, menus, toolbar and status bar.

It builds the parts and connects them (its frame: title, drops, close, size, help in
:mod:`app.window_frame`); the logic lives elsewhere: the
document (:mod:`app.document`) holds the state the views draw, edits are undo
commands (:mod:`app.commands`, :mod:`app.tools`, :mod:`app.layout_tools`), files go through the I/O
controller (:mod:`app.io_controller`), the background image through
:mod:`app.background`, the solver through :mod:`app.solver_controller`, and
every action comes from the table in :mod:`app.actions`.
"""

from __future__ import annotations

import logging
import math
import time
from pathlib import Path

from PySide6 import QtCore, QtGui, QtWidgets

from meshcore import MeshcoreError
from meshcore.io.outline import guess_corners

from . import actions
from . import geometry as geo
from . import io_adapter as fio
from .background import BackgroundController
from .commands import LAYOUT_CUT_HINT, LAYOUT_HINT, Editor, SetBlockOptions
from .document import Document
from .examples import LAKES, example_names
from .io_controller import IOController
from .lake_controller import LakeController
from .layout_tools import CutTool, LayoutTool
from .measure import Measurer
from .project import Project, boundary_to_loop
from .solve_status import SolveStatus
from .solver_controller import SolverController
from .tools import CalibrateTool, CornersTool, DrawTool, EditTool, PanTool
from .views.canvas import Canvas
from .views.docks import narrowable, scrolled
from .views.lake_panel import LakePanel, LakeQualityBox
from .views.messages import ElidedLabel, MessagePanel
from .views.panels import BlocksPanel, ConvergencePanel, ParamsPanel, QualityPanel
from .window_frame import APP_NAME, PRESET_KEY, WindowFrame

__all__ = ["MainWindow"]

log = logging.getLogger(__name__)

DEFAULT_SIZE = (1400, 880)
#: seconds a note of what was just done (a drag cancelled) leads the grid's line that follows it in the
#: status line (the grid of before the drag, solved again, wrote over "Drag cancelled" a moment later)
NOTE_HOLD_S = 6.0


def default_recovery_path() -> Path:
    """Where the autosave goes unless told otherwise (the platform's application data folder)."""
    loc = QtCore.QStandardPaths.StandardLocation.AppDataLocation
    return Path(QtCore.QStandardPaths.writableLocation(loc)) / "recovery.toml"


class MainWindow(WindowFrame, QtWidgets.QMainWindow):
    """The gcmesh main window (its frame: :class:`app.window_frame.WindowFrame`)."""

    def __init__(
        self,
        *,
        settings: QtCore.QSettings | None = None,
        recovery: Path | None = None,
        restore_layout: bool = True,
    ) -> None:
        super().__init__()
        self.setWindowTitle(APP_NAME)
        icon = Path(__file__).resolve().parent.parent / "resources" / "icons" / "gcmesh.svg"
        if icon.exists():
            self.setWindowIcon(QtGui.QIcon(str(icon)))
        self.resize(*DEFAULT_SIZE)
        self.setAcceptDrops(True)
        self.quiet = False  # True: no modal dialogs (tests, screenshots); errors go to the status bar
        self.settings = settings or QtCore.QSettings("gcmesh", "gcmesh")
        self.doc = Document()
        self.measurer = Measurer(self)  # a large grid's quality is measured in a worker thread
        self.doc.measure_async = self.measurer
        self.stack = QtGui.QUndoStack(self)
        self.editor = Editor(self.doc, self.stack)
        self.solver = SolverController(self.doc, self)
        self.lake_ctl = LakeController(self)
        self._cell_centres: dict[int, tuple] = {}  # id(grid) → (grid, its cell centres, its box): the read-out
        self.canvas = Canvas(self.doc)
        self.canvas.setFocusPolicy(QtCore.Qt.FocusPolicy.StrongFocus)
        # the canvas under a strip for offers (place_offer): an offer over the canvas covered the lake
        central = QtWidgets.QWidget()
        self._central = QtWidgets.QVBoxLayout(central)
        self._central.setContentsMargins(0, 0, 0, 0)
        self._central.setSpacing(0)
        self._central.addWidget(self.canvas, 1)
        self.setCentralWidget(central)
        self._status = ElidedLabel()
        self._note: tuple[str, float] | None = None  # (a note of what was just done, when): see message
        self._coords = QtWidgets.QLabel()
        self.statusBar().addWidget(self._status, 1)

        self.io = IOController(self, self.settings, recovery or default_recovery_path())
        self.background = BackgroundController(self)
        self._make_docks()
        self._make_tools()
        self.tool_group = QtGui.QActionGroup(self)
        self.tool_actions: dict[str, QtGui.QAction] = {}
        self.actions = actions.build(self, self._placeholder)
        self.solve_status = SolveStatus(self)
        self.statusBar().addPermanentWidget(self.solve_status.label)
        self.statusBar().addPermanentWidget(self._coords)
        self.io.refresh_recent()
        self._connect()

        self._shown = False
        self.fit_on_show = True  # False: a size asked for explicitly (``--size``) is kept as it is
        self._corners_seen = None  # (block, points, corners) last checked for corner advice
        self._advice_held = None  # (lake shore, corners): an imported lake's automatic corners, advised at F5
        self.set_tool("draw")
        self._update_title()
        self.focus_canvas()
        if restore_layout:
            self._restore_layout()
        self.live_for_document()
        self.fit_to_screen()
        self.canvas.fit()
        self.message(
            "Draw a boundary (click points, double-click to close), import points (Ctrl+I) "
            "or pick an example from the Examples menu"
        )

    # ------------------------------------------------------------ building
    def _make_docks(self) -> None:
        self.blocks_panel = BlocksPanel(self.doc)
        self.params_panel = ParamsPanel(self.doc, self.editor)
        self.conv_panel = ConvergencePanel()
        self.quality_panel = QualityPanel(self.doc)
        self.messages_panel = MessagePanel(self.doc)
        self.lake_panel = LakePanel(self.doc, self.lake_ctl)
        self.lake_quality = LakeQualityBox(self.doc)
        self.quality_panel.layout().insertWidget(0, self.lake_quality)  # for a lake, the verdict comes first
        self.undo_view = QtWidgets.QUndoView(self.stack)
        self.undo_view.setEmptyLabel("<start>")
        self.docks = {}
        left = QtCore.Qt.DockWidgetArea.LeftDockWidgetArea
        right = QtCore.Qt.DockWidgetArea.RightDockWidgetArea
        for key, title, w, area in (
            ("blocks", "Blocks and borders", self.blocks_panel, left),
            ("params", "Parameters", self.params_panel, left),
            ("lake", "Lake", self.lake_panel, left),
            ("quality", "Quality", self.quality_panel, right),
            ("convergence", "Convergence", self.conv_panel, right),
            ("messages", "Messages", self.messages_panel, right),
            ("history", "Undo history", self.undo_view, right),
        ):
            d = QtWidgets.QDockWidget(title, self)
            d.setObjectName(key)
            # a dock narrower than its contents scrolls, or wraps its text (the Quality panel's plots
            # crash PySide in a scroll area): a small screen keeps room to draw (fit_docks)
            d.setWidget(narrowable(w) if key == "quality" else scrolled(w))
            self.addDockWidget(area, d)
            self.docks[key] = d
        self.tabifyDockWidget(self.docks["params"], self.docks["lake"])
        self.docks["params"].raise_()
        self.tabifyDockWidget(self.docks["convergence"], self.docks["messages"])
        self.tabifyDockWidget(self.docks["messages"], self.docks["history"])
        self.docks["convergence"].raise_()
        vertical, horizontal = QtCore.Qt.Orientation.Vertical, QtCore.Qt.Orientation.Horizontal
        self.resizeDocks([self.docks["blocks"], self.docks["params"]], [230, 520], vertical)
        self.resizeDocks([self.docks["quality"], self.docks["convergence"]], [560, 260], vertical)
        self.resizeDocks([self.docks["blocks"], self.docks["quality"]], [330, 330], horizontal)  # the Lake panel: 317

    def _make_tools(self) -> None:
        ctx = (self.doc, self.editor, self.canvas, self.message)
        self.tools = {
            "pan": PanTool(*ctx),
            "draw": DrawTool(*ctx),
            "edit": EditTool(*ctx),
            "corners": CornersTool(*ctx),
            "cut": CutTool(*ctx),
            "layout": LayoutTool(*ctx),
            "calibrate": CalibrateTool(*ctx, on_pair=self.background.ask_true_points),
        }
        self.tools["draw"].on_closed = lambda: self.set_tool("corners")
        self.tools["layout"].controller = self.lake_ctl
        self.tools["cut"].controller = self.lake_ctl

    def _placeholder(self, name: str, menu: QtWidgets.QMenu, spec: actions.ActionSpec):
        """Fill the ``@name`` rows of the action table (see :func:`app.actions.build`)."""
        if name.startswith("tool:"):
            key = name.removeprefix("tool:")
            a = QtGui.QAction(spec.text, self, checkable=spec.checkable)
            a.triggered.connect(lambda _c=False, k=key: self.set_tool(k))
            if spec.checkable:
                self.tool_group.addAction(a)
                self.tool_actions[key] = a
        elif name in ("undo", "redo"):
            a = self._history_action(name, spec.text)
        elif name == "recent":
            self.recent_menu = self.io.recent_menu = menu.addMenu(spec.text)
            return None
        elif name == "docks":
            menu.addActions([d.toggleViewAction() for d in self.docks.values()])
            return None
        elif name == "examples":
            self._examples_menu(menu)
            return None
        else:
            raise KeyError(f"no placeholder {name!r} in the window")
        menu.addAction(a)
        return a

    def _history_action(self, name: str, prefix: str) -> QtGui.QAction:
        """Undo or Redo, named by the step it undoes or redoes as the stack's own actions are, through
        :meth:`undo` / :meth:`redo` (the stack's action undid under a drag: see :meth:`undo`)."""
        stack = self.stack
        a = _StepAction(prefix, self)
        if name == "undo":
            a.set_step(stack.undoText())
            a.setEnabled(stack.canUndo())
            stack.undoTextChanged.connect(a.set_step)
            stack.canUndoChanged.connect(a.setEnabled)
        else:
            a.set_step(stack.redoText())
            a.setEnabled(stack.canRedo())
            stack.redoTextChanged.connect(a.set_step)
            stack.canRedoChanged.connect(a.setEnabled)
        a.triggered.connect(self.undo if name == "undo" else self.redo)
        return a

    def undo(self) -> None:
        """Ctrl+Z: the last step undone — in the middle of a drag (a cut end, a shore point, points of a
        block), the drag cancelled instead (:meth:`cancel_drag`).  (The stack undid under the drag: the step
        before it went, then the drag's next move set its own layout over the undo, or moved points that
        were gone.)"""
        if self.cancel_drag("Ctrl+Z"):
            return
        self.stack.undo()
        self._say_undone("undo")

    def stop(self) -> None:
        """Esc (Generate ▸ Stop): in the middle of a drag, the drag cancelled as Ctrl+Z cancels it (the drag
        went on: Esc stopped the drag's solve, or did nothing); else Auto layout and the solver stopped."""
        if not self.cancel_drag("Esc"):
            self.lake_ctl.stop_layout()
            self.solver.stop()

    def cancel_drag(self, key: str) -> bool:
        """The drag of the tool (a cut end, a shore point, a block's points, a box selection) cancelled:
        back to before it, no step of it left to undo or redo, the rest of the mouse's drag doing nothing —
        said in the Messages and in the status line, ahead of the grid's line that follows (the grid of
        before the drag, solved again, wrote over it).  False when no drag is on."""
        tool = self.canvas.tool
        if tool is None or not tool.cancel_drag():
            return False
        text = f"Drag cancelled ({key}): back to before it"
        self.doc.report("info", text)
        again = " — Ctrl+Z again undoes the step before" if key == "Ctrl+Z" else ""
        self.message(text + again, note=True)
        return True

    def redo(self) -> None:
        """Ctrl+Y: the step undone last redone; not in the middle of a drag (said)."""
        tool = self.canvas.tool
        if tool is not None and tool.in_drag:
            self.message("Redo waits for the end of the drag (Ctrl+Z cancels the drag)")
            return
        self.stack.redo()
        self._say_undone("redo")

    def _say_undone(self, name: str) -> None:
        """The status line says what Ctrl+Z (or Ctrl+Y) just did: it went on showing the message of
        before (an undone Auto layout of 85 blocks under "Exported 85 block(s) to …")."""
        text = self.stack.redoText() if name == "undo" else self.stack.undoText()
        if text:
            again = "Ctrl+Y redoes it" if name == "undo" else "Ctrl+Z undoes it"
            self.message(f"{'Undone' if name == 'undo' else 'Redone'}: {text} ({again})")

    def _keep_in_sight(self, _index: int = 0) -> None:
        """After an undo or redo of another lake (an import: another title or frame) or one that leaves
        the project wholly outside the view, the view fits it (an import undone left the view on the
        other lake, the canvas empty: the lake looked lost)."""
        p, seen = self.doc.project, self._in_sight
        self._in_sight = p
        other = seen is not None and (
            (p.crs, p.origin) != (seen.crs, seen.origin) or bool(p.title and seen.title and p.title != seen.title)
        )
        bounds = p.bounds()
        if bounds is not None and (other or not self.canvas.shows_any_of(bounds)):
            self.canvas.fit()

    def _examples_menu(self, m: QtWidgets.QMenu) -> None:
        m.addSection("Paper cases")
        for name in example_names():
            if name not in LAKES:
                m.addAction(name, lambda n=name: self.io.open_example(n))
        m.addSection("Real lakes (GSHHG, lon/lat → UTM)")
        for name in example_names():
            if name in LAKES:
                a = m.addAction(name, lambda n=name: self.io.open_example(n))
                a.setToolTip(LAKES[name][1])

    def _connect(self) -> None:
        self.doc.message.connect(self.message)
        self.doc.project_changed.connect(self._on_project)
        self.doc.opened.connect(self.focus_canvas)
        self.doc.path_changed.connect(self._update_title)
        self.canvas.hovered.connect(self._show_coords)
        self.canvas.unhovered.connect(self._coords.clear)
        self.blocks_panel.border_selected.connect(self.params_panel.select_border)
        self.quality_panel.zoom_to_cell.connect(self.canvas.zoom_to_cell)
        self.params_panel.committed.connect(self.focus_canvas)
        self.lake_panel.committed.connect(self.focus_canvas)
        self.lake_quality.misses.connect(self.canvas.lake_items.set_misses)
        self.lake_quality.table.clicked.connect(lambda _i: self.show_misses(True))  # a limit picked: show where
        self.lake_quality.go_to.connect(self.show_worst)
        # the model a modeller grids for stays chosen in the next session (it went back to delft3d)
        self.lake_quality.preset.currentTextChanged.connect(lambda t: self.settings.setValue(PRESET_KEY, t))
        self.doc.colour_changed.connect(self._misses_for_colours)
        self.messages_panel.attention.connect(self.show_messages)
        self.doc.project_changed.connect(self._check_corners)
        self._had_layout = False  # whether the project had a layout at the last change (_tool_for_layout)
        self.doc.project_changed.connect(self._tool_for_layout)
        self._live_seen = None  # the kind of document Live was last set for (live_for_document)
        self.a_auto.triggered.connect(self._live_chosen)
        self.doc.project_changed.connect(self.live_for_document)
        self.stack.cleanChanged.connect(self._update_title)
        self._in_sight = None  # the project the view was last kept on (_keep_in_sight)
        self.stack.indexChanged.connect(self._keep_in_sight)
        # a step done, undone or redone after a note (a drag cancelled): the next grid line is of that step
        self.stack.indexChanged.connect(lambda _i: setattr(self, "_note", None))
        self.doc.opened.connect(lambda: setattr(self, "_in_sight", self.doc.project))

    # ------------------------------------------------------------ status
    def message(self, text: str, *, error: bool = False, note: bool = False, summary: bool = False) -> None:
        """One line in the status bar; errors also go to the message panel, in full.  ``note``: what was
        just done (a drag cancelled), kept ahead of a ``summary`` (the grid's line at the end of a solve)
        that comes within :data:`NOTE_HOLD_S` ("Drag cancelled (Esc): back to before it — Lake grid: …");
        any other message, or a step done, undone or redone (a new drag's), ends it."""
        held, now = self._note, time.monotonic()
        if summary and held is not None and now - held[1] <= NOTE_HOLD_S:
            text = f"{held[0]} — {text}"
        elif not summary:
            self._note = (text, now) if note else None
        self._status.setText(text)
        self._status.setStyleSheet("color: #b00000; font-weight: bold;" if error else "")
        if error:
            self.doc.report("error", text)

    def error(self, title: str, exc: BaseException | str) -> None:
        """Report a failed operation: the status bar, the message panel, a dialog (unless quiet), the log."""
        text = str(exc)
        log.info("%s: %s", title, text, exc_info=exc if isinstance(exc, BaseException) else None)
        self.message(f"{title}: {text}", error=True)
        if not self.quiet:
            QtWidgets.QMessageBox.warning(self, title, text)

    def show_messages(self) -> None:
        """Bring the message panel to the front (a problem was reported)."""
        dock = self.docks["messages"]
        dock.show()
        dock.raise_()

    def focus_canvas(self) -> None:
        """Give the keyboard to the canvas: tool keys and Ctrl+Z act on the drawing again."""
        self.canvas.setFocus(QtCore.Qt.FocusReason.OtherFocusReason)

    def _show_coords(self, x: float, y: float) -> None:
        p = self.doc.project
        text = f"x = {x:.6g}   y = {y:.6g}"
        if p.crs:
            text += f"   ({p.crs}: E {x + p.origin[0]:.1f}  N {y + p.origin[1]:.1f})"
        cell = self._cell_readout(x, y)
        self._coords.setText(f"{cell}   {text}" if cell else text)

    def _cell_readout(self, x: float, y: float) -> str:
        """The coloured metric of the cell under the cursor (nearest cell centre, if inside it), in any
        block the colours cover (deviation from 90° colours every block of a lake; the read-out was of the
        active block alone: over the others' dark cells it said nothing).  Over several blocks it names
        the block."""
        if self.doc.solving:
            return ""
        layers = self.doc.colour_blocks()
        best = None  # (distance to the cell's centre, block, i, j, values)
        for k, g, values in layers:
            entry = self._cell_centres.get(id(g))
            if entry is None or entry[0] is not g:
                box = (float(g.x.min()), float(g.y.min()), float(g.x.max()), float(g.y.max()))
                entry = self._cell_centres[id(g)] = (g, geo.cell_centres(g.x, g.y), box)
            if not (entry[2][0] <= x <= entry[2][2] and entry[2][1] <= y <= entry[2][3]):
                continue  # (off this block: a lake of 100 blocks is read out at every mouse move)
            cell = geo.cell_at(g.x, g.y, x, y, entry[1])
            if cell is None:
                continue
            i, j = cell
            d = math.hypot(float(entry[1][0][i, j]) - x, float(entry[1][1][i, j]) - y)
            if best is None or d < best[0]:
                best = (d, k, i, j, values)
        if len(self._cell_centres) > len(layers):  # (the grids of earlier solves go)
            shown = {id(g) for _k, g, _v in layers}
            self._cell_centres = {key: e for key, e in self._cell_centres.items() if key in shown}
        if best is None:
            return ""
        _d, k, i, j, values = best
        names = [b.name for b in self.doc.project.blocks]
        where = f"{names[k]} " if len(layers) > 1 and k < len(names) else ""
        return f"{where}cell ({i}, {j}): {self.doc.colour_by} {float(values[i, j]):.4g}"

    # -------------------------------------------------------------- tools
    def set_tool(self, key: str) -> None:
        if self.canvas.tool is not None:
            self.canvas.tool.deactivate()
        tool = self.tools[key]
        self.canvas.tool = tool
        if key in self.tool_actions:
            self.tool_actions[key].setChecked(True)
        tool.activate()

    def _tool_for_layout(self, project: Project) -> None:
        """The layout gone (Clear layout, Auto layout undone) under the Layout tool, which has nothing
        left to act on: the tool of a lake without a layout (Edit, as its import chooses).  The layout
        back (Clear layout undone) under the Edit tool, which has no points of it: the Layout tool, as
        Auto layout chooses."""
        has = project.layout is not None
        had, self._had_layout = self._had_layout, has
        key = None
        if not has and self.canvas.tool is self.tools["layout"]:
            key = "edit"
        elif has and not had and self.canvas.tool is self.tools["edit"]:
            key = "layout"
        if key is not None:  # the status line keeps what the change said (the tool's tip would cover it)
            text, style = self._status.text(), self._status.styleSheet()
            self.set_tool(key)
            self._status.setText(text)
            self._status.setStyleSheet(style)

    def keyPressEvent(self, ev: QtGui.QKeyEvent) -> None:
        # Esc with Stop disabled (no solve) reaches here: a drag is cancelled before the tool sees the key
        if ev.key() == QtCore.Qt.Key.Key_Escape and self.cancel_drag("Esc"):
            ev.accept()
            return
        if self.canvas.tool is not None and self.canvas.tool.key(ev.key()):
            ev.accept()
            return
        super().keyPressEvent(ev)

    # -------------------------------------------------------------- edits
    def delete_selection(self) -> None:
        if self.canvas.tool is not None and self.canvas.tool.delete():  # a cut line, with the Layout tool
            return
        if self.doc.project.layout is not None:  # Edit ▸ Delete did nothing, silently, on a laid-out lake
            self.message(LAYOUT_HINT)
            return
        self.editor.delete_points(self.doc.selection)

    def select_all(self) -> None:
        if self.doc.project.layout is not None:  # a layout's blocks have no points to select
            self.message(LAYOUT_HINT)
            return
        self.doc.set_selection(range(len(self.doc.block.points)))

    def auto_corners(self) -> None:
        if self.doc.project.layout is not None:  # it said "needs a closed loop of at least 4 points"
            self.message(LAYOUT_HINT)
            return
        b = self.doc.block
        if not b.closed or len(b.points) < 4:
            lay = " (Lake ▸ Auto layout grids a closed loop of 3)" if b.closed and len(b.points) == 3 else ""
            self.message(f"Auto corners needs a closed loop of at least 4 points{lay}")
            return
        try:
            c = guess_corners(b.points)
        except (ValueError, MeshcoreError) as exc:
            self.error("Auto corners", exc)
            return
        self.editor.set_corners(c)
        self.message("Corners chosen automatically (yellow squares); adjust them with the Corners tool")

    def convert_to_loop(self) -> None:
        if self.doc.block.boundary is None:
            self.message("This block is already an editable loop")
            return
        self.editor._edit_block(SetBlockOptions, boundary_to_loop, "Convert borders to loop")

    def split_by_cuts(self) -> bool:
        """Turn the outline + the drawn cut lines into blocks (undoable).

        A lake (an imported outline), or cuts that do not make a chain of blocks (a cut ending on
        another, cuts meeting at a point, a region bordered by three or more cuts): the lake's
        block layout between the cuts (:meth:`LakeController.split_by_cuts`, in a worker), gridded
        orthogonally and editable with the Layout tool.  A drawn loop cut into a chain: a
        multiblock case solved together (``meshcore.case.cut_case``), as before.
        """
        from meshcore.case import cut_case

        p = self.doc.project
        b = self.doc.block
        if p.layout is not None:  # ("needs a closed loop of points (draw or import one)" of an imported lake)
            self.message(f"{LAYOUT_CUT_HINT}. {LAYOUT_HINT}")
            return False
        if p.multiblock is not None or not b.closed or b.boundary is not None:
            self.message("Split needs a closed loop of points (draw or import one) and cut lines across it")
            return False
        if not p.cut_lines:
            self.message("Draw cut lines first: Cut line tool (L), click from shore to shore, Enter")
            return False
        if p.lake is None:
            try:
                case = cut_case(b.points, list(p.cut_lines), cells_across=(b.cell_counts or (32, 16))[1], title=p.title)
                after = fio.project_from_multiblock_case(case)
            except (MeshcoreError, ValueError) as exc:  # not a chain: the lake way takes any topology
                log.info("cut lines not a chain (%s): splitting as a lake", exc)
            else:
                after = after.replaced(crs=p.crs, origin=p.origin, source_crs=p.source_crs, title=p.title)
                self.editor.replace_project(after, f"Split into {len(after.blocks)} blocks")
                self.doc.set_active(0)
                self.set_tool("pan")
                self.message(
                    f"Split into {len(after.blocks)} blocks (η cells {(b.cell_counts or (32, 16))[1]} across every "
                    "block); F5 solves them together — Ctrl+Z undoes the split"
                )
                return True
        self.show_lake()
        return self.lake_ctl.split_by_cuts(list(p.cut_lines))

    def auto_layout_regular(self) -> None:
        """Auto layout without 3- or 5-block corners (what Delft3D domain decomposition couples)."""
        self.lake_ctl.auto_layout(regular=True)

    def auto_layout_single(self) -> None:
        """Auto layout for one index space (EFDC, Delft3D single domain): regular, rings closed."""
        self.lake_ctl.auto_layout(single=True)

    def place_offer(self, bar: QtWidgets.QWidget) -> None:
        """Show an offer (:class:`app.views.offer_bar.OfferBar`) in the strip above the canvas."""
        self._central.insertWidget(0, bar)
        bar.show()

    def show_lake(self) -> None:
        """Bring the Lake dock to the front."""
        self.docks["lake"].show()
        self.docks["lake"].raise_()

    def generate(self, *_a, cold: bool = False) -> None:
        """Generate (F5): solve the project (``cold``: a lake layout's grid from its start, no warm phase from
        the grid shown; see :meth:`app.solver_controller.SolverController.start`)."""
        if not any(b.ready for b in self.doc.project.blocks):
            b = self.doc.block
            if len(b.points) == 0:
                hint = "draw a boundary first"
            elif not b.closed:
                hint = "close the loop first (double-click or Enter)"
            elif len(b.points) < 4:  # three points: no four corners, but water Auto layout grids
                hint = "a loop of 3 points has no four corners: Lake ▸ Auto layout grids it, or add a point"
            else:
                hint = "pick four corners (Corners tool) or use Auto corners (A)"
            self.message(f"Nothing to generate yet: {hint}")
            return
        lake = self.doc.project.lake
        if lake is not None and lake.holes and lake.layout is None and len(self.doc.project.blocks) == 1:
            n = len(lake.holes)
            self.doc.report(
                "warning",
                f"one block over a lake with {n} island{'s' * (n != 1)}: the grid covers "
                f"{'them' if n != 1 else 'it'} — Lake ▸ Auto layout puts blocks around islands",
            )
        if lake is not None and lake.layout is None:  # one block of a lake: the advice held at its import
            self._check_corners(self.doc.project, generating=True)
        self.solve_status.reset()
        self.solver.start(cold=cold)

    # ---------------------------------------------------------- reactions
    def _on_project(self, project: Project) -> None:
        self._update_title()
        pi = self.canvas.getPlotItem()
        labels = {"bottom": "", "left": ""}
        if project.crs:
            ox, oy = project.origin
            labels = {"bottom": f"x = E − {ox:.0f} m ({project.crs})", "left": f"y = N − {oy:.0f} m"}
        for side, text in labels.items():
            # the same text: not set again (it would lay out the axes and make their ticks again, 20 ms
            # with each of the four layouts a second of a drag)
            if pi.getAxis(side).labelText != text:
                pi.setLabel(side, text)

    def hold_corner_advice(self, shore, corners) -> None:
        """The one block of an imported lake that Auto layout is offered for: its automatic ``corners``
        are not advised on (a reflex corner NE of a block the user will not make read as a problem of
        the lake) until the user moves one or makes that block (F5)."""
        self._advice_held = (shore, tuple(corners) if corners is not None else None)

    def _check_corners(self, project: Project, *, generating: bool = False) -> None:
        """New corners on reflex vertices: say which, and where to move them.  Not for a lake's layout
        (its blocks' corners are the layout's), nor for the held automatic corners of an imported lake
        (:meth:`hold_corner_advice`) unless ``generating`` (F5 makes that one block)."""
        b = self.doc.block
        key = (self.doc.active, b.corners)
        if b.corners is None or b.boundary is not None or key == self._corners_seen or project.layout is not None:
            return
        held, lake = self._advice_held, project.lake
        if (
            not generating
            and held is not None
            and lake is not None
            and lake.outline is held[0]
            and b.corners == held[1]
        ):
            return  # (another lake, or corners the user moved: advice as for any block)
        self._corners_seen = key
        try:
            advice = geo.corner_advice(b.points, b.corners)
        except (MeshcoreError, ValueError, IndexError):
            return
        for text in advice:
            self.doc.report("warning", f"{b.name}: {text}")

    def show_misses(self, on: bool) -> None:
        """Show or hide the places that miss the quality preset (View ▸ Preset misses)."""
        if self.a_misses.isChecked() != bool(on):
            self.a_misses.setChecked(bool(on))
        self.canvas.lake_items.set_misses_visible(on)

    def show_worst(self, where, what: str) -> None:
        """Zoom to the worst place of a quality limit (four cells round it) and say what it is."""
        lay = self.doc.project.layout
        h = lay.cell_size if lay is not None else 0.0
        if not h > 0:
            g = self.doc.grid
            h = max(g.bounds()[2] - g.bounds()[0], g.bounds()[3] - g.bounds()[1]) / 50 if g is not None else 1.0
        names = [b.name for b in self.doc.project.blocks]
        if where.block in names:  # its block's numbers in the Quality panel, its row in Blocks
            self.doc.set_active(names.index(where.block))
        # after the block is made active: its quality, drawn anew, clears the canvas's ring (the worst
        # place of a block not active was zoomed to but not ringed: a user could not tell which node)
        self.canvas.zoom_to_point(where.x, where.y, 4 * h)
        text = str(where)
        if what.startswith("folded"):  # its limit "…: none" and a flag for a value read "none: 1 at b8(1,50)"
            what, text = what.removesuffix(": none"), "a cell at " + text.split(" at ", 1)[-1]
        k, n = self.lake_quality.rank(where)  # (a click again on the limit: the next worst)
        lead = "Worst" if k == 0 else f"{k + 1}{'nd' if k == 1 else 'rd' if k == 2 else 'th'} worst"
        more = f" ({k + 1} of the {n} worst: click the limit again for the next)" if n > 1 else ""
        self.message(f"{lead} of {what}: {text}{more}")

    def _misses_for_colours(self, label: str) -> None:
        """Cells coloured by a metric: the misses step aside (they would hide the colours), and back."""
        coloured = label != "none"
        self.show_misses(not coloured)
        if coloured and self.lake_quality.verdict is not None and not self.lake_quality.verdict.passed:
            key = self.a_misses.shortcut().toString(QtGui.QKeySequence.SequenceFormat.NativeText)
            self.message(f"Cells coloured by {label}; the preset's misses are hidden — View ▸ Preset misses ({key})")


class _StepAction(QtGui.QAction):
    """Undo or Redo named by its step ("&Undo Move cut end"), as the undo stack's own actions are."""

    def __init__(self, prefix: str, parent) -> None:
        super().__init__(prefix, parent)
        self._prefix = prefix

    def set_step(self, text: str) -> None:
        self.setText(f"{self._prefix} {text}" if text else self._prefix)
