r"""Grid control: source terms P, Q and floating boundary nodes.

The elliptic solver iterates (see :mod:`meshcore.elliptic._kernels`)

.. math::

    α x_{ξξ} − 2β x_{ξη} + γ x_{ηη} + D^2 (P x_ξ + Q x_η) = 0
    \quad(\text{same for } y),\qquad D = x_ξ y_η − x_η y_ξ .

Every control here is first expressed in the **normalised** (Thomas–Middlecoff)
form

.. math::

    α (x_{ξξ} + \hat P x_ξ) − 2β x_{ξη} + γ (x_{ηη} + \hat Q x_η) = 0,

in which :math:`\hat P = −∂_ξ \ln |r_ξ|` is simply the log-rate at which the
ξ spacing shrinks per cell (scale invariant, dimensionless, index units).  The
kernel's sources follow as :math:`P = α \hat P / D^2`, :math:`Q = γ \hat Q / D^2`
with the metrics of the current iterate; :class:`ControlSources` recomputes them
every ``every`` sweeps (the metrics are lagged like α, β, γ in the sweep).

Components (all optional, summed):

* **Thomas–Middlecoff** — :math:`\hat P = φ`, :math:`\hat Q = ψ` with
  :math:`φ = −(r_ξ·r_{ξξ})/|r_ξ|^2` on the bottom and top borders (linearly
  interpolated in η) and :math:`ψ = −(r_η·r_{ηη})/|r_η|^2` on the left and right
  borders (interpolated in ξ): the interior follows the boundary spacing.  For a
  periodic ξ, ψ comes from the seam column of the start grid.
* **Thompson attraction** to ξ lines, η lines and points:
  :math:`\hat P \mathrel{+}= −a\,\mathrm{sgn}(ξ−ξ_l)\,e^{−c|ξ−ξ_l|}` (lines),
  :math:`−b\,\mathrm{sgn}(ξ−ξ_m)\,e^{−d\sqrt{(ξ−ξ_m)^2+(η−η_m)^2}}` (points), and
  the same for :math:`\hat Q` in η; ``a > 0`` attracts, ``a < 0`` repels.
* **Boundary control** (Steger–Sorenson): on a controlled border with tangential
  index *t* and normal index *n* the wanted normal derivative is

  .. math::  σ r_n = S_\text{eff}\; \mathrm{rot}(\hat r_t,\, ρ θ_\text{eff}),

  (σ = +1 when the interior lies at increasing n, ρ = ±1 so that θ is measured
  from the border's increasing-index direction into the interior), the second
  normal derivative is taken one-sided from the current iterate,
  :math:`r_{nn} = (−7r_0 + 8r_1 − r_2)/2 − 3σ r_n`, and the 2×2 system

  .. math::  A(r_{tt} + s_t r_t) − 2B r_{tn} + C(r_{nn} + s_n r_n) = 0,
             \quad A = |r_n|^2,\ B = r_t·r_n,\ C = |r_t|^2

  gives the Steger–Sorenson targets for the border values of the normalised
  sources :math:`(s_t, s_n)`; they are under-relaxed, :math:`s ← s + ω (s^* − s)`,
  clipped to ``limit`` and decay into the interior like :math:`e^{−a\,n}`.  The
  Taylor targets are only accurate to truncation error (on a coarse, strongly
  stretched grid the first cell can miss the request by tens of per cent), so
  an integral **Hilgenstock–White** feedback on the *measured* first cell is
  added, :math:`s_n \mathrel{−}= σ g \ln(s_1/S)`,
  :math:`s_t \mathrel{+}= ∓ g\, 2\,\mathrm{AR}\,(θ − θ_1)` (AR = tangential
  spacing / first-cell height, capped at 50; ``g = feedback · ω``): at the fixed
  point the discrete first-cell height :math:`s_1 = |r_1 − r_0|` and angle θ₁
  equal the request.  ``kind="hilgenstock-white"`` (the default) uses the
  feedback alone (``g = ω``); it is the robust choice at sharp boundary kinks
  and corners of coarse blocks, where the Taylor targets oscillate.
* **Floating boundary nodes**: every ``float_every`` sweeps the non-corner nodes
  of the listed borders slide along the border curve towards the foot of the
  perpendicular from their interior neighbour (relaxed by ``float_relaxation``,
  kept in order), so the grid lines meet the border at right angles without a
  source term; corners stay fixed.
* **C-grid wake cut** (``wake=n``): bottom nodes ``1 … n−1`` coincide with
  ``ni−1 … ni−n+1`` (the cut folds back on itself); they are solved each sweep
  as interior nodes with the mirrored side as their η neighbours (P = Q = 0 on
  the cut).

The updater protocol used by :func:`meshcore.elliptic.iterate`:
``initialize(x, y, p, q)``, ``wants_update(it) -> bool``,
``update(x, y, p, q, it)`` (mutates ``p, q`` and, for floating nodes and the
wake cut, the boundary rows of ``x, y`` in place) and ``settled() -> bool``
(False while the sources are still moving, so the solver does not stop early).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .errors import InvalidInputError
from .grid import BORDER_NAMES, StructuredGrid

__all__ = [
    "BOUNDARY_KINDS",
    "Attractor",
    "BorderControl",
    "ControlSources",
    "ControlSpec",
    "border_angles",
    "boundary_report",
    "control_from_mapping",
    "first_spacing",
    "make_sources",
]

BOUNDARY_KINDS = ("hilgenstock-white", "steger-sorenson")

# border -> (sigma: +1 if the interior is at increasing normal index,
#            rho: rotation sign from the tangent into the interior,
#            along: "xi" if the border runs along ξ)
_FRAME = {
    "bottom": (1, 1, "xi"),
    "top": (-1, -1, "xi"),
    "left": (1, -1, "eta"),
    "right": (-1, 1, "eta"),
}


@dataclass(frozen=True, slots=True)
class Attractor:
    """Thompson attraction to a ξ line, an η line or a point.

    Parameters
    ----------
    kind : {"xi", "eta", "point"}
        ``"xi"``: attract ξ = const lines towards ``xi``; ``"eta"``: η lines
        towards ``eta``; ``"point"``: both families towards ``(xi, eta)``.
    xi, eta : float
        Position as a fraction of the index range, in [0, 1].
    amplitude : float
        ``a`` in the normalised source (log spacing change per cell at the
        attractor); negative repels.
    decay : float
        ``c`` in ``exp(−c·distance)``, distance in cells.
    """

    kind: str
    xi: float | None = None
    eta: float | None = None
    amplitude: float = 0.2
    decay: float = 0.3

    def __post_init__(self) -> None:
        if self.kind not in ("xi", "eta", "point"):
            raise InvalidInputError(f"attractor kind must be 'xi', 'eta' or 'point', got {self.kind!r}")
        need = {"xi": ("xi",), "eta": ("eta",), "point": ("xi", "eta")}[self.kind]
        for nm in need:
            v = getattr(self, nm)
            if v is None or not (0.0 <= float(v) <= 1.0):
                raise InvalidInputError(f"{self.kind} attractor: {nm} must be a fraction in [0, 1], got {v!r}")
        if not math.isfinite(self.amplitude):
            raise InvalidInputError(f"attractor amplitude must be finite, got {self.amplitude!r}")
        if not (self.decay > 0 and math.isfinite(self.decay)):
            raise InvalidInputError(f"attractor decay must be > 0, got {self.decay!r}")


@dataclass(frozen=True, slots=True)
class BorderControl:
    """Boundary control wanted on one border.

    Parameters
    ----------
    spacing : float, optional
        First-cell height ``|r_1 − r_0|`` in model units; ``None`` keeps the
        current one (only the angle is controlled).
    angle : float, optional
        Angle in degrees between the border (increasing index) and the grid
        lines leaving it; 90 = orthogonal.  ``None`` = only spacing.
    decay : float
        Decay rate ``a`` of the sources away from the border (per cell).
    start, stop : int, optional
        Controlled node range along the border (default: all but the corners),
        e.g. the airfoil part of a C-grid's bottom border.
    corner_blend : int
        Over this many nodes next to each corner, blend the requested angle
        linearly towards the corner's own angle θc (node k ≥ 1 from the corner
        aims at ``θc + (θ − θc)·min(1, k/corner_blend)``); for blocks whose
        corners sit on a smooth shore (θc ≈ 180°), where orthogonality to both
        borders next to the corner is impossible.  0 = off.
    """

    spacing: float | None = None
    angle: float | None = 90.0
    decay: float = 0.5
    start: int | None = None
    stop: int | None = None
    corner_blend: int = 0

    def __post_init__(self) -> None:
        if not (isinstance(self.corner_blend, int) and self.corner_blend >= 0):
            raise InvalidInputError(f"corner_blend must be an integer ≥ 0, got {self.corner_blend!r}")
        if self.spacing is not None and not (self.spacing > 0 and math.isfinite(self.spacing)):
            raise InvalidInputError(f"spacing must be > 0, got {self.spacing!r}")
        if self.angle is not None and not (0.0 < self.angle < 180.0):
            raise InvalidInputError(f"angle must be in (0, 180) degrees, got {self.angle!r}")
        if not (self.decay > 0 and math.isfinite(self.decay)):
            raise InvalidInputError(f"decay must be > 0, got {self.decay!r}")


@dataclass(frozen=True, slots=True)
class ControlSpec:
    """Everything that controls one block's grid (see module docstring).

    Parameters
    ----------
    kind : {"hilgenstock-white", "steger-sorenson"}
        Boundary-control method for ``borders`` (see module docstring).
    borders : mapping of border name to BorderControl (or dict)
        Controlled borders.
    thomas_middlecoff : bool
        Add the Thomas–Middlecoff sources (interior follows boundary spacing).
    attractors : sequence of Attractor (or dict)
        Thompson attraction terms.
    relaxation : float
        Under-relaxation ω of the boundary sources per update, in (0, 1].
    feedback : float
        Steger–Sorenson only: gain of the added measured-first-cell feedback,
        as a multiple of ``relaxation``; 0 = classic Steger–Sorenson (targets
        met to truncation error only).
    limit : float
        Bound on |normalised source| at a border.
    every : int
        Update the sources every ``every`` sweeps.
    floating : sequence of border names
        Borders whose nodes slide along the border curve (corners fixed).
    float_every : int
        Re-project floating nodes every ``float_every`` sweeps.
    float_relaxation : float
        Fraction of the way to the projection moved per re-projection.
    wake : int
        C-grid: number of cells of the wake cut on each side (0 = none).
    """

    kind: str = "hilgenstock-white"
    borders: Mapping[str, BorderControl] = field(default_factory=dict)
    thomas_middlecoff: bool = False
    attractors: tuple[Attractor, ...] = ()
    relaxation: float = 0.1
    feedback: float = 1.0
    limit: float = 20.0
    every: int = 1
    floating: tuple[str, ...] = ()
    float_every: int = 10
    float_relaxation: float = 0.5
    wake: int = 0

    def __post_init__(self) -> None:
        if self.kind not in BOUNDARY_KINDS:
            raise InvalidInputError(f"control kind must be one of {list(BOUNDARY_KINDS)}, got {self.kind!r}")
        b = {}
        for name, v in dict(self.borders).items():
            if name not in BORDER_NAMES:
                raise InvalidInputError(f"control: unknown border {name!r}; valid: {list(BORDER_NAMES)}")
            b[name] = _coerce(BorderControl, v, where=f"control border {name}")
        object.__setattr__(self, "borders", b)
        object.__setattr__(
            self,
            "attractors",
            tuple(_coerce(Attractor, a, where="attractor") for a in self.attractors),
        )
        fl = tuple(self.floating)
        for name in fl:
            if name not in BORDER_NAMES:
                raise InvalidInputError(f"control: unknown floating border {name!r}; valid: {list(BORDER_NAMES)}")
        object.__setattr__(self, "floating", fl)
        if not (0.0 < self.relaxation <= 1.0):
            raise InvalidInputError(f"control relaxation must be in (0, 1], got {self.relaxation!r}")
        if not (0.0 <= self.feedback <= 1.0):
            raise InvalidInputError(f"control feedback must be in [0, 1], got {self.feedback!r}")
        if not (0.0 < self.float_relaxation <= 1.0):
            raise InvalidInputError(f"float_relaxation must be in (0, 1], got {self.float_relaxation!r}")
        if not self.limit > 0:
            raise InvalidInputError(f"control limit must be > 0, got {self.limit!r}")
        for nm in ("every", "float_every"):
            v = getattr(self, nm)
            if not (isinstance(v, int) and v >= 1):
                raise InvalidInputError(f"control {nm} must be an integer ≥ 1, got {v!r}")
        if not (isinstance(self.wake, int) and self.wake >= 0):
            raise InvalidInputError(f"control wake must be an integer ≥ 0, got {self.wake!r}")

    @property
    def active(self) -> bool:
        return bool(self.borders or self.thomas_middlecoff or self.attractors or self.floating or self.wake)


def _coerce(cls, value, *, where):
    if isinstance(value, cls):
        return value
    if isinstance(value, Mapping):
        valid = set(cls.__dataclass_fields__)
        unknown = set(value) - valid
        if unknown:
            raise InvalidInputError(f"{where}: unknown key(s) {sorted(unknown)}; valid: {sorted(valid)}")
        try:
            return cls(**dict(value))
        except InvalidInputError as exc:
            raise InvalidInputError(f"{where}: {exc}") from None
    raise InvalidInputError(f"{where}: expected a table, got {value!r}")


_SPEC_KEYS = (
    "kind",
    "borders",
    "thomas_middlecoff",
    "attractors",
    "relaxation",
    "feedback",
    "limit",
    "every",
    "floating",
    "float_every",
    "float_relaxation",
    "wake",
)


def control_from_mapping(table: Mapping[str, Any], *, where: str = "control") -> ControlSpec:
    """Build a :class:`ControlSpec` from a case-file ``[blocks.control]`` table.

    Keys may use ``-`` or ``_`` (``thomas-middlecoff``); unknown keys raise
    :class:`~meshcore.errors.InvalidInputError` naming the valid ones.

    Examples
    --------
    >>> spec = control_from_mapping({"kind": "steger-sorenson",
    ...     "borders": {"bottom": {"spacing": 0.01, "angle": 90}}, "floating": ["top"]})
    >>> spec.borders["bottom"].spacing, spec.floating
    (0.01, ('top',))
    """
    if not isinstance(table, Mapping):
        raise InvalidInputError(f"{where}: expected a table, got {table!r}")
    kw = {}
    for k, v in table.items():
        key = str(k).replace("-", "_")
        if key not in _SPEC_KEYS:
            raise InvalidInputError(f"{where}: unknown key {k!r}; valid: {sorted(_SPEC_KEYS)}")
        kw[key] = v
    if "borders" in kw and not isinstance(kw["borders"], Mapping):
        raise InvalidInputError(f"{where}: borders must be a table of border tables")
    if "attractors" in kw:
        kw["attractors"] = tuple(kw["attractors"])
    try:
        return ControlSpec(**kw)
    except InvalidInputError as exc:
        raise InvalidInputError(f"{where}: {exc}") from None
    except TypeError as exc:
        raise InvalidInputError(f"{where}: {exc}") from None


# ---------------------------------------------------------------------------
# geometry helpers


def _d_xi(a: np.ndarray, periodic: bool) -> np.ndarray:
    """Central ξ difference on all nodes; one-sided 2nd order at non-periodic ends."""
    d = np.empty_like(a)
    d[1:-1] = 0.5 * (a[2:] - a[:-2])
    if periodic:
        d[0] = 0.5 * (a[1] - a[-2])
        d[-1] = d[0]
    else:
        d[0] = 0.5 * (-3 * a[0] + 4 * a[1] - a[2]) if len(a) > 2 else a[1] - a[0]
        d[-1] = 0.5 * (3 * a[-1] - 4 * a[-2] + a[-3]) if len(a) > 2 else a[-1] - a[-2]
    return d


def _d_eta(a: np.ndarray) -> np.ndarray:
    return _d_xi(a.T, False).T


def _scale_factors(x: np.ndarray, y: np.ndarray, periodic: bool) -> tuple[np.ndarray, np.ndarray]:
    """``α/D²`` and ``γ/D²`` at every node (conversion normalised → kernel sources)."""
    xx, yx = _d_xi(x, periodic), _d_xi(y, periodic)
    xe, ye = _d_eta(x), _d_eta(y)
    a = xe * xe + ye * ye
    g = xx * xx + yx * yx
    d = xx * ye - xe * yx
    with np.errstate(all="ignore"):
        # D² ≥ 10⁻³·αγ (corner angle ≥ ~1.8°): near-degenerate or folded nodes get a
        # bounded source instead of an explosive one
        d2 = np.maximum(d * d, 1e-3 * a * g)
        d2 = np.maximum(d2, 1e-300)
        return a / d2, g / d2


def _rot(vx, vy, ang):
    c, s = np.cos(ang), np.sin(ang)
    return c * vx - s * vy, s * vx + c * vy


def _border_rows(x, y, name):
    """(r0, r1, r2) rows of a border as (k, 2) arrays: the border, 1 and 2 cells in."""
    if name == "bottom":
        rows = (0, 1, 2)
        return [np.column_stack([x[:, j], y[:, j]]) for j in rows]
    if name == "top":
        rows = (-1, -2, -3)
        return [np.column_stack([x[:, j], y[:, j]]) for j in rows]
    if name == "left":
        return [np.column_stack([x[i, :], y[i, :]]) for i in (0, 1, 2)]
    return [np.column_stack([x[i, :], y[i, :]]) for i in (-1, -2, -3)]


def _tangent(r0: np.ndarray, periodic: bool):
    rt = np.column_stack([_d_xi(r0[:, 0], periodic), _d_xi(r0[:, 1], periodic)])
    rtt = np.empty_like(r0)
    rtt[1:-1] = r0[2:] - 2 * r0[1:-1] + r0[:-2]
    if periodic:
        rtt[0] = r0[1] - 2 * r0[0] + r0[-2]
        rtt[-1] = rtt[0]
    else:
        rtt[0] = rtt[1]
        rtt[-1] = rtt[-2]
    return rt, rtt


def border_angles(grid: StructuredGrid, border: str) -> np.ndarray:
    """Angle (degrees) between a border and the grid lines leaving it.

    At each node of ``border`` (corners excluded unless the border is periodic)
    the angle is measured from the border tangent (central difference of the
    border nodes, increasing index) to the first grid segment into the
    interior; 90 means orthogonal.
    """
    per = grid.periodic and border in ("bottom", "top")
    r0, r1, _ = _border_rows(grid.x, grid.y, border)
    rt, _ = _tangent(r0, per)
    d = r1 - r0
    _, rho, _ = _FRAME[border]
    cross = rt[:, 0] * d[:, 1] - rt[:, 1] * d[:, 0]
    dot = (rt * d).sum(axis=1)
    ang = np.degrees(np.arctan2(rho * cross, dot))
    return ang[:-1] if per else ang[1:-1]


def first_spacing(grid: StructuredGrid, border: str) -> np.ndarray:
    """First-cell height ``|r_1 − r_0|`` at the nodes of ``border`` (corners excluded)."""
    per = grid.periodic and border in ("bottom", "top")
    r0, r1, _ = _border_rows(grid.x, grid.y, border)
    s = np.hypot(*(r1 - r0).T)
    return s[:-1] if per else s[1:-1]


def boundary_report(
    grid: StructuredGrid,
    borders: Iterable[str] = BORDER_NAMES,
    spacing: Mapping[str, float] | None = None,
) -> dict[str, float]:
    """Max |angle − 90°| over ``borders`` and max relative spacing error.

    Returns ``{"max_angle_deviation": …, "mean_angle_deviation": …,
    "max_spacing_error": …}`` (spacing error only for borders in ``spacing``).
    """
    devs = []
    errs = []
    for b in borders:
        if grid.periodic and b in ("left", "right"):
            continue
        a = border_angles(grid, b)
        devs.append(np.abs(a - 90.0))
        if spacing and b in spacing and spacing[b] is not None:
            errs.append(np.abs(first_spacing(grid, b) / spacing[b] - 1.0))
    dv = np.concatenate(devs) if devs else np.zeros(1)
    out = {"max_angle_deviation": float(dv.max()), "mean_angle_deviation": float(dv.mean())}
    out["max_spacing_error"] = float(np.concatenate(errs).max()) if errs else float("nan")
    return out


# ---------------------------------------------------------------------------
# the updater


class _Polyline:
    """Arc-length parametrised polyline (optionally closed) with windowed projection."""

    def __init__(self, pts: np.ndarray, closed: bool):
        pts = np.asarray(pts, dtype=np.float64)
        if closed and np.hypot(*(pts[0] - pts[-1])) > 0:
            pts = np.vstack([pts, pts[:1]])
        seg = np.hypot(*np.diff(pts, axis=0).T)
        keep = np.concatenate([[True], seg > 0])
        self.p = pts[keep]
        self.s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(self.p, axis=0).T))])
        self.length = float(self.s[-1])
        self.closed = closed
        if closed:  # three turns, parameters −L … 2L, so windows never wrap
            self.pe = np.vstack([self.p[:-1], self.p[:-1], self.p])
            self.se = np.concatenate([self.s[:-1] - self.length, self.s[:-1], self.s + self.length])
        else:
            self.pe, self.se = self.p, self.s

    def at(self, s: np.ndarray) -> np.ndarray:
        s = np.mod(s, self.length) if self.closed else np.clip(s, 0.0, self.length)
        return np.column_stack([np.interp(s, self.s, self.p[:, 0]), np.interp(s, self.s, self.p[:, 1])])

    def locate(self, q: np.ndarray) -> np.ndarray:
        """Arc-length parameter of the nearest point to each query (global search)."""
        a = self.p[:-1]
        d = np.diff(self.p, axis=0)
        L2 = (d * d).sum(axis=1)
        t = ((q[:, None, :] - a[None]) * d[None]).sum(axis=2) / L2[None]
        t = np.clip(t, 0.0, 1.0)
        foot = a[None] + t[..., None] * d[None]
        dist = ((q[:, None, :] - foot) ** 2).sum(axis=2)
        k = np.argmin(dist, axis=1)
        return self.s[k] + t[np.arange(len(q)), k] * np.sqrt(L2[k])

    def project(self, q: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        """Arc length of the nearest point to ``q[k]`` with parameter in ``[lo[k], hi[k]]``."""
        a = self.pe[:-1]
        d = np.diff(self.pe, axis=0)
        L2 = (d * d).sum(axis=1)
        L = np.sqrt(L2)
        s0 = self.se[:-1]
        t = ((q[:, None, :] - a[None]) * d[None]).sum(axis=2) / L2[None]
        # restrict the foot parameter to the window [lo, hi]
        tlo = (lo[:, None] - s0[None]) / L[None]
        thi = (hi[:, None] - s0[None]) / L[None]
        tmin = np.maximum(tlo, 0.0)
        tmax = np.minimum(thi, 1.0)
        valid = tmin <= tmax
        t = np.clip(t, tmin, np.where(valid, tmax, tmin))
        foot = a[None] + t[..., None] * d[None]
        dist = ((q[:, None, :] - foot) ** 2).sum(axis=2)
        dist = np.where(valid, dist, np.inf)
        k = np.argmin(dist, axis=1)
        return s0[k] + t[np.arange(len(q)), k] * L[k]


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
    ss_t: np.ndarray = None  # Steger–Sorenson part
    ss_n: np.ndarray = None
    hw_t: np.ndarray = None  # Hilgenstock–White integrators
    hw_n: np.ndarray = None

    def __post_init__(self) -> None:
        n = len(self.s_t)
        self.ss_t, self.ss_n, self.hw_t, self.hw_n = (np.zeros(n) for _ in range(4))


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

    # -- protocol ---------------------------------------------------------
    def initialize(self, x: np.ndarray, y: np.ndarray, p: np.ndarray, q: np.ndarray) -> None:
        """Precompute fixed fields (attraction, Thomas–Middlecoff, decays, curves)."""
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
        from .elliptic.solver import default_tolerance

        self._wake_tol = default_tolerance(x.shape)  # the solver's default stopping rule
        self.L = float(math.hypot(np.ptp(x), np.ptp(y))) or 1.0
        I, J = np.meshgrid(np.arange(ni1, dtype=float), np.arange(nj1, dtype=float), indexing="ij")
        self._I, self._J = I, J
        # user P, Q given to iterate(p=, q=) stay as a fixed physical part
        self.p0 = p.copy()
        self.q0 = q.copy()
        # fixed normalised fields: attraction
        ph = np.zeros(x.shape)
        qh = np.zeros(x.shape)
        for a in sp.attractors:
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
        self._fixed_p = ph
        self._fixed_q = qh
        self._seam_psi = None
        if self.periodic and sp.thomas_middlecoff:
            self._seam_psi = self._psi(np.column_stack([x[0], y[0]]))
        self._tm_p = self._tm_q = None
        # boundary control state
        self._bstate: dict[str, _BorderState] = {}
        for name, bc in sp.borders.items():
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
                a_eff = a_eff.astype(float)
                for end, step in ((0, 1), (n - 1, -1)):
                    th_c = _corner_angle(x, y, name, end)
                    if end:  # measured from the increasing-index direction, which points into it
                        th_c = math.pi - th_c
                    for kk in range(1, min(bc.corner_blend, n // 2)):
                        f = kk / bc.corner_blend
                        a_eff[end + step * kk] = th_c + (a_eff[end + step * kk] - th_c) * f
            dist = {"bottom": J, "top": nj - J, "left": I, "right": ni - I}[name]
            self._bstate[name] = _BorderState(
                name=name,
                spec=bc,
                idx=idx,
                s_t=np.zeros(n),
                s_n=np.zeros(n),
                spacing_eff=s_eff.astype(float),
                angle_eff=a_eff.astype(float),
                weight=np.exp(-bc.decay * dist),
            )
        # floating curves
        self._curves: dict[str, _Polyline] = {}
        self._fl_s: dict[str, np.ndarray] = {}
        for name in sp.floating:
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
            self._curves[name] = c
            self._fl_s[name] = s
        self._initialized = True
        self._recompute_tm(x, y)
        self._write(x, y, p, q)

    def wants_update(self, it: int) -> bool:
        return it % self.spec.every == 0 or (bool(self.spec.wake))

    def update(self, x: np.ndarray, y: np.ndarray, p: np.ndarray, q: np.ndarray, it: int) -> None:
        """Advance the controls one step and rewrite ``p, q`` (and floating/wake nodes)."""
        sp = self.spec
        if sp.wake:
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
        self._change = max(change, moved)
        self.history.append((it, self._change))
        self._write(x, y, p, q)

    def settled(self, tol: float = 1e-4) -> bool:
        """True when the last update changed the sources (and nodes) by less than ``tol``."""
        if self.spec.wake and self._wake_move > self._wake_tol:
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
        sigma, rho, along = _FRAME[bs.name]
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
            g = sp.feedback * w
        else:
            g = w
        # Hilgenstock–White: integral feedback on the measured first cell
        if g > 0:
            if req_s is not None:
                e = np.clip(np.log(np.maximum(s1[k], 1e-300) / req_s), -1.0, 1.0)
                bs.hw_n[k] -= sigma * g * e
            if req_a is not None:
                ar = np.minimum(lt[k] / np.maximum(s1[k], 1e-300), 50.0)
                err = np.clip(np.angle(np.exp(1j * (req_a - ang1[k]))), -0.5, 0.5)
                sgn = -rho * sigma * (1 if along == "xi" else -1)
                bs.hw_t[k] += sgn * g * 2.0 * ar * err
            bs.hw_t[k] = np.clip(bs.hw_t[k], -lim, lim)
            bs.hw_n[k] = np.clip(bs.hw_n[k], -lim, lim)
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
        fa, fg = _scale_factors(x, y, self.periodic)
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


def _corner_angle(x, y, name, end) -> float:
    """Interior angle (radians) of the block at the corner where ``name`` has node ``end``."""
    r0 = _border_rows(x, y, name)[0]
    c = r0[end]
    a = r0[1] if end == 0 else r0[-2]
    # the other border leaving the same corner
    ni, nj = x.shape[0] - 1, x.shape[1] - 1
    i, j = {
        ("bottom", 0): (0, 0),
        ("bottom", 1): (ni, 0),
        ("top", 0): (0, nj),
        ("top", 1): (ni, nj),
        ("left", 0): (0, 0),
        ("left", 1): (0, nj),
        ("right", 0): (ni, 0),
        ("right", 1): (ni, nj),
    }[(name, 0 if end == 0 else 1)]
    if name in ("bottom", "top"):
        b = np.array([x[i, 1 if j == 0 else nj - 1], y[i, 1 if j == 0 else nj - 1]])
    else:
        b = np.array([x[1 if i == 0 else ni - 1, j], y[1 if i == 0 else ni - 1, j]])
    u, v = a - c, b - c
    return float(np.arccos(np.clip(np.dot(u, v) / (np.hypot(*u) * np.hypot(*v)), -1.0, 1.0)))


def _set_border(x, y, name, ks, pts):
    if name == "bottom":
        x[ks, 0], y[ks, 0] = pts[:, 0], pts[:, 1]
    elif name == "top":
        x[ks, -1], y[ks, -1] = pts[:, 0], pts[:, 1]
    elif name == "left":
        x[0, ks], y[0, ks] = pts[:, 0], pts[:, 1]
    else:
        x[-1, ks], y[-1, ks] = pts[:, 0], pts[:, 1]


def make_sources(
    control: ControlSpec | Mapping[str, Any], *, periodic: bool = False, curves: Mapping[str, Any] | None = None
) -> ControlSources | None:
    """A :class:`ControlSources` for ``control`` (a spec or a case-file table); None if inactive."""
    spec = control if isinstance(control, ControlSpec) else control_from_mapping(control)
    if not spec.active:
        return None
    return ControlSources(spec, periodic=periodic, curves=curves)
