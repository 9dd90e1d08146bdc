r"""A last local step (on by default in :func:`~meshcore.lakegrid.mesh_layout`): cells across an
interface made alike where the orthogonal solve left them far apart.

The worst cross-interface pairs of a lake grid are single cells beside a cut's end at a reflex
shore corner, mostly where the block that has its corner there opens to 150–180° (a polar fan
whose cells shrink into the corner) and the block whose side passes keeps its cells
(``docs/lake-grids-journal.md``, *Cell-size jumps across interfaces*).  :func:`equalize_interfaces` takes
each pair above ``limit``, worst first, and moves the nodes within ``depth - 1`` grid edges of its
two cells — block-interior and interface nodes (with ``SLIDE`` shore nodes too, along the
shore); cut ends, block corners and nodes where 3 or 5 blocks meet stay — to minimize (BFGS,
exact gradient)

    Σ_pairs relu(|log A₁/A₂| − log AIM)²  +  penalties,

the penalties keeping every block-interior node's ``|cos|`` within what it had or within the
report's limits (3°, ``|cos| ≤ 0.02``), every cell corner's deviation within ``CORNER_ADD``
degrees more than it had (the border nodes the report does not measure: with no bound there the
optimum kinks the cut and squeezes slivers beside it), consecutive edge ratios along grid lines
(weight 0.03, and 3.0 in a second solve when no move of the first is kept: ``EDGE_WEIGHTS``),
every corner Jacobian above half of its own, and the moves small.  A patch is kept only when
its worst pair is lower and inside it no node within 3° or ``|cos| ≤ 0.02`` is lost,
no interface pair ≤ 2, at most ``EDGE_LOSS`` edge pairs ≤ 1.2 (or ``EDGE_LOSS_SHARE`` of the patch's
pairs while the grid keeps ``EDGE_FLOOR`` of its pairs ≤ 1.2), and no corner Jacobian is ≤ 0;
else half the step, a quarter, or nothing.  A pair still above ``limit`` after its own patch is
tried once more with up to ``RUN`` neighbouring pairs above ``AIM`` that touch it (a run along the
interface, all moving together: its own patch may not lose a neighbour's ratio ≤ 2), and while
it stays above, again with its free nodes within 4 edges and then 6 (``RUN_DEPTHS``); these are
solved at the first edge weight by :func:`._bfgs.bfgs` (scipy's BFGS update is O(n³) a step: 20 ×
the lake's CPU on those patches).  Once every pair above ``limit`` has been tried, those still above
it are tried once more (``RETRY``), and again after every such round that kept a patch, up to
``RETRY_ROUNDS`` rounds (all within ``max_patches``).  Measured in ``docs/lake-grids-journal.md``
(sessions 17, 18, 20, 36, 37).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..quality.interfaces import signed_area
from . import _equalize_kernels
from .driver import _assemble, quad_areas
from .shore import arc_lengths, project_to_rings, ring_point

__all__ = ["equalize_interfaces", "warm_up"]

LIMIT = 2.0  # pairs above this are worked on (issue 12's target)
AIM = 1.8  # the objective pays beyond this
DEPTH = 3  # free nodes: within DEPTH - 1 grid edges of the pair's cells
MAX_PATCHES = 24
MAX_ITER = 300  # BFGS iterations per patch (60: 20–30 % less CPU on 5 lakes, their largest ratio up to 9 % higher)
COS3 = float(np.sin(np.radians(3.0)))  # the quality report's deviation is arcsin |cos|
COS_D3D = 0.02
EDGE = 1.2
W_COS, W_EDGE, W_JAC = 1e4, 3.0, 10.0
# the edge-ratio weight of a patch's first solve, and of a second only when no move of the first
# was kept (session 18: with 3.0 alone this term, not the angles, held most pairs above 2)
EDGE_WEIGHTS = (0.03, W_EDGE)
CORNER_ADD = 5.0
METHOD = "BFGS"
SLIDE = False  # shore nodes slide too (on 4 nets: the same ratios within 0.2, shore 0.20 -> 0.26 cells)
EDGE_LOSS = 10  # edge pairs <= 1.2 a patch may lose ...
#: ... or this share of the patch's edge pairs, if more, while the lake keeps at least
#: :data:`EDGE_FLOOR` of all its edge pairs ≤ 1.2.  A run patch (30 seed nodes, 7 deep: ~500 edge
#: pairs) along a fan into a strait moves many lines at once, and the fixed allowance threw away
#: every such patch (session 39: Taal at 15 000 cells, 209 of 288 tries, its largest ratio left at
#: 3.43 after 24 patches and 8.4 s of CPU; with the share 1.97 in 5.9 s, its edge pairs 97.35 → 97.28 %).
EDGE_LOSS_SHARE = 0.04
EDGE_FLOOR = 0.95  # issue 12's target for edge pairs <= 1.2
RUN_WEIGHTS = EDGE_WEIGHTS[:1]
RUN_METHOD = "bfgs-n2"
RUN_SLIDE = False  # shore nodes (not cut ends or corners) slide in the run patches deeper than DEPTH
#: The run patches' depths, in turn while the pair stays above the limit.  The third (session 36)
#: reaches pairs beside cuts from convex land corners that the 5-deep patch left just above 2: on
#: held-out sets 20-23 (112 lakes at 15 000 and 10 000 cells and regular at 10 000: 336 grids) it
#: ran on 9 and brought the largest ratio under 2 on 6 (e.g. g181140 at 15 000 cells 2.24 -> 1.85,
#: g181790 regular 2.23 -> 1.91, g182553 2.10 -> 1.81), the other numbers within 0.1 points, CPU the
#: same; on one (g180702, 1.97 -> 2.31) it changed the order the pairs were mended in: :data:`RETRY`.
RUN_DEPTHS = (DEPTH, 5, 7)
#: Once every pair above the limit has had its patches, those still above it get theirs once more
#: (their neighbours' patches moved the grid round them since; session 36: held-out g180702 at
#: 15 000 cells, a pair left at 2.31 -> 1.91, the only one of the 336 grids above still above 2).
RETRY = True
#: Rounds of :data:`RETRY`, each only after a round that kept a patch (session 37: the patches of one
#: round move the grid round the pairs tried before them; generated ``dense net 370910`` at 15 000
#: cells 3.05 -> 1.92 and ``small islands 380851`` 2.65 -> 1.98 in a later round; of 108 generated
#: grids, 81 at 15 000 cells and 27 regular at 10 000, only those two changed, the others' numbers
#: the same, CPU the same).
RETRY_ROUNDS = 3
RUN = 8  # a second patch round a pair left above LIMIT: up to RUN neighbouring pairs above AIM with it (0: none)


class _Tables:
    """Every cell, node-cos stencil and edge-pair triple of the grid, in global node ids."""

    def __init__(self, topology, grids) -> None:
        m = topology.node_map
        cells, cblock, cos5, tri = [], [], [], []
        self.start = [0]
        sign = []
        for b, ids in enumerate(m.ids):
            n1, m1 = ids.shape
            c = np.stack([ids[:-1, :-1], ids[1:, :-1], ids[1:, 1:], ids[:-1, 1:]], -1).reshape(-1, 4)
            cells.append(c)
            cblock.append(np.full(len(c), b))
            self.start.append(self.start[-1] + len(c))
            area = signed_area(np.asarray(grids[b].x), np.asarray(grids[b].y))
            sign.append(np.full(len(c), -1.0 if area.sum() < 0 else 1.0))
            if n1 >= 3 and m1 >= 3:
                cos5.append(
                    np.stack(
                        [ids[1:-1, 1:-1], ids[2:, 1:-1], ids[:-2, 1:-1], ids[1:-1, 2:], ids[1:-1, :-2]], -1
                    ).reshape(-1, 5)
                )
            if n1 >= 3:
                tri.append(np.stack([ids[:-2, :], ids[1:-1, :], ids[2:, :]], -1).reshape(-1, 3))
            if m1 >= 3:
                tri.append(np.stack([ids[:, :-2], ids[:, 1:-1], ids[:, 2:]], -1).reshape(-1, 3))
        self.cells = np.vstack(cells).astype(np.int64)
        self.cblock = np.concatenate(cblock)
        self.sign = np.concatenate(sign)
        self.cos5 = np.vstack(cos5).astype(np.int64) if cos5 else np.zeros((0, 5), np.int64)
        self.tri = np.vstack(tri).astype(np.int64) if tri else np.zeros((0, 3), np.int64)
        self.nj = np.array([ids.shape[1] - 1 for ids in m.ids])
        cnt = np.bincount(self.cells.ravel(), minlength=m.n_nodes)
        self.cnt = cnt
        star = np.zeros(m.n_nodes, bool)
        for c in m.corners:
            star[c.node] = True
        self.shore = m.boundary & (cnt == 2)
        self.movable = (~m.boundary & ~star & (cnt == 4)) | (self.shore if SLIDE else False)
        e = np.concatenate([self.cells[:, [0, 1]], self.cells[:, [1, 2]], self.cells[:, [2, 3]], self.cells[:, [3, 0]]])
        from scipy.sparse import coo_matrix

        n = m.n_nodes
        A = coo_matrix((np.ones(len(e)), (e[:, 0], e[:, 1])), shape=(n, n)).tocsr()
        self.adj = ((A + A.T) > 0).astype(np.int8)
        self.edge_budget = 0  # edge pairs <= 1.2 the step may still lose beyond EDGE_LOSS a patch (_budget)

    def budget(self, P: np.ndarray) -> None:
        """:attr:`edge_budget` for the nodes ``P``: how many edge pairs ≤ 1.2 the grid has above
        :data:`EDGE_FLOOR` of all of them."""
        ok = int((_edge_logs(P, self.tri) <= np.log(EDGE)).sum())
        self.edge_budget = ok - int(np.ceil(EDGE_FLOOR * len(self.tri)))

    def row(self, cell) -> int:
        b, i, j = (int(v) for v in cell)
        return self.start[b] + i * self.nj[b] + j


def _areas(P: np.ndarray, C: np.ndarray) -> np.ndarray:
    return quad_areas(P[:, 0], P[:, 1], C)


def _jacobians(P: np.ndarray, C: np.ndarray) -> np.ndarray:
    Q = P[C]  # (n, 4, 2)
    a = np.roll(Q, -1, axis=1) - Q
    b = np.roll(Q, 1, axis=1) - Q
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def _cos(P: np.ndarray, S: np.ndarray) -> np.ndarray:
    a = P[S[:, 1]] - P[S[:, 2]]
    b = P[S[:, 3]] - P[S[:, 4]]
    nrm = np.hypot(*a.T) * np.hypot(*b.T)
    return np.abs((a * b).sum(1)) / np.maximum(nrm, 1e-300)


def _edge_logs(P: np.ndarray, T: np.ndarray) -> np.ndarray:
    l1 = np.hypot(*(P[T[:, 1]] - P[T[:, 0]]).T)
    l2 = np.hypot(*(P[T[:, 2]] - P[T[:, 1]]).T)
    return np.abs(np.log(np.maximum(l1, 1e-300) / np.maximum(l2, 1e-300)))


class _Patch:
    """The free nodes round one pair, the stencils they touch, and the objective."""

    def __init__(
        self,
        t: _Tables,
        P0: np.ndarray,
        seeds: np.ndarray,
        depth: int,
        pairs: np.ndarray,
        shore,
        w_edge: float = W_EDGE,
    ) -> None:
        self.w_edge = w_edge
        n = len(P0)
        reach = np.zeros(n, bool)
        reach[seeds] = True
        for _ in range(depth - 1):
            reach = reach | (t.adj @ reach.astype(np.int8) > 0)
        free = np.flatnonzero(reach & t.movable)
        isfree = np.zeros(n, bool)
        isfree[free] = True
        self.crow = np.flatnonzero(isfree[t.cells].any(1))
        self.cos = t.cos5[isfree[t.cos5].any(1)]
        self.tri = t.tri[isfree[t.tri].any(1)]
        inpatch = np.zeros(len(t.cells), bool)
        inpatch[self.crow] = True
        self.pairs = pairs[inpatch[pairs[:, 0]] | inpatch[pairs[:, 1]]]
        self.Ca, self.Cb = t.cells[self.pairs[:, 0]], t.cells[self.pairs[:, 1]]
        self.free = free
        self.slide = free[t.shore[free]]
        self.fly = free[~t.shore[free]]
        self.P0 = P0
        self.t = t
        rings, cums = shore
        self.rings, self.cums = rings, cums
        if len(self.slide):
            r, s, _ = project_to_rings(rings, P0[self.slide])
            self.ring_of, self.s0 = r.astype(int), s
        else:
            self.ring_of, self.s0 = np.zeros(0, int), np.zeros(0)
        C = t.cells[self.crow]
        sg = t.sign[self.crow]
        self.C, self.sg = C, sg
        self.J0 = sg[:, None] * _jacobians(P0, C)
        a0 = np.abs(_areas(P0, C))
        # node scale: the square root of the mean area of the patch's cells
        self.h = float(np.sqrt(np.mean(a0)))
        self.n_node_cos = len(self.cos)
        # every corner of every cell of the patch too (a border node's angles, which the node
        # measure leaves out: without them the optimum kinks a cut and leaves slivers beside it)
        corners = np.stack([C, np.roll(C, -1, axis=1), C, np.roll(C, 1, axis=1), C], -1).reshape(-1, 5)
        self.cos = np.vstack([self.cos, corners])
        self.c0 = _cos(P0, self.cos)
        self.e0 = _edge_logs(P0, self.tri)
        self.r0 = self.ratios(P0)
        allowed = np.where(self.c0 <= COS_D3D, 0.9 * COS_D3D, np.where(self.c0 <= COS3, 0.9 * COS3, self.c0))
        allowed = np.maximum(allowed, self.c0)
        # a cell corner (not a node the quality report measures) may turn by up to CORNER_ADD degrees
        dev0 = np.degrees(np.arcsin(np.clip(self.c0[self.n_node_cos :], 0.0, 1.0)))
        allowed[self.n_node_cos :] = np.maximum(
            allowed[self.n_node_cos :], np.sin(np.radians(np.minimum(dev0 + CORNER_ADD, 90.0)))
        )
        self.c_allowed = allowed
        self.e_allowed = np.maximum(self.e0, np.log(EDGE) * 0.95)
        self._local()

    def _local(self) -> None:
        """The patch's own nodes (those its cells, stencils and pairs touch) numbered from 0: the
        compiled objective works on them, not on a copy of the whole grid per call (the same
        numbers: every sum runs over the same terms in the same order)."""
        used = np.unique(np.concatenate([a.ravel() for a in (self.C, self.cos, self.tri, self.Ca, self.Cb, self.free)]))
        at = np.full(len(self.P0), -1, np.int64)
        at[used] = np.arange(len(used))
        self.l_P0 = self.P0[used]
        self.l_C, self.l_cos, self.l_tri = at[self.C], at[self.cos], at[self.tri]
        self.l_Ca, self.l_Cb = at[self.Ca], at[self.Cb]
        self.l_fly, self.l_slide = at[self.fly], at[self.slide]
        self.rings_used = np.unique(self.ring_of)

    def _moved(self, P: np.ndarray, fly: np.ndarray, slide: np.ndarray, z: np.ndarray) -> np.ndarray:
        """``P`` (a copy) with the nodes ``fly`` and ``slide`` moved by ``z``."""
        P = P.copy()
        k = 2 * len(fly)
        P[fly] += self.h * z[:k].reshape(-1, 2)
        for r in self.rings_used:
            sel = self.ring_of == r
            P[slide[sel]] = ring_point(self.rings[r], self.s0[sel] + self.h * z[k:][sel], self.cums[r])
        return P

    def positions(self, z: np.ndarray) -> np.ndarray:
        return self._moved(self.P0, self.fly, self.slide, z)

    def ratios(self, P: np.ndarray) -> np.ndarray:
        a = np.abs(_areas(P, self.t.cells[self.pairs[:, 0]]))
        b = np.abs(_areas(P, self.t.cells[self.pairs[:, 1]]))
        return np.abs(np.log(np.maximum(a, 1e-300) / np.maximum(b, 1e-300)))

    def objective(self, z: np.ndarray) -> tuple[float, np.ndarray]:
        """The objective and its gradient in ``z`` (compiled: :func:`._equalize_kernels.objective`)."""
        P = self._moved(self.l_P0, self.l_fly, self.l_slide, z)
        G = np.empty_like(P)
        ok, f = _equalize_kernels.objective(
            P, self.l_C, self.sg, self.J0, self.l_Ca, self.l_Cb, float(np.log(AIM)), self.l_cos, self.c_allowed, W_COS,
            self.l_tri, self.e_allowed, self.w_edge, W_JAC, G,
        )  # fmt: skip
        if not ok:
            return 1e6, np.zeros_like(z)
        return f + 1e-3 * float(z @ z), self.chain(G, z, self.l_fly, self.l_slide) + 2e-3 * z

    def objective_numpy(self, z: np.ndarray) -> tuple[float, np.ndarray]:
        """:meth:`objective` in NumPy (the compiled kernel's reference in the tests)."""
        from ._equalize_reference import objective_numpy

        return objective_numpy(self, z, AIM=AIM, W_COS=W_COS, W_JAC=W_JAC)

    def chain(self, G: np.ndarray, z: np.ndarray, fly=None, slide=None) -> np.ndarray:
        """The gradient in ``z`` from the gradient ``G`` in the nodes (``fly``, ``slide``: their
        rows in ``G``, default the grid's node ids)."""
        fly = self.fly if fly is None else fly
        slide = self.slide if slide is None else slide
        k = 2 * len(fly)
        out = np.empty_like(z)
        out[:k] = self.h * G[fly].ravel()
        if len(slide):
            eps = 1e-6 * self.h
            tang = np.zeros((len(slide), 2))
            for r in self.rings_used:
                sel = self.ring_of == r
                s = self.s0[sel] + self.h * z[k:][sel]
                p1 = ring_point(self.rings[r], s + eps, self.cums[r])
                p0 = ring_point(self.rings[r], s - eps, self.cums[r])
                tang[sel] = (p1 - p0) / (2 * eps)
            out[k:] = self.h * (G[slide] * tang).sum(1)
        return out

    def counts(self, P: np.ndarray) -> tuple:
        c = _cos(P, self.cos[: self.n_node_cos])
        e = _edge_logs(P, self.tri)
        r = self.ratios(P)
        J = self.sg[:, None] * _jacobians(P, self.C)
        return (
            int((c <= COS3).sum()),
            int((c <= COS_D3D).sum()),
            int((e <= np.log(EDGE)).sum()),
            int((r <= np.log(LIMIT)).sum()),
            bool((J > 0).all()),
        )


def _solve_patch(
    t: _Tables,
    P: np.ndarray,
    seeds: np.ndarray,
    depth: int,
    pairs: np.ndarray,
    shore,
    w_edge: float,
    method: str = METHOD,
) -> np.ndarray | None:
    """The node array with the patch of ``depth`` round ``seeds`` moved, or None when no move of
    it (the optimum, half or a quarter of it) is kept by the checks of the module docstring."""
    from scipy.optimize import minimize

    patch = _Patch(t, P, seeds, depth, pairs, shore, w_edge)
    nz = 2 * len(patch.fly) + len(patch.slide)
    if not nz:
        return None
    if method == "bfgs-n2":  # the run patches: O(n²) updates (._bfgs)
        from ._bfgs import bfgs

        x = bfgs(patch.objective, np.zeros(nz), maxiter=MAX_ITER)
    else:
        x = minimize(patch.objective, np.zeros(nz), jac=True, method=method, options={"maxiter": MAX_ITER}).x
    before = patch.counts(P)
    loss = max(EDGE_LOSS, min(int(EDGE_LOSS_SHARE * len(patch.tri)), t.edge_budget))
    for alpha in (1.0, 0.5, 0.25):
        Pn = patch.positions(alpha * x)
        after = patch.counts(Pn)
        better = patch.ratios(Pn).max() < patch.r0.max() - 1e-9
        ok = after[0] >= before[0] and after[1] >= before[1] and after[2] >= before[2] - loss and after[3] >= before[3]
        if better and after[4] and ok:
            return Pn
    return None


def _ratios(P: np.ndarray, t: _Tables, pairs: np.ndarray) -> np.ndarray:
    """``|log A₁/A₂|`` of the cell pairs ``pairs`` (rows of ``t.cells``)."""
    return np.abs(np.log(np.abs(_areas(P, t.cells[pairs[:, 0]])) / np.abs(_areas(P, t.cells[pairs[:, 1]]))))


def _first_kept(
    t: _Tables,
    P: np.ndarray,
    seeds: np.ndarray,
    depth: int,
    pairs: np.ndarray,
    shore,
    weights=None,
    method: str | None = None,
) -> np.ndarray | None:
    """The patch round ``seeds`` solved at each of ``weights`` (default ``EDGE_WEIGHTS``) in turn,
    the first kept; ``method``: the minimizer of :func:`_solve_patch` (default ``METHOD``)."""
    for w_edge in EDGE_WEIGHTS if weights is None else weights:  # the next only when no move was kept
        if method is None:
            Pn = _solve_patch(t, P, seeds, depth, pairs, shore, w_edge)
        else:
            Pn = _solve_patch(t, P, seeds, depth, pairs, shore, w_edge, method=method)
        if Pn is not None:
            return Pn
    return None


def _run_seeds(t: _Tables, pairs: np.ndarray, r: np.ndarray, q: int, run: int) -> np.ndarray:
    """The nodes of pair ``q``'s cells and of up to ``run`` more pairs above ``AIM`` that touch
    them along the interface, the largest first (a run of such pairs moves as one: a patch round one
    of them alone may not lose its neighbours' ratios ≤ 2)."""
    nodes = np.unique(t.cells[pairs[q]].ravel())
    if run <= 0:
        return nodes
    high = np.flatnonzero(r > np.log(AIM))
    if not len(high):  # no pair above AIM (q itself lies between the step's limit and AIM)
        return nodes
    taken = {q}
    for _ in range(run):
        near = np.isin(t.cells[pairs[high]].reshape(len(high), -1), nodes).any(1)
        new = [int(k) for k in high[near] if int(k) not in taken]
        if not new:
            break
        k = max(new, key=lambda v: r[v])
        taken.add(k)
        nodes = np.union1d(nodes, t.cells[pairs[k]].ravel())
    return nodes


def equalize_interfaces(
    topology,
    grids,
    rings,
    *,
    limit: float = LIMIT,
    depth: int = DEPTH,
    max_patches: int = MAX_PATCHES,
    run: int | None = None,
    should_stop: Callable[[], bool] | None = None,
) -> tuple[list, int]:
    """``(grids, patches)``: the grids with the nodes round every interface pair above ``limit``
    moved to make the two cells alike (see the module docstring), and how many patches were kept.

    ``run``: the most neighbouring pairs the second patch round a pair left above ``limit`` takes
    with it (default ``RUN``; 0: no second patch, the step of session 18).

    ``should_stop``: asked before every patch; when it answers True the step ends there, with the
    patches kept so far (``iterate_layout`` passes its ``stop_event``: the app's Stop)."""
    from ..quality.interfaces import interface_pairs

    pr = interface_pairs(grids)
    if not len(pr["ratio"]) or float(pr["ratio"].max()) <= limit:
        return list(grids), 0
    m = topology.node_map
    t = _Tables(topology, grids)
    X, Y = _assemble(grids, m)
    P = np.column_stack([X, Y])
    pairs = np.array([[t.row(a), t.row(b)] for a, b in zip(pr["cell_a"], pr["cell_b"], strict=True)], np.int64)
    shore = (list(rings), [arc_lengths(r) for r in rings])
    tried: set[int] = set()
    kept = 0
    again = RETRY_ROUNDS if RETRY else 0  # the pairs still above the limit once each was tried, tried again
    kept_at = 0  # patches kept when the round began
    t.budget(P)
    for _ in range(max_patches):
        if should_stop is not None and should_stop():
            break
        r = _ratios(P, t, pairs)
        above = [int(q) for q in np.argsort(-r) if r[q] > np.log(limit)]
        order = [q for q in above if q not in tried]
        if not order and again and kept > kept_at:  # (the grid round them has moved since their own try)
            again, tried, order, kept_at = again - 1, set(), above, kept
        if not order:
            break
        q = int(order[0])
        tried.add(q)
        seeds = np.unique(t.cells[pairs[q]].ravel())
        Pn = _first_kept(t, P, seeds, depth, pairs, shore)
        if Pn is not None:
            P = Pn
            kept += 1
            t.budget(P)
        n_run = RUN if run is None else run
        for d in RUN_DEPTHS if n_run > 0 else ():
            if _ratios(P, t, pairs[q : q + 1])[0] <= np.log(limit):
                break
            # the pair is still above the limit: its run of neighbours above AIM moves with it
            wide = _run_seeds(t, pairs, _ratios(P, t, pairs), q, n_run)
            if len(wide) > len(seeds) or d > depth:
                saved = t.movable
                if RUN_SLIDE and d > depth:  # shore nodes slide along the shore in the wider patch
                    t.movable = saved | t.shore
                try:
                    Pn = _first_kept(t, P, wide, max(depth, d), pairs, shore, RUN_WEIGHTS, RUN_METHOD)
                finally:
                    t.movable = saved
                if Pn is not None:
                    P = Pn
                    kept += 1
                    t.budget(P)
    if not kept:
        return list(grids), 0
    return [g.replaced(x=P[ids, 0], y=P[ids, 1]) for g, ids in zip(grids, m.ids, strict=True)], kept


def warm_up() -> None:
    """Compile (or load from numba's cache) the objective's kernel with the argument types of
    :meth:`_Patch.objective`, and the run patches' BFGS update (``meshcore._numba_setup.compile_all``)."""
    i4, i5, i3 = (np.zeros((0, k), np.int64) for k in (4, 5, 3))
    f0, f2, P = np.zeros(0), np.zeros((0, 4)), np.zeros((4, 2))
    _equalize_kernels.objective(P, i4, f0, f2, i4, i4, 0.5, i5, f0, W_COS, i3, f0, W_EDGE, W_JAC, P.copy())
    from ._bfgs import _update  # the run patches' BFGS update

    _update(np.eye(2), np.ones(2), np.ones(2), 1.0, 2.0)
