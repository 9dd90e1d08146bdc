"""numba kernels of the multigrid set-up (:mod:`.hierarchy`; functions only).

The set-up runs once per block structure, but on the first solve of a lake
layout its per-block NumPy calls cost as much as the solve; these two loops do
the same work in one call each.  NumPy references (test oracles):
:func:`.hierarchy._block_interp`, :func:`.hierarchy.greedy_reference` and
:func:`.hierarchy.near_reference` (:func:`grow_near` also runs after every cycle of a solve,
:func:`.multigrid._hot_sweeps`).
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
