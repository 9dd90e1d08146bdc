r"""EFDC / EFDC+ grid input: ``cell.inp``, ``celllt.inp``, ``dxdy.inp``, ``lxly.inp``, ``corners.inp``.

``write("run/cell.inp", mbgrid)`` (``meshcore mesh … -o run/cell.inp``) places the blocks in
one index space (:mod:`meshcore.multiblock.indexspace`) and writes the five files EFDC reads
by fixed names into the folder of ``cell.inp``.  Each cell of the merged grid is an EFDC cell
``(I, J)``, 1-based, ``I`` along the merged grid's first index and ``J`` along its second (the
index space is right-handed: ``J`` to the left of ``I``, as EFDC's north of east); cell
``(I, J)`` has the corners ``(I-2 … I-1, J-2 … J-1)`` of the merged grid's nodes (0-based), so
the ring ``I = 1``, ``I = IC``, ``J = 1``, ``J = JC`` is land round the water.  ``IC``, ``JC``
and the number of water cells (``LVC``; EFDC's ``efdc.inp`` card C9 asks for them) are
written in the first comment line of each file.

Sources: the EFDC+ documentation (efdcplus.readthedocs.io, "Required Spatial Files":
``cell.inp``, ``dxdy.inp``, ``lxly.inp``, ``corners.inp``), the US EPA EFDC User Manual
(Tetra Tech, 2007: cell types), and the reading routines of EFDC+ (github.com/dsi-llc/EFDC_Plus:
``Scan_Cell`` reads ``cell.inp``, ``INPUT`` reads ``lxly.inp``, ``AREA_CENTRD`` reads
``corners.inp``).  Comment lines start with ``C`` (EFDC+ skips lines starting with ``C c * #``
or anything but a digit, ``-`` or ``.``; the US EPA EFDC skips exactly four lines: every file
here has four).

``cell.inp`` (and ``celllt.inp``, the same map)
    One line per row, from ``J = JC`` down to ``J = 1``: ``J`` in 4 columns, a space, then one
    digit per cell ``I = 1 … IC`` (EFDC+ reads ``(I4,1X,640I1)``; wider grids are written as
    blocks of 640 columns, every row in each, as EFDC+ reads them).  Cell types: ``5`` a water
    cell (a quadrilateral), ``9`` a land cell next to a water cell on a side or a corner, ``0``
    land away from the water (triangular water cells ``1``–``4`` are not written).
``dxdy.inp``
    One line per water cell: ``I J DX DY DEPTH BOTTOM_ELEV ZROUGH VEG_TYPE``.  ``DX`` is the
    distance between the midpoints of the cell's two ``I`` faces (west and east), ``DY``
    between those of its ``J`` faces (south and north), in metres; ``DEPTH`` (default 1 m),
    ``BOTTOM_ELEV`` (default ``-DEPTH``: a water surface at 0), ``ZROUGH`` (log-law roughness
    height, default 0.002 m, the EFDC+ documentation's example) and ``VEG_TYPE`` (0) are
    placeholders to replace with the lake's bathymetry.
``lxly.inp``
    One line per water cell: ``I J X Y CUE CVE CUN CVN WIND_SHELTER``.  ``X, Y`` is the cell
    centre (the mean of its four corners), in the grid's CRS.  ``(CUE, CUN)`` is the unit vector
    of the cell's ``I`` direction (west face midpoint → east face midpoint) and ``(CVE, CVN)``
    that of its ``J`` direction (south → north), east and north components: the matrix
    ``[[CUE, CVE], [CUN, CVN]]`` takes a velocity's ``(u, v)`` along the grid lines to east and
    north.  EFDC+ reads the angle of ``I`` as ``atan2(CUN, CUE)`` and that of ``J`` less 90° as
    ``atan2(-CVE, CVN)`` and averages the two; on an orthogonal cell they agree.
    ``WIND_SHELTER`` is 1 (the full wind).
``corners.inp``
    One line per water cell: ``I J X1 Y1 X2 Y2 X3 Y3 X4 Y4``, the corners south-west,
    north-west, north-east, south-east (clockwise from ``(I-1, J-1)`` of the cell's own
    indices), as EFDC_Explorer writes them; EFDC+ reads it for particle tracking and for its
    NetCDF output.

The five files are written as a set (all or none, :mod:`._atomic`).  A layout that does not
fit one index space is refused with the place named (:mod:`.delft3d_single`).

Reading (:func:`read_efdc`, ``read_blocks("run/cell.inp")``): the cell types of ``cell.inp`` and
the corners of ``corners.inp`` beside it make the merged grid (:func:`read_index_space`: cell
``(I, J)`` has the nodes ``(I-2 … I-1, J-2 … J-1)``, as written); its water cells cut into
rectangles are the blocks of the :class:`GridSet` returned (as :mod:`.delft3d_single` reads a
``.grd``).  ``dxdy.inp`` and ``lxly.inp`` follow from the corners and are not read.  Refused, with
the file and line: a cell type other than 0, 5 or 9 (triangular cells 1–4 are not read), water on
the outer ring, a corners line for a cell that is not water (or twice), a water cell without one,
and two cells that put a shared node at two places.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from ..crs import Frame, normalize_crs
from ..errors import ReadError, WriteError
from ._atomic import atomic_paths
from ._base import GridSet, read_bytes

__all__ = ["FILES", "cell_types", "efdc_cells", "read_efdc", "read_index_space", "write_efdc"]

#: The files written, in the folder of ``cell.inp``.
FILES = ("cell.inp", "celllt.inp", "dxdy.inp", "lxly.inp", "corners.inp")
#: Columns of one ``cell.inp`` block (EFDC+ reads at most 640 digits a row).
WIDTH = 640


def cell_types(water: np.ndarray) -> np.ndarray:
    """EFDC cell types of a water mask padded by one land ring: 5 water, 9 land next to water, 0 else."""
    w = np.pad(water, 1)
    near = np.zeros_like(w)
    for di in (-1, 0, 1):
        for dj in (-1, 0, 1):
            near |= np.roll(np.roll(w, di, 0), dj, 1)
    return np.where(w, 5, np.where(near, 9, 0))


def efdc_cells(x: np.ndarray, y: np.ndarray, water: np.ndarray) -> dict[str, np.ndarray]:
    """Per water cell (in ``np.nonzero(water)`` order): EFDC ``I, J``, corners, ``DX, DY``, centre, directions."""
    I, J = np.nonzero(water)
    sw = np.stack([x[I, J], y[I, J]], -1)
    se = np.stack([x[I + 1, J], y[I + 1, J]], -1)
    ne = np.stack([x[I + 1, J + 1], y[I + 1, J + 1]], -1)
    nw = np.stack([x[I, J + 1], y[I, J + 1]], -1)
    du = 0.5 * (se + ne) - 0.5 * (sw + nw)  # west face midpoint → east face midpoint
    dv = 0.5 * (nw + ne) - 0.5 * (sw + se)  # south → north
    dx, dy = np.hypot(*du.T), np.hypot(*dv.T)
    return {
        "I": I + 2,
        "J": J + 2,
        "corners": np.stack([sw, nw, ne, se], 1),
        "dx": dx,
        "dy": dy,
        "centre": 0.25 * (sw + se + ne + nw),
        "u": du / dx[:, None],
        "v": dv / dy[:, None],
    }


def _cell_text(types: np.ndarray, head: str, name: str) -> str:
    ic, jc = types.shape
    lines = [f"C {name}: {head}", "C cell types: 5 water, 9 land next to water, 0 land", "C written by meshcore"]
    lines.append("C    " + "".join(str((i + 1) % 10) for i in range(min(ic, WIDTH))))
    for s in range(0, ic, WIDTH):
        for j in range(jc - 1, -1, -1):
            lines.append(f"{j + 1:4d} " + "".join(str(int(t)) for t in types[s : s + WIDTH, j]))
    return "\n".join(lines) + "\n"


def write_efdc(
    path: Path,
    gs: GridSet,
    *,
    depth: float = 1.0,
    bottom: float | None = None,
    zrough: float = 0.002,
    **_: Any,
) -> None:
    """Write the EFDC grid files of ``gs`` into the folder of ``path`` (named ``cell.inp``)."""
    from .delft3d_single import merged

    path = Path(path)
    if path.name.lower() != "cell.inp":
        raise WriteError(
            f"{path}: EFDC reads its grid from files of fixed names; write -o FOLDER/cell.inp "
            f"(and {', '.join(FILES[1:])} are written next to it)"
        )
    space = merged(gs, path)
    wx, wy = gs.frame.to_world(np.nan_to_num(space.x), np.nan_to_num(space.y))
    c = efdc_cells(wx, wy, space.water)
    types = cell_types(space.water)
    ic, jc = types.shape
    head = f"IC = {ic}, JC = {jc}, LVC = {len(c['I'])} water cells"
    crs = f" (CRS {gs.frame.crs})" if gs.frame.crs else ""
    bottom = -depth if bottom is None else bottom
    dxdy = [f"C dxdy.inp: {head}", "C DX, DY in metres; DEPTH, BOTTOM ELEV, ZROUGH are placeholders", "C"]
    dxdy.append("C     I     J              DX              DY     DEPTH  BOTTOM_ELEV    ZROUGH VEG")
    lxly = [f"C lxly.inp: {head}", f"C X, Y: cell centres{crs}; (CUE, CUN), (CVE, CVN): I and J directions", "C"]
    lxly.append("C     I     J                  X                  Y       CUE       CVE       CUN       CVN  SHELTER")
    corn = [f"C corners.inp: {head}", f"C corners SW, NW, NE, SE{crs}", "C", "C     I     J  X1 Y1 X2 Y2 X3 Y3 X4 Y4"]
    for k in range(len(c["I"])):
        ij = f"{c['I'][k]:7d}{c['J'][k]:6d}"
        u, v = c["u"][k], c["v"][k]
        dxdy.append(f"{ij} {c['dx'][k]:15.6f} {c['dy'][k]:15.6f} {depth:9.4f} {bottom:12.4f} {zrough:9.3E}   0")
        lxly.append(
            f"{ij} {c['centre'][k, 0]:18.6f} {c['centre'][k, 1]:18.6f} "
            f"{u[0]:9.6f} {v[0]:9.6f} {u[1]:9.6f} {v[1]:9.6f}     1.00"
        )
        corn.append(ij + "".join(f" {p[0]:.6f} {p[1]:.6f}" for p in c["corners"][k]))
    texts = {
        "cell.inp": _cell_text(types, head, "cell.inp"),
        "celllt.inp": _cell_text(types, head, "celllt.inp"),
        "dxdy.inp": "\n".join(dxdy) + "\n",
        "lxly.inp": "\n".join(lxly) + "\n",
        "corners.inp": "\n".join(corn) + "\n",
    }
    targets = [path.with_name(f) for f in FILES]
    with atomic_paths(targets) as tmps:
        for tmp, f in zip(tmps, FILES, strict=True):
            tmp.write_text(texts[f], encoding="ascii")


# ------------------------------------------------------------------- reading
def _data_lines(path: Path) -> list[tuple[int, str]]:
    """``(line number, text)`` of the lines EFDC+ reads: not comments (``C c * #``) nor blank."""
    text = read_bytes(path).decode("latin-1")
    return [(no, ln) for no, ln in enumerate(text.splitlines(), 1) if ln.strip() and ln.lstrip()[:1] not in "Cc*#"]


def _read_types(path: Path) -> np.ndarray:
    """The cell types of ``cell.inp``, ``(IC, JC)`` (``types[I-1, J-1]``)."""
    rows: dict[int, list[str]] = {}
    first: dict[int, int] = {}
    for no, ln in _data_lines(path):
        head, digits = ln[:4], ln[5:].rstrip()
        try:
            j = int(head)
        except ValueError:
            raise ReadError(f"{path}: line {no}: expected the row number J in columns 1-4, got {head!r}") from None
        if j < 1:
            raise ReadError(f"{path}: line {no}: row number J = {j} (rows are 1 … JC)")
        bad = next((k for k, c in enumerate(digits) if c not in "0123456789"), None)
        if bad is not None:
            raise ReadError(
                f"{path}: line {no}, column {bad + 6}: {digits[bad]!r} is not a cell type (one digit per cell)"
            )
        rows.setdefault(j, []).append(digits)
        first.setdefault(j, no)
    if not rows:
        raise ReadError(f"{path}: no rows of cell types")
    jc = max(rows)
    missing = sorted(set(range(1, jc + 1)) - set(rows))
    if missing:
        raise ReadError(f"{path}: no row J = {missing[0]} (rows 1 … {jc} are expected)")
    full = {j: "".join(parts) for j, parts in rows.items()}
    ic = len(full[jc])
    for j in range(jc, 0, -1):
        if len(full[j]) != ic:
            raise ReadError(f"{path}: line {first[j]}: row J = {j} has {len(full[j])} cells, row J = {jc} has {ic}")
    types = np.array([[int(c) for c in full[j]] for j in range(1, jc + 1)], dtype=np.int8).T
    odd = ~np.isin(types, (0, 5, 9))
    if odd.any():
        i, j = (int(v) for v in np.argwhere(odd)[0])
        kind = "a triangular water cell (1-4), not read" if 1 <= types[i, j] <= 4 else "not a cell type meshcore reads"
        raise ReadError(f"{path}: line {first[j + 1]}: cell (I={i + 1}, J={j + 1}) has type {types[i, j]}: {kind}")
    ring = np.zeros(types.shape, bool)
    ring[[0, -1], :] = ring[:, [0, -1]] = True
    if (ring & (types == 5)).any():
        i, j = (int(v) for v in np.argwhere(ring & (types == 5))[0])
        raise ReadError(
            f"{path}: line {first[j + 1]}: water cell (I={i + 1}, J={j + 1}) on the outer ring (I = 1 or {ic}, "
            f"J = 1 or {jc}): a grid with land all round is read"
        )
    return types


def read_index_space(path: Path) -> tuple[Any, Frame]:
    """The merged grid of EFDC's ``cell.inp`` and ``corners.inp`` (see the module docstring), and its frame."""
    import re

    from ..multiblock.indexspace import from_mask

    path = Path(path)
    if path.name.lower() not in FILES:
        raise ReadError(f"{path}: EFDC grids are read from cell.inp (and corners.inp beside it)")
    path = path.with_name("cell.inp")
    types = _read_types(path)
    water = types[1:-1, 1:-1] == 5
    corners_path = path.with_name("corners.inp")
    if not corners_path.is_file():
        raise ReadError(f"{path}: no corners.inp beside it: the cell corners (node coordinates) are read from it")
    lines = _data_lines(corners_path)
    text = read_bytes(corners_path).decode("latin-1")
    m = re.search(r"\(CRS ([^)]+)\)", text[:4096])
    crs = None
    if m:
        try:
            crs = normalize_crs(m.group(1).strip())
        except Exception:
            crs = None
    shape = (types.shape[0] - 1, types.shape[1] - 1)  # nodes
    x = np.full(shape, np.nan)
    y = np.full(shape, np.nan)
    line_of = np.zeros(water.shape, dtype=np.int64)  # the corners line of each water cell
    vals = np.zeros((len(lines), 8))
    at = np.zeros((len(lines), 2), dtype=np.int64)
    for k, (no, ln) in enumerate(lines):
        toks = ln.split()
        if len(toks) < 10:
            raise ReadError(
                f"{corners_path}: line {no}: expected 'I J X1 Y1 X2 Y2 X3 Y3 X4 Y4', got {ln.strip()[:60]!r}"
            )
        try:
            i, j = int(toks[0]), int(toks[1])
            vals[k] = [float(t) for t in toks[2:10]]
        except ValueError:
            raise ReadError(f"{corners_path}: line {no}: not a number in {ln.strip()[:60]!r}") from None
        if not np.isfinite(vals[k]).all():
            raise ReadError(f"{corners_path}: line {no}: a corner coordinate is not finite")
        if not (2 <= i <= types.shape[0] - 1 and 2 <= j <= types.shape[1] - 1) or not water[i - 2, j - 2]:
            raise ReadError(f"{corners_path}: line {no}: cell (I={i}, J={j}) is not a water cell of {path.name}")
        if line_of[i - 2, j - 2]:
            raise ReadError(
                f"{corners_path}: line {no}: cell (I={i}, J={j}) again (first on line {line_of[i - 2, j - 2]})"
            )
        line_of[i - 2, j - 2] = no
        at[k] = (i - 2, j - 2)
    if (water & (line_of == 0)).any():
        i, j = (int(v) for v in np.argwhere(water & (line_of == 0))[0])
        raise ReadError(f"{corners_path}: no line for water cell (I={i + 2}, J={j + 2}) of {path.name}")
    # corners SW, NW, NE, SE of cell (I, J) are the nodes (I-2, J-2), (I-2, J-1), (I-1, J-1), (I-1, J-2);
    # line by line, corner by corner: a node takes the place of its first line
    di, dj = np.array([0, 0, 1, 1]), np.array([0, 1, 1, 0])
    ni, nj = (at[:, :1] + di).ravel(), (at[:, 1:] + dj).ravel()
    px, py = vals[:, 0::2].ravel(), vals[:, 1::2].ravel()
    line = np.repeat([no for no, _ in lines], 4)
    first = np.zeros(shape, dtype=np.int64)
    nodes, k0 = np.unique(ni * shape[1] + nj, return_index=True)  # each node's first place
    x.flat[nodes], y.flat[nodes], first.flat[nodes] = px[k0], py[k0], line[k0]
    extent = float(np.hypot(np.ptp(px), np.ptp(py))) if len(px) else 0.0
    tol = 1e-6 + 1e-9 * extent  # six decimals written
    off = np.hypot(px - x[ni, nj], py - y[ni, nj]) > tol
    if off.any():
        q = int(np.flatnonzero(off)[0])
        k, c = divmod(q, 4)
        i, j = (int(v) for v in at[k])
        raise ReadError(
            f"{corners_path}: line {line[q]}: corner {('SW', 'NW', 'NE', 'SE')[c]} of cell (I={i + 2}, J={j + 2}) "
            f"is ({px[q]:.6f}, {py[q]:.6f}), but line {first[ni[q], nj[q]]} puts that node at "
            f"({x[ni[q], nj[q]]:.6f}, {y[ni[q], nj[q]]:.6f})"
        )
    return from_mask(x, y, water), Frame(crs, (0.0, 0.0))


def read_efdc(path: Path, **_: Any) -> GridSet:
    """Read EFDC's grid (``cell.inp`` + ``corners.inp``): its water cells as rectangular blocks."""
    from .delft3d_single import gridset_of

    space, frame = read_index_space(path)
    return gridset_of(space, frame, Path(path).with_name("cell.inp"))
