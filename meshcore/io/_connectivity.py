"""Block connectivity of grid files: 1-to-1 interfaces, found, coerced and checked.

An :class:`Interface` pairs the nodes of (part of) one block border with the
nodes of (part of) another's.  :func:`find_interfaces` finds them from
coordinates, :func:`coerce_interfaces` turns records (dicts, multiblock
topology interfaces) into them, :func:`check_interface` is the shared-node
check writers and readers run.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import WriteError
from ..grid import BORDER_NAMES, StructuredGrid

__all__ = ["Interface", "border_ij", "check_interface", "coerce_interfaces", "find_interfaces"]


@dataclass(frozen=True, slots=True)
class Interface:
    """A 1-to-1 connection: nodes of ``border_a`` of block ``a`` coincide node by node
    with nodes of ``border_b`` of block ``b``.

    ``range_a = (start, stop)`` (inclusive node indices, counted in the border's
    own direction) limits the connection to part of a border; ``None`` is the
    whole border.  ``reversed``: ``a[start_a + k]`` pairs with ``b[stop_b − k]``
    instead of ``b[start_b + k]``.
    """

    a: int
    border_a: str
    b: int
    border_b: str
    reversed: bool = False
    range_a: tuple[int, int] | None = None
    range_b: tuple[int, int] | None = None

    def span(self, side: str, blocks: Sequence[StructuredGrid]) -> tuple[int, int]:
        """``(start, stop)`` of side ``"a"`` or ``"b"`` (the whole border when the range is None)."""
        k, border, rng = (self.a, self.border_a, self.range_a) if side == "a" else (self.b, self.border_b, self.range_b)
        if rng is not None:
            return (int(rng[0]), int(rng[1]))
        n = blocks[k].shape[0] if border in ("bottom", "top") else blocks[k].shape[1]
        return (0, n - 1)

    def node_pairs(self, blocks: Sequence[StructuredGrid]) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``(ia, ja, ib, jb)``: node indices of the paired nodes in block ``a`` and block ``b``."""
        (sa, ea), (sb, eb) = self.span("a", blocks), self.span("b", blocks)
        ia, ja = border_ij(blocks[self.a].shape, self.border_a)
        ib, jb = border_ij(blocks[self.b].shape, self.border_b)
        ia, ja, ib, jb = ia[sa : ea + 1], ja[sa : ea + 1], ib[sb : eb + 1], jb[sb : eb + 1]
        if self.reversed:
            ib, jb = ib[::-1], jb[::-1]
        return ia, ja, ib, jb

    @property
    def label(self) -> str:
        ra = "" if self.range_a is None else f"[{self.range_a[0]}:{self.range_a[1]}]"
        rb = "" if self.range_b is None else f"[{self.range_b[0]}:{self.range_b[1]}]"
        return f"block {self.a} {self.border_a}{ra} ↔ block {self.b} {self.border_b}{rb}" + (
            " (reversed)" if self.reversed else ""
        )


def border_ij(shape: tuple[int, int], border: str) -> tuple[np.ndarray, np.ndarray]:
    """``(i, j)`` index arrays of a border's nodes, in the border's own direction."""
    n1, m1 = shape
    if border == "bottom":
        return np.arange(n1), np.zeros(n1, dtype=np.int64)
    if border == "top":
        return np.arange(n1), np.full(n1, m1 - 1)
    if border == "left":
        return np.zeros(m1, dtype=np.int64), np.arange(m1)
    return np.full(m1, n1 - 1), np.arange(m1)


def find_interfaces(blocks: Sequence[StructuredGrid], *, rtol: float = 1e-9) -> tuple[Interface, ...]:
    """1-to-1 interfaces between blocks, found by coordinates — whole borders and parts of borders.

    Border nodes of different blocks that coincide (to ``rtol`` times the
    largest block size) are paired; every maximal run of two or more
    consecutive pairs (in the same or the reverse order) is one interface.
    Whole-border interfaces carry ``range_a = range_b = None``.
    """
    from scipy.spatial import cKDTree

    if len(blocks) < 2:
        return ()
    size = max((g.size for g in blocks), default=1.0) or 1.0
    tol = rtol * size
    keys, idx, pts = [], [], []
    for k, g in enumerate(blocks):
        for b in BORDER_NAMES:
            p = g.border(b)
            keys.extend([(k, b)] * len(p))
            idx.append(np.arange(len(p)))
            pts.append(p)
    P = np.vstack(pts)
    node = np.concatenate(idx)
    owner = np.array([k for k, _ in keys])
    pairs = cKDTree(P).query_pairs(tol, output_type="ndarray")
    groups: dict[tuple, list[tuple[int, int]]] = {}
    for u, v in pairs.tolist():
        if owner[u] == owner[v]:
            continue
        if (keys[u], node[u]) > (keys[v], node[v]):
            u, v = v, u
        groups.setdefault((keys[u], keys[v]), []).append((int(node[u]), int(node[v])))
    found = []
    for ((ka, ba), (kb, bb)), lst in sorted(groups.items()):
        na = blocks[ka].shape[0] if ba in ("bottom", "top") else blocks[ka].shape[1]
        nb = blocks[kb].shape[0] if bb in ("bottom", "top") else blocks[kb].shape[1]
        for run, rev in _runs(sorted(set(lst))):
            (a0, b0), (a1, b1) = run[0], run[-1]
            ra, rb = (a0, a1), (min(b0, b1), max(b0, b1))
            whole = ra == (0, na - 1) and rb == (0, nb - 1)
            found.append(Interface(ka, ba, kb, bb, rev, None if whole else ra, None if whole else rb))
    return tuple(found)


def _runs(pairs: list[tuple[int, int]]) -> list[tuple[list[tuple[int, int]], bool]]:
    """Maximal runs of ``(i_a, i_b)`` pairs with i_a stepping by 1 and i_b by +1 (or −1: reversed)."""
    out = []
    used: set[tuple[int, int]] = set()
    have = set(pairs)
    for p in pairs:
        if p in used:
            continue
        for step, rev in ((1, False), (-1, True)):
            run = [p]
            while (run[-1][0] + 1, run[-1][1] + step) in have:
                run.append((run[-1][0] + 1, run[-1][1] + step))
            if len(run) >= 2 and not any(q in used for q in run):
                out.append((run, rev))
                used.update(run)
                break
    return out


def coerce_interfaces(conn: Any, blocks: Sequence[StructuredGrid], names: Sequence[str] = ()) -> tuple[Interface, ...]:
    """Interfaces from records: :class:`Interface`, dicts or objects with a/border_a/b/border_b
    (optionally reversed, range_a, range_b), or the interfaces of a multiblock topology
    (``Interface(Side(block, border, start, stop), Side(...), reversed)``, blocks by name)."""
    if conn is None:
        return find_interfaces(blocks) if len(blocks) > 1 else ()
    out = []
    for k, r in enumerate(conn):
        if isinstance(r, Interface):
            it = r
        elif hasattr(getattr(r, "a", None), "block"):  # meshcore.multiblock.Interface (named sides)
            sa, sb = r.a, r.b
            try:
                ka, kb = list(names).index(sa.block), list(names).index(sb.block)
            except ValueError:
                raise WriteError(
                    f"connectivity record {k} names a block that is not written: {sa.block}/{sb.block}"
                ) from None
            ra, rb = (
                (int(sd.start), int(sd.stop) if int(sd.stop) >= 0 else _border_len(blocks[kd], sd.border) - 1)
                for sd, kd in ((sa, ka), (sb, kb))
            )
            it = Interface(ka, sa.border, kb, sb.border, bool(r.reversed), ra, rb)
        else:
            get = r.get if isinstance(r, dict) else (lambda key, d=None, r=r: getattr(r, key, d))
            try:
                ra, rb = get("range_a"), get("range_b")
                it = Interface(
                    int(get("a")),
                    str(get("border_a")),
                    int(get("b")),
                    str(get("border_b")),
                    bool(get("reversed", False)),
                    None if ra is None else (int(ra[0]), int(ra[1])),
                    None if rb is None else (int(rb[0]), int(rb[1])),
                )
            except (TypeError, ValueError, IndexError) as exc:
                raise WriteError(
                    f"connectivity record {k} must have a, border_a, b, border_b (and optionally reversed, "
                    f"range_a, range_b): {exc}"
                ) from None
        if (
            it.border_a not in BORDER_NAMES
            or it.border_b not in BORDER_NAMES
            or not (0 <= it.a < len(blocks) and 0 <= it.b < len(blocks))
        ):
            raise WriteError(f"connectivity record {k} names an unknown block or border: {it}")
        check_interface(it, blocks, f"connectivity record {k}", WriteError)
        out.append(it)
    return tuple(out)


def _border_len(g: StructuredGrid, border: str) -> int:
    return g.shape[0] if border in ("bottom", "top") else g.shape[1]


def check_interface(it: Interface, blocks: Sequence[StructuredGrid], where: str, error: type[Exception]) -> None:
    """The shared-node check: the ranges fit the borders, the counts agree and the paired nodes coincide."""
    for side in ("a", "b"):
        k, border = (it.a, it.border_a) if side == "a" else (it.b, it.border_b)
        n = blocks[k].shape[0] if border in ("bottom", "top") else blocks[k].shape[1]
        s, e = it.span(side, blocks)
        if not 0 <= s < e <= n - 1:
            raise error(f"{where}: {it.label}: node range {s}…{e} does not fit block {k} {border} ({n} nodes)")
    (sa, ea), (sb, eb) = it.span("a", blocks), it.span("b", blocks)
    if ea - sa != eb - sb:
        raise error(f"{where}: {it.label}: {ea - sa + 1} nodes on one side, {eb - sb + 1} on the other")
    ia, ja, ib, jb = it.node_pairs(blocks)
    ga, gb = blocks[it.a], blocks[it.b]
    gap = np.hypot(ga.x[ia, ja] - gb.x[ib, jb], ga.y[ia, ja] - gb.y[ib, jb])
    tol = 1e-7 * max(ga.size, gb.size, 1e-300)
    if not (gap <= tol).all():
        m = int(np.argmax(np.where(np.isfinite(gap), gap, np.inf)))
        raise error(
            f"{where}: {it.label}: shared node {m} does not coincide with its partner (gap {gap[m]:.3g}); "
            f"the blocks do not fit together there"
        )
