r"""Metrics files for generalized-coordinate solvers: ``.npz`` and ``.csv``.

One row (CSV) / one array entry (NPZ) per node, columns:

============  ==========================================================
``block``     block number (0-based; CSV only)
``i``, ``j``  node indices along ξ and η (0-based)
``x``, ``y``  world coordinates (local + origin), metres in a projected CRS
``x_xi``      ∂x/∂ξ (Δξ = 1 per cell; central inside, 2nd-order one-sided on borders)
``x_eta``     ∂x/∂η
``y_xi``      ∂y/∂ξ
``y_eta``     ∂y/∂η
``J``         x_ξ y_η − x_η y_ξ (the paper's 1/J: cell area per unit ξη)
``alpha``     α = x_η² + y_η²
``beta``      β = x_ξ x_η + y_ξ y_η
``gamma``     γ = x_ξ² + y_ξ²
``xi_x``      ξ_x = y_η / J
``xi_y``      ξ_y = −x_η / J
``eta_x``     η_x = −y_ξ / J
``eta_y``     η_y = x_ξ / J
============  ==========================================================

The CSV starts with ``#`` comment lines naming the CRS, the origin, the border
names and every column.  The NPZ holds, per block ``k`` (prefix ``b{k}_``),
arrays of the node shape ``(ni + 1, nj + 1)`` under the same names, plus
``crs``, ``origin``, ``block_names`` and ``border_names`` (JSON).
"""

from __future__ import annotations

import io
import json
import zipfile
from pathlib import Path
from typing import Any

import numpy as np

from ..crs import Frame
from ..errors import ReadError
from ..grid import StructuredGrid
from ..metrics import metrics
from ._base import GridSet, atomic_path, border_names, read_bytes

__all__ = ["COLUMNS", "read_metrics_csv", "read_npz", "write_metrics_csv", "write_npz"]

#: Column → description (also written into the CSV header).
COLUMNS: dict[str, str] = {
    "block": "block number (0-based)",
    "i": "node index along xi (0-based)",
    "j": "node index along eta (0-based)",
    "x": "x, world coordinate (local + origin)",
    "y": "y, world coordinate (local + origin)",
    "x_xi": "dx/dxi (unit spacing in xi; central inside, 2nd-order one-sided at borders)",
    "x_eta": "dx/deta",
    "y_xi": "dy/dxi",
    "y_eta": "dy/deta",
    "J": "x_xi*y_eta - x_eta*y_xi (the paper's 1/J)",
    "alpha": "x_eta^2 + y_eta^2",
    "beta": "x_xi*x_eta + y_xi*y_eta",
    "gamma": "x_xi^2 + y_xi^2",
    "xi_x": "y_eta / J",
    "xi_y": "-x_eta / J",
    "eta_x": "-y_xi / J",
    "eta_y": "x_xi / J",
}
_METRIC_KEYS = (
    "x_xi",
    "x_eta",
    "y_xi",
    "y_eta",
    "jacobian",
    "alpha",
    "beta",
    "gamma",
    "xi_x",
    "xi_y",
    "eta_x",
    "eta_y",
)


def _node_table(g: StructuredGrid, frame: Frame) -> dict[str, np.ndarray]:
    m = metrics(g).as_dict()
    X, Y = frame.to_world(g.x, g.y)
    out = {"x": X, "y": Y}
    for k in _METRIC_KEYS:
        out["J" if k == "jacobian" else k] = m[k]
    return out


def write_metrics_csv(path: Path, gs: GridSet, **_: Any) -> None:
    """Write the per-node metrics table (see module docstring)."""
    lines = ["# meshcore metrics file: one row per grid node"]
    lines.append(f"# crs: {gs.frame.crs or 'unknown'}")
    lines.append(f"# origin: {gs.frame.origin[0]!r} {gs.frame.origin[1]!r}")
    for k, g in enumerate(gs.blocks):
        nm = border_names(g)
        lines.append(
            f"# block {k} ({gs.block_names[k]}): {g.shape[0]} x {g.shape[1]} nodes; "
            f"borders " + ", ".join(f"{b}={n}" for b, n in nm.items())
        )
    for c, d in COLUMNS.items():
        lines.append(f"# column {c}: {d}")
    lines.append(",".join(COLUMNS))
    buf = io.StringIO()
    buf.write("\n".join(lines) + "\n")
    for k, g in enumerate(gs.blocks):
        t = _node_table(g, gs.frame)
        I, Jn = np.meshgrid(np.arange(g.shape[0]), np.arange(g.shape[1]), indexing="ij")
        cols = [np.full(g.x.size, k), I.ravel(), Jn.ravel()]
        vals = np.column_stack([t[c].ravel() for c in list(COLUMNS)[3:]])
        ints = np.column_stack(cols).astype(np.int64)
        for r in range(len(ints)):
            buf.write(f"{ints[r][0]},{ints[r][1]},{ints[r][2]},")
            buf.write(",".join(f"{v:.17g}" for v in vals[r]) + "\n")
    with atomic_path(path) as tmp:
        tmp.write_text(buf.getvalue(), encoding="utf-8")


def read_metrics_csv(path: Path, **_: Any) -> GridSet:
    """Read the grid back from a metrics CSV (coordinates only; metrics are recomputed)."""
    from ..crs import normalize_crs

    text = read_bytes(path).decode("utf-8", errors="replace")
    crs, origin = None, (0.0, 0.0)
    rows = []
    header = None
    for lineno, ln in enumerate(text.splitlines(), 1):
        if ln.startswith("# crs:"):
            v = ln[6:].strip()
            crs = None if v == "unknown" else normalize_crs(v)
        elif ln.startswith("# origin:"):
            o = ln[9:].split()
            origin = (float(o[0]), float(o[1]))
        elif ln.startswith("#") or not ln.strip():
            continue
        elif header is None:
            header = [h.strip() for h in ln.split(",")]
            if header[:5] != ["block", "i", "j", "x", "y"]:
                raise ReadError(f"{path}: line {lineno}: not a meshcore metrics CSV header")
        else:
            v = ln.split(",")
            if len(v) != len(header):
                raise ReadError(f"{path}: line {lineno}: {len(v)} values, header has {len(header)}")
            try:
                rows.append((int(v[0]), int(v[1]), int(v[2]), float(v[3]), float(v[4])))
            except ValueError:
                raise ReadError(f"{path}: line {lineno}: not a number") from None
    if not rows:
        raise ReadError(f"{path}: no data rows")
    a = np.array(rows)
    blocks = []
    for b in np.unique(a[:, 0]).astype(int):
        r = a[a[:, 0] == b]
        ni, nj = int(r[:, 1].max()) + 1, int(r[:, 2].max()) + 1
        if len(r) != ni * nj:
            raise ReadError(f"{path}: block {b} has {len(r)} rows, expected {ni} x {nj}")
        X = np.full((ni, nj), np.nan)
        Y = np.full((ni, nj), np.nan)
        X[r[:, 1].astype(int), r[:, 2].astype(int)] = r[:, 3]
        Y[r[:, 1].astype(int), r[:, 2].astype(int)] = r[:, 4]
        if np.isnan(X).any():
            raise ReadError(f"{path}: block {b} has missing nodes")
        blocks.append(StructuredGrid(X - origin[0], Y - origin[1]))
    return GridSet(tuple(blocks), Frame(crs, origin), source=str(path))


def write_npz(path: Path, gs: GridSet, **_: Any) -> None:
    """Write coordinates and metrics of every block to a NumPy ``.npz``."""
    arrays: dict[str, Any] = {}
    for k, g in enumerate(gs.blocks):
        for name, v in _node_table(g, gs.frame).items():
            arrays[f"b{k}_{name}"] = v
    arrays["crs"] = np.array(gs.frame.crs or "")
    arrays["origin"] = np.array(gs.frame.origin, dtype=np.float64)
    arrays["block_names"] = np.array(json.dumps(list(gs.block_names)))
    arrays["border_names"] = np.array(json.dumps([dict(g.names) for g in gs.blocks]))
    arrays["columns"] = np.array(json.dumps(COLUMNS))
    with atomic_path(path) as tmp, open(tmp, "wb") as f:
        np.savez(f, **arrays)


def read_npz(path: Path, **_: Any) -> GridSet:
    """Read a ``.npz`` written by :func:`write_npz` (or any with ``x``/``y`` arrays)."""
    try:
        z = np.load(io.BytesIO(read_bytes(path)), allow_pickle=False)
    except (ValueError, OSError, zipfile.BadZipFile, EOFError) as exc:
        raise ReadError(f"{path}: not a valid .npz ({exc})") from None
    with z:
        keys = set(z.files)
        origin = tuple(float(v) for v in z["origin"]) if "origin" in keys else (0.0, 0.0)
        crs = str(z["crs"]) if "crs" in keys and str(z["crs"]) else None
        if "x" in keys and "y" in keys:
            pairs = [("x", "y")]
        else:
            n = 0
            while f"b{n}_x" in keys:
                n += 1
            pairs = [(f"b{k}_x", f"b{k}_y") for k in range(n)]
        if not pairs:
            raise ReadError(f"{path}: no x/y arrays (keys: {sorted(keys)[:10]})")
        bnames = [{} for _ in pairs]
        if "border_names" in keys:
            try:
                bnames = json.loads(str(z["border_names"]))
            except json.JSONDecodeError:
                raise ReadError(f"{path}: border_names is not JSON") from None
        names = ()
        if "block_names" in keys:
            try:
                names = tuple(json.loads(str(z["block_names"])))
            except json.JSONDecodeError:
                raise ReadError(f"{path}: block_names is not JSON") from None
        blocks = []
        for k, (kx, ky) in enumerate(pairs):
            X = np.asarray(z[kx], dtype=np.float64)
            Y = np.asarray(z[ky], dtype=np.float64)
            bn = bnames[k] if k < len(bnames) and isinstance(bnames[k], dict) else {}
            blocks.append(StructuredGrid(X - origin[0], Y - origin[1], names=bn))
    if len(names) != len(blocks):
        names = ()
    return GridSet(tuple(blocks), Frame(crs, origin), names, source=str(path))
