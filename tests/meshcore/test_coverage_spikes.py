import math

import numpy as np
import shapely

from meshcore import testing
from meshcore.quality import coverage as cv


def test_spike_pieces_mark_the_same_shore_points_as_one_buffer_of_the_whole():
    p = testing.round_lake(700401, kind="arms", n_islands=5)
    h = math.sqrt(p.area / 15000)
    sp = cv._boundary_points(p.boundary, h / 10)
    clean = cv.without_spikes(p, 0.5 * h)
    assert clean is not None
    whole = shapely.contains_xy(p.symmetric_difference(clean).buffer(1e-3 * h), sp[:, 0], sp[:, 1])
    assert whole.any()
    np.testing.assert_array_equal(cv._in_spikes(cv._spikes(p, h), sp), whole)
