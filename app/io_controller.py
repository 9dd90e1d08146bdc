"""Files in and out of the window: new/open/save, import, export, recent files, autosave.

:class:`IOController` owns every file dialog and file operation of the window (Export mesh and
Export figure in its part :mod:`app.io_export`).
Reading and writing are done by :mod:`app.io_adapter` (over ``meshcore.io``
and ``meshcore.case``); crash recovery goes through the case format
(:mod:`app.recovery`).  The autosave is debounced on edits: it writes
``DEBOUNCE_MS`` after the last edit, and at least every ``MAX_DELAY_S``
seconds while edits keep coming (a long drag), so a crash loses at most a
couple of seconds of work.
"""

from __future__ import annotations

import json
import logging
import re
import threading
import time
from pathlib import Path

from PySide6 import QtCore, QtWidgets

from meshcore import MeshcoreError

from . import io_adapter as fio
from . import recovery
from .examples import LAKES, lake_file, load_example
from .io_export import ExportMixin, export_default
from .lake import Lake, looks_branched, read_lake, read_lake_parts, water
from .off_gui import off_gui
from .project import Block, Project, block_from_points

__all__ = ["MAX_RECENT", "IOController", "claim_recovery", "export_default"]

log = logging.getLogger(__name__)

MAX_RECENT = 8
DEBOUNCE_MS = 1000
MAX_DELAY_S = 2.0
#: recovery files one user's running gcmesh processes may hold at once (recovery.toml, recovery-2.toml, …)
RECOVERY_SLOTS = 16
_claimed: dict[str, QtCore.QLockFile] = {}  # the recovery files this process holds (kept until it exits)


def claim_recovery(path: Path) -> Path:
    """The recovery file of this process: ``path``, unless another running gcmesh holds it (its unsaved
    work is autosaved there), then the first free one of ``NAME-2.toml``, ``NAME-3.toml`` …

    Each is held by a lock file beside it while its process runs (the windows of one process share
    theirs, as before); when the process ends without a clean exit, the lock is stale and the next
    window to start takes the file over and offers its project back.  Every gcmesh used one file: a
    second window offered the first one's unsaved lake as "did not shut down cleanly", and "No"
    deleted that autosave while the first window still had the work open.
    """
    path = Path(path)
    for k in range(1, RECOVERY_SLOTS + 1):
        p = path if k == 1 else path.with_name(f"{path.stem}-{k}{path.suffix}")
        if str(p) in _claimed:
            return p
        try:
            p.parent.mkdir(parents=True, exist_ok=True)
        except OSError:
            return path  # (the autosave says why it cannot write)
        lock = QtCore.QLockFile(str(p) + ".lock")
        lock.setStaleLockTime(0)  # stale only when its process is gone (Qt's default: after 30 s too)
        if lock.tryLock(0):
            _claimed[str(p)] = lock
            return p
    return path


def _centroid(points) -> tuple[float, float]:
    """The centroid of a ring (its mean point when it has no area)."""
    import numpy as np
    import shapely

    poly = shapely.Polygon(np.asarray(points, float))
    if poly.is_valid and poly.area > 0:
        return float(poly.centroid.x), float(poly.centroid.y)
    x, y = np.asarray(points, float).mean(axis=0)
    return float(x), float(y)


#: formats with a polygon type (a CSV's rows, a GPX track, a DXF polyline are an outline closed or not)
_TYPED = frozenset({".kml", ".kmz", ".geojson", ".json", ".shp"})


def _lines_only(path: Path, pointset) -> str | None:
    """A note when a file that has polygons has none, only open lines (one of them becomes the outline)."""
    if pointset is None or path.suffix.lower() not in _TYPED or any(pl.closed for pl in pointset.polylines):
        return None
    longest = max(pointset.polylines, key=lambda pl: len(pl.points))
    n = len(pointset.polylines)
    return (
        f"{path.name} has no polygon, only {n} open line{'s' * (n != 1)}: the longest ('{longest.name}', "
        f"{len(longest.points)} points) is closed into the outline — a lake's shore is a Polygon in the file"
    )


def _degrees_note(name: str, points) -> str:
    """What a lon/lat outline kept in degrees costs: its cells' stretch east-west at its latitude."""
    import math

    _lon, lat = _centroid(points)
    k = math.cos(math.radians(lat))
    return (
        f"{name}: kept in longitude/latitude degrees — at latitude {lat:.1f}° a degree east is {k:.2f} of a "
        "degree north, so square cells in degrees are "
        f"{1 / k:.1f}× longer north-south than east-west on the ground and a cell size is in degrees; "
        "import it again and answer Yes to project it to metres"
    )


class IOController(ExportMixin, QtCore.QObject):
    """File operations of a :class:`~app.main_window.MainWindow`.

    It talks to the window only through ``message``, ``error``, ``set_tool``,
    ``quiet`` (no modal dialogs) and the canvas's ``fit``.
    """

    def __init__(self, window, settings: QtCore.QSettings, recovery_path: Path) -> None:
        super().__init__(window)
        self.win = window
        self.doc = window.doc
        self.stack = window.stack
        self.editor = window.editor
        self.settings = settings
        self.recovery_path = claim_recovery(Path(recovery_path))
        self.recent_menu: QtWidgets.QMenu | None = None
        self._autosave = QtCore.QTimer(self)
        self._autosave.setSingleShot(True)
        self._autosave.setInterval(DEBOUNCE_MS)
        self._autosave.timeout.connect(lambda: self.autosave(wait=False))
        # the autosave's writes run in a thread of their own (a 40 000-point lake: 0.4 s of the GUI
        # thread's CPU, a 1.6 s stall at load 9, one second after every edit); one at a time, the newest
        # project next
        self._writer: threading.Thread | None = None
        self._write_lock = threading.Lock()
        self._write_next: tuple | None = None  # (project, path saved to) the writer takes next
        self.write_failed.connect(self._autosave_failed)
        self._first_unsaved = 0.0  # when the oldest edit not yet autosaved was made
        self.stack.indexChanged.connect(self._edited)
        self.stack.cleanChanged.connect(self._clean_changed)

    # ----------------------------------------------------------- helpers
    @property
    def quiet(self) -> bool:
        return bool(getattr(self.win, "quiet", False))

    def _parent(self):
        return self.win

    # ---------------------------------------------------------- project
    def set_project(self, project: Project, path: Path | None = None) -> None:
        """Start over with ``project`` (no undo history, nothing unsaved)."""
        self.win.solver.drop()  # (stopped, its grid became the new project's)
        self.stack.clear()
        self.doc.reset(project, path)
        self.win.canvas.fit()
        self.stack.setClean()
        if project.layout is not None:  # a lake's layout: its blocks and cells in front, not one block's ξ, η
            self.win.show_lake()

    def maybe_save(self) -> bool:
        """Ask about unsaved changes; False when the user cancels."""
        if self.stack.isClean() or self.quiet:
            return True
        b = QtWidgets.QMessageBox.StandardButton
        r = QtWidgets.QMessageBox.question(
            self._parent(),
            "Unsaved changes",
            "The project has unsaved changes. Save them?",
            b.Save | b.Discard | b.Cancel,
        )
        if r == b.Cancel:
            return False
        if r == b.Save:
            return self.save()
        return True

    def new_project(self) -> None:
        if self.maybe_save():
            self.set_project(Project())
            self.win.set_tool("draw")

    def open_dialog(self) -> None:
        if not self.maybe_save():
            return
        path, _ = QtWidgets.QFileDialog.getOpenFileName(
            self._parent(), "Open project", self.last_dir(), "gcmesh case (*.toml);;All files (*)"
        )
        if path:
            self.open_path(path)

    def open_path(self, path, *, project_lonlat: bool | None = None) -> bool:
        """Open a case file, or import a point file (by suffix; ``project_lonlat`` as for
        :meth:`import_points`: None asks whether to project lon/lat degrees)."""
        path = Path(path)
        if path.suffix.lower() != ".toml":
            return self.import_points(path, project_lonlat=project_lonlat)
        try:
            project = off_gui(fio.load_project, path)  # (a laid-out lake of 45 blocks: 0.2-0.6 s of CPU)
        except (MeshcoreError, OSError) as exc:
            self.win.error("Cannot open project", exc)
            return False
        self.set_project(project, path)
        self.add_recent(path)
        lay = project.layout
        for note in lay.notes if lay is not None else ():  # the Lake panel counts them: said in full again
            self.doc.report("info", f"layout: {note}")
        for note in lay.details if lay is not None else ():
            self.doc.report("info", f"layout (detail): {note}")
        # a lake's layout is edited with the Layout tool (the Edit tool has no points of it to drag)
        self.win.set_tool("layout" if project.layout is not None else "edit")
        if self._offer_layout(project, path):
            return True
        if self.win.solver.auto and any(b.ready for b in project.blocks):  # it said "press F5" as it solved
            self.win.message(f"Opened {path.name}: generating its grid (auto-generate on)")
        else:
            self.win.message(f"Opened {path.name}: press F5 to generate")
        return True

    def _offer_layout(self, project: Project, path: Path) -> bool:
        """A lake saved before its Auto layout, opened: Auto layout offered as its import offered it (it
        said "press F5 to generate", and F5 makes the one block the offer calls poor).  True: offered."""
        lake = project.lake
        if lake is None or project.layout is not None or len(project.blocks) != 1:
            return False
        branched = off_gui(looks_branched, lake.outline, lake.holes)
        if not (branched or project.crs):  # plain numbers of a compact shape: one block, as imported
            return False
        self._offer_auto_layout(path.name, len(lake.holes), branched)
        self.win.message(
            f"Opened {path.name}: a lake without a layout yet; Auto layout (Ctrl+L) lays it out in blocks for a "
            "model grid (F5 alone: one block)"
        )
        return True

    def open_example(self, name: str, *, confirm: bool = True) -> bool:
        """Open a bundled example; a lake opens as its file imported (Auto layout offered), its
        import not an undo step (the example is where the history starts)."""
        if confirm and not self.maybe_save():
            return False
        lake = lake_file(name)
        if lake is not None:  # it opened as one block with automatic corners, ~20° off orthogonal
            self.set_project(Project(), None)
            if not self.import_points(lake, project_lonlat=True, recent=False, title=LAKES[name][1]):
                return False
            self.stack.clear()
            self.stack.setClean()
            return True
        try:
            project, _path = load_example(name)
        except (MeshcoreError, OSError, KeyError) as exc:
            self.win.error("Cannot open example", exc)
            return False
        self.set_project(project, None)
        self.win.set_tool("edit")
        self.win.message(f"Example {name!r}: press F5 to generate; drag points to reshape")
        return True

    def save(self) -> bool:
        if self.doc.path is None:
            return self.save_as()
        return self.save_to(self.doc.path)

    def suggested_path(self) -> str:
        """What the Save dialog offers: the file saved to, or the project's title (the imported lake's
        file name) as a .toml in the last folder used, or "untitled.toml" there (the Export dialog
        offers the same name with its format's suffix)."""
        if self.doc.path is not None:
            return str(self.doc.path)
        stem = re.sub(r'[\\/:*?"<>|]+', "_", self.doc.project.title).strip(" .") or "untitled"
        return str(Path(self.last_dir()) / f"{stem}.toml")

    def save_as(self) -> bool:
        path, _ = QtWidgets.QFileDialog.getSaveFileName(
            self._parent(), "Save project", self.suggested_path(), "gcmesh case (*.toml)"
        )
        if not path:
            return False
        if not path.endswith(".toml"):
            path += ".toml"
        return self.save_to(Path(path))

    def save_to(self, path: Path) -> bool:
        try:
            fio.save_project(self.doc.project, path)
        except (MeshcoreError, OSError, ValueError) as exc:
            self.win.error("Cannot save project", exc)
            return False
        self.doc.set_path(path)
        self.stack.setClean()
        self.add_recent(path)
        p = self.doc.project
        skipped = [b.name for b in p.blocks if not b.ready and (len(b.points) or b.boundary is not None)]
        note = f" (not saved: {', '.join(skipped)} — no closed loop with corners yet)" if skipped else ""
        self.win.message(f"Saved {path}{note}", error=bool(skipped))
        return True

    # ------------------------------------------------------------ import
    def import_dialog(self) -> None:
        path, _ = QtWidgets.QFileDialog.getOpenFileName(
            self._parent(), "Import boundary points", self.last_dir(), fio.POINT_FILTER
        )
        if path:
            self.import_points(Path(path))

    def import_points(
        self,
        path: Path,
        *,
        project_lonlat: bool | None = None,
        part: int | None = None,
        again: bool = False,
        recent: bool = True,
        title: str | None = None,
    ) -> bool:
        """Read points as a new closed block with automatic corners (undoable).

        A lake outline on the map (lon/lat, or a CRS the file declares) or water with islands or arms
        gets Auto layout offered (:meth:`app.lake_controller.LakeController.offer`; ``--solve`` takes
        it); plain numbers without a CRS of a compact shape (a duct, an airfoil) stay one block.

        A lake file of several separate parts of water opens part ``part`` (1: the largest); with
        ``None`` (or a part the file no longer has) a dialog asks which
        (:class:`app.parts_dialog.PartsDialog`; quiet: the largest).  ``again``: File ▸ Open recent
        (``part`` the one opened last time: the message says so).  ``recent``: File ▸ Open recent
        lists it; ``title``: the project's (default: the file's name).
        """
        path = Path(path)
        try:  # (reading and every heavy step of the import: off the GUI thread, the window drawing meanwhile)
            pd = off_gui(fio.read_points, path)
        except (MeshcoreError, OSError, ValueError) as exc:
            self.win.error("Cannot import points", exc)
            return False
        pts = pd.points
        if len(pts) < 3:  # no lake, no block: one error (it also warned "not read as a lake (needs at least 3
            # distinct points); its largest line is imported as one block", and nothing was imported)
            self.win.error("Cannot import points", f"{path}: needs at least 3 points, found {len(pts)}")
            return False
        if pd.note:  # metres in a lon/lat format: read as local metres (the app has no --source-crs)
            self.doc.report("warning", pd.note)
        lines_only = _lines_only(path, pd.pointset)
        if lines_only:  # a KML of a road or a centreline became a lake of its points, unsaid
            self.doc.report("warning", lines_only)
        # a lake's project gets a new lake, in the file's own frame (the UTM zone of a lon/lat outline,
        # none for metres); otherwise the points join the project in its frame (a background traced)
        replace = self.doc.project.lake is not None
        frame = None if replace else fio.project_frame(self.doc.project)
        if pd.pointset is not None:
            from meshcore.cli.lakefile import lonlat_order_note, swapped_degrees_note

            note = lonlat_order_note(pd.pointset) if pd.lonlat else swapped_degrees_note(pd.pointset)
            if note:  # as meshcore mesh notes it (its --columns: a header "lat,lon" in the file here)
                note = note.replace("give --columns 1 0", "add the header 'lat,lon' to the file")
                note = re.sub(r"give --columns \d+ \d+", "name the columns 'lat' and 'lon' in the file's header", note)
                self.doc.report("warning", note)
        if pd.lonlat:
            if project_lonlat is None and not self.quiet:
                target = fio.projection_named(pd, frame)
                lon, lat = _centroid(pd.points)  # where the lake lands (a lon, lat header over lat, lon values)
                r = QtWidgets.QMessageBox.question(
                    self._parent(),
                    "Geographic coordinates",
                    f"{path.name} holds longitude/latitude degrees (centroid lon {lon:.5f}, lat {lat:.5f})."
                    f"\n\nProject them to metres "
                    f"({target}, relative to a round local origin)? Grids in degrees are distorted.",
                )
                project_lonlat = r == QtWidgets.QMessageBox.StandardButton.Yes
            if project_lonlat is None or project_lonlat:
                try:
                    pts, frame = off_gui(fio.to_local, pd, frame)
                except (MeshcoreError, ValueError) as exc:
                    self.win.error("Cannot project coordinates", exc)
                    return False
        elif pd.pointset is not None and pd.pointset.crs:  # a projected CRS the file declares (.prj, GeoJSON)
            from meshcore.crs import Frame, is_web_mercator

            # into the project's CRS and origin, or kept as they are (origin 0) as meshcore mesh keeps them
            # (Web Mercator, whose metres are not metres, to UTM as meshcore mesh takes it)
            if frame is None or not frame.crs:
                frame = None if is_web_mercator(pd.pointset.crs) else Frame(pd.pointset.crs, (0.0, 0.0), None)
            try:
                pts, frame = off_gui(fio.to_local, pd, frame)
            except (MeshcoreError, ValueError) as exc:
                self.win.error("Cannot project coordinates", exc)
                return False
        asked_part = part
        lake, (k_part, n_parts), refused = self._read_lake(
            pd, frame, lonlat=bool(pd.lonlat and project_lonlat is not False), part=part
        )
        if k_part == 0:  # the parts dialog cancelled: nothing imported
            self.win.message(f"Import of {path.name} cancelled")
            return False
        if lake is not None:
            pts = lake.outline
        # a lake of three points (a triangle) is water that Auto layout grids, as meshcore mesh does; its
        # block gets no corners (three points cannot be four) until points are added
        if len(pts) < (3 if lake is not None else 4):
            self.win.error("Cannot import points", f"{path}: needs at least 4 points, found {len(pts)}")
            return False
        stem = f"{path.stem}_part{k_part}" if n_parts > 1 else path.stem  # as meshcore mesh --case names it
        # the corners and cells of the one block (the Winslow cell ratio: 0.5 s on 40 000 points)
        block = off_gui(block_from_points, pts, stem)
        # water the layout refuses (an outline that crosses itself): no Auto layout offered, only to fail
        branched = lake is not None and not refused and off_gui(looks_branched, lake.outline, lake.holes)
        # a lake on the map (lon/lat, or a CRS the file declares) is water to model: its grid is the layout
        # meshcore mesh makes (one block with automatic corners was ~20° off orthogonal on a compact lake);
        # plain numbers without a CRS (a duct, an airfoil, a shape of the paper) stay one block
        on_map = lake is not None and bool(pd.lonlat or pd.pointset.crs)
        offered = (branched or on_map) and not refused
        # the one block's automatic corners: advice about them is noise beside the Auto layout offer, or
        # beside an outline that crosses itself (its "reflex vertex (interior angle 315°)" of a bow tie's
        # crossing); until F5 makes that block or the user moves a corner
        if (offered or refused) and lake is not None:
            self.win.hold_corner_advice(lake.outline, block.corners)
        self._add_imported(block, frame, path.name, lake=lake, replace=replace, title=title or stem)
        if recent:  # File ▸ Open recent imports it again (the same part of water) and remembers its folder
            self.add_recent(path, part=k_part if n_parts > 1 else None, lonlat=project_lonlat if pd.lonlat else None)
        projected = ""
        if frame is not None and pd.lonlat:  # where it lands: a lon, lat header over lat, lon values shows here
            lon, lat = _centroid(pd.points)
            projected = f" (centroid lon {lon:.5f}, lat {lat:.5f}; projected to {frame.crs})"
        elif pd.lonlat and project_lonlat is False:  # "No" to projecting: said, with what it costs
            projected = " (kept in degrees, not projected)"
            self.doc.report("warning", _degrees_note(path.name, pd.points))
        if pd.note:
            projected = " (as local metres: its numbers are no longitude/latitude)"
        n_isl = len(lake.holes) if lake is not None else 0
        isl = f" and {n_isl} island{'s' * (n_isl != 1)}" if n_isl else ""  # it said "1 island(s)"
        which = f" (part {k_part} of {n_parts}: Messages list the others)" if n_parts > 1 else ""
        if n_parts > 1 and again and asked_part == k_part:
            which = f" (part {k_part} of {n_parts}, the one opened last time: File ▸ Import asks for another)"
        if refused:
            self.win.message(
                f"Imported {len(pts)} points{isl} from {path.name}{which}{projected}; {refused} — Auto layout "
                "cannot lay it out: fix the outline (Edit tool) first"
            )
        elif block.corners is None:  # a triangle: no four corners; the lake's layout grids it
            self.win.message(
                f"Imported {len(pts)} points{isl} from {path.name}{which}{projected}; too few for four corners "
                f"— Lake ▸ Auto layout splits it into blocks and grids it"
            )
        elif offered:
            self.win.message(
                f"Imported {len(pts)} points{isl} from {path.name}{which}{projected}; Auto layout (Ctrl+L) lays "
                f"it out in blocks for a model grid (F5 alone: one block, automatic corners)"
            )
        else:
            self.win.message(
                f"Imported {len(pts)} points{isl} from {path.name}{which}{projected}; corners chosen "
                f"automatically — adjust with the Corners tool, then F5; Lake ▸ Auto layout splits it into blocks"
            )
        if offered:
            self._offer_auto_layout(path.name, n_isl, branched)
        return True

    def _offer_auto_layout(self, name: str, n_islands: int, branched: bool) -> None:
        """The Lake panel shown with Auto layout offered for ``name`` (why: its islands, or its arms
        and bends when ``branched``), and auto-generate skipped: not the one block the offer calls poor
        (its grid covered the islands, its repairs filled Messages, a big lake's solve ran on while the
        user chose Auto layout); F5 makes it."""
        self.win.solver.skip_auto()
        why = f"{n_islands} island{'s' * (n_islands != 1)}" if n_islands else "the water has arms or bends"
        self.win.show_lake()
        self.win.lake_ctl.offer(name, why if branched else None)

    def _read_lake(self, pd, frame, *, lonlat: bool, part: int | None = None):
        """The lake (shore and islands) of the file's rings, in the frame of the imported block (None
        if none), (the part opened, the number of parts): part 0 when the parts dialog was
        cancelled, and why the layout would refuse its water (None: it would not)."""
        if pd.pointset is None:
            return None, (1, 1), None
        try:
            parts, fr, notes = off_gui(read_lake_parts, pd.pointset, frame, lonlat=lonlat)
            metres = not (pd.lonlat and not lonlat)  # lon/lat kept as degrees: areas in degrees²
            if len(parts) == 1:
                k = 1
            elif part is not None and 1 <= part <= len(parts):
                k = part
            else:  # asked, or remembered from a file that has fewer parts now
                k = self.choose_part(pd.path, parts, metres, frame=fr, lonlat=bool(pd.lonlat))
            if k == 0:
                return None, (0, len(parts)), None
            outer, islands, _fr, notes = off_gui(read_lake, pd.pointset, frame, lonlat=lonlat, part=k, metres=metres)
        except (MeshcoreError, ValueError) as exc:  # meshcore mesh refuses the file: say why here too
            self.doc.report(
                "warning",
                f"{Path(pd.path).name}: not read as a lake ({exc}); its largest line is imported as one block",
            )
            return None, (1, 1), None
        refused = None
        try:  # what the water polygon changes (islands that touch joined): meshcore mesh says it on reading
            notes = notes + off_gui(water, outer, islands)[1]
        except (MeshcoreError, ValueError) as exc:  # the layout will refuse it, naming the ring: said now
            # (was only logged: the user saw the corners' "reflex vertex (interior angle 307°)" of a bow tie)
            refused = str(exc)
            notes = [*notes, f"{exc} — meshcore mesh refuses it; fix the outline (Edit tool) before Auto layout"]
        for note in notes:  # what meshcore mesh prints as notes
            self.doc.report("warning", f"{Path(pd.path).name}: {note}")
        return Lake(outline=outer, holes=tuple(islands)), (k, len(parts)), refused

    def choose_part(self, path, parts: list, metres: bool = True, *, frame=None, lonlat: bool = False) -> int:
        """The part of the water to open (from 1, largest first), asked in a dialog; 0: cancelled.
        Quiet (tests, scripts): the largest, as ``meshcore mesh --part 1``."""
        if self.quiet:
            return 1
        from .parts_dialog import PartsDialog

        dlg = PartsDialog(Path(path).name, parts, metres=metres, frame=frame, lonlat=lonlat, parent=self._parent())
        return dlg.chosen() if dlg.exec() == QtWidgets.QDialog.DialogCode.Accepted else 0

    def _add_imported(
        self, block: Block, frame, name: str, *, lake=None, replace: bool = False, title: str | None = None
    ) -> None:
        """Put an imported block into the first empty block (or add it), as one undo step; with
        ``replace`` (a project holding a lake) it replaces the lake, its layout, cuts and frame."""
        p = self.doc.project
        if replace:  # a new outline replaces the lake, laid out or not (undo brings it back)
            self.win.solver.drop()  # the solve of the lake before: its grid is of no block of this one
            p = p.replaced(
                blocks=(Block(name="block"),), lake=None, cut_lines=(), crs="", origin=(0.0, 0.0), source_crs=""
            )
        # an empty block, or a stray click's (an open block of a point or two): the file goes there, not
        # beside it (the stray one stayed in the Blocks panel, "1 points, open", until Auto layout)
        empty = [k for k, b in enumerate(p.blocks) if len(b.points) < 3 and not b.closed and b.boundary is None]
        if empty:
            k = empty[0]
            after = p.with_block(k, block)
        else:
            after = p.replaced(blocks=(*p.blocks, block))
            k = len(after.blocks) - 1
        if replace or not p.title:  # the case's title (and the Save dialog's name) is the lake's file name
            after = after.replaced(title=title or Path(name).stem)
        if frame is not None and frame.crs:
            after = after.replaced(crs=frame.crs, origin=tuple(frame.origin), source_crs=frame.source_crs or "")
        if lake is not None and after.layout is None and (k == 0 or p.lake is None):
            # the project's lake (islands, cell size, layout) is this outline's, also when a
            # block drawn before (a stray click in Draw) keeps it from being block 0
            after = after.replaced(lake=lake)
        self.editor.replace_project(after, f"Import {name}")
        if replace and self.doc.path is not None:  # another lake: Save must not write it over the first's file
            self.doc.report(
                "info", f"{name} replaces the lake of {self.doc.path.name}: Save asks for a file (the first is kept)"
            )
            self.doc.set_path(None)
        self.doc.set_active(k)
        self.win.canvas.fit()
        self.win.set_tool("edit")

    # ---------------------------------------------------- recent, folders
    def last_dir(self) -> str:
        return str(self.settings.value("last_dir", str(Path.home())))

    def remember_dir(self, path: Path) -> None:
        self.settings.setValue("last_dir", str(Path(path).parent))

    def add_recent(self, path: Path, *, part: int | None = None, lonlat: bool | None = None) -> None:
        """First in File ▸ Open recent; ``part``: the part of water opened of a file of several,
        ``lonlat``: the answer to "project lon/lat to metres?", both used again from there without
        asking (the records "recent_parts" and "recent_lonlat")."""
        rec = ([str(path)] + [p for p in self.recent() if p != str(path)])[:MAX_RECENT]
        self.settings.setValue("recent", rec)
        for key, value, kind in (("recent_parts", part, int), ("recent_lonlat", lonlat, bool)):
            kept = {p: v for p, v in self._recent_record(key, kind).items() if p in rec and p != str(path)}
            if value is not None:
                kept[str(path)] = kind(value)
            self.settings.setValue(key, json.dumps(kept))
        self.remember_dir(path)
        self.refresh_recent()

    def _recent_record(self, key: str, kind) -> dict:
        try:
            v = json.loads(str(self.settings.value(key, "{}") or "{}"))
            return {str(p): kind(k) for p, k in v.items()} if isinstance(v, dict) else {}
        except (ValueError, TypeError, AttributeError):  # a record written by hand or broken: none
            return {}

    def recent_parts(self) -> dict[str, int]:
        """The part of water opened last of each recent file of several parts (path: part from 1)."""
        return self._recent_record("recent_parts", int)

    def recent_lonlat(self) -> dict[str, bool]:
        """Whether each recent lon/lat file was projected to metres when imported last (path: answer)."""
        return self._recent_record("recent_lonlat", bool)

    def open_recent(self, path: str) -> bool:
        """File ▸ Open recent: the file again (a file of several parts of water: the part opened last;
        lon/lat: projected or not as the user answered last)."""
        if not self.maybe_save():
            return False
        part = self.recent_parts().get(str(path))
        lonlat = self.recent_lonlat().get(str(path))
        if (part is None and lonlat is None) or Path(path).suffix.lower() == ".toml":
            return self.open_path(path)
        return self.import_points(Path(path), part=part, project_lonlat=lonlat, again=True)

    def recent(self) -> list[str]:
        v = self.settings.value("recent", [])
        if isinstance(v, str):
            v = [v]
        return list(v or [])

    def refresh_recent(self) -> None:
        if self.recent_menu is None:
            return
        self.recent_menu.clear()
        rec = self.recent()
        for p in rec:
            self.recent_menu.addAction(p, lambda p=p: self.open_recent(p))
        self.recent_menu.setEnabled(bool(rec))

    # ---------------------------------------------------------- autosave
    def _edited(self, _index: int) -> None:
        """An edit (or undo/redo): autosave soon; at once when edits have kept coming for a while.

        Not during a drag: its steps merge into one undo step and writing the project (a second
        on a big lake) would stall the drag; the drag's last step is saved ``DEBOUNCE_MS`` after it.
        """
        now = time.monotonic()
        if not self._autosave.isActive():
            self._first_unsaved = now
        if now - self._first_unsaved >= MAX_DELAY_S and not self._dragging():
            self.autosave(wait=False)
        else:
            self._autosave.start()

    def _dragging(self) -> bool:
        """True while the user drags a point or a layout handle (or its edit is being computed),
        or while Generate's solve runs: the save (a few tenths of a second of Python on a big
        lake) would take the solver's turn; the project is saved when the solve ends.  (With
        auto-generate every edit solves again: edits are saved while they keep coming.)"""
        tool = getattr(getattr(self.win, "canvas", None), "tool", None)
        lake = getattr(self.win, "lake_ctl", None)
        solver = getattr(self.win, "solver", None)
        solving = solver is not None and solver.state == "running" and not solver.auto
        return bool(getattr(tool, "dragging", False)) or bool(lake is not None and lake.editing) or solving

    def _clean_changed(self, clean: bool) -> None:
        if clean:  # saved (or undone back to the saved state): nothing to recover
            self._autosave.stop()
            self.discard_recovery()

    def autosave(self, *, wait: bool = True) -> None:
        """Write the project to the recovery files when it has unsaved edits (after a drag ends).
        ``wait`` False (the debounce timer): in the writer thread, the GUI thread going on."""
        self._autosave.stop()
        if self.stack.isClean():
            return
        if self._dragging():
            self._autosave.start()
            return
        job = (self.doc.project, self.doc.path)  # immutable: the thread reads it as it is now
        if wait:
            self.wait_autosave()
            try:
                recovery.write(job[0], self.recovery_path, job[1])
            except (OSError, MeshcoreError, ValueError) as exc:
                self._autosave_failed(exc)
            return
        with self._write_lock:
            self._write_next = job
            if self._writer is not None and self._writer.is_alive():
                return  # the running writer takes it next
            self._writer = threading.Thread(target=self._write_loop, name="gcmesh-autosave", daemon=True)
            self._writer.start()

    write_failed = QtCore.Signal(object)  # an autosave in the writer thread failed (its exception)

    def _write_loop(self) -> None:
        while True:
            with self._write_lock:
                job, self._write_next = self._write_next, None
                if job is None:
                    return
            try:
                recovery.write(job[0], self.recovery_path, job[1])
            except (OSError, MeshcoreError, ValueError) as exc:
                self.write_failed.emit(exc)  # (to the GUI thread)

    @property
    def autosaving(self) -> bool:
        """True while the writer thread writes the recovery files."""
        return self._writer is not None and self._writer.is_alive()

    def wait_autosave(self) -> None:
        """Let the writer thread finish what it writes, and drop what it would write next."""
        with self._write_lock:
            self._write_next = None
        if self._writer is not None:
            self._writer.join()

    def _autosave_failed(self, exc) -> None:
        log.error("autosave to %s failed", self.recovery_path, exc_info=exc)
        self.win.message(f"autosave failed: {exc}", error=True)

    def discard_recovery(self) -> None:
        self.wait_autosave()  # (a write in flight would bring the files back after a save)
        try:
            recovery.discard(self.recovery_path)
        except OSError:
            log.warning("cannot remove the recovery file %s", self.recovery_path, exc_info=True)

    def offer_recovery(self, instead_of: str | None = None) -> bool:
        """After a crash: offer the autosaved project back (True when restored).  ``instead_of``: the
        file the app was started on, which is not opened when the project is restored (the question
        says so)."""
        if not recovery.exists(self.recovery_path):
            return False
        try:
            project, path = recovery.read(self.recovery_path)
        except (MeshcoreError, OSError, ValueError, KeyError, TypeError):
            log.exception("the recovery file %s cannot be read; it is removed", self.recovery_path)
            self.discard_recovery()
            return False
        what = recovery.describe(project, path, recovery.saved_at(self.recovery_path))
        if instead_of:  # (Yes said nothing of the file double-clicked: another lake came up, the file unsaid)
            what += f"\n\nYes: {instead_of} is not opened (File ▸ Open opens it then). No: {instead_of} opens."
        r = QtWidgets.QMessageBox.question(
            self._parent(),
            "Recover project",
            f"gcmesh did not shut down cleanly last time. Restore the autosaved project?\n\n{what}",
        )
        if r != QtWidgets.QMessageBox.StandardButton.Yes:
            self.discard_recovery()
            return False
        self.set_project(project, path)
        self.stack.resetClean()  # restored work counts as unsaved
        if project.layout is not None:  # a lake's layout is edited with the Layout tool (it stayed in Draw)
            self.win.set_tool("layout")
        return True

    def shutdown(self) -> None:
        """A clean exit: nothing to recover."""
        self._autosave.stop()
        self.discard_recovery()
