"""The background image: load, place over the outline, calibrate by two known points.

The maths (placing, composing the calibration) is in :mod:`app.geometry`;
this module reads the image and asks the user for the true coordinates.
"""

from __future__ import annotations

import logging

import numpy as np
from PySide6 import QtCore, QtGui, QtWidgets

from meshcore import MeshcoreError

from . import geometry as geo
from . import io_adapter as fio
from .project import Background

__all__ = ["BackgroundController", "read_image"]

log = logging.getLogger(__name__)


def read_image(path: str) -> np.ndarray | None:
    """An RGBA image as an ``(h, w, 4)`` uint8 array, row 0 the *bottom* row (None if unreadable)."""
    img = QtGui.QImage(str(path))
    if img.isNull():
        return None
    img = img.convertToFormat(QtGui.QImage.Format.Format_RGBA8888)
    w, h = img.width(), img.height()
    arr = np.frombuffer(img.constBits(), dtype=np.uint8, count=img.sizeInBytes())
    arr = arr.reshape(h, img.bytesPerLine())[:, : 4 * w].reshape(h, w, 4)
    return np.flipud(arr).copy()  # v runs upwards like y


class BackgroundController(QtCore.QObject):
    """Load and calibrate the background image of a window's project (undoable edits)."""

    def __init__(self, window) -> None:
        super().__init__(window)
        self.win = window
        self.doc = window.doc
        self._cache: tuple[str, np.ndarray] | None = None
        self.doc.project_changed.connect(self._show)

    def image(self, path: str) -> np.ndarray | None:
        """The image at ``path`` (cached: every edit redraws the background)."""
        if self._cache is not None and self._cache[0] == path:
            return self._cache[1]
        arr = read_image(path)
        if arr is None:
            self.win.message(f"cannot load background image {path}", error=True)
            return None
        self._cache = (path, arr)
        return arr

    def _show(self, project) -> None:
        bg = project.background
        img = self.image(bg.path) if bg is not None else None
        self.win.canvas.set_background(img, bg.transform if img is not None else None)

    def dialog(self) -> None:
        path, _ = QtWidgets.QFileDialog.getOpenFileName(
            self.win, "Background image", self.win.io.last_dir(), "Images (*.png *.jpg *.jpeg *.tif *.bmp)"
        )
        if path:
            self.load(path)

    def load(self, path: str) -> None:
        """Show the image at ``path`` behind the outline, fitted over it."""
        img = self.image(path)
        if img is None:
            return
        h, w = img.shape[:2]
        bounds = self.doc.project.bounds()
        tr = geo.fit_image(w, h, bounds)
        project = self.doc.project.replaced(background=Background(str(path), tr))
        self.win.editor.replace_project(project, "Load background")
        # the image covers the outline and reaches past it on one side: show all of it
        self.win.canvas.fit()
        self.win.message("Background loaded: File ▸ Calibrate to place it by two known points, then trace with Draw")

    def ask_true_points(self, pair) -> None:
        """The calibration tool picked two points: ask where they really are, then calibrate."""
        bg = self.doc.project.background
        if bg is None:
            self.win.message("Load a background image first")
            self.win.set_tool("pan")
            return
        p = self.doc.project
        answer = _TrueCoordinatesDialog(self.win, pair, p.crs, p.origin).ask()
        self.win.set_tool("draw")  # first: its tip would hide the outcome in the status bar
        if answer is not None:
            true, kind = answer
            try:
                self.calibrate(pair, true, lonlat=kind == "lonlat", world=kind == "world")
            except (ValueError, MeshcoreError) as exc:
                self.win.error("Calibration", exc)

    def calibrate(self, shown, true, *, lonlat: bool = False, world: bool = False) -> None:
        """Move the background so that the two ``shown`` model points land on ``true``.

        With ``lonlat`` the true points are longitude/latitude degrees: they are
        projected to the project's CRS, or, when it has none yet, to the UTM zone
        of the points, which the project then adopts (one undo step).  With ``world``
        they are projected metres in the project's CRS (easting, northing, as a map's
        grid gives them), not the model's coordinates relative to its local origin.
        """
        project = self.doc.project
        bg = project.background
        if world:
            ox, oy = project.origin
            true = [(float(x) - ox, float(y) - oy) for x, y in true]
        elif lonlat:
            local, frame = fio.lonlat_to_local(true, fio.project_frame(project))
            true = [tuple(p) for p in local]
            if not project.crs and frame.crs:
                # a project without a CRS adopts the frame of the calibration points
                project = project.replaced(
                    crs=frame.crs, origin=tuple(frame.origin), source_crs=frame.source_crs or "EPSG:4326"
                )
        tr = geo.compose_similarity(bg.transform, shown, true)
        self.win.editor.replace_project(project.replaced(background=Background(bg.path, tr)), "Calibrate background")
        self.win.canvas.fit()  # the image moved to its true place: show it there
        where = f" ({project.crs}, local origin {project.origin[0]:.0f}, {project.origin[1]:.0f})" if lonlat else ""
        self.win.message(f"Background calibrated{where}; trace the outline with Draw")


class _TrueCoordinatesDialog(QtWidgets.QDialog):
    """Asks for the true coordinates of two picked points: model x, y, projected easting and
    northing in the project's CRS (when it has one), or longitude, latitude."""

    def __init__(self, parent, pair, crs: str, origin=(0.0, 0.0)) -> None:
        super().__init__(parent)
        self.setWindowTitle("Calibrate background")
        self._pair, self._origin = [tuple(map(float, p)) for p in pair], tuple(map(float, origin))
        form = QtWidgets.QFormLayout(self)
        self.kind = QtWidgets.QComboBox()
        self.kind.addItem("model x, y", "model")
        if crs:
            self.kind.addItem(f"easting, northing (m, {crs})", "world")
        self.kind.addItem("longitude, latitude (degrees)", "lonlat")
        self.kind.setToolTip(
            f"longitude, latitude: projected to the project's {crs}"
            if crs
            else "longitude, latitude: projected to the UTM zone of the two points"
        )
        form.addRow("Coordinates are", self.kind)
        self.edits = []
        for k in range(2):
            ex, ey = QtWidgets.QLineEdit(), QtWidgets.QLineEdit()
            row = QtWidgets.QHBoxLayout()
            row.addWidget(ex)
            row.addWidget(ey)
            form.addRow(f"point {k + 1}", row)
            self.edits += [ex, ey]
        self._fill()
        self.kind.currentIndexChanged.connect(self._fill)
        sb = QtWidgets.QDialogButtonBox.StandardButton
        bb = QtWidgets.QDialogButtonBox(sb.Ok | sb.Cancel)
        bb.accepted.connect(self.accept)
        bb.rejected.connect(self.reject)
        form.addRow(bb)

    def _fill(self, *_args) -> None:
        """The picked points where they are now, in the frame chosen (blank for lon/lat: unknown)."""
        kind = self.kind.currentData()
        shift = self._origin if kind == "world" else (0.0, 0.0)
        for k, (x, y) in enumerate(self._pair):
            for e, v, o in ((self.edits[2 * k], x, shift[0]), (self.edits[2 * k + 1], y, shift[1])):
                e.setText("" if kind == "lonlat" else f"{v + o:.1f}" if kind == "world" else f"{v:.6g}")

    def answer(self):
        """``(((x0, y0), (x1, y1)), kind)`` as typed, kind "model", "world" or "lonlat" (ValueError: not numbers)."""
        v = [float(e.text()) for e in self.edits]
        return ((v[0], v[1]), (v[2], v[3])), self.kind.currentData()

    def ask(self):
        """:meth:`answer` after OK, or None when cancelled or not numbers."""
        if self.exec() != QtWidgets.QDialog.DialogCode.Accepted:
            return None
        try:
            return self.answer()
        except ValueError as exc:
            self.parent().error("Calibration", exc)
            return None
