"""DXF drawings (ezdxf): LWPOLYLINE, POLYLINE (2-D/3-D, x and y used) and SPLINE.

Each entity of the model space becomes a polyline named ``"<layer> <handle>"``;
splines are flattened to within ``sagitta`` drawing units (default 1e-3 of the
drawing's extent, control and fit points included), at most
:data:`SPLINE_MAX_POINTS` points per spline.  DXF carries no CRS, so the CRS is unknown (None) unless
given.
"""

from __future__ import annotations

import itertools
import math
from pathlib import Path
from typing import Any

import numpy as np

from .._validation import check_allocation, max_bytes, max_points, validate_positive
from ..crs import normalize_crs
from ..errors import ReadError
from ._base import PointSet, Polyline, make_polyline

__all__ = ["SPLINE_MAX_POINTS", "read_points_dxf"]

#: Most points one spline may flatten to (a larger ``sagitta`` gives fewer).
SPLINE_MAX_POINTS = 200_000


def read_points_dxf(path: Path, *, crs: Any = None, sagitta: float | None = None, **_: Any) -> PointSet:
    """Read polylines and splines from the model space of a DXF file."""
    try:
        import ezdxf
        from ezdxf.lldxf.const import DXFError
    except ImportError as exc:  # pragma: no cover
        raise ReadError(f"{path}: reading DXF needs ezdxf (pip install ezdxf)") from exc
    if not path.exists():
        raise ReadError(f"{path}: no such file")
    if path.stat().st_size == 0:
        raise ReadError(f"{path}: file is empty")
    check_allocation(
        path.stat().st_size, max_bytes(), what=f"{path}: file size in bytes", env="MESHCORE_MAX_BYTES", error=ReadError
    )
    try:
        with open(path, "rb") as f:
            bom = f.read(3) == b"\xef\xbb\xbf"  # ezdxf.readfile: "not a DXF file"
        if bom:
            import io

            doc = ezdxf.read(io.StringIO(path.read_bytes()[3:].decode("utf-8", errors="replace")))
        else:
            doc = ezdxf.readfile(str(path))
    except (DXFError, OSError, UnicodeDecodeError, ValueError) as exc:
        raise ReadError(f"{path}: not a valid DXF file ({type(exc).__name__}: {exc})") from None
    msp = doc.modelspace()
    raw: list[tuple[str, np.ndarray, bool | None, Any]] = []
    for e in msp:
        kind = e.dxftype()
        label = f"{e.dxf.get('layer', '0')} {e.dxf.handle}"
        where = f"{path}: {kind} {e.dxf.handle} on layer {e.dxf.get('layer', '0')}"
        if kind == "LWPOLYLINE":
            pts = np.array([(p[0], p[1]) for p in e.get_points("xy")], dtype=np.float64)
            raw.append((label, pts, bool(e.closed) or None, where))
        elif kind == "POLYLINE":
            if e.is_poly_face_mesh or e.is_polygon_mesh:
                continue
            pts = np.array([(v.dxf.location[0], v.dxf.location[1]) for v in e.vertices], dtype=np.float64)
            raw.append((label, pts, bool(e.is_closed) or None, where))
        elif kind == "SPLINE":
            raw.append((label, e, None, where))
    if not raw:
        raise ReadError(f"{path}: no LWPOLYLINE, POLYLINE or SPLINE entities in the model space")
    # flatten splines with a tolerance relative to the extent of everything (control
    # points and fit points included: a spline given by fit points alone has no control points)
    fixed = [r[1] for r in raw if isinstance(r[1], np.ndarray) and len(r[1])]
    for r in raw:
        if not isinstance(r[1], np.ndarray):
            for pts in (r[1].control_points, r[1].fit_points):
                cps = np.array([(p[0], p[1]) for p in pts], dtype=np.float64).reshape(-1, 2)
                if len(cps):
                    fixed.append(cps)
    allp = np.vstack(fixed) if fixed else np.zeros((1, 2))
    finite = allp[np.isfinite(allp).all(axis=1)]
    ext = float(np.hypot(*(finite.max(axis=0) - finite.min(axis=0)))) if len(finite) else 1.0
    ext = ext if math.isfinite(ext) and ext > 0 else 1.0
    tol = validate_positive(sagitta, name="sagitta") if sagitta is not None else 1e-3 * ext
    tol = max(tol, 1e-9 * ext)
    cap = min(max_points(), SPLINE_MAX_POINTS)
    out: list[Polyline] = []
    total = 0
    for label, obj, closed, where in raw:
        if isinstance(obj, np.ndarray):
            pts = obj
        else:
            try:
                flat = list(itertools.islice(obj.flattening(tol), cap + 1))
            except (DXFError, ValueError, ZeroDivisionError, IndexError, ArithmeticError) as exc:
                raise ReadError(f"{where}: cannot evaluate the spline ({exc})") from None
            if len(flat) > cap:
                raise ReadError(
                    f"{where}: the spline flattens to more than {cap:,} points at a sagitta of {tol:.3g} "
                    f"drawing units; give a larger sagitta"
                )
            pts = np.array([(v[0], v[1]) for v in flat], dtype=np.float64).reshape(-1, 2)
            closed = bool(obj.closed) or None
        if len(pts) < 2:
            raise ReadError(f"{where}: fewer than 2 points")
        total += len(pts)
        check_allocation(total, max_points(), what=f"{path}: points", env="MESHCORE_MAX_POINTS", error=ReadError)
        out.append(make_polyline(label, pts, closed=closed, where=where))
    return PointSet(tuple(out), normalize_crs(crs) if crs is not None else None, str(path))
