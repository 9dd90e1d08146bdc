"""Lakes with many polygonal islands: :func:`archipelago` (re-exported by :mod:`meshcore.testing`)."""

from __future__ import annotations

import math

import numpy as np

from ._shapes import _clean, _lobed_disc, _placed


def archipelago(
    seed: int,
    *,
    n_islands: int = 20,
    radius: float = 10.0,
    target_cells: int = 10_000,
    widths: tuple[float, float] = (1.0, 6.0),
):
    """A round lake with ``n_islands`` polygonal islands ``widths`` cells across at ``target_cells``.

    The many-island lakes real outlines bring (a lake of skerries, a drowned hilly landscape):
    each island is a 5–8-gon with jittered vertices (corners of 60–140°, a few cells across;
    log-uniform widths in cells of ``sqrt(area / target_cells)``).  A third lie 0.5–3 cells from
    the shore, a third as far from an island placed before them (narrow passages), the rest
    anywhere; no two closer than half a cell.
    """
    from shapely import affinity
    from shapely.geometry import Polygon

    rng = np.random.default_rng(seed)
    outer = _lobed_disc(rng, radius, 240, range(2, 5), 0.15)
    h = math.sqrt(outer.area / target_cells)
    body = outer.buffer(-0.5 * h)
    holes: list[Polygon] = []
    tries = 0
    while len(holes) < n_islands and tries < 4000:
        tries += 1
        w = h * math.exp(rng.uniform(math.log(widths[0]), math.log(widths[1])))
        k = int(rng.integers(5, 9))
        a = 2 * math.pi * (np.arange(k) + rng.uniform(-0.3, 0.3, k)) / k
        rr = 0.5 * w * rng.uniform(0.75, 1.0, k)
        isl = Polygon(np.column_stack([rr * np.cos(a), rr * np.sin(a)]))
        isl = affinity.scale(isl, rng.uniform(1.0, 1.6), 1.0)
        isl = _placed(
            rng,
            isl,
            outer,
            body,
            holes,
            radius,
            h=h,
            gaps=(0.5, 3.0),
            shore=0.6 * w,
            near=(0.5, 0.5 * w),
            any_before=True,
        )
        if isl is not None and not any(isl.distance(o) < 0.5 * h for o in holes):
            holes.append(isl)
    return _clean(Polygon(outer.exterior, [g.exterior for g in holes]))


def island_clusters(
    seed: int,
    *,
    n_islands: int = 120,
    clusters: int = 8,
    radius: float = 10.0,
    target_cells: int = 10_000,
    widths: tuple[float, float] = (0.7, 8.0),
    gaps: tuple[float, float] = (0.3, 5.0),
):
    """A round lake whose ``n_islands`` islands lie in ``clusters`` clusters, half of them at the shore.

    The islands of a drowned hilly landscape (Finnish, Swedish, Canadian lakes): groups of
    skerries a few cells apart rather than islands spread evenly.  Each island is a 5–9-gon
    with jittered vertices, ``widths`` cells across (log-uniform, cells of
    ``sqrt(area / target_cells)``); each is placed ``gaps`` cells (uniform) from an island of its
    cluster drawn before it, or, for the first of a shore cluster and a fifth of its islands,
    that far from the shore.  No two islands closer than ``gaps[0]`` cells, none closer to the
    shore than that.  Fewer islands when no place is found in 60 tries per island.
    """
    from shapely import affinity
    from shapely.geometry import Polygon

    rng = np.random.default_rng(seed)
    outer = _lobed_disc(rng, radius, 240, range(2, 5), 0.15)
    h = math.sqrt(outer.area / target_cells)
    ring = outer.exterior
    holes: list[Polygon] = []
    members: list[list[Polygon]] = [[] for _ in range(clusters)]
    at_shore = [k % 2 == 0 for k in range(clusters)]
    centre = [np.asarray(outer.representative_point().coords[0])] * clusters
    for k in range(clusters):
        if not at_shore[k]:
            for _ in range(50):
                c = rng.uniform(-0.7 * radius, 0.7 * radius, 2)
                if outer.buffer(-0.2 * radius).contains(Polygon([c, c + 1e-6, c + [0, 1e-6]])):
                    centre[k] = c
                    break
    for n in range(n_islands):
        k = n % clusters
        for _ in range(60):
            w = h * math.exp(rng.uniform(math.log(widths[0]), math.log(widths[1])))
            m = int(rng.integers(5, 10))
            a = 2 * math.pi * (np.arange(m) + rng.uniform(-0.3, 0.3, m)) / m
            rr = 0.5 * w * rng.uniform(0.7, 1.0, m)
            isl = affinity.scale(Polygon(np.column_stack([rr * np.cos(a), rr * np.sin(a)])), rng.uniform(1.0, 1.8), 1.0)
            isl = affinity.rotate(isl, rng.uniform(0, 360), origin=(0, 0))
            far = max(np.hypot(*np.asarray(isl.exterior.coords).T))  # its centre to its farthest corner
            gap = h * rng.uniform(*gaps)
            if members[k] and not (at_shore[k] and rng.uniform() < 0.2):
                prev = members[k][int(rng.integers(0, len(members[k])))]
                pc = np.asarray(prev.centroid.coords[0])
                pr = max(np.hypot(*(np.asarray(prev.exterior.coords) - pc).T))
                t = rng.uniform(0, 2 * math.pi)
                c = pc + (pr + far + gap) * np.array([math.cos(t), math.sin(t)])
            elif at_shore[k]:
                if not members[k]:
                    centre[k] = np.asarray(ring.interpolate(rng.uniform(0, ring.length)).coords[0])
                p = np.asarray(ring.interpolate(ring.project(_point(centre[k] + rng.normal(0, 6 * h, 2)))).coords[0])
                c = p * (1.0 - (gap + far) / max(np.hypot(*p), 1e-9))
            else:
                c = centre[k] + rng.normal(0, 2 * h, 2)
            isl = affinity.translate(isl, *c)
            if not isl.is_valid or not outer.buffer(-gaps[0] * h).contains(isl):
                continue
            if any(isl.distance(o) < gaps[0] * h for o in holes):
                continue
            holes.append(isl)
            members[k].append(isl)
            break
    return _clean(Polygon(outer.exterior, [g.exterior for g in holes]))


def _point(xy):
    from shapely.geometry import Point

    return Point(float(xy[0]), float(xy[1]))
