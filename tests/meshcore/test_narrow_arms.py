"""The generator of reservoirs of narrow arms (:func:`meshcore.testing.narrow_arms`) makes what it says."""

from __future__ import annotations

import math

import numpy as np
import pytest

from meshcore import testing
from meshcore.layout.corners import turning


@pytest.mark.parametrize("seed", [770000, 770005, 770017])
def test_narrow_arms_is_what_it_says(seed):
    poly = testing.narrow_arms(seed)
    assert poly.is_valid and testing.narrow_arms(seed).equals(poly)
    h = math.sqrt(poly.area / 15000)  # the cell size at 15 000 cells
    # arms 3-6 cells wide: little water farther than 3.5 cells from the shore (junctions),
    # and most of it at least 1.5 cells from it
    assert poly.buffer(-3.5 * h).area < 0.05 * poly.area
    assert poly.buffer(-1.0 * h).area > 0.4 * poly.area
    # wedge ends: the shore turns by more than 120° within a cell and a half of a tip
    xy = np.asarray(poly.exterior.coords)[:-1]
    t = turning(xy, 1.5 * h)
    tips = xy[t > 120]
    far = [p for k, p in enumerate(tips) if all(np.hypot(*(p - q)) > 5 * h for q in tips[:k])]
    assert len(far) >= 4
