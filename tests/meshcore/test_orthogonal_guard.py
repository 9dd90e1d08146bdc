"""The orthogonal smoother's move guard: no fold, and no cell squeezed thinner than ~1 : 100."""

import numpy as np

from meshcore.orthogonal import _kernels
from meshcore.orthogonal.driver import _node_cells


def _strip():
    """Two unit cells side by side: nodes 0 1 2 along y = 0, 3 4 5 along y = 1."""
    X = np.array([0.0, 1.0, 2.0, 0.0, 1.0, 2.0])
    Y = np.array([0.0, 0.0, 0.0, 1.0, 1.0, 1.0])
    cells = np.array([[0, 1, 4, 3], [1, 2, 5, 4]], dtype=np.int64)
    cptr, ncells, _ = _node_cells(cells, 6)
    return X, Y, cptr, ncells


def _move(X, Y, cptr, ncells, node, to, jmin):
    before, after = np.empty(32), np.empty(32)
    return _kernels._try_move(X, Y, node, to[0], to[1], cptr, ncells, np.full(6, jmin), before, after, False)


def test_a_move_that_would_squeeze_a_cell_to_a_sliver_is_cut_short():
    """Node 1 sent to x = 1.999 leaves the right cell 0.001 wide (aspect ratio 1 000), its
    corner Jacobians still above a tiny ``jmin``: the guard halves the step until the cell keeps
    ASPECT_FLOOR of its longest edge squared (the old guard took the whole step)."""
    X, Y, cptr, ncells = _strip()
    moved = _move(X, Y, cptr, ncells, 1, (1.999, 0.0), 1e-9)
    assert 0.0 < moved < 0.999
    width = 2.0 - X[1]
    assert width >= _kernels.ASPECT_FLOOR * 0.99  # the right cell is no thinner than the floor allows
    assert width <= 4 * _kernels.ASPECT_FLOOR + 0.5  # and the node did go some way


def test_a_cell_already_thin_may_get_better_and_a_plain_move_is_untouched():
    X, Y, cptr, ncells = _strip()
    X[1] = 1.999  # a sliver on the right, as a start grid may have it
    assert _move(X, Y, cptr, ncells, 1, (1.5, 0.0), 1e-9) > 0  # widening it is allowed
    assert X[1] == 1.5
    X2, Y2, cptr2, ncells2 = _strip()
    assert _move(X2, Y2, cptr2, ncells2, 4, (1.1, 1.05), 1e-9) > 0  # an ordinary move, whole
    assert (X2[4], Y2[4]) == (1.1, 1.05)


def test_the_guard_never_lets_a_thin_cell_fold():
    """A thin cell whose longest edge the move shortens: the thinness reading may improve while
    its Jacobian goes negative — the fold rule still holds."""
    X, Y, cptr, ncells = _strip()
    X[1] = 1.995
    for to in [(2.3, 0.0), (2.05, -0.2), (2.5, 0.5), (3.0, 0.9)]:
        Xc, Yc = X.copy(), Y.copy()
        _move(Xc, Yc, cptr, ncells, 1, to, 1e-9)
        for c in ([0, 1, 4, 3], [1, 2, 5, 4]):
            x, y = Xc[c], Yc[c]
            for k in range(4):
                n, m = (k + 1) % 4, (k + 3) % 4
                j = (x[n] - x[k]) * (y[m] - y[k]) - (y[n] - y[k]) * (x[m] - x[k])
                assert j > 0, (to, c, k, j)


def test_the_first_row_off_the_shore_moves_under_the_fold_rule_only():
    """``fold_only`` (the shore nodes and the first row off the shore): the sliver move that the
    thin rule cuts short is taken whole, and a move that would fold a cell is still cut short."""
    X, Y, cptr, ncells = _strip()
    before, after = np.empty(32), np.empty(32)
    jmin = np.full(6, 1e-9)
    assert _kernels._try_move(X, Y, 1, 1.999, 0.0, cptr, ncells, jmin, before, after, True) > 0
    assert X[1] == 1.999  # 0.001 wide: the thin rule would have stopped it short
    X, Y, cptr, ncells = _strip()
    _kernels._try_move(X, Y, 1, 2.5, 0.0, cptr, ncells, jmin, before, after, True)
    assert X[1] < 2.0  # never past the right cell's far side: no fold
