"""The main window: composition of canvas, docks, menus, toolbar and status bar.

It connects the components and turns menu actions into controller calls; the
logic lives in the document, commands, tools, solver controller and I/O
adapter.
"""

from __future__ import annotations

import contextlib
import pickle
import time
from pathlib import Path

import numpy as np
from PySide6 import QtCore, QtGui, QtWidgets

from meshcore import MeshcoreError

from . import geometry as geo
from . import io_adapter as fio
from .commands import Editor, SetBlockOptions
from .document import Document
from .examples import LAKES, example_names, load_example
from .pipeline import ALL_BLOCKS
from .project import Background, Block, Project, boundary_to_loop, default_cells
from .solver_controller import SolverController
from .tools import CalibrateTool, CornersTool, CutTool, DrawTool, EditTool, PanTool
from .views.canvas import Canvas
from .views.panels import BlocksPanel, ConvergencePanel, ParamsPanel, QualityPanel

__all__ = ["MainWindow"]

APP_NAME = "gcmesh"
MAX_RECENT = 8

SHORTCUTS = [
    ("Ctrl+N / Ctrl+O / Ctrl+S", "new, open, save project"),
    ("Ctrl+I", "import boundary points (or drop a file on the window)"),
    ("Ctrl+E", "export mesh"),
    ("Ctrl+Z / Ctrl+Shift+Z", "undo / redo"),
    ("P, D, E, C, L", "tools: pan, draw, edit, corners, cut line"),
    ("Enter / double-click", "close the loop being drawn (Draw) or finish a cut line"),
    ("Del", "delete selected points (Edit)"),
    ("Shift+drag", "snap a dragged point onto another point (Edit)"),
    ("drag on empty space", "box-select points (Edit); pan (other tools)"),
    ("wheel / right-drag", "zoom"),
    ("A", "auto corners"),
    ("Ctrl+K", "split the loop into blocks by the drawn cut lines"),
    ("F5", "generate"),
    ("Space", "pause / resume the solver"),
    ("Esc", "stop the solver"),
    ("Ctrl+Shift+A", "auto-generate on every edit"),
    ("F", "fit the view"),
]


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
        self.settings = settings or QtCore.QSettings("gcmesh", "gcmesh")
        self.doc = Document()
        self.stack = QtGui.QUndoStack(self)
        self.editor = Editor(self.doc, self.stack)
        self.solver = SolverController(self.doc, self)
        self._bg_cache: tuple[str, np.ndarray] | None = None
        self._frames: list[float] = []
        self.canvas = Canvas(self.doc)
        self.setCentralWidget(self.canvas)
        self._status = QtWidgets.QLabel()
        self._coords = QtWidgets.QLabel()
        self._solver_label = QtWidgets.QLabel("idle")
        self.statusBar().addWidget(self._status, 1)
        self.statusBar().addPermanentWidget(self._solver_label)
        self.statusBar().addPermanentWidget(self._coords)

        self._make_docks()
        self._make_tools()
        self._make_actions()
        self._make_menus()
        self._make_toolbar()
        self._connect()

        self.recovery_path = (
            recovery
            or Path(QtCore.QStandardPaths.writableLocation(QtCore.QStandardPaths.StandardLocation.AppDataLocation))
            / "recovery.gcmesh"
        )
        self._autosave = QtCore.QTimer(self)
        self._autosave.setInterval(15_000)
        self._autosave.timeout.connect(self.autosave)
        self._autosave.start()
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
        self.resizeDocks([self.docks["blocks"], self.docks["params"]], [230, 520], QtCore.Qt.Orientation.Vertical)
        self.resizeDocks([self.docks["quality"], self.docks["convergence"]], [560, 260], QtCore.Qt.Orientation.Vertical)
        self.resizeDocks([self.docks["blocks"], self.docks["quality"]], [300, 330], QtCore.Qt.Orientation.Horizontal)

    def _make_tools(self) -> None:
        ctx = (self.doc, self.editor, self.canvas, self.message)
        self.tools = {
            "pan": PanTool(*ctx),
            "draw": DrawTool(*ctx),
            "edit": EditTool(*ctx),
            "corners": CornersTool(*ctx),
            "cut": CutTool(*ctx),
            "calibrate": CalibrateTool(*ctx, on_pair=self._calibrate_pair),
        }
        self.tools["draw"].on_closed = lambda: self.set_tool("corners")
        self.tool_group = QtGui.QActionGroup(self)
        self.tool_actions = {}
        for key, t in self.tools.items():
            if key == "calibrate":
                continue
            a = QtGui.QAction(t.label, self, checkable=True, toolTip=f"{t.tip} ({t.shortcut})")
            a.setShortcut(QtGui.QKeySequence(t.shortcut))
            a.setStatusTip(t.tip)
            a.triggered.connect(lambda _c=False, k=key: self.set_tool(k))
            self.tool_group.addAction(a)
            self.tool_actions[key] = a

    def _act(self, text, slot, shortcut=None, tip=None, checkable=False) -> QtGui.QAction:
        a = QtGui.QAction(text, self, checkable=checkable)
        if shortcut:
            a.setShortcut(QtGui.QKeySequence(shortcut))
        if tip:
            a.setToolTip(tip)
            a.setStatusTip(tip)
        a.triggered.connect(slot)
        return a

    def _make_actions(self) -> None:
        K = QtGui.QKeySequence.StandardKey
        self.a_new = self._act("&New", self.new_project, K.New)
        self.a_open = self._act("&Open project…", self.open_dialog, K.Open)
        self.a_save = self._act("&Save project", self.save, K.Save)
        self.a_save_as = self._act("Save project &as…", self.save_as, K.SaveAs)
        self.a_import = self._act(
            "&Import boundary points…",
            self.import_dialog,
            "Ctrl+I",
            "CSV x,y or lon,lat; KML; GeoJSON; every format meshcore reads",
        )
        self.a_bg = self._act("Load &background image…", self.background_dialog)
        self.a_calib = self._act("&Calibrate background by two points", lambda: self.set_tool("calibrate"))
        self.a_export = self._act("&Export mesh…", self.export_dialog, "Ctrl+E")
        self.a_figure = self._act("Export &figure (PNG/SVG)…", self.figure_dialog, "Ctrl+Shift+E")
        self.a_quit = self._act("&Quit", self.close, K.Quit)
        self.a_undo = self.stack.createUndoAction(self, "&Undo")
        self.a_undo.setShortcut(QtGui.QKeySequence("Ctrl+Z"))
        self.a_redo = self.stack.createRedoAction(self, "&Redo")
        self.a_redo.setShortcuts([QtGui.QKeySequence("Ctrl+Shift+Z"), QtGui.QKeySequence("Ctrl+Y")])
        self.a_delete = self._act(
            "&Delete selected points", lambda: self.editor.delete_points(self.doc.selection), K.Delete
        )
        self.a_select_all = self._act(
            "Select &all points", lambda: self.doc.set_selection(range(len(self.doc.block.points))), K.SelectAll
        )
        self.a_auto_corners = self._act(
            "&Auto corners",
            self.auto_corners,
            "A",
            "corners at the vertices nearest the principal-axis bounding box corners",
        )
        self.a_add_block = self._act("Add &block", self.editor.add_block)
        self.a_del_block = self._act("&Delete block", lambda: self.editor.delete_block())
        self.a_to_loop = self._act("&Convert borders to an editable loop", self.convert_to_loop)
        self.a_split = self._act(
            "&Split into blocks by cut lines",
            self.split_by_cuts,
            "Ctrl+K",
            "each region between the cut lines becomes a block; all blocks are solved together (meshcore.multiblock)",
        )
        self.a_generate = self._act("&Generate", self.generate, "F5", "build the algebraic grid and solve")
        self.a_pause = self._act("&Pause", self.solver.toggle_pause, "Space", "pause / resume", checkable=True)
        self.a_stop = self._act("&Stop", self.solver.stop, "Esc", "stop the solver (keeps the current grid)")
        self.a_auto = self._act(
            "A&uto-generate on edit",
            self.solver.set_auto,
            "Ctrl+Shift+A",
            "re-solve automatically after every edit (live remesh)",
            checkable=True,
        )
        self.a_fit = self._act("&Fit view", self.canvas.fit, "F")
        self.a_shortcuts = self._act("&Keyboard shortcuts", self.show_shortcuts, K.HelpContents)
        self.a_about = self._act("&About", self.show_about)
        self.a_pause.setEnabled(False)
        self.a_stop.setEnabled(False)

    def _make_menus(self) -> None:
        mb = self.menuBar()
        m = mb.addMenu("&File")
        m.addActions([self.a_new, self.a_open])
        self.recent_menu = m.addMenu("Open &recent")
        m.addActions([self.a_save, self.a_save_as])
        m.addSeparator()
        m.addActions([self.a_import, self.a_bg, self.a_calib])
        m.addSeparator()
        m.addActions([self.a_export, self.a_figure])
        m.addSeparator()
        m.addAction(self.a_quit)
        m = mb.addMenu("&Edit")
        m.addActions([self.a_undo, self.a_redo])
        m.addSeparator()
        m.addActions([self.a_delete, self.a_select_all])
        m = mb.addMenu("&Tools")
        m.addActions(list(self.tool_actions.values()))
        m = mb.addMenu("&Block")
        m.addActions([self.a_auto_corners, self.a_add_block, self.a_del_block, self.a_to_loop])
        m.addSeparator()
        m.addAction(self.a_split)
        m = mb.addMenu("&Generate")
        m.addActions([self.a_generate, self.a_pause, self.a_stop, self.a_auto])
        m = mb.addMenu("&View")
        m.addAction(self.a_fit)
        m.addSeparator()
        for d in self.docks.values():
            m.addAction(d.toggleViewAction())
        m = mb.addMenu("E&xamples")
        lakes = [n for n in example_names() if n in LAKES]
        m.addSection("Paper cases")
        for name in example_names():
            if name not in LAKES:
                m.addAction(name, lambda n=name: self.open_example(n))
        m.addSection("Real lakes (GSHHG, lon/lat → UTM)")
        for name in lakes:
            a = m.addAction(name, lambda n=name: self.open_example(n))
            a.setToolTip(LAKES[name][1])
        m = mb.addMenu("&Help")
        m.addActions([self.a_shortcuts, self.a_about])
        self._refresh_recent()

    def _make_toolbar(self) -> None:
        tb = self.addToolBar("Main")
        tb.setObjectName("main-toolbar")
        tb.setToolButtonStyle(QtCore.Qt.ToolButtonStyle.ToolButtonTextOnly)
        tb.addActions([self.a_open, self.a_import, self.a_save])
        tb.addSeparator()
        tb.addActions(list(self.tool_actions.values()))
        self.tool_actions["cut"].setToolTip(
            "Cut line: click a polyline from shore to shore (double-click / Enter ends it), then "
            "Block ▸ Split into blocks by cut lines (Ctrl+K)"
        )
        tb.addAction(self.a_auto_corners)
        tb.addSeparator()
        tb.addActions([self.a_generate, self.a_pause, self.a_stop, self.a_auto])
        tb.addSeparator()
        tb.addAction(self.a_fit)

    def _connect(self) -> None:
        self.doc.message.connect(self.message)
        self.solver.error.connect(self._on_solver_error)
        self.doc.grids_changed.connect(self._on_grids)
        self.doc.project_changed.connect(self._on_project)
        self.doc.active_changed.connect(lambda _k: self._on_final())
        self.canvas.hovered.connect(self._show_coords)
        self.blocks_panel.border_selected.connect(self.params_panel.select_border)
        self.quality_panel.colour_requested.connect(self._colour)
        self.quality_panel.zoom_to_cell.connect(self.zoom_to_cell)
        self.solver.state_changed.connect(self._on_solver_state)
        self.solver.progress.connect(self._on_progress)
        self.solver.finished.connect(lambda _r: self._on_final())
        self.stack.cleanChanged.connect(self._update_title)

    def _show_coords(self, x: float, y: float) -> None:
        p = self.doc.project
        text = f"x = {x:.6g}   y = {y:.6g}"
        if p.crs:
            text += f"   ({p.crs}: E {x + p.origin[0]:.1f}  N {y + p.origin[1]:.1f})"
        cell = self._cell_readout(x, y)
        self._coords.setText(f"{cell}   {text}" if cell else text)

    def _cell_readout(self, x: float, y: float) -> str:
        """The coloured metric of the cell under the cursor (nearest cell centre, if inside it)."""
        qp = self.quality_panel
        values, label = qp._values()
        g = qp._grid
        if values is None or g is None or self.solver.running:
            return ""
        if getattr(self, "_centres_of", None) is not g:
            self._centres = (
                0.25 * (g.x[:-1, :-1] + g.x[1:, :-1] + g.x[1:, 1:] + g.x[:-1, 1:]),
                0.25 * (g.y[:-1, :-1] + g.y[1:, :-1] + g.y[1:, 1:] + g.y[:-1, 1:]),
            )
            self._centres_of = g
        cx, cy = self._centres
        d = np.hypot(cx - x, cy - y)
        i, j = np.unravel_index(int(np.argmin(d)), d.shape)
        size = np.hypot(g.x[i + 1, j + 1] - g.x[i, j], g.y[i + 1, j + 1] - g.y[i, j])
        if d[i, j] > size:
            return ""
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

    def message(self, text: str, *, error: bool = False) -> None:
        self._status.setText(text)
        self._status.setToolTip(text)
        self._status.setStyleSheet("color: #b00000; font-weight: bold;" if error else "")

    def error(self, title: str, exc: BaseException | str) -> None:
        text = str(exc)
        self.message(f"{title}: {text}", error=True)
        if not getattr(self, "quiet", False):
            QtWidgets.QMessageBox.warning(self, title, text)

    # -------------------------------------------------------------- edits
    def auto_corners(self) -> None:
        b = self.doc.block
        if not b.closed or len(b.points) < 4:
            self.message("Auto corners needs a closed loop of at least 4 points")
            return
        try:
            c = _corners(b.points)
        except (ValueError, MeshcoreError) as exc:
            self.error("Auto corners", exc)
            return
        self.editor.set_corners(c)
        self.message("Corners chosen automatically (yellow squares); adjust them with the Corners tool")

    def convert_to_loop(self) -> None:
        b = self.doc.block
        if b.boundary is None:
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
            hint = (
                "draw a boundary first"
                if len(b.points) == 0
                else "close the loop first (double-click or Enter)"
                if not b.closed
                else "pick four corners (Corners tool) or use Auto corners (A)"
            )
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
        bg = project.background
        if bg is None:
            self.canvas.set_background(None)
        else:
            img = self._load_image(bg.path)
            if img is not None:
                self.canvas.set_background(img, bg.transform)

    def _on_grids(self) -> None:
        self.canvas.set_grids(self.doc.grids)
        self._frames.append(time.perf_counter())
        if self.solver.running and self.canvas.quality_item is not None:
            self.canvas.set_quality(None, None)

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
        self.a_pause.setEnabled(running)
        self.a_stop.setEnabled(running)
        self.a_pause.setChecked(state == "paused")
        if state == "paused":
            self._solver_label.setText("paused")

    def _on_solver_error(self, text: str) -> None:
        # the boundary cannot be gridded as it is: keep the old grid, greyed, and say why
        self.canvas.set_grid_stale(True)
        self.canvas.set_quality(None, None)
        self.message(f"Cannot generate: {text}", error=True)
        self._solver_label.setText("error")

    def _on_final(self) -> None:
        g = self.doc.grid
        if self.solver.running:
            return
        if self.solver.last_error:
            return
        self.canvas.set_grid_stale(False)
        self.quality_panel.update_grid(g)
        if g is None:
            self._solver_label.setText("idle")
            self.canvas.set_folded(None, None)
            return
        info = g.info
        if info.residual_history:
            self.conv_panel.set_history(list(info.residual_history), info.tolerance)
        r = self.quality_panel.report
        cells = r.folded if r is not None else None
        self.canvas.set_folded(g, cells)
        dt = self.solver.t_done - self.solver.t_start
        state = "converged" if info.converged else info.message or "not converged"
        warn = f" — {r.n_folded} FOLDED cells (red ×)" if r is not None and r.n_folded else ""
        self._solver_label.setText(f"{info.method}: {state}, {info.iterations} iterations, {dt * 1000:.0f} ms")
        self.message(f"Grid {g.cells[0]}×{g.cells[1]} cells: {state}{warn}")

    def _colour(self, grid, values, label: str) -> None:
        try:
            self.canvas.set_quality(grid, values, label=label)
        except Exception as exc:  # drawing problems must not kill the window
            self.message(f"cannot colour cells: {exc}")

    def zoom_to_cell(self, i: int, j: int) -> None:
        g = self.doc.grid
        if g is None:
            return
        ni, nj = g.cells
        i0, i1 = max(i - 3, 0), min(i + 4, ni)
        j0, j1 = max(j - 3, 0), min(j + 4, nj)
        xs, ys = g.x[i0 : i1 + 1, j0 : j1 + 1], g.y[i0 : i1 + 1, j0 : j1 + 1]
        self.canvas.zoom_to((xs.min(), ys.min(), xs.max(), ys.max()), margin=0.1)
        cx = 0.25 * (g.x[i, j] + g.x[i + 1, j] + g.x[i + 1, j + 1] + g.x[i, j + 1])
        cy = 0.25 * (g.y[i, j] + g.y[i + 1, j] + g.y[i + 1, j + 1] + g.y[i, j + 1])
        self.canvas.highlight_item.setData([cx], [cy])

    # ------------------------------------------------------------- files
    def _update_title(self, *_a) -> None:
        try:
            clean = self.stack.isClean()
        except RuntimeError:  # the stack is gone while the window is being destroyed
            return
        name = self.doc.path.name if self.doc.path else (self.doc.project.title or "untitled")
        self.setWindowTitle(f"{name}{'' if clean else ' *'} — {APP_NAME}")

    def maybe_save(self) -> bool:
        """Ask about unsaved changes; False when the user cancels."""
        if self.stack.isClean() or getattr(self, "quiet", False):
            return True
        r = QtWidgets.QMessageBox.question(
            self,
            "Unsaved changes",
            "The project has unsaved changes. Save them?",
            QtWidgets.QMessageBox.StandardButton.Save
            | QtWidgets.QMessageBox.StandardButton.Discard
            | QtWidgets.QMessageBox.StandardButton.Cancel,
        )
        if r == QtWidgets.QMessageBox.StandardButton.Cancel:
            return False
        if r == QtWidgets.QMessageBox.StandardButton.Save:
            return self.save()
        return True

    def set_project(self, project: Project, path: Path | None = None) -> None:
        self.solver.stop()
        self.stack.clear()
        self.doc.reset(project, path)
        self.conv_panel.clear_history()
        self.canvas.set_quality(None, None)
        self.canvas.set_folded(None, None)
        self.quality_panel.update_grid(None)
        self.canvas.fit()
        self.stack.setClean()
        self._update_title()

    def new_project(self) -> None:
        if self.maybe_save():
            self.set_project(Project())
            self.set_tool("draw")

    def open_dialog(self) -> None:
        if not self.maybe_save():
            return
        path, _ = QtWidgets.QFileDialog.getOpenFileName(
            self, "Open project", self._last_dir(), "gcmesh case (*.toml);;All files (*)"
        )
        if path:
            self.open_path(path)

    def open_path(self, path) -> bool:
        """Open a case file, or import a point file (by suffix)."""
        path = Path(path)
        if path.suffix.lower() != ".toml":
            return self.import_points(path)
        try:
            project = fio.load_project(path)
        except (MeshcoreError, OSError) as exc:
            self.error("Cannot open project", exc)
            return False
        self.set_project(project, path)
        self._add_recent(path)
        self.set_tool("edit")
        self.message(f"Opened {path.name}: press F5 to generate")
        return True

    def open_example(self, name: str, *, confirm: bool = True) -> bool:
        if confirm and not self.maybe_save():
            return False
        try:
            project, _path = load_example(name)
        except (MeshcoreError, OSError, KeyError) as exc:
            self.error("Cannot open example", exc)
            return False
        self.set_project(project, None)
        self.set_tool("edit")
        self.message(f"Example {name!r}: press F5 to generate; drag points to reshape")
        return True

    def save(self) -> bool:
        if self.doc.path is None:
            return self.save_as()
        return self._save_to(self.doc.path)

    def save_as(self) -> bool:
        path, _ = QtWidgets.QFileDialog.getSaveFileName(self, "Save project", self._last_dir(), "gcmesh case (*.toml)")
        if not path:
            return False
        if not path.endswith(".toml"):
            path += ".toml"
        return self._save_to(Path(path))

    def _save_to(self, path: Path) -> bool:
        try:
            fio.save_project(self.doc.project, path)
        except (MeshcoreError, OSError, ValueError) as exc:
            self.error("Cannot save project", exc)
            return False
        self.doc.set_path(path)
        self.stack.setClean()
        self._add_recent(path)
        p = self.doc.project
        skipped = [b.name for b in p.blocks if not b.ready and (len(b.points) or b.boundary is not None)]
        note = f" (not saved: {', '.join(skipped)} — no closed loop with corners yet)" if skipped else ""
        self.message(f"Saved {path}{note}", error=bool(skipped))
        return True

    def import_dialog(self) -> None:
        path, _ = QtWidgets.QFileDialog.getOpenFileName(
            self, "Import boundary points", self._last_dir(), fio.POINT_FILTER
        )
        if path:
            self.import_points(Path(path))

    def import_points(self, path: Path, *, project_lonlat: bool | None = None) -> bool:
        """Read points as a new closed block with automatic corners (undoable)."""
        try:
            pd = fio.read_points(path)
        except (MeshcoreError, OSError, ValueError) as exc:
            self.error("Cannot import points", exc)
            return False
        pts = pd.points
        p = self.doc.project
        frame = fio.project_frame(p)
        if pd.lonlat:
            if project_lonlat is None and not getattr(self, "quiet", False):
                target = frame.crs if frame is not None else "the UTM zone of the outline"
                r = QtWidgets.QMessageBox.question(
                    self,
                    "Geographic coordinates",
                    f"{path.name} holds longitude/latitude degrees.\n\nProject them to metres "
                    f"({target}, relative to a round local origin)? Grids in degrees are distorted.",
                )
                project_lonlat = r == QtWidgets.QMessageBox.StandardButton.Yes
            if project_lonlat is None or project_lonlat:
                try:
                    pts, frame = fio.to_local(pd, frame)
                except (MeshcoreError, ValueError) as exc:
                    self.error("Cannot project coordinates", exc)
                    return False
        if len(pts) < 4:
            self.error("Cannot import points", f"{path}: needs at least 4 points, found {len(pts)}")
            return False
        try:
            corners = _corners(pts)
        except (ValueError, MeshcoreError):
            corners = None
        p = self.doc.project
        block = Block(
            name=path.stem,
            points=pts,
            closed=True,
            corners=corners,
            cells=default_cells(pts, corners, total=40, minimum=8) if corners else (32, 16),
        )
        empty = [k for k, b in enumerate(p.blocks) if len(b.points) == 0 and b.boundary is None]
        if empty:
            after = p.with_block(empty[0], block)
            k = empty[0]
        else:
            after = p.replaced(blocks=(*p.blocks, block))
            k = len(after.blocks) - 1
        if frame is not None and frame.crs:
            after = after.replaced(crs=frame.crs, origin=tuple(frame.origin), source_crs=frame.source_crs or "")
        self.editor.replace_project(after, f"Import {path.name}")
        self.doc.set_active(k)
        self.canvas.fit()
        self.set_tool("edit")
        self._remember_dir(path)
        self.message(
            f"Imported {len(pts)} points from {path.name}"
            f"{' (projected to ' + frame.crs + ')' if frame is not None and pd.lonlat else ''}; corners chosen "
            f"automatically — adjust with the Corners tool, then F5"
        )
        return True

    def export_dialog(self) -> None:
        grids = [self.doc.grids[k] for k in sorted(self.doc.grids)]
        if not grids:
            self.message("Nothing to export yet: generate a grid first (F5)")
            return
        fmts = fio.mesh_formats()
        filt = ";;".join(f"{d} ({p})" for d, p in fmts)
        path, chosen = QtWidgets.QFileDialog.getSaveFileName(self, "Export mesh", self._last_dir(), filt)
        if path:
            if not Path(path).suffix:
                pat = next((p for d, p in fmts if chosen.startswith(d)), "*.vts")
                path += pat.split()[0].lstrip("*")
            self.export_mesh(Path(path))

    def export_mesh(self, path: Path) -> bool:
        grids = [self.doc.grids[k] for k in sorted(self.doc.grids)]
        try:
            mb = getattr(self.solver.last_result, "multiblock", None)
            if mb is not None and self.doc.project.multiblock is not None and not self.doc.stale:
                fio.write_mesh(path, mb, fio.project_frame(self.doc.project))  # with its connectivity
            else:
                fio.write_mesh(path, grids, fio.project_frame(self.doc.project))
        except (MeshcoreError, OSError) as exc:
            self.error("Cannot export mesh", exc)
            return False
        self._remember_dir(path)
        self.message(f"Exported {len(grids)} block(s) to {path}")
        return True

    def figure_dialog(self) -> None:
        path, _ = QtWidgets.QFileDialog.getSaveFileName(
            self, "Export figure", self._last_dir(), "PNG image (*.png);;SVG vector (*.svg)"
        )
        if path:
            if not Path(path).suffix:
                path += ".png"
            try:
                self.canvas.export_image(path)
                self.message(f"Saved figure {path}")
            except Exception as exc:
                self.error("Cannot export figure", exc)

    def dragEnterEvent(self, ev: QtGui.QDragEnterEvent) -> None:
        if ev.mimeData().hasUrls():
            ev.acceptProposedAction()

    def dropEvent(self, ev: QtGui.QDropEvent) -> None:
        for url in ev.mimeData().urls():
            if url.isLocalFile():
                self.open_path(Path(url.toLocalFile()))
                break

    # --------------------------------------------------------- background
    def _load_image(self, path: str) -> np.ndarray | None:
        if self._bg_cache is not None and self._bg_cache[0] == path:
            return self._bg_cache[1]
        img = QtGui.QImage(path)
        if img.isNull():
            self.message(f"cannot load background image {path}")
            return None
        img = img.convertToFormat(QtGui.QImage.Format.Format_RGBA8888)
        w, h = img.width(), img.height()
        arr = np.frombuffer(img.constBits(), dtype=np.uint8, count=img.sizeInBytes())
        arr = arr.reshape(h, img.bytesPerLine())[:, : 4 * w].reshape(h, w, 4)
        arr = np.flipud(arr).copy()  # row 0 = bottom row: v runs upwards like y
        self._bg_cache = (path, arr)
        return arr

    def background_dialog(self) -> None:
        path, _ = QtWidgets.QFileDialog.getOpenFileName(
            self, "Background image", self._last_dir(), "Images (*.png *.jpg *.jpeg *.tif *.bmp)"
        )
        if path:
            self.load_background(path)

    def load_background(self, path: str) -> None:
        img = self._load_image(path)
        if img is None:
            return
        h, w = img.shape[:2]
        b = self.doc.project.bounds()
        if b is not None:  # fit the image over the current points
            s = max((b[2] - b[0]) / w, (b[3] - b[1]) / h)
            tr = (s, 0.0, b[0], b[1])
        else:
            tr = (1.0, 0.0, 0.0, 0.0)
        self.editor.replace_project(self.doc.project.replaced(background=Background(str(path), tr)), "Load background")
        self.canvas.fit() if b is None else None
        self.message("Background loaded: File ▸ Calibrate to place it by two known points, then trace with Draw")

    def _calibrate_pair(self, pair) -> None:
        bg = self.doc.project.background
        if bg is None:
            self.message("Load a background image first")
            self.set_tool("pan")
            return
        dlg = QtWidgets.QDialog(self)
        dlg.setWindowTitle("Calibrate background")
        f = QtWidgets.QFormLayout(dlg)
        edits = []
        for k, (x, y) in enumerate(pair):
            ex, ey = QtWidgets.QLineEdit(f"{x:.6g}"), QtWidgets.QLineEdit(f"{y:.6g}")
            row = QtWidgets.QHBoxLayout()
            row.addWidget(ex)
            row.addWidget(ey)
            f.addRow(f"true x, y of point {k + 1}", row)
            edits += [ex, ey]
        bb = QtWidgets.QDialogButtonBox(
            QtWidgets.QDialogButtonBox.StandardButton.Ok | QtWidgets.QDialogButtonBox.StandardButton.Cancel
        )
        bb.accepted.connect(dlg.accept)
        bb.rejected.connect(dlg.reject)
        f.addRow(bb)
        if dlg.exec() != QtWidgets.QDialog.DialogCode.Accepted:
            return
        try:
            vals = [float(e.text()) for e in edits]
            self.calibrate_background(pair, ((vals[0], vals[1]), (vals[2], vals[3])))
        except ValueError as exc:
            self.error("Calibration", exc)
        self.set_tool("draw")

    def calibrate_background(self, shown, true) -> None:
        """Move the background so that the two ``shown`` model points land on ``true``."""
        bg = self.doc.project.background
        a, b, tx, ty = geo.similarity_from_pairs(shown[0], true[0], shown[1], true[1])
        m_s, t_s = complex(a, b), complex(tx, ty)
        a0, b0, tx0, ty0 = bg.transform
        m, t = m_s * complex(a0, b0), m_s * complex(tx0, ty0) + t_s
        nb = Background(bg.path, (m.real, m.imag, t.real, t.imag))
        self.editor.replace_project(self.doc.project.replaced(background=nb), "Calibrate background")
        self.message("Background calibrated")

    # ------------------------------------------------------------ safety
    def autosave(self) -> None:
        """Write the project to the recovery file when it has unsaved edits."""
        if self.stack.isClean():
            return
        try:
            self.recovery_path.parent.mkdir(parents=True, exist_ok=True)
            tmp = self.recovery_path.with_suffix(".tmp")
            tmp.write_bytes(
                pickle.dumps({"project": self.doc.project, "path": str(self.doc.path) if self.doc.path else None})
            )
            tmp.replace(self.recovery_path)
        except OSError as exc:
            self.message(f"autosave failed: {exc}")

    def offer_recovery(self) -> bool:
        """After a crash: offer the recovery file back (True when restored)."""
        if not self.recovery_path.exists():
            return False
        try:
            data = pickle.loads(self.recovery_path.read_bytes())
            project = data["project"]
        except Exception:
            self.recovery_path.unlink(missing_ok=True)
            return False
        r = QtWidgets.QMessageBox.question(
            self, "Recover project", "gcmesh did not shut down cleanly last time. Restore the autosaved project?"
        )
        if r != QtWidgets.QMessageBox.StandardButton.Yes:
            self.recovery_path.unlink(missing_ok=True)
            return False
        self.set_project(project, Path(data["path"]) if data.get("path") else None)
        self.stack.resetClean()
        self._update_title()
        return True

    def closeEvent(self, ev: QtGui.QCloseEvent) -> None:
        if not self.maybe_save():
            ev.ignore()
            return
        self.solver.shutdown()
        self._autosave.stop()
        with contextlib.suppress(OSError):
            self.recovery_path.unlink(missing_ok=True)
        self.settings.setValue("geometry", self.saveGeometry())
        self.settings.setValue("window_state", self.saveState())
        ev.accept()

    # ----------------------------------------------------------- settings
    def _restore_layout(self) -> None:
        """Window size and dock layout from the last session (if any)."""
        geom = self.settings.value("geometry")
        state = self.settings.value("window_state")
        with contextlib.suppress(TypeError):
            if geom is not None:
                self.restoreGeometry(geom)
            if state is not None:
                self.restoreState(state)

    def _last_dir(self) -> str:
        return str(self.settings.value("last_dir", str(Path.home())))

    def _remember_dir(self, path: Path) -> None:
        self.settings.setValue("last_dir", str(Path(path).parent))

    def _add_recent(self, path: Path) -> None:
        rec = [str(path)] + [p for p in self._recent() if p != str(path)]
        self.settings.setValue("recent", rec[:MAX_RECENT])
        self._remember_dir(path)
        self._refresh_recent()

    def _recent(self) -> list[str]:
        v = self.settings.value("recent", [])
        if isinstance(v, str):
            v = [v]
        return list(v or [])

    def _refresh_recent(self) -> None:
        self.recent_menu.clear()
        rec = self._recent()
        for p in rec:
            self.recent_menu.addAction(p, lambda p=p: self.maybe_save() and self.open_path(p))
        self.recent_menu.setEnabled(bool(rec))

    # --------------------------------------------------------------- help
    def show_shortcuts(self) -> None:
        rows = "".join(f"<tr><td><b>{k}</b></td><td>&nbsp;&nbsp;{v}</td></tr>" for k, v in SHORTCUTS)
        QtWidgets.QMessageBox.information(self, "Keyboard shortcuts", f"<table>{rows}</table>")

    def show_about(self) -> None:
        import meshcore

        QtWidgets.QMessageBox.about(
            self,
            "About gcmesh",
            f"<b>gcmesh</b> {meshcore.__version__}<br>Structured boundary-fitted grids in generalized "
            "coordinates: algebraic start grid + Thompson–Thames–Mastin / Winslow elliptic smoothing.",
        )


def _corners(points) -> tuple[int, int, int, int]:
    """Automatic corners: :func:`app.geometry.auto_corners` (principal box or tip caps,
    off reflex vertices via :mod:`meshcore.corners`, bottom kept at the bottom)."""
    return geo.auto_corners(np.asarray(points))
