"""The places that miss a quality preset, drawn so the grid stays in sight at any count.

A modeller asks two things of the marks: *where are my bad places* and *which is worst*.  One dot
per miss answered neither once misses were many (59 % of a lake's nodes beyond Delft3D's
``|cos| ≤ 0.02``: the lake turned orange, the grid under it gone).  So the canvas marks at most one
place per :data:`PATCH_PX` × :data:`PATCH_PX` pixels of the screen — the worst miss there — and
rings the worst miss of all.  Zoomed in, patches are small in model units and every miss gets its
own mark again.  Pure NumPy here (:func:`thin_misses`); :class:`MissMarks` owns the two items.
"""

from __future__ import annotations

import numpy as np
import pyqtgraph as pg

from .items import Scatter, set_points

__all__ = ["PATCH_PX", "MissMarks", "thin_misses"]

#: one mark per square of this many screen pixels (a dot of 6 px covers at most a quarter of it)
PATCH_PX = 12.0


def thin_misses(points: np.ndarray, badness: np.ndarray, patch: float) -> np.ndarray:
    """Indices of the worst miss in each ``patch`` × ``patch`` square (model units), worst first.

    ``badness``: how far each place is beyond its limit (larger is worse; NaN counts as worst).
    Squares are fixed in model coordinates (anchored at the origin), so panning keeps the marks.
    """
    pts = np.asarray(points, float).reshape(-1, 2)
    bad = np.where(np.isnan(badness), np.inf, np.asarray(badness, float))
    if not len(pts):
        return np.zeros(0, dtype=int)
    if not patch > 0 or not np.isfinite(patch):
        return np.argsort(-bad, kind="stable")
    keys = np.floor(pts / patch).astype(np.int64)
    # by square, and the worst first inside a square: the first of each square is its worst
    order = np.lexsort((-bad, keys[:, 1], keys[:, 0]))
    k = keys[order]
    first = np.ones(len(order), bool)
    first[1:] = np.any(k[1:] != k[:-1], axis=1)
    kept = order[first]
    return kept[np.argsort(-bad[kept], kind="stable")]


class MissMarks:
    """The miss marks of a canvas: one orange dot per crowded patch, the worst ringed red."""

    def __init__(self, canvas) -> None:
        self.canvas = canvas
        self.dots = Scatter(size=6, symbol="o", pen=None, brush=pg.mkBrush(255, 127, 14, 200))
        self.dots.setZValue(31)
        self.worst = Scatter(size=15, symbol="o", pen=pg.mkPen("#d62728", width=2.5), brush=None)
        self.worst.setZValue(32)
        self.points = np.zeros((0, 2))
        self.badness = np.zeros(0)
        self.shown = np.zeros(0, dtype=int)  # indices into points of the marks drawn
        self.over_colours = False
        self._patch = 0.0  # the patch size (model units) the marks were thinned for
        self._style: bool | None = None

    def items(self) -> tuple:
        return (self.dots, self.worst)

    def set(self, points: np.ndarray | None) -> None:
        """The places that miss: ``(k, 2)``, or ``(k, 3)`` with how far beyond the limit (None: none)."""
        a = np.zeros((0, 3)) if points is None else np.asarray(points, float)
        a = a.reshape(len(a), -1) if len(a) else np.zeros((0, 3))
        self.points = a[:, :2].copy()
        self.badness = a[:, 2].copy() if a.shape[1] > 2 else np.zeros(len(a))
        self._patch = 0.0
        self.update()

    def update(self, force: bool = False) -> None:
        """Thin again for the view's pixel size (only when it changed by more than a quarter)."""
        patch = PATCH_PX * self.canvas.pixel()
        if not force and self._patch > 0 and 0.8 < patch / self._patch < 1.25:
            return
        self._patch = patch
        self.shown = thin_misses(self.points, self.badness, patch)
        self._restyle()
        set_points(self.dots, self.points[self.shown] if len(self.shown) else None)
        set_points(self.worst, self.points[self.shown[:1]] if len(self.shown) else None)

    def set_over_colours(self, on: bool) -> None:
        """Filled dots on a plain grid; thin dark rings over coloured cells (the colour shows through)."""
        self.over_colours = bool(on)
        self._restyle()

    def _restyle(self) -> None:
        """One size at any count: thinned to one per patch, the marks cannot crowd (a faint 3-px style
        for over 1000 marks left the 65 in a zoomed view unseen at the grid's crossings)."""
        if self.over_colours == self._style:
            return
        self._style = self.over_colours
        if self.over_colours:
            self.dots.setPen(pg.mkPen(0, 0, 0, 200, width=1))
            self.dots.setBrush(None)
            self.dots.setSize(6)
        else:
            self.dots.setPen(None)
            self.dots.setBrush(pg.mkBrush(255, 127, 14, 200))
            self.dots.setSize(6)

    def set_visible(self, on: bool) -> None:
        for it in self.items():
            it.setVisible(on)
