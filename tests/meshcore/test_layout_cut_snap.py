"""A hand-drawn cut's end that lands a cell or two from a cut end snaps onto it (layout_from_cuts(snap=...))."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from shapely.geometry import box

from meshcore.errors import TopologyError
from meshcore.layout.edit import SNAP_CELLS, layout_from_cuts, snap_cut, snap_targets

H = 0.5  # cell size: the 20 × 10 box is 40 × 20 cells
BOX = box(0.0, 0.0, 20.0, 10.0)
A = np.array([[10.0, -0.5], [10.0, 10.5]])  # across the box, drawn past both shores
B = np.array([[-0.5, 5.0], [10.2, 5.0]])  # from the west shore to A (drawn a little past it): a T


def _third(off_cells: float) -> np.ndarray:
    """From the east shore to A, landing ``off_cells`` cells above B's end on A."""
    y = 5.0 + off_cells * H
    return np.array([[20.5, y], [9.8, y]])


def _junctions(lay) -> np.ndarray:
    """The distinct cut ends inside the water (where cuts meet), rounded."""
    ends = np.array([c[k] for c in lay.cuts for k in (0, -1)])
    inside = [e for e in ends if 0.0 < e[0] < 20.0 and 0.0 < e[1] < 10.0]
    return np.unique(np.round(inside, 6), axis=0)


def test_a_cut_ending_1_5_cells_from_a_cut_end_joins_it():
    off = 1.5
    plain = layout_from_cuts(BOX, [A, B, _third(off)], cell_size=H)
    assert len(_junctions(plain)) == 2  # two T's on A 1.5 cells apart: a 1.5-cell side between them
    lay = layout_from_cuts(BOX, [A, B, _third(off)], cell_size=H, snap=SNAP_CELLS)
    j = _junctions(lay)
    assert j.tolist() == [[10.0, 5.0]]  # one 4-way junction: C ends where B does
    assert sorted(b.cells for b in lay.blocks) == [(10, 20), (10, 20), (20, 10), (20, 10)]
    # no block side shorter than the snap distance
    for pc in lay.pieces:
        r, cs = np.asarray(pc.ring), list(pc.corners)
        for a, e in zip(cs, cs[1:] + cs[:1], strict=True):
            idx = [(a + i) % len(r) for i in range((e - a) % len(r) + 1)]
            assert np.sum(np.hypot(*np.diff(r[idx], axis=0).T)) > SNAP_CELLS * H
    assert len(lay.notes) == 1 and "snapped" in lay.notes[0] and "(10, 5)" in lay.notes[0]
    lay.topology()  # a valid multiblock layout


def test_a_cut_ending_4_cells_from_a_cut_end_stays_where_drawn():
    lay = layout_from_cuts(BOX, [A, B, _third(4.0)], cell_size=H, snap=SNAP_CELLS)
    assert _junctions(lay).tolist() == [[10.0, 5.0], [10.0, 7.0]]
    assert lay.notes == ()
    plain = layout_from_cuts(BOX, [A, B, _third(4.0)], cell_size=H)
    assert [b.cells for b in lay.blocks] == [b.cells for b in plain.blocks]


def test_an_end_on_the_shore_snaps_to_another_cut_end_on_the_shore():
    # a second cut from the south shore 1 cell east of A's end, drawn to the east shore
    c = np.array([[10.0 + 1.0 * H, -0.3], [20.3, 6.0]])
    out, snaps = snap_cut(BOX, c, snap_targets(BOX, [A]), SNAP_CELLS * H, [A])
    assert [(e, kind) for e, _a, _b, kind in snaps] == [(0, "cut end")]
    assert out[0].tolist() == [10.0, 0.0]


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    y_b=st.floats(1.0, 9.0),
    y_c=st.floats(0.2, 9.8),
    x_a=st.floats(4.0, 16.0),
    past=st.floats(-0.3, 0.6),
    tilt=st.floats(-2.0, 2.0),
)
def test_snapping_never_makes_an_invalid_layout(y_b, y_c, x_a, past, tilt):
    """Snapped or not, layout_from_cuts gives a layout whose topology holds, or the TopologyError it
    gives today; every end it moves lands within the snap distance of where it was drawn to."""
    a = np.array([[x_a, -0.5], [x_a + tilt, 10.5]])
    b = np.array([[-0.5, y_b], [x_a + past, y_b]])
    c = np.array([[20.5, y_c], [x_a + 0.5 * tilt - past, y_c]])
    try:
        lay = layout_from_cuts(BOX, [a, b, c], cell_size=H, snap=SNAP_CELLS)
    except TopologyError:
        return
    lay.topology()
    assert all(min(bl.cells) >= 1 for bl in lay.blocks)
    for note in lay.notes:
        cells = float(note.split("snapped ")[1].split(" cells")[0])
        assert cells <= SNAP_CELLS + 1e-9


@pytest.mark.parametrize("snap", [0.0, SNAP_CELLS])
def test_no_cut_to_snap_keeps_the_layout(snap):
    lay = layout_from_cuts(BOX, [A], cell_size=H, snap=snap)
    assert len(lay.blocks) == 2 and lay.notes == ()


def test_a_tip_next_to_a_cut_end_is_no_target():
    """An end landing 3.5 cells from A's end on the shore and 2 cells from a shore tip 1.5 cells from
    A's end stays where drawn: put on the tip it would leave a 1.5-cell wedge beside A."""
    targets = [*snap_targets(BOX, [A]), ((10.0 + 1.5 * H, 0.0), "shore tip")]
    c = np.array([[10.0 + 3.5 * H, -0.3], [10.0 + 3.5 * H, 10.3]])
    out, snaps = snap_cut(BOX, c, targets, SNAP_CELLS * H, [A])
    assert snaps == []
    assert out.tolist() == [[10.0 + 3.5 * H, 0.0], [10.0 + 3.5 * H, 10.0]]
    alone = [((10.0 + 1.5 * H, 0.0), "shore tip")]  # without A's end beside it, the tip is one
    assert [kind for *_x, kind in snap_cut(BOX, c, alone, SNAP_CELLS * H)[1]] == ["shore tip"]


def test_a_cut_drawn_beside_another_does_not_snap_onto_its_ends():
    """A cut drawn 1 cell beside A, along it, would close a sliver block if its ends went onto A's."""
    c = np.array([[10.0 + H, -0.3], [10.0 + H, 10.3]])
    out, snaps = snap_cut(BOX, c, snap_targets(BOX, [A]), SNAP_CELLS * H, [A])
    assert snaps == [] and out.tolist() == [[10.0 + H, 0.0], [10.0 + H, 10.0]]
