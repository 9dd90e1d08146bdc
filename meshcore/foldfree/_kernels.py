r"""numba kernels of the fold-free (barrier) grid functional (functions only).

Corner-triangle energy
----------------------
Every cell with corners ``c0 = (i, j)``, ``c1 = (i+1, j)``, ``c2 = (i+1, j+1)``,
``c3 = (i, j+1)`` (counter-clockwise) is split into its four *corner
triangles* ``T_m = (p, a, b) = (c_m, c_{m+1}, c_{m−1})``.  With
``u = a − p``, ``v = b − p``:

.. math::

    F = |u|^2 + |v|^2,\qquad D = u \times v = u_x v_y − u_y v_x,

    f_ε(T) = \frac{F}{χ(D, ε)},\qquad χ(D, ε) = \frac{D + \sqrt{ε^2 + D^2}}{2}.

``D`` is the corner Jacobian of the cell at ``c_m``; a cell is convex and
positively oriented iff its four ``D > 0``.  For ``ε = 0`` (``χ = D`` for
``D > 0``, ``+∞`` otherwise) the sum ``E = Σ f_0`` is the discrete
Winslow–Ivanenko functional (harmonic energy divided by the Jacobian,
``∫ (g11 + g22)/J``): ``f_0 ≥ 2`` with equality for a square corner, and
``E → ∞`` as any corner Jacobian → 0⁺, so a descent method started on a
valid grid can never fold a cell (Ivanenko; Charakhch'yan & Ivanenko 1997).
For ``ε > 0`` the energy is finite on folded grids and its minimisation with
decreasing ``ε`` untangles them (Garanzha et al., "Foldover-free maps in 50
lines of code", ACM TOG 40(4), 2021).

Per-node Newton
---------------
With all other nodes fixed, ``D`` is affine and ``F`` quadratic in one node
``q``: for the apex ``p`` (``∇F = −2(u+v)``, ``∇²F = 4I``,
``∇D = (u_y − v_y, v_x − u_x)``), for ``a`` (``∇F = 2u``, ``∇²F = 2I``,
``∇D = (v_y, −v_x)``), for ``b`` (``∇F = 2v``, ``∇²F = 2I``,
``∇D = (−u_y, u_x)``).  With ``χ' = χ/s``, ``χ'' = ε²/(2s³)``,
``s = \sqrt{ε² + D²}``:

.. math::

    ∇f = \frac{∇F}{χ} − \frac{F χ'}{χ^2} ∇D,\qquad
    ∇^2 f = \frac{∇^2F}{χ} − \frac{χ'}{χ^2}(∇F∇D^T + ∇D∇F^T)
            + F\Bigl(\frac{2χ'^2}{χ^3} − \frac{χ''}{χ^2}\Bigr)∇D∇D^T.

For ``ε = 0`` each ``f`` is convex in ``q`` on ``D > 0`` (a quadratic over an
affine function), so the per-node problem is convex.  Each node belongs to 12
corner triangles (3 in each of its ≤ 4 cells).  :func:`sweep` applies a
damped Newton step with backtracking on the node's local energy, node by node
in 4-colour order (nodes of one colour share no cell).  Triangles whose three
nodes are all fixed are constant and ignored.  The sweep reads a node's
neighbours once: it keeps each triangle's ``F, ∇F, D, ∇D`` at the node
(:func:`_node_forms`), from which the energy, gradient and Hessian there
(:func:`_form_local`, the same terms) and, ``F`` being quadratic and ``D``
affine in the node, the energy at every trial point (:func:`_form_energy`)
follow, both equal to the term-by-term sums up to rounding.  The repair runs
:func:`meshcore.foldfree._sweep.fast_sweep`: the same steps in one loop per node (this
:func:`sweep` is its readable form and test oracle).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

_INF = np.inf


@njit(cache=True, inline="always")
def _regularised(d, e2):
    """``(c, s)``: the regularised area ``c = (d + s) / 2`` (``ε² / (2 (s − d))`` for ``d < 0``: no
    cancellation), ``s = sqrt(ε² + d²)``, under ``ε² = e2`` (:func:`_barrier`)."""
    s = math.sqrt(e2 + d * d)
    return (0.5 * (d + s) if d >= 0.0 else 0.5 * e2 / (s - d)), s


@njit(cache=True, inline="always")
def _barrier(d, eps):
    """The regularised area ``c(d) = (d + s) / 2``, ``s = sqrt(ε² + d²)`` (``ε² / (2 (s − d))`` for
    ``d < 0``: no cancellation; ``c = d`` at ε = 0), and ``c' = c / s``, ``c'' / 2 = ε² / (2 s³)``:
    ``(c, c', c''/2)``, with ``c = 0`` where the triangle is inverted under the ε = 0 barrier (the
    caller's energy is infinite there)."""
    if eps == 0.0:
        if d <= 0.0:
            return 0.0, 1.0, 0.0
        return d, 1.0, 0.0
    c, s = _regularised(d, eps * eps)
    if c <= 0.0 or s <= 0.0:
        return 0.0, 1.0, 0.0
    return c, c / s, eps * eps / (2.0 * s * s * s)


@njit(cache=True, nogil=True)
def _chi(d, eps):
    """``c(d)`` of :func:`_barrier` alone (0 where inverted under ε = 0)."""
    return _barrier(d, eps)[0]


@njit(cache=True, nogil=True)
def tri_energy(px, py, ax, ay, bx, by, eps):
    """``f_ε`` of one corner triangle (``+inf`` when ``ε = 0`` and ``D ≤ 0``)."""
    ux, uy = ax - px, ay - py
    vx, vy = bx - px, by - py
    d = ux * vy - uy * vx
    c = _chi(d, eps)
    if c <= 0.0:
        return _INF
    return (ux * ux + uy * uy + vx * vx + vy * vy) / c


@njit(cache=True, nogil=True)
def _tri_node(px, py, ax, ay, bx, by, role, eps, out, full=True):
    """Add f, ∇f, ∇²f w.r.t. node ``role`` (0 = p, 1 = a, 2 = b) into ``out``.

    ``out = [E, gx, gy, hxx, hxy, hyy]``; ``full=False``: ``f`` alone (a trial point).
    Returns False if the triangle is inverted under the ε = 0 barrier (energy infinite).
    """
    ux, uy = ax - px, ay - py
    vx, vy = bx - px, by - py
    d = ux * vy - uy * vx
    f2 = ux * ux + uy * uy + vx * vx + vy * vy
    c, c1, c2 = _barrier(d, eps)
    if c <= 0.0:
        return False
    if not full:
        out[0] += f2 * (1.0 / c)
        return True
    if role == 0:
        gfx, gfy, hf = -2.0 * (ux + vx), -2.0 * (uy + vy), 4.0
        gdx, gdy = uy - vy, vx - ux
    elif role == 1:
        gfx, gfy, hf = 2.0 * ux, 2.0 * uy, 2.0
        gdx, gdy = vy, -vx
    else:
        gfx, gfy, hf = 2.0 * vx, 2.0 * vy, 2.0
        gdx, gdy = -uy, ux
    ic = 1.0 / c
    k1 = f2 * c1 * ic * ic
    out[0] += f2 * ic
    out[1] += gfx * ic - k1 * gdx
    out[2] += gfy * ic - k1 * gdy
    k2 = c1 * ic * ic
    k3 = f2 * (2.0 * c1 * c1 * ic * ic * ic - c2 * ic * ic)
    out[3] += hf * ic - 2.0 * k2 * gfx * gdx + k3 * gdx * gdx
    out[4] += -k2 * (gfx * gdy + gdx * gfy) + k3 * gdx * gdy
    out[5] += hf * ic - 2.0 * k2 * gfy * gdy + k3 * gdy * gdy
    return True


@njit(cache=True, nogil=True)
def node_local(x, y, i, j, qx, qy, eps, out, periodic=False):
    """Local energy, gradient and Hessian of node ``(i, j)`` placed at ``(qx, qy)``.

    Sums the (up to) 12 corner triangles that contain the node, skipping none
    (a triangle that contains a free node is never all-fixed).  Returns False
    when a triangle is inverted under the ε = 0 barrier.  ``periodic``: column
    ``ni`` repeats column 0, and a seam node ``(0, j)`` also belongs to the
    cells of column ``ni − 1`` (as their corner in column ``ni``).
    """
    return _node_local(x, y, i, j, qx, qy, eps, out, periodic, np.empty(4), np.empty(4), True)


@njit(cache=True, inline="always")
def _cell_round(x, y, i, j, dc, periodic, cx, cy):
    """The corners c0..c3 of the ``dc``-th cell (0..3) round node ``(i, j)`` into ``cx, cy``; returns
    which corner is the node (``(i, j) = (ci + di, cj + dj)``: 0, 1 on the cell's first row, 2, 3
    on its second), or −1 when there is no such cell (the node on a border; ``periodic``: column
    ``ni − 1``'s cells for a seam node)."""
    ni1, nj1 = x.shape
    ci = i - 1 + (dc & 1)
    cj = j - 1 + (dc >> 1)
    di = i - ci
    if periodic and ci < 0:
        ci = ni1 - 2
        di = 1
    if ci < 0 or cj < 0 or ci >= ni1 - 1 or cj >= nj1 - 1:
        return -1
    cx[0], cy[0] = x[ci, cj], y[ci, cj]
    cx[1], cy[1] = x[ci + 1, cj], y[ci + 1, cj]
    cx[2], cy[2] = x[ci + 1, cj + 1], y[ci + 1, cj + 1]
    cx[3], cy[3] = x[ci, cj + 1], y[ci, cj + 1]
    return di if j - cj == 0 else 3 - di


@njit(cache=True, nogil=True)
def _node_local(x, y, i, j, qx, qy, eps, out, periodic, cx, cy, full):
    """:func:`node_local` with the caller's scratch corners ``cx, cy`` (4 each: no allocation per
    node); ``full=False`` sums the energy alone (``out[0]``, the same terms in the same order)."""
    for k in range(6):
        out[k] = 0.0
    for dc in range(4):
        m = _cell_round(x, y, i, j, dc, periodic, cx, cy)
        if m < 0:
            continue
        cx[m], cy[m] = qx, qy
        for r in range(3):
            # triangle with apex t = m, m-1 (node is a), m+1 (node is b)
            if r == 0:
                t = m
            elif r == 1:
                t = (m + 3) % 4
            else:
                t = (m + 1) % 4
            ta = (t + 1) % 4
            tb = (t + 3) % 4
            if not _tri_node(cx[t], cy[t], cx[ta], cy[ta], cx[tb], cy[tb], r, eps, out, full):
                return False
    return True


@njit(cache=True, inline="always")
def _tri_forms(ux, uy, vx, vy, r):
    """The forms of one corner triangle with edges ``u, v`` from its apex w.r.t. the node in role
    ``r`` (0 apex, 1 ``a``, 2 ``b``): ``(F, ∂F/∂x, ∂F/∂y, ∇²F/2, D, ∂D/∂x, ∂D/∂y)``."""
    f = ux * ux + uy * uy + vx * vx + vy * vy
    d = ux * vy - uy * vx
    if r == 0:
        return f, -2.0 * (ux + vx), -2.0 * (uy + vy), 2.0, d, uy - vy, vx - ux
    if r == 1:
        return f, 2.0 * ux, 2.0 * uy, 1.0, d, vy, -vx
    return f, 2.0 * vx, 2.0 * vy, 1.0, d, -uy, ux


@njit(cache=True, inline="always")
def _terms(f2, gfx, gfy, hf, d, gdx, gdy, e2):
    """One triangle's terms of the local energy, gradient and Hessian (``hf = ∇²F``) under
    ``ε² = e2``: ``(c, E, gx, gy, hxx, hxy, hyy)``; ``c = χ(D, ε)`` (``D`` itself at ε = 0: the
    caller checks ``D > 0`` there, ``c > 0`` otherwise)."""
    if e2 == 0.0:
        ic = 1.0 / d
        k2 = ic * ic
        k1 = f2 * k2
        k3 = 2.0 * k1 * ic
        c = d
    else:
        c, s = _regularised(d, e2)
        ic = 1.0 / c
        i_s = 1.0 / s
        c1 = c * i_s
        c2 = 0.5 * e2 * i_s * i_s * i_s
        k2 = c1 * ic * ic
        k1 = f2 * k2
        k3 = f2 * (2.0 * c1 * c1 * ic * ic * ic - c2 * ic * ic)
    return (
        c,
        f2 * ic,
        gfx * ic - k1 * gdx,
        gfy * ic - k1 * gdy,
        hf * ic - 2.0 * k2 * gfx * gdx + k3 * gdx * gdx,
        -k2 * (gfx * gdy + gdx * gfy) + k3 * gdx * gdy,
        hf * ic - 2.0 * k2 * gfy * gdy + k3 * gdy * gdy,
    )


@njit(cache=True, inline="always")
def _sum_terms(f0, f1, f2, f3, d0, d1, d2, n, e2):
    """:func:`_terms` summed over the first ``n`` triangles of the forms ``f0 … d2`` (``f3`` =
    ``∇²F/2``): ``(least c, E, gx, gy, hxx, hxy, hyy)``."""
    cmin = _INF
    e = gx = gy = hxx = hxy = hyy = 0.0
    for k in range(n):
        t = _terms(f0[k], f1[k], f2[k], 2.0 * f3[k], d0[k], d1[k], d2[k], e2)
        cmin = min(cmin, t[0])
        e += t[1]
        gx += t[2]
        gy += t[3]
        hxx += t[4]
        hxy += t[5]
        hyy += t[6]
    return cmin, e, gx, gy, hxx, hxy, hyy


@njit(cache=True, inline="always")
def _newton(gx, gy, hxx, hxy, hyy):
    """The Newton step ``−H⁻¹ g`` of a node, the Hessian shifted to be positive definite:
    ``(ok, sx, sy)``, ``ok = False`` when the shifted determinant is not positive."""
    tr = hxx + hyy
    det = hxx * hyy - hxy * hxy
    lam_min = 0.5 * tr - math.sqrt(max(0.25 * (hxx - hyy) ** 2 + hxy * hxy, 0.0))
    if lam_min <= 1e-12 * max(abs(tr), 1e-300):
        shift = -lam_min + 1e-6 * max(abs(tr), 1e-300) + 1e-300
        hxx += shift
        hyy += shift
        det = hxx * hyy - hxy * hxy
    if det <= 0.0:
        return False, 0.0, 0.0
    return True, -(hyy * gx - hxy * gy) / det, -(-hxy * gx + hxx * gy) / det


@njit(cache=True, nogil=True)
def _node_forms(x, y, i, j, periodic, cx, cy, forms):
    """The forms of node ``(i, j)``'s 12 corner triangles, in :func:`_node_local`'s order:
    ``forms[:, k] = (F, ∂F/∂x, ∂F/∂y, ∇²F/2, D, ∂D/∂x, ∂D/∂y)`` w.r.t. the node where it is.
    ``F`` is quadratic and ``D`` affine in the node, so these give every triangle's ``f_ε`` at any
    other place of the node exactly (:func:`_form_energy`).  The node is a free one: an interior
    node, or (``periodic``) a seam node of column 0 whose left neighbours are column ``ni − 1``.
    ``cx, cy``: scratch of 9 values (the node's 3 × 3 neighbourhood).  Returns 12."""
    im = i - 1 if i > 0 else x.shape[0] - 2
    for b in range(3):
        jj = j - 1 + b
        cx[b], cy[b] = x[im, jj], y[im, jj]
        cx[3 + b], cy[3 + b] = x[i, jj], y[i, jj]
        cx[6 + b], cy[6 + b] = x[i + 1, jj], y[i + 1, jj]
    n = 0
    for dc in range(4):
        a = dc & 1
        b = dc >> 1
        # the cell's corners c0..c3 in the 3 × 3 neighbourhood (index 3 * di + dj)
        q0 = 3 * a + b
        m = (1 - a) if b == 1 else 3 - (1 - a)
        for r in range(3):
            t = m if r == 0 else ((m + 3) % 4 if r == 1 else (m + 1) % 4)
            ta = (t + 1) % 4
            tb = (t + 3) % 4
            # corner k of the cell sits at q0 + (0, 3, 4, 1)[k]
            kt = q0 + (0 if t == 0 else (3 if t == 1 else (4 if t == 2 else 1)))
            ka = q0 + (0 if ta == 0 else (3 if ta == 1 else (4 if ta == 2 else 1)))
            kb = q0 + (0 if tb == 0 else (3 if tb == 1 else (4 if tb == 2 else 1)))
            ux, uy = cx[ka] - cx[kt], cy[ka] - cy[kt]
            vx, vy = cx[kb] - cx[kt], cy[kb] - cy[kt]
            f = _tri_forms(ux, uy, vx, vy, r)
            for q in range(7):
                forms[q, n] = f[q]
            n += 1
    return n


#: The flags of the two sums over a node's 12 triangles: they may be fused (no assumption on
#: infinities: the ε = 0 trial energy is +inf on an inverted triangle).  With them and the forms
#: stored by form (``forms[f, k]``) a node update took 176 → 141 ns (ε = 0) and 281 → 238 ns
#: (ε > 0; session 26, with ``reassoc`` too), CPU, a lake's whole-block relax; the energies equal
#: the term-by-term sums up to rounding.  Not ``reassoc``: with it a kernel compiled in the running
#: process and the same kernel loaded from numba's cache summed in other orders, and a lake's first
#: run after the cache was emptied gave another grid than every later run (session 49; without it
#: the repair of the four branched lakes of ``benchmarks/robust.py`` took the same CPU time within
#: ±3 %).
_FM = {"nsz", "contract", "arcp"}


@njit(cache=True, nogil=True, fastmath=_FM)
def _form_local(forms, n, eps, out):
    """:func:`_node_local` (``full``) from the node's forms: ``out = [E, gx, gy, hxx, hxy, hyy]``
    (the same terms as :func:`_tri_node`, summed in another order: equal up to rounding); False
    when a triangle is inverted under ε = 0."""
    dmin = _INF
    for k in range(n):
        dmin = min(dmin, forms[4, k])
    if eps == 0.0 and dmin <= 0.0:
        return False
    t = _sum_terms(forms[0], forms[1], forms[2], forms[3], forms[4], forms[5], forms[6], n, eps * eps)
    if not (t[0] > 0.0):
        return False
    e, gx, gy, hxx, hxy, hyy = t[1], t[2], t[3], t[4], t[5], t[6]
    out[0], out[1], out[2], out[3], out[4], out[5] = e, gx, gy, hxx, hxy, hyy
    return True


@njit(cache=True, inline="always")
def _trial_energy(f0, f1, f2, f3, d0, d1, d2, n, dx, dy, e2):
    """The local energy of a node moved by ``(dx, dy)`` from where its triangles' forms ``f0 … d2``
    (``f3`` = ``∇²F/2``) were taken, under ``ε² = e2``, and whether every triangle's area (``D`` at
    ε = 0, else ``c``) stays positive: ``(E, ok)``."""
    e = 0.0
    dd = dx * dx + dy * dy
    cm = _INF
    for k in range(n):
        d = d0[k] + d1[k] * dx + d2[k] * dy
        c = d if e2 == 0.0 else _regularised(d, e2)[0]
        cm = min(cm, c)
        e += (f0[k] + f1[k] * dx + f2[k] * dy + f3[k] * dd) / c
    return e, cm > 0.0


@njit(cache=True, nogil=True, fastmath=_FM, error_model="numpy")
def _form_energy(forms, n, dx, dy, eps):
    """The node's local energy with the node moved by ``(dx, dy)`` from where ``forms`` were
    taken (``+inf`` where a triangle inverts under the ε = 0 barrier): the trial points of
    :func:`sweep`, equal to :func:`_node_local` there up to rounding (division by a zero ``D``
    gives ±inf or nan here, never an error: the verdict is the least ``D``'s)."""
    e, ok = _trial_energy(forms[0], forms[1], forms[2], forms[3], forms[4], forms[5], forms[6], n, dx, dy, eps * eps)
    return e if ok else _INF


@njit(cache=True, nogil=True)
def sweep(x, y, nodes, eps, max_step, omega=1.0, periodic=False):
    """One damped-Newton Gauss–Seidel sweep over ``nodes`` (int32 (k, 2), colour ordered).

    Each node minimises its local energy (12 corner triangles) along the
    Newton direction (the Hessian shifted to be positive definite), with
    backtracking until the energy decreases; under ``ε = 0`` the barrier
    rejects every step that would invert a triangle.  ``periodic``: seam
    nodes are given as column 0 and their copy in column ``ni`` follows.  ``max_step`` caps the
    step length (in units of the coordinates).  ``omega > 1`` first tries the
    over-relaxed step ``ω·δ`` (nonlinear SOR) and falls back to backtracking
    from the plain Newton step when it does not lower the energy.

    Returns the largest node displacement.
    """
    out = np.empty(6)
    forms = np.empty((7, 12))
    cx = np.empty(9)
    cy = np.empty(9)
    dmax = 0.0
    for k in range(nodes.shape[0]):
        i = nodes[k, 0]
        j = nodes[k, 1]
        qx, qy = x[i, j], y[i, j]
        nt = _node_forms(x, y, i, j, periodic, cx, cy, forms)
        if not _form_local(forms, nt, eps, out):
            continue
        e0, gx, gy = out[0], out[1], out[2]
        ok, sx, sy = _newton(gx, gy, out[3], out[4], out[5])
        if not ok:
            continue
        slen = math.sqrt(sx * sx + sy * sy)
        if slen > max_step:
            sx *= max_step / slen
            sy *= max_step / slen
        slope = gx * sx + gy * sy
        if not (slope < 0.0):
            continue
        alpha = 1.0
        if omega > 1.0:
            nx = qx + omega * sx
            ny = qy + omega * sy
            if _form_energy(forms, nt, omega * sx, omega * sy, eps) < e0:
                x[i, j] = nx
                y[i, j] = ny
                if periodic and i == 0:
                    x[x.shape[0] - 1, j] = nx
                    y[x.shape[0] - 1, j] = ny
                dd = omega * math.sqrt(sx * sx + sy * sy)
                if dd > dmax:
                    dmax = dd
                continue
        for _ in range(30):
            nx = qx + alpha * sx
            ny = qy + alpha * sy
            if _form_energy(forms, nt, alpha * sx, alpha * sy, eps) <= e0 + 1e-4 * alpha * slope:
                x[i, j] = nx
                y[i, j] = ny
                if periodic and i == 0:
                    x[x.shape[0] - 1, j] = nx
                    y[x.shape[0] - 1, j] = ny
                dd = alpha * math.sqrt(sx * sx + sy * sy)
                if dd > dmax:
                    dmax = dd
                break
            alpha *= 0.5
    return dmax


@njit(cache=True, nogil=True)
def patch_stats(x, y, cells, eps, exempt):
    """Energy ``Σ f_ε`` and the smallest corner Jacobian over ``cells`` (int32 (k, 2)).

    ``exempt`` (uint8, shape (ni, nj)) marks cells whose corner triangles are
    skipped (block-corner cells on reflex boundary vertices are passed with
    only that corner excluded via bit flags: bit m excludes corner m).
    """
    e = 0.0
    dmin = _INF
    cx = np.empty(4)
    cy = np.empty(4)
    for k in range(cells.shape[0]):
        ci = cells[k, 0]
        cj = cells[k, 1]
        cx[0], cy[0] = x[ci, cj], y[ci, cj]
        cx[1], cy[1] = x[ci + 1, cj], y[ci + 1, cj]
        cx[2], cy[2] = x[ci + 1, cj + 1], y[ci + 1, cj + 1]
        cx[3], cy[3] = x[ci, cj + 1], y[ci, cj + 1]
        ex = exempt[ci, cj]
        for t in range(4):
            if (ex >> t) & 1:
                continue
            ta = (t + 1) % 4
            tb = (t + 3) % 4
            ux, uy = cx[ta] - cx[t], cy[ta] - cy[t]
            vx, vy = cx[tb] - cx[t], cy[tb] - cy[t]
            d = ux * vy - uy * vx
            if d < dmin:
                dmin = d
            c = _chi(d, eps)
            if c <= 0.0:
                e = _INF
            else:
                e += (ux * ux + uy * uy + vx * vx + vy * vy) / c
    return e, dmin


@njit(cache=True, nogil=True)
def corner_jacobians(x, y):
    """Corner Jacobians, shape ``(4, ni, nj)`` (same as :func:`meshcore.quality.cell_quality`)."""
    ni = x.shape[0] - 1
    nj = x.shape[1] - 1
    out = np.empty((4, ni, nj))
    cx = np.empty(4)
    cy = np.empty(4)
    for ci in range(ni):
        for cj in range(nj):
            cx[0], cy[0] = x[ci, cj], y[ci, cj]
            cx[1], cy[1] = x[ci + 1, cj], y[ci + 1, cj]
            cx[2], cy[2] = x[ci + 1, cj + 1], y[ci + 1, cj + 1]
            cx[3], cy[3] = x[ci, cj + 1], y[ci, cj + 1]
            for t in range(4):
                ta = (t + 1) % 4
                tb = (t + 3) % 4
                ux, uy = cx[ta] - cx[t], cy[ta] - cy[t]
                out[t, ci, cj] = ux * (cy[tb] - cy[t]) - uy * (cx[tb] - cx[t])
    return out
