r"""Cell counts that let the blocks share one ``(I, J)`` index space: ring-closure rows.

A single-domain model grid (Delft3D ``.grd``, EFDC ``cell.inp``) places every block in one
index space (:mod:`.indexspace`).  Round an island the blocks form a ring, and walking round it
the index offsets must come back to where they started: the counts along the ring's two sides
must agree.  The count program (:func:`~.counts.solve_counts`) knows only each block's opposite
sides; :func:`closure_rows` gives the missing equalities, linear in the chain counts.

Every block walks its boundary counter-clockwise from its first corner: bottom ``+I`` from
``(0, 0)``, right ``+J`` from ``(n_i, 0)``, top ``−I`` from ``(n_i, n_j)``, left ``−J`` from
``(0, n_j)``, with ``n_i`` the sum of its bottom chains' counts and ``n_j`` of its right ones.
A break point's position in its block is therefore a linear form in the counts.  A block is
placed by a quarter-turn ``r_b`` and an offset ``o_b``; two blocks sharing a chain walk it in
opposite directions, which fixes ``r_b = r_a + k_a + 2 − k_b`` (mod 4, ``k`` the sides'
numbers) and ``o_b`` from the chain's first point.  A breadth-first walk over the shared chains
places every block as a linear form; each shared chain not on the walk's tree closes a cycle and
gives two rows ``R_a l_a(P) + o_a − R_b l_b(P) − o_b = 0``.  A cycle whose turns do not come
back (a 3- or 5-block corner, an island's ring that turns) has no such counts:
:class:`~meshcore.errors.TopologyError`.

Example: the eight blocks of a 3 × 3 lattice round a hole in its middle cell.  Each block's
opposite sides already agree (the count program's own rows); closing the ring asks in addition
that the blocks below and above the hole be as wide, and those left and right of it as high:

>>> import numpy as np
>>> cells = [(i, j) for j in range(3) for i in range(3) if (i, j) != (1, 1)]
>>> corners = [((i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)) for i, j in cells]
>>> chains, sides = {}, []
>>> for c in corners:
...     sides.append(tuple([chains.setdefault(frozenset((c[k], c[(k + 1) % 4])), len(chains))] for k in range(4)))
>>> ends = [tuple(sorted(k)) for k in chains]
>>> rows = closure_rows(sides, ends, corners)
>>> n = np.ones(len(ends))  # one cell a chain: the ring closes
>>> bool(np.all(rows @ n == 0))
True
>>> for edge in (((1, 0), (2, 0)), ((1, 1), (2, 1))):  # the block below the hole a cell wider
...     n[chains[frozenset(edge)]] = 2
>>> bool(np.all(rows @ n == 0))
False
"""

from __future__ import annotations

from collections import deque
from collections.abc import Hashable, Sequence

import numpy as np

from ..errors import TopologyError

__all__ = ["closure_rows"]

#: Walking direction of side k (bottom, right, top, left) in the block's index space.
_DIR = np.array([(1, 0), (0, 1), (-1, 0), (0, -1)])


def _turn(r: int) -> np.ndarray:
    """The quarter-turn matrix ``R^r`` (counter-clockwise)."""
    c, s = ((1, 0), (0, 1), (-1, 0), (0, -1))[r % 4]
    return np.array([[c, -s], [s, c]])


def _positions(sides, ends, corners, n: int) -> list[dict]:
    """Per block: break-point key → its index position as a (2, n) linear form in the counts,
    and per shared chain the key of its first point in the block's walk."""
    out = []
    for b, four in enumerate(sides):
        ni = np.zeros(n)
        ni[list(four[0])] = 1.0
        nj = np.zeros(n)
        nj[list(four[1])] = 1.0
        start = [np.zeros((2, n)), np.array([ni, 0 * ni]), np.array([ni, nj]), np.array([0 * ni, nj])]
        pos: dict = {}
        first: dict[int, tuple[Hashable, int]] = {}
        for k, chains in enumerate(four):
            cur = corners[b][k]
            form = start[k].copy()
            for c in chains:
                a, z = ends[c]
                if cur not in (a, z):
                    raise TopologyError(f"block {b}: chain {c} does not continue its side {k} (a broken walk)")
                pos.setdefault(cur, form.copy())
                first[c] = (cur, k)
                cur = z if cur == a else a
                form = form + np.outer(_DIR[k], np.eye(n)[c])
            pos.setdefault(cur, form)
        out.append({"pos": pos, "first": first})
    return out


def closure_rows(
    sides: Sequence[Sequence[Sequence[int]]],
    ends: Sequence[tuple[Hashable, Hashable]],
    corners: Sequence[Sequence[Hashable]],
    names: Sequence[str] | None = None,
) -> np.ndarray:
    """Rows ``A`` (m × chains) with ``A @ counts = 0`` exactly when the blocks fit one index space
    (rings closed; whether arms fold onto each other is :mod:`.indexspace`'s check).

    ``sides``: per block its (bottom, right, top, left) chain indices in counter-clockwise walking
    order; ``ends``: per chain its two end keys; ``corners``: per block its four corner keys
    (sw, se, ne, nw); ``names``: the blocks' names for messages.  Raises :class:`TopologyError`
    when a cycle of blocks comes back turned.
    """
    name = list(names) if names is not None else [f"block {b}" for b in range(len(sides))]
    n = len(ends)
    blocks = _positions(sides, ends, corners, n)
    users: dict[int, list[tuple[int, int]]] = {}
    for b, four in enumerate(sides):
        for k, chains in enumerate(four):
            for c in chains:
                users.setdefault(c, []).append((b, k))
    turn: list[int | None] = [None] * len(sides)
    offset: list[np.ndarray | None] = [None] * len(sides)
    rows: list[np.ndarray] = []

    def place(a: int, ka: int, b: int, kb: int, c: int) -> tuple[int, np.ndarray]:
        ra = turn[a]
        assert ra is not None and offset[a] is not None
        rb = (ra + ka + 2 - kb) % 4
        p = blocks[a]["first"][c][0]  # a walks c from p; b walks it towards p
        ob = _turn(ra) @ blocks[a]["pos"][p] + offset[a] - _turn(rb) @ blocks[b]["pos"][p]
        return rb, ob

    for root in range(len(sides)):
        if turn[root] is not None:
            continue
        turn[root], offset[root] = 0, np.zeros((2, n))
        queue = deque([root])
        while queue:
            a = queue.popleft()
            for k, chains in enumerate(sides[a]):
                for c in chains:
                    for b, kb in users[c]:
                        if b == a:
                            continue
                        rb, ob = place(a, k, b, kb, c)
                        if turn[b] is None:
                            turn[b], offset[b] = rb, ob
                            queue.append(b)
                        elif turn[b] != rb:
                            p = blocks[a]["first"][c][0]
                            where = f" near ({p[0]:.8g}, {p[1]:.8g})" if isinstance(p, tuple) and len(p) == 2 else ""
                            raise TopologyError(
                                f"the blocks do not fit one index space: walking round the blocks from {name[a]} "
                                f"to {name[b]}{where}, the index directions come back turned (a corner of 3 or "
                                f"5 blocks, or a ring round an island that turns)"
                            )
                        elif a < b:  # each shared chain once
                            ob_have = offset[b]
                            assert ob_have is not None
                            for r in ob - ob_have:
                                if np.any(np.abs(r) > 1e-9):
                                    rows.append(r)
    if not rows:
        return np.zeros((0, n))
    out = np.array(rows)
    return out[np.unique(np.round(out, 9), axis=0, return_index=True)[1]]
