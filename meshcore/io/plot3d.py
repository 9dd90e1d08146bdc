r"""PLOT3D 2-D grid files (``.xyz``, ``.x``, ``.p3d``, ``.g``), single and multi-block.

Layout (2-D, "whole" grid without IBLANK)::

    [nblocks]                       multi-block files only
    ni_1 nj_1  ni_2 nj_2 …           node counts per block
    x_1(i fastest) y_1(i fastest)   one record per block
    …

Three encodings: ``"ascii"`` (numbers as text, 17 significant digits),
``"fortran"`` (Fortran unformatted sequential: every record framed by its byte
count as int32, the default) and ``"binary"`` (plain C stream).  Binary files
use float64 (``precision="single"``: float32), int32 counts and little endian
(``byte_order="big"`` for big).  The reader detects all of these, and 3-D
files with ``nk = 1``.  PLOT3D carries no CRS: world coordinates are written.
"""

from __future__ import annotations

import io
import struct
import warnings
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import ReadError, WriteError
from ..grid import StructuredGrid
from ._base import GridSet, atomic_path, check_nodes, grid_from_world, read_bytes

__all__ = ["read_plot3d", "write_plot3d"]


def write_plot3d(
    path: Path,
    gs: GridSet,
    *,
    mode: str = "fortran",
    multi: bool | None = None,
    precision: str = "double",
    byte_order: str = "little",
    **_: Any,
) -> None:
    """Write blocks as a 2-D PLOT3D grid file (see module docstring)."""
    if mode not in ("ascii", "fortran", "binary"):
        raise WriteError(f"{path}: PLOT3D mode must be ascii, fortran or binary, got {mode!r}")
    if precision not in ("double", "single"):
        raise WriteError(f"{path}: precision must be 'double' or 'single', got {precision!r}")
    multi = len(gs.blocks) > 1 if multi is None else bool(multi)
    if not multi and len(gs.blocks) > 1:
        raise WriteError(f"{path}: {len(gs.blocks)} blocks need a multi-block PLOT3D file")
    dims = [g.shape for g in gs.blocks]
    coords = [gs.world(k) for k in range(len(gs.blocks))]
    with atomic_path(path) as tmp:
        if mode == "ascii":
            with open(tmp, "w", encoding="ascii") as f:
                if multi:
                    f.write(f"{len(dims)}\n")
                f.write(" ".join(f"{a} {b}" for a, b in dims) + "\n")
                for x, y in coords:
                    for arr in (x, y):
                        v = arr.ravel(order="F")
                        for s in range(0, len(v), 4):
                            f.write(" ".join(f"{t:.17g}" for t in v[s : s + 4]) + "\n")
            return
        bo = "<" if byte_order == "little" else ">"
        ft = np.dtype(f"{bo}f8" if precision == "double" else f"{bo}f4")
        it = np.dtype(f"{bo}i4")
        recs: list[bytes] = []
        if multi:
            recs.append(np.array([len(dims)], dtype=it).tobytes())
        recs.append(np.array(dims, dtype=it).ravel().tobytes())
        for x, y in coords:
            recs.append(np.concatenate([x.ravel(order="F"), y.ravel(order="F")]).astype(ft).tobytes())
        with open(tmp, "wb") as f:
            for r in recs:
                if mode == "fortran":
                    n = struct.pack(f"{bo}i", len(r))
                    f.write(n + r + n)
                else:
                    f.write(r)


# --------------------------------------------------------------------- reading
def _blocks_from(values: np.ndarray, dims: list[tuple[int, ...]], path: Path) -> list[StructuredGrid]:
    out = []
    pos = 0
    for k, d in enumerate(dims):
        n = int(np.prod(d))
        ncoord = 3 if len(d) == 3 else 2
        chunk = values[pos : pos + ncoord * n]
        if len(chunk) < ncoord * n:
            raise ReadError(f"{path}: block {k + 1} is truncated ({len(chunk)} of {ncoord * n} values)")
        pos += ncoord * n
        x = chunk[:n].reshape(d, order="F")
        y = chunk[n : 2 * n].reshape(d, order="F")
        if len(d) == 3:
            x, y = x[:, :, 0], y[:, :, 0]
        out.append(grid_from_world(x, y, (0.0, 0.0), path, f"block {k + 1}"))
    return out


def _check_dims(dims: list[tuple[int, ...]], path: Path) -> None:
    for k, d in enumerate(dims):
        if any(v < 1 for v in d) or (len(d) == 3 and d[2] != 1):
            raise ReadError(f"{path}: block {k + 1} has invalid dimensions {d} (2-D grids only)")
        if d[0] < 2 or d[1] < 2:
            raise ReadError(f"{path}: block {k + 1} has {d} nodes, at least 2 × 2 are needed")
        check_nodes(d, path, f"block {k + 1}")


def _numbers(path: Path, text: str) -> np.ndarray:
    """All white-space separated numbers of ``text`` (Fortran ``D`` exponents too), in one C pass."""
    text = text.replace("d", "e").replace("D", "e")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            return np.fromstring(text, dtype=np.float64, sep=" ")
    except (ValueError, DeprecationWarning):
        pass
    for lineno, ln in enumerate(io.StringIO(text), 1):  # find the culprit (only on error)
        for t in ln.split():
            if not _isfloat(t):
                raise ReadError(f"{path}: line {lineno}: {t[:30]!r} is not a number") from None
    raise ReadError(f"{path}: not a list of numbers")


def _read_ascii(path: Path, text: str) -> list[StructuredGrid]:
    v = _numbers(path, text)
    if not v.size:
        raise ReadError(f"{path}: file is empty")
    # hypotheses: multi/single × 2-D/3-D; pick the one whose count matches
    for multi in (True, False):
        for nd in (2, 3):
            try:
                nb = int(v[0]) if multi else 1
                if multi and (v[0] != nb or nb < 1 or nb > 100_000):
                    continue
                off = 1 if multi else 0
                dv = v[off : off + nd * nb]
                if len(dv) < nd * nb or np.any(dv != np.round(dv)) or np.any(dv < 1):
                    continue
                dims = [tuple(int(t) for t in dv[k * nd : (k + 1) * nd]) for k in range(nb)]
                need = sum(nd * int(np.prod(d)) for d in dims)
                if len(v) - off - nd * nb != need:
                    continue
            except (OverflowError, ValueError):
                continue
            _check_dims(dims, path)
            return _blocks_from(v[off + nd * nb :], dims, path)
    raise ReadError(f"{path}: not a 2-D PLOT3D grid: the {len(v)} numbers match no single- or multi-block layout")


def _isfloat(t: str) -> bool:
    try:
        float(t.replace("d", "e").replace("D", "e"))
        return True
    except ValueError:
        return False


def _read_binary(path: Path, data: bytes) -> list[StructuredGrid]:
    size = len(data)
    for bo in ("<", ">"):
        i4 = np.dtype(f"{bo}i4")
        for fortran in (True, False):
            for multi in (True, False):
                for nd in (2, 3):
                    for fsz in (8, 4):
                        r = _try_binary(data, size, bo, i4, fortran, multi, nd, fsz)
                        if r is not None:
                            dims, values = r
                            _check_dims(dims, path)
                            return _blocks_from(values, dims, path)
    raise ReadError(
        f"{path}: not a 2-D PLOT3D grid: no ASCII, Fortran-unformatted or plain binary layout matches its {size} bytes"
    )


def _try_binary(data, size, bo, i4, fortran, multi, nd, fsz):
    pos = 0

    def ints(n):
        nonlocal pos
        if fortran:
            if pos + 4 > size or struct.unpack_from(f"{bo}i", data, pos)[0] != 4 * n:
                return None
            pos += 4
        if pos + 4 * n > size:
            return None
        a = np.frombuffer(data, dtype=i4, count=n, offset=pos)
        pos += 4 * n
        if fortran:
            if pos + 4 > size or struct.unpack_from(f"{bo}i", data, pos)[0] != 4 * n:
                return None
            pos += 4
        return a

    if multi:
        nb_a = ints(1)
        if nb_a is None or not (1 <= nb_a[0] <= 100_000):
            return None
        nb = int(nb_a[0])
    else:
        nb = 1
    d = ints(nd * nb)
    if d is None or np.any(d < 1) or np.any(d > 10**8):
        return None
    dims = [tuple(int(t) for t in d[k * nd : (k + 1) * nd]) for k in range(nb)]
    need = [nd * int(np.prod(dd)) * fsz for dd in dims]
    expect = pos + sum(need) + (8 * nb if fortran else 0)
    if expect != size:
        return None
    ft = np.dtype(f"{bo}f{fsz}")
    parts = []
    for n in need:
        if fortran:
            if struct.unpack_from(f"{bo}i", data, pos)[0] != n:
                return None
            pos += 4
        parts.append(np.frombuffer(data, dtype=ft, count=n // fsz, offset=pos).astype(np.float64))
        pos += n + (4 if fortran else 0)
    return dims, np.concatenate(parts)


def read_plot3d(path: Path, **_: Any) -> GridSet:
    """Read a 2-D PLOT3D grid file in any of the encodings (see module docstring)."""
    data = read_bytes(path)
    if not data.strip():
        raise ReadError(f"{path}: file is empty")
    head = data[:4096]
    is_text = all(32 <= c < 127 or c in (9, 10, 13) for c in head)
    if is_text:
        blocks = _read_ascii(path, data.decode("ascii", errors="replace"))
    else:
        blocks = _read_binary(path, data)
    return GridSet(tuple(blocks), source=str(path))
