"""Multiblock grids: blocks glued along shared borders, solved as one grid.

* :mod:`.topology` — blocks, interfaces (border parts with orientation),
  global node numbering, corners where 3/4/5 blocks meet, validation.
* :mod:`.outline` — one closed shoreline + corner points + cut lines → blocks.
* :mod:`.solver` — ``frozen`` and ``smooth`` interface modes; :class:`MultiBlockGrid`.
"""

from .solver import MODES, MultiBlockGrid, MultiBlockQuality, initial_grids, solve_multiblock
from .topology import Block, Corner, Interface, MultiBlockTopology, NodeMap, Side, parse_side

__all__ = [
    "MODES",
    "Block",
    "Corner",
    "Interface",
    "MultiBlockGrid",
    "MultiBlockQuality",
    "MultiBlockTopology",
    "NodeMap",
    "Side",
    "initial_grids",
    "parse_side",
    "solve_multiblock",
]
