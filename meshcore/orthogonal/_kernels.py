r"""Numba kernels of the orthogonal smoother (the formulas, once; NumPy oracle in ``_reference``).

Interior node ``P`` with neighbours ``E, W, N, S`` (and diagonals) in its local frame moves
towards the solution of the Ryskin–Leal equations with the distortion function read off the
current grid (the "weak constraint"):

.. math::
    x_P = \frac{a_E x_E + a_W x_W + b_N x_N + b_S x_S}{a_E + a_W + b_N + b_S},\quad
    a_E = \frac{\bar h_\eta(PE)}{|E - P|},\ b_N = \frac{\bar h_\xi(PN)}{|N - P|},

``h̄_η(PE)`` the mean length of the four η-edges that touch ``P`` or ``E`` (and likewise for
``h̄_ξ``).  Any orthogonal grid is a fixed point (for a rectangular grid of spacing ``dx, dy``
the update returns ``P``); with boundary nodes free to slide, the iteration drives the grid to
an orthogonal one of the same topology.  Nodes where three or five cells meet move to the
mean of their edge neighbours.  Shore nodes slide along the shore to the foot of the
perpendicular from their inward neighbour (the grid line leaving the shore meets it at a right
angle).  Every move is checked against the cells around the node: a move that would make a
corner Jacobian of one of them fall below a small positive floor (``jmin``, per node) is
halved, up to four times, and otherwise not made, so a valid grid stays valid.  Where the driver
asks for it (the nodes round cells a stage left thin, ``thin``), the floor is raised by
:data:`ASPECT_FLOOR` of the square of the cell's longest edge: no cell is squeezed thinner than
~1 : 100 there.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

__all__ = ["hold_fans", "jacobi_targets", "shore_sweep", "sweep"]


@njit(cache=True, inline="always")
def _dist(X, Y, a, b):
    dx = X[b] - X[a]
    dy = Y[b] - Y[a]
    return math.sqrt(dx * dx + dy * dy)  # not math.hypot: a libm call, several times slower


#: With ``jmin``, the guard's second floor: no move may leave a corner Jacobian of a cell round
#: the node below this share of the square of the cell's longest edge (a cell thinner than about
#: 1 : 100 — its short edge a hundredth of its long one at right angles).  The floor ``jmin`` alone
#: (a thousandth of the mean area round the node) let an interior node slide to 0.08 m of a shore
#: node (aspect ratio 1 889) and rows of a block side squeeze into a land tip (439).  Only for the
#: nodes the driver marks (``thin``): everywhere, it changed the sweeps' path on lakes where no
#: cell ended thin and cost interface ratios (``docs/lake-grids-journal.md``, thin-cell guard).
ASPECT_FLOOR = 1e-2


@njit(cache=True, inline="always")
def _longest2(X, Y, cells, q):
    """The square of the longest edge of cell ``q``."""
    L = 0.0
    for k in range(4):
        a = cells[q, k]
        b = cells[q, (k + 1) % 4]
        dx = X[b] - X[a]
        dy = Y[b] - Y[a]
        L = max(L, dx * dx + dy * dy)
    return L


@njit(cache=True, nogil=True)
def _worst(X, Y, cptr, cells, node, out, thin):
    """The smallest corner Jacobian of each cell around ``node`` into ``out[:16]``, and (``thin``)
    the same less :data:`ASPECT_FLOOR` times the square of the cell's longest edge into
    ``out[16:]``."""
    for q in range(cptr[node], cptr[node + 1]):
        w = 1e300
        for k in range(4):
            p = cells[q, k]
            n = cells[q, (k + 1) % 4]
            m = cells[q, (k + 3) % 4]
            j = (X[n] - X[p]) * (Y[m] - Y[p]) - (Y[n] - Y[p]) * (X[m] - X[p])
            w = min(w, j)
        out[q - cptr[node]] = w
        if thin:
            out[16 + q - cptr[node]] = w - ASPECT_FLOOR * _longest2(X, Y, cells, q)


@njit(cache=True, inline="always")
def _valid(before, nc, floor):
    """Whether every one of a node's ``nc`` cells has its smallest corner Jacobian above ``floor``."""
    for q in range(nc):  # noqa: SIM110 -- a loop: numba compiles no generator in all()
        if before[q] <= floor:
            return False
    return True


@njit(cache=True, inline="always")
def _worse(before, after, q, floor, thin):
    """Whether cell ``q`` of a node's cells got worse below a floor (:func:`_worst`'s two
    readings before and after a move): its smallest corner Jacobian below ``floor`` and lower than
    before, or (``thin``) the cell thinner than :data:`ASPECT_FLOOR` allows and thinner than
    before.  ``thin`` is False round a node with a cell below ``floor`` (a fold being undone may
    thin a neighbour: unfolding comes first — with the thin rule there, a generated lake of narrow
    arms kept 6 folded cells)."""
    if after[q] <= floor and after[q] < before[q]:
        return True
    return thin and after[16 + q] <= 0.0 and after[16 + q] < before[16 + q]


@njit(cache=True, nogil=True)
def _all_above(X, Y, cptr, cells, node, floor, thin):
    """True when every corner Jacobian of the cells around ``node`` exceeds ``floor`` — plus,
    with ``thin``, :data:`ASPECT_FLOOR` times the square of the cell's longest edge."""
    for q in range(cptr[node], cptr[node + 1]):
        f = floor + ASPECT_FLOOR * _longest2(X, Y, cells, q) if thin else floor
        for k in range(4):
            p = cells[q, k]
            n = cells[q, (k + 1) % 4]
            m = cells[q, (k + 3) % 4]
            if (X[n] - X[p]) * (Y[m] - Y[p]) - (Y[n] - Y[p]) * (X[m] - X[p]) <= f:
                return False
    return True


@njit(cache=True, nogil=True)
def _try_move(X, Y, node, nx, ny, cptr, cells, jmin, before, after, thin):
    """Move ``node`` towards ``(nx, ny)``, halving the step up to four times, so that every
    cell around it keeps its smallest corner Jacobian above ``jmin[node]`` and (``thin``: the
    thin rule) stays no thinner than :data:`ASPECT_FLOOR` allows — or, for a cell that was
    already below, at least where it was (an invalid or thin cell may only get better;
    ``before``, ``after``: 32 numbers each).  Without ``thin`` (shore nodes, which follow the
    shore, and nodes the driver has not found by a thin cell) the fold rule alone holds it."""
    ox, oy = X[node], Y[node]
    dx, dy = nx - ox, ny - oy
    X[node], Y[node] = nx, ny
    if _all_above(X, Y, cptr, cells, node, jmin[node], thin):  # the usual case: one check
        return math.hypot(dx, dy)
    X[node], Y[node] = ox, oy
    _worst(X, Y, cptr, cells, node, before, thin)
    nc = cptr[node + 1] - cptr[node]
    thin = thin and _valid(before, nc, jmin[node])
    for _ in range(5):
        X[node], Y[node] = ox + dx, oy + dy
        _worst(X, Y, cptr, cells, node, after, thin)
        ok = True
        for q in range(nc):
            if _worse(before, after, q, jmin[node], thin):
                ok = False
                break
        if ok:
            return math.hypot(dx, dy)
        dx *= 0.5
        dy *= 0.5
    X[node], Y[node] = ox, oy
    return 0.0


@njit(cache=True, inline="always")
def _ramp(h1, h2, lo, hi):
    """0 while two consecutive edges ``h1, h2`` differ by a ratio up to ``lo``, rising
    linearly to 1 at the ratio ``hi``."""
    r = max(h1, h2) / min(h1, h2)
    if r <= lo:
        return 0.0
    return min(1.0, (r - lo) / (hi - lo))


@njit(cache=True, inline="always")
def _short(h1, h2, floor):
    """0 while both edges ``h1, h2`` are at least ``floor`` long, rising linearly to 1 where the
    shorter is half of it (``floor`` 0: always 0)."""
    h = min(h1, h2)
    if h >= floor:
        return 0.0
    return min(1.0, 2.0 * (floor - h) / floor)


@njit(cache=True, inline="always")
def _target(X, Y, p, e, w, n, s, ne, nw, se, sw, smooth, lo_x, lo_y, hi, floor, bx, by, relax):
    """The Ryskin–Leal position of node ``p``, its weights along each grid line blended
    ``smooth`` towards their mean — and further, up to the full mean, where the line's two
    edges at ``p`` differ by a ratio above ``lo_x`` (the e–w line) or ``lo_y`` (the n–s line;
    :func:`_ramp`), or where the shorter of them is under ``floor`` (:func:`_short`).

    The extra blend of each line is the node's state ``bx, by`` moved ``relax`` of the way
    to the current ramp value (``relax = 1``: the ramp itself); a relaxed state keeps a node
    from cycling between the orthogonal and the smoothing position.  Returns the position and
    the new states; ``(nan, nan, bx, by)`` when an edge at ``p`` has zero length."""
    he = _dist(X, Y, p, e)
    hw = _dist(X, Y, w, p)
    hn = _dist(X, Y, p, n)
    hs = _dist(X, Y, s, p)
    if he <= 0.0 or hw <= 0.0 or hn <= 0.0 or hs <= 0.0:
        return np.nan, np.nan, bx, by
    eta_e = 0.25 * (hn + hs + _dist(X, Y, e, ne) + _dist(X, Y, se, e))
    eta_w = 0.25 * (hn + hs + _dist(X, Y, w, nw) + _dist(X, Y, sw, w))
    xi_n = 0.25 * (he + hw + _dist(X, Y, n, ne) + _dist(X, Y, nw, n))
    xi_s = 0.25 * (he + hw + _dist(X, Y, s, se) + _dist(X, Y, sw, s))
    ae, aw, bn, bs = eta_e / he, eta_w / hw, xi_n / hn, xi_s / hs
    # blend with the symmetrised weights (equal spacing along each line: smoothness)
    am, bm = 0.5 * (ae + aw), 0.5 * (bn + bs)
    rx = bx + relax * (max(_ramp(he, hw, lo_x, hi), _short(he, hw, floor)) - bx)
    ry = by + relax * (max(_ramp(hn, hs, lo_y, hi), _short(hn, hs, floor)) - by)
    sx = smooth + (1.0 - smooth) * rx
    sy = smooth + (1.0 - smooth) * ry
    ae += sx * (am - ae)
    aw += sx * (am - aw)
    bn += sy * (bm - bn)
    bs += sy * (bm - bs)
    den = ae + aw + bn + bs
    return (
        (ae * X[e] + aw * X[w] + bn * X[n] + bs * X[s]) / den,
        (ae * Y[e] + aw * Y[w] + bn * Y[n] + bs * Y[s]) / den,
        rx,
        ry,
    )


@njit(cache=True, nogil=True)
def jacobi_targets(X, Y, nodes, nbr, smooth, lox, loy, hi, floor, tx, ty):
    """The update of every regular node from the same old positions (test oracle's twin;
    ``lox, loy``: each node's ``lo`` along its e–w and n–s lines)."""
    for k in range(len(nodes)):
        tx[k], ty[k], _, _ = _target(
            X,
            Y,
            nodes[k],
            nbr[k, 0],
            nbr[k, 1],
            nbr[k, 2],
            nbr[k, 3],
            nbr[k, 4],
            nbr[k, 5],
            nbr[k, 6],
            nbr[k, 7],
            smooth,
            lox[k],
            loy[k],
            hi,
            floor,
            0.0,
            0.0,
            1.0,
        )


@njit(cache=True, nogil=True)
def sweep(
    X,
    Y,
    nodes,
    nbr,
    irr_nodes,
    irr_ptr,
    irr_ring,
    cptr,
    cells,
    omega,
    smooth,
    lox,
    loy,
    hi,
    floor,
    bx,
    by,
    relax,
    jmin,
    thin,
):
    """One Gauss–Seidel sweep over the free interior nodes (``lox, loy``: each regular node's
    size-blend ``lo`` along its two lines; ``floor``: the edge length under which the blend rises
    too; ``bx, by``: its size-blend state, updated; see
    :func:`_target`; ``thin[node]``: the move guard's thin rule for that node, see
    :func:`_try_move`); returns the largest move."""
    big = 0.0
    before = np.empty(32)
    after = np.empty(32)
    for k in range(len(nodes)):
        p = nodes[k]
        tx, ty, bx[k], by[k] = _target(
            X,
            Y,
            p,
            nbr[k, 0],
            nbr[k, 1],
            nbr[k, 2],
            nbr[k, 3],
            nbr[k, 4],
            nbr[k, 5],
            nbr[k, 6],
            nbr[k, 7],
            smooth,
            lox[k],
            loy[k],
            hi,
            floor,
            bx[k],
            by[k],
            relax,
        )
        t = max(bx[k], by[k])
        if tx != tx:
            continue
        # where the size blend acts, no over-relaxation: the blended update is not the
        # linear one SOR's factor was chosen for, and over-relaxed it can oscillate
        w = omega - (omega - 1.0) * t if omega > 1.0 else omega
        ox, oy = X[p], Y[p]
        nx = ox + w * (tx - ox)
        ny = oy + w * (ty - oy)
        # the usual case of _try_move written here (the move kept at its one check): its call
        # with seven arrays cost more than the update itself (150 → 88 ns a node, bit for bit)
        X[p], Y[p] = nx, ny
        if _all_above(X, Y, cptr, cells, p, jmin[p], thin[p] != 0):
            big = max(big, math.hypot(nx - ox, ny - oy))
            continue
        X[p], Y[p] = ox, oy
        big = max(big, _try_move(X, Y, p, nx, ny, cptr, cells, jmin, before, after, thin[p] != 0))
    for k in range(len(irr_nodes)):
        p = irr_nodes[k]
        sx, sy = 0.0, 0.0
        cnt = irr_ptr[k + 1] - irr_ptr[k]
        for q in range(irr_ptr[k], irr_ptr[k + 1]):
            sx += X[irr_ring[q]]
            sy += Y[irr_ring[q]]
        d = _try_move(X, Y, p, sx / cnt, sy / cnt, cptr, cells, jmin, before, after, thin[p] != 0)
        big = max(big, d)
    return big


# The ring helpers below are inlined: the shore sweep calls them several times a node, and a call
# passing the ring's arrays cost ~20 % of the sweep (490 → 400 ns a shore node, bit for bit).
@njit(cache=True, inline="always")
def _segment(S, s0, n, u):
    """Index ``k`` (0 ≤ k < n) of the ring segment holding arc length ``u`` (0 ≤ u < total)."""
    a, b = 0, n
    while b - a > 1:
        m = (a + b) // 2
        if S[s0 + m] <= u:
            a = m
        else:
            b = m
    return a


#: Steps :func:`_segment_from` walks before it bisects (a shore node's arcs span a few cells,
#: a cell a few ring segments: the walk usually ends within ten).
WALK = 32


@njit(cache=True, inline="always")
def _segment_from(S, s0, n, u, hint):
    """:func:`_segment` found by walking from segment ``hint``, or by bisection after
    :data:`WALK` steps: the same index either way (the last ``k < n`` with ``S[k] <= u``, else 0).

    The ring searches of a shore node all fall near the node itself: a walk from its segment
    instead of eight bisections of the whole shore made the shore sweep 30 % cheaper on a
    100-block lake (11 000 ring points), bit for bit the same."""
    k = hint
    for _ in range(WALK):
        if S[s0 + k] > u:
            if k == 0:
                return 0
            k -= 1
        elif k + 1 < n and S[s0 + k + 1] <= u:
            k += 1
        else:
            return k
    return _segment(S, s0, n, u)


@njit(cache=True, inline="always")
def _ring_point(R, S, r0, s0, n, s, hint):
    """Point at arc length ``s`` (any real: the ring is closed) of ring ``R[r0:r0+n]`` (``hint``:
    a segment near it, see :func:`_segment_from`)."""
    total = S[s0 + n]
    u = s % total
    k = _segment_from(S, s0, n, u, hint)
    k1 = (k + 1) % n
    L = S[s0 + k + 1] - S[s0 + k]
    t = (u - S[s0 + k]) / L if L > 0 else 0.0
    return (
        R[r0 + k, 0] + t * (R[r0 + k1, 0] - R[r0 + k, 0]),
        R[r0 + k, 1] + t * (R[r0 + k1, 1] - R[r0 + k, 1]),
    )


@njit(cache=True, inline="always")
def _foot(R, S, r0, s0, n, qx, qy, sa, sb, hint):
    """Arc length (unwrapped, in ``[sa, sb]``) of the ring point nearest to ``q``."""
    total = S[s0 + n]
    base = math.floor(sa / total) * total
    k = _segment_from(S, s0, n, sa - base, hint)
    best_d, best_s = 1e300, sa
    for _ in range(n + 1):
        lo = base + S[s0 + k]
        hi = base + S[s0 + k + 1]
        if lo > sb:
            break
        ax, ay = R[r0 + k, 0], R[r0 + k, 1]
        k1 = k + 1 if k + 1 < n else 0
        dx, dy = R[r0 + k1, 0] - ax, R[r0 + k1, 1] - ay
        L2 = dx * dx + dy * dy
        t = ((qx - ax) * dx + (qy - ay) * dy) / L2 if L2 > 0 else 0.0
        t = min(max(t, 0.0), 1.0)
        st = lo + t * (hi - lo)
        if st < sa:
            st = sa
        elif st > sb:
            st = sb
        # the point at st on this segment (st within [lo, hi] unless clamped to the window)
        u = (st - lo) / (hi - lo) if hi > lo else 0.0
        u = min(max(u, 0.0), 1.0)
        px, py = ax + u * dx, ay + u * dy
        d = (px - qx) ** 2 + (py - qy) ** 2
        if d < best_d:
            best_d, best_s = d, st
        k += 1
        if k == n:
            k = 0
            base += total
    return best_s


@njit(cache=True, inline="always")
def _gap(R, S, r0, s0, n, sa, sb, ax, ay, bx, by, hint):
    """How far the shore between arc lengths ``sa < sb`` strays from the straight edge a–b:
    the largest distance of a shore vertex in between from that segment."""
    total = S[s0 + n]
    dx, dy = bx - ax, by - ay
    L2 = dx * dx + dy * dy
    worst = 0.0
    base = math.floor(sa / total) * total
    k = _segment_from(S, s0, n, sa - base, hint) + 1
    for _ in range(n + 1):
        if k >= n:
            k -= n
            base += total
        sv = base + S[s0 + k]
        if sv >= sb:
            break
        px, py = R[r0 + k, 0], R[r0 + k, 1]
        t = ((px - ax) * dx + (py - ay) * dy) / L2 if L2 > 0 else 0.0
        t = min(max(t, 0.0), 1.0)
        ex, ey = px - ax - t * dx, py - ay - t * dy
        d = ex * ex + ey * ey
        if d > worst:
            worst = d
        k += 1
    return math.sqrt(worst)


@njit(cache=True, inline="always")
def _bend(R, S, r0, s0, n, sp, s, sn, px, py, x, y, qx, qy, limit, hint):
    """How far the shore next to a node strays from its two grid edges beyond ``limit``
    (≤ 0: both edges follow the shore closely enough)."""
    g1 = _gap(R, S, r0, s0, n, sp, s, px, py, x, y, hint)
    g2 = _gap(R, S, r0, s0, n, s, sn, x, y, qx, qy, hint)
    return max(g1, g2) - limit


@njit(cache=True, inline="always")
def _window(a, b, c, d):
    """``[a, b] ∩ [c, d]``; when they do not meet, the point halfway between the two gaps' ends."""
    lo_ = max(a, c)
    hi_ = min(b, d)
    if lo_ > hi_:
        m = 0.5 * (lo_ + hi_)
        return m, m
    return lo_, hi_


@njit(cache=True, nogil=True)
def shore_sweep(
    X,
    Y,
    free,
    bnode,
    binner,
    bprev,
    bnext,
    bring,
    bs,
    R,
    S,
    roff,
    cptr,
    cells,
    omega,
    mu,
    gap,
    jmin,
    lo,
    hi,
    floor,
    bz,
    relax,
    across,
    blo,
    thin,
):
    """Slide the free shore nodes (indices ``free`` into the shore arrays) towards the foot of
    the perpendicular from their inward neighbour, between their two shore neighbours, pulled
    ``mu`` towards the middle of the two — more where the two arcs differ by a ratio above
    ``lo`` or where the shorter is under ``floor`` (state ``bz`` per free node, as in
    :func:`_target`) — and never so far that they
    differ by more than ``lo``.  Next to a cut line's end on the shore (``across[k]``: the shore
    node beyond that end, before and after, or -1) the arc to the end also stays within ``lo`` of
    the arc beyond it (where both limits cannot hold, halfway between them, but never nearer
    either neighbour than a tenth of the arc between the two).  ``blo[f]`` is the
    ratio that free node ``f`` keeps instead of ``lo`` (larger at a cut's end where both blocks
    have a corner: its two arcs lie in two blocks; ``thin[node]``: the thin rule, as in
    :func:`sweep`); returns the largest move."""
    big = 0.0
    before = np.empty(32)
    after = np.empty(32)
    for f in range(len(free)):
        k = free[f]
        p = bnode[k]
        r = bring[k]
        r0 = roff[r]
        n = roff[r + 1] - r0
        s0 = r0 + r
        total = S[s0 + n]
        s = bs[k]
        sp = bs[bprev[k]]
        sn = bs[bnext[k]]
        while sp > s:
            sp -= total
        while sp <= s - total:
            sp += total
        while sn < s:
            sn += total
        while sn >= s + total:
            sn -= total
        if sn - sp > 0.75 * total:
            # its neighbours are not on its two sides along the shore (round a spike of water
            # narrower than a cell, nodes on its two flanks projected onto one: a neighbour a little
            # ahead of the node where it should be behind, and the arc between them a whole perimeter
            # less that little): measured so, the node's arc would run round the whole ring, and the
            # foot or the middle of that arc lie anywhere on it (generated `dendritic(952505)` at
            # 15 000 cells: a node thrown 190 cells along the shore, one edge across the land).  It
            # stays where it is.  (A node truly between its neighbours has an arc that long only
            # where they hold three quarters of its ring: a ring of a few nodes, unevenly spread.)
            continue
        # the node stays far enough from both neighbours that its two arcs differ by at most
        # ``lo`` (the smoothness limit): sliding to the foot of the perpendicular, shore nodes
        # next to an obtuse block corner otherwise crowd into it, each arc 1.7 times the next
        lk = blo[f]  # ``lo``, or more at a cut's end where both blocks have a corner
        margin = (sn - sp) * max(0.1, 1.0 / (1.0 + lk))
        wa, wb = sp + margin, sn - margin
        # next to a cut line's end (``across``: the shore node beyond it), the edge to that end
        # within ``lo`` of the edge beyond it: the first cells on the two sides of the cut alike
        if across[k, 0] >= 0:
            out = (sp - bs[across[k, 0]]) % total
            wa, wb = _window(wa, wb, sp + out / lo, sp + out * lo)
        if across[k, 1] >= 0:
            out = (bs[across[k, 1]] - sn) % total
            wa, wb = _window(wa, wb, sn - out * lo, sn - out / lo)
        # and never nearer a neighbour than a tenth of the arc between them: where the two ends'
        # limits cannot both hold, halfway between them can lie beyond a neighbour — past a cut's
        # end, from where the next sweep's arc runs the other way round the ring
        edge = 0.1 * (sn - sp)
        wa = min(max(wa, sp + edge), sn - edge)
        wb = min(max(wb, sp + edge), sn - edge)
        q = binner[k]
        hint = _segment(S, s0, n, s % total)  # the node's own segment: the searches below start there
        sf = _foot(R, S, r0, s0, n, X[q], Y[q], wa, wb, hint)
        # a pull to the middle keeps the spacing: a little, more where the spacing jumps
        a1, a2 = s - sp, sn - s
        if a1 > 0.0 and a2 > 0.0:
            bz[f] += relax * (max(_ramp(a1, a2, lk, max(hi, 1.01 * lk)), _short(a1, a2, floor)) - bz[f])
        m = mu + (1.0 - mu) * bz[f]
        sf = (1.0 - m) * sf + m * 0.5 * (sp + sn)
        # the shore between a node and its neighbours must stay within ``gap`` of the straight
        # edges between them: a node may not slide past a bay or a point
        ppx, ppy = _ring_point(R, S, r0, s0, n, sp, hint)
        pnx, pny = _ring_point(R, S, r0, s0, n, sn, hint)
        bad0 = _bend(R, S, r0, s0, n, sp, s, sn, ppx, ppy, X[p], Y[p], pnx, pny, gap, hint)
        if bad0 > 0.0:  # already too far from the shore: head for the middle of the arc
            sf = 0.5 * (sp + sn)
        ox, oy = X[p], Y[p]
        tp = thin[p] != 0
        step = omega * (sf - s)
        moved = False
        for _ in range(5):
            snew = s + step
            nx, ny = _ring_point(R, S, r0, s0, n, snew, hint)
            bad = _bend(R, S, r0, s0, n, sp, snew, sn, ppx, ppy, nx, ny, pnx, pny, gap, hint)
            if bad <= max(bad0, 0.0):
                X[p], Y[p] = nx, ny
                ok = _all_above(X, Y, cptr, cells, p, jmin[p], tp)
                if not ok:
                    X[p], Y[p] = ox, oy
                    _worst(X, Y, cptr, cells, p, before, tp)
                    X[p], Y[p] = nx, ny
                    _worst(X, Y, cptr, cells, p, after, tp)
                    ok = True
                    # the fold rule, and the thin rule only where the driver marked the node:
                    # a shore node follows the shore (the rule on every shore node held a
                    # generated network's grid 0.51 cells off a tip)
                    tq = tp and _valid(before, cptr[p + 1] - cptr[p], jmin[p])
                    for qq in range(cptr[p + 1] - cptr[p]):
                        if _worse(before, after, qq, jmin[p], tq):
                            ok = False
                if ok:
                    bs[k] = snew % total
                    big = max(big, math.hypot(nx - ox, ny - oy))
                    moved = True
                    break
                X[p], Y[p] = ox, oy
            step *= 0.5
        if not moved:
            X[p], Y[p] = ox, oy
            # off the shore (a new node the refinement could not put on it without folding a
            # cell): as far towards its own shore point as the cells around it allow, so the
            # grid inside follows it there over the sweeps instead of holding it where it is
            tx, ty = _ring_point(R, S, r0, s0, n, s, hint)
            if (tx - ox) ** 2 + (ty - oy) ** 2 > (1e-3 * gap) ** 2:
                big = max(big, _try_move(X, Y, p, tx, ty, cptr, cells, jmin, before, after, tp))
    return big


@njit(cache=True, inline="always")
def _fan_angles(w, corner, a0, m):
    """The angles of the ``m`` cells round a cut end whose water angle is ``w``: a cell that is its
    block's corner (``corner[a0 + q]``) a right angle, or half the water angle shared among those
    corners where that is less; the other cells (two per block whose side passes) share the rest."""
    nc = 0
    for q in range(m):
        if corner[a0 + q]:
            nc += 1
    if nc == 0 or nc == m:
        return w / m, w / m
    ac = min(0.5 * math.pi, 0.5 * w / nc)
    return ac, (w - nc * ac) / (m - nc)


@njit(cache=True, nogil=True)
def hold_fans(X, Y, ends, fptr, fan, corner, cptr, cells, jmin, least, slack, lo, thin):
    """Keep the grid lines that leave each cut line's end on the shore near set angles:
    ``fan[fptr[k]:fptr[k + 1]]`` are the neighbours of ``ends[k]`` in counter-clockwise order, a
    shore node first and last, the nodes of the lines into the water between; the cell between
    lines ``q`` and ``q + 1`` is meant to get the angle :func:`_fan_angles` gives it
    (``corner[fptr[k] + q]``: it is the only cell of its block there).  A line more than
    ``slack`` times the mean cell angle off its place is turned about the end back to that
    distance, and no line is shorter than the shore edges at the end (their geometric mean) over
    ``lo``.  Ends whose water angle is below ``least`` are left alone.  Moves are guarded as
    :func:`_try_move` (``thin[node]``: the thin rule); returns the largest."""
    big = 0.0
    before = np.empty(32)
    after = np.empty(32)
    for k in range(len(ends)):
        c = ends[k]
        a0 = fptr[k]
        m = fptr[k + 1] - a0 - 1  # cells at the end
        ax, ay = X[fan[a0]] - X[c], Y[fan[a0]] - Y[c]
        bx, by = X[fan[a0 + m]] - X[c], Y[fan[a0 + m]] - Y[c]
        w = math.atan2(ax * by - ay * bx, ax * bx + ay * by)
        if w <= 0.0:
            w += 2.0 * math.pi
        if w < least:
            continue
        ac, aside = _fan_angles(w, corner, a0, m)
        t0 = math.atan2(ay, ax)
        band = slack * w / m
        short = math.sqrt(math.sqrt((ax * ax + ay * ay) * (bx * bx + by * by))) / lo
        tau = 0.0
        for q in range(1, m):
            tau += ac if corner[a0 + q - 1] else aside
            p = fan[a0 + q]
            dx, dy = X[p] - X[c], Y[p] - Y[c]
            r = math.sqrt(dx * dx + dy * dy)
            phi = math.atan2(ax * dy - ay * dx, ax * dx + ay * dy)  # from line 0, counter-clockwise
            if phi < 0.0:
                phi += 2.0 * math.pi
            off = phi - tau
            if abs(off) <= band and r >= short:
                continue
            phi = tau + min(max(off, -band), band)
            r = max(r, short)
            d = _try_move(
                X,
                Y,
                p,
                X[c] + r * math.cos(t0 + phi),
                Y[c] + r * math.sin(t0 + phi),
                cptr,
                cells,
                jmin,
                before,
                after,
                thin[p] != 0,
            )
            big = max(big, d)
    return big
