r"""Anderson acceleration of a fixed-point iteration (the FAS cycles of both multigrid drivers).

A cycle is a map ``x → G(x)``; its fixed point is the solution.  Anderson mixing of depth
``m`` keeps the last ``m`` differences of the iterates' displacements ``f = G(x) − x`` and of
their images ``G(x)``, and takes as the next iterate

.. math::

    x_{k+1} = G(x_k) - \Delta G\,\gamma,\qquad
    \gamma = \arg\min_\gamma \lVert f_k - \Delta F\,\gamma \rVert_2 ,

the combination of the last ``m + 1`` images whose (linearised) displacement is least.  The
least-squares problem is solved by its normal equations on the column-scaled differences; the
oldest columns are dropped while their Gram matrix is ill-conditioned (:data:`COND_MAX`).

:class:`Mixer` applies it to a driver's arrays with the safeguards: a mixed iterate whose
residual (the driver's stopping measure) is above the plain cycle's (:data:`ACCEPT`), or that has
more folded cells than the plain cycle's image, is replaced by that image and the history restarts
(:meth:`Anderson.reset`); so does a change of the map (new control sources).  It starts with the
first cycle slower than :data:`START_RATE` (a fast cycle gains little and pays the overhead).

Measured (one-block Winslow, ~24 000 nodes, CPU, one process alternating off/on, load 10–14):
generated shapes of :mod:`meshcore.testing` (seeds from 774000: channel networks, lakes with
arms, jagged Y junctions, lakes with islands, a disc, a blob, a spiral, a channel), the 19 that
converge by multigrid 1.42 → 0.99 s (the 3 that stall go on with SOR either way).  The depth
was chosen on the 9 lakes of ``benchmarks/robust.py``: 3 and 5 took 120 and 116 cycles in all
against 115 at 4 (176 without mixing).  The products are BLAS matrix–vector ones on preallocated
buffers (see :class:`Anderson`): a mixed step costs ~0.15 ms at 48 000 values, about a
twentieth of a line-smoothed cycle.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

__all__ = ["ACCEPT", "COND_MAX", "DEPTH", "MIN_PAIRS", "START_RATE", "Anderson", "Mixer", "folded_cells"]

#: Differences kept (the depth ``m`` of the mixing).
DEPTH = 4
#: Columns are dropped (oldest first) while the scaled Gram matrix's condition exceeds this.
COND_MAX = 1e10
#: Differences needed before the first mixed iterate (after a start or a restart).
MIN_PAIRS = 2
#: The drivers mix from the first cycle that reduces the residual by less than this on.
START_RATE = 0.3
#: A mixed iterate is kept when its residual is at most ACCEPT × the driver's reference.
ACCEPT = 1.0


class Anderson:
    """Anderson mixing of depth ``depth`` on vectors of ``n`` values (NumPy only).

    The differences sit in ring buffers with their Gram matrix, updated by one row per step.
    Every product is a matrix–vector one on preallocated buffers (no temporaries of ``n``
    values: at 48 000 values each one cost ~0.1 ms of page faults, and a 1-D ``np.dot`` goes to a
    threaded BLAS: 0.9 ms of CPU against 0.04 ms for the matrix–vector product, measured)."""

    def __init__(self, n: int, depth: int = DEPTH):
        self.depth = depth
        self.dF = np.zeros((depth, n))  # ring buffers of differences (row = one pair)
        self.dG = np.zeros((depth, n))
        self.gram = np.zeros((depth, depth))
        self.f_prev, self.g_prev = np.zeros(n), np.zeros(n)
        self.f, self.out = np.zeros(n), np.zeros(n)
        self.rejected = 0  # mixed iterates the driver rejected (diagnostics)
        self.mixed = 0
        self.reset()

    def reset(self) -> None:
        """Forget the history (the next :meth:`mix` only records)."""
        self.count = 0  # differences held
        self.head = 0  # next row to write
        self.primed = False  # f_prev, g_prev hold a pair

    def mix(self, x: np.ndarray, g: np.ndarray) -> np.ndarray | None:
        """The next iterate from the iterate ``x`` and its image ``g = G(x)`` (flat arrays, not
        kept); ``None`` while fewer than :data:`MIN_PAIRS` differences are held (the driver goes
        on with ``g``).  The result is a buffer of this object, overwritten by the next call."""
        f = self.f
        np.subtract(g, x, out=f)
        if self.primed:
            h = self.head
            np.subtract(f, self.f_prev, out=self.dF[h])
            np.subtract(g, self.g_prev, out=self.dG[h])
            row = self.dF @ self.dF[h]
            self.gram[h, :] = row
            self.gram[:, h] = row
            self.head = (h + 1) % self.depth
            self.count = min(self.count + 1, self.depth)
        self.f, self.f_prev = self.f_prev, f  # (swapped: the next call overwrites the old one)
        self.g_prev[...] = g
        self.primed = True
        if self.count < MIN_PAIRS:
            return None
        # rows oldest first
        order = [(self.head - self.count + i) % self.depth for i in range(self.count)]
        rhs = self.dF @ f
        gamma, rows = _least_squares(self.gram, order, rhs)
        if gamma is None:
            return None
        self.mixed += 1
        full = np.zeros(self.depth)
        full[rows] = gamma
        np.dot(full, self.dG, out=self.out)
        np.subtract(g, self.out, out=self.out)
        return self.out


def _least_squares(gram: np.ndarray, order: list[int], rhs: np.ndarray) -> tuple[np.ndarray | None, list[int]]:
    """``γ`` minimising ``‖f − Σ γ_i dF_i‖`` over the newest rows of ``order`` whose scaled Gram
    matrix is well conditioned (``gram`` = the rows' products, ``rhs`` = their products with
    ``f``); ``None`` if not even the newest row is (a zero difference)."""
    for start in range(len(order)):
        rows = order[start:]
        G = gram[np.ix_(rows, rows)]
        d = np.sqrt(np.diag(G))
        if d.min() <= 0.0 or not np.isfinite(G).all():
            continue
        S = G / np.outer(d, d)
        w = np.linalg.eigvalsh(S)
        if w[0] <= 0.0 or w[-1] > COND_MAX * w[0]:
            continue
        c = np.linalg.solve(S, rhs[rows] / d)
        return c / d, rows
    return None, []


class Mixer:
    """A driver's Anderson mixing of the arrays ``arrays`` (updated in place by its cycles), with
    the safeguards: a mixed iterate whose residual exceeds ``ACCEPT`` × the reference (the
    residual before the cycle, or the cycle's image's when the driver knows it), or with more
    folded cells (``folds`` of arrays shaped like ``arrays``) than the cycle's image, is replaced
    by that image and the history restarts.  It starts with the first cycle (the first one, a
    full-multigrid start, excepted) that reduced the residual by less than :data:`START_RATE`.

    Per cycle: :meth:`before` (residual history so far), the cycle, :meth:`after` (True: the
    arrays hold a mixed iterate), then the driver's residual of the arrays and :meth:`keep`."""

    def __init__(self, arrays: Sequence[np.ndarray], folds: Callable[[list[np.ndarray]], int], depth: int = DEPTH):
        self.arrays = list(arrays)
        self.sizes = np.cumsum([0] + [a.size for a in self.arrays])
        self.folds = folds
        self.depth = depth
        self.acc: Anderson | None = None  # sized when the mixing starts
        self.active = self.pending = False
        self.r_ref = np.inf
        self.why: list = []  # (reason, …) of every rejected iterate (diagnostics)

    def restart(self) -> None:
        """Forget the history (the cycles' map changed, e.g. new control sources)."""
        if self.acc is not None:
            self.acc.reset()

    def _get(self, out: np.ndarray) -> None:
        for a, lo, hi in zip(self.arrays, self.sizes[:-1], self.sizes[1:], strict=True):
            out[lo:hi] = a.ravel()

    def _put(self, v: np.ndarray) -> None:
        for a, lo, hi in zip(self.arrays, self.sizes[:-1], self.sizes[1:], strict=True):
            a[...] = v[lo:hi].reshape(a.shape)

    def _views(self, v: np.ndarray) -> list[np.ndarray]:
        return [
            v[lo:hi].reshape(a.shape) for a, lo, hi in zip(self.arrays, self.sizes[:-1], self.sizes[1:], strict=True)
        ]

    def before(self, history: Sequence[tuple[int, float]]) -> None:
        """Before a cycle from the current arrays (``history[-1]``: their residual)."""
        if not self.active:
            h = history
            self.active = len(h) > 2 and h[-1][1] > START_RATE * h[-2][1]
            if not self.active:
                return
            n = int(self.sizes[-1])
            self.acc = Anderson(n, self.depth)
            self.x, self.g = np.empty(n), np.empty(n)
        self.r_ref = history[-1][1]
        self._get(self.x)

    def after(self, plain_residual: Callable[[], float] | None = None, tol: float = 0.0) -> bool:
        """After the cycle: a mixed iterate in place of the cycle's image (True) or not.
        ``plain_residual``: the image's residual (called only when a mixed iterate is made, while
        the arrays still hold the image); it is the reference of :meth:`keep` if given (else the
        residual before the cycle is), and an image within ``tol`` is kept as it is (the solve
        ends on a cycle's own grid, as without mixing)."""
        if not self.active or self.acc is None:
            return False
        self._get(self.g)
        mixed = self.acc.mix(self.x, self.g)
        self.pending = mixed is not None and bool(np.isfinite(mixed).all())
        if self.pending:
            assert mixed is not None
            if plain_residual is not None:
                self.r_ref = plain_residual()
                if self.r_ref <= tol:
                    self.pending = False
                    return False
            self._put(mixed)
        return self.pending

    def keep(self, r: float) -> bool:
        """Whether the mixed iterate (residual ``r``) stays; if not, the cycle's image is put back
        (the driver then recomputes its residual) and the history restarts."""
        assert self.acc is not None
        self.pending = False
        why: tuple = ()
        if not r <= ACCEPT * self.r_ref:
            why = ("residual", r / self.r_ref)
        else:
            folds = self.folds(self.arrays)
            if folds and folds > (plain := self.folds(self._views(self.g))):
                why = ("folds", folds, plain)
        if not why:
            return True
        self.why.append(why)
        self._put(self.g)
        self.acc.reset()
        self.acc.rejected += 1
        return False


def folded_cells(x: np.ndarray, y: np.ndarray, cells: np.ndarray | None = None) -> int:
    """Cells of the grid ``(x, y)`` turned against the majority (folded): of a one-block grid (2-D
    ``x, y``) or of the cells ``cells`` (``(n, 4)`` corner ids, counter-clockwise) of flat arrays."""
    if cells is None:
        a = (x[1:, 1:] - x[:-1, :-1]) * (y[:-1, 1:] - y[1:, :-1]) - (x[:-1, 1:] - x[1:, :-1]) * (
            y[1:, 1:] - y[:-1, :-1]
        )
        pos = int((a > 0).sum())
        return min(pos, a.size - pos)
    c0, c1, c2, c3 = cells.T
    a = (x[c2] - x[c0]) * (y[c3] - y[c1]) - (x[c3] - x[c1]) * (y[c2] - y[c0])
    return int((a <= 0).sum())
