"""Multiblock grids: blocks glued along shared borders, solved as one grid.

* :mod:`.topology` — blocks, interfaces (border parts with orientation),
  global node numbering, corners where 3/4/5 blocks meet, validation.
* :mod:`.outline` — one closed shoreline + corner points + cut lines → blocks.
* :mod:`.start` — shared border nodes made identical; the algebraic start grids.
* :mod:`.solver` — ``frozen`` and ``smooth`` interface modes: :func:`iterate_multiblock`
  yields progress like the single-block solver, :func:`solve_multiblock` drains it.
* :mod:`.sor`, :mod:`.multigrid` — SOR and nonlinear multigrid (FAS) over all blocks.
* :mod:`.result` — :class:`MultiBlockGrid` and its quality across interfaces.
* Case files (``[multiblock]``, ``[[interfaces]]``, ``[outline]``): :mod:`meshcore.case`.
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
from .result import MultiBlockGrid, MultiBlockQuality
from .solver import ENGINES, MODES, iterate_multiblock, solve_multiblock
from .start import initial_grids
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
    "iterate_multiblock",
    "parse_side",
    "project_lonlat",
    "solve_multiblock",
]
