"""The start of a multiblock solve: every block's borders with shared nodes made identical, and its algebraic grid."""

from __future__ import annotations

from typing import Any

import numpy as np

from ..algebraic import algebraic_grid, border_frame
from ..boundary import Borders
from ..grid import StructuredGrid
from . import _start_kernels as _typed_sk
from .topology import MultiBlockTopology

#: The numba kernel (``Any``: mypy's numba stubs reject some calls).
_sk: Any = _typed_sk

__all__ = ["initial_grids", "snapped_borders"]


#: Each border's nodes in a block's node-index array.
_SIDES: dict[str, tuple[Any, Any]] = {
    "bottom": (slice(None), 0),
    "top": (slice(None), -1),
    "left": (0, slice(None)),
    "right": (-1, slice(None)),
}


def snapped_borders(topology: MultiBlockTopology) -> list:
    """Each block's borders with every shared node set to one value (bit-identical copies)."""
    m = topology.node_map
    x = np.full(m.n_nodes, np.nan)
    y = np.full(m.n_nodes, np.nan)
    out = []
    for b, ids in zip(topology.blocks, m.ids, strict=True):
        new = {}
        for name, sl in _SIDES.items():
            g = ids[sl]
            p = np.array(b.borders[name], dtype=np.float64)
            have = ~np.isnan(x[g])
            p[have, 0] = x[g[have]]
            p[have, 1] = y[g[have]]
            x[g[~have]] = p[~have, 0]
            y[g[~have]] = p[~have, 1]
            new[name] = p
        # the corners were written by the first border that saw them
        for name, sl in _SIDES.items():
            g = ids[sl]
            new[name][:, 0] = x[g]
            new[name][:, 1] = y[g]
        out.append(Borders(**new, periodic=False))
    return out


def initial_grids(topology: MultiBlockTopology) -> list[StructuredGrid]:
    """Algebraic start grid of each block from its (snapped) borders (``initial = "tfi"``: one
    compiled call per block, :func:`._start_kernels.tfi_fill`, the grid of
    :func:`meshcore.algebraic.tfi`)."""
    out = []
    for b, bd in zip(topology.blocks, snapped_borders(topology), strict=True):
        if b.initial == "tfi":
            x, y = border_frame(bd)
            _sk.tfi_fill(x, y)
            out.append(StructuredGrid(x, y, names=dict(b.names)))
        else:
            g = algebraic_grid(bd, b.initial, weights=b.weights)
            out.append(g.replaced(names=dict(b.names)))
    return out
