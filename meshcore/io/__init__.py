"""Readers and writers (minimal core set; the I/O issue extends this package).

* ``write(path, grid_or_blocks, format=None)`` — format from the suffix:
  ``.npz`` (numpy), ``.vts`` (VTK XML StructuredGrid, ASCII),
  ``.xyz``/``.x``/``.p3d`` (PLOT3D 2-D, ASCII, multi-block), ``.png``/``.svg``/``.pdf``.
* ``read_grid(path)`` — ``.npz``, ``.vts`` and ASCII PLOT3D back to grids.
* ``read_points(path)`` — a CSV/TXT of x, y columns.

Every file is written atomically: to a temporary file in the same directory,
then renamed, so nothing partial is left behind on error.
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import ReadError, WriteError
from ..grid import StructuredGrid

__all__ = ["atomic_write_bytes", "atomic_write_text", "read_grid", "read_points", "write"]


def _atomic(path: Path, writer: Callable[[Path], None]) -> None:
    path = Path(path)
    d = path.parent if str(path.parent) else Path(".")
    if not d.is_dir():
        raise WriteError(f"{path}: directory {str(d)!r} does not exist")
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=d)
    except OSError as exc:
        raise WriteError(f"{path}: cannot write ({exc.strerror})") from None
    os.close(fd)
    try:
        writer(Path(tmp))
        os.replace(tmp, path)
    except BaseException as exc:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        if isinstance(exc, OSError):
            raise WriteError(f"{path}: cannot write ({exc})") from None
        raise


def atomic_write_text(path: str | Path, text: str) -> None:
    _atomic(Path(path), lambda t: t.write_text(text, encoding="utf-8"))


def atomic_write_bytes(path: str | Path, data: bytes) -> None:
    _atomic(Path(path), lambda t: t.write_bytes(data))


def _blocks(obj: Any) -> list[StructuredGrid]:
    if isinstance(obj, StructuredGrid):
        return [obj]
    blocks = getattr(obj, "blocks", obj)
    if isinstance(blocks, Sequence) and all(isinstance(b, StructuredGrid) for b in blocks) and blocks:
        return list(blocks)
    raise WriteError(f"cannot write {type(obj).__name__}: expected a StructuredGrid or a list of them")


def _write_npz(path: Path, blocks: list[StructuredGrid]) -> None:
    arrays = {}
    for k, g in enumerate(blocks):
        arrays[f"x{k}"] = g.x
        arrays[f"y{k}"] = g.y
    with open(path, "wb") as f:
        np.savez(f, nblocks=len(blocks), **arrays)


def _write_vts(path: Path, blocks: list[StructuredGrid]) -> None:
    if len(blocks) != 1:
        raise WriteError(f"{path}: .vts holds one block; use .vtm for {len(blocks)} blocks")
    g = blocks[0]
    ni1, nj1 = g.shape
    # VTK point order: i fastest → transpose our (i, j) C-order arrays
    pts = np.column_stack([g.x.T.ravel(), g.y.T.ravel(), np.zeros(g.n_nodes)])
    body = "\n".join(f"{a:.17g} {b:.17g} {c:.17g}" for a, b, c in pts)
    ext = f"0 {ni1 - 1} 0 {nj1 - 1} 0 0"
    text = (
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
    path.write_text(text, encoding="utf-8")


def _write_plot3d(path: Path, blocks: list[StructuredGrid]) -> None:
    lines = [str(len(blocks))]
    lines += [f"{g.shape[0]} {g.shape[1]}" for g in blocks]
    for g in blocks:
        for arr in (g.x, g.y):
            vals = arr.T.ravel()  # i fastest
            lines += [" ".join(f"{v:.17g}" for v in vals[k:k + 4]) for k in range(0, len(vals), 4)]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")


def _write_figure(path: Path, blocks: list[StructuredGrid]) -> None:
    from ..plot import plot_grid

    plot_grid(blocks, path=path, fmt=path.suffix.lstrip(".") if path.suffix else "png")


_WRITERS: dict[str, Callable[[Path, list[StructuredGrid]], None]] = {
    "npz": _write_npz,
    "vts": _write_vts,
    "plot3d": _write_plot3d,
    "png": _write_figure,
    "svg": _write_figure,
    "pdf": _write_figure,
}
_SUFFIX = {".npz": "npz", ".vts": "vts", ".xyz": "plot3d", ".x": "plot3d", ".p3d": "plot3d",
           ".png": "png", ".svg": "svg", ".pdf": "pdf"}


def write(path: str | Path, obj: Any, format: str | None = None) -> Path:
    """Write a grid (or a list of block grids) to ``path``; format from the suffix."""
    p = Path(path)
    fmt = format or _SUFFIX.get(p.suffix.lower())
    if fmt not in _WRITERS:
        raise WriteError(
            f"{p}: unknown output format {p.suffix or format!r}; known: {', '.join(sorted(_SUFFIX))}"
        )
    blocks = _blocks(obj)
    writer = _WRITERS[fmt]
    if fmt in ("png", "svg", "pdf"):
        # matplotlib picks the format from the suffix; the temp file must keep it
        def w(t: Path) -> None:
            tt = t.with_suffix(p.suffix)
            writer(tt, blocks)
            os.replace(tt, t)
        _atomic(p, w)
    else:
        _atomic(p, lambda t: writer(t, blocks))
    return p


def read_grid(path: str | Path) -> list[StructuredGrid]:
    """Read block grids from ``.npz``, ``.vts`` or ASCII PLOT3D."""
    p = Path(path)
    if not p.exists():
        raise ReadError(f"{p}: file not found")
    suf = p.suffix.lower()
    try:
        if suf == ".npz":
            with np.load(p) as z:
                n = int(z["nblocks"])
                return [StructuredGrid(z[f"x{k}"], z[f"y{k}"]) for k in range(n)]
        if suf == ".vts":
            import re

            text = p.read_text(encoding="utf-8")
            m = re.search(r'WholeExtent="0 (\d+) 0 (\d+) 0 0"', text)
            body = re.search(r"<DataArray[^>]*>(.*?)</DataArray>", text, re.S)
            if not m or not body:
                raise ReadError(f"{p}: not an ASCII VTK StructuredGrid written by meshcore")
            ni1, nj1 = int(m.group(1)) + 1, int(m.group(2)) + 1
            pts = np.array(body.group(1).split(), dtype=float).reshape(nj1, ni1, 3)
            return [StructuredGrid(pts[..., 0].T, pts[..., 1].T)]
        if suf in (".xyz", ".x", ".p3d"):
            tok = p.read_text(encoding="utf-8").split()
            nb = int(tok[0])
            dims = [(int(tok[1 + 2 * k]), int(tok[2 + 2 * k])) for k in range(nb)]
            vals = np.array(tok[1 + 2 * nb:], dtype=float)
            out, off = [], 0
            for ni1, nj1 in dims:
                n = ni1 * nj1
                x = vals[off:off + n].reshape(nj1, ni1).T
                y = vals[off + n:off + 2 * n].reshape(nj1, ni1).T
                off += 2 * n
                out.append(StructuredGrid(x, y))
            return out
    except ReadError:
        raise
    except (ValueError, KeyError, IndexError, OSError) as exc:
        raise ReadError(f"{p}: cannot read grid ({exc})") from None
    raise ReadError(f"{p}: unknown grid format {suf!r}; known: .npz, .vts, .xyz/.x/.p3d")


def read_points(path: str | Path) -> np.ndarray:
    """Read an ``(n, 2)`` array of points from a CSV/TXT with two numeric columns."""
    p = Path(path)
    if not p.exists():
        raise ReadError(f"{p}: file not found")
    rows = []
    for ln, line in enumerate(p.read_text(encoding="utf-8", errors="replace").splitlines(), 1):
        s = line.strip()
        if not s or s.startswith("#"):
            continue
        parts = s.replace(",", " ").replace(";", " ").split()
        try:
            rows.append((float(parts[0]), float(parts[1])))
        except (ValueError, IndexError):
            if rows:
                raise ReadError(f"{p}, line {ln}: expected two numbers, got {s!r}") from None
            continue  # header
    if not rows:
        raise ReadError(f"{p}: no numeric x, y rows")
    return np.array(rows)
