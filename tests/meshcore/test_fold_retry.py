"""A lake grid whose levels end with folded or non-convex cells is made again with block corners
and cut ends sliding along the shore (``meshcore.lakegrid.FOLD_RETRY``), and the grid with fewer
such cells is the one returned: what ``meshcore mesh``, the app and ``mesh_outline`` get."""

from __future__ import annotations

import numpy as np
import pytest

from meshcore import lakegrid, testing
from meshcore.lakegrid import mesh_layout, mesh_outline
from meshcore.layout import auto_layout
from meshcore.quality import lake_metrics


@pytest.fixture(scope="module")
def layout():
    return auto_layout(testing.y_junction(), target_cells=800, multiple=4)


def _same(a, b) -> bool:
    return all(np.array_equal(p.x, q.x) and np.array_equal(p.y, q.y) for p, q in zip(a.grids, b.grids, strict=True))


def _counted(monkeypatch, counts):
    """``lakegrid._n_folded`` answering ``counts`` in turn (the first pass, then the retry)."""
    said = list(counts)
    calls = []

    def n_folded(grids):
        calls.append(len(grids))
        return said.pop(0)

    monkeypatch.setattr(lakegrid, "_n_folded", n_folded)
    return calls


def test_a_grid_with_fewer_bad_cells_made_again_is_the_one_returned(layout, monkeypatch):
    sliding = mesh_layout(layout, levels=2, slide_ends=True)
    calls = _counted(monkeypatch, [3, 1])
    mb = mesh_layout(layout, levels=2)
    assert len(calls) == 2  # the first pass counted, then the retry
    assert _same(mb, sliding)
    assert "made again with block corners and cut ends sliding along the shore: 3 → 1" in mb.info.message
    assert all("made again" in g.info.message for g in mb.grids)


def test_the_first_grid_stays_when_the_retry_is_no_better_or_not_needed(layout, monkeypatch):
    plain = mesh_layout(layout, levels=2)
    _counted(monkeypatch, [2, 2])
    assert _same(mesh_layout(layout, levels=2), plain)
    calls = _counted(monkeypatch, [0])
    assert _same(mesh_layout(layout, levels=2), plain) and len(calls) == 1  # no fold: no retry
    monkeypatch.setattr(lakegrid, "FOLD_RETRY", False)
    calls = _counted(monkeypatch, [5])
    assert _same(mesh_layout(layout, levels=2), plain) and not calls
    monkeypatch.setattr(lakegrid, "FOLD_RETRY", True)
    calls = _counted(monkeypatch, [])
    assert _same(mesh_layout(layout, levels=2, slide_ends=True), mesh_layout(layout, levels=2, slide_ends=True))
    assert not calls  # asked for sliding ends already: nothing to retry


def test_a_stop_during_the_retry_returns_the_first_grid(layout, monkeypatch):
    import threading

    plain = mesh_layout(layout, levels=2)
    stop = threading.Event()
    said = [1, 0]

    def n_folded(grids):
        stop.set()  # the user stops while the grid is made again
        return said.pop(0)

    monkeypatch.setattr(lakegrid, "_n_folded", n_folded)
    mb = mesh_layout(layout, levels=2, stop_event=stop)
    assert _same(mb, plain) and "made again" not in mb.info.message


@pytest.mark.slow
def test_a_dendritic_reservoirs_corner_on_a_notch_of_the_shore_leaves_no_bad_cell():
    """``dendritic(370703)`` at 15 000 cells: a tip block's corner where the arm's flank bends away
    from the water left one non-convex cell; made again with sliding corners it has none, and the
    other numbers are no worse than a tenth of a point."""
    poly = testing.dendritic(370703)
    mb = mesh_outline(poly, target_cells=15000)
    s = lake_metrics(mb, polygon=poly).summary()
    assert s["folded_cells"] == 0 and mb.info.converged
    assert "made again with block corners and cut ends sliding along the shore: 1 → 0" in mb.info.message
    assert s["pct_nodes_within_3deg"] >= 90.8 and s["pct_smoothness_le_1.2"] >= 92.4
    assert s["max_interface_ratio"] <= 2.0 and s["hausdorff_cells"] <= 0.5
