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
from ..grid import StructuredGrid
from ._base import GridSet, atomic_path, read_bytes

__all__ = ["read_grd", "write_grd"]

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


def write_grd(path: Path, gs: GridSet, *, lonlat: bool = False, enclosure: bool = True, **_: Any) -> None:
    """Write an RGFGRID ``.grd`` (and ``.enc``) file (see module docstring)."""
    g = gs.blocks[0]
    if lonlat:
        X, Y = gs.frame.to_lonlat(g.x, g.y)
    else:
        X, Y = gs.world(0)
    mmax, nmax = X.shape
    head = ["* Deltares, Delft3D-RGFGRID grid written by meshcore (gcmesh)"]
    if gs.frame.crs and not lonlat:
        head.append(f"* Projection: {gs.frame.crs}")
    head += [
        f"Coordinate System = {'Spherical' if lonlat else 'Cartesian'}",
        f"Missing Value     = {MISSING:25.17E}",
        f"{mmax:8d}{nmax:8d}",
        " 0 0 0",
    ]
    text = "\n".join(head + _rows("x", X) + _rows("y", Y)) + "\n"
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="ascii")
    if enclosure:
        enc = [(1, 1), (mmax + 1, 1), (mmax + 1, nmax + 1), (1, nmax + 1), (1, 1)]
        with atomic_path(Path(path).with_suffix(".enc")) as tmp:
            tmp.write_text("".join(f"{m:6d}{n:6d}\n" for m, n in enc), encoding="ascii")


_KV = re.compile(r"^\s*([A-Za-z ]+?)\s*=\s*(.*)$")


def read_grd(path: Path, **_: Any) -> GridSet:
    """Read an RGFGRID ``.grd`` file (Cartesian or Spherical)."""
    text = read_bytes(path).decode("latin-1")
    lines = text.splitlines()
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
                    raise ReadError(f"{path}: line {k + 1}: bad Missing Value {val!r}") from None
        k += 1
    if k >= len(lines):
        raise ReadError(f"{path}: no grid dimensions line")
    try:
        mmax, nmax = (int(v) for v in lines[k].split()[:2])
    except ValueError:
        raise ReadError(f"{path}: line {k + 1}: expected 'MMAX NMAX', got {lines[k][:40]!r}") from None
    if mmax < 2 or nmax < 2 or mmax * nmax > 10**8:
        raise ReadError(f"{path}: line {k + 1}: invalid grid size {mmax} x {nmax}")
    k += 2  # skip "0 0 0"
    vals: list[float] = []
    for ln_no in range(k, len(lines)):
        ln = lines[ln_no]
        if not ln.strip():
            continue
        s = ln.split("=", 1)[1] if "ETA=" in ln else ln
        toks = s.split()
        if "ETA=" in ln:
            toks = toks[1:]
        try:
            vals.extend(float(t.replace("D", "E")) for t in toks)
        except ValueError:
            raise ReadError(f"{path}: line {ln_no + 1}: not a number in {ln.strip()[:40]!r}") from None
    if len(vals) != 2 * mmax * nmax:
        raise ReadError(f"{path}: {len(vals)} coordinates, expected 2 x {mmax} x {nmax}")
    a = np.array(vals)
    X = a[: mmax * nmax].reshape((nmax, mmax)).T
    Y = a[mmax * nmax :].reshape((nmax, mmax)).T
    if np.any(missing == X) or np.any(missing == Y):
        raise ReadError(f"{path}: grid has missing (inactive) points; only full grids are read")
    frame = Frame("EPSG:4326" if spherical else crs, (0.0, 0.0))
    return GridSet((StructuredGrid(X, Y),), frame, source=str(path))
