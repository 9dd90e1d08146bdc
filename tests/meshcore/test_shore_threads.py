"""The shore rings' STR-trees (:mod:`meshcore.orthogonal.shore`) are kept safely from threads: the app
solves a lake grid while a layout's coarse readings are made in another thread."""

from __future__ import annotations

import sys
import threading

import numpy as np

from meshcore.orthogonal import shore


def hammer(work, threads: int = 4) -> list[str]:
    """``work(k)`` in ``threads`` threads started together, thread switches as often as Python allows: the
    exceptions they raised (also used by ``tests/app/test_lake_solve.py``)."""
    errors: list[str] = []
    start = threading.Barrier(threads)

    def run(k: int) -> None:
        start.wait()
        try:
            work(k)
        except Exception as exc:  # what the tests are about
            errors.append(repr(exc))

    switch = sys.getswitchinterval()
    sys.setswitchinterval(1e-6)
    try:
        ts = [threading.Thread(target=run, args=(k,)) for k in range(threads)]
        for t in ts:
            t.start()
        for t in ts:
            t.join()
    finally:
        sys.setswitchinterval(switch)
    return errors


def test_the_trees_of_rings_are_kept_safely_from_threads(monkeypatch):
    """Two threads evicting the same oldest tree raised KeyError, or "dictionary changed size during
    iteration" when one evicted while another added (the trees themselves stubbed: the bookkeeping is what
    is tested, as often as it can be in the time)."""
    import shapely

    monkeypatch.setattr(shapely, "STRtree", lambda geoms: None)
    monkeypatch.setattr(shapely, "linestrings", lambda coords: None)
    monkeypatch.setattr(shore, "_segments", lambda rs: (np.zeros(1), np.zeros(1), None, None, None))
    rings = [[np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0 + k], [0.0, 1.0]])] for k in range(6)]

    def trees(k: int) -> None:
        for i in range(50_000):
            shore._tree(rings[(i + k) % 6])

    assert hammer(trees) == []
    assert len(shore._TREES) <= shore._TREES_KEPT
