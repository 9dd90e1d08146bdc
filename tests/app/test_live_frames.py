"""The live frames of a solve started by Generate: paced by their cost, the history always complete.

Behaviour only (which frames are drawn, what the convergence plot ends on), never how fast.
"""

from __future__ import annotations

import numpy as np
import pytest

from app.views.panels import step_ranges

pytestmark = pytest.mark.gui


def test_the_convergence_plot_ranges_change_in_steps():
    """The axes of the convergence plot are drawn again only when the history passes a step of its
    ranges: the iteration axis ends on 1, 1.5, 2, 3, 4, 5, 6, 8 × 10^k, the residual axis on decades."""
    h = np.array([[1, 0.5], [7, 3e-3], [12, 2e-4]])
    assert step_ranges(h) == ((0.0, 15.0), (-4.0, 0.0))
    assert step_ranges(h[:2]) == ((0.0, 8.0), (-3.0, 0.0))
    assert step_ranges(h, tolerance=1e-6) == ((0.0, 15.0), (-6.0, 0.0))
    assert step_ranges(np.array([[100.0, 1.0]])) == ((0.0, 100.0), (0.0, 1.0))
    assert step_ranges(np.array([[101.0, 1.0]]))[0] == (0.0, 150.0)
    assert step_ranges(np.zeros((0, 2))) is None
    assert step_ranges(np.array([[3.0, np.inf]])) is None


def test_a_new_point_within_the_ranges_does_not_draw_the_axes_again(qtbot):
    """A live frame that adds points within the shown ranges keeps the axes' ticks and labels (made again,
    with the grid lines over the whole plot, they were most of a frame's cost); a step passed makes them."""
    from app.views.panels import ConvergencePanel

    conv = ConvergencePanel()
    qtbot.addWidget(conv)
    conv.resize(400, 250)
    conv.show()
    qtbot.waitExposed(conv)
    h = [(k, 10.0 ** (-k / 10)) for k in range(1, 40)]
    axes = conv.getAxis("left"), conv.getAxis("bottom")

    def drawn():  # the axes' pictures once they were painted
        qtbot.waitUntil(lambda: all(a.picture is not None for a in axes))
        return tuple(a.picture for a in axes)

    conv.set_history(h[:11], 1e-6)  # iterations to 11: the axis ends on 15
    before = drawn()
    conv.set_history(h[:14], 1e-6)
    qtbot.wait(50)
    conv.viewport().repaint()
    assert all(p is q for p, q in zip(drawn(), before, strict=True))  # the same pictures: not made again
    conv.set_history(h[:16], 1e-6)  # past 15: the iteration axis ends on 20
    qtbot.wait(50)
    assert drawn()[1] is not before[1]
