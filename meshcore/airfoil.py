r"""NACA 4-digit airfoils and the wall spacing for a requested y⁺.

NACA ``MPXX``: maximum camber ``m = M/100`` at ``p = P/10`` chord, thickness
``t = XX/100``:

.. math::

    y_t = 5t\,(0.2969\sqrt{x} − 0.1260x − 0.3516x^2 + 0.2843x^3 − a_4 x^4)

with ``a_4 = 0.1015`` (open trailing edge, the original definition) or
``0.1036`` (closed trailing edge, used here by default so the body is a closed
curve); camber line ``y_c = m/p^2 (2px − x^2)`` for ``x < p`` and
``m/(1−p)^2 ((1−2p) + 2px − x^2)`` behind it, thickness applied normal to it.

First-cell height for a wanted y⁺ (flat-plate estimate, Schlichting's skin
friction ``C_f = 0.026 / Re^{1/7}``):

.. math::  Δy = y^+ \frac{c}{Re\,\sqrt{C_f/2}} .
"""

from __future__ import annotations

import math

import numpy as np

from ._validation import validate_count, validate_positive
from .errors import InvalidInputError

__all__ = ["first_cell_height", "naca4", "naca4_body"]


def _parse(code: str | int) -> tuple[float, float, float]:
    s = f"{code}" if not isinstance(code, str) else code.strip().upper().removeprefix("NACA").strip()
    if len(s) != 4 or not s.isdigit():
        raise InvalidInputError(f"NACA 4-digit code must be 4 digits, e.g. '0012', got {code!r}")
    m, p, t = int(s[0]) / 100.0, int(s[1]) / 10.0, int(s[2:]) / 100.0
    if t <= 0:
        raise InvalidInputError(f"NACA {s}: thickness must be > 0")
    if m > 0 and p == 0:
        raise InvalidInputError(f"NACA {s}: cambered section needs a camber position digit > 0")
    return m, p, t


def naca4(code: str | int, n: int = 64, *, closed: bool = True, chord: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """Upper and lower surfaces, each ``n + 1`` points from LE to TE (cosine spaced).

    Returns
    -------
    upper, lower : (n + 1, 2) arrays
        ``upper[0] = lower[0]`` is the leading edge, ``[-1]`` the trailing edge.
    """
    m, p, t = _parse(code)
    n = validate_count(n, name="n", minimum=2)
    validate_positive(chord, name="chord")
    beta = np.linspace(0.0, math.pi, n + 1)
    x = 0.5 * (1.0 - np.cos(beta))
    a4 = 0.1036 if closed else 0.1015
    yt = 5 * t * (0.2969 * np.sqrt(x) - 0.1260 * x - 0.3516 * x**2 + 0.2843 * x**3 - a4 * x**4)
    if m > 0:
        front = x < p
        yc = np.where(
            front,
            m / p**2 * (2 * p * x - x**2),
            m / (1 - p) ** 2 * ((1 - 2 * p) + 2 * p * x - x**2),
        )
        dyc = np.where(front, 2 * m / p**2 * (p - x), 2 * m / (1 - p) ** 2 * (p - x))
    else:
        yc = np.zeros_like(x)
        dyc = np.zeros_like(x)
    th = np.arctan(dyc)
    up = np.column_stack([x - yt * np.sin(th), yc + yt * np.cos(th)]) * chord
    lo = np.column_stack([x + yt * np.sin(th), yc - yt * np.cos(th)]) * chord
    if closed:
        lo[-1] = up[-1]
    return up, lo


def naca4_body(code: str | int, n: int = 64, *, chord: float = 1.0) -> np.ndarray:
    """Closed-TE body walk TE → lower → LE → upper → TE (clockwise), ``2n + 1`` points."""
    up, lo = naca4(code, n, closed=True, chord=chord)
    return np.vstack([lo[::-1], up[1:]])


def first_cell_height(y_plus: float, reynolds: float, chord: float = 1.0) -> float:
    """Wall spacing Δy for a wanted ``y_plus`` at Reynolds number ``reynolds`` (based on ``chord``).

    >>> round(first_cell_height(1.0, 1e6), 7)
    2.35e-05
    """
    validate_positive(y_plus, name="y_plus")
    validate_positive(reynolds, name="reynolds")
    validate_positive(chord, name="chord")
    cf = 0.026 / reynolds ** (1.0 / 7.0)
    return y_plus * chord / (reynolds * math.sqrt(0.5 * cf))
