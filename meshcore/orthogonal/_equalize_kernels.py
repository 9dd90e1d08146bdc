"""The objective of :mod:`.equalize` as one compiled loop (its NumPy form, ``_Patch.objective_numpy``,
is the reference the tests hold it to): a patch's objective is evaluated some 600 times per BFGS
solve, and as ~40 NumPy calls on a few hundred cells each it cost 0.4 ms a call."""

from __future__ import annotations

import math

from numba import njit


@njit(cache=True, inline="always")
def _add(G, k, gx, gy):
    G[k, 0] += gx
    G[k, 1] += gy


@njit(cache=True, inline="always")
def _quad_area(P, c):
    d1x = P[c[2], 0] - P[c[0], 0]
    d1y = P[c[2], 1] - P[c[0], 1]
    d2x = P[c[3], 0] - P[c[1], 0]
    d2y = P[c[3], 1] - P[c[1], 1]
    return 0.5 * (d1x * d2y - d1y * d2x), d1x, d1y, d2x, d2y


@njit(cache=True, inline="always")
def _add_area_grad(G, P, c, s):
    """``G += s · ∂A/∂(corners)`` for the quad ``c`` (its signed area ``A``)."""
    _, d1x, d1y, d2x, d2y = _quad_area(P, c)
    g2x, g2y = 0.5 * d2y, -0.5 * d2x
    g3x, g3y = -0.5 * d1y, 0.5 * d1x
    _add(G, c[0], -s * g2x, -s * g2y)
    _add(G, c[1], -s * g3x, -s * g3y)
    _add(G, c[2], s * g2x, s * g2y)
    _add(G, c[3], s * g3x, s * g3y)


@njit(cache=True, nogil=True)
def objective(P, C, sg, J0, Ca, Cb, log_aim, S, c_allowed, w_cos, T, e_allowed, w_edge, w_jac, G):
    """``(ok, f)`` with ``G`` (zeroed here) the gradient in every node; ``ok`` False (and ``f``,
    ``G`` meaningless) when a corner Jacobian of the patch's cells ``C`` is not positive."""
    G[:, :] = 0.0
    n = C.shape[0]
    for q in range(n):
        for k in range(4):
            p, nx, m = C[q, k], C[q, (k + 1) % 4], C[q, (k + 3) % 4]
            ax, ay = P[nx, 0] - P[p, 0], P[nx, 1] - P[p, 1]
            bx, by = P[m, 0] - P[p, 0], P[m, 1] - P[p, 1]
            if sg[q] * (ax * by - ay * bx) <= 0.0:
                return False, 1e6
    f_pairs = 0.0
    for q in range(Ca.shape[0]):
        Aa = _quad_area(P, Ca[q])[0]
        Ab = _quad_area(P, Cb[q])[0]
        u = math.log(abs(Aa)) - math.log(abs(Ab))
        ex = max(abs(u) - log_aim, 0.0)
        if ex > 0.0:
            f_pairs += ex * ex
            w = 2.0 * ex * (1.0 if u > 0 else -1.0)
            _add_area_grad(G, P, Ca[q], w / Aa)
            _add_area_grad(G, P, Cb[q], -w / Ab)
    f_cos = 0.0
    for q in range(S.shape[0]):
        ax = P[S[q, 1], 0] - P[S[q, 2], 0]
        ay = P[S[q, 1], 1] - P[S[q, 2], 1]
        bx = P[S[q, 3], 0] - P[S[q, 4], 0]
        by = P[S[q, 3], 1] - P[S[q, 4], 1]
        na = math.sqrt(ax * ax + ay * ay)
        nb = math.sqrt(bx * bx + by * by)
        d = ax * bx + ay * by
        nn = max(na * nb, 1e-300)
        c = abs(d) / nn
        ex = max(c - c_allowed[q], 0.0)
        if ex > 0.0:
            f_cos += ex * ex
            w = 2.0 * w_cos * ex
            sd = 1.0 if d > 0 else (-1.0 if d < 0 else 0.0)
            ka = c / max(na, 1e-300) ** 2
            kb = c / max(nb, 1e-300) ** 2
            dax, day = sd * bx / nn - ka * ax, sd * by / nn - ka * ay
            dbx, dby = sd * ax / nn - kb * bx, sd * ay / nn - kb * by
            _add(G, S[q, 1], w * dax, w * day)
            _add(G, S[q, 2], -w * dax, -w * day)
            _add(G, S[q, 3], w * dbx, w * dby)
            _add(G, S[q, 4], -w * dbx, -w * dby)
    f_edge = 0.0
    for q in range(T.shape[0]):
        v1x, v1y = P[T[q, 1], 0] - P[T[q, 0], 0], P[T[q, 1], 1] - P[T[q, 0], 1]
        v2x, v2y = P[T[q, 2], 0] - P[T[q, 1], 0], P[T[q, 2], 1] - P[T[q, 1], 1]
        q1 = max(v1x * v1x + v1y * v1y, 1e-300)
        q2 = max(v2x * v2x + v2y * v2y, 1e-300)
        u = 0.5 * (math.log(q1) - math.log(q2))
        ex = max(abs(u) - e_allowed[q], 0.0)
        if ex > 0.0:
            f_edge += ex * ex
            w = 2.0 * w_edge * ex * (1.0 if u > 0 else -1.0)
            g1x, g1y = v1x / q1, v1y / q1
            g2x, g2y = v2x / q2, v2y / q2
            _add(G, T[q, 0], -w * g1x, -w * g1y)
            _add(G, T[q, 1], w * (g1x + g2x), w * (g1y + g2y))
            _add(G, T[q, 2], -w * g2x, -w * g2y)
    f_jac = 0.0
    for q in range(n):
        for k in range(4):
            p, nx, m = C[q, k], C[q, (k + 1) % 4], C[q, (k + 3) % 4]
            ax, ay = P[nx, 0] - P[p, 0], P[nx, 1] - P[p, 1]
            bx, by = P[m, 0] - P[p, 0], P[m, 1] - P[p, 1]
            J = sg[q] * (ax * by - ay * bx)
            ex = max(0.5 - J / J0[q, k], 0.0)
            if ex > 0.0:
                f_jac += ex * ex
                w = -2.0 * w_jac * ex / J0[q, k] * sg[q]
                _add(G, nx, w * by, -w * bx)
                _add(G, m, -w * ay, w * ax)
                _add(G, p, -w * (by - ay), -w * (-bx + ax))
    return True, f_pairs + w_cos * f_cos + w_edge * f_edge + w_jac * f_jac
