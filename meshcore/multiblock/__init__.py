"""Multiblock grids: blocks glued along shared borders, solved as one grid.

* :mod:`.topology` — blocks, interfaces (border parts with orientation),
  global node numbering, corners where 3/4/5 blocks meet, validation.
* :mod:`.outline` — one closed shoreline + corner points + cut lines → blocks.
* :mod:`.solver` — ``frozen`` and ``smooth`` interface modes; :class:`MultiBlockGrid`.
* :mod:`.multigrid` — nonlinear multigrid (FAS) over all blocks (smooth mode).
* :mod:`.case` — ``[multiblock]``, ``[[interfaces]]``, ``[outline]`` in case files.
* :mod:`.export`, :mod:`.figure` — connectivity report, one-colour-per-block figures.

Example
-------
>>> import numpy as np
>>> from meshcore.multiblock import from_outline, solve_multiblock
>>> ring = [[0, 0], [2, 0], [2, 1], [0, 1]]
>>> blocks = [{"name": "w", "corners": [[0, 0], [1, 0], [1, 1], [0, 1]], "cells": [4, 4]},
...           {"name": "e", "corners": [[1, 0], [2, 0], [2, 1], [1, 1]], "cells": [4, 4]}]
>>> topo = from_outline(ring, cuts=[[[1, 0], [1, 1]]], blocks=blocks).topology
>>> mb = solve_multiblock(topo)
>>> mb.names, mb.converged, mb.interface_mismatch()
(('w', 'e'), True, 0.0)
"""

from .outline import BlockOutline, OutlineBlocks, from_outline, project_lonlat
from .solver import (
    ENGINES,
    MODES,
    MultiBlockGrid,
    MultiBlockQuality,
    initial_grids,
    solve_multiblock,
)
from .topology import Block, Corner, Interface, MultiBlockTopology, NodeMap, Side, parse_side

__all__ = [
    "ENGINES",
    "MODES",
    "Block",
    "BlockOutline",
    "Corner",
    "Interface",
    "MultiBlockGrid",
    "MultiBlockQuality",
    "MultiBlockTopology",
    "NodeMap",
    "OutlineBlocks",
    "Side",
    "from_outline",
    "initial_grids",
    "parse_side",
    "project_lonlat",
    "solve_multiblock",
]
