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

from .geometry import border_angles, boundary_report, first_spacing
from .sources import ControlSources, make_sources
from .spec import BOUNDARY_KINDS, Attractor, BorderControl, ControlSpec, control_from_mapping

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
