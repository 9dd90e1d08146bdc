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

from .._validation import check_allocation, max_nodes
from ..crs import Frame
from ..errors import ReadError
from ..grid import BORDER_NAMES, StructuredGrid
from ..metrics import METRIC_FIELDS, metrics
from ._base import GridSet, atomic_path, border_names, grid_from_world, read_bytes

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


def _node_table(g: StructuredGrid, frame: Frame) -> dict[str, np.ndarray]:
    m = metrics(g).as_dict()
    X, Y = frame.to_world(g.x, g.y)
    out = {"x": X, "y": Y}
    for k in METRIC_FIELDS:
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
    # the names once more, machine-readable (any characters survive): read back by read_metrics_csv
    lines.append("# block_names: " + json.dumps(list(gs.block_names), ensure_ascii=True))
    lines.append("# border_names: " + json.dumps([dict(g.names) for g in gs.blocks], ensure_ascii=True))
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


def _json_comment(path: Path, lineno: int, text: str, kind: type) -> Any:
    try:
        v = json.loads(text)
    except (json.JSONDecodeError, RecursionError):
        raise ReadError(f"{path}: line {lineno}: not a JSON list ({text[:40]!r})") from None
    if not isinstance(v, list) or not all(isinstance(t, kind) for t in v):
        raise ReadError(f"{path}: line {lineno}: expected a JSON list of {kind.__name__}")
    return v


def read_metrics_csv(path: Path, **_: Any) -> GridSet:
    """Read the grid back from a metrics CSV (coordinates, CRS, origin, block and border names).

    One pass over the lines into preallocated arrays (the number of data lines
    is checked against the node limit first); metrics are not read (they are
    recomputed from the coordinates).
    """
    from ..crs import normalize_crs

    text = read_bytes(path).decode("utf-8", errors="replace")
    check_allocation(
        text.count("\n"), max_nodes(), what=f"{path}: lines (one per node)", env="MESHCORE_MAX_NODES", error=ReadError
    )
    crs, origin = None, (0.0, 0.0)
    block_names: list = []
    bnames: list = []
    header = None
    n_rows = 0
    ints = np.empty((text.count("\n") + 1, 3), dtype=np.int64)
    xy = np.empty((len(ints), 2))
    for lineno, ln in enumerate(io.StringIO(text), 1):
        if ln.startswith("#"):
            if ln.startswith("# crs:"):
                v = ln[6:].strip()
                crs = None if v == "unknown" else normalize_crs(v)
            elif ln.startswith("# origin:"):
                try:
                    o = ln[9:].split()
                    origin = (float(o[0]), float(o[1]))
                except (IndexError, ValueError):
                    raise ReadError(f"{path}: line {lineno}: the origin is not two numbers") from None
            elif ln.startswith("# block_names:"):
                block_names = _json_comment(path, lineno, ln[14:], str)
            elif ln.startswith("# border_names:"):
                bnames = _json_comment(path, lineno, ln[15:], dict)
            continue
        if not ln.strip():
            continue
        if header is None:
            header = [h.strip() for h in ln.split(",")]
            if header[:5] != ["block", "i", "j", "x", "y"]:
                raise ReadError(f"{path}: line {lineno}: not a meshcore metrics CSV header")
            continue
        v = ln.split(",", 5)
        if len(v) < 5 or (len(header) > 5 and len(v) != 6) or (len(v) == 6 and v[5].count(",") != len(header) - 6):
            raise ReadError(f"{path}: line {lineno}: {ln.count(',') + 1} values, header has {len(header)}")
        try:
            ints[n_rows] = (int(v[0]), int(v[1]), int(v[2]))
            xy[n_rows] = (float(v[3]), float(v[4]))
        except (ValueError, OverflowError):
            raise ReadError(f"{path}: line {lineno}: not a number") from None
        n_rows += 1
    if not n_rows:
        raise ReadError(f"{path}: no data rows")
    ints, xy = ints[:n_rows], xy[:n_rows]
    if (ints < 0).any():
        raise ReadError(f"{path}: line of row {int(np.argmax((ints < 0).any(axis=1))) + 1}: negative block/i/j")
    blocks = []
    for b in np.unique(ints[:, 0]).tolist():
        sel = ints[:, 0] == b
        r, c = ints[sel], xy[sel]
        ni, nj = int(r[:, 1].max()) + 1, int(r[:, 2].max()) + 1
        if len(r) != ni * nj:
            raise ReadError(f"{path}: block {b} has {len(r)} rows, expected {ni} x {nj}")
        X = np.full((ni, nj), np.nan)
        Y = np.full((ni, nj), np.nan)
        X[r[:, 1], r[:, 2]] = c[:, 0]
        Y[r[:, 1], r[:, 2]] = c[:, 1]
        seen = np.zeros((ni, nj), dtype=bool)
        seen[r[:, 1], r[:, 2]] = True
        if not seen.all():
            raise ReadError(f"{path}: block {b} has missing nodes (repeated i, j rows)")
        names = bnames[len(blocks)] if len(blocks) < len(bnames) else {}
        names = {k: str(v) for k, v in names.items() if k in BORDER_NAMES}
        blocks.append(grid_from_world(X, Y, origin, path, f"block {b}", names))
    names_t = tuple(block_names) if len(block_names) == len(blocks) else ()
    return GridSet(tuple(blocks), Frame(crs, origin), names_t, source=str(path))


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
        inflated = {i.filename.removesuffix(".npy"): i.file_size for i in z.zip.infolist()}
        for key in keys:
            if key not in ("x", "y") and not (key.startswith("b") and key[1:2].isdigit()) and inflated[key] > 2**20:
                raise ReadError(f"{path}: refused: the entry {key!r} inflates to more than 1 MiB")
        origin = tuple(float(v) for v in np.asarray(z["origin"]).reshape(-1)[:2]) if "origin" in keys else (0.0, 0.0)
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
        bnames: Any = [{} for _ in pairs]
        if "border_names" in keys:
            try:
                bnames = json.loads(str(z["border_names"]))
            except (json.JSONDecodeError, RecursionError):
                raise ReadError(f"{path}: border_names is not JSON") from None
        if not isinstance(bnames, list):
            bnames = []
        names: tuple = ()
        if "block_names" in keys:
            try:
                names = json.loads(str(z["block_names"]))
            except (json.JSONDecodeError, RecursionError):
                raise ReadError(f"{path}: block_names is not JSON") from None
            names = tuple(names) if isinstance(names, list) and all(isinstance(t, str) for t in names) else ()
        blocks = []
        total = 0
        for k, (kx, ky) in enumerate(pairs):
            for key in (kx, ky):  # the inflated size, from the zip directory, before inflating
                total += inflated[key]
            check_allocation(
                total,
                16 * max_nodes() + 4096 * len(pairs),
                what=f"{path}: inflated bytes of x/y",
                env="MESHCORE_MAX_NODES",
                error=ReadError,
            )
            X = np.asarray(z[kx], dtype=np.float64)
            Y = np.asarray(z[ky], dtype=np.float64)
            bn = bnames[k] if k < len(bnames) and isinstance(bnames[k], dict) else {}
            bn = {b: str(v) for b, v in bn.items() if b in BORDER_NAMES}
            blocks.append(grid_from_world(X, Y, origin, path, f"block {k}", bn))
    if len(names) != len(blocks):
        names = ()
    return GridSet(tuple(blocks), Frame(crs, origin), names, source=str(path))
