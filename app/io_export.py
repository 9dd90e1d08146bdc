"""File ▸ Export mesh and Export figure: the dialogs, the checks before writing (folded cells, a
Delft3D domain decomposition that cannot be coupled) and the writes.

:class:`ExportMixin` is a part of :class:`app.io_controller.IOController` (a mixin: it uses the
controller's ``win``, ``doc``, ``quiet``, ``settings``, ``_parent``, ``suggested_path``, ``last_dir``
and ``remember_dir``); meshes are written by :mod:`app.io_adapter` over ``meshcore.io``.
"""

from __future__ import annotations

import logging
from pathlib import Path

import numpy as np
from PySide6 import QtWidgets

from meshcore import MeshcoreError

from . import io_adapter as fio

__all__ = ["ExportMixin", "export_default"]

log = logging.getLogger(__name__)

#: grids of at least this many cells (all blocks) are written in a child process, waited for in a worker
#: thread: the window stays responsive (1.75 million cells: a .vtm took 26 s of the GUI thread, EFDC files
#: 128 s, at load 20; written in a worker thread the writers' long calls held the GIL: 1.4 s stalls)
EXPORT_ASYNC_CELLS = 200_000


def export_default(project) -> str:
    """The format the export dialog offers first: Delft3D domain decomposition for a lake layout of
    several blocks (what lake modellers export), VTK multiblock for other cases of several blocks, VTK
    structured grid for one block (it offered PLOT3D, the first format meshcore writes)."""
    n = len(project.blocks)
    if project.layout is not None and n > 1:
        return "delft3d-dd"
    return "vtm" if n > 1 else "vts"


def chosen_format(chosen: str, path: Path) -> str | None:
    """The format name of a dialog filter ``"… [name] (*.x)"`` when it shares the path's suffix with
    another format (``.grd``: one block, or the blocks merged into one domain), else ``None``."""
    import re

    from meshcore.io import FORMATS

    m = re.search(r"\[([\w-]+)\]", chosen)
    fmt = FORMATS.get(m.group(1)) if m else None
    if fmt is None or path.suffix.lower() not in fmt.suffixes:
        return None
    return fmt.name if sum(path.suffix.lower() in f.suffixes for f in FORMATS.values() if f.writer) > 1 else None


_NOTHING_YET = "Nothing to export yet: generate a grid first (F5)"
#: a layout or a grid being computed (it said "generate a grid first (F5)": F5 starts that grid over)
_BEING_MADE = "The grid is being made: export it when it is done (the status bar says so)"
#: the greyed grid on screen after an edit with auto-generate off (it said "Nothing to export yet")
_BEFORE_EDIT = (
    "The grid on screen (greyed) is of before the last edit, not of this layout: F5 makes the grid of "
    "this layout, then export"
)


#: the settings key of the folder of the last export (mesh or figure)
EXPORT_DIR = "last_export_dir"


class ExportMixin:
    """Export mesh and Export figure of the window's :class:`~app.io_controller.IOController`."""

    def export_dir(self) -> str:
        """The folder the Export dialogs open in: the last export's (remembered in the settings),
        else the project file's, else the last folder used (the outline's, after an import).

        It opened in the folder the outline was imported from: a modeller keeps the lake's outline
        with the source data and writes grids elsewhere, and found that folder offered every time."""
        last = str(self.settings.value(EXPORT_DIR, "") or "")
        if last and Path(last).is_dir():
            return last
        if self.doc.path is not None:
            return str(Path(self.doc.path).parent)
        return self.last_dir()

    def remember_export(self, path: Path) -> None:
        """The folder the next Export dialog opens in (:meth:`export_dir`)."""
        self.settings.setValue(EXPORT_DIR, str(Path(path).parent))
        self.remember_dir(path)

    def _why_not(self) -> str | None:
        """Why the grid on screen cannot be exported now (None: it can)."""
        doc, lake = self.doc, self.win.lake_ctl
        if doc.solving or lake.busy or lake.editing:
            return _BEING_MADE
        if not doc.grids:
            return _NOTHING_YET if not doc.before_grids else _BEFORE_EDIT
        if doc.project.layout is not None and (doc.multiblock is None or doc.stale or doc.solving):
            if doc.stale and not doc.solving:  # a cut moved with auto-generate off: the grid is of before it
                return _BEFORE_EDIT  # (it said "not finished: generate it" of a finished grid, greyed)
            return "The lake grid is not finished: generate it (F5) and export when it is done"
        return None

    def export_dialog(self) -> None:
        why = self._why_not()
        if why is not None:  # said before the file dialog (the dialog came first, then this as an error)
            self.win.message(why)
            return
        fmts = fio.mesh_formats()
        filt = ";;".join(f"{d} ({p})" for d, p in fmts)
        want = export_default(self.doc.project)
        first = next((f"{d} ({p})" for d, p in fmts if d.endswith(f"[{want}]")), "")
        suffix = next((p.split()[0].lstrip("*") for d, p in fmts if d.endswith(f"[{want}]")), "")
        stem = Path(self.suggested_path()).stem
        offer = str(Path(self.export_dir()) / f"{stem}{suffix}") if suffix else self.export_dir()
        path, chosen = QtWidgets.QFileDialog.getSaveFileName(self._parent(), "Export mesh", offer, filt, first)
        if path:
            if not Path(path).suffix:
                pat = next((p for d, p in fmts if chosen.startswith(d)), "*.vts")
                path += pat.split()[0].lstrip("*")
            self.export_mesh(Path(path), chosen_format(chosen, Path(path)))

    def export_mesh(self, path: Path, format: str | None = None) -> bool:
        """Write the grids (a multiblock result with its connectivity) with meshcore.io
        (``format``: the format chosen in the dialog, when the suffix alone does not say it)."""
        why = self._why_not()  # as the dialog says (was, called directly: "expected a StructuredGrid ... got list")
        if why is not None:
            self.win.message(why, error=True)
            return False
        if path.suffix.lower() == ".inp" and path.name.lower() != "cell.inp":
            path = self._efdc_cell_inp(path)
            if path is None:
                return False
        grids = [self.doc.grids[k] for k in sorted(self.doc.grids)]
        mb = self.doc.multiblock
        p = self.doc.project
        frame = fio.project_frame(p)
        if getattr(self, "_export_worker", None) is not None:
            self.win.message("An export is being written: export again when it is done", error=True)
            return False
        one = _one_block_format(path, format, len(grids)) if len(grids) > 1 else None
        if one is not None:  # said before the fold question (was: the writer's "holds one block, got 45")
            self.win.error("Cannot export mesh", f"{path.name}: {one}")
            return False
        if not self._folds_confirmed():
            return False
        whole = mb is not None and (p.multiblock is not None or p.layout is not None) and not self.doc.stale
        what = mb if whole else grids
        cells = sum(g.cells[0] * g.cells[1] for g in grids)
        if cells >= EXPORT_ASYNC_CELLS:
            return self._export_in_worker(path, what, frame, format, len(grids), cells)
        try:
            fio.write_mesh(path, what, frame, format)
        except (MeshcoreError, OSError) as exc:
            self._export_failed(path, exc, format)
            return False
        self._exported(path, len(grids))
        return True

    def _export_in_worker(self, path: Path, what, frame, format: str | None, n: int, cells: int) -> bool:
        """Write a large grid in a child process (:mod:`app.write_process`), waited for in a worker thread
        (the grids are immutable: an edit meanwhile does not change what is written; meshcore writes
        atomically: the file is complete or absent).  True: started."""
        from superqt.utils import create_worker

        from .write_process import write_in_process

        worker = create_worker(write_in_process, path, what, frame, format, _start_thread=False, _ignore_errors=True)
        failed: list = []
        worker.errored.connect(failed.append)
        worker.finished.connect(lambda: self._export_ended(worker, path, n, failed, format))
        self._export_worker = worker
        self.win.message(f"Exporting {cells:,} cells to {path} …")
        worker.start()
        return True

    def _export_ended(self, worker, path: Path, n: int, failed: list, format: str | None) -> None:
        if worker is not getattr(self, "_export_worker", None):
            return
        self._export_worker = None
        if not failed:
            self._exported(path, n)
        elif isinstance(failed[0], (MeshcoreError, OSError)):
            self._export_failed(path, failed[0], format)
        else:
            log.error("the export failed", exc_info=failed[0])
            self.win.error("Cannot export mesh", failed[0])

    @property
    def exporting(self) -> bool:
        """A large grid is being written (in a worker thread)."""
        return getattr(self, "_export_worker", None) is not None

    def _exported(self, path: Path, n: int) -> None:
        self.remember_export(path)
        self.win.message(f"Exported {n} block(s) to {path}")

    def _export_failed(self, path: Path, exc: BaseException, format: str | None) -> None:
        if not self._offer_regular(path, exc, format):
            self.win.error("Cannot export mesh", exc)

    def _efdc_cell_inp(self, path: Path) -> Path | None:
        """EFDC reads its grid from files of fixed names (``cell.inp`` and four beside it): a name the
        user typed (``lake.inp``) becomes ``cell.inp`` in its folder; files of those names already
        there are replaced only when the user says so (None: not confirmed)."""
        from meshcore.io.efdc import FILES

        target = path.with_name("cell.inp")
        there = [n for n in FILES if (path.parent / n).exists()]
        text = f"EFDC reads its grid from files of fixed names: writing {', '.join(FILES)} into {path.parent}"
        if there and not self.quiet:
            b = QtWidgets.QMessageBox.StandardButton
            ask = f"{text}.\n\n{', '.join(there)} already exist there. Replace them?"
            if QtWidgets.QMessageBox.question(self._parent(), "EFDC files", ask, b.Yes | b.No) != b.Yes:
                self.win.message("EFDC export cancelled: nothing written")
                return None
        self.doc.report("info", text + (f" (replacing {', '.join(there)})" if there else ""))
        return target

    def _folds_confirmed(self) -> bool:
        """A grid with folded or non-convex cells (a lake's, or any block's): warn (and ask, unless quiet)
        before writing it; the warning names the blocks."""
        from meshcore.quality import quality

        m = self.doc.lake_metrics
        names = [b.name for b in self.doc.project.blocks]
        if m is not None:
            bad = [(b.name, int(np.sum(b.folded))) for b in m.blocks]
        else:  # every block the export writes (a hand-made case, one block)
            bad = []
            for k, g in sorted(self.doc.grids.items()):
                r = self.doc.quality if g is self.doc.quality_grid and self.doc.quality is not None else quality(g)
                bad.append((names[k] if k < len(names) else f"block {k + 1}", max(r.n_folded, r.n_nonconvex)))
        bad = [(name, n) for name, n in bad if n]
        n = sum(k for _name, k in bad)
        if not n:
            return True
        where = ", ".join(f"{name}: {k}" for name, k in bad[:8]) + (", …" if len(bad) > 8 else "")
        text = f"The grid has {n} folded or non-convex cell(s) ({where}); a model may refuse it"
        self.doc.report("warning", text)
        if self.quiet:
            return True
        b = QtWidgets.QMessageBox.StandardButton
        r = QtWidgets.QMessageBox.question(self._parent(), "Folded cells", f"{text}.\n\nExport anyway?", b.Yes | b.No)
        return r == b.Yes

    def _offer_regular(self, path: Path, exc: BaseException, format: str | None = None) -> bool:
        """A .ddb that Delft3D cannot couple, or a single-domain grid (Delft3D .grd of the blocks
        merged, EFDC) whose layout does not fit one index space (3- or 5-block corners): the writer's
        error and a regular layout offered instead (for a single domain, a layout for one index space:
        its rings round islands closed, ``auto_layout(single=True)``)."""
        lay = self.doc.project.layout
        suffix = Path(path).suffix.lower()
        # a single domain refused for its index space (not for water in parts, or a folder it cannot write)
        single = (format == "delft3d-single" or suffix == ".inp") and "one index space" in str(exc)
        if lay is None or not (single or suffix == ".ddb") or len(lay.blocks) < 2:
            return False  # one block: nothing to couple, the error says to write a .grd (no layout helps)
        name = Path(path).name
        lake = self.doc.project.lake
        if lake.single or (lake.regular and not single):  # made for it and still refused: the error says why
            return False
        if single:
            title = "One index space"
            # the writer's message says why and where (was followed by the same reasons again: ten lines)
            text = (
                f"Cannot export {name}: {exc}. Or a layout made for it: regular, its rings of blocks round islands "
                "closed (it fits one index space unless the lake's arms fold onto each other); then export again"
            )
        else:
            title = "Delft3D domain decomposition"
            text = (
                f"Cannot export {name}: {exc}. Or a regular layout (Lake ▸ Auto layout, regular), which Delft3D "
                "can couple; then export again"
            )
        self.win.message(text, error=True)
        if not self.quiet:
            b = QtWidgets.QMessageBox.StandardButton
            what = "a layout for one index space" if single else "a regular layout"
            ask = f"{text}.\n\nMake {what} now? {name} is written when its grid is done."
            r = QtWidgets.QMessageBox.question(self._parent(), title, ask, b.Yes | b.No)
            if r == b.Yes:
                self._export_when_done(path, format)
                if not self.win.lake_ctl.auto_layout(**({"single": True} if single else {"regular": True})):
                    self._pending_export = None
        return True

    # ------------------------------------------- the export after a new layout
    _pending_export: tuple | None = None  # (path, format, phase): the export waiting for a layout's grid

    def _export_when_done(self, path: Path, format: str | None) -> None:
        """Write ``path`` when the layout just asked for is made and gridded (the user said Yes to
        "Make a regular layout now?"; was: the layout and its grid, then File ▸ Export again, the
        file name typed again).  A layout refused, or a grid stopped or failed: nothing written, said."""
        if self._pending_export is None and not getattr(self, "_export_hooked", False):
            self._export_hooked = True
            self.win.lake_ctl.layout_done.connect(self._pending_layout_done)
            self.win.solver.finished.connect(self._pending_grid_done)
        self._pending_export = (Path(path), format, "layout")

    def _pending_layout_done(self, layout) -> None:
        if self._pending_export is None or self._pending_export[2] != "layout":
            return
        path, format, _ = self._pending_export
        if layout is None:  # the layout's own error is in the messages
            self._pending_export = None
            self.win.message(f"{path.name} not written: no new layout", error=True)
            return
        self._pending_export = (path, format, "grid")

    def _pending_grid_done(self, result) -> None:
        if self._pending_export is None or self._pending_export[2] != "grid":
            return
        if result is None and self.win.solver.running:  # a solve stopped before this one started
            return
        path, format, _ = self._pending_export
        self._pending_export = None
        if result is None or self.doc.stale or self.doc.multiblock is None:
            why = "the grid was not finished — export again when it is"
            self.win.message(f"{path.name} not written: {why}", error=True)
            return
        self.export_mesh(path, format)

    def figure_dialog(self) -> None:
        path, _ = QtWidgets.QFileDialog.getSaveFileName(
            self._parent(), "Export figure", self.export_dir(), "PNG image (*.png);;SVG vector (*.svg)"
        )
        if path:
            if not Path(path).suffix:
                path += ".png"
            self.export_figure(path)

    def export_figure(self, path) -> bool:
        try:
            self.win.canvas.export_image(str(path))
        except Exception as exc:  # pyqtgraph's exporters raise anything
            log.exception("cannot export the figure %s", path)
            self.win.error("Cannot export figure", exc)
            return False
        self.remember_export(Path(path))
        self.win.message(f"Saved figure {path}")
        return True


def _one_block_format(path: Path, format: str | None, n: int) -> str | None:
    """Why a grid of ``n`` blocks cannot go to the format of ``path`` (None: it can, or the format is
    unknown: the writer says so), and the file types that take it."""
    from meshcore.io import FORMATS, find_format

    try:
        fmt = find_format(path, format, role="write")
    except (MeshcoreError, ValueError):
        return None
    if fmt.multiblock:
        return None

    def name(f) -> str:
        return f"{f.description.split(' (')[0].split(':')[0]} ({f.suffixes[0]})"

    grids = [f for f in FORMATS.values() if f.writer and f.multiblock and f.name not in _NOT_A_GRID]
    blocks = ", ".join(name(f) for f in grids if f.name not in _ONE_DOMAIN)
    merged = " or ".join(name(f) for f in grids if f.name in _ONE_DOMAIN)
    return (
        f"{name(fmt)} holds one block and this grid has {n}: choose a file type that holds blocks — {blocks} — "
        f"or one that merges them into one domain: {merged}"
    )


#: formats that take blocks but are no grid for a model; formats that merge the blocks into one domain
_NOT_A_GRID = frozenset({"figure", "metrics-csv"})
_ONE_DOMAIN = frozenset({"delft3d-single", "efdc"})
