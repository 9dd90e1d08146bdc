"""What grid control is wanted: :class:`ControlSpec` and its parts (frozen, validated)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from .._tables import from_table
from ..errors import InvalidInputError
from ..grid import BORDER_NAMES

__all__ = ["BOUNDARY_KINDS", "Attractor", "BorderControl", "ControlSpec", "control_from_mapping"]

BOUNDARY_KINDS = ("hilgenstock-white", "steger-sorenson")


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


def _coerce(cls: type, value: Any, *, where: str) -> Any:
    """``value`` as a ``cls`` (a dataclass of this module): as it is, or from a table."""
    if isinstance(value, cls):
        return value
    if isinstance(value, Mapping):
        return from_table(cls, value, where=where)
    raise InvalidInputError(f"{where}: expected a table, got {value!r}")


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
    return from_table(ControlSpec, table, where=where, convert={"borders": _borders, "attractors": _attractors})


def _borders(value: Any, where: str) -> Any:
    if not isinstance(value, Mapping):
        raise InvalidInputError(f"{where} must be a table of border tables")
    return value


def _attractors(value: Any, where: str) -> tuple:
    if isinstance(value, Mapping) or not isinstance(value, (list, tuple)):
        raise InvalidInputError(f"{where} must be a list of attractor tables")
    return tuple(value)
