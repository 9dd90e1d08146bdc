"""numba kernels of the fold-free sweeps: one node-wise Newton sweep in one pass per node, the
untangling loop and the barrier sweeps of :func:`meshcore.foldfree.minimise.minimise`.

:func:`fast_sweep` takes the steps of :func:`meshcore.foldfree._kernels.sweep` (the readable form:
each triangle's forms, then the sums; the test oracle of this one) with the forms and the local
energy, gradient and Hessian of a node in one loop over its 12 corner triangles, and the trial
energies from the same forms.  The same steps, the sums in another order (equal up to rounding).
A node update on Shasta's whole-block relax (23 000 nodes, CPU, the same process, session 32) took
164 → 90 ns at ε = 0 (the barrier sweeps, ω = 1.9) and 231 → 168 ns at ε > 0 (the untangling).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ._kernels import _FM, _INF, _newton, _sum_terms, _tri_forms, _trial_energy, patch_stats

__all__ = ["STALL", "barrier_sweeps", "fast_sweep", "untangle"]

#: :func:`untangle` gives up when ε has shrunk below this fraction of the worst inverted corner's
#: ``|D|`` (χ there is then ~ε²/(4|D|): a wall).  The failed pieces cost most of the untangling:
#: on 79 saved Winslow grids (session 30) 1457 pieces failed in 303 000 sweeps, 1706 succeeded in
#: 86 000; 4 of the 1706 went below 1e-3 before they succeeded, 9 below 1e-2.  1e-4 → 1e-3: the same
#: outcome on all 79, the same grid on 76 (Garda and a headlands shape repaired by the transplant
#: instead of a wide patch, lower energy), repair CPU -10 % (1e-2: -23 %, 9 grids differ, one moved
#: 5× as far from Winslow).
STALL = 1e-3

#: The 12 corner triangles round a node in its 3 × 3 neighbourhood (index ``3 di + dj``, the node
#: at 4): ``(apex, a, b)`` in :func:`._kernels._node_forms`' order; the node's role is ``n % 3`` (0 apex,
#: 1 ``a``, 2 ``b``).
_TRI = np.array(
    [4, 1, 3, 3, 4, 0, 1, 0, 4, 4, 3, 7, 7, 4, 6, 3, 6, 4, 4, 5, 1, 1, 4, 2, 5, 2, 4, 4, 7, 5, 5, 4, 8, 7, 8, 4]
).reshape(12, 3)


@njit(cache=True, nogil=True, fastmath=_FM, error_model="numpy")
def fast_sweep(x, y, nodes, eps, omega, periodic):
    """:func:`._kernels.sweep` with no step cap, in one loop per node: the 12 triangles' forms and
    the local energy, gradient and Hessian in one pass (``_node_forms`` + ``_form_local`` there),
    then the trial points (``_form_energy``).  The same steps, the sums in another order (equal up
    to rounding).  Returns the largest node displacement."""
    f0 = np.empty(12)
    f1 = np.empty(12)
    f2 = np.empty(12)
    f3 = np.empty(12)
    d0 = np.empty(12)
    d1 = np.empty(12)
    d2 = np.empty(12)
    cx = np.empty(9)
    cy = np.empty(9)
    dmax = 0.0
    ni1 = x.shape[0]
    e2 = eps * eps
    for k in range(nodes.shape[0]):
        i = nodes[k, 0]
        j = nodes[k, 1]
        im = i - 1 if i > 0 else ni1 - 2
        for b in range(3):
            jj = j - 1 + b
            cx[b], cy[b] = x[im, jj], y[im, jj]
            cx[3 + b], cy[3 + b] = x[i, jj], y[i, jj]
            cx[6 + b], cy[6 + b] = x[i + 1, jj], y[i + 1, jj]
        dmin = _INF
        for n in range(12):
            kt, ka, kb = _TRI[n, 0], _TRI[n, 1], _TRI[n, 2]
            ux, uy = cx[ka] - cx[kt], cy[ka] - cy[kt]
            vx, vy = cx[kb] - cx[kt], cy[kb] - cy[kt]
            f0[n], f1[n], f2[n], f3[n], d0[n], d1[n], d2[n] = _tri_forms(ux, uy, vx, vy, n % 3)
            dmin = min(dmin, d0[n])
        if eps == 0.0:  # (the literal ε² lets the compiler drop the ε > 0 terms)
            if dmin <= 0.0:
                continue
            t = _sum_terms(f0, f1, f2, f3, d0, d1, d2, 12, 0.0)
        else:
            t = _sum_terms(f0, f1, f2, f3, d0, d1, d2, 12, e2)
            if not (t[0] > 0.0):
                continue
        e0, gx, gy, hxx, hxy, hyy = t[1], t[2], t[3], t[4], t[5], t[6]
        ok, sx, sy = _newton(gx, gy, hxx, hxy, hyy)
        if not ok:
            continue
        slope = gx * sx + gy * sy
        if not (slope < 0.0):
            continue
        first = omega > 1.0
        alpha = omega if first else 1.0
        for _ in range(31 if first else 30):
            tx, ty = alpha * sx, alpha * sy
            if eps == 0.0:
                e, ok = _trial_energy(f0, f1, f2, f3, d0, d1, d2, 12, tx, ty, 0.0)
            else:
                e, ok = _trial_energy(f0, f1, f2, f3, d0, d1, d2, 12, tx, ty, e2)
            if ok and (e < e0 if first else e <= e0 + 1e-4 * alpha * slope):
                nx, ny = x[i, j] + tx, y[i, j] + ty
                x[i, j] = nx
                y[i, j] = ny
                if periodic and i == 0:
                    x[ni1 - 1, j] = nx
                    y[ni1 - 1, j] = ny
                step = alpha * math.sqrt(sx * sx + sy * sy)
                if step > dmax:
                    dmax = step
                break
            if first:
                first = False
                alpha = 1.0
            else:
                alpha *= 0.5
    return dmax


@njit(cache=True, nogil=True)
def untangle(x, y, nodes, cells, exempt, eps, eps_floor, tol, inner, max_outer, periodic):
    """The untangling loop of :func:`meshcore.foldfree.minimise.minimise` (its steps one for one,
    kept here so that a piece's hundreds of ε steps make no Python calls): at each ε up to
    ``inner`` sweeps until the energy stalls, then ε shrinks by the rule of Garanzha et al.
    Returns ``(least corner Jacobian, sweeps)``."""
    sweeps = 0
    e_prev, _ = patch_stats(x, y, cells, eps, exempt)
    dmin = -_INF
    e = e_prev
    for _outer in range(max_outer):
        e_in = e_prev
        for _ in range(inner):
            d = fast_sweep(x, y, nodes, eps, 1.0, periodic)
            sweeps += 1
            e, dmin = patch_stats(x, y, cells, eps, exempt)
            if d <= tol or dmin > 0.0 or e_in - e <= 1e-3 * e:
                break
            e_in = e
        if dmin > 0.0:
            break
        sigma = max(1.0 - e / e_prev, 0.1)
        chi = 0.5 * (dmin + math.sqrt(eps * eps + dmin * dmin))
        mu = (1.0 - sigma) * chi
        eps = 2.0 * math.sqrt(mu * (mu - dmin)) if dmin < mu else eps_floor
        eps = max(eps, eps_floor)
        if eps < STALL * abs(dmin):
            break  # stagnated: ε has vanished next to the worst inverted corner
        e_prev, _ = patch_stats(x, y, cells, eps, exempt)
    return dmin, sweeps


@njit(cache=True, nogil=True)
def barrier_sweeps(x, y, nodes, tol, max_sweeps, omega, periodic):
    """Up to ``max_sweeps`` ε = 0 sweeps (over-relaxed by ``omega``), until no node moves more
    than ``tol``; the sweeps made."""
    sweeps = 0
    for _ in range(max_sweeps):
        d = fast_sweep(x, y, nodes, 0.0, omega, periodic)
        sweeps += 1
        if d <= tol:
            break
    return sweeps
