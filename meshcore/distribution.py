r"""One-dimensional point distributions along a border.

Every function returns ``n + 1`` monotone fractions ``u_0 = 0 < u_1 < … < u_n = 1``
of the arc length (``n`` cells), with exact end points.

* ``uniform`` — equal arc length (the paper).
* ``tanh`` — one-sided clustering at the start (or end) with a prescribed
  first (last) spacing, Vinokur's one-sided stretching
  ``u(ξ) = 1 + tanh(δ(ξ − 1)/2) / tanh(δ/2)``; the spacing is matched exactly
  by solving for δ (bisection on a monotone function).  When the requested
  spacing exceeds the uniform one the ``tan`` branch is used (δ → iδ).
* ``vinokur`` — two-sided clustering with prescribed first *and* last spacing
  (Vinokur 1983, J. Comput. Phys. 50:215): ``A = √(Δs₁/Δs₀)``, ``B = 1/(n√(Δs₀Δs₁))``,
  ``sinh δ / δ = B``, ``v = ½(1 + tanh(δ(ξ − ½))/tanh(δ/2))``,
  ``u = v / (A + (1 − A) v)``; δ and A are then refined by Newton so that both
  end spacings are met to 1e-10 relative.

Spacings passed to :func:`distribute` are fractions of the border length; the
block layer converts absolute lengths (model units) to fractions.
"""

from __future__ import annotations

import math

import numpy as np

from ._validation import validate_choice, validate_count
from .errors import InvalidInputError

__all__ = ["DISTRIBUTIONS", "distribute", "tanh_one_sided", "uniform", "vinokur"]

DISTRIBUTIONS = ("uniform", "tanh", "vinokur")


def uniform(n: int) -> np.ndarray:
    """``n + 1`` equally spaced fractions.

    >>> uniform(4).tolist()
    [0.0, 0.25, 0.5, 0.75, 1.0]
    """
    n = validate_count(n, name="cells")
    return np.linspace(0.0, 1.0, n + 1)


def _one_sided(xi: np.ndarray, d: float) -> np.ndarray:
    """Stretching clustered at ξ = 0 with parameter d (>0 tanh, <0 tan, 0 linear)."""
    if abs(d) < 1e-9:
        return xi.copy()
    if d > 0:
        return 1.0 + np.tanh(0.5 * d * (xi - 1.0)) / math.tanh(0.5 * d)
    a = -d
    return 1.0 + np.tan(0.5 * a * (xi - 1.0)) / math.tan(0.5 * a)


def tanh_one_sided(n: int, first: float, *, at_end: bool = False) -> np.ndarray:
    """One-sided stretching with first spacing ``first`` (fraction of length).

    ``at_end=True`` clusters at ``u = 1`` instead (``first`` is then the last spacing).

    >>> u = tanh_one_sided(10, 0.01)
    >>> round(float(u[1]), 12), float(u[0]), float(u[-1])
    (0.01, 0.0, 1.0)
    """
    n = validate_count(n, name="cells")
    if not (0.0 < first < 1.0):
        raise InvalidInputError(f"first spacing must be a fraction in (0, 1), got {first}")
    if n == 1:
        return np.array([0.0, 1.0])
    xi = np.linspace(0.0, 1.0, n + 1)

    # f(d) = first spacing for parameter d; monotone decreasing in d on (-π, ∞).
    def f(d: float) -> float:
        return float(_one_sided(np.array([1.0 / n]), d)[0])

    target = first
    uniform_sp = 1.0 / n
    if abs(target - uniform_sp) < 1e-14:
        u = xi.copy()
    else:
        if target < uniform_sp:
            lo, hi = 0.0, 1.0
            while f(hi) > target:
                hi *= 2.0
                if hi > 1e4:
                    raise InvalidInputError(f"first spacing {first:g} is too small for {n} cells")
        else:
            # tan branch: spacing grows as a → π; the largest reachable spacing
            lo, hi = -math.pi * (1 - 1e-12), 0.0
            if f(lo) < target:
                raise InvalidInputError(
                    f"first spacing {first:g} of the length is too large for {n} cells (at most {f(lo):.4g})"
                )
        for _ in range(200):
            mid = 0.5 * (lo + hi)
            if f(mid) > target:
                lo = mid
            else:
                hi = mid
            if hi - lo < 1e-15 * max(1.0, abs(hi)):
                break
        u = _one_sided(xi, 0.5 * (lo + hi))
    u[0], u[-1] = 0.0, 1.0
    if at_end:
        u = 1.0 - u[::-1]
    return u


def _vinokur_map(xi: np.ndarray, delta: float, a: float) -> np.ndarray:
    if abs(delta) < 1e-9:
        v = xi.copy()
    elif delta > 0:
        v = 0.5 * (1.0 + np.tanh(delta * (xi - 0.5)) / math.tanh(0.5 * delta))
    else:
        d = -delta
        v = 0.5 * (1.0 + np.tan(d * (xi - 0.5)) / math.tan(0.5 * d))
    return v / (a + (1.0 - a) * v)


def _solve_sinhc(b: float) -> float:
    """Solve sinh(δ)/δ = b (b > 1) or sin(δ)/δ = b (b < 1, returned negative)."""
    if abs(b - 1.0) < 1e-12:
        return 0.0
    if b > 1.0:
        lo, hi = 1e-12, 1.0
        while math.sinh(hi) / hi < b:
            hi *= 2.0
        g = lambda d: math.sinh(d) / d - b  # noqa: E731
    else:
        lo, hi = 1e-12, math.pi * (1 - 1e-12)
        g = lambda d: b - math.sin(d) / d  # noqa: E731
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if g(mid) < 0:
            lo = mid
        else:
            hi = mid
    d = 0.5 * (lo + hi)
    return d if b > 1.0 else -d


def vinokur(n: int, first: float, last: float) -> np.ndarray:
    """Two-sided stretching with first and last spacing (fractions of length).

    >>> u = vinokur(20, 0.01, 0.02)
    >>> round(float(u[1]), 10), round(float(1 - u[-2]), 10)
    (0.01, 0.02)
    """
    n = validate_count(n, name="cells")
    for nm, v in (("first", first), ("last", last)):
        if not (0.0 < v < 1.0):
            raise InvalidInputError(f"{nm} spacing must be a fraction in (0, 1), got {v}")
    if n == 1:
        return np.array([0.0, 1.0])
    if n == 2:
        if abs(first + last - 1.0) > 1e-9:
            raise InvalidInputError(f"with 2 cells first + last spacing must be 1, got {first} + {last}")
        return np.array([0.0, first, 1.0])
    if first + last >= 1.0:
        raise InvalidInputError(f"first + last spacing ({first:g} + {last:g}) must be < 1 of the border length")
    xi = np.linspace(0.0, 1.0, n + 1)
    a0 = math.sqrt(last / first)
    b0 = 1.0 / (n * math.sqrt(first * last))
    delta = _solve_sinhc(b0)
    a = a0

    def resid(d: float, aa: float) -> np.ndarray:
        u = _vinokur_map(np.array([1.0 / n, 1.0 - 1.0 / n]), d, aa)
        if not (np.isfinite(u).all() and u[0] > 0.0 and u[1] < 1.0):
            return np.array([math.inf, math.inf])  # outside the valid parameter range
        return np.array([math.log(u[0] / first), math.log((1.0 - u[1]) / last)])

    # Newton on (δ, log A) with finite-difference Jacobian; the analytic guess is close.
    la = math.log(a)
    for _ in range(50):
        r = resid(delta, math.exp(la))
        if not np.isfinite(r).all() or np.max(np.abs(r)) < 1e-12:
            break
        h = 1e-7
        jd = (resid(delta + h, math.exp(la)) - r) / h
        ja = (resid(delta, math.exp(la + h)) - r) / h
        jac = np.column_stack([jd, ja])
        try:
            step = np.linalg.solve(jac, -r)
        except np.linalg.LinAlgError:
            break
        # damp to stay in the valid range (tan branch needs |δ| < π)
        lam = 1.0
        for _ in range(30):
            nd = delta + lam * step[0]
            if nd > -math.pi * (1 - 1e-9):
                r2 = resid(nd, math.exp(la + lam * step[1]))
                if np.all(np.isfinite(r2)) and np.max(np.abs(r2)) < np.max(np.abs(r)):
                    break
            lam *= 0.5
        delta += lam * step[0]
        la += lam * step[1]
    u = _vinokur_map(xi, delta, math.exp(la))
    u[0], u[-1] = 0.0, 1.0
    if not np.all(np.diff(u) > 0):
        raise InvalidInputError(f"cannot distribute {n} cells with first spacing {first:g} and last {last:g}")
    return u


def distribute(
    n: int,
    kind: str = "uniform",
    *,
    first: float | None = None,
    last: float | None = None,
) -> np.ndarray:
    """Fractions of arc length for ``n`` cells.

    Parameters
    ----------
    n : int
        Number of cells (``n + 1`` points are returned).
    kind : {"uniform", "tanh", "vinokur"}
        ``tanh`` needs ``first`` or ``last`` (one-sided); ``vinokur`` needs both
        (with only one it falls back to the one-sided tanh).
    first, last : float, optional
        Spacing of the first / last cell as a fraction of the border length.
    """
    kind = validate_choice(kind, DISTRIBUTIONS, name="distribution")
    n = validate_count(n, name="cells")
    if kind == "uniform":
        return uniform(n)
    if first is not None and last is not None:
        return vinokur(n, first, last)
    if first is not None:
        return tanh_one_sided(n, first)
    if last is not None:
        return tanh_one_sided(n, last, at_end=True)
    raise InvalidInputError(f"distribution {kind!r} needs a first and/or last spacing")
