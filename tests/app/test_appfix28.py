"""What a user saw in the app in session 28: a ring the file holds twice, the Export dialog's folder,
Redo of Auto layout, the Auto layout offer over the lake, Stop on a huge solve."""

from __future__ import annotations

import json

import numpy as np
import pytest

from tests.app.waits import wait_idle

pytestmark = pytest.mark.gui

T = np.linspace(0, 2 * np.pi, 60, endpoint=False)
SHORE = np.column_stack([1000 * np.cos(T), 600 * np.sin(T)])
ISLE = np.column_stack([200 + 100 * np.cos(T[::3]), 80 * np.sin(T[::3])])


def _geojson(path, rings):
    lonlat = [[[8 + x / 1e5, 47 + y / 1e5] for x, y in [*r.tolist(), r[0].tolist()]] for r in rings]
    geometry = {"type": "Polygon", "coordinates": lonlat}
    feature = {"type": "Feature", "properties": {"name": "lake"}, "geometry": geometry}
    path.write_text(json.dumps({"type": "FeatureCollection", "features": [feature]}))
    return path


@pytest.mark.parametrize(("holes", "islands"), [((ISLE[::-1], ISLE[::-1]), 1), ((SHORE[::-1],), 0)])
def test_an_outline_with_a_ring_twice_imports_the_lake_once_with_a_note(qtbot, win, tmp_path, holes, islands):
    """A duplicated hole was "a pond on an island" (two islands in the lake), a hole the same as the
    shore was "not read as a lake" (one block of the shore, the layout refused)."""
    said: list[str] = []
    win.doc.reported.connect(lambda _level, text: said.append(text))
    f = _geojson(tmp_path / "lake.geojson", [SHORE, *holes])
    assert win.io.import_points(f, project_lonlat=True)
    wait_idle(qtbot, win)
    lake = win.doc.project.lake
    assert lake is not None and len(lake.holes) == islands
    (note,) = [t for t in said if "same ring" in t]
    assert note.startswith("lake.geojson: 'lake hole ") and "read once" in note
    assert not any("pond" in t or "not read as a lake" in t for t in said), said
