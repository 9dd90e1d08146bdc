"""The result of a multiblock solve: :class:`MultiBlockGrid` and its quality across interfaces."""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..grid import SolveInfo, StructuredGrid
from ..quality import QualityReport, interface_pairs, quality
from .topology import Interface, MultiBlockTopology

__all__ = ["MultiBlockGrid", "MultiBlockQuality", "assemble"]


@dataclass(frozen=True, slots=True, eq=False)
class MultiBlockQuality:
    """Quality per block and across interfaces.

    ``interfaces`` maps ``"a ↔ b"`` to the largest area ratio (≥ 1) of two
    cells that share an edge across that block pair; ``worst_inside`` is the
    largest adjacent-cell size ratio inside any block.
    """

    blocks: dict[str, QualityReport]
    interfaces: dict[str, float]
    n_folded: int
    worst_inside: float
    worst_interface: float

    def table(self) -> str:
        lines = [
            "| block | cells | folded | min Jac. ratio | max orth. dev. | max skew | max aspect | max size ratio |",
            "|---|---|---|---|---|---|---|---|",
        ]
        for name, r in self.blocks.items():
            lines.append(
                f"| {name} | {r.cells[0]} × {r.cells[1]} | {r.n_folded} | "
                f"{r.min_jacobian_ratio:.3f} | "
                f"{r.max_orthogonality:.1f}° | {r.max_skewness:.3f} | {r.max_aspect_ratio:.2f} | "
                f"{r.max_size_ratio:.3f} |"
            )
        lines.append("")
        lines.append("| interface (block pair) | max adjacent-cell size ratio across |")
        lines.append("|---|---|")
        for k, v in self.interfaces.items():
            lines.append(f"| {k} | {v:.3f} |")
        lines.append("")
        lines.append(
            f"worst size ratio inside blocks {self.worst_inside:.3f}, across interfaces "
            f"{self.worst_interface:.3f}; folded cells {self.n_folded}"
        )
        return "\n".join(lines)

    def __str__(self) -> str:
        return self.table()


@dataclass(frozen=True, slots=True, eq=False)
class MultiBlockGrid:
    """The result: one :class:`StructuredGrid` per block plus the connectivity."""

    grids: tuple[StructuredGrid, ...]
    names: tuple[str, ...]
    interfaces: tuple[Interface, ...]
    mode: str = "smooth"
    info: SolveInfo = field(default_factory=SolveInfo)
    topology: MultiBlockTopology | None = field(default=None, repr=False)
    frame: Any = field(default=None, repr=False)  # meshcore.crs.Frame of the coordinates
    #: What was changed in the water or the layout on the way (islands left out, a shore
    #: smoothed, cell counts far from the asked size): a lake grid's layout notes
    #: (:func:`meshcore.mesh_outline`; what ``meshcore mesh`` prints as notes)
    notes: tuple[str, ...] = ()
    #: The dead-end arms narrower than two cells the layout left out of the water (shapely Polygons
    #: in the grid's coordinates, :class:`meshcore.layout.Layout` ``arms``; None: not known): the
    #: quality report measures the shore across their mouths (:func:`meshcore.quality.lake_metrics`)
    arms: tuple[Any, ...] | None = field(default=None, repr=False)

    def __len__(self) -> int:
        return len(self.grids)

    @property
    def blocks(self) -> tuple[StructuredGrid, ...]:
        """The block grids (what writers take: ``meshcore.io.write(path, mbgrid)``)."""
        return self.grids

    def __iter__(self) -> Iterator[StructuredGrid]:
        return iter(self.grids)

    def __getitem__(self, key: int | str) -> StructuredGrid:
        if isinstance(key, str):
            try:
                return self.grids[self.names.index(key)]
            except ValueError:
                raise KeyError(f"no block named {key!r}; blocks: {', '.join(self.names)}") from None
        return self.grids[key]

    @property
    def converged(self) -> bool:
        return self.info.converged

    @property
    def n_nodes(self) -> int:
        """Unique nodes (shared interface nodes counted once) when the topology is known."""
        if self.topology is not None:
            return self.topology.node_map.n_nodes
        return sum(g.n_nodes for g in self.grids)

    def interface_mismatch(self) -> float:
        """Largest distance between the two copies of any interface node (0 when glued)."""
        worst = 0.0
        for itf in self.interfaces:
            pa = self[itf.a.block].border(itf.a.border)[itf.a.start : itf.a.stop + 1]
            pb = self[itf.b.block].border(itf.b.border)[itf.b.start : itf.b.stop + 1]
            if itf.reversed:
                pb = pb[::-1]
            worst = max(worst, float(np.hypot(*(pa - pb).T).max()))
        return worst

    def quality(self, reports: list[QualityReport] | None = None) -> MultiBlockQuality:
        """Per block and across interfaces; ``reports``: the blocks' :func:`meshcore.quality.quality`
        when the caller has them (the CLI prints them first)."""
        if reports is None:
            reports = [quality(g) for g in self.grids]
        by_name = dict(zip(self.names, reports, strict=True))
        inter: dict[str, float] = {}
        if len(self.grids) > 1:
            pairs = interface_pairs(self.grids)  # the cross-interface ratio of meshcore.quality
            for p, q, r in zip(pairs["cell_a"][:, 0], pairs["cell_b"][:, 0], pairs["ratio"], strict=True):
                k = f"{self.names[min(p, q)]} ↔ {self.names[max(p, q)]}"
                inter[k] = max(inter.get(k, 1.0), float(r))
        return MultiBlockQuality(
            blocks=by_name,
            interfaces=inter,
            n_folded=sum(r.n_folded for r in by_name.values()),
            worst_inside=max(r.max_size_ratio for r in by_name.values()),
            worst_interface=max(inter.values(), default=1.0),
        )

    def report(self) -> str:
        """Connectivity report plus the solve summary."""
        head = (
            f"Multiblock grid: {len(self.grids)} blocks, mode {self.mode!r}, "
            f"{'converged' if self.info.converged else 'NOT converged'} after "
            f"{self.info.iterations} iterations (residual {self.info.residual:.3g}, "
            f"{self.info.elapsed:.3g} s)"
        )
        body = self.topology.connectivity_report() if self.topology is not None else ""
        return head + "\n" + body


def assemble(grids, m) -> tuple[np.ndarray, np.ndarray]:
    """The global node arrays ``(x, y)`` of per-block grids (shared nodes stored once)."""
    x = np.empty(m.n_nodes)
    y = np.empty(m.n_nodes)
    for g, ids in zip(grids, m.ids, strict=True):
        x[ids.ravel()] = np.asarray(g.x).ravel()
        y[ids.ravel()] = np.asarray(g.y).ravel()
    return x, y
