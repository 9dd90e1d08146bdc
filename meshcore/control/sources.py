"""The source-term updater: :class:`ControlSources` and :func:`make_sources` (see :mod:`meshcore.control`)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import InvalidInputError
from .geometry import (
    _FRAME,
    _border_rows,
    _corner_angle,
    _d_xi,
    _Polyline,
    _rot,
    _set_border,
    _tangent,
    scale_factors,
)
from .spec import BorderControl, ControlSpec, control_from_mapping

__all__ = ["ControlSources", "make_sources"]


@dataclass
class _BorderState:
    name: str
    spec: BorderControl
    idx: np.ndarray  # controlled node indices along the border
    s_t: np.ndarray  # normalised tangential source at the border nodes (full length)
    s_n: np.ndarray
    spacing_eff: np.ndarray
    angle_eff: np.ndarray  # radians
    weight: np.ndarray  # decay field (full node shape)
    ss_t: np.ndarray = field(init=False)  # Steger–Sorenson part
    ss_n: np.ndarray = field(init=False)
    hw_t: np.ndarray = field(init=False)  # Hilgenstock–White integrators
    hw_n: np.ndarray = field(init=False)
    gain: np.ndarray = field(init=False)  # adaptive gain multipliers (height, angle) and last error signs
    sign: np.ndarray = field(init=False)
    unclipped: bool = field(init=False, default=False)  # the last feedback step clipped nothing

    def __post_init__(self) -> None:
        n = len(self.s_t)
        self.ss_t, self.ss_n, self.hw_t, self.hw_n = (np.zeros(n) for _ in range(4))
        self.gain = np.ones((2, n))
        self.sign = np.zeros((2, n))


class ControlSources:
    """Source-term updater for :func:`meshcore.elliptic.iterate` (``sources=``).

    Parameters
    ----------
    spec : ControlSpec
        What to control.
    periodic : bool
        Whether ξ is periodic (O-grid); must match the grid.
    curves : mapping of border name to (k, 2) points, optional
        Curves that floating nodes slide on; default: the start grid's border
        nodes as a polyline (for periodic bottom/top, closed).

    Attributes
    ----------
    history : list of (iteration, change)
        Largest change of the normalised sources per update.
    metric_scaled : bool
        True: ``P, Q`` are written as ``(α/D², γ/D²)`` times normalised sources, so a
        solver may re-apply them with the current metric between updates (the
        multigrid does, see :mod:`meshcore.elliptic._mg_control`).
    wake_by_solver : bool
        Set by a solver that relaxes the C-grid wake-cut nodes as unknowns (the
        multigrid): the updater then leaves them alone.
    """

    def __init__(self, spec: ControlSpec, *, periodic: bool = False, curves: Mapping[str, Any] | None = None):
        if not isinstance(spec, ControlSpec):
            raise InvalidInputError(f"spec must be a ControlSpec, got {type(spec).__name__}")
        if periodic:
            for b in ("left", "right"):
                if b in spec.borders or b in spec.floating:
                    raise InvalidInputError(f"control on the {b} border of a periodic grid: the seam is not a boundary")
        self.spec = spec
        self.periodic = bool(periodic)
        self.curves_in = dict(curves or {})
        self.history: list[tuple[int, float]] = []
        self._change = math.inf
        self._moved = math.inf if spec.floating else 0.0
        self._wake_move = math.inf
        self._initialized = False
        #: Set by a solver that relaxes the wake-cut nodes itself (the multigrid, see
        #: :mod:`meshcore.elliptic._mg_wake`): :meth:`update` then leaves them alone.
        self.wake_by_solver = False
        #: Set by a solver that converges the grid between updates (the multigrid): the
        #: feedback gain then adapts per node while the last update clipped no error
        #: (see :func:`_adapt`).
        self.adaptive_gain = False
        self._unclipped = False
        #: Whether an update since :meth:`initialize` adapted the gains (a solver whose try
        #: failed starts over with fixed gains only then).
        self.gains_adapted = False

    # -- protocol ---------------------------------------------------------
    def initialize(self, x: np.ndarray, y: np.ndarray, p: np.ndarray, q: np.ndarray) -> None:
        """Precompute fixed fields (attraction, Thomas–Middlecoff, decays, curves)."""
        from ..elliptic.solver import default_tolerance

        ni1, nj1 = x.shape
        if p.shape != x.shape:
            raise InvalidInputError("ControlSources needs full P, Q arrays of the grid shape")
        ni, nj = ni1 - 1, nj1 - 1
        sp = self.spec
        if sp.wake and not (0 < sp.wake < ni // 2):
            raise InvalidInputError(f"control wake={sp.wake} must be in 1 … {ni // 2 - 1} for ni={ni}")
        for name in sp.borders:
            if (name in ("bottom", "top") and nj < 3) or (name in ("left", "right") and ni < 3):
                raise InvalidInputError(f"boundary control on the {name} border needs ≥ 3 cells across it")
        self.shape = x.shape
        self._wake_tol = default_tolerance(x.shape)  # the solver's default stopping rule
        self.L = float(math.hypot(np.ptp(x), np.ptp(y))) or 1.0
        I, J = np.meshgrid(np.arange(ni1, dtype=float), np.arange(nj1, dtype=float), indexing="ij")
        self._I, self._J = I, J
        # user P, Q given to iterate(p=, q=) stay as a fixed physical part
        self.p0 = p.copy()
        self.q0 = q.copy()
        self._fixed_p, self._fixed_q = _attraction(sp.attractors, I, J)
        self._seam_psi = None
        if self.periodic and sp.thomas_middlecoff:
            self._seam_psi = self._psi(np.column_stack([x[0], y[0]]))
        self._tm_p = self._tm_q = None
        self._bstate = {name: self._border_state(name, bc, x, y) for name, bc in sp.borders.items()}
        self._curves: dict[str, _Polyline] = {}
        self._fl_s: dict[str, np.ndarray] = {}
        for name in sp.floating:
            self._curves[name], self._fl_s[name] = self._floating_curve(name, x, y)
        self._initialized = True
        self._unclipped = False
        self.gains_adapted = False
        self._recompute_tm(x, y)
        self._write(x, y, p, q)

    def _border_state(self, name: str, bc: BorderControl, x: np.ndarray, y: np.ndarray) -> _BorderState:
        """The boundary-control state of one border: controlled nodes, targets, decay field."""
        ni, nj = x.shape[0] - 1, x.shape[1] - 1
        _sigma, rho, along = _FRAME[name]
        r0, r1, _ = _border_rows(x, y, name)
        n = len(r0)
        per = self.periodic and along == "xi"
        if bc.start is not None or bc.stop is not None:
            lo = 1 if bc.start is None else int(bc.start)
            hi = n - 1 if bc.stop is None else int(bc.stop)
            if not (0 <= lo < hi <= n):
                raise InvalidInputError(f"{name} border control: bad node range {lo}…{hi} (border has {n} nodes)")
            idx = np.arange(lo, hi)
        else:
            idx = np.arange(0, n - 1) if per else np.arange(1, n - 1)
        s1 = np.hypot(*(r1 - r0).T)
        rt, _ = _tangent(r0, per)
        d = r1 - r0
        ang1 = np.arctan2(rho * (rt[:, 0] * d[:, 1] - rt[:, 1] * d[:, 0]), (rt * d).sum(axis=1))
        s_eff = np.full(n, bc.spacing) if bc.spacing is not None else s1
        a_eff = np.full(n, math.radians(bc.angle)) if bc.angle is not None else ang1
        if bc.corner_blend and bc.angle is not None and not per:
            a_eff = _blend_corners(a_eff.astype(float), bc.corner_blend, x, y, name)
        dist = {"bottom": self._J, "top": nj - self._J, "left": self._I, "right": ni - self._I}[name]
        return _BorderState(
            name=name,
            spec=bc,
            idx=idx,
            s_t=np.zeros(n),
            s_n=np.zeros(n),
            spacing_eff=s_eff.astype(float),
            angle_eff=a_eff.astype(float),
            weight=np.exp(-bc.decay * dist),
        )

    def _floating_curve(self, name: str, x: np.ndarray, y: np.ndarray) -> tuple[_Polyline, np.ndarray]:
        """The curve a floating border slides on and its nodes' arc-length parameters."""
        closed = self.periodic and name in ("bottom", "top")
        r0 = _border_rows(x, y, name)[0]
        pts = self.curves_in.get(name)
        pts = r0[:-1] if (pts is None and closed) else (r0 if pts is None else np.asarray(pts, float))
        c = _Polyline(pts, closed)
        s = c.locate(r0)
        if closed:
            s = np.unwrap(s, period=c.length)
        if s[-1] < s[0]:  # the curve runs against the border: reverse it
            c = _Polyline(np.asarray(pts)[::-1], closed)
            s = c.locate(r0)
            if closed:
                s = np.unwrap(s, period=c.length)
        return c, s

    @property
    def metric_scaled(self) -> bool:
        return True

    @property
    def wake(self) -> int:
        """Cells of the C-grid wake cut (0: none)."""
        return self.spec.wake

    def wants_update(self, it: int) -> bool:
        return it % self.spec.every == 0 or (bool(self.spec.wake) and not self.wake_by_solver)

    def update(self, x: np.ndarray, y: np.ndarray, p: np.ndarray, q: np.ndarray, it: int) -> None:
        """Advance the controls one step and rewrite ``p, q`` (and floating/wake nodes)."""
        sp = self.spec
        if sp.wake and not self.wake_by_solver:
            self._wake_move = self._wake_step(x, y) / self.L
            if it % sp.every:
                return
        moved = self._moved
        if sp.floating and it % sp.float_every == 0:
            moved = self._moved = self._float_step(x, y)
            self._recompute_tm(x, y)
        change = 0.0
        for bs in self._bstate.values():
            change = max(change, self._border_step(bs, x, y))
        self._unclipped = all(bs.unclipped for bs in self._bstate.values())
        self._change = max(change, moved)
        self.history.append((it, self._change))
        self._write(x, y, p, q)

    def settled(self, tol: float = 1e-4) -> bool:
        """True when the last update changed the sources (and nodes) by less than ``tol``."""
        if self.spec.wake and not self.wake_by_solver and self._wake_move > self._wake_tol:
            return False  # the cut nodes are not in the solver's residual
        if not (self._bstate or self.spec.floating):
            return True
        return self._change <= tol

    # -- pieces -------------------------------------------------------------
    def _psi(self, r: np.ndarray) -> np.ndarray:
        rt, rtt = _tangent(r, False)
        return -(rt * rtt).sum(axis=1) / np.maximum((rt * rt).sum(axis=1), 1e-300)

    def _recompute_tm(self, x, y):
        if not self.spec.thomas_middlecoff:
            return
        ni1, nj1 = x.shape
        J, I = self._J / (nj1 - 1), self._I / (ni1 - 1)
        phi_b = self._psi_periodic(np.column_stack([x[:, 0], y[:, 0]]))
        phi_t = self._psi_periodic(np.column_stack([x[:, -1], y[:, -1]]))
        self._tm_p = (1 - J) * phi_b[:, None] + J * phi_t[:, None]
        if self.periodic:
            self._tm_q = np.broadcast_to(self._seam_psi[None, :], x.shape).copy()
        else:
            psi_l = self._psi(np.column_stack([x[0], y[0]]))
            psi_r = self._psi(np.column_stack([x[-1], y[-1]]))
            self._tm_q = (1 - I) * psi_l[None, :] + I * psi_r[None, :]

    def _psi_periodic(self, r):
        rt, rtt = _tangent(r, self.periodic)
        return -(rt * rtt).sum(axis=1) / np.maximum((rt * rt).sum(axis=1), 1e-300)

    def _border_step(self, bs: _BorderState, x, y) -> float:
        sp = self.spec
        _sigma, rho, along = _FRAME[bs.name]
        per = self.periodic and along == "xi"
        r0, r1, r2 = _border_rows(x, y, bs.name)
        rt, rtt = _tangent(r0, per)
        k = bs.idx
        # measured first cell
        d = r1 - r0
        s1 = np.hypot(d[:, 0], d[:, 1])
        ang1 = np.arctan2(rho * (rt[:, 0] * d[:, 1] - rt[:, 1] * d[:, 0]), (rt * d).sum(axis=1))
        lt = np.hypot(rt[:, 0], rt[:, 1])
        req_s = bs.spec.spacing
        if req_s is None:
            bs.spacing_eff[k] = s1[k]
        if bs.spec.angle is None:
            bs.angle_eff[k] = ang1[k]
            req_a = None
        else:
            req_a = bs.angle_eff[k]
        old_t, old_n = bs.s_t[k].copy(), bs.s_n[k].copy()
        lim = sp.limit
        w = sp.relaxation
        if sp.kind == "steger-sorenson":
            _steger_sorenson(bs, (r0, r1, r2), rt, rtt, lt, per, w, lim)
            g = sp.feedback * w
        else:
            g = w
        if g > 0:  # Hilgenstock–White: integral feedback on the measured first cell
            adaptive = self.adaptive_gain and self._unclipped
            self.gains_adapted |= adaptive
            _feedback(bs, s1[k], ang1[k], lt[k], req_a, g, lim, adaptive)
        if not per and len(bs.hw_n) > 5:
            # Next to a corner of angle θc ≠ 90° the first cell cannot be both
            # orthogonal to the two walls and of the requested height (h = d·tan(θc/2)
            # for a corner distance d): the angle wins, the spacing source there
            # follows its neighbour.
            if 1 in k:
                bs.hw_n[1] = bs.hw_n[2]
            if len(bs.hw_n) - 2 in k:
                bs.hw_n[-2] = bs.hw_n[-3]
        bs.s_t[k] = np.clip(bs.ss_t[k] + bs.hw_t[k], -lim, lim)
        bs.s_n[k] = np.clip(bs.ss_n[k] + bs.hw_n[k], -lim, lim)
        return float(
            max(
                np.max(np.abs(bs.s_t[k] - old_t), initial=0.0),
                np.max(np.abs(bs.s_n[k] - old_n), initial=0.0),
            )
        )

    def _write(self, x, y, p, q) -> None:
        """p, q ← user part + (α/D², γ/D²) · (normalised sources)."""
        ph = self._fixed_p.copy()
        qh = self._fixed_q.copy()
        if self._tm_p is not None:
            ph += self._tm_p
            qh += self._tm_q
        for bs in self._bstate.values():
            along = _FRAME[bs.name][2]
            if along == "xi":
                st, sn = bs.s_t[:, None], bs.s_n[:, None]
                ph += st * bs.weight
                qh += sn * bs.weight
            else:
                st, sn = bs.s_t[None, :], bs.s_n[None, :]
                qh += st * bs.weight
                ph += sn * bs.weight
        fa, fg = scale_factors(x, y, self.periodic)
        with np.errstate(all="ignore"):
            pp = self.p0 + fa * ph
            qq = self.q0 + fg * qh
        if not (np.isfinite(pp).all() and np.isfinite(qq).all()):
            # a degenerate cell (D = 0): drop the control there rather than poison the sweep
            pp = np.where(np.isfinite(pp), pp, 0.0)
            qq = np.where(np.isfinite(qq), qq, 0.0)
        p[...] = pp
        q[...] = qq

    def _float_step(self, x, y) -> float:
        moved = 0.0
        w = self.spec.float_relaxation
        for name, c in self._curves.items():
            r0, r1, _ = _border_rows(x, y, name)
            s = self._fl_s[name]
            closed = c.closed
            n = len(s)
            if closed:
                ks = np.arange(0, n - 1)
                sl = np.concatenate([[s[-2] - c.length], s[:-1]])[ks]
                sr = s[1:][ks]
            else:
                ks = np.arange(1, n - 1)
                sl, sr = s[ks - 1], s[ks + 1]
            lo = s[ks] + 0.6 * (sl - s[ks])
            hi = s[ks] + 0.6 * (sr - s[ks])
            tgt = c.project(r1[ks], lo, hi)
            new = s[ks] + w * (tgt - s[ks])
            new = np.clip(new, lo, hi)
            pts = c.at(new)
            moved = max(moved, float(np.max(np.hypot(*(pts - r0[ks]).T), initial=0.0)) / self.L)
            s[ks] = new
            if closed:
                s[-1] = s[0] + c.length
            _set_border(x, y, name, ks, pts)
            if closed:
                x[-1, :] = x[0, :]
                y[-1, :] = y[0, :]
        return moved * 100.0  # relative to 1 % of the size per update

    def _wake_step(self, x, y) -> float:
        """Jacobi update of the C-grid wake-cut nodes with mirrored η neighbours."""
        ni = x.shape[0] - 1
        n = self.spec.wake
        i = np.arange(1, n)
        m = ni - i
        X = [x, y]
        new = []
        xe_ = [a[i + 1, 0] for a in X]
        xw_ = [a[i - 1, 0] for a in X]
        xn_ = [a[i, 1] for a in X]
        xs_ = [a[m, 1] for a in X]
        xxi = [0.5 * (e - w) for e, w in zip(xe_, xw_, strict=True)]
        xet = [0.5 * (nn - s) for nn, s in zip(xn_, xs_, strict=True)]
        a = xet[0] ** 2 + xet[1] ** 2
        b = xxi[0] * xet[0] + xxi[1] * xet[1]
        g = xxi[0] ** 2 + xxi[1] ** 2
        den = 2 * (a + g)
        for c, arr in enumerate(X):
            ne, nw = arr[i + 1, 1], arr[i - 1, 1]
            se, sw = arr[m - 1, 1], arr[m + 1, 1]
            cross = ne - nw - se + sw
            new.append((a * (xe_[c] + xw_[c]) + g * (xn_[c] + xs_[c]) - 0.5 * b * cross) / den)
        move = float(np.max(np.hypot(new[0] - x[i, 0], new[1] - y[i, 0]), initial=0.0))
        w = 1.5  # over-relaxed like the SOR interior (the cut is a line of nodes)
        for c, arr in enumerate(X):
            v = arr[i, 0] + w * (new[c] - arr[i, 0])
            arr[i, 0] = v
            arr[m, 0] = v
        return move


def _steger_sorenson(bs: _BorderState, rows: tuple, rt, rtt, lt, per: bool, w: float, lim: float) -> None:
    """Relax the Steger–Sorenson part of the border sources towards its Taylor targets."""
    sigma, rho, _along = _FRAME[bs.name]
    r0, r1, r2 = rows
    k = bs.idx
    S = bs.spacing_eff
    tx, ty = rt[:, 0] / np.maximum(lt, 1e-300), rt[:, 1] / np.maximum(lt, 1e-300)
    nx, ny = _rot(tx, ty, rho * bs.angle_eff)
    rn = sigma * S[:, None] * np.column_stack([nx, ny])
    rtn = np.column_stack([_d_xi(rn[:, 0], per), _d_xi(rn[:, 1], per)])
    rnn = 0.5 * (-7 * r0 + 8 * r1 - r2) - 3 * sigma * rn
    A = (rn * rn).sum(axis=1)
    B = (rt * rn).sum(axis=1)
    C = (rt * rt).sum(axis=1)
    R = A[:, None] * rtt - 2 * B[:, None] * rtn + C[:, None] * rnn
    det = rt[:, 0] * rn[:, 1] - rn[:, 0] * rt[:, 1]
    det = np.where(np.abs(det) > 0, det, 1e-300)
    # [rt rn] [A s_t; C s_n] = −R
    as_t = -(rn[:, 1] * R[:, 0] - rn[:, 0] * R[:, 1]) / det
    cs_n = -(rt[:, 0] * R[:, 1] - rt[:, 1] * R[:, 0]) / det
    tgt_t = np.nan_to_num(as_t / np.maximum(A, 1e-300))
    tgt_n = np.nan_to_num(cs_n / np.maximum(C, 1e-300))
    if not per:
        # next to a corner the Taylor targets see both walls: leave those
        # nodes to the feedback part
        tgt_t[[1, -2]] = 0.0
        tgt_n[[1, -2]] = 0.0
    bs.ss_t[k] += w * (np.clip(tgt_t[k], -lim, lim) - bs.ss_t[k])
    bs.ss_n[k] += w * (np.clip(tgt_n[k], -lim, lim) - bs.ss_n[k])


#: Adaptive feedback gain: ×GAIN_UP per update while a node's error keeps its sign,
#: ×GAIN_DOWN (not below 1) when it flips, at most GAIN_MAX.
GAIN_UP, GAIN_DOWN, GAIN_MAX = 1.25, 0.5, 8.0


def _adapt(bs: _BorderState, row: int, e: np.ndarray) -> np.ndarray:
    """``e`` times the adaptive gain of its nodes (updated from the sign of ``e``).

    With a solver that converges the grid between updates (the multigrid) the
    first cell responds to the sources at once: an integral feedback then
    creeps towards the request at a rate set by the gain (measured on the NACA
    O-grid: 0.98 per update in the tail, 275 updates; on the C-grid 0.963, 190).
    A node whose error keeps its sign gets a larger gain, one that overshoots a
    smaller one (the rule of resilient back-propagation): same fixed point, fewer
    updates.

    The gains adapt only while the previous update clipped nothing
    (``_BorderState.unclipped``, see :func:`_feedback`).  At the start the first
    cells miss the request many times over (NACA O-grid trailing edge: e⁴), the
    errors are clipped and the sources ramp at the clip rate; a gain grown there
    multiplies steps the grid cannot follow (adapting from the first update made
    the O-grid multigrid blow up after 14 updates).  Once the errors are within
    the clip bounds the map is smooth and the adapted steps are safe; that gate
    replaced "the cycle left the grid converged" (``r ≤ tol``, which holds only
    once the sources have almost stopped moving).  Measured (1 thread): NACA O-grid
    117 → 93 cycles, C-grid 190 → 69, the ellipse O-grids 41 → 24 and 55 → 40, 16
    generated smooth bodies (64 × 24) 57–73 → 21–35 cycles with fixed gains → adaptive,
    but one of them (seed 7 of the test) fell into a limit cycle at the trailing nodes
    (neighbours with grown gains drive a node whose error flips sign) and diverged after
    242 cycles: a multigrid try whose gains adapted and that fails starts over with fixed
    gains (:func:`meshcore.elliptic.multigrid._fas`), 73 cycles there.
    """
    k = bs.idx
    sg = np.sign(e)
    prod = sg * bs.sign[row, k]
    gk = bs.gain[row, k]
    gk = np.where(prod > 0, np.minimum(gk * GAIN_UP, GAIN_MAX), gk)
    gk = np.where(prod < 0, np.maximum(gk * GAIN_DOWN, 1.0), gk)
    bs.gain[row, k] = gk
    bs.sign[row, k] = sg
    return e * gk


#: The feedback integrates the log first-cell height error and the angle error (radians)
#: clipped to these bounds: one update moves a source by at most gain × bound.
ERR_CLIP_HEIGHT, ERR_CLIP_ANGLE = 1.0, 0.5


def _feedback(bs: _BorderState, s1, ang1, lt, req_a, g: float, lim: float, adaptive: bool = False) -> None:
    """Hilgenstock–White: integrate the error of the measured first cell (height, angle) at the controlled
    nodes (with per-node adaptive gains if ``adaptive``, see :func:`_adapt`).

    Sets ``bs.unclipped``: no error was clipped and no integrator sits at ``±lim``.
    """
    sigma, rho, along = _FRAME[bs.name]
    k = bs.idx
    req_s = bs.spec.spacing
    e = np.log(np.maximum(s1, 1e-300) / req_s) if req_s is not None else np.zeros(0)
    err = np.angle(np.exp(1j * (req_a - ang1))) if req_a is not None else np.zeros(0)
    unclipped = bool(np.all(np.abs(e) < ERR_CLIP_HEIGHT) and np.all(np.abs(err) < ERR_CLIP_ANGLE))
    if req_s is not None:
        e = np.clip(e, -ERR_CLIP_HEIGHT, ERR_CLIP_HEIGHT)
        bs.hw_n[k] -= sigma * g * (_adapt(bs, 0, e) if adaptive else e)
    if req_a is not None:
        ar = np.minimum(lt / np.maximum(s1, 1e-300), 50.0)
        err = np.clip(err, -ERR_CLIP_ANGLE, ERR_CLIP_ANGLE)
        sgn = -rho * sigma * (1 if along == "xi" else -1)
        bs.hw_t[k] += sgn * g * 2.0 * ar * (_adapt(bs, 1, err) if adaptive else err)
    unclipped &= bool(np.all(np.abs(bs.hw_t[k]) < lim) and np.all(np.abs(bs.hw_n[k]) < lim))
    bs.hw_t[k] = np.clip(bs.hw_t[k], -lim, lim)
    bs.hw_n[k] = np.clip(bs.hw_n[k], -lim, lim)
    bs.unclipped = unclipped


def _attraction(attractors: tuple, I: np.ndarray, J: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The fixed normalised sources of Thompson attraction (index units)."""
    ni, nj = I.shape[0] - 1, I.shape[1] - 1
    ph = np.zeros(I.shape)
    qh = np.zeros(I.shape)
    for a in attractors:
        if a.kind in ("xi", "point"):
            xl = a.xi * ni
        if a.kind in ("eta", "point"):
            el = a.eta * nj
        if a.kind == "xi":
            dx = I - xl
            ph -= a.amplitude * np.sign(dx) * np.exp(-a.decay * np.abs(dx))
        elif a.kind == "eta":
            de = J - el
            qh -= a.amplitude * np.sign(de) * np.exp(-a.decay * np.abs(de))
        else:
            dx, de = I - xl, J - el
            w = a.amplitude * np.exp(-a.decay * np.hypot(dx, de))
            ph -= np.sign(dx) * w
            qh -= np.sign(de) * w
    return ph, qh


def _blend_corners(a_eff: np.ndarray, blend: int, x: np.ndarray, y: np.ndarray, name: str) -> np.ndarray:
    """Requested angles blended towards each corner's own angle over ``blend`` nodes."""
    n = len(a_eff)
    for end, step in ((0, 1), (n - 1, -1)):
        th_c = _corner_angle(x, y, name, end)
        if end:  # measured from the increasing-index direction, which points into it
            th_c = math.pi - th_c
        for kk in range(1, min(blend, n // 2)):
            f = kk / blend
            a_eff[end + step * kk] = th_c + (a_eff[end + step * kk] - th_c) * f
    return a_eff


def make_sources(
    control: ControlSpec | Mapping[str, Any], *, periodic: bool = False, curves: Mapping[str, Any] | None = None
) -> ControlSources | None:
    """A :class:`ControlSources` for ``control`` (a spec or a case-file table); None if inactive."""
    spec = control if isinstance(control, ControlSpec) else control_from_mapping(control)
    if not spec.active:
        return None
    return ControlSources(spec, periodic=periodic, curves=curves)
