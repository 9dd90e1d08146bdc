"""The main window: composition of canvas, docks, menus, toolbar and status bar.

It builds the parts and connects them; the logic lives elsewhere: the
document (:mod:`app.document`) holds the state the views draw, edits are undo
commands (:mod:`app.commands`, :mod:`app.tools`), files go through the I/O
controller (:mod:`app.io_controller`), the background image through
:mod:`app.background`, the solver through :mod:`app.solver_controller`, and
every action comes from the table in :mod:`app.actions`.
"""

from __future__ import annotations

import contextlib
import logging
import time
from pathlib import Path

from PySide6 import QtCore, QtGui, QtWidgets

from meshcore import MeshcoreError

from . import actions
from . import geometry as geo
from . import io_adapter as fio
from .background import BackgroundController
from .commands import Editor, SetBlockOptions
from .document import Document
from .examples import LAKES, example_names
from .io_controller import IOController
from .pipeline import ALL_BLOCKS
from .project import Project, boundary_to_loop
from .solver_controller import SolverController
from .tools import CalibrateTool, CornersTool, CutTool, DrawTool, EditTool, PanTool
from .views.canvas import Canvas
from .views.panels import BlocksPanel, ConvergencePanel, ParamsPanel, QualityPanel

__all__ = ["MainWindow"]

log = logging.getLogger(__name__)

APP_NAME = "gcmesh"


def default_recovery_path() -> Path:
    """Where the autosave goes unless told otherwise (the platform's application data folder)."""
    loc = QtCore.QStandardPaths.StandardLocation.AppDataLocation
    return Path(QtCore.QStandardPaths.writableLocation(loc)) / "recovery.toml"


class MainWindow(QtWidgets.QMainWindow):
    """The gcmesh main window."""

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
        self.resize(1400, 880)
        self.setAcceptDrops(True)
        self.quiet = False  # True: no modal dialogs (tests, screenshots); errors go to the status bar
        self.settings = settings or QtCore.QSettings("gcmesh", "gcmesh")
        self.doc = Document()
        self.stack = QtGui.QUndoStack(self)
        self.editor = Editor(self.doc, self.stack)
        self.solver = SolverController(self.doc, self)
        self._frames: list[float] = []
        self._centres = (None, None)  # (grid, its cell centres) for the hover read-out
        self.canvas = Canvas(self.doc)
        self.setCentralWidget(self.canvas)
        self._status = QtWidgets.QLabel()
        self._coords = QtWidgets.QLabel()
        self._solver_label = QtWidgets.QLabel("idle")
        self.statusBar().addWidget(self._status, 1)
        self.statusBar().addPermanentWidget(self._solver_label)
        self.statusBar().addPermanentWidget(self._coords)

        self.io = IOController(self, self.settings, recovery or default_recovery_path())
        self.background = BackgroundController(self)
        self._make_docks()
        self._make_tools()
        self.tool_group = QtGui.QActionGroup(self)
        self.tool_actions: dict[str, QtGui.QAction] = {}
        self.actions = actions.build(self, self._placeholder)
        self.io.refresh_recent()
        self._connect()

        self.set_tool("draw")
        self._update_title()
        if restore_layout:
            self._restore_layout()
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
        self.undo_view = QtWidgets.QUndoView(self.stack)
        self.undo_view.setEmptyLabel("<start>")
        self.docks = {}
        left = QtCore.Qt.DockWidgetArea.LeftDockWidgetArea
        right = QtCore.Qt.DockWidgetArea.RightDockWidgetArea
        for key, title, w, area in (
            ("blocks", "Blocks and borders", self.blocks_panel, left),
            ("params", "Parameters", self.params_panel, left),
            ("quality", "Quality", self.quality_panel, right),
            ("convergence", "Convergence", self.conv_panel, right),
            ("history", "Undo history", self.undo_view, right),
        ):
            d = QtWidgets.QDockWidget(title, self)
            d.setObjectName(key)
            d.setWidget(w)
            self.addDockWidget(area, d)
            self.docks[key] = d
        self.tabifyDockWidget(self.docks["convergence"], self.docks["history"])
        self.docks["convergence"].raise_()
        vertical, horizontal = QtCore.Qt.Orientation.Vertical, QtCore.Qt.Orientation.Horizontal
        self.resizeDocks([self.docks["blocks"], self.docks["params"]], [230, 520], vertical)
        self.resizeDocks([self.docks["quality"], self.docks["convergence"]], [560, 260], vertical)
        self.resizeDocks([self.docks["blocks"], self.docks["quality"]], [300, 330], horizontal)

    def _make_tools(self) -> None:
        ctx = (self.doc, self.editor, self.canvas, self.message)
        self.tools = {
            "pan": PanTool(*ctx),
            "draw": DrawTool(*ctx),
            "edit": EditTool(*ctx),
            "corners": CornersTool(*ctx),
            "cut": CutTool(*ctx),
            "calibrate": CalibrateTool(*ctx, on_pair=self.background.ask_true_points),
        }
        self.tools["draw"].on_closed = lambda: self.set_tool("corners")

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
            make = self.stack.createUndoAction if name == "undo" else self.stack.createRedoAction
            a = make(self, spec.text)
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
        self.doc.grids_changed.connect(lambda: self._frames.append(time.perf_counter()))
        self.doc.active_changed.connect(lambda _k: self._on_final())
        self.doc.opened.connect(self._on_opened)
        self.doc.path_changed.connect(self._update_title)
        self.canvas.hovered.connect(self._show_coords)
        self.blocks_panel.border_selected.connect(self.params_panel.select_border)
        self.quality_panel.zoom_to_cell.connect(self.canvas.zoom_to_cell)
        self.solver.state_changed.connect(self._on_solver_state)
        self.solver.error.connect(self._on_solver_error)
        self.solver.progress.connect(self._on_progress)
        self.solver.finished.connect(self._on_finished)
        self.stack.cleanChanged.connect(self._update_title)

    # ------------------------------------------------------------ status
    def message(self, text: str, *, error: bool = False) -> None:
        self._status.setText(text)
        self._status.setToolTip(text)
        self._status.setStyleSheet("color: #b00000; font-weight: bold;" if error else "")

    def error(self, title: str, exc: BaseException | str) -> None:
        """Report a failed operation: the status bar, a dialog (unless quiet) and the log."""
        text = str(exc)
        log.info("%s: %s", title, text, exc_info=exc if isinstance(exc, BaseException) else None)
        self.message(f"{title}: {text}", error=True)
        if not self.quiet:
            QtWidgets.QMessageBox.warning(self, title, text)

    def _show_coords(self, x: float, y: float) -> None:
        p = self.doc.project
        text = f"x = {x:.6g}   y = {y:.6g}"
        if p.crs:
            text += f"   ({p.crs}: E {x + p.origin[0]:.1f}  N {y + p.origin[1]:.1f})"
        cell = self._cell_readout(x, y)
        self._coords.setText(f"{cell}   {text}" if cell else text)

    def _cell_readout(self, x: float, y: float) -> str:
        """The coloured metric of the cell under the cursor (nearest cell centre, if inside it)."""
        g, values, label = self.doc.colour_values()
        if values is None or self.doc.solving:
            return ""
        if self._centres[0] is not g:
            self._centres = (g, geo.cell_centres(g.x, g.y))
        cell = geo.cell_at(g.x, g.y, x, y, self._centres[1])
        if cell is None:
            return ""
        i, j = cell
        return f"cell ({i}, {j}): {label} {float(values[i, j]):.4g}"

    # -------------------------------------------------------------- tools
    def set_tool(self, key: str) -> None:
        if self.canvas.tool is not None:
            self.canvas.tool.deactivate()
        tool = self.tools[key]
        self.canvas.tool = tool
        if key in self.tool_actions:
            self.tool_actions[key].setChecked(True)
        tool.activate()

    def keyPressEvent(self, ev: QtGui.QKeyEvent) -> None:
        if self.canvas.tool is not None and self.canvas.tool.key(ev.key()):
            ev.accept()
            return
        super().keyPressEvent(ev)

    # -------------------------------------------------------------- edits
    def delete_selection(self) -> None:
        self.editor.delete_points(self.doc.selection)

    def select_all(self) -> None:
        self.doc.set_selection(range(len(self.doc.block.points)))

    def auto_corners(self) -> None:
        b = self.doc.block
        if not b.closed or len(b.points) < 4:
            self.message("Auto corners needs a closed loop of at least 4 points")
            return
        try:
            c = geo.auto_corners(b.points)
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
        """Turn the active loop + the drawn cut lines into a multiblock case (undoable)."""
        import tomli_w

        from meshcore.case import loads_case

        from .cutsplit import case_dict_from_cuts

        p = self.doc.project
        b = self.doc.block
        if p.multiblock is not None or not b.closed or b.boundary is not None:
            self.message("Split needs a closed loop of points (draw or import one) and cut lines across it")
            return False
        try:
            d = case_dict_from_cuts(b.points, list(p.cut_lines), cells_across=b.cells[1], title=p.title)
            case = loads_case(tomli_w.dumps(d), source="cut lines")
            after = fio.project_from_multiblock_case(case)
        except (MeshcoreError, ValueError) as exc:
            self.error("Cannot split by cut lines", exc)
            return False
        after = after.replaced(crs=p.crs, origin=p.origin, source_crs=p.source_crs, title=p.title)
        self.editor.replace_project(after, f"Split into {len(after.blocks)} blocks")
        self.doc.set_active(0)
        self.set_tool("pan")
        self.message(
            f"Split into {len(after.blocks)} blocks (η cells {b.cells[1]} across every block); "
            "F5 solves them together — Ctrl+Z undoes the split"
        )
        return True

    def generate(self) -> None:
        if not any(b.ready for b in self.doc.project.blocks):
            b = self.doc.block
            if len(b.points) == 0:
                hint = "draw a boundary first"
            elif not b.closed:
                hint = "close the loop first (double-click or Enter)"
            else:
                hint = "pick four corners (Corners tool) or use Auto corners (A)"
            self.message(f"Nothing to generate yet: {hint}")
            return
        self.conv_panel.clear_history()
        self._frames = []
        self.solver.start()

    # ---------------------------------------------------------- reactions
    def _on_project(self, project: Project) -> None:
        self._update_title()
        pi = self.canvas.getPlotItem()
        if project.crs:
            ox, oy = project.origin
            pi.setLabel("bottom", f"x = E − {ox:.0f} m ({project.crs})")
            pi.setLabel("left", f"y = N − {oy:.0f} m")
        else:
            pi.setLabel("bottom", "")
            pi.setLabel("left", "")

    def _on_opened(self) -> None:
        self.conv_panel.clear_history()
        self.canvas.set_grid_stale(False)
        self._solver_label.setText("idle")

    def _on_progress(self, k: int, snap) -> None:
        if k == ALL_BLOCKS:  # a multiblock solve: relative residuals of the global iteration
            self.conv_panel.set_history(list(snap.history))
            self._solver_label.setText(f"multiblock: iteration {snap.iteration}, residual {snap.residual:.2e}")
            return
        if k == self.doc.active:
            length = max(snap.grid.size, 1e-300)  # history is absolute, residual relative
            self.conv_panel.set_history([(i, r / length) for i, r in snap.history], snap.tolerance)
        fr = [t for t in self._frames if t > self._frames[-1] - 1.0] if self._frames else []
        self._solver_label.setText(
            f"{snap.method}: iteration {snap.iteration}, residual {snap.residual:.2e} "
            f"(tol {snap.tolerance:.1e}), {len(fr)} redraws/s"
        )

    def _on_solver_state(self, state: str) -> None:
        running = state != "idle"
        self.doc.set_solving(running)
        self.a_pause.setEnabled(running)
        self.a_stop.setEnabled(running)
        self.a_pause.setChecked(state == "paused")
        if state == "paused":
            self._solver_label.setText("paused")

    def _on_solver_error(self, text: str) -> None:
        # the boundary cannot be gridded as it is: keep the old grid, greyed, and say why
        self.canvas.set_grid_stale(True)
        self.message(f"Cannot generate: {text}", error=True)
        self._solver_label.setText("error")

    def _on_finished(self, result) -> None:
        if result is not None and self.doc.project.multiblock is not None:
            self.doc.set_multiblock(getattr(result, "multiblock", None))
        self._on_final()

    def _on_final(self) -> None:
        g = self.doc.grid
        if self.solver.running or self.solver.last_error:
            return
        self.canvas.set_grid_stale(False)
        if g is None:
            self._solver_label.setText("idle")
            return
        info = g.info
        if info.residual_history:
            self.conv_panel.set_history(list(info.residual_history), info.tolerance)
        r = self.doc.quality
        dt = self.solver.t_done - self.solver.t_start
        state = "converged" if info.converged else info.message or "not converged"
        warn = f" — {r.n_folded} FOLDED cells (red ×)" if r is not None and r.n_folded else ""
        self._solver_label.setText(f"{info.method}: {state}, {info.iterations} iterations, {dt * 1000:.0f} ms")
        self.message(f"Grid {g.cells[0]}×{g.cells[1]} cells: {state}{warn}")

    # ------------------------------------------------------------- window
    def _update_title(self, *_a) -> None:
        try:
            clean = self.stack.isClean()
        except RuntimeError:  # the stack is gone while the window is being destroyed
            return
        name = self.doc.path.name if self.doc.path else (self.doc.project.title or "untitled")
        self.setWindowTitle(f"{name}{'' if clean else ' *'} — {APP_NAME}")

    def dragEnterEvent(self, ev: QtGui.QDragEnterEvent) -> None:
        if ev.mimeData().hasUrls():
            ev.acceptProposedAction()

    def dropEvent(self, ev: QtGui.QDropEvent) -> None:
        for url in ev.mimeData().urls():
            if url.isLocalFile():
                self.io.open_path(Path(url.toLocalFile()))
                break

    def closeEvent(self, ev: QtGui.QCloseEvent) -> None:
        if not self.io.maybe_save():
            ev.ignore()
            return
        self.solver.shutdown()
        self.io.shutdown()
        self.settings.setValue("geometry", self.saveGeometry())
        self.settings.setValue("window_state", self.saveState())
        ev.accept()

    def _restore_layout(self) -> None:
        """Window size and dock layout from the last session (if any)."""
        geom = self.settings.value("geometry")
        state = self.settings.value("window_state")
        with contextlib.suppress(TypeError):
            if geom is not None:
                self.restoreGeometry(geom)
            if state is not None:
                self.restoreState(state)

    # --------------------------------------------------------------- help
    def show_shortcuts(self) -> None:
        rows = "".join(f"<tr><td><b>{k}</b></td><td>&nbsp;&nbsp;{v}</td></tr>" for k, v in actions.shortcut_rows())
        QtWidgets.QMessageBox.information(self, "Keyboard shortcuts", f"<table>{rows}</table>")

    def show_about(self) -> None:
        import meshcore

        QtWidgets.QMessageBox.about(
            self,
            "About gcmesh",
            f"<b>gcmesh</b> {meshcore.__version__}<br>Structured boundary-fitted grids in generalized "
            "coordinates: algebraic start grid + Thompson–Thames–Mastin / Winslow elliptic smoothing.",
        )
