"""Every menu entry, toolbar button and shortcut of the window, from one table.

Each row of :data:`ACTIONS` is one :class:`ActionSpec`: the text, the
shortcuts (the first is the one menus show), the tip, the slot (a dotted path
from the window, e.g. ``"io.save"``), the menu it sits in and its place on the
toolbar.  :func:`build` makes the ``QAction`` objects (``window.a_<key>``),
the menus and the toolbar; :func:`shortcut_rows` makes the keyboard help from
the same rows.  A slot starting with ``@`` is a placeholder the window fills
(the recent-files submenu, the dock toggles, the example list).
"""

from __future__ import annotations

from dataclasses import dataclass
from operator import attrgetter

from PySide6 import QtCore, QtGui, QtWidgets

from .layout_tools import CutTool, LayoutTool
from .tools import CornersTool, DrawTool, EditTool, PanTool

__all__ = ["ACTIONS", "GESTURES", "ActionSpec", "build", "shortcut_rows"]

K = QtGui.QKeySequence.StandardKey

#: The tools on the toolbar and in the Tools menu, in their order (calibrate is started from the
#: background's menu).
TOOLS = (PanTool, DrawTool, EditTool, CornersTool, CutTool, LayoutTool)


@dataclass(frozen=True, slots=True)
class ActionSpec:
    """One action: what it says, what it does, where it is."""

    key: str  # the window attribute is ``a_<key>``
    text: str
    slot: str  # dotted path from the window ("io.save"), "@name" for a placeholder
    shortcuts: tuple = ()  # strings or QKeySequence.StandardKey; the first is shown in menus
    tip: str = ""
    menu: str = ""
    separator: bool = False  # a separator line before it in its menu
    toolbar: float = 0.0  # 0: not on the toolbar; else its place (the integer part groups buttons)
    checkable: bool = False
    checked: bool = False  # the initial state of a checkable action
    enabled: bool = True
    help: str = ""  # the line in Help ▸ Keyboard shortcuts (default: the text)
    short: str = ""  # the toolbar's text, when shorter than the menu's (default: the text)


def _tool_rows() -> tuple[ActionSpec, ...]:
    return tuple(
        ActionSpec(
            f"tool_{t.name}",
            t.label,
            f"@tool:{t.name}",
            (t.shortcut,),
            f"{t.tip} ({t.shortcut})",
            "&Tools",
            toolbar=2 + k / 10,
            checkable=True,
            help=f"tool: {t.label.lower()}",
        )
        for k, t in enumerate(TOOLS)
    )


ACTIONS: tuple[ActionSpec, ...] = (
    # File
    ActionSpec("new", "&New", "io.new_project", (K.New,), menu="&File", help="new project"),
    ActionSpec(
        "open", "&Open project…", "io.open_dialog", (K.Open,), menu="&File", toolbar=1.1, help="open", short="Open…"
    ),
    ActionSpec("recent", "Open &recent", "@recent", menu="&File"),
    ActionSpec(
        "save", "&Save project", "io.save", (K.Save,), menu="&File", toolbar=1.3, help="save project", short="Save"
    ),
    ActionSpec("save_as", "Save project &as…", "io.save_as", (K.SaveAs,), menu="&File"),
    ActionSpec(
        "import",
        "&Import boundary points…",
        "io.import_dialog",
        ("Ctrl+I",),
        "CSV x,y or lon,lat; KML; GeoJSON; every format meshcore reads",
        "&File",
        separator=True,
        toolbar=1.2,
        help="import boundary points (or drop a file on the window)",
        short="Import…",
    ),
    ActionSpec("bg", "Load &background image…", "background.dialog", menu="&File"),
    ActionSpec("calib", "&Calibrate background by two points", "@tool:calibrate", menu="&File"),
    ActionSpec("export", "&Export mesh…", "io.export_dialog", ("Ctrl+E",), menu="&File", separator=True),
    ActionSpec("figure", "Export &figure (PNG/SVG)…", "io.figure_dialog", ("Ctrl+Shift+E",), menu="&File"),
    ActionSpec("quit", "&Quit", "close", (K.Quit,), menu="&File", separator=True),
    # Edit (undo/redo name the step, as the undo stack's actions do; Ctrl+Z in a drag cancels it: MainWindow.undo)
    ActionSpec("undo", "&Undo", "@undo", ("Ctrl+Z",), menu="&Edit", help="undo"),
    ActionSpec("redo", "&Redo", "@redo", ("Ctrl+Y", "Ctrl+Shift+Z"), menu="&Edit", help="redo"),
    ActionSpec("delete", "&Delete selected points", "delete_selection", (K.Delete,), menu="&Edit", separator=True),
    ActionSpec("select_all", "Select &all points", "select_all", (K.SelectAll,), menu="&Edit"),
    *_tool_rows(),
    # Block
    ActionSpec(
        "auto_corners",
        "&Auto corners",
        "auto_corners",
        ("A",),
        "corners at the vertices nearest the principal-axis bounding box corners",
        "&Block",
        toolbar=3,
    ),
    ActionSpec("add_block", "Add &block", "editor.add_block", menu="&Block"),
    ActionSpec("del_block", "&Delete block", "editor.delete_block", menu="&Block"),
    ActionSpec("to_loop", "&Convert borders to an editable loop", "convert_to_loop", menu="&Block"),
    ActionSpec(
        "split",
        "&Split into blocks by cut lines",
        "split_by_cuts",
        ("Ctrl+K",),
        "each region between the cut lines becomes a block; all blocks are solved together (meshcore.multiblock)",
        "&Block",
        separator=True,
    ),
    # Lake
    ActionSpec(
        "auto_layout",
        "&Auto layout",
        "lake_ctl.auto_layout",
        ("Ctrl+L",),
        "split the lake into four-sided blocks that follow its arms (cell size in the Lake panel), then generate",
        "&Lake",
        toolbar=3.5,
        help="auto layout of a lake",
    ),
    ActionSpec(
        "auto_layout_regular",
        "Auto layout, &regular (Delft3D DD)",
        "auto_layout_regular",
        tip="a layout without corners where 3 or 5 blocks meet: what Delft3D domain decomposition can couple",
        menu="&Lake",
    ),
    ActionSpec(
        "auto_layout_single",
        "Auto layout, &one index space (EFDC, Delft3D single domain)",
        "auto_layout_single",
        tip="a regular layout whose rings of blocks round islands close in one (I, J) index space: what EFDC "
        "and a Delft3D single-domain grid need",
        menu="&Lake",
    ),
    ActionSpec(
        "clear_layout",
        "&Clear layout",
        "editor.clear_layout",
        tip="back to the shore as one editable block",
        menu="&Lake",
    ),
    ActionSpec("lake_panel", "Lake &panel", "show_lake", menu="&Lake", separator=True),
    # Generate
    ActionSpec(
        "generate", "&Generate", "generate", ("F5",), "build the algebraic grid and solve", "&Generate", toolbar=4.1
    ),
    ActionSpec(
        "pause",
        "&Pause",
        "solver.toggle_pause",
        ("Space",),
        "pause / resume",
        "&Generate",
        toolbar=4.2,
        checkable=True,
        enabled=False,
        help="pause / resume the solver",
    ),
    ActionSpec(
        "stop",
        "&Stop",
        "stop",
        ("Esc",),
        "stop the solver (keeps the current grid; a lake grid stopped on a coarse level: none, that one greyed)"
        " or Auto layout (nothing set); in a drag: cancel the drag",
        "&Generate",
        toolbar=4.3,
        enabled=False,
        help="stop the solver or Auto layout",
    ),
    ActionSpec(
        "auto",
        "A&uto-generate on edit",
        "solver.set_auto",
        ("Ctrl+Shift+A",),
        "re-solve automatically after every edit (live remesh)",
        "&Generate",
        toolbar=4.4,
        checkable=True,
        short="Live",
    ),
    # View
    ActionSpec("fit", "&Fit view", "canvas.fit", ("F",), menu="&View", toolbar=5, help="fit the view", short="Fit"),
    ActionSpec(
        "grid_lines",
        "&Grid lines",
        "canvas.set_grid_visible",
        ("G",),
        "show the grid lines (they fade by themselves when the cells are only a few pixels wide)",
        "&View",
        separator=True,
        checkable=True,
        checked=True,
        help="show / hide the grid lines",
    ),
    ActionSpec(
        "markers",
        "&Boundary points and markers",
        "canvas.set_markers_visible",
        ("M",),
        "show the boundary points, corners, border arrows and labels (hide them to see a zoomed-out grid)",
        "&View",
        checkable=True,
        checked=True,
        help="show / hide the boundary points and markers",
    ),
    ActionSpec(
        "misses",
        "Preset &misses",
        "show_misses",
        ("Q",),
        "mark the places that miss the quality preset's selected limit (off by itself while a metric "
        "colours the cells: then they are thin rings)",
        "&View",
        checkable=True,
        checked=True,
        help="show / hide the places that miss the quality preset",
    ),
    ActionSpec("docks", "", "@docks", menu="&View", separator=True),
    ActionSpec("examples", "", "@examples", menu="E&xamples"),
    # Help
    ActionSpec("shortcuts", "&Keyboard shortcuts", "show_shortcuts", (K.HelpContents,), menu="&Help"),
    ActionSpec("about", "&About", "show_about", menu="&Help"),
)

#: mouse gestures and keys the tools handle themselves (for the help only)
GESTURES: tuple[tuple[str, str], ...] = (
    ("Enter / double-click", "close the loop being drawn (Draw) or finish a cut line"),
    (
        "Del",
        "delete selected points (Edit); the cut line pointed at, drawn in red (Layout): its two blocks become one",
    ),
    ("Ctrl+Z or Esc in a drag", "cancel the drag: back to before it, nothing of it in the history"),
    ("Shift+drag", "snap a dragged point onto another point (Edit)"),
    ("drag on empty space", "box-select points (Edit); pan (other tools)"),
    ("wheel / right-drag", "zoom"),
    (
        "click / Enter on a verdict row",
        "zoom to the worst place of that quality limit (Quality panel); click again: the next worst",
    ),
)


def _sequence(s) -> QtGui.QKeySequence:
    return QtGui.QKeySequence(s)


def _resolve(window, path: str):
    return attrgetter(path)(window)


def build(window, placeholders) -> dict[str, QtGui.QAction]:
    """Make every action of the table on ``window``, its menus and its toolbar.

    ``placeholders(name, menu)`` fills a ``@name`` row into ``menu`` (it may
    return a QAction for the row, e.g. the undo action).  Returns the actions
    by key; each is also set as ``window.a_<key>``.
    """
    actions: dict[str, QtGui.QAction] = {}
    menus: dict[str, QtWidgets.QMenu] = {}
    for spec in ACTIONS:
        menu = None
        if spec.menu:
            if spec.menu not in menus:
                menus[spec.menu] = window.menuBar().addMenu(spec.menu)
            menu = menus[spec.menu]
            if spec.separator:
                menu.addSeparator()
        if spec.slot.startswith("@"):
            a = placeholders(spec.slot[1:], menu, spec)
            if a is None:
                continue
        else:
            a = QtGui.QAction(spec.text, window, checkable=spec.checkable)
            a.triggered.connect(_caller(window, spec))
            if menu is not None:
                menu.addAction(a)
        _describe(a, spec)
        actions[spec.key] = a
        setattr(window, f"a_{spec.key}", a)
    _toolbar(window, actions)
    return actions


def _caller(window, spec: ActionSpec):
    """The slot of a row; checkable actions pass their state, others pass nothing."""
    if spec.checkable:
        return lambda on=False: _resolve(window, spec.slot)(on)
    return lambda _checked=False: _resolve(window, spec.slot)()


def _describe(a: QtGui.QAction, spec: ActionSpec) -> None:
    if spec.shortcuts:
        a.setShortcuts([_sequence(s) for s in spec.shortcuts])
    if spec.short:  # a text-only toolbar shows the icon text: at 1024 px Pause, Stop and Fit were behind »
        a.setIconText(spec.short)
        a.setToolTip(spec.text.replace("&", ""))  # (a tip below replaces it)
    if spec.tip:
        a.setToolTip(spec.tip)
        a.setStatusTip(spec.tip)
    a.setEnabled(spec.enabled)
    if spec.checkable:
        a.setChecked(spec.checked)


def _toolbar(window, actions: dict[str, QtGui.QAction]) -> QtWidgets.QToolBar:
    tb = window.addToolBar("Main")
    tb.setObjectName("main-toolbar")
    tb.setToolButtonStyle(QtCore.Qt.ToolButtonStyle.ToolButtonTextOnly)
    group = None
    for spec in sorted((s for s in ACTIONS if s.toolbar and s.key in actions), key=lambda s: s.toolbar):
        if group is not None and int(spec.toolbar) != group:
            tb.addSeparator()
        group = int(spec.toolbar)
        tb.addAction(actions[spec.key])
    return tb


def shortcut_rows() -> list[tuple[str, str]]:
    """``(keys, what)`` rows of the keyboard help: every action with a shortcut, then the gestures."""
    rows = []
    for spec in ACTIONS:
        if not spec.shortcuts:
            continue
        keys = " / ".join(_sequence(s).toString(QtGui.QKeySequence.SequenceFormat.NativeText) for s in spec.shortcuts)
        what = spec.help or spec.text.replace("&", "").rstrip("…")
        rows.append((keys, what))
    return rows + list(GESTURES)
