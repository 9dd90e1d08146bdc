r"""Nonlinear multigrid (FAS) over a whole multiblock topology (``engine="multigrid"``).

The unknowns are the free nodes of the global node array (see
:class:`~.topology.NodeMap`), the equations ``A(u) = u − T(u) = f`` with ``T``
the point-Jacobi target of :mod:`._kernels` (9-point Winslow stencil in the
local frame of each regular node, ring mean at nodes where 3, 5, … blocks
meet), ``f = 0`` on the finest level.

Hierarchy (:mod:`.hierarchy`): a coarse level keeps a subset of the finer
level's nodes, whole grid lines of every block, chosen so that the blocks still
meet node to node; both directions coarsen, odd cell counts too (a coarse cell
spans one or two fine cells).

Smoother (one step): a point Gauss–Seidel sweep over the table (block interiors in
4-colour order, :func:`.hierarchy._colour_order`), a line
Gauss–Seidel sweep over every interior block line along ξ (even steps of a
smoothing call) or along η (odd steps), tridiagonal solves with frozen
coefficients (:func:`._kernels.line_sweep_rhs`: robust where cells are
stretched, which on the lakes happens where the solution pulls a row of cells
away from the shore, not on the start grid), and :data:`BORDER_SWEEPS` point
sweeps over the block borders.  A line takes the nodes at its two ends on an
interface into its solve (:func:`.hierarchy.lines_reference`: an interface node
is on a line of each block beside it, its stencil turned into that block's
frame): 81 → 76 cycles on 19 topologies (the 3 Shasta examples, 4 lake layouts,
12 generated layouts of :mod:`meshcore.testing` at ~15 000 nodes), none more,
where the lines that ended next to the borders left the interface nodes to the
point sweeps.  One line direction per
step, so V(2, 2) still relaxes both directions before and after the coarse
correction: a line sweep costs about two point sweeps, and sweeping both
directions in every step cost 15–25 % more CPU time per solve than the ~20 %
more cycles this takes (measured on 11 automatic layouts, 7 of them generated
shapes of :mod:`meshcore.testing`: 43 → 52 cycles in all, every one converged
by multigrid).

Full Approximation Scheme, one V(``PRE``, ``POST``) cycle::

    u ← smooth(u, f)                                     (PRE smoothing steps)
    r = f − A(u)
    v = R̂ u              (injection: the coarse nodes are fine nodes)
    solve approximately  A_H(u_H) = A_H(v) + s · R r     (recursively)
    u ← u + P (u_H − v)
    u ← smooth(u, f)

``P`` is linear interpolation along the block lines, ``R = D⁻¹ Pᵀ`` its
transpose normalised by the row sums (consistent across interfaces and corners
of any valence), ``s`` the FAS scaling of the restricted defect (all in
:mod:`.hierarchy`).  The stopping rule is the shared one: the finest-level
defect with ``f = 0`` is the point-Jacobi displacement.

Each smoothing step ends with :data:`BAND_SWEEPS` point sweeps over the nodes
next to the fixed boundary (:func:`.hierarchy._band`), where the error a cycle
leaves is largest on the lake layouts.

After every cycle (outside the compiled call), point sweeps round the nodes with the
largest defect (:func:`_hot_sweeps`, :data:`HOT_SWEEPS`).

The first cycle is a full-multigrid start (:func:`_fmg`).  Measured
(``benchmarks/robust.py``, Shasta examples and automatic lake layouts): 3–6
cycles with rates 0.05–0.26 per cycle (4–9 V(2, 2) cycles, rates up to 0.36,
without the band sweeps and the full-multigrid start); with one line direction per
step and the hot-spot sweeps, 2–8 cycles on 11 layouts (7 generated), rates
0.02–0.42, median 0.18, where the point smoother with
semi-coarsening reduced by 0.5–0.8 per cycle and ``engine="auto"`` switched to
SOR.  The cycle runs in one compiled call (:mod:`._mg_fused`); :func:`_cycle_reference`
is the same cycle kernel by kernel (the test oracle).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from typing import Any

import numpy as np

from ..elliptic import accel as _accel
from . import _kernels as _typed_kernels
from . import _mg_fused as _typed_fused
from .hierarchy import Level, hot_rows, levels
from .topology import MultiBlockTopology

__all__ = ["iterate_fas", "levels"]

#: The numba kernels (``Any``: mypy's numba stubs reject calls with ``*args``).
_kernels: Any = _typed_kernels
_fused: Any = _typed_fused

#: ``engine="auto"`` leaves multigrid for SOR when a cycle reduces the defect by less than
#: this (SOR reduces by ≈ 0.96 per sweep on the lake examples, 0.96¹⁶ ≈ 0.5, and a cycle costs
#: more than 16 sweeps; the cycles measured on the lake layouts reduce by 0.1–0.36).
AUTO_GIVE_UP_RATE = 0.5
#: Start with full multigrid (:func:`_fmg`): it costs about one cycle and saved 1-3 of the 4-6
#: cycles on the Shasta examples and lake layouts (measured).
FMG_START = True
#: Gauss–Seidel sweeps before / after the coarse-grid correction.
PRE, POST = 2, 2
#: Extra point sweeps over the block borders after the line sweeps of a smoothing step (the
#: lines end at the borders; those through an interface take its node in their solve, but not
#: the nodes along it, at block corners and T-junctions).  With the lines through the interface
#: nodes, 1 sweep took 78 cycles and 0 took 80 instead of 76 on 19 topologies (measured), at
#: about 1 % of a smoothing step each.
BORDER_SWEEPS = 2
#: Extra point sweeps over the band of nodes next to the fixed boundary (:func:`.hierarchy._band`)
#: after each smoothing step.
BAND_SWEEPS = 2
#: Sweeps on the coarsest level: at least COARSEST_SWEEPS, then until the defect fell by
#: COARSEST_REDUCTION, at most COARSEST_MAX_SWEEPS (where the coarsening stops early, e.g. the
#: lake layouts, the coarsest level is large and its SOR does not reach the reduction: 2000
#: sweeps made a cycle cost ~10× more and, on Shasta's automatic layout, diverged; measured).
#: After every cycle, HOT_SWEEPS point sweeps over the nodes whose defect exceeds HOT_SHARE ×
#: the largest and the nodes HOT_WIDTH stencil steps round them (:func:`_hot_sweeps`).  The
#: stopping test is the largest defect, and on the lake layouts it sits cycle after cycle at
#: the same few nodes (next to an interface or the shore where cells are most distorted), which
#: the cycle reduces slowest.  On 11 automatic layouts (7 generated shapes of
#: :mod:`meshcore.testing`, ~15 000 nodes): 51 → 43 cycles in all, the worst late rate
#: 0.49 → 0.42 per cycle (``engine="auto"`` gives up at 0.5), for 100–1000 nodes × 10 sweeps
#: per cycle.  Wider or more sweeps (0.05, 3, 20): 36 cycles, but no less CPU time; narrower
#: (0.1, 1, 5) or (0.2, 2, 10): 45 cycles (measured).
HOT_SHARE, HOT_WIDTH, HOT_SWEEPS = 0.1, 2, 10
COARSEST_SWEEPS = 20
COARSEST_REDUCTION = 1e-3
COARSEST_MAX_SWEEPS = 100
#: Anderson mixing of the cycles (:mod:`meshcore.elliptic.accel`, the one-block solver's), of
#: depth ACCEL_DEPTH; a mixed iterate is kept when its residual is at most ``accel.ACCEPT`` × the
#: cycle's own image's (ACCEL_PLAIN_REF; else the residual before the cycle).  Off: it did not pay
#: here.  On 21 topologies (the 3 Shasta examples, 4 lake layouts, 14 generated layouts of
#: :mod:`meshcore.testing` at ~15 000 nodes) the cycles take 2–7 steps at 0.1–0.45 each, so the
#: mixing (from the first cycle slower than ``accel.START_RATE``, after ``accel.MIN_PAIRS``
#: differences) mixed on one topology (7 cycles both); mixing from the first cycle on, 9 of its
#: 12 mixed iterates had a larger residual than the cycle's own (1.0–1.9×) and were rejected:
#: 2798 → 2797 cycles, 733 → 811 ms of CPU in all (one process, load ~11).
ACCEL, ACCEL_DEPTH, ACCEL_PLAIN_REF = False, 4, True
#: Diagnostics of the most recent solve (``accel``: the mixer, its counts).
last_run: dict = {}


def _smooth(lv: Level, x, y, fx, fy, steps: int, line_omega: float = 1.0) -> None:
    """``steps`` smoothing steps: point sweep, line sweep along ξ (even steps) or η (odd steps;
    damped by ``line_omega``), border and band sweeps."""
    for step in range(steps):
        _kernels.table_sweep_rhs(x, y, fx, fy, *lv.args, 1.0)
        _kernels.line_sweep_rhs(x, y, fx, fy, *lv.lines[step % 2], line_omega)
        for _ in range(BORDER_SWEEPS):
            _kernels.table_sweep_rhs(x, y, fx, fy, *lv.border, 1.0)
        for _ in range(BAND_SWEEPS):
            _kernels.table_sweep_rhs(x, y, fx, fy, *lv.band, 1.0)


def _hot_sweeps(lv: Level, x, y, rx, ry) -> tuple:
    """Point sweeps (``f = 0``) round the nodes with the largest defect ``(rx, ry)`` (see
    :data:`HOT_SHARE`); returns the table rows swept."""
    d2 = rx * rx + ry * ry
    rows = hot_rows(lv, np.flatnonzero(d2 > HOT_SHARE**2 * d2.max()), HOT_WIDTH)
    e = np.zeros(0)
    for _ in range(HOT_SWEEPS):
        _kernels.table_sweep_rhs(x, y, e, e, *rows, 1.0)
    return rows


def _defect_after(lv: Level, x, y, zero, rx, ry, moved: np.ndarray) -> float:
    """The largest defect (``f = zero``) after only the nodes ``moved`` changed, with ``rx, ry`` the
    defect before: recomputed at the regular nodes whose stencil holds a moved node and at the
    irregular nodes, the rest kept.  The same value as a full :func:`._kernels.table_defect` (each
    node's defect is the same expression of its stencil), for the nodes round the hot spots instead
    of all (one defect of the finest level per cycle less)."""
    rows = hot_rows(lv, moved, 1)
    _kernels.table_defect(x, y, zero, zero, *rows[:2], *lv.args[2:], rx, ry)
    d2 = float((rx * rx + ry * ry).max(initial=0.0))
    return math.sqrt(d2) if d2 == d2 else math.inf


def _cycle_reference(lvs: list[Level], k: int, x, y, fx, fy, line_omega: float = 1.0) -> None:
    """One V-cycle from level ``k``, kernel by kernel (the reference of :func:`_cycle`)."""
    lv = lvs[k]
    if k == len(lvs) - 1:
        # SOR until the defect dropped by COARSEST_REDUCTION (checked every 10 sweeps)
        omega = 2.0 / (1.0 + math.sin(math.pi / max(math.sqrt(2.0 * lv.n), 2.0)))
        rx, ry = np.zeros(lv.n), np.zeros(lv.n)
        r0 = _kernels.table_defect(x, y, fx, fy, *lv.args, rx, ry)
        for sweep in range(1, COARSEST_MAX_SWEEPS + 1):
            _kernels.table_sweep_rhs(x, y, fx, fy, *lv.args, omega)
            if sweep % 10 == 0 and sweep >= COARSEST_SWEEPS:
                r = _kernels.table_defect(x, y, fx, fy, *lv.args, rx, ry)
                if r <= COARSEST_REDUCTION * r0:
                    break
        return
    _smooth(lv, x, y, fx, fy, PRE, line_omega)
    rx, ry = np.zeros(lv.n), np.zeros(lv.n)
    _kernels.table_defect(x, y, fx, fy, *lv.args, rx, ry)
    co = lvs[k + 1]
    vx, vy = x[co.inj].copy(), y[co.inj].copy()
    zero = np.zeros(co.n)
    dx, dy = np.zeros(co.n), np.zeros(co.n)
    _kernels.table_defect(vx, vy, zero, zero, *co.args, dx, dy)  # d = T(v) − v = −A_H(v)
    fcx = -dx + co.scale * (co.R @ rx)
    fcy = -dy + co.scale * (co.R @ ry)
    fcx[~co.free] = 0.0
    fcy[~co.free] = 0.0
    ux, uy = vx.copy(), vy.copy()
    _cycle_reference(lvs, k + 1, ux, uy, fcx, fcy, line_omega)
    x += co.P @ (ux - vx)
    y += co.P @ (uy - vy)
    _smooth(lv, x, y, fx, fy, POST, line_omega)


def pack(lvs: list[Level], index_dtype: Any = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(fb, ib, meta)``: the levels in the flat buffers of :mod:`._mg_fused` (node values zero).

    Every array is copied once, into its place in the buffers (a list of parts concatenated
    copied the 22 MB of a 46 000-node hierarchy twice: 12 → 4 ms, measured).

    ``ib`` holds ids and pointers (each below the length of the array it indexes, so below
    the larger buffer's size) as ``index_dtype``; None: int32 when they fit, else int64.  The
    tables in int32 are half the bytes the sweeps stream through per node (the finest level's
    neighbour table and its copy in line order: 5.9 → 2.9 MB at 46 000 nodes); the same ids, so
    the same iterates.  One V-cycle, min of 40, int64 → int32 in one process at load ~7:
    refined Shasta example (45 849 nodes) 18.6 → 8.5 ms, the four lake layouts of
    ``benchmarks/robust.py`` (15 000–17 000 nodes) −12 to −21 %, the fine example (11 725) −6 %,
    the coarse (3 063) the same (measured)."""
    F = _typed_fused
    meta = np.zeros((len(lvs), F.META_COLS), dtype=np.int64)
    parts: tuple[list, list] = ([], [])  # (offset, array or None for zeros) of ints, floats
    sizes = [0, 0]

    def put(col: int | None, a: np.ndarray | int, is_float: bool = False) -> None:
        """The next part of a buffer: ``a`` (or ``a`` zeros); ``col`` (None: a continuation) notes its offset."""
        if col is not None:
            meta[k, col] = sizes[is_float]
        if isinstance(a, (int, np.integer)):
            parts[is_float].append((sizes[is_float], None))
            sizes[is_float] += int(a)
        else:
            parts[is_float].append((sizes[is_float], a))
            sizes[is_float] += a.size

    for k, lv in enumerate(lvs):
        nodes, nbr, irr_n, irr_p, ring = lv.args
        (nx, bx, px, ax), (ny, by, py, ay) = lv.lines
        meta[k, [F.C_N, F.C_NREG, F.C_NINT, F.C_NIRR, F.C_NRING]] = (
            lv.n,
            len(nodes),
            len(nodes) - len(lv.border[0]),
            len(irr_n),
            len(ring),
        )
        meta[k, [F.C_NROWS, F.C_NL0, F.C_NL]] = len(nx) + len(ny), len(px) - 1, len(px) + len(py) - 2
        for col, a in ((F.C_NODES, nodes), (F.C_NBR, nbr), (F.C_IRRN, irr_n), (F.C_IRRP, irr_p), (F.C_RING, ring)):
            put(col, a)
        put(F.C_LNODES, nx)  # the line tables: ξ then η, one array each
        put(None, ny)
        put(F.C_LNBR, bx)
        put(None, by)
        put(F.C_LPTR, px)
        put(None, py[1:] + len(nx))
        put(F.C_LAXIS, ax)
        put(None, ay)
        meta[k, F.C_NBAND] = len(lv.band[0])
        put(F.C_BNODES, lv.band[0])
        put(F.C_BNBR, lv.band[1])
        for col in (F.C_X, F.C_Y, F.C_FX, F.C_FY, F.C_RX, F.C_RY, F.C_VX, F.C_VY):
            put(col, lv.n, True)
        if k == 0:
            continue
        assert lv.inj is not None and lv.scale is not None
        P, R = lv.P, lv.R
        meta[k, [F.C_PNZ, F.C_RNZ]] = P.nnz, R.nnz
        for col, a in ((F.C_INJ, lv.inj), (F.C_FREE, lv.free), (F.C_PPTR, P.indptr), (F.C_PIDX, P.indices)):
            put(col, a)
        put(F.C_RPTR, R.indptr)
        put(F.C_RIDX, R.indices)
        for col, a in ((F.C_SCALE, lv.scale), (F.C_PVAL, P.data), (F.C_RVAL, R.data)):
            put(col, a, True)
    if index_dtype is None:
        index_dtype = np.int32 if max(sizes) < 2**31 else np.int64
    ib, fb = np.empty(sizes[0], dtype=index_dtype), np.zeros(sizes[1])
    for buf, ps in ((ib, parts[0]), (fb, parts[1])):
        for off, a in ps:
            if a is not None:
                buf[off : off + a.size] = a.ravel()
    return fb, ib, meta


def _packed(lvs: list[Level]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`pack` of ``lvs``, kept with the finest level (one packing per depth: the solver may
    retry with fewer levels)."""
    lv0 = lvs[0]
    if lv0.packed is None:
        lv0.packed = {}
    if len(lvs) not in lv0.packed:
        lv0.packed[len(lvs)] = pack(lvs)
    return lv0.packed[len(lvs)]


def _full_defect(lvs: list[Level], x, y, rx, ry) -> float:
    """The finest level's largest defect with ``f = 0`` (``rx, ry`` filled at the free nodes):
    :func:`._kernels.table_defect` of its table as packed for the cycles (the same rows in the same
    order, so the same value; the int32 copy the cycles just streamed through, where the level's
    own int64 table costs a tenth of a cycle at 16 000 nodes under load, measured)."""
    fb, ib, meta = _packed(lvs)
    e = np.zeros(0)
    return float(_fused._defect(fb, ib, meta[0], x, y, e, e, rx, ry))


def _cycle(lvs: list[Level], k: int, x, y, fx, fy, line_omega: float = 1.0) -> None:
    """One V-cycle from level ``k`` in one compiled call (:func:`._mg_fused.vcycle`)."""
    fb, ib, meta = _packed(lvs)
    m, n = meta[k], lvs[k].n
    F = _typed_fused
    for col, a in ((F.C_X, x), (F.C_Y, y), (F.C_FX, fx), (F.C_FY, fy)):
        fb[m[col] : m[col] + n] = a
    _fused.vcycle(
        fb,
        ib,
        meta,
        k,
        PRE,
        POST,
        BORDER_SWEEPS,
        BAND_SWEEPS,
        COARSEST_SWEEPS,
        COARSEST_REDUCTION,
        COARSEST_MAX_SWEEPS,
        float(line_omega),
        bool(fx.any() or fy.any()),  # f = 0 (every cycle of the solver): not read on level k
    )
    x[:] = fb[m[F.C_X] : m[F.C_X] + n]
    y[:] = fb[m[F.C_Y] : m[F.C_Y] + n]


def _fmg(lvs: list[Level], x, y, line_omega: float = 1.0, should_stop: Callable[[], bool] | None = None) -> None:
    """Full-multigrid start: the start grid injected into every level, the coarsest level solved,
    then on each finer level the coarse change interpolated (``u_h ← u_h + P (u_H − R̂ u_h)``) and
    one V-cycle from that level, up to ``x, y`` (in place).  ``should_stop()`` true before a level's
    cycle: ``x, y`` stay as they were (only the finest level's cycle changes them)."""
    xs, ys = [x], [y]
    for co in lvs[1:]:
        xs.append(xs[-1][co.inj])
        ys.append(ys[-1][co.inj])
    x0, y0 = [a.copy() for a in xs], [a.copy() for a in ys]
    for k in range(len(lvs) - 1, -1, -1):
        if k < len(lvs) - 1:
            co = lvs[k + 1]
            xs[k] += co.P @ (xs[k + 1] - x0[k + 1])
            ys[k] += co.P @ (ys[k + 1] - y0[k + 1])
        if should_stop is not None and should_stop():
            return
        zero = np.zeros(lvs[k].n)
        _cycle(lvs, k, xs[k], ys[k], zero, zero, line_omega)


def iterate_fas(
    x,
    y,
    topo: MultiBlockTopology,
    tol: float,
    max_cycles: int,
    give_up_rate: float | None = None,
    lvs: list | None = None,
    line_omega: float = 1.0,
    should_stop: Callable[[], bool] | None = None,
):
    """V-cycles on the global arrays ``x, y`` (in place) until the Jacobi residual ≤ ``tol``.

    The first cycle is the full-multigrid start (:func:`_fmg`, when :data:`FMG_START`).
    A generator: yields ``(cycle, residual)`` after every cycle (send
    ``"stop"`` to stop).  ``give_up_rate``: stop with message ``"slow"`` when,
    from the third cycle on, the defect falls by less than this factor per
    cycle (geometric mean of the last two cycles) — the caller then continues
    with SOR.  ``line_omega``: damping of the line sweeps (1: none; :data:`RETRY_LINE_OMEGA`).
    ``should_stop()``: looked at between the levels of the full-multigrid start (on 1.7 million cells
    one start took several seconds after a Stop); true, it ends with message ``"stopped"``.

    Returns ``(cycles, residual, history, message, n_levels)``.
    """
    lvs = levels(topo) if lvs is None else lvs
    lv = lvs[0]
    zero = np.zeros(lv.n)
    rx, ry = np.zeros(lv.n), np.zeros(lv.n)
    r = _full_defect(lvs, x, y, rx, ry)
    history = [(0, r)]
    best, saved = r, (x.copy(), y.copy())
    cells = topo.node_map.cells
    acc = _accel.Mixer([x, y], lambda a: _accel.folded_cells(a[0], a[1], cells), ACCEL_DEPTH) if ACCEL else None
    last_run["accel"] = acc
    for it in range(1, max_cycles + 1):
        if r <= tol:
            return it - 1, r, history, "", len(lvs)
        if it == 1 and FMG_START:
            _fmg(lvs, x, y, line_omega, should_stop)
            if should_stop is not None and should_stop():
                r = _full_defect(lvs, x, y, rx, ry)
                history.append((it, r))
                return it, r, history, "stopped", len(lvs)
        else:
            if acc is not None:
                acc.before(history)
            _cycle(lvs, 0, x, y, zero, zero, line_omega)
        r = _full_defect(lvs, x, y, rx, ry)
        if HOT_SWEEPS and tol < r < math.inf:
            swept = _hot_sweeps(lv, x, y, rx, ry)
            r = _defect_after(lv, x, y, zero, rx, ry, swept[0])
        if acc is not None and acc.after(functools.partial(float, r) if ACCEL_PLAIN_REF else None, tol):
            r_mixed = _full_defect(lvs, x, y, rx, ry)
            if acc.keep(r_mixed):
                r = r_mixed
            elif not ACCEL_PLAIN_REF:
                r = _full_defect(lvs, x, y, rx, ry)
        history.append((it, r))
        if (yield it, r) == "stop":
            return it, r, history, "stopped", len(lvs)
        if not math.isfinite(r) or r > 1e3 * best:
            x[...] = saved[0]
            y[...] = saved[1]
            return it, history[0][1], history, "diverged", len(lvs)
        if r < best:
            best = r
            saved = (x.copy(), y.copy())
        if give_up_rate is not None and it >= 3 and r > tol:
            rate = math.sqrt(r / history[-3][1]) if history[-3][1] > 0 else 0.0
            if rate > give_up_rate:
                return it, r, history, "slow", len(lvs)
    return max_cycles, r, history, "", len(lvs)
