r"""Delft3D-FLOW domain decomposition: a ``.grd``/``.enc`` per block and the ``.ddb`` couplings.

``write("lake.ddb", mbgrid)`` writes, next to each other::

    lake.ddb                  the coupling file
    lake_<block>.grd/.enc     one RGFGRID grid and enclosure per block (:mod:`.delft3d`)

Each line of the ``.ddb`` couples a segment of one domain's boundary to a
segment of another's::

    lake_main.grd    49     5    49    13   lake_arm.grd     1     1     1     9

``m1 n1 m2 n2`` are the 1-based **grid-point** (depth-point, corner) indices of
the segment's begin and end in that domain's ``.grd`` numbering — node
``(i, j)`` of a block is ``(m, n) = (i + 1, j + 1)``, so a right border is the
line ``m = MMAX`` and the water-level cells next to it are ``n1+1 … n2``.  A
segment lies on one grid line (``m1 = m2`` or ``n1 = n2``) and may be part of a
border (a T-junction); begin matches begin.  Delft3D couples M-lines only to
M-lines and N-lines only to N-lines, in the same direction ("DD grids require
the same M,N orientation", Deltares RGFGRID course; Delft3D's own ``ddcouple``
reads a constant-``m`` segment of the first domain as a constant-``m`` segment
of the second).  The writer therefore turns blocks by quarter turns of their
index space (fewest turned blocks) so that every interface joins a right
border to a left one or a top border to a bottom one; a layout where that is
impossible — a corner where 3 or 5 blocks meet, or a ring of blocks round
an island whose index directions come back turned by a quarter — is a clear
:class:`~meshcore.errors.WriteError`.

Couplings are found from the coordinates: border edges of two blocks whose end
nodes coincide (within ``1e-7`` of the domain size), grouped into runs.  The
files are written as a set: all into a staging folder first, then moved into
place; on any failure none of them is left (and files they would have replaced
are restored).

:func:`read_dd` reads a ``.ddb`` with its grids back into blocks and
:class:`~meshcore.multiblock.Interface` records (node ranges);
``read_blocks("lake.ddb")`` gives the blocks as a :class:`GridSet`.
"""

from __future__ import annotations

import contextlib
import os
import re
import shutil
import tempfile
from collections import defaultdict
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import MeshcoreError, ReadError, WriteError
from ..grid import BORDER_NAMES, StructuredGrid
from ._base import GridSet, Interface, decode_text, read_bytes

__all__ = ["Coupling", "DomainDecomposition", "find_couplings", "read_dd", "read_ddb", "write_ddb"]


@dataclass(frozen=True, slots=True)
class Coupling:
    """Nodes ``start_a … stop_a`` of border ``border_a`` of block ``a`` coincide with nodes
    ``start_b … stop_b`` of ``border_b`` of block ``b`` (in each border's own direction;
    ``reversed``: the second run is walked backwards)."""

    a: int
    border_a: str
    start_a: int
    stop_a: int
    b: int
    border_b: str
    start_b: int
    stop_b: int
    reversed: bool = False


def _border_edges(blocks: list[StructuredGrid]) -> dict[str, np.ndarray]:
    p, q, blk, brd, pos = [], [], [], [], []
    for k, g in enumerate(blocks):
        for ib, b in enumerate(BORDER_NAMES):
            nodes = g.border(b)
            p.append(nodes[:-1])
            q.append(nodes[1:])
            n = len(nodes) - 1
            blk.append(np.full(n, k))
            brd.append(np.full(n, ib))
            pos.append(np.arange(n))
    cat = np.concatenate
    return {"p": cat(p), "q": cat(q), "blk": cat(blk), "brd": cat(brd), "pos": cat(pos)}


def find_couplings(blocks: list[StructuredGrid], *, rtol: float = 1e-7) -> list[Coupling]:
    """Every run of border nodes that two blocks share (whole or partial borders)."""
    from scipy.spatial import cKDTree

    e = _border_edges(blocks)
    allp = np.vstack([e["p"], e["q"]])
    tol = rtol * max(float(np.hypot(*np.ptp(allp, axis=0))), np.finfo(float).tiny)
    pairs = cKDTree(0.5 * (e["p"] + e["q"])).query_pairs(tol, p=np.inf, output_type="ndarray")
    runs: dict[tuple, list[tuple[int, int]]] = defaultdict(list)
    for u, v in pairs.tolist():
        if e["blk"][u] == e["blk"][v]:
            continue
        if e["blk"][u] > e["blk"][v]:
            u, v = v, u
        same = max(np.abs(e["p"][u] - e["p"][v]).max(), np.abs(e["q"][u] - e["q"][v]).max()) <= tol
        flip = max(np.abs(e["p"][u] - e["q"][v]).max(), np.abs(e["q"][u] - e["p"][v]).max()) <= tol
        if same or flip:
            key = (int(e["blk"][u]), int(e["brd"][u]), int(e["blk"][v]), int(e["brd"][v]), not same)
            runs[key].append((int(e["pos"][u]), int(e["pos"][v])))
    out = []
    for (ka, ba, kb, bb, rev), lst in sorted(runs.items(), key=lambda kv: (kv[0][0], kv[0][2], kv[0][1:])):
        lst.sort()
        step = -1 if rev else 1
        group = [lst[0]]
        for pa, pb in lst[1:] + [(None, None)]:
            if pa is not None and pa == group[-1][0] + 1 and pb == group[-1][1] + step:
                group.append((pa, pb))
                continue
            (a0, b0), (a1, b1) = group[0], group[-1]
            sb, tb = (b1, b0 + 1) if rev else (b0, b1 + 1)
            out.append(Coupling(ka, BORDER_NAMES[ba], a0, a1 + 1, kb, BORDER_NAMES[bb], sb, tb, rev))
            group = [(pa, pb)]
    return out


def turned(grid: StructuredGrid, quarter_turns: int) -> StructuredGrid:
    """The grid with its index space turned: each turn maps bottom → right → top → left → bottom."""
    g = grid
    for _ in range(quarter_turns % 4):
        g = g.transposed()
    return g


def _turns(blocks: list[StructuredGrid], couplings: list[Coupling], names: tuple[str, ...]) -> list[int]:
    """Quarter turns per block so that every coupling joins opposite borders (fewest turned blocks).

    After ``r`` turns border ``b`` becomes ``b + r`` (mod 4, in BORDER_NAMES order); opposite
    borders differ by 2, so a coupling asks ``r_a − r_b ≡ 2 − b_a + b_b``.
    """
    adj: dict[int, list[tuple[int, int, Coupling]]] = defaultdict(list)
    for c in couplings:
        d = (2 - BORDER_NAMES.index(c.border_a) + BORDER_NAMES.index(c.border_b)) % 4
        adj[c.a].append((c.b, -d, c))  # r_b = r_a - d
        adj[c.b].append((c.a, d, c))
    turns: list[int | None] = [None] * len(blocks)
    for root in range(len(blocks)):
        if turns[root] is not None:
            continue
        turns[root], comp, stack = 0, [root], [root]
        while stack:
            k = stack.pop()
            for nb, delta, c in adj[k]:
                want = (turns[k] + delta) % 4
                if turns[nb] is None:
                    turns[nb] = want
                    comp.append(nb)
                    stack.append(nb)
                elif turns[nb] != want:
                    p = blocks[c.a].border(c.border_a)[(c.start_a + c.stop_a) // 2]
                    raise WriteError(
                        f"the blocks cannot be written as Delft3D domain decomposition: Delft3D couples "
                        f"M-lines only to M-lines and N-lines to N-lines, and no turning of the blocks "
                        f"makes the interface {names[c.a]}.{c.border_a} ↔ {names[c.b]}.{c.border_b} near "
                        f"({p[0]:.8g}, {p[1]:.8g}) agree with the others around it (a corner where 3 or 5 "
                        f"blocks meet, or blocks round an island whose index directions turn by a quarter "
                        f"on the way round); use a layout with 4 blocks at every inner corner and blocks "
                        f"round each island that close up"
                    )
        best = max(range(4), key=lambda s: (sum((turns[k] + s) % 4 == 0 for k in comp), -s))
        for k in comp:
            turns[k] = (turns[k] + best) % 4
    return [int(t) for t in turns]


def _mn(shape: tuple[int, int], border: str, start: int, stop: int) -> tuple[int, int, int, int]:
    """1-based grid-point indices ``(m1, n1, m2, n2)`` of nodes ``start … stop`` of a border."""
    mmax, nmax = shape
    if border in ("bottom", "top"):
        n = 1 if border == "bottom" else nmax
        return start + 1, n, stop + 1, n
    m = 1 if border == "left" else mmax
    return m, start + 1, m, stop + 1


def _file_names(stem: str, names: tuple[str, ...]) -> list[str]:
    out: list[str] = []
    for nm in names:
        base = f"{stem}_{re.sub(r'[^A-Za-z0-9_.-]+', '_', nm).strip('._') or 'block'}"
        cand, k = base, 2
        while f"{cand}.grd".lower() in {o.lower() for o in out}:
            cand, k = f"{base}_{k}", k + 1
        out.append(f"{cand}.grd")
    return out


def ddb_text(files: list[str], shapes: list[tuple[int, int]], couplings: list[Coupling]) -> str:
    """The ``.ddb`` lines, in block order (``find_couplings`` puts the lower block first)."""
    w = max(len(f) for f in files)
    lines = []
    for c in couplings:
        a, b = (c.a, c.border_a, c.start_a, c.stop_a), (c.b, c.border_b, c.start_b, c.stop_b)
        ma, mb = _mn(shapes[a[0]], *a[1:]), _mn(shapes[b[0]], *b[1:])
        lines.append(
            f"{files[a[0]]:<{w}} {ma[0]:6d}{ma[1]:6d}{ma[2]:6d}{ma[3]:6d}   "
            f"{files[b[0]]:<{w}} {mb[0]:6d}{mb[1]:6d}{mb[2]:6d}{mb[3]:6d}"
        )
    return "\n".join(lines) + "\n"


def write_ddb(path: Path, gs: GridSet, *, lonlat: bool = False, enclosure: bool = True, **_: Any) -> None:
    """Write the blocks of ``gs`` as Delft3D domain decomposition (see module docstring)."""
    from .delft3d import write_grd

    path = Path(path)
    blocks = list(gs.blocks)
    names = tuple(gs.block_names)
    for k, g in enumerate(blocks):
        bad = ~(np.isfinite(g.x) & np.isfinite(g.y))
        if bad.any():
            i, j = (int(v) for v in np.argwhere(bad)[0])
            raise WriteError(f"{path}: block {names[k]!r} has a non-finite coordinate at node ({i}, {j})")
    if len(blocks) < 2:
        raise WriteError(f"{path}: domain decomposition needs at least two blocks; write one block as .grd")
    couplings = find_couplings(blocks)
    alone = sorted(set(range(len(blocks))) - {c.a for c in couplings} - {c.b for c in couplings})
    if alone:
        raise WriteError(
            f"{path}: block {names[alone[0]]!r} shares no border with another block, and a .ddb file "
            f"lists only coupled domains"
        )
    turns = _turns(blocks, couplings, names)
    blocks = [turned(g, r) for g, r in zip(blocks, turns, strict=True)]
    couplings = find_couplings(blocks)
    for c in couplings:
        if c.reversed or {c.border_a, c.border_b} not in ({"left", "right"}, {"bottom", "top"}):
            raise WriteError(
                f"{path}: blocks {names[c.a]!r} and {names[c.b]!r} meet with opposite orientations "
                f"(a mirrored block); Delft3D needs every domain counter-clockwise"
            )
    files = _file_names(path.stem, names)
    text = ddb_text(files, [g.shape for g in blocks], couplings)
    with _staged(path) as stage:
        for g, f in zip(blocks, files, strict=True):
            write_grd(stage / f, GridSet((g,), gs.frame, (f,)), lonlat=lonlat, enclosure=enclosure)
        (stage / path.name).write_text(text, encoding="ascii")


@contextlib.contextmanager
def _staged(path: Path):
    """Yield a staging folder next to ``path``; move everything in it into place, all or none."""
    directory = path.parent if str(path.parent) else Path(".")
    try:
        stage = Path(tempfile.mkdtemp(prefix=f".{path.name}.", suffix=".tmp", dir=directory))
    except OSError as exc:
        raise WriteError(f"{path}: cannot write here ({exc.strerror or exc})") from None
    backup = stage / ".replaced"
    moved: list[tuple[Path, Path | None]] = []
    try:
        yield stage
        files = sorted(p for p in stage.iterdir() if p != backup)
        for f in files:  # only files are replaced: a folder (or link to one) of that name is not output
            final = directory / f.name
            if final.is_dir():
                raise WriteError(f"{path}: {final} is a folder, not a grid file: nothing was written")
        backup.mkdir()
        for f in files:
            final = directory / f.name
            old = None
            if final.exists():
                old = backup / f.name
                os.replace(final, old)
            moved.append((final, old))
            os.chmod(f, 0o644)
            os.replace(f, final)
    except BaseException as exc:
        for final, old in reversed(moved):
            with contextlib.suppress(OSError):
                final.unlink()  # absent when this very move failed
            if old is not None:
                with contextlib.suppress(OSError):
                    os.replace(old, final)
        if isinstance(exc, MeshcoreError) or not isinstance(exc, Exception):
            raise
        raise WriteError(f"{path}: cannot write ({getattr(exc, 'strerror', None) or exc})") from exc
    finally:
        shutil.rmtree(stage, ignore_errors=True)


# ------------------------------------------------------------------ reading
@dataclass(frozen=True, slots=True, eq=False)
class DomainDecomposition:
    """A ``.ddb`` read back: the blocks, their files, and the interfaces as node ranges."""

    blocks: GridSet
    files: tuple[str, ...]
    interfaces: tuple[Any, ...]  # meshcore.multiblock.Interface

    def topology(self, *, check_geometry: bool = True) -> Any:
        """A validated :class:`~meshcore.multiblock.MultiBlockTopology` of the blocks
        (``check_geometry=False``: without the shapely checks, which take the water round an
        island for a gap between blocks; the couplings are checked node for node either way)."""
        from ..boundary import Borders
        from ..multiblock import Block, MultiBlockTopology

        bl = tuple(
            Block(n, Borders(*(g.border(b) for b in BORDER_NAMES)))
            for n, g in zip(self.blocks.block_names, self.blocks.blocks, strict=True)
        )
        return MultiBlockTopology(bl, self.interfaces, check_geometry=check_geometry)


def _tokens(path: Path) -> list[tuple[int, str]]:
    text = decode_text(path, read_bytes(path))
    out = []
    for no, line in enumerate(text.splitlines(), 1):
        line = re.split(r"[#;]", line, maxsplit=1)[0]
        out.extend((no, t) for t in line.split())
    return out


def _side(path: Path, line: int, name: str, shape: tuple[int, int], mn: list[int]) -> tuple[str, int, int, bool]:
    """(border, start, stop, descending) of a ``m1 n1 m2 n2`` segment of a grid of ``shape`` points."""
    (m1, n1, m2, n2), (mmax, nmax) = mn, shape
    where = f"{path}: line {line}: {name} ({mmax} x {nmax} points)"
    if not (min(m1, m2) >= 1 and max(m1, m2) <= mmax and min(n1, n2) >= 1 and max(n1, n2) <= nmax):
        raise ReadError(f"{where}: segment ({m1},{n1})-({m2},{n2}) lies outside the grid")
    if m1 == m2 and n1 != n2 and m1 in (1, mmax):
        border, a, b = ("left" if m1 == 1 else "right"), n1 - 1, n2 - 1
    elif n1 == n2 and m1 != m2 and n1 in (1, nmax):
        border, a, b = ("bottom" if n1 == 1 else "top"), m1 - 1, m2 - 1
    else:
        raise ReadError(f"{where}: segment ({m1},{n1})-({m2},{n2}) is not part of the grid's outer boundary")
    return border, min(a, b), max(a, b), a > b


def read_dd(path: Any) -> DomainDecomposition:
    """Read a ``.ddb`` file and every ``.grd`` it names (paths relative to the ``.ddb``)."""
    from ..multiblock.topology import Interface as MBInterface
    from ..multiblock.topology import Side
    from .delft3d import read_grd

    path = Path(path)
    toks = _tokens(path)
    if not toks:
        raise ReadError(f"{path}: no couplings (an empty .ddb file)")
    if len(toks) % 10:
        line = toks[len(toks) - len(toks) % 10][0]
        raise ReadError(f"{path}: line {line}: a coupling needs 10 fields: file m1 n1 m2 n2 file m1 n1 m2 n2")
    files: list[str] = []
    grids: dict[str, GridSet] = {}
    records = []
    for k in range(0, len(toks), 10):
        rec = toks[k : k + 10]
        line = rec[0][0]
        try:
            nums = [int(t) for _, t in rec[1:5] + rec[6:10]]
        except ValueError:
            raise ReadError(f"{path}: line {line}: grid indices must be integers") from None
        for f in (rec[0][1], rec[5][1]):
            if f not in grids:
                gp = path.parent / f
                if not gp.is_file():
                    raise ReadError(f"{path}: line {line}: grid file {f} not found next to the .ddb")
                grids[f] = read_grd(gp)
                files.append(f)
        records.append((line, rec[0][1], nums[:4], rec[5][1], nums[4:]))
    stems = [Path(f).stem for f in files]
    prefix = f"{path.stem}_"
    names = tuple(
        s[len(prefix) :] if all(t.startswith(prefix) and len(t) > len(prefix) for t in stems) else s for s in stems
    )
    name_of = dict(zip(files, names, strict=True))
    itfs, conn = [], []
    for line, fa, mna, fb, mnb in records:
        ga, gb = grids[fa].blocks[0], grids[fb].blocks[0]
        ba, sa, ta, da = _side(path, line, fa, ga.shape, mna)
        bb, sb, tb, db = _side(path, line, fb, gb.shape, mnb)
        if ta - sa != tb - sb:
            raise ReadError(
                f"{path}: line {line}: {ta - sa} cells on {fa} but {tb - sb} on {fb}; grid refinement "
                f"across a coupling is not supported"
            )
        itfs.append(MBInterface(Side(name_of[fa], ba, sa, ta), Side(name_of[fb], bb, sb, tb), da != db))
        whole = sa == 0 and sb == 0 and ta == len(ga.border(ba)) - 1 and tb == len(gb.border(bb)) - 1
        ranges = (None, None) if whole else ((sa, ta), (sb, tb))
        conn.append(Interface(files.index(fa), ba, files.index(fb), bb, da != db, *ranges))
    frame = grids[files[0]].frame
    gs = GridSet(tuple(grids[f].blocks[0] for f in files), frame, names, tuple(conn), str(path))
    return DomainDecomposition(gs, tuple(files), tuple(itfs))


def read_ddb(path: Path, **_: Any) -> GridSet:
    """The blocks of a ``.ddb`` (every coupling, parts of borders too, as ``connectivity``); see :func:`read_dd`."""
    return read_dd(path).blocks
