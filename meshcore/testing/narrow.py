"""Reservoirs of many narrow arms: :func:`narrow_arms` (re-exported by :mod:`meshcore.testing`)."""

from __future__ import annotations

import math

import numpy as np

from ._shapes import _clean


def _arm(pts: np.ndarray, half: np.ndarray):
    """The polygon of a centre line ``pts`` with half-widths ``half`` (0 at a wedge's tip)."""
    from shapely.geometry import Polygon

    d = np.diff(pts, axis=0)
    d /= np.linalg.norm(d, axis=1)[:, None]
    t = np.vstack([d[:1], d[:-1] + d[1:], d[-1:]])
    t /= np.linalg.norm(t, axis=1)[:, None]
    n = np.column_stack([-t[:, 1], t[:, 0]])
    left = pts + n * half[:, None]
    right = pts - n * half[:, None]
    ring = np.vstack([left, right[::-1]])
    return Polygon(ring).buffer(0)


def narrow_arms(
    seed: int,
    *,
    target_cells: int = 15_000,
    widths: tuple[float, float] = (3.0, 6.0),
    length: tuple[float, float] = (25.0, 70.0),
    taper: tuple[float, float] = (1.0, 4.0),
    depth: int = 8,
    gap: float = 3.0,
):
    """A dendritic reservoir of arms ``widths`` cells wide at ``target_cells`` meeting at junctions.

    The reservoirs where lake grids missed their targets on unseen lakes: a tree of arms 3–6 cells
    across (cells of ``sqrt(area / target_cells)``), each ``length`` cells long in 3 bent
    pieces, meeting 3 or 4 at a junction (2–3 arms leave the end of an arm, at 35–160° from its
    heading either way, at least 40° apart), the ends of the last ones wedges tapering to a
    point over ``taper`` times their width (tips of 14–53°).  No arm comes within ``gap`` cells
    of another one away from its junction (an arm that would is tried at up to 8 other
    headings); the tree grows breadth first (at most ``depth`` arms from the first junction,
    30 % of the arms ending early while four others are open) until the water holds 80 % of
    ``target_cells`` cells, then is scaled so that it holds them exactly: twice the area over
    the perimeter is 3.8–6.1 cells on seeds 770000–770008 (4.3–4.8 on most); arms that close a
    loop leave an island.
    """
    import shapely
    from shapely import affinity
    from shapely.geometry import Point

    rng = np.random.default_rng(seed)
    pieces: list = []
    todo: list[tuple[np.ndarray, float, int, int]] = []
    h0 = rng.uniform(0, 2 * math.pi)
    for k in range(int(rng.integers(3, 5))):
        todo.append((np.zeros(2), h0 + k * 2 * math.pi / 3 + rng.uniform(-0.4, 0.4), 1, 0))
    area = 0.0
    while todo:
        start, heading, level, tries = todo.pop(0)
        w = rng.uniform(*widths)
        end = level >= depth or area > 0.8 * target_cells or (level > 1 and len(todo) >= 4 and rng.uniform() < 0.3)
        L = rng.uniform(*length)
        ang = heading
        pts = [start]
        for _ in range(3):
            ang += math.radians(rng.uniform(-20.0, 20.0))
            pts.append(pts[-1] + (L / 3) * np.array([math.cos(ang), math.sin(ang)]))
        line = np.asarray(shapely.LineString(pts).segmentize(1.0).coords)
        s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(line, axis=0), axis=1))])
        half = np.full(len(s), 0.5 * w)
        if end:
            tl = min(rng.uniform(*taper) * w, 0.8 * s[-1])
            half = 0.5 * w * np.clip((s[-1] - s) / tl, 0.0, 1.0)
        arm = _arm(line, half)
        if not end:
            arm = arm.union(Point(line[-1]).buffer(0.5 * w, quad_segs=8))
        away = arm.difference(Point(start).buffer(2.5 * widths[1]))
        if pieces and shapely.union_all(pieces).difference(Point(start).buffer(2.5 * widths[1])).distance(away) < gap:
            if tries < 8:  # another heading: the water grows until it holds its cells
                todo.append((start, heading + math.radians(rng.uniform(-60.0, 60.0)), level, tries + 1))
            continue
        pieces.append(arm)
        area = shapely.union_all(pieces).area
        if end:
            continue
        n = int(rng.integers(2, 4))
        taken: list[float] = []
        for _ in range(20):
            if len(taken) == n:
                break
            a = math.radians(rng.uniform(35.0, 160.0)) * (1 if rng.uniform() < 0.5 else -1)
            if all(abs(a - b) > math.radians(40.0) for b in taken):
                taken.append(a)
        for a in taken:
            todo.append((line[-1], ang + a, level + 1, 0))
    water = _clean(shapely.union_all(pieces).buffer(0.05, quad_segs=2).buffer(-0.05, quad_segs=2))
    f = math.sqrt(target_cells / water.area)
    return affinity.scale(water, f / 100.0, f / 100.0, origin=(0, 0))
