r"""From four-cornered pieces to a multiblock topology: chains, counts, borders, interfaces.

The pieces are counter-clockwise rings that share their common edges vertex for vertex
(:func:`conform` inserts every vertex into every ring whose edge it lies on, so T-junctions
are explicit).  Each ring has four corner indices.  The boundary of each piece is cut into
**chains** at its corners and wherever the neighbour across changes; a chain is shared by at
most two pieces.  Counts come from :func:`~meshcore.multiblock.counts.solve_counts`; each chain is re-sampled
once (uniformly in arc length) and used by both neighbours, so interface nodes coincide by
construction.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from ..boundary import Borders
from ..errors import TopologyError
from ..multiblock.counts import solve_counts
from ..multiblock.topology import Block, Interface, MultiBlockTopology, Side

__all__ = ["Piece", "build_topology", "conform"]

BORDERS = ("bottom", "right", "top", "left")


@dataclass(frozen=True, slots=True, eq=False)
class Piece:
    """A region with its four corners (indices into ``ring``, counter-clockwise sw, se, ne, nw)."""

    ring: np.ndarray
    corners: tuple[int, int, int, int]
    name: str = ""


def _key(p) -> tuple[float, float]:
    return (float(p[0]), float(p[1]))


def conform(rings: list[np.ndarray], eps: float) -> list[np.ndarray]:
    """Insert every ring vertex that lies on another ring's edge into that edge (T-junctions)."""
    from scipy.spatial import cKDTree

    allv = np.unique(np.vstack(rings), axis=0)
    tree = cKDTree(allv)
    out = []
    for r in rings:
        a, b = r, np.roll(r, -1, axis=0)
        d = b - a
        L = np.hypot(*d.T)
        # candidate vertices: within half an edge (plus eps) of the edge's midpoint
        cand = tree.query_ball_point(0.5 * (a + b), 0.5 * L + eps)
        pts = []
        for k in range(len(r)):
            pts.append(r[k])
            idx = np.asarray(cand[k], dtype=int)
            if len(idx) <= 2 or L[k] == 0:
                continue
            v = allv[idx]
            t = ((v - a[k]) @ d[k]) / (L[k] * L[k])
            foot = a[k] + np.outer(t, d[k])
            on = (t > 1e-9) & (t < 1 - 1e-9) & (np.hypot(*(v - foot).T) <= eps)
            for j in np.argsort(t[on]):
                pts.append(v[on][j])
        out.append(np.array(pts))
    return out


def _chains_of(pieces: list[Piece]):
    """Per piece and side, the chain keys; the chain polylines; the users of each chain."""
    edge_users: dict = {}
    for pi, pc in enumerate(pieces):
        r = pc.ring
        n = len(r)
        for k in range(n):
            e = (_key(r[k]), _key(r[(k + 1) % n]))
            edge_users.setdefault(frozenset(e), []).append(pi)
    corner_keys = {_key(pc.ring[c]) for pc in pieces for c in pc.corners}
    side_chains = {}
    chain_pts: dict = {}
    chain_users: dict = {}
    for pi, pc in enumerate(pieces):
        r = pc.ring
        n = len(r)
        cs = list(pc.corners)
        for side, (a, b) in zip(BORDERS, zip(cs, cs[1:] + cs[:1], strict=True), strict=True):
            walk = [r[(a + s) % n] for s in range((b - a) % n + 1)]
            chains, cur = [], [walk[0]]
            prev_users = None
            for p, q in itertools.pairwise(walk):
                users = tuple(sorted(edge_users[frozenset((_key(p), _key(q)))]))
                if prev_users is not None and (users != prev_users or _key(p) in corner_keys):
                    chains.append(np.array(cur))
                    cur = [p]
                cur.append(q)
                prev_users = users
            chains.append(np.array(cur))
            keys = []
            for ch in chains:
                fwd = tuple(_key(p) for p in ch)
                key = min(fwd, fwd[::-1])
                chain_pts.setdefault(key, np.array(key))
                chain_users.setdefault(key, []).append((pi, side))
                keys.append(key)
            side_chains[(pi, side)] = keys
    return side_chains, chain_pts, chain_users


def _resample(chain: np.ndarray, n_cells: int) -> np.ndarray:
    s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(chain, axis=0).T))])
    u = np.linspace(0.0, s[-1], n_cells + 1)
    out = np.column_stack([np.interp(u, s, chain[:, 0]), np.interp(u, s, chain[:, 1])])
    out[0], out[-1] = chain[0], chain[-1]
    return out


def build_topology(
    pieces: list[Piece],
    cell_size: float,
    *,
    min_cells: int = 3,
    multiple: int = 1,
    block_cells: dict[int, tuple[int, int]] | None = None,
):
    """The :class:`MultiBlockTopology` of ``pieces`` with counts for ``cell_size``
    (``block_cells``: pieces whose cells ``(ni, nj)`` are given)."""
    side_chains, chain_pts, chain_users = _chains_of(pieces)
    keys = list(chain_pts)
    index = {k: i for i, k in enumerate(keys)}
    length = np.array([float(np.hypot(*np.diff(chain_pts[k], axis=0).T).sum()) for k in keys])
    sides = [tuple([index[k] for k in side_chains[(pi, s)]] for s in BORDERS) for pi in range(len(pieces))]
    counts = solve_counts(length / cell_size, sides, min_cells=min_cells, multiple=multiple, block_cells=block_cells)
    nodes = {k: _resample(chain_pts[k], int(counts[index[k]])) for k in keys}
    blocks, offsets = [], {}
    for pi, pc in enumerate(pieces):
        walked = {}
        for si, side in enumerate(BORDERS):
            pieces_xy, at = [], 0
            start = _key(pc.ring[pc.corners[si]])
            for key in side_chains[(pi, side)]:
                p = nodes[key]
                if pieces_xy:
                    if not np.array_equal(p[0], pieces_xy[-1][-1]):
                        p = p[::-1]
                elif _key(p[0]) != start:
                    p = p[::-1]
                offsets[(pi, side, key)] = (at, at + len(p) - 1)
                at += len(p) - 1
                pieces_xy.append(p)
            walked[side] = np.vstack([pieces_xy[0]] + [q[1:] for q in pieces_xy[1:]])
        # walked counter-clockwise: top and left run backwards
        for side in ("top", "left"):
            n_side = len(walked[side]) - 1
            walked[side] = walked[side][::-1].copy()
            for key in side_chains[(pi, side)]:
                a, b = offsets[(pi, side, key)]
                offsets[(pi, side, key)] = (n_side - b, n_side - a)
        bd = Borders(bottom=walked["bottom"], right=walked["right"], top=walked["top"], left=walked["left"])
        blocks.append(Block(pc.name or f"b{pi}", bd, initial="tfi"))
    interfaces = []
    for key, users in chain_users.items():
        if len(users) == 2:
            (pa, sa), (pb, sb) = users
            a0, a1 = offsets[(pa, sa, key)]
            b0, b1 = offsets[(pb, sb, key)]
            interfaces.append(Interface(Side(blocks[pa].name, sa, a0, a1), Side(blocks[pb].name, sb, b0, b1), None))
        elif len(users) > 2:
            c = np.asarray(key).mean(axis=0)
            raise TopologyError(
                f"blocks overlap: an edge near ({c[0]:.6g}, {c[1]:.6g}) is shared by {len(users)} blocks"
            )
    return MultiBlockTopology(tuple(blocks), tuple(interfaces), check_geometry=False), counts
