"""The document: the single source of truth the views draw (psygnal, no Qt widgets).

It holds the immutable :class:`~app.project.Project`, the grids of the last
solve (and the live preview while solving), the multiblock result with its
connectivity, the quality report of the active block's final grid, the
metric the cells are coloured by, the selection and the active block.  Views
subscribe to its signals and draw it; edits go through undo commands
(:mod:`app.commands`) that call :meth:`Document.set_project`.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np
from psygnal import Signal

from meshcore import StructuredGrid, quality

from .project import Block, Project

__all__ = ["METRICS", "Document"]


def _same_blocks(a, b) -> bool:
    """Two lake layouts of the same blocks by name (their cells may differ)."""
    return a is not None and b is not None and [x.name for x in a.blocks] == [y.name for y in b.blocks]


def _finished(multiblock) -> bool:
    """A kept solve's MultiBlockGrid is of a solve that ran to its end (None: a solve without one)."""
    info = getattr(multiblock, "info", None)
    return info is None or info.converged or info.message != "stopped"


def _layout_shape(layout) -> tuple | None:
    """What a lake layout's grids depend on in shape: the blocks' names and cells."""
    return None if layout is None else tuple((b.name, tuple(b.cells)) for b in layout.blocks)


#: the metrics cells can be coloured by: label → (array of the quality report, colour map)
DEVIATION = "deviation from 90° (deg)"
SHRINK = "time step cost (h ÷ shortest edge)"
#: the metrics measured over every block of a lake grid (its lake metrics), not of the active block alone
LAKE_WIDE = frozenset({DEVIATION, SHRINK})
METRICS = {
    "none": None,
    "Jacobian ratio": ("jacobian_ratio", "viridis"),
    "skewness": ("skewness", "viridis"),
    "orthogonality (deg)": ("orthogonality", "viridis"),
    "aspect ratio": ("aspect_ratio", "viridis"),
    "cell area": ("area", "viridis"),
    "size ratio": ("size_ratio", "viridis"),
    # the lake modellers' measure (EFDC: < 3°): the largest deviation from 90° at a cell's four nodes,
    # over every block of a lake grid (as ``meshcore mesh --colour deviation`` draws it)
    DEVIATION: ("deviation", "magma_r"),
    # how much shorter an explicit model's time step is in a cell than in cells of the grid's mean size
    # (its mean size over its shortest edge: meshcore.quality's ``shrink``), over every block of a lake grid
    SHRINK: ("shrink", "magma_r"),
}
#: the metrics whose worst cells are their smallest values (cells merged for colouring show their smallest)
LOW_IS_WORSE = frozenset({"Jacobian ratio"})
#: the colour range of :data:`DEVIATION` (degrees; above it, the top colour)
DEVIATION_LEVELS = (0.0, 10.0)
#: ... and of :data:`SHRINK`: 1 for a cell of the mean size, the top colour from an edge of a twentieth
SHRINK_LEVELS = (1.0, 20.0)
#: the fixed colour ranges, by label (the others span their values)
LEVELS = {DEVIATION: DEVIATION_LEVELS, SHRINK: SHRINK_LEVELS}


#: a grid (with the lake grid its metrics are measured over) of at least this many cells is measured off the
#: GUI thread when the app gives the document a runner (:attr:`Document.measure_async`): the quality report
#: costs ~1.5 µs of CPU per cell, a lake's metrics with their coverage more (a single block of 1.75 million
#: cells froze the window for 5-7 s after its solve)
ASYNC_CELLS = 50_000

#: finished solves the document keeps for undo and redo: back to a layout (or project) a grid was made
#: for, that grid is shown again instead of nothing (a few MB each for lakes of ~10 000 cells)
KEPT_SOLVES = 8


def _made_of(project: Project):
    """What a project's grid is made of: a lake's grid of its layout alone (the lake's cell size and
    *regular* are settings for the next Auto layout), every other grid of the whole project."""
    return project.layout if project.layout is not None else project


class Document:
    """Project + grids + selection, with change signals.

    Signals
    -------
    project_changed(Project)
        After any edit (or undo/redo, or open).
    grids_changed()
        The grids (final or preview) changed.
    selection_changed(frozenset)
        Selected point indices of the active block changed.
    active_changed(int)
        The active block changed.
    path_changed(object)
        The file path of the project changed (None for unsaved).
    message(str)
        A human-readable status message (errors included).
    quality_changed()
        :attr:`quality` changed (a solve finished, started, or another block became active), or a
        measure of a large grid began (:attr:`measuring` True, :attr:`quality` None) or ended.
    colour_changed(str)
        The metric the cells are coloured by changed (a key of :data:`METRICS`).
    opened()
        A new project was opened (:meth:`reset`): views drop what they showed.
    reported(str, str)
        A problem or a note worth keeping: level ("info", "warning", "error") and the full text
        (the message panel lists them; the status bar shows only the latest line).
    superseded()
        A new grid was made (or the project started over): the errors and warnings reported
        before it are of an earlier grid — the message panel keeps them, greyed, uncounted.
    """

    project_changed = Signal(object)
    grids_changed = Signal()
    selection_changed = Signal(object)
    active_changed = Signal(int)
    path_changed = Signal(object)
    message = Signal(str)
    quality_changed = Signal()
    colour_changed = Signal(str)
    opened = Signal()
    reported = Signal(str, str)
    superseded = Signal()

    def __init__(self, project: Project | None = None) -> None:
        self.project: Project = project or Project()
        self.grids: dict[int, StructuredGrid] = {}
        self.initial: dict[int, StructuredGrid] = {}
        self.stale: bool = False  # the grids on screen are not of the project (an edit since their solve)
        #: the lake grid of before an edit that gave the same blocks other cells (a drag whose cells
        #: followed it, a block's cells set): not of any block now, drawn greyed until a solve's grids
        self.before_grids: dict[int, StructuredGrid] = {}
        #: the project the final grids were made for: an undo back to it makes them current again
        self.solved: Project | None = None
        self.selection: frozenset[int] = frozenset()
        self.active: int = 0
        self.path: Path | None = None
        #: the meshcore MultiBlockGrid of the last multiblock solve (with its connectivity)
        self.multiblock = None
        #: the meshcore QualityReport of the active block's final grid (None while solving)
        self.quality = None
        self.quality_grid: StructuredGrid | None = None  # the grid ``quality`` describes
        #: ``run(job, done)``: runs ``job()`` off the GUI thread and calls ``done(its value)`` (or ``done(None)``
        #: if it failed) in the GUI thread; None (the default, scripts): every grid is measured at once
        self.measure_async: Callable[[Callable[[], object], Callable[[object], None]], None] | None = None
        #: the quality of :attr:`quality_grid` is being measured (:attr:`quality` is None until it is)
        self.measuring = False
        self._measure_token = 0  # a measure's result is taken only while no newer grid came
        self.colour_by: str = "none"
        self.solving: bool = False
        self._final: bool = False  # the grids are the result of a finished solve
        #: meshcore LakeMetrics of a lake layout's finished grid (None otherwise)
        self.lake_metrics = None
        self._given_metrics = None  # (MultiBlockGrid, LakeMetrics) measured by the solver worker
        #: the last :data:`KEPT_SOLVES` finished solves: (project, grids, initial, multiblock, given metrics)
        self._kept: list[tuple] = []
        #: the project an undo or redo brought a kept solve back for (None once a solve or an open replaced it)
        self.restored: Project | None = None

    # ----------------------------------------------------------- project
    @property
    def block(self) -> Block:
        """The active block."""
        return self.project.blocks[min(self.active, len(self.project.blocks) - 1)]

    def set_project(self, project: Project) -> None:
        """Replace the project (commands call this) and tell the views."""
        if project is self.project:
            return
        old = self.project
        self.project = project
        relaid = project.layout is not old.layout and _layout_shape(project.layout) != _layout_shape(old.layout)
        if relaid or project.multiblock is not old.multiblock or len(project.blocks) != len(old.blocks):
            # a different block structure (split by cuts, undo of it, add/delete block): keep
            # only the grids of blocks that are still there, unchanged, at the same index
            keep = {
                k
                for k in self.grids
                if project.multiblock is old.multiblock
                and not relaid
                and k < min(len(project.blocks), len(old.blocks))
                and project.blocks[k] is old.blocks[k]
            }
            if not keep and _same_blocks(old.layout, project.layout):  # new cells, the same blocks
                self.before_grids = dict(self.grids) or self.before_grids
            else:
                self.before_grids = {}
            self.grids = {k: g for k, g in self.grids.items() if k in keep}
            self.initial = {k: g for k, g in self.initial.items() if k in keep}
            self.multiblock = None
            self.grids_changed.emit()
            self._update_quality()
        self._restore_kept(project)
        if self.active >= len(project.blocks):
            self.set_active(len(project.blocks) - 1)
        n = len(self.block.points)
        if any(i >= n for i in self.selection):
            self.set_selection(frozenset(i for i in self.selection if i < n))
        self.stale = not (self.grids and self.solved is not None and _made_of(project) is _made_of(self.solved))
        self.project_changed.emit(project)

    def _restore_kept(self, project: Project) -> None:
        """An undo or redo back to what a kept solve was made of: its grids become the current ones.

        Also while a solve runs (of the project before the undo; the solver drops it when it sees
        :attr:`restored`): an undo of Auto layout started the one block's solve (auto-generate on),
        and a redo while it ran solved the layout again from scratch (its grid was kept)."""
        made = _made_of(project)
        if self.solved is not None and _made_of(self.solved) is made and self.grids and not self.solving:
            return
        kept = next((k for k in self._kept if _made_of(k[0]) is made), None)
        if kept is None:
            return
        self.restored = project
        self.solved, grids, initial, self.multiblock, self._given_metrics = kept
        self.grids, self.initial = dict(grids), dict(initial)
        self.before_grids = {}
        self._final = True
        self.grids_changed.emit()
        self._update_quality()

    def reset(self, project: Project, path: Path | None = None) -> None:
        """Start over with ``project`` (open/new): grids and selection cleared."""
        self.grids = {}
        self.before_grids = {}
        self.initial = {}
        self.multiblock = None
        self._final = False
        self.selection = frozenset()
        self.active = 0
        self.project = project
        self.path = Path(path) if path else None
        self.stale = True
        self.solved = None
        self._kept = []
        self.restored = None
        self._update_quality()
        self.opened.emit()
        self.project_changed.emit(project)
        self.grids_changed.emit()
        self.selection_changed.emit(self.selection)
        self.active_changed.emit(0)
        self.path_changed.emit(self.path)

    # ------------------------------------------------------------- grids
    def set_grid(self, index: int, grid: StructuredGrid, *, final: bool = False) -> None:
        self.grids[index] = grid
        self.before_grids = {}
        if final:
            self.stale = False
            self.solved = self.project
        self.grids_changed.emit()

    def set_grids(
        self,
        grids: dict[int, StructuredGrid],
        initial: dict | None = None,
        *,
        multiblock=None,
        metrics=None,
        project: Project | None = None,
    ) -> None:
        """The final grids of a solve (and, for a multiblock case, meshcore's MultiBlockGrid; for a lake,
        its LakeMetrics if the worker measured them) of ``project`` (default: the current one); of
        another (an edit made while it solved) they stay marked as of before the edit."""
        self._given_metrics = (multiblock, metrics) if metrics is not None else None
        self.restored = None
        self.grids = dict(grids)
        self.before_grids = {}
        if initial is not None:
            self.initial = dict(initial)
        self.multiblock = multiblock
        self.solved = project if project is not None else self.project
        self.stale = _made_of(self.solved) is not _made_of(self.project)
        self._final = True
        made = _made_of(self.solved)
        self._kept = [k for k in self._kept if _made_of(k[0]) is not made][-(KEPT_SOLVES - 1) :]
        self._kept.append((self.solved, dict(self.grids), dict(self.initial), multiblock, self._given_metrics))
        self.grids_changed.emit()
        self._update_quality()

    def set_multiblock(self, multiblock) -> None:
        """The MultiBlockGrid (connectivity included) of the grids just set."""
        self.multiblock = multiblock
        if self._kept and self._kept[-1][0] is self.solved:
            self._kept[-1] = (*self._kept[-1][:3], multiblock, self._kept[-1][4])

    def set_stopped_coarse(self, frames: dict[int, StructuredGrid]) -> None:
        """A lake solve stopped before its full level: no grid of the layout (nothing to measure or
        export; the project is stale: F5 makes its grid).  Its last coarse frames (``frames``; none: what
        was drawn greyed before stays) are drawn greyed, as the grid of before an edit is."""
        self.solved = None
        self.restored = None
        self.grids = {}
        self.initial = {}
        self.before_grids = dict(frames) or self.before_grids
        self.multiblock = None
        self._final = False
        self.stale = True
        self.grids_changed.emit()
        self._update_quality()

    def final_of(self, project: Project) -> tuple | None:
        """The kept solve of what ``project`` is made of (a lake: its layout) that ran to its end (not
        stopped), when the project shown is made of the same; else None."""
        made = _made_of(project)
        if _made_of(self.project) is not made:
            return None
        return next((k for k in self._kept if _made_of(k[0]) is made and _finished(k[3])), None)

    def restore_final(self, project: Project) -> bool:
        """A solve of ``project`` stopped (F5 on its finished grid, then Stop): that finished grid is the
        document's again, with its quality (the stopped one replaced it, or none was left).  False: none."""
        kept = self.final_of(project)
        if kept is None:
            return False
        self.solved, grids, initial, self.multiblock, self._given_metrics = kept
        self.grids, self.initial = dict(grids), dict(initial)
        self.before_grids = {}
        self.restored = None
        self._final = True
        self.stale = False
        self.grids_changed.emit()
        self._update_quality()
        return True

    def clear_grids(self) -> None:
        self.solved = None
        self.restored = None
        self.grids = {}
        self.before_grids = {}
        self.initial = {}
        self.multiblock = None
        self._final = False
        self.grids_changed.emit()
        self._update_quality()

    def set_solving(self, solving: bool) -> None:
        """A solve started (the quality of the old grid is withdrawn) or ended."""
        solving = bool(solving)
        if solving == self.solving:
            return
        self.solving = solving
        if solving:
            self._final = False
        self._update_quality()

    def report(self, level: str, text: str) -> None:
        """Add ``text`` to the message panel (``level``: "info", "warning" or "error")."""
        if level not in ("info", "warning", "error"):
            raise ValueError(f"unknown message level {level!r}")
        self.reported.emit(level, str(text))

    # ----------------------------------------------------------- quality
    def _update_quality(self) -> None:
        g = self.grid if self._final and not self.solving else None
        if g is self.quality_grid:
            return
        self.quality_grid = g
        self._measure_token += 1
        token = self._measure_token
        if g is None:
            self.quality, self.lake_metrics, self.measuring = None, None, False
        else:
            job, cells = self._measure_job(g)
            if self.measure_async is not None and cells >= ASYNC_CELLS:
                self.quality, self.lake_metrics, self.measuring = None, None, True
                self.measure_async(job, lambda value: self._measured(token, value))
            else:
                self.measuring = False
                self.quality, self.lake_metrics = job()
        self.quality_changed.emit()

    def _measure_job(self, g: StructuredGrid) -> tuple[Callable[[], tuple], int]:
        """``(job, cells)``: the measure of grid ``g`` (its quality report and, of a lake layout's grid,
        the lake metrics) as a function of what the document holds now, and how many cells it measures."""
        lay, mb, given = self.project.layout, self.multiblock, self._given_metrics
        if lay is None or mb is None or len(mb.grids) != len(lay.blocks):
            lake = None
        elif given is not None and given[0] is mb:
            lake = given[1]
        else:
            lake = mb  # measured in the job
        measure_lake = lake is not None and lake is mb
        cells = g.cells[0] * g.cells[1]
        if measure_lake:
            cells += sum(b.cells[0] * b.cells[1] for b in mb.grids)

        def job() -> tuple:
            m = lake
            if measure_lake:
                from meshcore.quality import lake_metrics

                m = lake_metrics(mb, polygon=lay.polygon, cell_size=lay.cell_size)
            return quality(g), m

        return job, cells

    def _measured(self, token: int, value) -> None:
        """A measure made off the GUI thread: taken only if no newer grid came since it began."""
        if token != self._measure_token:
            return
        self.measuring = False
        self.quality, self.lake_metrics = value if value is not None else (None, None)
        self.quality_changed.emit()

    def set_colour_by(self, label: str) -> None:
        """Colour the cells by the metric ``label`` (a key of :data:`METRICS`)."""
        if label not in METRICS:
            raise ValueError(f"unknown metric {label!r}; known: {', '.join(METRICS)}")
        if label != self.colour_by:
            self.colour_by = label
            self.colour_changed.emit(label)

    def colour_values(self):
        """``(grid, values, label)`` of the cell colouring of the active block, or ``(None, None, "")``."""
        m = METRICS.get(self.colour_by)
        if m is None or self.quality is None:
            return None, None, ""
        if self.colour_by in LAKE_WIDE:
            layers = self.colour_layers()
            return (*layers[0], self.colour_by) if layers else (None, None, "")
        return self.quality_grid, self.quality.arrays[m[0]], self.colour_by

    def colour_layers(self) -> list:
        """``[(grid, values), …]`` of the cell colouring: the active block first, then the lake's other blocks.

        A metric of the block quality colours the active block; :data:`DEVIATION` and :data:`SHRINK`
        colour every block of a lake grid (its lake metrics), or the active block's grid otherwise.
        """
        return [(g, v) for _k, g, v in self.colour_blocks()]

    def colour_blocks(self) -> list:
        """:meth:`colour_layers` with the index of each layer's block: ``[(block, grid, values), …]``."""
        m = METRICS.get(self.colour_by)
        if m is None or self.quality is None:
            return []
        if self.colour_by not in LAKE_WIDE:
            return [(self.active, self.quality_grid, self.quality.arrays[m[0]])]
        lm, mb = self.lake_metrics, self.multiblock
        if lm is not None and mb is not None and len(lm.blocks) == len(mb.grids):
            layers = [
                (k, g, _cell_values(self.colour_by, b, lm.cell_size))
                for k, (g, b) in enumerate(zip(mb.grids, lm.blocks, strict=True))
            ]
            k = self.active if 0 <= self.active < len(layers) else 0
            return [layers[k], *layers[:k], *layers[k + 1 :]]
        from meshcore.quality.lake import block_metrics, mean_cell_size

        g = self.quality_grid
        b = block_metrics(g)
        return [(self.active, g, _cell_values(self.colour_by, b, mean_cell_size([b])))]

    @property
    def grid(self) -> StructuredGrid | None:
        """The grid of the active block, if any."""
        return self.grids.get(self.active)

    # --------------------------------------------------------- selection
    def set_selection(self, indices) -> None:
        sel = frozenset(int(i) for i in indices)
        if sel != self.selection:
            self.selection = sel
            self.selection_changed.emit(sel)

    def set_active(self, index: int) -> None:
        index = max(0, min(int(index), len(self.project.blocks) - 1))
        if index != self.active:
            self.active = index
            self.selection = frozenset()
            self._update_quality()
            self.active_changed.emit(index)
            self.selection_changed.emit(self.selection)

    def set_path(self, path) -> None:
        self.path = Path(path) if path else None
        self.path_changed.emit(self.path)


def _cell_values(label: str, b, h: float) -> np.ndarray:
    """Per cell of a block's lake metrics ``b``, the value :data:`DEVIATION` or :data:`SHRINK` colours
    it by (``h``: the grid's mean cell size, the unit of ``SHRINK``)."""
    from meshcore.quality.lake import cell_shrink

    return cell_shrink(b.shortest, h) if label == SHRINK else _cell_max(b.deviation)


def _cell_max(nodes: np.ndarray) -> np.ndarray:
    """Per cell, the largest of a node value at its four corners (NaN where all four are NaN)."""
    d = np.asarray(nodes, dtype=float)
    corners = np.stack([d[:-1, :-1], d[1:, :-1], d[1:, 1:], d[:-1, 1:]])
    out = np.full(corners.shape[1:], np.nan)
    some = ~np.isnan(corners).all(axis=0)
    out[some] = np.nanmax(corners[:, some], axis=0)
    return out
