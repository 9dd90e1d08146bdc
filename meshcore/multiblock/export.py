"""Multiblock output that the core I/O does not cover yet: VTK ``.vtm`` and a connectivity report.

``write_vtm(path, mb)`` writes a VTK XML MultiBlock file plus one ASCII
``.vts`` per block in a sibling directory ``<stem>/`` (what ParaView expects).
``write_report(path, mb)`` writes :meth:`MultiBlockGrid.report` plus the
quality tables as UTF-8 text.  Both write atomically.  (The I/O module's
general writers — PLOT3D multi-block, ``.vtm`` with CRS — supersede the
``.vtm`` writer once they are on main.)
"""

from __future__ import annotations

from pathlib import Path
from typing import Any
from xml.sax.saxutils import quoteattr

import numpy as np

from ..errors import WriteError

__all__ = ["vts_text", "write_report", "write_vtm"]


def vts_text(x: np.ndarray, y: np.ndarray) -> str:
    """ASCII VTK XML StructuredGrid text of one block (points in VTK order, i fastest)."""
    ni1, nj1 = x.shape
    pts = np.column_stack([x.T.ravel(), y.T.ravel(), np.zeros(x.size)])
    body = "\n".join(f"{a!r} {b!r} {c!r}" for a, b, c in pts.tolist())
    ext = f"0 {ni1 - 1} 0 {nj1 - 1} 0 0"
    return (
        '<?xml version="1.0"?>\n'
        '<VTKFile type="StructuredGrid" version="1.0" byte_order="LittleEndian">\n'
        f'  <StructuredGrid WholeExtent="{ext}">\n'
        f'    <Piece Extent="{ext}">\n'
        "      <Points>\n"
        '        <DataArray type="Float64" NumberOfComponents="3" format="ascii">\n'
        f"{body}\n"
        "        </DataArray>\n"
        "      </Points>\n"
        "    </Piece>\n"
        "  </StructuredGrid>\n"
        "</VTKFile>\n"
    )


def write_vtm(path: str | Path, mb: Any) -> Path:
    """Write ``mb`` (a MultiBlockGrid or a list of grids) as ``path`` (.vtm) + ``<stem>/*.vts``."""
    from ..io import atomic_write_text

    p = Path(path)
    grids = list(getattr(mb, "grids", mb))
    names = list(getattr(mb, "names", [f"block{k + 1}" for k in range(len(grids))]))
    d = p.parent / p.stem
    try:
        d.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise WriteError(f"{d}: cannot create the block directory ({exc})") from None
    entries = []
    for k, (name, g) in enumerate(zip(names, grids, strict=True)):
        fn = f"{k:03d}_{''.join(c if c.isalnum() or c in '-_' else '_' for c in name)}.vts"
        atomic_write_text(d / fn, vts_text(np.asarray(g.x), np.asarray(g.y)))
        entries.append(
            f'    <DataSet index="{k}" name={quoteattr(name)} file={quoteattr(f"{p.stem}/{fn}")}/>'
        )
    text = (
        '<?xml version="1.0"?>\n'
        '<VTKFile type="vtkMultiBlockDataSet" version="1.0" byte_order="LittleEndian">\n'
        "  <vtkMultiBlockDataSet>\n" + "\n".join(entries) + "\n"
        "  </vtkMultiBlockDataSet>\n"
        "</VTKFile>\n"
    )
    atomic_write_text(p, text)
    return p


def write_report(path: str | Path, mb: Any) -> Path:
    """Write the connectivity report and the quality tables of a MultiBlockGrid."""
    from ..io import atomic_write_text

    p = Path(path)
    atomic_write_text(p, mb.report() + "\n\n" + mb.quality().table() + "\n")
    return p
