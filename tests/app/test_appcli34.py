"""A lake's grid in the app is the CLI's work, done once: Generate keeps its frame budget with Live on, Auto
layout's grid goes on from the coarse level that chose the layout (as ``meshcore mesh`` does), F5 on a
finished lake grid makes it again coarse to fine without a warm phase before.

Behaviour only (which solves run, from where, which frames are drawn), never how fast.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import app.lake_solve as lake_solve
import app.solver_controller as controller
from app.window_frame import LIVE
from tests.app.waits import wait_for, wait_idle

pytestmark = pytest.mark.gui

ISEO = Path(__file__).resolve().parents[2] / "benchmarks" / "lakes" / "lake_iseo_sparse.geojson"  # one island


def _solves(monkeypatch) -> list[dict]:
    """Every solve the window starts: its keyword arguments (``warm``: the warm-start grids given)."""
    seen: list[dict] = []
    solve = controller.solve_project

    def counted(*args, **kwargs):
        seen.append(kwargs)
        return (yield from solve(*args, **kwargs))

    monkeypatch.setattr(controller, "solve_project", counted)
    return seen


def _held(monkeypatch) -> list[bool]:
    """For each cold lake solve: whether it went on from the held coarse reading of its layout."""
    hits: list[bool] = []
    take = lake_solve._held_solve

    def held(*args):
        got = take(*args)
        hits.append(got is not None)
        return got

    monkeypatch.setattr(lake_solve, "_held_solve", held)
    return hits


def _laid_out(qtbot, win, *, live: bool) -> None:
    """Iseo imported at 600 m cells, Auto layout pressed with Live on or off for lakes, its grid made."""
    win.settings.setValue(LIVE["lake"][0], live)
    assert win.io.import_points(ISEO, project_lonlat=True)
    win.lake_panel.cell_size.setValue(600.0)
    win.lake_panel.cell_size.editingFinished.emit()
    win.a_auto_layout.trigger()  # lays out, then the grid
    wait_for(qtbot, win, lambda: win.doc.project.layout is not None or bool(win.lake_ctl.last_error))
    assert win.lake_ctl.last_error is None
    wait_idle(qtbot, win)
    assert win.solver.auto is live


def _same(a, b) -> bool:
    return len(a.grids) == len(b.grids) and all(
        np.array_equal(g.x, h.x) and np.array_equal(g.y, h.y) for g, h in zip(a.grids, b.grids, strict=True)
    )


def test_with_live_on_auto_layout_solves_its_grid_once_within_the_frame_budget(qtbot, win, monkeypatch):
    """Live is on for a lake's layout (session 33): the grid that follows Auto layout was drawn at the full
    frame rate of a drag (40 a second, a quarter of the process's CPU on a 3 s solve).  It is a solve asked
    for, not an edit's: its frames keep to the budget (here none: a frame would cost more than any solve),
    and it runs once (no second solve of the new layout by Live beside Generate's)."""
    monkeypatch.setattr(controller, "MAX_FRAME_GAP", 1e9)
    win.solver.frame_cost = 1e9
    frames: list = []
    win.solver.redrawn.connect(lambda: frames.append(1))
    solves = _solves(monkeypatch)
    _laid_out(qtbot, win, live=True)
    assert len(solves) == 1 and not solves[0]["warm"]
    assert frames == []
    mb = win.doc.multiblock
    assert mb is not None and len(mb.grids) == len(win.doc.project.layout.blocks)
    assert [name for _k, name in win.conv_panel.levels] == ["cells ÷4", "÷2", "full"]


def test_auto_layouts_grid_goes_on_from_the_coarse_level_that_chose_the_layout(qtbot, win, monkeypatch):
    """Auto layout solves the coarse level of each layout it weighs; the grid of the one chosen went on to
    solve that level again (``meshcore mesh`` goes on from it).  Now it goes on too, once, to the grid the
    library makes of the layout from scratch, node for node; F5 later solves it from scratch, the same."""
    from meshcore.lakegrid import mesh_layout

    hits = _held(monkeypatch)
    _laid_out(qtbot, win, live=False)
    assert hits == [True]
    fresh = mesh_layout(win.doc.project.layout)
    assert _same(win.doc.multiblock, fresh)
    assert [name for _k, name in win.conv_panel.levels] == ["cells ÷4", "÷2", "full"]
    win.generate()
    wait_idle(qtbot, win)
    assert hits == [True, False]  # taken once
    assert _same(win.doc.multiblock, fresh)


def test_f5_on_a_finished_lake_grid_makes_it_coarse_to_fine_without_a_warm_phase(qtbot, win, monkeypatch):
    """F5 on a lake grid that is finished and current swept the grid shown for up to 60 sweeps (its 'warm
    start' frames), then made it again coarse to fine unseen: the warm sweeps were lost work.  Now it is made
    coarse to fine at once, and a Stop still keeps the finished grid (the kept solve)."""
    solves = _solves(monkeypatch)
    _laid_out(qtbot, win, live=True)
    before = win.doc.multiblock
    win.generate()
    wait_idle(qtbot, win)
    assert len(solves) == 2 and not solves[1]["warm"]
    assert "warm start" not in [name for _k, name in win.conv_panel.levels]
    assert _same(win.doc.multiblock, before)


def test_a_lake_edit_with_live_on_still_solves_from_the_grid_of_before(qtbot, win, monkeypatch):
    """An edit's solve (Live) keeps its warm start and its full frame rate: only Generate changed."""
    solves = _solves(monkeypatch)
    _laid_out(qtbot, win, live=True)
    assert not win.solver._full_rate()  # Generate's solve
    import dataclasses

    lake = win.doc.project.lake
    copy = dataclasses.replace(lake.layout)  # the same blocks and cells, another layout: an edit
    win.editor.set_lake(lake.replaced(layout=copy), "the same layout again")
    wait_for(qtbot, win, lambda: len(solves) == 2)
    assert win.solver._full_rate() or not win.solver.running
    wait_idle(qtbot, win)
    assert len(solves) == 2 and solves[1]["warm"]
