"""numba kernels of the multigrid set-up (:mod:`.hierarchy`; functions only).

The set-up runs once per block structure, but on the first solve of a lake
layout its per-block NumPy calls cost as much as the solve; these two loops do
the same work in one call each.  NumPy references (test oracles):
:func:`.hierarchy._block_interp`, :func:`.hierarchy.greedy_reference`,
:func:`.hierarchy.lines_reference` (:func:`block_lines`) and
:func:`.hierarchy.near_reference` (:func:`grow_near`: the band of each level; the rows round a
cycle's hot spots grow from the seeds instead, :func:`._kernels.grow_rows`, tested against it).
"""

from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["greedy_drop", "grow_near", "interp_coo"]


@njit(cache=True, nogil=True)
def greedy_drop(cls, line_ptr, adj_ptr, adj, state):  # pragma: no cover - compiled
    """Decide the undecided position classes (``state`` 0 → 1 kept / 2 dropped, in place): line
    by line (line ``L`` is ``cls[line_ptr[L]:line_ptr[L + 1]]``), every inner position whose
    class is undecided is kept if a neighbouring class is dropped, else dropped."""
    for L in range(line_ptr.shape[0] - 1):
        for t in range(line_ptr[L] + 1, line_ptr[L + 1] - 1):
            q = cls[t]
            if state[q] != 0:
                continue
            keep = False
            for r in range(adj_ptr[q], adj_ptr[q + 1]):
                if state[adj[r]] == 2:
                    keep = True
                    break
            state[q] = 1 if keep else 2


@njit(cache=True, nogil=True)
def grow_near(nodes, nbr, near, width):  # pragma: no cover - compiled
    """``width`` times: mark (in a copy of the boolean ``near``) every table row's node one of
    whose eight neighbours is marked; returns the last copy."""
    for _ in range(width):
        grown = near.copy()
        for k in range(nodes.shape[0]):
            for q in range(8):
                if near[nbr[k, q]]:
                    grown[nodes[k]] = True
                    break
        near = grown
    return near


@njit(cache=True, nogil=True)
def _interp_1d(n, s, k_out, w_out):  # pragma: no cover - compiled
    """Linear interpolation of positions ``0..n-1`` from the kept positions ``s`` (ascending,
    ``s[0] = 0``, ``s[-1] = n − 1``): left kept index and weights (a kept position: weight 1, 0)."""
    k = 0
    for i in range(n):
        while k + 1 < s.shape[0] and s[k + 1] <= i:
            k += 1
        k1 = min(k + 1, s.shape[0] - 1)
        if s[k] == i:
            t = 0.0
        else:
            t = (i - s[k]) / max(s[k1] - s[k], 1)
        k_out[i, 0] = k
        k_out[i, 1] = k1
        w_out[i, 0] = 1.0 - t
        w_out[i, 1] = t


@njit(cache=True, nogil=True)
def interp_coo(
    fine_ids, fine_off, fine_shape, coarse_ids, coarse_off, si, si_off, sj, sj_off, mult
):  # pragma: no cover
    """COO ``(rows, cols, vals)`` of the prolongation over the global node arrays: block ``b``'s
    fine ids ``fine_ids[fine_off[b]:fine_off[b + 1]]`` (shape ``fine_shape[b]``, row-major), its
    coarse ids likewise, kept positions ``si, sj``; every entry weighted by ``1/mult`` of its row
    (each block that holds a shared node adds its equal share)."""
    nb = fine_off.shape[0] - 1
    total = 4 * (fine_off[nb] - fine_off[0])
    rows = np.empty(total, dtype=np.int64)
    cols = np.empty(total, dtype=np.int64)
    vals = np.empty(total)
    q = 0
    for b in range(nb):
        ni, nj = fine_shape[b, 0], fine_shape[b, 1]
        s_i = si[si_off[b] : si_off[b + 1]]
        s_j = sj[sj_off[b] : sj_off[b + 1]]
        ki = np.empty((ni, 2), dtype=np.int64)
        wi = np.empty((ni, 2))
        kj = np.empty((nj, 2), dtype=np.int64)
        wj = np.empty((nj, 2))
        _interp_1d(ni, s_i, ki, wi)
        _interp_1d(nj, s_j, kj, wj)
        ncj = s_j.shape[0]
        f0, c0 = fine_off[b], coarse_off[b]
        for i in range(ni):
            for j in range(nj):
                r = fine_ids[f0 + i * nj + j]
                for a in range(2):
                    for c in range(2):
                        w = wi[i, a] * wj[j, c]
                        if w != 0.0:
                            rows[q] = r
                            cols[q] = coarse_ids[c0 + ki[i, a] * ncj + kj[j, c]]
                            vals[q] = w / mult[r]
                            q += 1
    return rows[:q], cols[:q], vals[:q]


@njit(cache=True, nogil=True)
def position_classes(el, gid, n_el, n_gid):  # pragma: no cover - compiled
    """Classes of ``n_el`` line positions: positions ``el[t]`` holding a common node ``gid[t]``
    are one class (union–find).  Returns the class of each position, numbered ``0, 1, …`` in the
    order of their first position."""
    parent = np.arange(n_el)
    first = np.full(n_gid, -1, dtype=np.int64)
    for t in range(el.shape[0]):
        a = el[t]
        g = gid[t]
        if first[g] < 0:
            first[g] = a
            continue
        b = first[g]
        while parent[a] != a:
            parent[a] = parent[parent[a]]
            a = parent[a]
        while parent[b] != b:
            parent[b] = parent[parent[b]]
            b = parent[b]
        if a != b:
            if a < b:
                parent[b] = a
            else:
                parent[a] = b
    label = np.full(n_el, -1, dtype=np.int64)
    out = np.empty(n_el, dtype=np.int64)
    nc = 0
    for e in range(n_el):
        r = e
        while parent[r] != r:
            r = parent[r]
        if label[r] < 0:
            label[r] = nc
            nc += 1
        out[e] = label[r]
    return out


# ------------------------------------------------------------------ per-block tables in one call
# Blocks given flat: block ``b``'s global ids are ``flat[off[b]:off[b + 1]]``, row-major of shape
# ``shape[b]`` (node counts).  Each kernel does what a NumPy function does block by block (its
# reference, named in the docstring), in the same order, so the tables are identical.


@njit(cache=True, nogil=True)
def perimeter_cells(flat, off, shape):  # pragma: no cover - compiled
    """The CCW cells of every block that touch its border (reference
    :func:`.nodemap._perimeter_cells`)."""
    total = 0
    for b in range(shape.shape[0]):
        a, c = shape[b, 0] - 1, shape[b, 1] - 1
        total += a * c if a <= 2 or c <= 2 else 2 * c + 2 * (a - 2)
    out = np.empty((total, 4), dtype=np.int64)
    q = 0
    for b in range(shape.shape[0]):
        a, c, nj, o = shape[b, 0] - 1, shape[b, 1] - 1, shape[b, 1], off[b]
        for i in range(a):
            inner = a > 2 and c > 2 and 0 < i < a - 1
            for j in range(c):
                if inner and 0 < j < c - 1:
                    continue
                out[q, 0] = flat[o + i * nj + j]
                out[q, 1] = flat[o + (i + 1) * nj + j]
                out[q, 2] = flat[o + (i + 1) * nj + j + 1]
                out[q, 3] = flat[o + i * nj + j + 1]
                q += 1
    return out


@njit(cache=True, nogil=True)
def interior_stencils(flat, off, shape):  # pragma: no cover - compiled
    """``(nodes, nbr)``: every block's interior nodes (row-major, block by block) and their 8
    neighbours E, W, N, S, NE, NW, SE, SW (reference :func:`.nodemap._interior_stencils`)."""
    total = 0
    for b in range(shape.shape[0]):
        if shape[b, 0] >= 3 and shape[b, 1] >= 3:
            total += (shape[b, 0] - 2) * (shape[b, 1] - 2)
    nodes = np.empty(total, dtype=np.int64)
    nbr = np.empty((total, 8), dtype=np.int64)
    q = 0
    for b in range(shape.shape[0]):
        ni, nj, o = shape[b, 0], shape[b, 1], off[b]
        if ni < 3 or nj < 3:
            continue
        for i in range(1, ni - 1):
            for j in range(1, nj - 1):
                p = o + i * nj + j
                nodes[q] = flat[p]
                nbr[q, 0] = flat[p + nj]
                nbr[q, 1] = flat[p - nj]
                nbr[q, 2] = flat[p + 1]
                nbr[q, 3] = flat[p - 1]
                nbr[q, 4] = flat[p + nj + 1]
                nbr[q, 5] = flat[p - nj + 1]
                nbr[q, 6] = flat[p + nj - 1]
                nbr[q, 7] = flat[p - nj - 1]
                q += 1
    return nodes, nbr


@njit(cache=True, nogil=True)
def colour_perm(shape, n_rows):  # pragma: no cover - compiled
    """The 4-colour order of the interior rows (those of :func:`interior_stencils`), then rows
    ``n_interior … n_rows − 1`` unchanged (reference :func:`.hierarchy._colour_order`)."""
    order = np.empty(n_rows, dtype=np.int64)
    q = 0
    start = 0
    for b in range(shape.shape[0]):
        ni, nj = shape[b, 0] - 2, shape[b, 1] - 2
        if ni < 1 or nj < 1:
            continue
        for pi, pj in ((1, 0), (1, 1), (0, 0), (0, 1)):
            for i in range(pi, ni, 2):
                for j in range(pj, nj, 2):
                    order[q] = start + i * nj + j
                    q += 1
        start += ni * nj
    for r in range(start, n_rows):
        order[q] = r
        q += 1
    return order


#: The 8 stencil directions of a table row ``(E, W, N, S, NE, NW, SE, SW)`` as ``(di, dj)``.
DIRS = np.array([(1, 0), (-1, 0), (0, 1), (0, -1), (1, 1), (-1, 1), (1, -1), (-1, -1)], dtype=np.int64)
#: ``DIR_INDEX[3 * (di + 1) + dj + 1]``: the row position of direction ``(di, dj)`` (−1 for (0, 0)).
DIR_INDEX = np.array([7, 1, 5, 3, -1, 2, 6, 0, 4], dtype=np.int64)


@njit(cache=True, nogil=True)
def _find4(row, q):  # pragma: no cover - compiled
    """The position of node ``q`` among the edge neighbours ``row[:4]`` (−1 if absent)."""
    for d in range(4):
        if row[d] == q:
            return d
    return -1


@njit(cache=True, nogil=True)
def block_frame_row(row, i_next, i_prev, j_next, j_prev, out):  # pragma: no cover - compiled
    """``out``: the table row ``row`` (a border node's stencil in the frame of its ring of cells)
    in a block's frame, given the block's neighbours of the node along +i / −i / +j / −j (−1 where
    the node is at the block's end in that direction).  Returns False when the row does not hold
    them (then ``out`` is undefined)."""
    de = _find4(row, i_next) if i_next >= 0 else -1
    if de < 0:
        d = _find4(row, i_prev) if i_prev >= 0 else -1
        if d < 0:
            return False
        de = d ^ 1  # the opposite direction (E↔W, N↔S)
    dn = _find4(row, j_next) if j_next >= 0 else -1
    if dn < 0:
        d = _find4(row, j_prev) if j_prev >= 0 else -1
        if d < 0:
            return False
        dn = d ^ 1
    if de // 2 == dn // 2:  # not a frame (the four edge neighbours are E, W, N, S)
        return False
    for d in range(8):
        a, b = DIRS[d, 0], DIRS[d, 1]
        u = a * DIRS[de, 0] + b * DIRS[dn, 0]
        v = a * DIRS[de, 1] + b * DIRS[dn, 1]
        k = DIR_INDEX[3 * (u + 1) + v + 1]
        if k < 0:
            return False
        out[d] = row[k]
    return True


@njit(cache=True, nogil=True)
def block_lines(flat, off, shape, pos, nbr, axis):  # pragma: no cover - compiled
    """``(rows, lnbr, ptr)``: every interior line of every block along ``axis`` (0: ξ, i varies)
    as table rows ``pos[node]``, with the line's two end nodes on the block border when they are
    free regular nodes (an interface), and the rows' stencils in the block's frame ``lnbr`` (the
    border nodes' rows turned by :func:`block_frame_row`).  Reference: :func:`.hierarchy.lines_reference`."""
    n_rows, n_lines = 0, 0
    for b in range(shape.shape[0]):
        ni, nj = shape[b, 0] - 2, shape[b, 1] - 2
        if ni >= 1 and nj >= 1:
            n_rows += (ni + 2) * nj if axis == 0 else ni * (nj + 2)
            n_lines += nj if axis == 0 else ni
    rows = np.empty(n_rows, dtype=np.int64)
    lnbr = np.empty((n_rows, 8), dtype=np.int64)
    ptr = np.empty(n_lines + 1, dtype=np.int64)
    ptr[0] = 0
    q, L = 0, 0
    for b in range(shape.shape[0]):
        ni, nj, o, w = shape[b, 0], shape[b, 1], off[b], shape[b, 1]  # nodes
        if ni < 3 or nj < 3:
            continue
        outer, inner = (nj, ni) if axis == 0 else (ni, nj)
        for s in range(1, outer - 1):
            for t in range(inner):
                i, j = (t, s) if axis == 0 else (s, t)
                r = pos[flat[o + i * w + j]]
                if r < 0:
                    continue
                if 0 < t < inner - 1:
                    for c in range(8):  # element by element: a row slice assigned took 3× longer (measured)
                        lnbr[q, c] = nbr[r, c]
                else:
                    i_next = flat[o + (i + 1) * w + j] if i + 1 < ni else -1
                    i_prev = flat[o + (i - 1) * w + j] if i > 0 else -1
                    j_next = flat[o + i * w + j + 1] if j + 1 < nj else -1
                    j_prev = flat[o + i * w + j - 1] if j > 0 else -1
                    if not block_frame_row(nbr[r], i_next, i_prev, j_next, j_prev, lnbr[q]):
                        continue
                rows[q] = r
                q += 1
            L += 1
            ptr[L] = q
    if q == n_rows:  # every row on a line: no trimmed copies
        return rows, lnbr, ptr
    return rows[:q].copy(), lnbr[:q].copy(), ptr


@njit(cache=True, nogil=True)
def gather_kept(flat, off, shape, si, si_off, sj, sj_off):  # pragma: no cover - compiled
    """The ids at the kept positions ``si × sj`` of every block, flat (block ``b``: row-major
    ``len(si_b) × len(sj_b)``; reference: ``g[np.ix_(si, sj)]`` block by block)."""
    total = 0
    for b in range(shape.shape[0]):
        total += (si_off[b + 1] - si_off[b]) * (sj_off[b + 1] - sj_off[b])
    out = np.empty(total, dtype=np.int64)
    q = 0
    for b in range(shape.shape[0]):
        nj, o = shape[b, 1], off[b]
        for a in range(si_off[b], si_off[b + 1]):
            for c in range(sj_off[b], sj_off[b + 1]):
                out[q] = flat[o + si[a] * nj + sj[c]]
                q += 1
    return out


@njit(cache=True, nogil=True)
def line_elements(flat, off, shape):  # pragma: no cover - compiled
    """``(el, gid, line_ptr)``: the line positions of every block (block ``b``: its ``ni``
    positions along ξ, then its ``nj`` along η, numbered on from the last block's) paired with the
    border nodes on them (bottom, top rows on the ξ positions, left, right on the η ones), and the
    first position of every line (reference: :func:`.hierarchy.positions_reference`'s pairs)."""
    nb = shape.shape[0]
    n_pairs = 0
    for b in range(nb):
        n_pairs += 2 * (shape[b, 0] + shape[b, 1])
    el = np.empty(n_pairs, dtype=np.int64)
    gid = np.empty(n_pairs, dtype=np.int64)
    line_ptr = np.empty(2 * nb + 1, dtype=np.int64)
    line_ptr[0] = 0
    total, q = 0, 0
    for b in range(nb):
        ni, nj, o = shape[b, 0], shape[b, 1], off[b]
        for i in range(ni):  # bottom (j = 0), then top (j = nj − 1)
            el[q], gid[q] = total + i, flat[o + i * nj]
            q += 1
        for i in range(ni):
            el[q], gid[q] = total + i, flat[o + i * nj + nj - 1]
            q += 1
        for j in range(nj):  # left (i = 0), then right (i = ni − 1)
            el[q], gid[q] = total + ni + j, flat[o + j]
            q += 1
        for j in range(nj):
            el[q], gid[q] = total + ni + j, flat[o + (ni - 1) * nj + j]
            q += 1
        line_ptr[2 * b + 1] = total + ni
        total += ni + nj
        line_ptr[2 * b + 2] = total
    return el, gid, line_ptr


@njit(cache=True, nogil=True)
def keep_classes(cls, line_ptr, n_classes, min_cells):  # pragma: no cover - compiled
    """The kept (1) and dropped (2) position classes of the next coarser level, line ``L`` being
    ``cls[line_ptr[L]:line_ptr[L + 1]]``: the ends of every line, every position of a line with
    fewer than ``2 · min_cells`` cells and a class twice in a row are kept; the rest by
    :func:`greedy_drop` over the classes' neighbours along the lines (reference
    :func:`.hierarchy.select_reference`)."""
    state = np.zeros(n_classes, dtype=np.int64)
    deg = np.zeros(n_classes + 1, dtype=np.int64)
    for L in range(line_ptr.shape[0] - 1):
        a, b = line_ptr[L], line_ptr[L + 1]
        state[cls[a]] = 1
        state[cls[b - 1]] = 1
        short = b - a - 1 < 2 * min_cells
        for t in range(a, b):
            if short or (t > a and cls[t] == cls[t - 1]):
                state[cls[t]] = 1
        for t in range(a + 1, b):
            deg[cls[t - 1] + 1] += 1
            deg[cls[t] + 1] += 1
    for c in range(n_classes):
        deg[c + 1] += deg[c]
    adj = np.empty(deg[n_classes], dtype=np.int64)
    fill = deg[:-1].copy()
    for L in range(line_ptr.shape[0] - 1):
        for t in range(line_ptr[L] + 1, line_ptr[L + 1]):
            p, q = cls[t - 1], cls[t]
            adj[fill[p]] = q
            fill[p] += 1
            adj[fill[q]] = p
            fill[q] += 1
    greedy_drop(cls, line_ptr, deg, adj, state)
    return state


@njit(cache=True, nogil=True)
def _gradient(s, out):  # pragma: no cover - compiled
    """``np.gradient`` of the positions ``s`` (one-sided at the ends; 1 for a single one)."""
    n = s.shape[0]
    if n < 2:
        out[:n] = 1.0
        return
    out[0] = s[1] - s[0]
    out[n - 1] = s[n - 1] - s[n - 2]
    for k in range(1, n - 1):
        out[k] = (s[k + 1] - s[k - 1]) / 2.0


@njit(cache=True, nogil=True)
def fas_scale(coarse_flat, coarse_off, si, si_off, sj, sj_off, n):  # pragma: no cover - compiled
    """The FAS scaling ``2 a² b² / (a² + b²)`` of every coarse node (``a, b``: the gradients of the
    kept positions along ξ and η; a node of several blocks takes the last block's; reference
    :func:`.hierarchy.scale_reference`)."""
    scale = np.zeros(n)
    for b in range(si_off.shape[0] - 1):
        s_i = si[si_off[b] : si_off[b + 1]].astype(np.float64)
        s_j = sj[sj_off[b] : sj_off[b + 1]].astype(np.float64)
        gi = np.empty(s_i.shape[0])
        gj = np.empty(s_j.shape[0])
        _gradient(s_i, gi)
        _gradient(s_j, gj)
        ncj, o = s_j.shape[0], coarse_off[b]
        for i in range(s_i.shape[0]):
            a2 = gi[i] * gi[i]
            for j in range(ncj):
                b2 = gj[j] * gj[j]
                scale[coarse_flat[o + i * ncj + j]] = 2.0 * a2 * b2 / (a2 + b2)
    return scale


@njit(cache=True, nogil=True)
def _bucket(keys, other, vals, n):  # pragma: no cover
    """The entries ``(other[q], vals[q])`` grouped by ``keys[q] ∈ [0, n)``, in their order within
    a group (a counting sort): ``(ptr, idx, val)``, group ``k`` at ``ptr[k]:ptr[k + 1]``."""
    ptr = np.zeros(n + 1, dtype=np.int64)
    for q in range(keys.shape[0]):
        ptr[keys[q] + 1] += 1
    for k in range(n):
        ptr[k + 1] += ptr[k]
    idx = np.empty(keys.shape[0], dtype=np.int64)
    val = np.empty(keys.shape[0])
    fill = ptr[:-1].copy()
    for q in range(keys.shape[0]):
        j = fill[keys[q]]
        idx[j] = other[q]
        val[j] = vals[q]
        fill[keys[q]] += 1
    return ptr, idx, val


@njit(cache=True, nogil=True)
def transfer_csr(rows, cols, vals, n_fine, n_coarse, fine_free, coarse_free):  # pragma: no cover
    """``P`` and ``R`` in CSR from the COO entries of :func:`interp_coo` (reference
    :func:`.hierarchy.transfers_reference`, scipy): ``P`` sums the entries of a (row, column)
    pair, columns ascending, rows of fixed fine nodes empty; ``rsum`` are the column sums of
    ``P`` (fine rows ascending), and ``R = D⁻¹ Pᵀ`` with the rows of fixed coarse nodes empty.
    Returns ``(p_ptr, p_idx, p_val, r_ptr, r_idx, r_val, rsum)``."""
    nnz = rows.shape[0]
    ptr, idx, val = _bucket(rows, cols, vals, n_fine)
    # each row: columns ascending (insertion sort: a row has at most 4 entries per block), the
    # entries of one column summed, compacted into p_*
    p_ptr = np.zeros(n_fine + 1, dtype=np.int64)
    p_idx = np.empty(nnz, dtype=np.int64)
    p_val = np.empty(nnz)
    q = 0
    for r in range(n_fine):
        a, b = ptr[r], ptr[r + 1]
        for t in range(a + 1, b):
            ci, cv = idx[t], val[t]
            u = t - 1
            while u >= a and idx[u] > ci:
                idx[u + 1] = idx[u]
                val[u + 1] = val[u]
                u -= 1
            idx[u + 1] = ci
            val[u + 1] = cv
        t = a
        while t < b:
            ci, s = idx[t], val[t]
            t += 1
            while t < b and idx[t] == ci:
                s += val[t]
                t += 1
            p_idx[q] = ci
            p_val[q] = s
            q += 1
        p_ptr[r + 1] = q
    # the transpose (fine rows ascending in every coarse row) and its row sums
    p_row = np.empty(q, dtype=np.int64)
    for r in range(n_fine):
        p_row[p_ptr[r] : p_ptr[r + 1]] = r
    r_ptr, t_idx, t_val = _bucket(p_idx[:q], p_row, p_val[:q], n_coarse)
    rsum = np.zeros(n_coarse)
    for c in range(n_coarse):
        s = 0.0
        for t in range(r_ptr[c], r_ptr[c + 1]):
            s += t_val[t]
        rsum[c] = s
    # R: rows of fixed coarse nodes dropped, the rest scaled by 1 / rsum
    out_ptr = np.zeros(n_coarse + 1, dtype=np.int64)
    out_idx = np.empty(q, dtype=np.int64)
    out_val = np.empty(q)
    k = 0
    for c in range(n_coarse):
        if coarse_free[c]:
            inv = 1.0 / (rsum[c] if rsum[c] > 0 else 1.0)
            for t in range(r_ptr[c], r_ptr[c + 1]):
                v = t_val[t] * inv
                if v != 0.0:
                    out_idx[k] = t_idx[t]
                    out_val[k] = v
                    k += 1
        out_ptr[c + 1] = k
    # P: rows of fixed fine nodes dropped
    f_ptr = np.zeros(n_fine + 1, dtype=np.int64)
    k2 = 0
    for r in range(n_fine):
        if fine_free[r]:
            for t in range(p_ptr[r], p_ptr[r + 1]):
                if p_val[t] != 0.0:
                    p_idx[k2] = p_idx[t]
                    p_val[k2] = p_val[t]
                    k2 += 1
        f_ptr[r + 1] = k2
    return f_ptr, p_idx[:k2].copy(), p_val[:k2].copy(), out_ptr, out_idx[:k].copy(), out_val[:k].copy(), rsum
