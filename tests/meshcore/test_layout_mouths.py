"""Junction chords at the arms' mouths (``auto_layout(..., options=LayoutOptions(mouths=True))``, off by default): at a
junction of three or four arms 4–7 cells wide each arm's chord lies where the arm meets the
junction, through the reflex shore corners between the arms, instead of just outside the
junction's inscribed circle."""

from __future__ import annotations

import math

import numpy as np
import pytest

from meshcore.layout.chords import place_chords
from meshcore.layout.skeleton import skeleton


def _star(arms: int, across: float, h: float):
    """``arms`` straight arms ``across`` cells wide and 30 cells long from the origin."""
    from shapely.geometry import LineString
    from shapely.ops import unary_union

    ang = np.radians(np.arange(arms) * 360 / arms + 10)
    w = across * h
    legs = [
        LineString([(0, 0), (30 * h * math.cos(a), 30 * h * math.sin(a))]).buffer(0.5 * w, cap_style="flat")
        for a in ang
    ]
    return unary_union(legs).buffer(0.15 * w).buffer(-0.15 * w)


def _junction_chords(poly, h: float, mouths: bool) -> list[float]:
    """Distances from the origin (the junction) of the chords nearest it, one per arm."""
    sk = skeleton(poly, spacing=h / 2, prune=0.5, min_arm=3 * h)
    chords = place_chords(poly, sk, min_length=2 * h, mouths=mouths)
    near = [c for c in chords if c.kind in ("junction", "mouth")]
    return sorted(float(np.hypot(*c.points.mean(axis=0))) for c in near)


@pytest.mark.parametrize(("arms", "across"), [(3, 4.5), (4, 4.5), (4, 5.5)])
def test_mouth_chords_meet_the_reflex_corners(arms, across):
    h = 1.0
    poly = _star(arms, across, h)
    w = across * h
    # a chord across an arm through the reflex corners: its middle as far from the junction
    # as the corners' projection on the arm, half the width over tan(half the angle between arms)
    mouth = 0.5 * w / math.tan(math.pi / arms)
    off = _junction_chords(poly, h, mouths=False)
    on = _junction_chords(poly, h, mouths=True)
    assert len(off) == len(on) == arms
    assert min(off) > mouth + 0.4 * w  # outside the inscribed circle: the junction zone has stubs
    assert max(on) < mouth + 0.3 * w  # at the mouth: the arms' blocks reach the corners


def test_five_arms_and_wide_arms_keep_the_default():
    h = 1.0
    assert _junction_chords(_star(5, 4.5, h), h, True) == _junction_chords(_star(5, 4.5, h), h, False)
    assert _junction_chords(_star(4, 9.0, h), h, True) == _junction_chords(_star(4, 9.0, h), h, False)
