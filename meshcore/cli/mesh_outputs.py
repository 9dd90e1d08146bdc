"""``meshcore mesh``: outputs that depend on the layout, checked before the solve.

* ``--single`` turns every ``.grd`` output into the merged single-domain grid
  (:mod:`meshcore.io.delft3d_single`);
* a ``.ddb`` (Delft3D domain decomposition), a ``--single`` ``.grd`` and an EFDC ``cell.inp``
  are written once, from the algebraic grids of the layout's blocks, into a temporary folder:
  whether Delft3D can couple the blocks, or whether they fit one index space, depends on the
  layout only, so the real write after the solve cannot fail on it (exit 2, nothing written).
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from ..errors import InvalidInputError

__all__ = ["SINGLE_DOMAIN", "check_blocks", "dry_run", "single_outputs"]


def single_outputs(args: argparse.Namespace, outputs: list[tuple[Path, Any]]) -> list[tuple[Path, Any]]:
    """``--single``: every ``.grd`` output becomes the merged single-domain grid."""
    from ..io import FORMATS

    if not getattr(args, "single", False):
        return outputs
    if not any(fmt.name == "delft3d" for _, fmt in outputs):
        raise InvalidInputError("--single merges the blocks into one Delft3D grid: give -o OUT.grd")
    return [(p, FORMATS["delft3d-single"] if fmt.name == "delft3d" else fmt) for p, fmt in outputs]


def one_block_only(p: Path, fmt: Any, blocks: str, single: bool = True) -> str:
    """The message for ``-o p`` of a one-block format and a grid of several blocks (``blocks``
    says how many); a Delft3D ``.grd`` of one lake is told of ``--single``, which merges them."""
    also = (
        "; or add --single for one Delft3D grid of the blocks merged (with inactive points and its .enc)"
        if fmt.name == "delft3d" and single
        else ""
    )
    return (
        f"-o {p}: the {fmt.name} format holds one block and {blocks}; "
        f"write .vtm, .cgns, .xyz, .ddb, .npz, .su2 or .msh{also}"
    )


def check_blocks(outputs: list[tuple[Path, Any]], lay: Any) -> None:
    """Refuse, before the solve, an output that cannot hold this layout.

    A ``.ddb`` is written once, from the algebraic grids of the layout's blocks, into a
    temporary folder: the couplings (and whether Delft3D can orient them) depend on the
    layout only, so the real write after the solve cannot fail on them.
    """
    n_blocks = len(lay.blocks)
    for p, fmt in outputs:
        if n_blocks > 1 and not fmt.multiblock:
            raise InvalidInputError(one_block_only(p, fmt, f"the layout has {n_blocks}"))
        if fmt.name == "delft3d-dd":
            if n_blocks < 2:
                raise InvalidInputError(f"-o {p}: the layout is one block; write it as .grd, not as a .ddb")
            dry_run(p, lay)
        if fmt.name in SINGLE_DOMAIN:
            dry_run(p, lay, fmt.name)


#: Formats that need every block in one index space (:mod:`meshcore.multiblock.indexspace`).
SINGLE_DOMAIN = ("delft3d-single", "efdc")


def dry_run(p: Path, lay: Any, format: str | None = None) -> None:
    """Write ``p`` (as ``format``, else by its suffix) from the layout's start grids into a temporary
    folder; a :class:`~meshcore.errors.WriteError` becomes one line naming ``-o p``."""
    import tempfile

    from ..algebraic import tfi
    from ..errors import WriteError
    from ..io import write

    topo = lay.topology()
    grids = [tfi(b.borders) for b in topo.blocks]
    with tempfile.TemporaryDirectory(prefix="meshcore-mesh-") as d:
        trial = Path(d) / p.name
        try:
            write(trial, grids, format, block_names=[b.name for b in topo.blocks])
        except WriteError as exc:
            from ..layout.frames import frame_defects

            msg = str(exc).replace(f"{trial}: ", "").replace(str(trial), str(p))
            if format in SINGLE_DOMAIN:
                raise InvalidInputError(f"-o {p}: {msg}") from None
            where = "; ".join(d.note() for d in frame_defects(list(lay.pieces)))
            msg += f"; here {where}" if where else ""
            raise InvalidInputError(f"-o {p}: {msg} (write .vtm, .cgns or .xyz instead)") from None
