r"""Compiled kernels of :func:`~meshcore.layout.corners.choose_corners`: the same numbers, faster.

A layout draw costs thousands of candidate pieces (:mod:`.split`), and choosing each one's corners
in NumPy took ~0.1–0.3 ms, most of it the overhead of some forty small array operations (a tenth of
a lake's CPU, session 45).  Here the same steps run in two kernels with NumPy's own arithmetic, so
that every corner and cost is **the same to the last bit** as the NumPy functions of
:mod:`.corners`, which stay the reference (``tests/meshcore/test_corner_kernels.py``): sums are
NumPy's pairwise sums (:func:`_pw`), the interpolation is ``np.interp``, and the two things numba
would compute differently stay with NumPy in the caller — ``np.arctan2`` (NumPy's own SIMD
routine, not libm's) of the cross and dot products made here, and the sort of the turning.

* :func:`ring_terms` — arc length at every vertex, the perimeter, and the cross and dot products
  whose angles are the turning at scale (:func:`~.corners.turning`) and between the two edges
  (:func:`~.corners.raw_turning`);
* :func:`choose` — the sharp peaks (:func:`~.corners._sharp_peaks`), moved to where the boundary
  itself bends (:func:`~.corners._where_they_bend`), the missing corners on the smooth stretches
  (:func:`~.corners._smooth_corners`), and the corner term of the cost (:func:`~.corners.corner_cost`).
"""

from __future__ import annotations

import numpy as np
from numba import njit

SHARP = 30.0  # = corners.SHARP, a copy: importing it makes an import cycle (tests/test_imports.py); asserted equal


@njit(cache=True)
def _leaf(a, lo, n):
    """NumPy's pairwise sum of ``a[lo:lo + n]`` for ``n`` ≤ 128: eight running sums."""
    if n < 8:
        res = 0.0
        for i in range(n):
            res += a[lo + i]
        return res
    r0, r1, r2, r3 = a[lo], a[lo + 1], a[lo + 2], a[lo + 3]
    r4, r5, r6, r7 = a[lo + 4], a[lo + 5], a[lo + 6], a[lo + 7]
    i = 8
    m = n - n % 8
    while i < m:
        r0 += a[lo + i]
        r1 += a[lo + i + 1]
        r2 += a[lo + i + 2]
        r3 += a[lo + i + 3]
        r4 += a[lo + i + 4]
        r5 += a[lo + i + 5]
        r6 += a[lo + i + 6]
        r7 += a[lo + i + 7]
        i += 8
    res = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
    while i < n:
        res += a[lo + i]
        i += 1
    return res


@njit(cache=True)
def _pw(a, lo, n):
    """NumPy's pairwise sum of ``a[lo:lo + n]`` (its ``pairwise_sum``: above 128 the two halves, the
    first a multiple of 8 long, summed alike and added), the same bits.  Its recursion walked
    with a stack of its own: numba's cache loaded a recursive kernel that crashed."""
    if n <= 128:
        return _leaf(a, lo, n)
    starts = np.empty(64, np.int64)
    sizes = np.empty(64, np.int64)
    phase = np.zeros(64, np.int64)  # 0: new, 1: its first half summed, 2: both
    first = np.empty(64)
    top = 0
    starts[0], sizes[0] = lo, n
    ret = 0.0
    while top >= 0:
        m = sizes[top]
        if m <= 128:
            ret = _leaf(a, starts[top], m)
            top -= 1
            continue
        half = m // 2
        half -= half % 8
        if phase[top] == 0:
            phase[top] = 1
            top += 1
            starts[top], sizes[top], phase[top] = starts[top - 1], half, 0
        elif phase[top] == 1:
            first[top] = ret
            phase[top] = 2
            top += 1
            starts[top], sizes[top], phase[top] = starts[top - 1] + half, m - half, 0
        else:
            ret = first[top] + ret
            top -= 1
    return ret


@njit(cache=True)
def _sum(a):
    """``a.sum()`` of a 1-D float array, bit for bit (the reduction starts from 0)."""
    return 0.0 + _pw(a, 0, len(a))


@njit(cache=True, inline="always")
def _cross_dot(ax, ay, bx, by, out, i):
    """``out[:, i]``: the cross and dot products of ``a`` and ``b`` (the dot as NumPy's sum of two)."""
    dot = 0.0
    dot += ax * bx
    dot += ay * by
    out[0, i] = ax * by - ay * bx
    out[1, i] = 0.0 + dot


@njit(cache=True)
def ring_terms(ring, sigma):
    """``(s, total, at_scale, between)`` of a closed ring ``(n, 2)``: arc length at every vertex, the
    perimeter, and ``(2, n)`` cross and dot products whose ``degrees(arctan2(cross, dot))`` are
    :func:`~.corners.turning` at ``sigma`` and :func:`~.corners.raw_turning`."""
    n = len(ring)
    d = np.empty((n, 2))
    for i in range(n - 1):
        d[i, 0] = ring[i + 1, 0] - ring[i, 0]
        d[i, 1] = ring[i + 1, 1] - ring[i, 1]
    d[n - 1, 0] = ring[0, 0] - ring[n - 1, 0]
    d[n - 1, 1] = ring[0, 1] - ring[n - 1, 1]
    seg = np.hypot(d[:, 0], d[:, 1])
    s = np.empty(n)
    s[0] = 0.0
    acc = 0.0
    for i in range(n - 1):
        acc += seg[i]
        s[i + 1] = acc
    total = _sum(seg)
    sg = min(sigma, 0.25 * total)
    # the points sg behind and ahead of every vertex, interpolated along three copies of the ring
    xs = np.concatenate((s - total, s, s + total))
    q = np.concatenate((s - sg, s + sg))
    x = np.interp(q, xs, np.concatenate((ring[:, 0], ring[:, 0], ring[:, 0])))
    y = np.interp(q, xs, np.concatenate((ring[:, 1], ring[:, 1], ring[:, 1])))
    at_scale = np.empty((2, n))
    between = np.empty((2, n))
    for i in range(n):
        _cross_dot(ring[i, 0] - x[i], ring[i, 1] - y[i], x[n + i] - ring[i, 0], y[n + i] - ring[i, 1], at_scale, i)
        k = i - 1 if i > 0 else n - 1
        _cross_dot(d[k, 0], d[k, 1], d[i, 0], d[i, 1], between, i)
    return s, total, at_scale, between


@njit(cache=True)
def _smooth(raw, a, b, m, out, nout):
    """:func:`~.corners._smooth_corners`: ``m`` corners strictly between ``a`` and ``b`` appended to
    ``out[:nout]``; the new count, or -1 when the stretch has fewer than ``m`` vertices."""
    n = len(raw)
    span = (b - a) % n
    size = (span if span else n) - 1
    if size < m:
        return -1
    idx = np.empty(size, np.int64)
    cum = np.empty(size)
    acc = 0.0
    for k in range(size):
        v = (a + 1 + k) % n
        idx[k] = v
        acc += max(raw[v], 0.0)
        cum[k] = acc
    total = cum[size - 1] if size else 0.0
    start = nout
    for k in range(m):
        level = (k + 0.5) / m * total
        j = np.searchsorted(cum, level) if total > 0 else int((k + 0.5) / m * size)
        j = min(max(j, 0), size - 1)
        while j + 1 < size:  # the next vertex if this call took this one already
            taken = False
            for q in range(start, nout):
                if out[q] == idx[j]:
                    taken = True
            if not taken:
                break
            j += 1
        out[nout] = idx[j]
        nout += 1
    return nout


@njit(cache=True)
def choose(s, total, t, raw, order, forced, sigma):
    """``(picks, corner term)`` of :func:`~.corners.choose_corners`: the distinct corner indices in
    increasing order and, if there are four, :func:`~.corners.corner_cost` of them (``t``, ``raw``:
    the turning at ``sigma`` and between the edges; ``order``: ``argsort(-t)`` with the ``forced``
    vertices first, as NumPy sorts it)."""
    n = len(t)
    # the sharp peaks, the most turning first, at most one within sig of arc length
    sig = min(sigma, 0.1 * total)
    taken = np.empty(4, np.int64)
    nt = 0
    for i in order:
        if (1e9 if forced[i] else t[i]) < 45.0:
            break
        ok = True
        for q in range(nt):
            dd = abs(s[i] - s[taken[q]])
            if not min(dd, total - dd) > sig:
                ok = False
                break
        if ok:
            taken[nt] = i
            nt += 1
            if nt >= 4:
                break
    # each moved to the vertex within half a sigma where the boundary itself turns most
    reach = 0.5 * sigma
    picks = np.empty(8, np.int64)
    for q in range(nt):
        i = taken[q]
        if forced[i]:
            picks[q] = i
            continue
        best = -np.inf
        jk = -1
        for v in range(n):
            dd = abs(s[v] - s[i])
            val = raw[v] if min(dd, total - dd) <= reach else -np.inf
            if jk < 0 or val > best:
                best = val
                jk = v
        picks[q] = jk if raw[jk] > max(raw[i], SHARP) else i
    count = nt
    if count < 4:  # the missing corners on the smooth stretches, by their share of the turning
        p = np.sort(picks[:count])
        out = np.empty(8, np.int64)
        out[:count] = p
        nout = count
        if count == 0:
            nout = max(_smooth(raw, 0, 0, 4, out, 0), 0)
        else:
            turn = np.empty(count)
            for q in range(count):
                a, b = p[q], p[(q + 1) % count]
                span = (b - a) % n
                g = np.empty((span if span else n) - 1)
                for k in range(len(g)):
                    g[k] = max(raw[(a + 1 + k) % n], 0.0)
                turn[q] = _sum(g)
            share = np.zeros(count, np.int64)
            for _ in range(4 - count):
                w = -1
                bw = 0.0
                for q in range(count):
                    v = turn[q] / (share[q] + 1)
                    if w < 0 or v > bw:
                        bw = v
                        w = q
                share[w] += 1
            for q in range(count):
                if share[q]:
                    nout = max(_smooth(raw, p[q], p[(q + 1) % count], share[q], out, nout), nout)
        picks = out
        count = nout
    u = np.unique(picks[:count])
    if len(u) != 4:
        return u, 0.0
    # the corner term: (t - 90)^2 per corner, steeper below 60 degrees, and t^2 of every sharp
    # vertex not within sigma of a corner
    skip = np.zeros(n, np.bool_)
    for q in range(4):
        for v in range(n):
            dd = abs(s[v] - s[u[q]])
            if v == u[q] or min(dd, total - dd) < sigma:
                skip[v] = True
    at = np.empty(4)
    for q in range(4):
        tc = t[u[q]]
        e = tc - 90.0
        at[q] = e * e * (1.0 + 2.0 * min(max(60.0 - tc, 0.0), 60.0) / 60.0)
    side = np.empty(n)
    ns = 0
    for v in range(n):
        if not skip[v] and abs(t[v]) > SHARP:
            side[ns] = t[v] * t[v]
            ns += 1
    return u, _sum(at) + _sum(side[:ns])
