r"""Unstructured solver formats built from structured blocks: Gmsh ``.msh`` 4.1 and SU2.

Every cell becomes a quadrilateral with nodes ``(i, j), (i+1, j), (i+1, j+1),
(i, j+1)`` (counter-clockwise for a valid grid).  Nodes shared by blocks (1-to-1
interfaces, also those that cover only part of a border) and the seam of a
periodic block are merged, so the mesh is conforming.  Every border edge that
no other cell shares becomes a line element in a marker named after its
border (``grid.names``, default ``bottom/right/top/left``); borders with the
same name across blocks share one marker.  Names are written as UTF-8.

* Gmsh: ASCII MSH 4.1; one surface entity per block (physical group of
  dimension 2 named after the block), one curve entity per boundary border,
  one physical group of dimension 1 per marker name.
* SU2: ``NDIME= 2``, quadrilaterals (VTK type 9), ``NMARK`` markers of lines
  (type 3).  Coordinates printed with 17 significant digits.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..grid import BORDER_NAMES
from ._base import GridSet, atomic_path, border_index, border_names

__all__ = ["UnstructuredMesh", "to_unstructured", "write_msh", "write_su2"]


@dataclass(frozen=True, slots=True, eq=False)
class UnstructuredMesh:
    """Merged nodes, quads per block, and boundary line elements per border."""

    points: np.ndarray  # (N, 2) world coordinates
    quads: tuple[np.ndarray, ...]  # per block (M_k, 4), 0-based node ids
    borders: tuple[tuple[str, int, str, np.ndarray], ...]  # (marker, block, border, (L, 2))


def to_unstructured(gs: GridSet) -> UnstructuredMesh:
    """Merge the blocks of ``gs`` into one conforming quad mesh (see module docstring).

    Nodes paired by an interface (whole border or part of one) and the seam
    of a periodic block become one node; node ids follow the first block
    (then the first node, i-major) that holds them.  A border edge is a
    boundary element only when no other cell shares it, so interfaces —
    however they cut the borders — never appear in a marker.
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    blocks = gs.blocks
    shapes = [g.shape for g in blocks]
    offsets = np.cumsum([0] + [a * b for a, b in shapes])
    total = int(offsets[-1])
    us, vs = [], []
    for it in gs.connectivity:
        ia, ja, ib, jb = it.node_pairs(blocks)
        us.append(offsets[it.a] + ia * shapes[it.a][1] + ja)
        vs.append(offsets[it.b] + ib * shapes[it.b][1] + jb)
    for k, g in enumerate(blocks):
        if g.periodic:  # the seam column ni repeats column 0
            j = np.arange(shapes[k][1])
            us.append(offsets[k] + (shapes[k][0] - 1) * shapes[k][1] + j)
            vs.append(offsets[k] + j)
    u = np.concatenate(us) if us else np.zeros(0, dtype=np.int64)
    v = np.concatenate(vs) if vs else np.zeros(0, dtype=np.int64)
    graph = coo_matrix((np.ones(len(u), dtype=np.int8), (u, v)), shape=(total, total))
    _, label = connected_components(graph, directed=False)
    # number the merged nodes in order of their first occurrence
    _, first = np.unique(label, return_index=True)
    rank = np.empty(len(first), dtype=np.int64)
    rank[np.argsort(first)] = np.arange(len(first))
    gid = rank[label]
    ids = [gid[offsets[k] : offsets[k + 1]].reshape(shapes[k]) for k in range(len(blocks))]
    world = [gs.world(k) for k in range(len(blocks))]
    X = np.concatenate([w[0].ravel() for w in world])
    Y = np.concatenate([w[1].ravel() for w in world])
    points = np.column_stack([X[np.sort(first)], Y[np.sort(first)]])
    quads = []
    for idx in ids:
        q = np.stack([idx[:-1, :-1], idx[1:, :-1], idx[1:, 1:], idx[:-1, 1:]], axis=-1)
        quads.append(q.reshape(-1, 4))
    allq = np.vstack(quads)
    n = len(points)
    e0, e1 = allq.reshape(-1), np.roll(allq, -1, axis=1).reshape(-1)
    ukey, cnt = np.unique(np.minimum(e0, e1) * n + np.maximum(e0, e1), return_counts=True)
    borders = []
    for k, g in enumerate(blocks):
        names = border_names(g)
        for b in BORDER_NAMES:
            line = ids[k][border_index(g.shape, b)]
            seg = np.column_stack([line[:-1], line[1:]])
            key = np.minimum(seg[:, 0], seg[:, 1]) * n + np.maximum(seg[:, 0], seg[:, 1])
            pos = np.searchsorted(ukey, key)
            keep = (seg[:, 0] != seg[:, 1]) & (cnt[np.minimum(pos, len(cnt) - 1)] == 1)
            if keep.any():
                borders.append((names[b], k, b, seg[keep]))
    return UnstructuredMesh(points, tuple(quads), tuple(borders))


def _fmt(v: float) -> str:
    return f"{v:.17g}"


def write_msh(path: Path, gs: GridSet, **_: Any) -> None:
    """Write a Gmsh MSH 4.1 ASCII file with physical groups (see module docstring)."""
    m = to_unstructured(gs)
    markers = list(dict.fromkeys(b[0] for b in m.borders))
    phys1 = {nm: k + 1 for k, nm in enumerate(markers)}
    phys2 = {k: len(markers) + k + 1 for k in range(len(gs.blocks))}
    out = ["$MeshFormat", "4.1 0 8", "$EndMeshFormat", "$PhysicalNames", str(len(phys1) + len(phys2))]
    out += [f'1 {t} "{nm}"' for nm, t in phys1.items()]
    out += [f'2 {t} "{gs.block_names[k]}"' for k, t in phys2.items()]
    out.append("$EndPhysicalNames")

    def bbox(p):
        lo, hi = p.min(axis=0), p.max(axis=0)
        return f"{_fmt(lo[0])} {_fmt(lo[1])} 0 {_fmt(hi[0])} {_fmt(hi[1])} 0"

    out += ["$Entities", f"0 {len(m.borders)} {len(gs.blocks)} 0"]
    curve_of_block: dict[int, list[int]] = {}
    for c, (nm, k, _b, lines) in enumerate(m.borders, 1):
        nodes = np.unique(lines)
        out.append(f"{c} {bbox(m.points[nodes])} 1 {phys1[nm]} 0")
        curve_of_block.setdefault(k, []).append(c)
    for k, q in enumerate(m.quads):
        curves = curve_of_block.get(k, [])
        out.append(
            f"{k + 1} {bbox(m.points[np.unique(q)])} 1 {phys2[k]} {len(curves)} " + " ".join(str(c) for c in curves)
        )
    out.append("$EndEntities")
    # nodes: each node in the surface entity of the first block that uses it
    owner = np.full(len(m.points), -1)
    for k in range(len(m.quads) - 1, -1, -1):
        owner[np.unique(m.quads[k])] = k
    N = len(m.points)
    out += ["$Nodes", f"{len(m.quads)} {N} 1 {N}"]
    for k in range(len(m.quads)):
        tags = np.flatnonzero(owner == k)
        out.append(f"2 {k + 1} 0 {len(tags)}")
        out += [str(t + 1) for t in tags]
        out += [f"{_fmt(m.points[t, 0])} {_fmt(m.points[t, 1])} 0" for t in tags]
    out.append("$EndNodes")
    n_el = sum(len(q) for q in m.quads) + sum(len(b[3]) for b in m.borders)
    out += ["$Elements", f"{len(m.borders) + len(m.quads)} {n_el} 1 {n_el}"]
    tag = 1
    for c, (_nm, _k, _b, lines) in enumerate(m.borders, 1):
        out.append(f"1 {c} 1 {len(lines)}")
        for a, b in lines + 1:
            out.append(f"{tag} {a} {b}")
            tag += 1
    for k, q in enumerate(m.quads):
        out.append(f"2 {k + 1} 3 {len(q)}")
        for r in q + 1:
            out.append(f"{tag} {r[0]} {r[1]} {r[2]} {r[3]}")
            tag += 1
    out.append("$EndElements")
    with atomic_path(path) as tmp:
        tmp.write_text("\n".join(out) + "\n", encoding="utf-8")


def write_su2(path: Path, gs: GridSet, **_: Any) -> None:
    """Write an SU2 ASCII mesh with one marker per border name (see module docstring)."""
    m = to_unstructured(gs)
    quads = np.vstack(m.quads)
    out = ["% meshcore structured grid as SU2 quadrilaterals"]
    if gs.frame.crs:
        out.append(f"% crs: {gs.frame.crs}")
    out += ["NDIME= 2", f"NELEM= {len(quads)}"]
    out += [f"9 {r[0]} {r[1]} {r[2]} {r[3]} {e}" for e, r in enumerate(quads)]
    out.append(f"NPOIN= {len(m.points)}")
    out += [f"{_fmt(p[0])} {_fmt(p[1])} {k}" for k, p in enumerate(m.points)]
    groups: dict[str, list[np.ndarray]] = {}
    for nm, _k, _b, lines in m.borders:
        groups.setdefault(nm, []).append(lines)
    out.append(f"NMARK= {len(groups)}")
    for nm, parts in groups.items():
        lines = np.vstack(parts)
        out += [f"MARKER_TAG= {nm}", f"MARKER_ELEMS= {len(lines)}"]
        out += [f"3 {a} {b}" for a, b in lines]
    with atomic_path(path) as tmp:
        tmp.write_text("\n".join(out) + "\n", encoding="utf-8")
