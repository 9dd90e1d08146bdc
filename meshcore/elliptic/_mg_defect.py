r"""Defects of the multigrid (FAS) equations and the coarse right-hand side (numba).

``N(u) = 2(α + γ) φ_P − s(φ)`` (:func:`._stencil.winslow`), ``N = −(α φ_ξξ −
2β φ_ξη + γ φ_ηη + D²(P φ_ξ + Q φ_η))``; the defect is ``r = f − N(u)``.  The
largest ``|N(u)|/den`` with ``f = 0`` is exactly the shared stopping measure
(the point-Jacobi displacement of :func:`._kernels.jacobi_residual`).
:func:`defect_restrict` computes the defect row by row and restricts it at
once (no fine defect arrays); :func:`add_operator` adds ``N_c(R̂u)`` to a
coarse right-hand side.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from ._compile import ROW_CHUNKS, parallel, serial
from ._stencil import winslow_at, with_sources

__all__ = [
    "add_operator",
    "add_operator_parallel",
    "defect",
    "defect_parallel",
    "defect_restrict",
    "defect_restrict_parallel",
]


@njit(cache=True, nogil=True)
def _defect_row(
    x, y, fx, fy, p, q, use_f, use_pq, i, iw, nj1, outx, outy, tx, ty, tq, td, measure=True
):  # pragma: no cover - compiled
    """Defect of row ``i`` into ``outx, outy`` (length ``nj1``, 0 at both ends); returns the
    row's largest ``(|f − N|/den)²`` (``inf`` on NaN; 0 without ``measure``).  ``tx … td``
    are scratch rows whose end entries are 0 (fresh, so the unit-stride loop vectorises)."""
    ie = i + 1
    for j in range(1, nj1 - 1):
        sx, sy, den, xxi, yxi, xet, yet = winslow_at(x, y, i, iw, ie, j)
        if use_pq:
            sx, sy = with_sources(sx, sy, xxi, yxi, xet, yet, p[i, j], q[i, j])
        dx = sx - den * x[i, j]
        dy = sy - den * y[i, j]
        if use_f:
            dx += fx[i, j]
            dy += fy[i, j]
        tx[j] = dx
        ty[j] = dy
        if measure:
            tq[j] = dx * dx + dy * dy
            td[j] = den * den
    m = 0.0
    for j in range(nj1):
        outx[j] = tx[j]
        outy[j] = ty[j]
    if not measure:
        return m
    for j in range(nj1):
        if td[j] > 0.0 and tq[j] > m * td[j]:  # (dx² + dy²)/den² > m, divided only when true
            m = tq[j] / td[j]
    nan = 0
    for j in range(nj1):  # NaN (also from a NaN den) is never a silent pass
        nan += tq[j] != tq[j]
    return m if nan == 0 else np.inf


@njit(cache=True, nogil=True)
def _scratch_rows(nj1):  # pragma: no cover - compiled
    """Four fresh scratch rows for :func:`_defect_row` (end entries 0)."""
    tx = np.empty(nj1)
    ty = np.empty(nj1)
    tq = np.empty(nj1)
    td = np.empty(nj1)
    for e in (0, nj1 - 1):
        tx[e] = 0.0
        ty[e] = 0.0
        tq[e] = 0.0
        td[e] = 0.0
    return tx, ty, tq, td


@njit(cache=True, nogil=True)
def _defect_rows(
    x, y, fx, fy, p, q, use_f, use_pq, i0, ni, nj1, nrows, nchunks, c, rx, ry, row_max
):  # pragma: no cover - compiled
    """Rows of chunk ``c`` of :func:`_defect` (a separate function, so that the
    serial and parallel compilations run the same vectorised machine code)."""
    tx, ty, tq, td = _scratch_rows(nj1)
    for k in range(c * nrows // nchunks, (c + 1) * nrows // nchunks):
        i = i0 + k
        iw = i - 1
        if iw < 0:
            iw = ni - 1
        row_max[i] = _defect_row(x, y, fx, fy, p, q, use_f, use_pq, i, iw, nj1, rx[i], ry[i], tx, ty, tq, td)


def _defect(x, y, fx, fy, p, q, periodic, rx, ry):  # pragma: no cover - compiled
    """``r = f − N(u)`` at interior nodes (0 on the boundary); returns max (|f−N|/den)².

    With ``f = 0`` the square root of the return value is the stopping measure
    (``inf`` if any node gives NaN, as :func:`._kernels.jacobi_residual`).
    Each row is computed into local scratch rows (unit stride, no aliasing:
    the loop vectorises) and then stored; the maximum is a separate loop.
    """
    ni1, nj1 = x.shape
    use_f = fx.size > 0
    use_pq = p.size > 0
    ni = ni1 - 1
    i0 = 0 if periodic else 1
    row_max = np.zeros(ni1)
    for j in range(nj1):
        rx[0, j] = 0.0
        ry[0, j] = 0.0
        rx[ni, j] = 0.0
        ry[ni, j] = 0.0
    nrows = ni - i0
    nchunks = min(nrows, ROW_CHUNKS)
    for c in prange(nchunks):
        _defect_rows(x, y, fx, fy, p, q, use_f, use_pq, i0, ni, nj1, nrows, nchunks, c, rx, ry, row_max)
    if periodic:
        for j in range(nj1):
            rx[ni, j] = rx[0, j]
            ry[ni, j] = ry[0, j]
    return row_max.max()


@njit(cache=True, nogil=True)
def _add_operator_rows(x, y, p, q, use_pq, ni, nj1, fx, fy, lo, hi):  # pragma: no cover
    """Rows ``lo ≤ i < hi`` of :func:`_add_operator`: ``f −= (f = 0 defect)``, which is
    ``f += N(u)`` exactly (IEEE negation)."""
    tx, ty, tq, td = _scratch_rows(nj1)
    ox = np.empty(nj1)
    oy = np.empty(nj1)
    e = np.zeros((0, 0))
    for i in range(lo, hi):
        iw = i - 1
        if iw < 0:
            iw = ni - 1
        _defect_row(x, y, e, e, p, q, False, use_pq, i, iw, nj1, ox, oy, tx, ty, tq, td, False)
        for j in range(1, nj1 - 1):
            fx[i, j] -= ox[j]
            fy[i, j] -= oy[j]


def _add_operator(x, y, p, q, periodic, fx, fy):  # pragma: no cover - compiled
    """``f += N(u)`` at interior nodes (the FAS coarse right-hand side)."""
    ni1, nj1 = x.shape
    use_pq = p.size > 0
    ni = ni1 - 1
    i0 = 0 if periodic else 1
    nrows = ni - i0
    nchunks = min(nrows, ROW_CHUNKS)
    for c in prange(nchunks):
        _add_operator_rows(
            x, y, p, q, use_pq, ni, nj1, fx, fy, i0 + c * nrows // nchunks, i0 + (c + 1) * nrows // nchunks
        )
    if periodic:
        for j in range(nj1):
            fx[ni, j] = fx[0, j]
            fy[ni, j] = fy[0, j]


#: Fine rows held by a chunk of :func:`_defect_restrict` (a coarse row needs ≤ 4).
RING = 6


@njit(cache=True, nogil=True)
def _defect_restrict_rows(
    x, y, fx, fy, p, q, use_f, use_pq, ii, wi, jj, wj, scale, fxc, fyc, lo, hi
):  # pragma: no cover - compiled
    """Coarse rows ``lo ≤ I < hi`` of :func:`_defect_restrict`; returns the largest
    ``(|f − N|/den)²`` of the fine rows it computed."""
    ni1, nj1 = x.shape
    ni = ni1 - 1
    tx, ty, tq, td = _scratch_rows(nj1)
    ringx = np.empty((RING, nj1))
    ringy = np.empty((RING, nj1))
    held = np.full(RING, -1, dtype=np.int64)
    slot = np.empty(ii.shape[1], dtype=np.int64)
    m = 0.0
    nJ = fxc.shape[1]
    for I in range(lo, hi):
        for a in range(ii.shape[1]):
            i = ii[I, a]
            s = i % RING
            slot[a] = s
            if held[s] != i:
                held[s] = i
                if i == 0 or i == ni:  # boundary rows: no defect
                    for j in range(nj1):
                        ringx[s, j] = 0.0
                        ringy[s, j] = 0.0
                else:
                    mm = _defect_row(
                        x, y, fx, fy, p, q, use_f, use_pq, i, i - 1, nj1, ringx[s], ringy[s], tx, ty, tq, td
                    )
                    if mm > m:
                        m = mm
        # the arithmetic of _restrict_rows, reading the ring instead of r
        if ii.shape[1] == 3 and jj.shape[1] == 3:
            for J in range(nJ):
                sx = 0.0
                sy = 0.0
                for a in range(3):
                    w_a = wi[I, a]
                    sa = slot[a]
                    for b in range(3):
                        w = w_a * wj[J, b]
                        jb = jj[J, b]
                        sx += w * ringx[sa, jb]
                        sy += w * ringy[sa, jb]
                fxc[I, J] = scale * sx
                fyc[I, J] = scale * sy
        else:
            for J in range(nJ):
                sx = 0.0
                sy = 0.0
                for a in range(ii.shape[1]):
                    w_a = wi[I, a]
                    sa = slot[a]
                    for b in range(jj.shape[1]):
                        w = w_a * wj[J, b]
                        jb = jj[J, b]
                        sx += w * ringx[sa, jb]
                        sy += w * ringy[sa, jb]
                fxc[I, J] = scale * sx
                fyc[I, J] = scale * sy
    return m


def _defect_restrict(x, y, fx, fy, p, q, ii, wi, jj, wj, scale, fxc, fyc, chunks):  # pragma: no cover - compiled
    """:func:`_defect` followed by :func:`_restrict`, without the fine defect arrays.

    Each chunk of coarse rows computes the fine defect rows its full-weighting
    stencils need into a small ring buffer (rows shared by two chunks are
    computed by both, with the same result) and restricts them at once: the
    same numbers as ``defect`` + ``restrict`` bit for bit, without writing and
    re-reading two fine arrays (the largest memory stream of a cycle on big
    grids).  Not periodic (the seam's stencil wraps around).  ``chunks``:
    at most this many independent chunks (1 for the serial kernel: one ring,
    no recomputed rows).  Returns the largest ``(|f − N|/den)²`` as
    :func:`_defect`.
    """
    use_f = fx.size > 0
    use_pq = p.size > 0
    nI = fxc.shape[0]
    nchunks = max(1, min(nI, chunks))
    cmax = np.zeros(nchunks)
    for c in prange(nchunks):
        cmax[c] = _defect_restrict_rows(
            x,
            y,
            fx,
            fy,
            p,
            q,
            use_f,
            use_pq,
            ii,
            wi,
            jj,
            wj,
            scale,
            fxc,
            fyc,
            c * nI // nchunks,
            (c + 1) * nI // nchunks,
        )
    return cmax.max()


defect = serial(_defect)
defect_parallel = parallel(_defect)
add_operator = serial(_add_operator)
add_operator_parallel = parallel(_add_operator)
defect_restrict = serial(_defect_restrict)
defect_restrict_parallel = parallel(_defect_restrict)
