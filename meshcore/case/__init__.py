r"""Case files: a documented TOML format for one or more blocks.

A case file describes everything needed to generate a grid.  Paths inside it
are relative to the case file.  Unknown keys are errors that name the key and
list the valid ones.  Example (the paper's bottle, refinement 1)::

    title = "Bottle (paper, refinement 1)"

    [solver]                      # optional; fields of meshcore.SolverSpec
    method = "auto"               # auto | sor | multigrid | foldfree
    repair = "auto"               # auto | strict | off: fold-free repair of invalid cells
    tolerance = 1e-6              # relative to the bounding-box diagonal (omit: scale-aware default)
    max_iterations = 50000

    [[blocks]]
    name = "bottle"
    cells = [6, 15]               # ni × nj cells (omit: the given points are the nodes)
    weights = [1.0, 0.5]          # paper eq. 34: p13_x, p13_y (left/right weight; p24 = 1 − p13)
    initial = "weighted"          # weighted (paper) | tfi
    curve = "linear"              # linear (paper) | cubic | catmull-rom
    periodic = false              # true: O-grid, left = right is a seam solved like the interior
    snap_angle = 30               # optional: input vertices turning > 30° get a node exactly

    [blocks.boundary]             # either four borders (inline points or a point-file name) ...
    bottom = [[-3.0, 0.0], [-1.0, 0.0], [1.0, 0.0], [3.0, 0.0]]
    right  = [[3.0, 0.0], ..., [1.1, 8.0]]
    top    = [[-1.1, 8.0], ..., [1.1, 8.0]]
    left   = [[-3.0, 0.0], ..., [-1.1, 8.0]]
    # ... or a closed loop plus four corner indices (sw, se, ne, nw):
    # points = "shore.csv"        # or inline [[x, y], ...]
    # corners = [0, 40, 90, 130]

    [blocks.borders.bottom]       # optional, per border: distribution and a name
    distribution = "tanh"         # uniform | tanh | vinokur
    first = 0.05                  # absolute first spacing (model units)
    last = 0.05                   # absolute last spacing
    name = "wall"                 # boundary-condition name carried to exports

    [blocks.control]              # optional grid control (meshcore.control)
    kind = "hilgenstock-white"    # or "steger-sorenson" (Taylor targets + feedback)
    thomas-middlecoff = false     # interior follows the boundary point distribution
    relaxation = 0.1              # under-relaxation of the boundary sources
    floating = []                 # borders whose nodes slide along the boundary curve
    attractors = [{ kind = "xi", xi = 0.5, amplitude = 0.2, decay = 0.3 }]
    [blocks.control.borders]      # per wall: first-cell height and angle (degrees)
    bottom = { spacing = 0.05, angle = 90 }

Multiblock cases add ``[multiblock]``, ``[[interfaces]]`` or ``[outline]``
(:mod:`meshcore.case.multiblock`); a top-level ``crs`` table records the
coordinate frame (written by ``meshcore import``).  A ``[lake]`` table (the app's
*Save project*) holds the water the case was made from, as imported, and its layout
settings; the generator does not read it::

    [lake]
    shore = [[0, 0], [900, 0], [900, 400], [0, 400]]   # the shore as imported (model units)
    islands = [[[300, 150], [400, 150], [350, 250]]]   # optional: island rings
    cell_size = 25.0              # optional (absent: the automatic size)
    regular = true                # optional: no 3- or 5-block corners (Delft3D DD)
    single = true                 # optional: a layout for one index space

Modules: :mod:`.model` (the frozen :class:`Case` and its sections),
:mod:`.parse` (TOML → Case), :mod:`.write` (Case → TOML),
:mod:`.multiblock` (a multiblock case → topology), :mod:`.run`
(:func:`generate_case`).  Blocks are :class:`meshcore.BlockSpec`, solver
settings :class:`meshcore.SolverSpec`.
"""

from .model import Case, InterfaceEntry, LakeSection, MultiblockSection, OutlineSection
from .multiblock import case_frame, case_layout, case_topology, cut_case, layout_case, outline_points, topology_case
from .parse import load_case, loads_case, xy_pairs
from .run import case_solver, generate_case, iterate_multiblock_case
from .write import case_to_dict, dumps_case, save_case

__all__ = [
    "Case",
    "InterfaceEntry",
    "LakeSection",
    "MultiblockSection",
    "OutlineSection",
    "case_frame",
    "case_layout",
    "case_solver",
    "case_to_dict",
    "case_topology",
    "cut_case",
    "dumps_case",
    "generate_case",
    "iterate_multiblock_case",
    "layout_case",
    "load_case",
    "loads_case",
    "outline_points",
    "save_case",
    "topology_case",
    "xy_pairs",
]
