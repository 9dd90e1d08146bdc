"""Shared border chains of an outline split into blocks: cell counts, nodes, interfaces.

Each block side (walked counter-clockwise on its region) is split into
**chains** at block corners and at points where three or more lines meet.  A
chain shared by two blocks is re-sampled once (uniformly in arc length, the
paper's linear spline) and used by both, so interface nodes are identical by
construction.  A side's chains must add up to its block's ``ni`` (bottom, top)
or ``nj`` (left, right): counts fixed by another block are taken from there,
the remaining cells of a side are shared among its free chains by arc length.
Used by :func:`meshcore.multiblock.from_outline`.
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from ..boundary import Borders
from ..errors import TopologyError
from ..pointindex import point_key, point_keys
from .topology import Block, Interface, MultiBlockTopology, Side

__all__ = ["chain_topology", "side_chains"]

SIDES = ("bottom", "right", "top", "left")

Key = tuple  # a chain: its vertices as (x, y) tuples, in the smaller of its two directions


def _resample(chain: np.ndarray, n_cells: int) -> np.ndarray:
    s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(chain, axis=0).T))])
    u = np.linspace(0.0, s[-1], n_cells + 1)
    out = np.column_stack([np.interp(u, s, chain[:, 0]), np.interp(u, s, chain[:, 1])])
    out[0], out[-1] = chain[0], chain[-1]
    return out


def side_chains(specs: list, rings: dict[str, np.ndarray], corners: dict[str, list], breaks: set) -> tuple:
    """``(side → chain keys, chain key → points, chain key → [(block, side)])``."""
    side_chains: dict[tuple[str, str], list[Key]] = {}
    chain_pts: dict[Key, np.ndarray] = {}
    chain_users: dict[Key, list[tuple[str, str]]] = defaultdict(list)
    for s in specs:
        kr = point_keys(rings[s.name])
        n = len(kr)
        pos = {k: i for i, k in enumerate(kr)}
        ci = [pos[c] for c in corners[s.name]]
        for side, (a, b) in zip(SIDES, zip(ci, ci[1:] + ci[:1], strict=True), strict=True):
            walk = [kr[(a + k) % n] for k in range((b - a) % n + 1)]
            chains, cur = [], [walk[0]]
            for p in walk[1:]:
                cur.append(p)
                if p in breaks:
                    chains.append(cur)
                    cur = [p]
            keys = []
            for ch in chains:
                fwd = tuple(ch)
                key = min(fwd, fwd[::-1])
                chain_pts.setdefault(key, np.array(key))
                keys.append(key)
                chain_users[key].append((s.name, side))
            side_chains[(s.name, side)] = keys
    return side_chains, chain_pts, chain_users


class _Counts:
    """Cells per chain, so that every side adds up to its block's count."""

    def __init__(self, specs: list, side_chains: dict, chain_pts: dict, chain_users: dict, multiple: int) -> None:
        self.side_chains, self.chain_pts, self.chain_users = side_chains, chain_pts, chain_users
        self.multiple = multiple
        self.need = {
            (s.name, side): int(s.cells[0] if side in ("bottom", "top") else s.cells[1])
            for s in specs
            for side in SIDES
        }
        self.count: dict[Key, int] = {}

    def arclen(self, key: Key) -> float:
        return float(np.hypot(*np.diff(self.chain_pts[key], axis=0).T).sum())

    def describe(self, bs: tuple[str, str]) -> str:
        parts = []
        for key in self.side_chains[bs]:
            other = [u for u in self.chain_users[key] if u != bs]
            who = f"shared with {other[0][0]}.{other[0][1]}" if other else "shore"
            parts.append(f"{self.count.get(key, '?')} ({who})")
        return " + ".join(parts)

    def propagate(self) -> None:
        """Sides with one unknown chain: it gets the rest of the side."""
        changed = True
        while changed:
            changed = False
            for bs, keys in self.side_chains.items():
                unknown = [k for k in keys if k not in self.count]
                if len(unknown) == 1:
                    rest = self.need[bs] - sum(self.count[k] for k in keys if k in self.count)
                    if rest < 1:
                        raise TopologyError(
                            f"cell counts disagree at block {bs[0]!r} {bs[1]} border: it has "
                            f"{self.need[bs]} cells but its parts already need {self.describe(bs)}"
                        )
                    self.count[unknown[0]] = rest
                    changed = True

    def share(self, bs: tuple[str, str], keys: list[Key]) -> None:
        """The free chains of one side share its remaining cells by arc length (in units of ``multiple``)."""
        unknown = [k for k in keys if k not in self.count]
        rest = self.need[bs] - sum(self.count[k] for k in keys if k in self.count)
        if rest < len(unknown) * self.multiple:
            raise TopologyError(
                f"cell counts disagree at block {bs[0]!r} {bs[1]} border: {self.need[bs]} cells cannot "
                f"hold its parts {self.describe(bs)} with at least {self.multiple} cell(s) each"
            )
        units = rest // self.multiple
        w = np.array([self.arclen(k) for k in unknown])
        share = 1 + (units - len(unknown)) * w / w.sum()
        base = np.floor(share).astype(int)
        for k in np.argsort(-(share - base))[: units - int(base.sum())]:
            base[k] += 1
        for k, c in zip(unknown, base.tolist(), strict=True):
            self.count[k] = int(c) * self.multiple

    def implied(self) -> dict[Key, int] | None:
        """The counts the blocks' cells imply: from the chains that are a whole side, every chain
        that is the rest of a side whose other chains are known (:meth:`propagate`).  Every integer
        solution has them (they follow from the sides' sums alone): when they are every chain's and
        agree (:meth:`complete`), they are the only solution of the program of
        :func:`~.counts.solve_counts`.  (Fixing them in the program when some are left gives it no
        less work: 13 ms either way on Como, whose branch and bound is on the free chains.)  None
        when they are not valid counts (below ``multiple`` or not a multiple of it: no solution;
        the program says where)."""
        try:
            self.propagate()
        except TopologyError:
            return None
        m = self.multiple
        if any(c < m or c % m for c in self.count.values()):
            return None
        return dict(self.count)

    def complete(self, count: dict[Key, int]) -> bool:
        """True when ``count`` has every chain and every side adds up to its block's cells."""
        return len(count) == len(self.chain_pts) and all(
            sum(count[k] for k in keys) == self.need[bs] for bs, keys in self.side_chains.items()
        )

    def solve(self) -> dict[Key, int]:
        while True:
            self.propagate()
            open_sides = [(bs, keys) for bs, keys in self.side_chains.items() if any(k not in self.count for k in keys)]
            if not open_sides:
                break
            self.share(*open_sides[0])
        for bs, keys in self.side_chains.items():
            if sum(self.count[k] for k in keys) != self.need[bs]:
                raise TopologyError(
                    f"cell counts disagree across an interface: block {bs[0]!r} {bs[1]} border needs "
                    f"{self.need[bs]} cells but its parts have {self.describe(bs)} = "
                    f"{sum(self.count[k] for k in keys)}; change the cells of {bs[0]!r} or of its neighbours"
                )
        return self.count


def _kept(counts: _Counts, keep: Mapping[tuple[str, str], Sequence[int]]) -> dict[Key, int] | None:
    """The counts of ``keep`` (cells per chain of each block side, in the side's order) when every
    side still has that many chains, the two blocks of a shared chain agree on it and the counts
    are valid (multiples of ``multiple``, every side adding up); else None."""
    out: dict[Key, int] = {}
    for bs, keys in counts.side_chains.items():
        given = keep.get(bs)
        if given is None or len(given) != len(keys):
            return None
        for k, c in zip(keys, given, strict=True):
            if out.setdefault(k, int(c)) != int(c):
                return None
    m = counts.multiple
    if any(c < m or c % m for c in out.values()) or not counts.complete(out):
        return None
    return out


def _chain_counts(
    specs: list,
    side_chains: dict,
    chain_pts: dict,
    chain_users: dict,
    multiple: int,
    cell_size: float | None,
    keep: Mapping[tuple[str, str], Sequence[int]] | None = None,
    rings: Mapping[str, np.ndarray] | None = None,
    corners: Mapping[str, Sequence[Any]] | None = None,
) -> dict[Key, int]:
    """Cells per chain: the integer program of :func:`~.counts.solve_counts` with every block's cells
    given; when it has no solution, the step-by-step count names the block and border at fault.
    ``keep``: counts per block side taken instead of the program's while they still fit (:func:`_kept`);
    ``rings``: the blocks' regions, for :func:`~.shorecells.least_weights`; ``corners`` (each
    block's four corner keys): the counts also close every ring of blocks in one index space
    (:func:`~.closure.closure_rows`)."""
    from .counts import solve_counts
    from .shorecells import least_weights, shore_least

    keys = list(chain_pts)
    counts = _Counts(specs, side_chains, chain_pts, chain_users, multiple)
    implied = counts.implied()
    if implied is not None and counts.complete(implied):  # the cells fix every chain: the only solution
        return {k: int(implied[k]) for k in keys}
    kept = None if keep is None or corners is not None else _kept(counts, keep)
    if kept is not None:
        return {k: kept[k] for k in keys}
    index = {k: i for i, k in enumerate(keys)}
    length = np.array([float(np.hypot(*np.diff(chain_pts[k], axis=0).T).sum()) for k in keys])
    if cell_size is None:  # each chain at the cell size of the sides it lies on
        scale = np.zeros(len(keys))
        users = np.zeros(len(keys))
        for s in specs:
            for side in SIDES:
                ks = side_chains[(s.name, side)]
                need = s.cells[0] if side in ("bottom", "top") else s.cells[1]
                total = sum(length[index[k]] for k in ks)
                for k in ks:
                    scale[index[k]] += need / total if total > 0 else 0.0
                    users[index[k]] += 1
        targets = length * scale / np.maximum(users, 1)
    else:
        targets = np.round(length / float(cell_size), 6)  # as the layout's counts (meshcore.layout.blocks)
    sides = [tuple([index[k] for k in side_chains[(s.name, side)]] for side in SIDES) for s in specs]
    cells = {bi: (int(s.cells[0]), int(s.cells[1])) for bi, s in enumerate(specs)}
    equal = None
    if corners is not None:
        from .closure import closure_rows

        equal = closure_rows(
            sides, [(k[0], k[-1]) for k in keys], [corners[s.name] for s in specs], names=[s.name for s in specs]
        )
    pts, on_shore = [chain_pts[k] for k in keys], [len(chain_users[k]) == 1 for k in keys]
    try:
        least = None if cell_size is None else shore_least(pts, on_shore, cell_size, multiple)
        weight = None if least is None or rings is None else least_weights(pts, on_shore, list(rings.values()))
        n = solve_counts(
            targets,
            sides,
            min_cells=1,
            multiple=multiple,
            block_cells=cells,
            least=least,
            least_weight=weight,
            equal=equal,
        )
    except TopologyError:
        _Counts(specs, side_chains, chain_pts, chain_users, multiple).solve()  # names the conflict
        raise
    return {k: int(n[index[k]]) for k in keys}


def _block(s: Any, side_chains: dict, nodes: dict, corners: list, offsets: dict) -> Block:
    """One block's borders from its chains' nodes; records each chain's node range in ``offsets``."""
    sides = {}
    for side in SIDES:
        pieces: list[np.ndarray] = []
        at = 0
        for key in side_chains[(s.name, side)]:
            p = nodes[key]
            if pieces:
                if not np.array_equal(p[0], pieces[-1][-1]):
                    p = p[::-1]
            elif point_key(p[0]) != corners[SIDES.index(side)]:
                p = p[::-1]
            offsets[(s.name, side, key)] = (at, at + len(p) - 1)
            at += len(p) - 1
            pieces.append(p)
        sides[side] = np.vstack([pieces[0]] + [q[1:] for q in pieces[1:]])
    # walked CCW: bottom sw→se, right se→ne, top ne→nw, left nw→sw; top and left run the other way
    for side in ("top", "left"):
        n = len(sides[side]) - 1
        sides[side] = sides[side][::-1].copy()
        for key in side_chains[(s.name, side)]:
            a, b = offsets[(s.name, side, key)]
            offsets[(s.name, side, key)] = (n - b, n - a)
    bd = Borders(bottom=sides["bottom"], right=sides["right"], top=sides["top"], left=sides["left"])
    return Block(s.name, bd, initial=s.initial)


def chain_topology(
    specs: list,
    rings: dict[str, np.ndarray],
    corners: dict[str, list],
    breaks: set,
    multiple: int,
    *,
    check_geometry: bool = True,
    cell_size: float | None = None,
    keep: Mapping[tuple[str, str], Sequence[int]] | None = None,
    single: bool = False,
) -> tuple[MultiBlockTopology, dict[tuple[str, str], tuple[int, ...]]]:
    """The topology of blocks on regions, and the cells of the chains of every block side
    (``(block, side) →`` counts in the side's order).

    ``specs``: the :class:`~.outline.BlockOutline` of each block; ``rings``: its
    region (counter-clockwise vertex ring); ``corners``: its four corner
    vertices (``(x, y)`` tuples, sw, se, ne, nw); ``breaks``: vertices where
    chains end (corners and junctions of three or more lines).  ``check_geometry=False``
    skips the topology's shapely checks (islands are holes the blocks do not cover).
    Where a side has several chains, its cells are shared among them as
    :func:`~.counts.solve_counts` does: closest to ``length / cell_size`` (default: each
    side's own cell size), integer and consistent round every block.  ``keep`` (such counts of
    the layout before an edit) is taken instead where it still fits every side.  ``single``: the
    counts also close every ring of blocks in one index space (:mod:`.closure`).
    """
    sides, chain_pts, chain_users = side_chains(specs, rings, corners, breaks)
    count = _chain_counts(
        specs, sides, chain_pts, chain_users, multiple, cell_size, keep, rings, corners if single else None
    )
    nodes = {key: _resample(chain_pts[key], count[key]) for key in chain_pts}
    offsets: dict[tuple[str, str, Key], tuple[int, int]] = {}
    blocks = [_block(s, sides, nodes, corners[s.name], offsets) for s in specs]
    interfaces = []
    for key, users in chain_users.items():
        if len(users) == 2:
            (ba, sa), (bb, sb) = users
            a0, a1 = offsets[(ba, sa, key)]
            b0, b1 = offsets[(bb, sb, key)]
            interfaces.append(Interface(Side(ba, sa, a0, a1), Side(bb, sb, b0, b1), None))
    topo = MultiBlockTopology(tuple(blocks), tuple(interfaces), check_geometry=check_geometry)
    return topo, {bs: tuple(count[k] for k in keys) for bs, keys in sides.items()}
