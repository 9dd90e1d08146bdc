"""Border geometry for grid control: differences, border rows and tangents, measured angles and spacings."""

from __future__ import annotations

from collections.abc import Iterable, Mapping

import numpy as np

from ..grid import BORDER_NAMES, StructuredGrid

__all__ = ["border_angles", "boundary_report", "first_spacing"]

# border -> (sigma: +1 if the interior is at increasing normal index,
#            rho: rotation sign from the tangent into the interior,
#            along: "xi" if the border runs along ξ)
_FRAME = {
    "bottom": (1, 1, "xi"),
    "top": (-1, -1, "xi"),
    "left": (1, -1, "eta"),
    "right": (-1, 1, "eta"),
}


def _d_xi(a: np.ndarray, periodic: bool) -> np.ndarray:
    """Central ξ difference on all nodes; one-sided 2nd order at non-periodic ends."""
    d = np.empty_like(a)
    d[1:-1] = 0.5 * (a[2:] - a[:-2])
    if periodic:
        d[0] = 0.5 * (a[1] - a[-2])
        d[-1] = d[0]
    else:
        d[0] = 0.5 * (-3 * a[0] + 4 * a[1] - a[2]) if len(a) > 2 else a[1] - a[0]
        d[-1] = 0.5 * (3 * a[-1] - 4 * a[-2] + a[-3]) if len(a) > 2 else a[-1] - a[-2]
    return d


def _d_eta(a: np.ndarray) -> np.ndarray:
    return _d_xi(a.T, False).T


def scale_factors(x: np.ndarray, y: np.ndarray, periodic: bool) -> tuple[np.ndarray, np.ndarray]:
    """``α/D²`` and ``γ/D²`` at every node (conversion normalised → kernel sources)."""
    xx, yx = _d_xi(x, periodic), _d_xi(y, periodic)
    xe, ye = _d_eta(x), _d_eta(y)
    a = xe * xe + ye * ye
    g = xx * xx + yx * yx
    d = xx * ye - xe * yx
    with np.errstate(all="ignore"):
        # D² ≥ 10⁻³·αγ (corner angle ≥ ~1.8°): near-degenerate or folded nodes get a
        # bounded source instead of an explosive one
        d2 = np.maximum(d * d, 1e-3 * a * g)
        d2 = np.maximum(d2, 1e-300)
        return a / d2, g / d2


def _rot(vx, vy, ang):
    c, s = np.cos(ang), np.sin(ang)
    return c * vx - s * vy, s * vx + c * vy


def _border_rows(x, y, name):
    """(r0, r1, r2) rows of a border as (k, 2) arrays: the border, 1 and 2 cells in."""
    if name == "bottom":
        rows = (0, 1, 2)
        return [np.column_stack([x[:, j], y[:, j]]) for j in rows]
    if name == "top":
        rows = (-1, -2, -3)
        return [np.column_stack([x[:, j], y[:, j]]) for j in rows]
    if name == "left":
        return [np.column_stack([x[i, :], y[i, :]]) for i in (0, 1, 2)]
    return [np.column_stack([x[i, :], y[i, :]]) for i in (-1, -2, -3)]


def _tangent(r0: np.ndarray, periodic: bool):
    rt = np.column_stack([_d_xi(r0[:, 0], periodic), _d_xi(r0[:, 1], periodic)])
    rtt = np.empty_like(r0)
    rtt[1:-1] = r0[2:] - 2 * r0[1:-1] + r0[:-2]
    if periodic:
        rtt[0] = r0[1] - 2 * r0[0] + r0[-2]
        rtt[-1] = rtt[0]
    else:
        rtt[0] = rtt[1]
        rtt[-1] = rtt[-2]
    return rt, rtt


def border_angles(grid: StructuredGrid, border: str) -> np.ndarray:
    """Angle (degrees) between a border and the grid lines leaving it.

    At each node of ``border`` (corners excluded unless the border is periodic)
    the angle is measured from the border tangent (central difference of the
    border nodes, increasing index) to the first grid segment into the
    interior; 90 means orthogonal.
    """
    per = grid.periodic and border in ("bottom", "top")
    r0, r1, _ = _border_rows(grid.x, grid.y, border)
    rt, _ = _tangent(r0, per)
    d = r1 - r0
    _, rho, _ = _FRAME[border]
    cross = rt[:, 0] * d[:, 1] - rt[:, 1] * d[:, 0]
    dot = (rt * d).sum(axis=1)
    ang = np.degrees(np.arctan2(rho * cross, dot))
    return ang[:-1] if per else ang[1:-1]


def first_spacing(grid: StructuredGrid, border: str) -> np.ndarray:
    """First-cell height ``|r_1 − r_0|`` at the nodes of ``border`` (corners excluded)."""
    per = grid.periodic and border in ("bottom", "top")
    r0, r1, _ = _border_rows(grid.x, grid.y, border)
    s = np.hypot(*(r1 - r0).T)
    return s[:-1] if per else s[1:-1]


def boundary_report(
    grid: StructuredGrid,
    borders: Iterable[str] = BORDER_NAMES,
    spacing: Mapping[str, float] | None = None,
) -> dict[str, float]:
    """Max |angle − 90°| over ``borders`` and max relative spacing error.

    Returns ``{"max_angle_deviation": …, "mean_angle_deviation": …,
    "max_spacing_error": …}`` (spacing error only for borders in ``spacing``).
    """
    devs = []
    errs = []
    for b in borders:
        if grid.periodic and b in ("left", "right"):
            continue
        a = border_angles(grid, b)
        devs.append(np.abs(a - 90.0))
        if spacing and b in spacing and spacing[b] is not None:
            errs.append(np.abs(first_spacing(grid, b) / spacing[b] - 1.0))
    dv = np.concatenate(devs) if devs else np.zeros(1)
    out = {"max_angle_deviation": float(dv.max()), "mean_angle_deviation": float(dv.mean())}
    out["max_spacing_error"] = float(np.concatenate(errs).max()) if errs else float("nan")
    return out


class _Polyline:
    """Arc-length parametrised polyline (optionally closed) with windowed projection."""

    def __init__(self, pts: np.ndarray, closed: bool):
        pts = np.asarray(pts, dtype=np.float64)
        if closed and np.hypot(*(pts[0] - pts[-1])) > 0:
            pts = np.vstack([pts, pts[:1]])
        seg = np.hypot(*np.diff(pts, axis=0).T)
        keep = np.concatenate([[True], seg > 0])
        self.p = pts[keep]
        self.s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(self.p, axis=0).T))])
        self.length = float(self.s[-1])
        self.closed = closed
        if closed:  # three turns, parameters −L … 2L, so windows never wrap
            self.pe = np.vstack([self.p[:-1], self.p[:-1], self.p])
            self.se = np.concatenate([self.s[:-1] - self.length, self.s[:-1], self.s + self.length])
        else:
            self.pe, self.se = self.p, self.s

    def at(self, s: np.ndarray) -> np.ndarray:
        s = np.mod(s, self.length) if self.closed else np.clip(s, 0.0, self.length)
        return np.column_stack([np.interp(s, self.s, self.p[:, 0]), np.interp(s, self.s, self.p[:, 1])])

    def locate(self, q: np.ndarray) -> np.ndarray:
        """Arc-length parameter of the nearest point to each query (global search)."""
        a = self.p[:-1]
        d = np.diff(self.p, axis=0)
        L2 = (d * d).sum(axis=1)
        t = ((q[:, None, :] - a[None]) * d[None]).sum(axis=2) / L2[None]
        t = np.clip(t, 0.0, 1.0)
        foot = a[None] + t[..., None] * d[None]
        dist = ((q[:, None, :] - foot) ** 2).sum(axis=2)
        k = np.argmin(dist, axis=1)
        return self.s[k] + t[np.arange(len(q)), k] * np.sqrt(L2[k])

    def project(self, q: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        """Arc length of the nearest point to ``q[k]`` with parameter in ``[lo[k], hi[k]]``."""
        a = self.pe[:-1]
        d = np.diff(self.pe, axis=0)
        L2 = (d * d).sum(axis=1)
        L = np.sqrt(L2)
        s0 = self.se[:-1]
        t = ((q[:, None, :] - a[None]) * d[None]).sum(axis=2) / L2[None]
        # restrict the foot parameter to the window [lo, hi]
        tlo = (lo[:, None] - s0[None]) / L[None]
        thi = (hi[:, None] - s0[None]) / L[None]
        tmin = np.maximum(tlo, 0.0)
        tmax = np.minimum(thi, 1.0)
        valid = tmin <= tmax
        t = np.clip(t, tmin, np.where(valid, tmax, tmin))
        foot = a[None] + t[..., None] * d[None]
        dist = ((q[:, None, :] - foot) ** 2).sum(axis=2)
        dist = np.where(valid, dist, np.inf)
        k = np.argmin(dist, axis=1)
        return s0[k] + t[np.arange(len(q)), k] * L[k]


def _corner_angle(x, y, name, end) -> float:
    """Interior angle (radians) of the block at the corner where ``name`` has node ``end``."""
    r0 = _border_rows(x, y, name)[0]
    c = r0[end]
    a = r0[1] if end == 0 else r0[-2]
    # the other border leaving the same corner
    ni, nj = x.shape[0] - 1, x.shape[1] - 1
    i, j = {
        ("bottom", 0): (0, 0),
        ("bottom", 1): (ni, 0),
        ("top", 0): (0, nj),
        ("top", 1): (ni, nj),
        ("left", 0): (0, 0),
        ("left", 1): (0, nj),
        ("right", 0): (ni, 0),
        ("right", 1): (ni, nj),
    }[(name, 0 if end == 0 else 1)]
    if name in ("bottom", "top"):
        b = np.array([x[i, 1 if j == 0 else nj - 1], y[i, 1 if j == 0 else nj - 1]])
    else:
        b = np.array([x[1 if i == 0 else ni - 1, j], y[1 if i == 0 else ni - 1, j]])
    u, v = a - c, b - c
    return float(np.arccos(np.clip(np.dot(u, v) / (np.hypot(*u) * np.hypot(*v)), -1.0, 1.0)))


def _set_border(x, y, name, ks, pts):
    if name == "bottom":
        x[ks, 0], y[ks, 0] = pts[:, 0], pts[:, 1]
    elif name == "top":
        x[ks, -1], y[ks, -1] = pts[:, 0], pts[:, 1]
    elif name == "left":
        x[0, ks], y[0, ks] = pts[:, 0], pts[:, 1]
    else:
        x[-1, ks], y[-1, ks] = pts[:, 0], pts[:, 1]
