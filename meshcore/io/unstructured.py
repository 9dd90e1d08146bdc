r"""Unstructured solver formats built from structured blocks: Gmsh ``.msh`` 4.1 and SU2.

Every cell becomes a quadrilateral with nodes ``(i, j), (i+1, j), (i+1, j+1),
(i, j+1)`` (counter-clockwise for a valid grid).  Nodes shared by blocks (1-to-1
interfaces) and the seam of a periodic block are merged, so the mesh is
conforming.  Every border that is not an interface becomes line elements in a
marker named after it (``grid.names``, default ``bottom/right/top/left``);
borders with the same name across blocks share one marker.

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
    """Merge the blocks of ``gs`` into one conforming quad mesh (see module docstring)."""
    ids: list[np.ndarray] = []
    coords: list[np.ndarray] = []
    n = 0
    shared: set[tuple[int, str]] = set()
    for it in gs.connectivity:
        shared.add((it.a, it.border_a))
        shared.add((it.b, it.border_b))
    for k, g in enumerate(gs.blocks):
        idx = np.full(g.shape, -1, dtype=np.int64)
        for it in gs.connectivity:
            for me, mb, other, ob in ((it.b, it.border_b, it.a, it.border_a), (it.a, it.border_a, it.b, it.border_b)):
                if me == k and other < k:
                    src = ids[other][border_index(gs.blocks[other].shape, ob)]
                    idx[border_index(g.shape, mb)] = src[::-1] if it.reversed else src
        free = idx < 0
        if g.periodic:
            free[-1, :] = False  # the seam column repeats column 0
        cnt = int(free.sum())
        idx[free] = np.arange(n, n + cnt)
        if g.periodic:
            idx[-1, :] = idx[0, :]
        X, Y = gs.world(k)
        pts = np.zeros((cnt, 2))
        pts[:, 0] = X[free]
        pts[:, 1] = Y[free]
        coords.append(pts)
        n += cnt
        ids.append(idx)
    points = np.vstack(coords)
    quads = []
    for idx in ids:
        q = np.stack([idx[:-1, :-1], idx[1:, :-1], idx[1:, 1:], idx[:-1, 1:]], axis=-1)
        quads.append(q.reshape(-1, 4))
    borders = []
    for k, g in enumerate(gs.blocks):
        names = border_names(g)
        for b in BORDER_NAMES:
            if (k, b) in shared or (g.periodic and b in ("left", "right")):
                continue
            line = ids[k][border_index(g.shape, b)]
            borders.append((names[b], k, b, np.column_stack([line[:-1], line[1:]])))
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
        tmp.write_text("\n".join(out) + "\n", encoding="ascii")


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
        tmp.write_text("\n".join(out) + "\n", encoding="ascii")
