"""PROJ and the app's worker threads.

The app solves in Qt's thread pool, which re-uses operating-system threads under new Python
thread states; pyproj's per-thread PROJ context did not survive that and the second solve of a
lon/lat case crashed the whole process (segfault in ``proj_create``). meshcore now makes every
PROJ call on one thread of its own.
"""

from __future__ import annotations

import threading

import numpy as np
import pytest

from tests.app.waits import wait_for

pytest.importorskip("pyproj")


def test_projections_from_pool_workers_run_on_one_proj_thread(qtbot):
    from superqt.utils import create_worker

    from meshcore.crs import transform

    seen, results = set(), []

    def project():
        from meshcore import crs

        seen.add(crs.proj_call(lambda: threading.current_thread().name))
        return transform("EPSG:4326", "EPSG:32632", np.array([9.2]), np.array([46.0]), "test")

    for _ in range(4):  # four runnables of the pool, one after the other (the second one crashed)
        w = create_worker(project)
        w.returned.connect(results.append)
        with qtbot.waitSignal(w.finished, timeout=60_000):
            w.start()
    assert len(results) == 4 and len(seen) == 1 and next(iter(seen)).startswith("meshcore-proj")
    x0, y0 = results[0]
    for x, y in results[1:]:
        assert x == pytest.approx(x0, abs=1e-9) and y == pytest.approx(y0, abs=1e-9)
    # the UTM zone 32 false easting and a northing of about 5100 km
    assert 500_000 < x0[0] < 520_000 and 5_090_000 < y0[0] < 5_100_000


def test_a_lonlat_case_solves_twice_in_the_app(qtbot, win):
    from pathlib import Path

    case = Path(__file__).resolve().parents[2] / "resources" / "examples" / "shasta-multiblock-coarse.toml"
    grids = []
    for _ in range(2):
        assert win.io.open_path(case)
        win.generate()
        wait_for(qtbot, win, lambda: not win.solver.running and bool(win.doc.grids))
        grids.append({k: (g.x.copy(), g.y.copy()) for k, g in win.doc.grids.items()})
    assert grids[0].keys() == grids[1].keys() and len(grids[0]) == 7
    for k, (x, y) in grids[0].items():
        np.testing.assert_allclose(grids[1][k][0], x, atol=1e-9)
        np.testing.assert_allclose(grids[1][k][1], y, atol=1e-9)
