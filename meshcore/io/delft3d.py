r"""Delft3D RGFGRID curvilinear grids (``.grd``) and enclosures (``.enc``).

``.grd`` (as RGFGRID writes it)::

    * comment lines start with '*'
    Coordinate System = Cartesian          (or Spherical for lon/lat)
    Missing Value     =   -9.99999000000000024E+02
         MMAX      NMAX                     number of grid points along M (ξ) and N (η)
     0 0 0
     ETA=    1   x(1,1) … x(5,1)            5 values per line, 17 significant digits,
                 x(6,1) …                   continuation lines indented
     …  (all ETA rows of x, then all ETA rows of y)

M runs along ξ (``i``), N along η (``j``): ``ETA=j+1`` holds ``x[:, j]``.
World coordinates are written (``lonlat=True``: longitude/latitude and
``Coordinate System = Spherical``); the projected CRS is recorded in a
``* Projection:`` comment because the format has no field for it.

``.enc`` (written next to the ``.grd``): the closed polygon, in water-level
point indices, around the fully active grid: ``(1, 1), (MMAX+1, 1),
(MMAX+1, NMAX+1), (1, NMAX+1), (1, 1)``.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import numpy as np

from ..crs import Frame, normalize_crs
from ..errors import ReadError
from ._base import GridSet, atomic_path, atomic_paths, check_nodes, grid_from_world, read_bytes

__all__ = ["full_grid", "read_enc", "read_grd", "read_grd_arrays", "write_grd"]

MISSING = -999.0


def _rows(name: str, a: np.ndarray) -> list[str]:
    out = []
    mmax, nmax = a.shape
    for j in range(nmax):
        v = a[:, j]
        for s in range(0, mmax, 5):
            vals = "".join(f"{t:25.17E}" for t in v[s : s + 5])
            out.append((f" ETA={j + 1:5d}" if s == 0 else " " * 10) + vals)
    return out


def _grd_text(gs: GridSet, k: int = 0, *, lonlat: bool = False) -> tuple[str, int, int]:
    """The ``.grd`` text of block ``k`` and its node counts (MMAX, NMAX)."""
    g = gs.blocks[k]
    if lonlat:
        X, Y = gs.frame.to_lonlat(g.x, g.y)
    else:
        X, Y = gs.world(k)
    mmax, nmax = X.shape
    return grd_text(X, Y, gs.frame.crs, lonlat, MISSING), mmax, nmax


def grd_text(X: np.ndarray, Y: np.ndarray, crs: Any, lonlat: bool, missing: float, title: str = "") -> str:
    """The text of an RGFGRID ``.grd`` of the node arrays ``X``, ``Y`` (MMAX × NMAX) with ``missing``
    in the header (``title``: added to the first comment line)."""
    mmax, nmax = X.shape
    head = ["* Deltares, Delft3D-RGFGRID grid written by meshcore (gcmesh)" + title]
    if crs and not lonlat:
        head.append(f"* Projection: {crs}")
    head += [
        f"Coordinate System = {'Spherical' if lonlat else 'Cartesian'}",
        f"Missing Value     = {missing:25.17E}",
        f"{mmax:8d}{nmax:8d}",
        " 0 0 0",
    ]
    return "\n".join(head + _rows("x", X) + _rows("y", Y)) + "\n"


def _enc_text(mmax: int, nmax: int) -> str:
    """The enclosure of a fully active grid of MMAX × NMAX points."""
    enc = [(1, 1), (mmax + 1, 1), (mmax + 1, nmax + 1), (1, nmax + 1), (1, 1)]
    return "".join(f"{m:6d}{n:6d}\n" for m, n in enc)


def write_grd(path: Path, gs: GridSet, *, lonlat: bool = False, enclosure: bool = True, **_: Any) -> None:
    """Write an RGFGRID ``.grd`` (and ``.enc``) file (see module docstring).

    The two files are written as a set: both are complete before either
    replaces an old one, so a failure (disk full) leaves the old pair intact.
    """
    text, mmax, nmax = _grd_text(gs, 0, lonlat=lonlat)
    path = Path(path)
    if not enclosure:
        with atomic_path(path) as tmp:
            tmp.write_text(text, encoding="ascii")
        return
    # the .enc is renamed first: a crash between the two renames leaves a new .enc that
    # read_grd finds inconsistent with the old .grd (when the sizes differ) and says so
    with atomic_paths([path.with_suffix(".enc"), path]) as (tmp_enc, tmp_grd):
        tmp_grd.write_text(text, encoding="ascii")
        tmp_enc.write_text(_enc_text(mmax, nmax), encoding="ascii")


_KV = re.compile(r"^\s*([A-Za-z ]+?)\s*=\s*(.*)$")


def _header(path: Path, lines: list[str]) -> tuple[int, str | None, bool, float]:
    """Skip comments and ``key = value`` lines; return (index of the dimensions line, crs, spherical, missing)."""
    k = 0
    crs: str | None = None
    spherical = False
    missing = MISSING
    while k < len(lines) and (lines[k].startswith("*") or _KV.match(lines[k]) or not lines[k].strip()):
        ln = lines[k]
        if ln.startswith("* Projection:"):
            try:
                crs = normalize_crs(ln.split(":", 1)[1].strip())
            except Exception:
                crs = None
        m = _KV.match(ln) if not ln.startswith("*") else None
        if m:
            key, val = m.group(1).strip().lower(), m.group(2).strip()
            if key == "coordinate system":
                spherical = val.lower().startswith("spher")
            elif key == "missing value":
                try:
                    missing = float(val.replace("D", "E"))
                except ValueError:
                    raise ReadError(f"{path}: line {k + 1}: bad Missing Value {val[:40]!r}") from None
        k += 1
    return k, crs, spherical, missing


def read_grd(path: Path, **_: Any) -> GridSet:
    """Read an RGFGRID ``.grd`` file (Cartesian or Spherical) of a full grid.

    The grid size is checked against the node limit before the values are
    read (one pass, into an array of that size); every coordinate must be a
    finite number; a ``.enc`` next to the file that does not fit the grid (a
    pair written by two different runs) is reported.  A grid with missing
    (inactive) points, or whose ``.enc`` is not the full grid's (an island of inactive cells
    between active points), is refused here: ``meshcore.io.read_blocks`` (or
    :func:`meshcore.io.delft3d_single.read_grd_any`) reads it as a single-domain grid.
    """
    gs = full_grid(path)
    if gs is None:
        raise ReadError(
            f"{path}: grid has missing (inactive) points or an enclosure that leaves cells out; "
            "a full grid is expected here (meshcore.io.read_blocks reads it as a single-domain grid)"
        )
    return gs


def full_grid(path: Path, arrays: tuple | None = None) -> GridSet | None:
    """The grid of an RGFGRID ``.grd`` as one block, or None when it has missing (inactive) points or
    its ``.enc`` is not the full grid's (:func:`read_grd`'s checks otherwise; ``arrays``: the file's
    :func:`read_grd_arrays`, if read already)."""
    X, Y, crs, spherical, missing = read_grd_arrays(path) if arrays is None else arrays
    _check_enclosure(path, *X.shape)
    if np.any(missing == X) or np.any(missing == Y) or not _full_enclosure(path, *X.shape):
        return None
    frame = Frame("EPSG:4326" if spherical else crs, (0.0, 0.0))
    return GridSet((grid_from_world(X, Y, (0.0, 0.0), path),), frame, source=str(path))


def read_grd_arrays(path: Path) -> tuple[np.ndarray, np.ndarray, str | None, bool, float]:
    """The node arrays ``X, Y`` (MMAX × NMAX, the missing value at inactive points) of an RGFGRID
    ``.grd``, its CRS (``* Projection:`` comment), whether it is Spherical, and its missing value."""
    text = read_bytes(path).decode("latin-1")
    lines = text.splitlines()
    k, crs, spherical, missing = _header(path, lines)
    if k >= len(lines):
        raise ReadError(f"{path}: no grid dimensions line")
    try:
        mmax, nmax = (int(v) for v in lines[k].split()[:2])
    except ValueError:
        raise ReadError(f"{path}: line {k + 1}: expected 'MMAX NMAX', got {lines[k][:40]!r}") from None
    if mmax < 2 or nmax < 2:
        raise ReadError(f"{path}: line {k + 1}: invalid grid size {mmax} x {nmax}")
    check_nodes((mmax, nmax), path)
    need = 2 * mmax * nmax
    a = np.empty(need)
    n = 0
    for ln_no in range(k + 2, len(lines)):  # k + 1 is "0 0 0"
        ln = lines[ln_no]
        s = ln.split("=", 1)[1] if "ETA=" in ln else ln
        toks = s.split()
        if "ETA=" in ln:
            toks = toks[1:]
        if not toks:
            continue
        if n + len(toks) > need:
            raise ReadError(f"{path}: line {ln_no + 1}: more coordinates than 2 x {mmax} x {nmax}")
        try:
            a[n : n + len(toks)] = [float(t.replace("D", "E")) for t in toks]
        except ValueError:
            raise ReadError(f"{path}: line {ln_no + 1}: not a number in {ln.strip()[:40]!r}") from None
        n += len(toks)
    if n != need:
        raise ReadError(f"{path}: {n} coordinates, expected 2 x {mmax} x {nmax}")
    X = a[: mmax * nmax].reshape((nmax, mmax)).T
    Y = a[mmax * nmax :].reshape((nmax, mmax)).T
    if spherical:  # lon/lat: metres in a file that says Spherical would be read as degrees
        bad = np.argwhere(((np.abs(X) > 360) | (np.abs(Y) > 90)) & np.not_equal(X, missing) & np.not_equal(Y, missing))
        if len(bad):
            m, nn = (int(v) for v in bad[0])
            raise ReadError(
                f"{path}: Coordinate System = Spherical, but node (m={m + 1}, n={nn + 1}) is "
                f"({X[m, nn]:.6g}, {Y[m, nn]:.6g}), not longitude, latitude: is the grid Cartesian?"
            )
    return X, Y, crs, spherical, missing


def read_enc(path: Path) -> list[list[tuple[int, int]]]:
    """The polygons of an enclosure file: ``m n`` per line, each polygon closed by repeating its first
    point (ReadError naming the file and line for anything else)."""
    text = read_bytes(path).decode("latin-1")
    polys: list[list[tuple[int, int]]] = []
    cur: list[tuple[int, int]] = []
    for no, ln in enumerate(text.splitlines(), 1):
        toks = ln.split()
        if not toks or ln.lstrip().startswith("*"):
            continue
        try:
            p = (int(toks[0]), int(toks[1]))
        except (ValueError, IndexError):
            raise ReadError(f"{path}: line {no}: expected two integers 'M N', got {ln.strip()[:40]!r}") from None
        cur.append(p)
        if len(cur) > 1 and p == cur[0]:
            polys.append(cur)
            cur = []
    if cur:
        raise ReadError(
            f"{path}: the last polygon (from point {cur[0]}) is not closed: its first point is not repeated"
        )
    if not polys:
        raise ReadError(f"{path}: no enclosure polygon")
    return polys


def _full_enclosure(path: Path, mmax: int, nmax: int) -> bool:
    """True when no ``.enc`` is beside ``path`` or it is the enclosure of the full grid."""
    enc = Path(path).with_suffix(".enc")
    if not enc.is_file():
        return True
    full = [(1, 1), (mmax + 1, 1), (mmax + 1, nmax + 1), (1, nmax + 1), (1, 1)]
    return read_enc(enc) == [full]


def _check_enclosure(path: Path, mmax: int, nmax: int) -> None:
    """A sibling ``.enc`` must stay within the grid's MMAX+1 × NMAX+1 water-level points."""
    enc = Path(path).with_suffix(".enc")
    try:
        if not enc.is_file() or enc.stat().st_size > 2**20:
            return
        text = enc.read_text(encoding="latin-1")
    except OSError:
        return
    for no, ln in enumerate(text.splitlines(), 1):
        v = ln.split()
        if len(v) >= 2 and v[0].lstrip("-").isdigit() and v[1].lstrip("-").isdigit():
            m, nn = int(v[0]), int(v[1])
            if not (0 <= m <= mmax + 1 and 0 <= nn <= nmax + 1):
                raise ReadError(
                    f"{path}: the enclosure {enc.name} (line {no}: {m} {nn}) does not fit this "
                    f"{mmax} x {nmax} grid: the two files come from different writes"
                )
