r"""Nonlinear multigrid (FAS) solver of the elliptic grid equations.

The fine problem is ``N(u) = 0`` with ``N`` the Winslow/TTM operator of
:mod:`._mg_kernels` (eq. 30, P and Q included, Dirichlet borders).  The
Full Approximation Scheme keeps the full solution on every level:

.. math::

    N_c(u_c) = N_c(\hat R u) + s\, R\,(f - N(u)),\qquad
    u \leftarrow u + P\,(u_c - \hat R u),

with ``R̂`` sampling (injection where coarse nodes are fine nodes), ``R`` full weighting,
``P`` bilinear interpolation (linear in the finest index) and
``s = (a b)^2`` for coarsening factors ``a, b`` (≈ 1 or 2, the ratio of cell
counts) in ξ, η: in index units ``N`` scales like ``h⁴``, and the
equations are invariant under ``ξ → aξ, η → bη`` when ``P → P/a, Q → Q/b``,
which is how P, Q are carried to the coarse levels.

Hierarchy: each direction is coarsened (vertex-centred, see
:func:`._mg_kernels.transfer_tables`) while it has at least
:data:`MIN_COARSEN_CELLS` cells, so any size works (an odd count gets
uniform coarse intervals whose nodes fall between fine nodes: every level is
uniform in the finest index, and odd sizes converge as fast as even ones).
Where cells are clearly longer in one direction only the other direction is coarsened (automatic semi-coarsening, see
:func:`coarsening`), so the point smoother still smooths.  Where they are long one way in
some places and the other way elsewhere (a branched lake as one block: arms run along ξ
and across it), no one coarsening suits point smoothing: such non-periodic grids
(:func:`anisotropic`) are smoothed on every level by alternating zebra lines, η lines
then ξ lines, each pass damped (:func:`_alt_lines`, ``LINE_OMEGA``); a point-smoothed solve
that stalls or diverges goes on with line smoothing before SOR is tried.  Coarsening stops
before a level that would fold (e.g. a ring of two cells) and keeps a
periodic direction at ≥ :data:`MIN_PERIODIC_CELLS` cells.  The coarsest level
is solved by many Gauss–Seidel sweeps.  Periodic ξ (O-grids, column ``ni``
repeats column 0) is carried through every level.

Iteration: a full-multigrid start (solve the coarsest level, interpolate the
correction up, one cycle per level), then V (or W) cycles until the shared
stopping rule holds.  After the FMG interpolation to the finest level the
nodes within :data:`FMG_BAND_WIDTH` of a border get :data:`FMG_BAND_SWEEPS`
Gauss–Seidel sweeps before the first full sweep (so do coarse FMG levels with
≥ :data:`FMG_BAND_MIN_CELLS` cells): the coarser FMG solution misses the
fine truncation error next to curved borders.
The fine defect that a cycle restricts is computed first
and its largest ``|N(u)|/(2(α+γ))`` *is* the point-Jacobi stopping measure, so
the convergence check costs nothing extra; on non-periodic grids the finest
defect is restricted as it is computed (:func:`._mg_kernels.defect_restrict`,
no fine defect arrays).  The measure is the same number as
:func:`._kernels.jacobi_residual` up to rounding (``inf`` on NaN; a test
holds them together).  On the finest level a cycle
is V(0, ``POST``) after one initial pre-smoothing sweep (the same sequence of
operations as V(1, ``POST`` − 1) repeated); coarse levels use
V(``PRE``, ``COARSE_POST``).  The serial coarse levels run a whole V-cycle in
one compiled call (:func:`._mg_kernels.vcycle`, arrays packed into flat
buffers).  After post-smoothing, ``BAND_SWEEPS`` extra sweeps
relax the nodes within ``BAND_WIDTH`` of the borders (local relaxation where
the nonlinearity next to curved borders is strongest; O(n) work).

With ``ACCEL`` (off by default, see there) the fine-level cycles are a fixed-point map
accelerated by Anderson mixing (:mod:`.accel`): from the first cycle that reduces the residual
by less than ``accel.START_RATE``, each cycle's image is replaced by the combination of the last
``ACCEL_DEPTH`` + 1 images whose displacement is least, unless that raises the residual above
the image's (one more fine defect per mixed cycle) or folds more cells (then the history
restarts).  Not on point-smoothed grids that could be line-smoothed (their stall is what hands
them to the lines) nor with a control (see :func:`_cycles`).  Generated one-block shapes at ~24 000 nodes (seeds
from 774000, line-smoothed): 38 → 29, 46 → 22, 29 → 17 cycles on channel networks, 27–42 →
14–19 on jagged Y junctions; CPU 1.42 → 0.99 s in all of the 19 that converge by multigrid (the
3 others stall with and without mixing).

If the iteration diverges (a residual that grows 1000-fold or is not finite),
the solver restores the start grid and falls back to SOR; if it stalls (less
than 10 % in 6 cycles, see ``STALL_*``) SOR continues from the current
grid.  Either way ``info.message`` of the result says so.  With a control
updater whose sources are metric-scaled (wall control, Thomas–Middlecoff) a
diverged or stalled solve first starts over with the sources following the
grid on every level, a hierarchy whose coarse sources stay monotone and
fold-safe corrections (:mod:`._mg_control`: what makes wall-controlled grids
converge).  There the control's feedback adapts its gains once the wall errors
are within the feedback's clip bounds (``adaptive_gain``, see
:func:`meshcore.control.sources._adapt`): 93 instead of 275 updates on the NACA
O-grid, 69 instead of 190 on the C-grid.  If that try fails too, it starts over
once more with fixed gains (the plain iteration); SOR takes over only after
that.  A C-grid wake cut (``control.wake``) is solved
by the multigrid itself: its nodes are unknowns on every level
(:mod:`._mg_wake`), not moved once per cycle by the updater; such a grid's
levels are smoothed by zebra η-line relaxation, the lines through the cut
joined (:mod:`._mg_lines`: the wake's cells are far longer in ξ than in η).
"""

from __future__ import annotations

import math
from collections.abc import Generator

import numba
import numpy as np

from . import _mg_control as C
from . import _mg_kernels as K
from . import _mg_lines as L
from . import _mg_wake as W
from . import accel as A
from ._mg_plan import (  # noqa: F401  (re-exported: the level plan's names as before)
    FOLD_GROWTH,
    LINE_ASPECT,
    LINE_FRACTION,
    MAX_NEW_FOLDED,
    MIN_COARSEN_CELLS,
    MIN_PERIODIC_CELLS,
    SEMI_ASPECT,
    _coarse_norm,
    _factors,
    _Level,
    _plan,
    _stride,
    _tables,
    anisotropic,
    coarsening,
    hierarchy,
)
from .solver import SolverState, _sor, _sources_settled, register_method

__all__ = ["MIN_COARSEN_CELLS", "anisotropic", "coarsening", "hierarchy", "multigrid", "multigrid_w"]

#: Damping of each line pass (``u ← u + ω (u_lines − u)``).  A line solved with its
#: coefficients frozen overshoots where the grid folds (the coefficients change much with the
#: move): undamped, the cycles of a branched lake as one block circled round a defect of
#: 1e-4 for 100 cycles.  Measured on generated channel networks and a spiral (~24 000 nodes):
#: ω = 0.9 left one network circling (SOR took over), 0.7 took 1–4 more cycles than 0.8.
LINE_OMEGA = 0.8
#: Post-smoothing sweeps on a line-smoothed finest level (``POST`` point sweeps otherwise).
#: Measured on generated one-block shapes and lakes (~24 000 nodes): 3 and 2 take the same
#: cycles ± 2, 2 costs 10–20 % less; 1 took up to twice the cycles (a spiral).
LINE_POST = 2
#: After this many cycles, a residual that fell less than STALL_FACTOR in the last
#: STALL_WINDOW cycles hands over to SOR (continuing from the current grid).
STALL_START, STALL_WINDOW, STALL_FACTOR = 12, 6, 0.9
#: Pre-/post-smoothing sweeps (4-colour Gauss–Seidel) per level.
PRE, POST = 1, 3
#: Post-smoothing sweeps on the coarse levels (``POST`` on the finest).
COARSE_POST = 2
#: Extra Gauss–Seidel sweeps on the nodes within BAND_WIDTH of a border, after post-smoothing.
BAND_WIDTH, BAND_SWEEPS = 8, 4
#: The same on the coarse levels.
COARSE_BAND_WIDTH, COARSE_BAND_SWEEPS = 8, 4
#: After the FMG interpolation to the finest level, this many Gauss–Seidel sweeps on the
#: nodes within FMG_BAND_WIDTH of a border (a narrow band: the error sits right there).
FMG_BAND_WIDTH, FMG_BAND_SWEEPS = 2, 32
#: FMG levels whose smaller side has at least this many cells get the same narrow-band
#: pass right after the FMG interpolation (on smaller levels it costs more than it saves).
FMG_BAND_MIN_CELLS = 128
#: Cycles on each level of the full-multigrid start (the finest excepted).
FMG_CYCLES = 1
#: Sweeps on the coarsest level (at least; more for a periodic ring, see _coarsest_sweeps).
COARSEST_SWEEPS = 24
#: At most this many sweeps on the coarsest level (a large coarsest level: the shape
#: stopped the coarsening).
COARSEST_MAX = 100
#: Sweeps on a coarsest level smoothed by η lines (a C-grid's, see smooth): a line sweep
#: solves every η line exactly, so fewer do than point sweeps.  Measured on the NACA 0012
#: C-grid (coarsest 73 × 21): 24, 48 or 100 sweeps take the same 190 cycles, and the 100
#: were 3/4 of the solve; on a generated wall-controlled C-grid (128 × 24 cells) with the
#: sources frozen the cycle contracts 0.71 per cycle with 100, 0.72 with 48, 0.80 with
#: 24–32, 0.85 with 8.  Point-smoothed coarsest levels keep COARSEST_MAX (at 24 the NACA
#: O-grid diverged).
COARSEST_LINE_SWEEPS = 48
#: Anderson mixing of the fine-level cycles (:mod:`.accel`), of depth ACCEL_DEPTH; a mixed grid
#: is kept when its residual is at most ``accel.ACCEPT`` × the cycle's own grid's (ACCEL_PLAIN_REF;
#: else × the residual before the cycle).  Off: it takes 30-45 % fewer cycles and CPU on
#: line-smoothed branched shapes (see the module docstring), but the fold-free repair starts from
#: the converged grid and is sensitive to where in the tolerance that lies: of 32 generated shapes
#: at 6000 nodes (the 4 of tests/meshcore/test_foldfree_pieces.py, 28 of seeds 777000, 778000)
#: ``channel_network(0)`` is no longer repaired (2 cells), the other 31 are repaired as before
#: (from the plain cycles' grid at 2 × the default tolerance it is not repaired either: the
#: same 2 cells; at 0.25, 0.5, 1, 4 × it is).
ACCEL, ACCEL_DEPTH, ACCEL_PLAIN_REF = False, 4, True
#: Levels with fewer nodes than this use the serial kernels even with threads > 1.
PARALLEL_MIN_NODES = 8192
#: FMG levels with more nodes than this yield to the driver (snapshots keep flowing).
YIELD_NODES = 200_000

#: Solves of at most this many nodes keep their working storage for the next solve of
#: the same shape (see :meth:`_FAS.release`); this many workspaces are kept.
WORKSPACE_MAX_NODES, WORKSPACE_CACHE_SIZE = 1 << 17, 4

_EMPTY = np.zeros((0, 0))
_ZERO = np.zeros(())
_WORKSPACES: dict = {}

#: Diagnostics of the most recent multigrid solve in this process (for benchmarks):
#: ``levels`` (node shapes), ``node_updates`` (smoother node updates, all levels),
#: ``sources_follow_grid`` (the solve that ran had the sources follow the grid).
last_run: dict = {}


def _alt_lines(lv: _Level, sweeps: int = 1) -> None:
    """``sweeps`` alternating zebra-line sweeps of level ``lv``: every η line, then every ξ line.

    The ξ lines are the η lines of the transposed level (:func:`._mg_lines.smooth_lines`
    on transposed copies): the discrete operator is the same under ``ξ ↔ η`` with ``α ↔ γ``
    and ``P ↔ Q`` (the cross term and ``D²`` do not change), so the same kernel relaxes
    both; the copies cost about a quarter of a point sweep.  Each pass is damped by
    ``LINE_OMEGA``; the sweeps run in one compiled call (:func:`._mg_lines.alt_lines`).
    """
    L.alt_lines(lv.x, lv.y, lv.fx, lv.fy, lv.p, lv.q, LINE_OMEGA, sweeps)


class _FAS:
    """Working storage and cycles of one solve."""

    def __init__(self, state: SolverState, gamma: int, controlled: bool = False, lines: bool | None = None):
        self.state = state
        self.gamma = gamma
        self.adaptive = False  # the control's feedback gains may adapt (see _fas)
        self.updates = 0
        self.periodic = bool(state.periodic)
        threads = state.config.threads
        if threads > 1:
            numba.set_num_threads(min(threads, numba.config.NUMBA_NUM_THREADS))
        use_pq = state.p.size > 0
        # sources that follow the grid (a control updater's metric-scaled sources, _mg_control)
        self.controlled = use_pq and controlled
        self.norm: list = []
        norm = C.normalised(state.x, state.y, state.p, state.q, self.periodic) if self.controlled else None
        # a C-grid wake cut: the multigrid relaxes its nodes on every level (see _mg_wake)
        self.wake = int(getattr(state.sources, "wake", 0) or 0) if not self.periodic else 0
        plan = _plan(state.x, state.y, self.periodic, norm, self.wake)
        # cells far longer one way in places and the other way elsewhere: no choice of
        # (semi-)coarsening suits point smoothing, lines smooth whatever the aspect
        self.line_capable = not (self.periodic or self.controlled or self.wake)
        self.lines = self.line_capable and (anisotropic(state.x, state.y) if lines is None else lines)
        self.key = (
            state.x.shape,
            self.periodic,
            use_pq,
            threads,
            gamma,
            self.controlled,
            self.wake,
            self.lines,
            tuple((ci, cj) for ci, cj, _, _ in plan),
        )
        ws = _WORKSPACES.pop(self.key, None)
        if ws is None:
            self._build(plan, use_pq, threads)
        else:
            (
                self.levels,
                self.kfuse,
                self.fbuf,
                self.ibuf,
                self.meta,
                self.fscale,
                self.fused_updates,
                self.coarsest_sweeps,
            ) = ws
        lv0 = self.levels[0]
        lv0.x, lv0.y, lv0.p, lv0.q = state.x, state.y, state.p, state.q
        # restricted[k]: level k+1's right-hand side holds level k's restricted defect
        self.restricted = [False] * len(self.levels)
        self.restrict_sources()

    def release(self) -> None:
        """Keep the working storage of a small solve for the next one of the same shape.

        Building the hierarchy (tables, flat buffers) costs as much as a cycle
        on a 129² grid; a workspace is taken out of the cache while a solve
        uses it, so concurrent solves never share one.
        """
        if self.state.x.size > WORKSPACE_MAX_NODES:
            return
        lv0 = self.levels[0]
        lv0.x = lv0.y = lv0.p = lv0.q = _EMPTY  # no reference to the caller's arrays
        _WORKSPACES[self.key] = (
            self.levels,
            self.kfuse,
            getattr(self, "fbuf", None),
            getattr(self, "ibuf", None),
            getattr(self, "meta", None),
            getattr(self, "fscale", None),
            getattr(self, "fused_updates", None),
            self.coarsest_sweeps,
        )
        while len(_WORKSPACES) > WORKSPACE_CACHE_SIZE:
            try:
                del _WORKSPACES[next(iter(_WORKSPACES))]  # the oldest
            except (KeyError, StopIteration, RuntimeError):  # another thread got there first
                break

    def _build(self, plan: list, use_pq: bool, threads: int) -> None:
        """Allocate the levels of ``plan``; the fused ones live in flat buffers (:meth:`_pack`)."""
        state = self.state
        lv0 = _Level(state.x, state.y, _EMPTY, _EMPTY, state.p, state.q, wake=self.wake)
        self.levels = [lv0]

        def fused(shp):  # see _pack: V-cycles fuse every serial coarse level
            par = threads > 1 and shp[0] * shp[1] >= PARALLEL_MIN_NODES
            return self.gamma == 1 and not par and not self.lines and not self.controlled and not self.wake

        def new(shp, fuse, zero=False):  # a fused level's arrays are placed by _pack
            if fuse:
                return np.broadcast_to(_ZERO, shp)
            return np.zeros(shp) if zero else np.empty(shp)

        for _ci, _cj, tab_i, tab_j in plan:
            fine = self.levels[-1]
            ni, nj = fine.x.shape[0] - 1, fine.x.shape[1] - 1
            fine.si, fine.swi, fine.ri, fine.rwi, fine.li, fine.wli, _ = tab_i
            fine.sj, fine.swj, fine.rj, fine.rwj, fine.lj, fine.wlj, _ = tab_j
            shp = (fine.si.size, fine.sj.size)
            a = ni / (shp[0] - 1)
            b = nj / (shp[1] - 1)
            fine.scale = (a * b) ** 2
            fine.pscale, fine.qscale = 1.0 / a, 1.0 / b
            if fine is not lv0 or self.periodic or self.wake:  # else level 0's defect is restricted on the fly
                ff = fine is not lv0 and fused(fine.x.shape)
                fine.rx = new(fine.x.shape, ff)
                fine.ry = new(fine.x.shape, ff)
            fc = fused(shp)
            pc = new(shp, fc) if use_pq else _EMPTY
            qc = new(shp, fc) if use_pq else _EMPTY
            lv = _Level(new(shp, fc), new(shp, fc), new(shp, fc, True), new(shp, fc, True), pc, qc)
            lv.wake = fine.wake // 2 if shp[0] < fine.x.shape[0] else fine.wake
            self.levels.append(lv)
        last = self.levels[-1]
        if last.rx is None and len(self.levels) > 1:
            # scratch for the correction to the next finer level
            last.rx = new(last.x.shape, fused(last.x.shape))
            last.ry = new(last.x.shape, fused(last.x.shape))
        n = max(self.levels[-1].x.shape) - 1
        self.coarsest_sweeps = max(COARSEST_SWEEPS, min(2 * n * n, COARSEST_MAX))
        if self.levels[-1].wake and len(self.levels) > 1:
            self.coarsest_sweeps = COARSEST_LINE_SWEEPS  # line sweeps (see smooth)
        if self.lines and len(self.levels) > 1:
            self.coarsest_sweeps = COARSEST_LINE_SWEEPS
        for lv in self.levels:
            lv.par = threads > 1 and lv.x.size >= PARALLEL_MIN_NODES
            lv.lines = self.lines
            if lv.wake:
                lv.rcx, lv.rcy = np.zeros(lv.x.shape[0]), np.zeros(lv.x.shape[0])
        self._pack()

    def _pack(self) -> None:
        """Place the arrays of the small levels in flat buffers for :func:`K.vcycle`.

        Levels from ``kfuse`` on (all but the finest for V-cycles, or the
        serial ones with threads) run a whole V-cycle in one compiled call;
        their arrays are views of the buffers (allocated here, once: the
        levels hold shape-only placeholders until then), so the Python code
        paths (FMG start, sources, transfers from level ``kfuse − 1``) see the
        same data.  The transfer tables are copied in.
        """
        levels = self.levels
        nlev = len(levels)
        self.kfuse = nlev  # no fused levels
        if self.gamma != 1 or nlev < 2 or self.controlled or self.wake:
            return
        kf = 1
        while kf < nlev and (levels[kf].par or levels[kf].lines):
            kf += 1
        if kf >= nlev:
            return
        fpos, ipos = 0, 0
        fcopy, icopy = [], []  # (offset, table) to copy once the buffers exist
        meta = np.zeros((nlev - kf, K.META_COLS), dtype=np.int64)
        fnames = ("x", "y", "fx", "fy", "p", "q", "rx", "ry")
        fcols = (K.M_X, K.M_Y, K.M_FX, K.M_FY, K.M_P, K.M_Q, K.M_RX, K.M_RY)
        for r, lv in enumerate(levels[kf:]):
            m = meta[r]
            m[K.M_N0], m[K.M_N1] = lv.x.shape
            m[K.M_PQ] = lv.p.size > 0
            for name, col in zip(fnames, fcols, strict=True):
                arr = getattr(lv, name)
                if arr is not None and arr.size:
                    m[col] = fpos
                    fpos += arr.size
            if lv.si is not None:
                for name, col in (
                    ("si", K.M_SI),
                    ("sj", K.M_SJ),
                    ("ri", K.M_RI),
                    ("rj", K.M_RJ),
                    ("li", K.M_LI),
                    ("lj", K.M_LJ),
                ):
                    tab = getattr(lv, name)
                    m[col] = ipos
                    icopy.append((ipos, tab))
                    ipos += tab.size
                m[K.M_WI], m[K.M_WJ] = lv.ri.shape[1], lv.rj.shape[1]
                for name, col in (
                    ("swi", K.M_SWI),
                    ("swj", K.M_SWJ),
                    ("rwi", K.M_RWI),
                    ("rwj", K.M_RWJ),
                    ("wli", K.M_WLI),
                    ("wlj", K.M_WLJ),
                ):
                    tab = getattr(lv, name)
                    m[col] = fpos
                    fcopy.append((fpos, tab))
                    fpos += tab.size
        fbuf = np.empty(fpos)
        ibuf = np.empty(ipos, dtype=np.int64)
        for off, tab in fcopy:
            fbuf[off : off + tab.size] = np.ravel(tab)
        for off, tab in icopy:
            ibuf[off : off + tab.size] = np.ravel(tab)
        for r, lv in enumerate(levels[kf:]):
            m = meta[r]
            shp = lv.x.shape
            n = shp[0] * shp[1]
            for name, col in zip(fnames, fcols, strict=True):
                arr = getattr(lv, name)
                if arr is not None and arr.size:
                    view = fbuf[m[col] : m[col] + n].reshape(shp)
                    if name in ("fx", "fy"):
                        view[...] = 0.0
                    setattr(lv, name, view)
        self.kfuse = kf
        self.fbuf, self.ibuf, self.meta = fbuf, ibuf, meta
        self.fscale = np.array([lv.scale for lv in levels[kf:]])
        # smoother node updates of a fused cycle started at each level (for last_run)
        cnt = [0] * nlev
        cnt[-1] = self.coarsest_sweeps * levels[-1].x.size
        for k in range(nlev - 2, kf - 1, -1):
            cnt[k] = cnt[k + 1] + (PRE + COARSE_POST) * levels[k].x.size
        self.fused_updates = cnt

    # ------------------------------------------------------------------ pieces
    def restrict_sources(self) -> None:
        """Carry P, Q to the coarse levels (sampled, scaled by 1/a, 1/b).

        Controlled solves carry the normalised sources instead (each level
        applies them with its own metric, see :meth:`follow`).
        """
        if self.controlled:
            lv0 = self.levels[0]
            self.norm = [C.normalised(lv0.x, lv0.y, lv0.p, lv0.q, self.periodic)]
            for k in range(1, len(self.levels)):
                f, c = self.levels[k - 1], self.levels[k]
                self.norm.append(_coarse_norm(self.norm[-1], f.si, f.swi, f.sj, f.swj, c.x.shape))
            return
        for k in range(1, len(self.levels)):
            f, c = self.levels[k - 1], self.levels[k]
            if c.p.size:
                K.sample(f.p, f.si, f.swi, f.sj, f.swj, c.p)
                K.sample(f.q, f.si, f.swi, f.sj, f.swj, c.q)
                if f.pscale != 1.0:
                    c.p *= f.pscale
                if f.qscale != 1.0:
                    c.q *= f.qscale

    def follow(self, lv: _Level) -> None:
        """Controlled solves: P, Q of level ``lv`` from its normalised sources and current metric."""
        if self.controlled:
            ph, qh = self.norm[next(k for k, m in enumerate(self.levels) if m is lv)]
            C.apply(lv.x, lv.y, ph, qh, self.periodic, lv.p, lv.q)

    def smooth(self, lv: _Level, sweeps: int) -> None:
        self.follow(lv)
        if sweeps > 0:
            self.updates += sweeps * lv.x.size
            fn = K.smooth_parallel if lv.par else K.smooth
            if lv.lines:
                _alt_lines(lv, sweeps)
                return
            if not lv.wake:
                fn(lv.x, lv.y, lv.fx, lv.fy, lv.p, lv.q, self.periodic, sweeps)
                return
            # η lines, those through the cut joined (the wake's cells are far longer in ξ,
            # see _mg_lines); sources that follow the grid follow it after each sweep
            lines = L.smooth_lines_parallel if lv.par else L.smooth_lines
            for s in range(sweeps):
                if s:
                    self.follow(lv)
                lines(lv.x, lv.y, lv.fx, lv.fy, lv.p, lv.q, lv.wake, 1)

    def smooth_band(self, lv: _Level, fine: bool) -> None:
        width, sweeps = (BAND_WIDTH, BAND_SWEEPS) if fine else (COARSE_BAND_WIDTH, COARSE_BAND_SWEEPS)
        if self.controlled or lv.wake:  # the sources follow the grid, the cut relaxes, sweep by sweep
            for _ in range(sweeps):
                self.follow(lv)
                K.smooth_band(lv.x, lv.y, lv.fx, lv.fy, lv.p, lv.q, self.periodic, width, 1)
                if lv.wake:
                    W.relax_cut(lv.x, lv.y, lv.fx, lv.fy, lv.wake, 1)
        elif sweeps > 0:
            K.smooth_band(lv.x, lv.y, lv.fx, lv.fy, lv.p, lv.q, self.periodic, width, sweeps)

    def fmg_band(self, lv: _Level) -> None:
        K.smooth_band(lv.x, lv.y, lv.fx, lv.fy, lv.p, lv.q, self.periodic, FMG_BAND_WIDTH, FMG_BAND_SWEEPS)

    def fmg_fused(self) -> None:
        """The FMG start on the fused levels in one compiled call (:func:`K.fmg_start`)."""
        kf = self.kfuse
        self.updates += self.coarsest_sweeps * self.levels[-1].x.size
        self.updates += FMG_CYCLES * sum(self.fused_updates[kf:-1])
        K.fmg_start(
            self.fbuf,
            self.ibuf,
            self.meta,
            self.fscale,
            PRE,
            COARSE_POST,
            self.coarsest_sweeps,
            COARSE_BAND_WIDTH,
            COARSE_BAND_SWEEPS,
            FMG_BAND_WIDTH,
            FMG_BAND_SWEEPS,
            FMG_BAND_MIN_CELLS,
            FMG_CYCLES,
            self.periodic,
        )

    def defect(self, lv: _Level) -> float:
        fn = K.defect_parallel if lv.par else K.defect
        m = fn(lv.x, lv.y, lv.fx, lv.fy, lv.p, lv.q, self.periodic, lv.rx, lv.ry)
        if lv.wake:  # the cut nodes are unknowns too
            m = max(m, W.cut_defect(lv.x, lv.y, lv.fx, lv.fy, lv.wake, lv.rcx, lv.rcy))
        return m

    def defect_restrict(self, k: int) -> float:
        """Level k's defect measure (largest ``(|f − N|/den)²``), its restriction already in
        level k+1's right-hand side unless periodic (:func:`K.defect_restrict`: no fine
        defect arrays); :meth:`to_coarse` then only adds ``N_c``."""
        f = self.levels[k]
        if self.periodic or f.wake:
            self.restricted[k] = False
            return self.defect(f)
        c = self.levels[k + 1]
        self.restricted[k] = True
        if f.par:
            return K.defect_restrict_parallel(
                f.x, f.y, f.fx, f.fy, f.p, f.q, f.ri, f.rwi, f.rj, f.rwj, f.scale, c.fx, c.fy, K.ROW_CHUNKS
            )
        return K.defect_restrict(f.x, f.y, f.fx, f.fy, f.p, f.q, f.ri, f.rwi, f.rj, f.rwj, f.scale, c.fx, c.fy, 1)

    def to_coarse(self, k: int) -> None:
        """FAS right-hand side of level k+1 from the defect of level k."""
        f, c = self.levels[k], self.levels[k + 1]
        K.sample(f.x, f.si, f.swi, f.sj, f.swj, c.x)
        K.sample(f.y, f.si, f.swi, f.sj, f.swj, c.y)
        if not self.restricted[k]:
            restrict = K.restrict_parallel if c.par else K.restrict
            restrict(f.rx, f.ry, f.ri, f.rwi, f.rj, f.rwj, f.scale, c.fx, c.fy)
            if c.wake:
                eta = c.x.shape[1] < f.x.shape[1]
                W.restrict_cut(f.rcx, f.rcy, f.rx, f.ry, f.ri, f.rwi, eta, f.scale, c.wake, c.fx, c.fy)
        self.restricted[k] = False
        self.follow(c)
        add = K.add_operator_parallel if c.par else K.add_operator
        add(c.x, c.y, c.p, c.q, self.periodic, c.fx, c.fy)
        if c.wake:
            W.add_cut_operator(c.x, c.y, c.wake, c.fx, c.fy, c.rcx, c.rcy)

    def correct(self, k: int) -> None:
        """``u_k += P(u_{k+1} − R̂ u_k)`` (the coarse level's scratch holds the correction)."""
        f, c = self.levels[k], self.levels[k + 1]
        fn = K.prolong_correct_parallel if f.par else K.prolong_correct
        if self.controlled:  # never let the correction collapse a thin cell (see _mg_control)
            x0, y0 = f.x.copy(), f.y.copy()
        fn(f.x, f.y, c.x, c.y, c.rx, c.ry, f.si, f.swi, f.sj, f.swj, f.li, f.lj, f.wli, f.wlj, self.periodic)
        if f.wake:
            W.prolong_cut(f.x, f.y, c.rx, c.ry, f.li, f.wli, f.wake)
        if self.controlled:
            C.safe_step(f.x, f.y, x0, y0)

    def cycle(self, k: int, *, have_defect: bool = False) -> None:
        """One V (gamma = 1) or W (gamma = 2) cycle on level k."""
        lv = self.levels[k]
        if k >= self.kfuse:
            self.updates += self.fused_updates[k]
            K.vcycle(
                self.fbuf,
                self.ibuf,
                self.meta,
                self.fscale,
                k - self.kfuse,
                PRE,
                COARSE_POST,
                self.coarsest_sweeps,
                COARSE_BAND_WIDTH,
                COARSE_BAND_SWEEPS,
                self.periodic,
            )
            return
        if k == len(self.levels) - 1:
            self.smooth(lv, self.coarsest_sweeps)
            return
        if not have_defect:
            self.smooth(lv, PRE)
            self.defect_restrict(k)
        self.to_coarse(k)
        for _ in range(self.gamma if k + 1 < len(self.levels) - 1 else 1):
            self.cycle(k + 1)
        self.correct(k)
        self.smooth(lv, COARSE_POST if k else LINE_POST if lv.lines else POST)
        self.smooth_band(lv, k == 0)


def _fas(state: SolverState, gamma: int) -> Generator[str, None, bool]:
    """The FAS solve; if it diverges or stalls, with a control whose sources are metric-scaled
    it starts over with the sources following the grid (see :mod:`._mg_control`) and adaptive
    feedback gains, and if those gains adapted and that fails too, once more with fixed gains;
    a point-smoothed solve that could be line-smoothed goes on with line smoothing (from the
    current grid after a stall, from the start grid after a divergence); else (and if that
    fails too) SOR takes over."""
    retry = state.p.size > 0 and bool(getattr(state.sources, "metric_scaled", False))
    why = ""
    updates = 0
    # (sources follow the grid, adaptive feedback gains): the last try keeps the gains fixed
    tries = ((False, False), (True, True), (True, False)) if retry else ((False, False),)
    for controlled, adaptive in tries:
        lines, fmg = None, True
        while True:
            mg = _FAS(state, gamma, controlled, lines)
            mg.adaptive = adaptive
            if mg.wake:  # the cut nodes are the multigrid's unknowns now, not the updater's
                state.sources.wake_by_solver = len(mg.levels) > 1
            last_run.clear()
            last_run["levels"] = [lv.x.shape for lv in mg.levels]
            last_run["sources_follow_grid"] = mg.controlled
            last_run["adaptive_gain"] = adaptive
            last_run["lines"] = mg.lines
            try:
                out = yield from _fas_run(state, mg, fmg)
            finally:
                updates += mg.updates
                last_run["node_updates"] = updates
                mg.release()
            if not isinstance(out, str):
                return out
            why = out
            if mg.lines or not mg.line_capable or len(mg.levels) < 2:
                break
            # point smoothing failed on this grid: its cells are too anisotropic in places
            lines, fmg = True, out.startswith("diverged")
            if fmg:
                _restart(state)
            state.history.clear()
            state.iterations = 0
        if not retry or (controlled and not (adaptive and getattr(state.sources, "gains_adapted", False))):
            break  # (a try with gains that never adapted is not repeated with fixed gains)
        _restart(state)  # the sources-following cycles start over from the start grid
        state.history.clear()
        state.iterations = 0
    if state.sources is not None:  # SOR leaves the cut to the updater, with fixed gains
        state.sources.wake_by_solver = False
        state.sources.adaptive_gain = False
    if why.startswith("diverged"):
        _restart(state)
    state.message = f"multigrid {why}; continued with SOR"
    state.history.clear()
    state.iterations = 0
    return (yield from _sor(state))


def _restart(state: SolverState) -> None:
    """The start grid back, and the control (if any) started over with it."""
    state.x[...] = state.start[0]
    state.y[...] = state.start[1]
    if state.sources is not None:
        state.p[...], state.q[...] = state.pq_given
        state.sources.initialize(state.x, state.y, state.p, state.q)


def _fas_run(state: SolverState, mg: _FAS, fmg: bool = True) -> Generator[str, None, bool | str]:
    tol = state.tol_abs
    levels = mg.levels
    lv0 = levels[0]
    if len(levels) == 1:  # too small to coarsen: plain Gauss–Seidel/SOR
        return (yield from _sor(state))
    # ----------------------------------------------------- full-multigrid start
    r0 = math.sqrt(mg.defect_restrict(0))  # the stopping measure (see the module docstring)
    if r0 <= tol:
        r0 = state.residual()
    state.history.append((0, r0))
    if r0 <= tol:
        state.final_residual = r0
        return True
    if mg.controlled or mg.wake or not fmg:  # no FMG start: coarse solutions do not hold the wall spacing
        mg.smooth(lv0, PRE)
        return (yield from _cycles(state, mg, r0))
    for k in range(1, len(levels)):
        f = levels[k - 1]
        K.sample(f.x, f.si, f.swi, f.sj, f.swj, levels[k].x)
        K.sample(f.y, f.si, f.swi, f.sj, f.swj, levels[k].y)
        levels[k].fx[...] = 0.0
        levels[k].fy[...] = 0.0
    mg.restricted[0] = False  # the r0 check's restriction was just zeroed
    top = len(levels) - 1  # the levels below ``top`` run their FMG step from Python
    if mg.kfuse < len(levels) and levels[mg.kfuse].x.size < YIELD_NODES:
        mg.fmg_fused()
        top = mg.kfuse
    else:
        mg.smooth(levels[-1], mg.coarsest_sweeps)
    for k in range(top - 1, 0, -1):
        mg.correct(k)
        levels[k].fx[...] = 0.0  # plain coarse discretisation (f = 0) on this FMG level
        levels[k].fy[...] = 0.0
        if min(levels[k].x.shape) - 1 >= FMG_BAND_MIN_CELLS:
            mg.fmg_band(levels[k])  # as on the finest level below
        for _ in range(FMG_CYCLES):
            mg.cycle(k)
        if levels[k].x.size >= YIELD_NODES:
            yield "tick"
    mg.correct(0)
    # The FMG correction is interpolated from a coarse problem without the fine
    # truncation error, which is largest next to curved borders: relax the
    # nodes next to the borders first (it takes one or two cycles off).
    mg.fmg_band(lv0)
    mg.smooth(lv0, PRE)
    return (yield from _cycles(state, mg, r0))


def _cycles(state: SolverState, mg: _FAS, r0: float) -> Generator[str, None, bool | str]:
    """V (W) cycles from the current fine grid until the stopping rule holds: True, False
    (not converged within ``max_iterations``) or why they gave up (``"diverged"``,
    ``"stalled after n cycles"``)."""
    cfg = state.config
    tol = state.tol_abs
    # ``it`` counts finished fine-level cycles; the FMG start counts as the first.
    best = math.inf
    moved = -STALL_WINDOW - 1  # the last cycle after which the sources were still moving
    # not on a point-smoothed grid that could be line-smoothed: its stall is what hands it to
    # the lines.  Mixed, such solves kept point smoothing (2-4x the cycles of the plain ones'
    # stall and line cycles, about the same CPU: generated networks and Y junctions at 3000
    # nodes; mixing them too: -2 to -4 % CPU on 32 generated shapes, within the noise).  Nor with
    # a control (its sources move every cycle: nothing to mix on the examples, bit for bit the
    # same; a C-grid whose sources froze got 30x ahead, then circled near 1e-7 where the plain
    # cycles went on: test_multigrid_wake.test_sources_frozen_the_cgrid_cycle_contracts)
    mixes = ACCEL and state.sources is None and (mg.lines or not mg.line_capable)
    acc = A.Mixer([state.x, state.y], _folds, ACCEL_DEPTH) if mixes else None
    last_run["accel"] = acc
    for it in range(1, cfg.max_iterations + 1):
        state.iterations = it
        r = math.sqrt(mg.defect_restrict(0))
        if acc is not None and acc.pending and not acc.keep(r):
            r = math.sqrt(mg.defect_restrict(0))  # the cycle's own image back
        state.history.append((it, r))
        if r <= tol and _sources_settled(state):
            state.final_residual = r
            return True
        if not math.isfinite(r) or r > 1e3 * max(min(best, r0), tol if state.sources is not None else 0.0):
            return "diverged"  # the control (if any) starts over with the start grid
        best = min(best, r)
        if mg.controlled and not _sources_settled(state):
            moved = it
        if _stalled(state.history, it, tol, it - moved <= STALL_WINDOW):
            return f"stalled after {it} cycles"
        yield "tick"
        if it == cfg.max_iterations:
            break
        if state.sources is not None and state.sources.wants_update(it):
            # the cycles converge the grid for the current sources: the feedback may adapt
            # its gains once its errors are unclipped (see meshcore.control.sources._adapt)
            state.sources.adaptive_gain = mg.controlled and mg.adaptive
            state.sources.update(state.x, state.y, state.p, state.q, it)
            mg.restrict_sources()
            mg.defect_restrict(0)
            if acc is not None:
                acc.restart()  # another map: the differences no longer belong to it
        if acc is not None:
            acc.before(state.history)
        mg.cycle(0, have_defect=True)
        if acc is not None:
            acc.after((lambda: math.sqrt(mg.defect_restrict(0))) if ACCEL_PLAIN_REF else None, tol)
    return False


def _folds(a: list) -> int:
    return A.folded_cells(a[0], a[1])


def _stalled(history: list, it: int, tol: float, moving: bool) -> bool:
    """The stall rule: less than ``1 − STALL_FACTOR`` gained in the last ``STALL_WINDOW`` cycles.

    ``moving``: a control whose sources moved (were not settled) within the
    window sets the pace; the residual then follows the source updates (a
    plateau, bumps), so it is no stall.  SOR would need the same updates, one
    per sweep.  (Judged on the current update alone, a control whose change
    crossed the settled threshold once while the residual bumped round the
    tolerance handed the NACA 0012 C-grid to SOR after 191 cycles.)
    """
    if moving or it < STALL_START or history[-1][1] <= tol:
        return False
    return history[-1][1] > STALL_FACTOR * history[-1 - STALL_WINDOW][1]


def multigrid(state: SolverState) -> Generator[str, None, bool]:
    """FAS V-cycles with a full-multigrid start (method ``"multigrid"``)."""
    return (yield from _fas(state, 1))


def multigrid_w(state: SolverState) -> Generator[str, None, bool]:
    """FAS W-cycles with a full-multigrid start (method ``"multigrid-w"``)."""
    return (yield from _fas(state, 2))


register_method("multigrid", multigrid)
register_method("multigrid-w", multigrid_w)
