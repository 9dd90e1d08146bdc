"""The dialog that asks which part of the water to open when a file holds several.

A lake file may hold several separate pieces of water (a reservoir split by a causeway, several
placemarks of one KML, a MultiPolygon).  ``meshcore mesh`` grids every part into one grid
(:mod:`meshcore.lakeparts`); the app's project holds one lake, so on import the user picks the
part to open from a table of them (largest first, numbered as ``meshcore mesh --part`` numbers
them): name, water area, islands and where it lies.  The largest is chosen at first.
"""

from __future__ import annotations

from typing import Any

from PySide6 import QtCore, QtWidgets

from .lake import area_text, near_header, part_area, part_centres

__all__ = ["PartsDialog", "part_rows"]


def part_rows(
    parts: list, *, metres: bool = True, frame: Any = None, lonlat: bool = False
) -> list[tuple[str, str, str, str, str]]:
    """Rows of the table: number, name, water area, islands, centre (``parts`` as
    :func:`app.lake.read_lake_parts` gives them; the centre as :func:`part_centres` says)."""
    centres, _unit = part_centres(parts, frame, lonlat=lonlat, metres=metres)
    rows = []
    for k, (part, (x, y)) in enumerate(zip(parts, centres, strict=True), start=1):
        name, _outer, islands = part
        rows.append((str(k), str(name), area_text(part_area(part), metres), str(len(islands)), f"{x:.6g}, {y:.6g}"))
    return rows


class PartsDialog(QtWidgets.QDialog):
    """Choose one part of the water (:meth:`chosen`: its number from 1, largest first)."""

    HEADERS = ("part", "name", "water area", "islands", "near (x, y)")

    def __init__(
        self,
        file_name: str,
        parts: list,
        *,
        metres: bool = True,
        frame: Any = None,
        lonlat: bool = False,
        parent: Any = None,
    ) -> None:
        """``frame``: the frame the parts are in (:func:`app.lake.read_lake_parts`); ``lonlat``:
        the file holds longitude/latitude (the centres are shown in it)."""
        super().__init__(parent)
        self.setWindowTitle("Several parts of water")
        text = QtWidgets.QLabel(
            f"{file_name} holds {len(parts)} separate parts of water. A project holds one lake: choose the "
            f"part to open (File ▸ Import again opens another).\n'meshcore mesh {file_name}' grids every "
            f"part into one grid (blocks part1_…, part2_…)."
        )
        text.setWordWrap(True)
        self.table = QtWidgets.QTableWidget(len(parts), len(self.HEADERS), self)
        _centres, unit = part_centres(parts[:1], frame, lonlat=lonlat, metres=metres)
        self.table.setHorizontalHeaderLabels([*self.HEADERS[:-1], near_header(unit)])
        self.table.verticalHeader().setVisible(False)
        self.table.setSelectionBehavior(QtWidgets.QAbstractItemView.SelectionBehavior.SelectRows)
        self.table.setSelectionMode(QtWidgets.QAbstractItemView.SelectionMode.SingleSelection)
        self.table.setEditTriggers(QtWidgets.QAbstractItemView.EditTrigger.NoEditTriggers)
        right = QtCore.Qt.AlignmentFlag.AlignRight | QtCore.Qt.AlignmentFlag.AlignVCenter
        for r, row in enumerate(part_rows(parts, metres=metres, frame=frame, lonlat=lonlat)):
            for c, value in enumerate(row):
                item = QtWidgets.QTableWidgetItem(value)
                if c in (0, 2, 3):
                    item.setTextAlignment(right)
                self.table.setItem(r, c, item)
        self.table.resizeColumnsToContents()
        self.table.horizontalHeader().setStretchLastSection(True)
        self.table.selectRow(0)
        self.table.doubleClicked.connect(self.accept)
        buttons = QtWidgets.QDialogButtonBox(
            QtWidgets.QDialogButtonBox.StandardButton.Open | QtWidgets.QDialogButtonBox.StandardButton.Cancel
        )
        buttons.accepted.connect(self.accept)
        buttons.rejected.connect(self.reject)
        layout = QtWidgets.QVBoxLayout(self)
        layout.addWidget(text)
        layout.addWidget(self.table)
        layout.addWidget(buttons)
        self.resize(620, 160 + 30 * min(len(parts), 8))

    def chosen(self) -> int:
        """The number (from 1) of the part selected; the largest, 1, when none is."""
        rows = self.table.selectionModel().selectedRows()
        return rows[0].row() + 1 if rows else 1
