r"""The skeleton of a water polygon: its pruned medial axis as a graph of branches.

The medial axis is approximated by the Voronoi diagram of points sampled densely along every
shore (outer ring and islands): Voronoi vertices inside the water are centres of inscribed
circles, and a Voronoi edge between two samples on *opposite* shores is a piece of the axis.
Edges between samples on the same stretch of shore are noise of the sampling; they are
removed by a λ-medial-axis test (keep an edge when its two generators are at least
``1.2 × spacing`` apart; neighbouring samples never are).

What is left is simplified to a graph: **nodes** are tips (degree 1) and junctions (degree
≥ 3); **branches** are the chains between them, each a polyline of circle centres with the
radius (half the local channel width) at every point.  Short side branches — bays and bumps
that do not reach far beyond the circle of the junction they leave — are pruned repeatedly
(``prune``), so what remains are the lake's arms.  A lake with an island has a cycle in its
skeleton around the island.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

__all__ = ["Branch", "Skeleton", "skeleton"]


@dataclass(frozen=True, slots=True, eq=False)
class Branch:
    """A chain of the medial axis from node ``a`` to node ``b``.

    ``points`` (k, 2) are inscribed-circle centres from ``a`` to ``b``, ``radius`` (k,) their
    radii (distance to the nearest shore).
    """

    a: int
    b: int
    points: np.ndarray
    radius: np.ndarray

    @property
    def length(self) -> float:
        return float(np.hypot(*np.diff(self.points, axis=0).T).sum())


@dataclass(frozen=True, slots=True, eq=False)
class Skeleton:
    """Nodes (positions, radii) and the branches between them."""

    nodes: np.ndarray  # (n, 2)
    node_radius: np.ndarray  # (n,)
    branches: tuple[Branch, ...]

    def degree(self) -> np.ndarray:
        d = np.zeros(len(self.nodes), dtype=int)
        for b in self.branches:
            d[b.a] += 1
            d[b.b] += 1
        return d


def _samples(poly, spacing: float) -> np.ndarray:
    """Points along every ring, at most ``spacing`` apart (ring vertices included)."""
    import shapely

    rings = [poly.exterior, *poly.interiors]
    out = []
    for r in rings:
        p = np.asarray(shapely.segmentize(r, spacing).coords)[:-1]
        out.append(p)
    return np.vstack(out)


def _raw_axis(poly, spacing: float, lam: float):
    """Voronoi edges of the shore samples inside the water whose generators are ≥ 2·lam apart."""
    import shapely
    from scipy.spatial import Voronoi

    pts = np.unique(_samples(poly, spacing), axis=0)
    vor = Voronoi(pts)
    V = vor.vertices
    shapely.prepare(poly)  # many point and segment tests against one shore: seconds → milliseconds on dense shores
    inside = shapely.contains_xy(poly, V[:, 0], V[:, 1])
    rv = np.asarray(vor.ridge_vertices)
    rp = np.asarray(vor.ridge_points)
    ok = (rv >= 0).all(axis=1)
    rv, rp = rv[ok], rp[ok]
    ok = inside[rv[:, 0]] & inside[rv[:, 1]]
    rv, rp = rv[ok], rp[ok]
    gap = np.hypot(*(pts[rp[:, 0]] - pts[rp[:, 1]]).T)
    rv = rv[gap >= 2.0 * lam]
    # an edge between two inside vertices may still cross a concave shore
    lines = shapely.linestrings(np.stack([V[rv[:, 0]], V[rv[:, 1]]], axis=1))
    rv = rv[shapely.covers(poly, lines)]  # covers, not covered_by: the prepared shore is the first argument
    radius = np.full(len(V), np.nan)
    used = np.unique(rv)
    radius[used] = np.hypot(*(V[used] - _nearest(pts, V[used])).T)
    return V, radius, rv


def _nearest(pts: np.ndarray, q: np.ndarray) -> np.ndarray:
    from scipy.spatial import cKDTree

    _, k = cKDTree(pts).query(q)
    return pts[k]


def _chains(n_vertices: int, edges: np.ndarray):
    """Split an edge list into chains between vertices of degree ≠ 2 (cycles included)."""
    adj: dict[int, list[int]] = {}
    for a, b in edges:
        if a == b:
            continue
        adj.setdefault(int(a), []).append(int(b))
        adj.setdefault(int(b), []).append(int(a))
    for k in adj:
        adj[k] = sorted(set(adj[k]))
    deg = {k: len(v) for k, v in adj.items()}
    seen: set[tuple[int, int]] = set()
    chains = []
    starts = [k for k in adj if deg[k] != 2]
    for s in starts:
        for nb in adj[s]:
            if (s, nb) in seen:
                continue
            chain = [s, nb]
            seen.add((s, nb))
            seen.add((nb, s))
            prev, cur = s, nb
            while deg[cur] == 2:
                nxt = adj[cur][0] if adj[cur][0] != prev else adj[cur][1]
                seen.add((cur, nxt))
                seen.add((nxt, cur))
                chain.append(nxt)
                prev, cur = cur, nxt
            chains.append(chain)
    # pure cycles (every vertex degree 2): an island ring with nothing attached
    for s in adj:
        if deg[s] != 2:
            continue
        nb = adj[s][0]
        if (s, nb) in seen:
            continue
        chain = [s, nb]
        seen.add((s, nb))
        seen.add((nb, s))
        prev, cur = s, nb
        while cur != s:
            nxt = adj[cur][0] if adj[cur][0] != prev else adj[cur][1]
            seen.add((cur, nxt))
            seen.add((nxt, cur))
            chain.append(nxt)
            prev, cur = cur, nxt
        chains.append(chain)
    return chains


def skeleton(poly, *, spacing: float, prune: float = 1.0, min_arm: float = 0.0) -> Skeleton:
    """The pruned medial axis of ``poly`` (a shapely Polygon, islands as holes).

    Parameters
    ----------
    spacing : float
        Sampling distance along the shores (a fraction of the cell size); channels narrower
        than about 1.2 × ``spacing`` are not resolved.
    prune : float
        A side branch ending in a tip is removed when it reaches less than ``prune`` times
        its own width beyond the junction's circle (an arm is longer than it is wide).
    min_arm : float
        ... and also when that reach is below ``min_arm`` (absolute, e.g. a few cells).
    """
    V, radius, edges = _raw_axis(poly, spacing, 0.6 * spacing)
    adj: dict[int, set[int]] = {}
    for a, b in edges:
        adj.setdefault(int(a), set()).add(int(b))
        adj.setdefault(int(b), set()).add(int(a))
    _prune_leaves(adj, V, radius, prune, min_arm)
    edges = np.array([(a, b) for a, nb in adj.items() for b in nb if a < b], dtype=int).reshape(-1, 2)
    chains = _chains(len(V), edges)
    nodes_ids = sorted({v for c in chains for v in (c[0], c[-1])})
    if not chains:  # a single point survived (a round pond): its deepest vertex
        k = int(np.nanargmax(radius))
        return Skeleton(V[[k]].copy(), radius[[k]].copy(), ())
    index = {v: i for i, v in enumerate(nodes_ids)}
    out = tuple(Branch(index[c[0]], index[c[-1]], V[c].copy(), radius[c].copy()) for c in chains)
    return Skeleton(V[nodes_ids].copy(), radius[nodes_ids].copy(), out)


def _leaf_chain(adj, tip):
    """Vertices from a tip to the first vertex of degree ≠ 2 (that vertex last)."""
    path = [tip]
    prev, cur = -1, tip
    while True:
        nxt = [v for v in adj[cur] if v != prev]
        if not nxt:
            return path
        prev, cur = cur, nxt[0]
        path.append(cur)
        if len(adj[cur]) != 2:
            return path


def _prune_leaves(adj, V, radius, prune, min_arm) -> None:
    """Remove weak leaf chains in rounds until none is left (keeps at least one chain)."""
    for _round in range(10_000):
        leaves = [v for v, nb in adj.items() if len(nb) == 1]
        removals = []
        by_junction: dict[int, list] = {}
        for tip in leaves:
            path = _leaf_chain(adj, tip)
            junc = path[-1]
            if len(adj[junc]) < 3:
                continue  # the whole graph is one chain
            reach = float(np.hypot(*(V[tip] - V[junc])) + radius[tip] - radius[junc])
            # the arm's own width, outside the junction's circle (a long narrow arm off a wide
            # basin is an arm; a bump of the basin's shore, or a blunt corner, is not)
            P = V[path]
            out = np.hypot(*(P - V[junc]).T) >= radius[junc]
            width = 2.0 * float(np.median(radius[np.asarray(path)[out]])) if out.any() else 2.0 * radius[tip]
            lim = max(prune * width, min_arm)
            by_junction.setdefault(junc, []).append((reach / max(lim, 1e-300), path))
        for junc, items in by_junction.items():
            weak = [it for it in items if it[0] < 1.0]
            if len(weak) >= len(adj[junc]) - 1:  # keep the junction reachable by two chains
                weak.sort(key=lambda it: it[0])
                weak = weak[: max(0, len(adj[junc]) - 2)]
            removals.extend(p for _, p in weak)
        if not removals:
            return
        for path in removals:
            for u, v in itertools.pairwise(path):
                adj[u].discard(v)
                adj[v].discard(u)
            for u in path[:-1]:
                if not adj.get(u):
                    adj.pop(u, None)
