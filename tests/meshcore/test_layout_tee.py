"""Junctions of regular layouts as a T (``LayoutOptions(tees=True)``, off by default, :mod:`meshcore.layout.tee`).

A regular (Delft3D domain-decomposition) layout has no star: a junction may instead be split by a
straight *through* cut between two of its reflex corners and a *stem* from a third reflex corner
or from the opposite shore that meets the through cut at a right angle.  The geometry is checked on
generated junctions; generated lakes laid out with the option must still close up round every
island (or be refused) and their ``.ddb`` read back.
"""

from __future__ import annotations

import math
import tempfile
from pathlib import Path

import numpy as np
import pytest

from meshcore import testing
from meshcore.layout import LayoutOptions, auto_layout
from meshcore.layout.frames import frame_defects
from meshcore.layout.tee import _PARALLEL, tee
from tests.meshcore.test_layout_frames import _written_and_read_back

shapely = pytest.importorskip("shapely")


def _ring(poly, h: float) -> np.ndarray:
    r = np.asarray(shapely.segmentize(poly, h).exterior.coords)[:-1]
    return r if shapely.LinearRing(r).is_ccw else r[::-1].copy()


def _cross(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    return u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]


def _angle(u: np.ndarray, v: np.ndarray) -> float:
    return math.degrees(math.acos(abs(u @ v) / (np.hypot(*u) * np.hypot(*v))))


def _side_arm(width: float, arm: float, tilt: float):
    """A channel ``width`` wide along x with an arm ``arm`` wide leaving its north bank, tilted by
    ``tilt`` degrees from the bank's normal: two reflex corners, the south bank straight."""
    from shapely import affinity
    from shapely.geometry import LineString, box

    a = LineString([(0.0, 0.0), (0.0, 8.0)]).buffer(arm / 2, cap_style="flat")
    a = affinity.rotate(a, -tilt, origin=(0.0, 0.0))
    return box(-8.0, -width / 2, 8.0, width / 2).union(a.intersection(box(-9, 0, 9, 9)))


@pytest.mark.parametrize(
    ("width", "arm", "tilt"), [(3.0, 2.0, 0.0), (3.0, 2.0, 20.0), (2.5, 1.6, -25.0), (4.0, 3.0, 10.0)]
)
def test_a_side_arm_meeting_a_channel_is_split_as_a_right_angled_t(width, arm, tilt):
    h = 0.1
    poly = _side_arm(width, arm, tilt)
    ring = _ring(poly, h)
    # the junction's centre: on the arm's axis just inside its mouth
    center = np.array([width / 2 * math.tan(math.radians(tilt)), width / 2 - arm / 4])
    got = tee(ring, center, 1.5 * h, 3 * h)
    assert got is not None
    pieces, (through, stem), _ = got
    assert len(pieces) == 3
    # the through cut is straight, the stem straight and at right angles to it
    d = through[-1] - through[0]
    off = np.abs(_cross(d, through - through[0])) / np.hypot(*d)
    assert off.max() < 1e-9 * np.hypot(*d)
    assert _angle(d, stem[-1] - stem[0]) == pytest.approx(90.0, abs=1e-6)
    # the stem's foot on the through cut, its other end on the shore
    foot, end = stem[0], stem[-1]
    assert np.abs(_cross(d, foot - through[0])) < 1e-9 * np.hypot(*d) ** 2
    assert any(np.allclose(end, p) for p in ring)
    # the three pieces tile the junction's water
    area = sum(shapely.Polygon(p).area for p, _ in pieces)
    assert area == pytest.approx(shapely.Polygon(ring).area, rel=1e-9)
    # a stem from the smooth south bank meets it within _PARALLEL of a right angle
    if abs(end[1] + width / 2) < 1e-9:
        assert _angle(np.array([1.0, 0.0]), end - foot) >= 90.0 - _PARALLEL


def test_no_t_for_a_region_without_two_reflex_corners():
    from shapely.geometry import box

    h = 0.1
    assert tee(_ring(box(-3, -1, 3, 1), h), np.array([0.0, 0.0]), 1.5 * h, 3 * h) is None


#: generated shapes with junctions (seeds used nowhere else)
CASES = [
    "testing.y_junction(width=2.5, angle0=11.0)",
    "testing.channel_network(61301, n_branches=5, width=(1.5, 3.0))",
    "testing.channel_network(61302, n_branches=6)",
    "testing.lake_with_islands(61303)",
    "testing.round_lake(61304, kind='arms', n_islands=3)",
]


@pytest.mark.parametrize("expr", CASES)
def test_regular_layouts_with_tees_still_close_up_and_read_back_as_ddb(expr):
    poly = eval(expr, {"testing": testing})
    lay = auto_layout(poly, target_cells=2000, multiple=4, regular=True, options=LayoutOptions(tees=True))
    if frame_defects(list(lay.pieces)):  # (the writer refuses such a layout: test_layout_frames)
        pytest.skip("the frames do not close")
    with tempfile.TemporaryDirectory() as d:
        _written_and_read_back(lay, Path(d) / "lake.ddb")


def test_tees_are_for_regular_layouts_only():
    poly = testing.channel_network(61305, n_branches=5)
    a = auto_layout(poly, target_cells=2000, multiple=4)
    b = auto_layout(poly, target_cells=2000, multiple=4, options=LayoutOptions(tees=True))
    assert [blk.corners for blk in a.blocks] == [blk.corners for blk in b.blocks]


def test_tees_change_the_regular_layout_of_generated_junctions():
    # (the option would be a no-op if no junction ever took a T)
    changed = 0
    for expr in CASES:
        poly = eval(expr, {"testing": testing})
        a = auto_layout(poly, target_cells=2000, multiple=4, regular=True)
        b = auto_layout(poly, target_cells=2000, multiple=4, regular=True, options=LayoutOptions(tees=True))
        changed += [blk.corners for blk in a.blocks] != [blk.corners for blk in b.blocks]
    assert changed >= 2
