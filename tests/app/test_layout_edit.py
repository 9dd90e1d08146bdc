"""The layout handles a user drags and what moving one does (no Qt)."""

from __future__ import annotations

import contextlib

import numpy as np
import pytest
from shapely.geometry import Point

from app.layout_edit import Handle, handles, moved_parts, nearest_handle, place


@pytest.fixture(scope="module")
def layout():
    from meshcore import testing
    from meshcore.layout import auto_layout

    poly = testing.y_junction()
    return auto_layout(poly, cell_size=float(np.sqrt(poly.area / 600)), multiple=4)


def test_every_cut_end_and_corner_is_a_handle_once(layout):
    hs = handles(layout)
    ends = [h for h in hs if h.kind == "end"]
    assert len({h.xy for h in hs}) == len(hs)
    boundary = layout.polygon.boundary
    for h in ends:
        assert boundary.distance(Point(h.xy)) < 1e-9  # cut ends lie on the shore
    corners = {tuple(map(float, p)) for b in layout.blocks for p in b.corners}
    assert corners <= {h.xy for h in hs}
    interior = [h for h in hs if h.kind == "cut"]
    assert len(interior) == sum(max(len(c) - 2, 0) for c in layout.cuts)
    ends = {tuple(map(float, p)) for c in layout.cuts for p in (c[0], c[-1])}
    assert ends == {h.xy for h in hs if h.kind in ("end", "junction")}


def test_nearest_handle_prefers_a_cut_end(layout):
    hs = handles(layout)
    end = next(h for h in hs if h.kind == "end")
    twin = Handle("corner", end.xy, block=0)
    got = nearest_handle([twin, *hs], end.xy, tol=1e-3)
    assert got.kind == "end" and got.xy == end.xy
    assert nearest_handle(hs, (1e3, 1e3), tol=1e-3) is None


def test_a_dragged_end_slides_on_the_shore_and_a_corner_on_its_block(layout):
    hs = handles(layout)
    end = next(h for h in hs if h.kind == "end")
    far = (end.xy[0] + 0.3, end.xy[1] + 0.4)
    q = place(layout, end, far)
    assert layout.polygon.boundary.distance(Point(q)) < 1e-9
    assert np.hypot(q[0] - far[0], q[1] - far[1]) <= np.hypot(end.xy[0] - far[0], end.xy[1] - far[1]) + 1e-12
    inner = next(h for h in hs if h.kind == "cut")
    assert place(layout, inner, (0.25, 0.5)) == (0.25, 0.5)


def test_a_move_takes_every_coinciding_point_along(layout):
    end = next(h for h in handles(layout) if h.kind == "end")
    parts = {
        "cuts": [np.asarray(c) for c in layout.cuts],
        "blocks": [{"name": b.name, "corners": list(b.corners), "cells": b.cells} for b in layout.blocks],
    }
    new = (end.xy[0] + 0.01, end.xy[1])
    out = moved_parts(parts, end.xy, new, tol=1e-9)
    n_before = sum(1 for c in parts["cuts"] for p in c if np.allclose(p, end.xy))
    n_before += sum(1 for b in parts["blocks"] for p in b["corners"] if np.allclose(p, end.xy))
    n_after = sum(1 for c in out["cuts"] for p in c if np.allclose(p, new))
    n_after += sum(1 for b in out["blocks"] for p in b["corners"] if np.allclose(p, new))
    assert n_before >= 1 and n_after == n_before
    assert not any(np.allclose(p, end.xy) for c in out["cuts"] for p in c)
    assert [b["cells"] for b in out["blocks"]] == [b.cells for b in layout.blocks]  # cells kept


def test_a_cut_bends_smoothly_and_keeps_its_far_end(layout):
    c = np.asarray(max(layout.cuts, key=len), float)
    parts = {"cuts": [c], "blocks": []}
    d = np.array([0.02, -0.01])
    for k in (0, len(c) // 2):
        out = np.asarray(moved_parts(parts, c[k], c[k] + d, tol=1e-12)["cuts"][0])
        shift = np.hypot(*(out - c).T)
        np.testing.assert_allclose(out[k], c[k] + d)
        assert shift[-1] == 0 and (k == 0 or shift[0] == 0)  # the far end(s) stay
        assert np.all(np.diff(shift[k:]) <= 1e-15)  # less and less towards the far end


def test_a_dragged_corner_lands_on_a_vertex_of_its_block(layout):
    from shapely.geometry import LinearRing

    from meshcore.layout.outline import outline_parts

    parts = outline_parts(layout)
    vertices = {tuple(map(float, p)) for key in ("outline",) for p in parts[key]}
    vertices |= {tuple(map(float, p)) for c in parts["cuts"] for p in c}
    vertices |= {tuple(map(float, p)) for r in parts["holes"] for p in r}
    for h in (h for h in handles(layout) if h.kind == "corner"):
        q = place(layout, h, (h.xy[0] + 0.3, h.xy[1] - 0.2), parts)
        assert q in vertices
        assert LinearRing(layout.pieces[h.block].ring).distance(Point(q)) < 1e-9


# --------------------------------------------------------------- a three-block strip
def _strip():
    """A 10 × 2 strip sampled at every unit, cut at x = 3 and x = 6 into blocks a, b, c."""
    from meshcore.layout import layout_from_outline

    outline = [(float(x), 0.0) for x in range(11)] + [(float(x), 2.0) for x in range(10, -1, -1)]
    cuts = [[(3.0, 0.0), (3.0, 2.0)], [(6.0, 0.0), (6.0, 2.0)]]
    blocks = [
        {"name": "a", "corners": [(0, 0), (3, 0), (3, 2), (0, 2)], "cells": [6, 4]},
        {"name": "b", "corners": [(3, 0), (6, 0), (6, 2), (3, 2)], "cells": [6, 4]},
        {"name": "c", "corners": [(6, 0), (10, 0), (10, 2), (6, 2)], "cells": [8, 4]},
    ]
    return layout_from_outline(outline, cuts=cuts, blocks=blocks, cell_size=0.5, multiple=2)


def test_shore_points_are_handles_after_the_layouts_own_points():
    from app.layout_edit import shore_points

    lay = _strip()
    hs = handles(lay)
    shore = [h for h in hs if h.kind == "shore"]
    # every vertex of the water polygon is a handle; where a cut end or a corner sits, that one
    assert {h.xy for h in hs} >= {tuple(map(float, p)) for p in shore_points(lay)}
    assert (1.0, 0.0) in {h.xy for h in shore} and (3.0, 0.0) not in {h.xy for h in shore}
    assert nearest_handle(hs, (3.01, 0.0), tol=0.1).kind == "end"


def test_a_dragged_shore_point_takes_the_shore_and_keeps_the_blocks():
    from app.layout_edit import moved_layout, shore_points
    from meshcore.layout.outline import outline_parts

    lay = _strip()
    parts = outline_parts(lay)
    parts2 = moved_parts(parts, (4.0, 2.0), (4.0, 2.5), 1e-9, shore=shore_points(lay))
    moved = {tuple(a) for a in np.asarray(parts["outline"])} ^ {tuple(b) for b in np.asarray(parts2["outline"])}
    assert moved == {(4.0, 2.0), (4.0, 2.5)}  # only that vertex: its neighbours are shore points too
    lay2 = moved_layout(lay, parts2)
    assert lay2.polygon.area == pytest.approx(lay.polygon.area + 0.5 * 2 * 0.5)  # a triangle 2 wide, 0.5 high
    assert [(b.name, b.cells) for b in lay2.blocks] == [(b.name, b.cells) for b in lay.blocks]
    assert lay2.topology() is not None


def test_a_shore_drag_moves_the_layouts_sampling_points_between_two_shore_points():
    from app.layout_edit import _moved_ring

    ring = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [3.0, 0.0], [4.0, 0.0], [4.0, 1.0], [0.0, 1.0]])
    stops = ring[[0, 2, 4, 5, 6]]  # 1 and 3 are sampling points the layout added
    out, moved = _moved_ring(ring, ring[2], np.array([0.0, -1.0]), stops, 1e-12)
    assert out[2].tolist() == [2.0, -1.0]
    assert out[1].tolist() == [1.0, -0.5] and out[3].tolist() == [3.0, -0.5]  # half way: half the move
    assert np.array_equal(out[[0, 4, 5, 6]], ring[[0, 4, 5, 6]]) and len(moved) == 3


def test_a_cut_end_dragged_across_another_cut_is_refused():
    from app.layout_edit import moved_layout
    from meshcore.errors import TopologyError
    from meshcore.layout.outline import outline_parts

    lay = _strip()
    parts = outline_parts(lay)
    end = next(h for h in handles(lay) if h.xy == (3.0, 2.0))
    ok = moved_layout(lay, moved_parts(parts, end.xy, place(lay, end, (4.0, 2.0), parts), 1e-9))
    assert [b.cells for b in ok.blocks] == [b.cells for b in lay.blocks]
    across = moved_parts(parts, end.xy, place(lay, end, (8.0, 2.0), parts), 1e-9)  # past the cut at x = 6
    with pytest.raises(TopologyError, match="block 'a'"):
        moved_layout(lay, across)


def _handles_by_scan(layout):
    """The rule of :func:`handles` written plainly (every candidate against every handle kept): the oracle."""
    from app.layout_edit import shore_points

    tol = 1e-9 * max(1.0, float(np.sqrt(layout.polygon.area)))
    cand = [tuple(map(float, p)) for c in layout.cuts for p in (c[0], c[-1])]
    cand += [tuple(map(float, p)) for b in layout.blocks for p in b.corners]
    cand += [tuple(map(float, p)) for c in layout.cuts for p in np.asarray(c, float)[1:-1]]
    cand += [tuple(map(float, p)) for p in shore_points(layout)]
    out = []
    for p in cand:
        if not any(abs(p[0] - q[0]) <= tol and abs(p[1] - q[1]) <= tol for q in out):
            out.append(p)
    return out


@pytest.mark.parametrize("seed", range(3))
def test_handles_are_those_of_the_plain_scan(seed):
    """The grid of tol-sized cells finds the same handles as a scan of all (generated lakes)."""
    from meshcore import testing
    from meshcore.layout import auto_layout

    for poly in (testing.channel_network(seed), testing.lake_with_islands(seed)):
        lay = auto_layout(poly, cell_size=float(np.sqrt(poly.area / 1500)), multiple=2)
        assert [h.xy for h in handles(lay)] == _handles_by_scan(lay)


def test_points_within_the_tolerance_across_a_cell_edge_are_one_handle():
    from types import SimpleNamespace

    from shapely.geometry import Polygon

    poly = Polygon([(0, 0), (4, 0), (4, 1), (0, 1)])
    tol = 1e-9 * 2.0  # handles' tolerance for this area (4)
    edge = 1000 * tol  # a cell edge of its grid
    a, b = (1.0 + edge - 0.3 * tol, 0.5), (1.0 + edge + 0.3 * tol, 0.5 + 0.5 * tol)
    lay = SimpleNamespace(
        polygon=poly, cuts=[np.array([(1.0, 0.0), a, (1.0, 1.0)]), np.array([(2.0, 0.0), b, (2.0, 1.0)])], blocks=[]
    )
    xy = [h.xy for h in handles(lay)]
    assert xy == _handles_by_scan(lay) and (a in xy) != (b in xy)


def _same_topology(a, b) -> None:
    """The layouts ``a`` and ``b`` have the same topology: every block's borders, the interfaces."""
    ta, tb = a.topology(), b.topology()
    for p, q in zip(ta.blocks, tb.blocks, strict=True):
        assert p.name == q.name
        for side in ("bottom", "right", "top", "left"):
            assert np.array_equal(getattr(p.borders, side), getattr(q.borders, side))
    assert ta.interfaces == tb.interfaces


def _same_layout(a, b) -> None:
    """``a`` and ``b`` are the same layout: water, cuts, pieces, blocks, and the same topology."""
    assert a.polygon.equals_exact(b.polygon, 0.0) and a.cell_size == b.cell_size and a.multiple == b.multiple
    assert len(a.cuts) == len(b.cuts) and all(np.array_equal(p, q) for p, q in zip(a.cuts, b.cuts, strict=True))
    for p, q in zip(a.pieces, b.pieces, strict=True):
        assert p.name == q.name and p.corners == q.corners and np.array_equal(p.ring, q.ring)
    assert a.blocks == b.blocks and a.notes == b.notes
    _same_topology(a, b)


@pytest.mark.parametrize("seed", range(2))
def test_a_moved_layout_is_the_layout_of_its_case_loaded_fresh(seed):
    """A drag's layout (one from_outline, its topology kept) is what saving the moved layout as a
    case and loading it again gives (layout_from_outline, then Layout.topology), for every kind
    of handle on generated lakes; a move it refuses, the fresh load refuses too."""
    from app.layout_edit import moved_layout, shore_points
    from meshcore import testing
    from meshcore.case import case_layout, dumps_case, layout_case, loads_case
    from meshcore.errors import TopologyError
    from meshcore.layout import auto_layout, layout_from_outline
    from meshcore.layout.outline import outline_parts

    rng = np.random.default_rng(seed)
    checked = refused = 0
    for poly in (testing.channel_network(seed), testing.lake_with_islands(seed), testing.round_lake(seed, kind="arms")):
        h = float(np.sqrt(poly.area / 1200))
        lay = auto_layout(poly, cell_size=h, multiple=4)
        parts = outline_parts(lay)
        tol = 1e-9 * max(1.0, float(np.sqrt(lay.polygon.area)))
        hs = handles(lay)
        for kind in ("end", "junction", "cut", "corner", "shore"):
            of_kind = [x for x in hs if x.kind == kind]
            for hd in (of_kind[i] for i in rng.choice(len(of_kind), min(2, len(of_kind)), replace=False)):
                step = rng.uniform(-1.0, 1.0, 2) * h
                q = place(lay, hd, np.add(hd.xy, step), parts)
                p2 = moved_parts(parts, hd.xy, q, tol, shore=shore_points(lay) if kind == "shore" else None)
                with contextlib.suppress(TopologyError):
                    fast = None
                    fast = moved_layout(lay, p2)
                try:
                    fresh = layout_from_outline(
                        p2["outline"], holes=p2["holes"], cuts=p2["cuts"], blocks=p2["blocks"], cell_size=h, multiple=4
                    )
                    fresh.topology()
                except TopologyError:
                    assert fast is None  # refused by both
                    refused += 1
                    continue
                assert fast is not None
                _same_layout(fast, fresh)
                # saved as a case and loaded again: the same blocks and nodes (the shore ring may start elsewhere)
                loaded = case_layout(loads_case(dumps_case(layout_case(fast))))
                assert loaded.polygon.normalize().equals_exact(fast.polygon.normalize(), 0.0)
                _same_topology(fast, loaded)
                checked += 1
    assert checked >= 15 and refused <= checked


def test_a_move_makes_the_layout_and_its_topology_in_one_from_outline(monkeypatch):
    """The layout worker splits the water once per step (it did twice: the layout, then its topology)."""
    import meshcore.multiblock.outline as mo
    from app.layout_edit import moved_layout
    from meshcore.layout.outline import outline_parts

    lay = _strip()
    parts = outline_parts(lay)
    end = next(h for h in handles(lay) if h.xy == (3.0, 2.0))
    calls = []
    real = mo.from_outline
    monkeypatch.setattr(mo, "from_outline", lambda *a, **k: calls.append(1) or real(*a, **k))
    moved = moved_layout(lay, moved_parts(parts, end.xy, place(lay, end, (4.0, 2.0), parts), 1e-9))
    assert moved.topology() is not None and len(calls) == 1


def _drag_steps(seed: int):
    """A generated lake whose layout has block sides of several parts (their cells are shared by
    the integer program), a cut end on such a block, and the drag's steps along the shore."""
    from meshcore import testing
    from meshcore.layout import auto_layout
    from meshcore.layout.outline import outline_blocks, outline_parts

    for k in range(20):
        poly = testing.channel_network(seed + k)
        lay = auto_layout(poly, cell_size=float(np.sqrt(poly.area / 1200)), multiple=4)
        cells = outline_blocks(lay).side_cells
        if any(len(v) > 1 for v in cells.values()):
            break
    parts = outline_parts(lay)
    tol = 1e-9 * max(1.0, float(np.sqrt(lay.polygon.area)))
    h = lay.cell_size
    ends = [x for x in handles(lay) if x.kind == "end"]
    return lay, parts, tol, h, ends


@pytest.mark.parametrize("seed", range(2))
def test_a_drags_steps_keep_the_first_steps_cells_and_its_end_is_made_fresh(seed, monkeypatch):
    """The steps of a drag keep the chains' cells of its first step (no integer program); the
    drag's last layout is the one a case of it gives (the program's cells), on generated lakes."""
    import meshcore.multiblock.counts as counts
    from app.layout_edit import DragSteps, moved_layout, settled_layout
    from meshcore.case import case_layout, dumps_case, layout_case, loads_case
    from meshcore.errors import TopologyError

    lay, parts, tol, h, ends = _drag_steps(seed)
    programs = []
    real = counts.solve_counts
    monkeypatch.setattr(counts, "solve_counts", lambda *a, **k: programs.append(1) or real(*a, **k))
    done = saved = 0
    for end in ends:
        steps, last = DragSteps(), None
        for f in (0.2, 0.5, 0.9, 1.3):
            q = place(lay, end, np.add(end.xy, (f * h, 0.7 * f * h)), parts)
            with contextlib.suppress(TopologyError):
                n = len(programs)
                moved_layout(lay, moved_parts(parts, end.xy, q, tol), steps)
                saved += steps.kept and len(programs) == n  # a later step: the first one's cells, no program
                last = q
        if last is None or steps.cells is None:
            continue
        p2 = moved_parts(parts, end.xy, last, tol)
        final = settled_layout(lay, p2, steps)
        _same_layout(final, moved_layout(lay, p2))
        _same_topology(final, case_layout(loads_case(dumps_case(layout_case(final)))))
        done += 1
    assert done >= 2 and programs and saved >= 2


def test_a_drag_refused_at_its_end_leaves_its_last_good_layout_made_fresh():
    from app.layout_edit import DragSteps, MoveRefused, moved_layout, settled_layout
    from meshcore.errors import TopologyError

    lay = _strip()
    parts = moved_parts_of(lay)
    end = next(h for h in handles(lay) if h.xy == (3.0, 2.0))
    steps = DragSteps()
    for x in (3.5, 4.0):
        moved_layout(lay, moved_parts(parts, end.xy, place(lay, end, (x, 2.0), parts), 1e-9), steps)
    assert steps.kept
    across = moved_parts(parts, end.xy, place(lay, end, (8.0, 2.0), parts), 1e-9)  # past the cut at x = 6
    with pytest.raises(MoveRefused) as err:
        settled_layout(lay, across, steps)
    _same_layout(err.value.layout, moved_layout(lay, moved_parts(parts, end.xy, (4.0, 2.0), 1e-9)))
    with pytest.raises(TopologyError) as err2:  # no kept cells on screen: the plain refusal
        settled_layout(lay, across, DragSteps())
    assert not isinstance(err2.value, MoveRefused)


def moved_parts_of(lay):
    from meshcore.layout.outline import outline_parts

    return outline_parts(lay)
