"""Pieces the generators of :mod:`meshcore.testing` share: a valid polygon, a lobed disc, an island placed."""

from __future__ import annotations

import math

import numpy as np


def _clean(poly, min_hole_area: float = 0.0):
    """The largest valid polygon part, oriented (outer CCW), small holes dropped."""
    import shapely
    from shapely.geometry import Polygon
    from shapely.geometry.polygon import orient

    poly = shapely.make_valid(poly)
    parts = [g for g in getattr(poly, "geoms", [poly]) if g.geom_type == "Polygon" and g.area > 0]
    if not parts:
        raise ValueError("empty shape")
    p = max(parts, key=lambda g: g.area)
    holes = [h for h in p.interiors if Polygon(h).area > min_hole_area]
    out = Polygon(p.exterior, holes)
    if not out.is_valid:  # an island left touching the shore: joined to it
        out = max(getattr(g := out.buffer(0), "geoms", [g]), key=lambda g: g.area)
    return orient(out, 1.0)


def _lobed_disc(rng, radius: float, points: int, lobes, amplitude: float):
    """A disc whose farthest point is ``radius`` from the origin, its radius modulated by the
    harmonics ``k`` of ``lobes`` with random phases and amplitudes up to ``amplitude / sqrt(k)``
    (drawn from ``rng`` in that order), as a polygon of ``points`` vertices."""
    from shapely.geometry import Polygon

    t = np.linspace(0, 2 * math.pi, points, endpoint=False)
    r = np.ones_like(t)
    for k in lobes:
        r += rng.uniform(0.0, amplitude / k**0.5) * np.cos(k * t + rng.uniform(0, 2 * math.pi))
    r *= radius / r.max()
    return Polygon(np.column_stack([r * np.cos(t), r * np.sin(t)]))


def _placed(
    rng, isl, outer, body, holes, radius: float, *, h: float, gaps, shore: float, near, any_before: bool = False
):
    """The island shape ``isl`` (centred on the origin) turned at random and put, a third of the
    time each, near the shore (its centre ``gap + shore`` in from a shore point), near an island
    placed before (``near[0] · sqrt(area) + gap + near[1]`` from its centre: the last one, or
    any with ``any_before``) or anywhere within ``radius``; ``gap`` uniform in ``gaps`` cells of ``h``.  None
    when it does not lie inside ``body`` (the water away from the shore)."""
    from shapely import affinity

    isl = affinity.rotate(isl, rng.uniform(0, 360), origin=(0, 0))
    where = rng.uniform()
    gap = h * rng.uniform(*gaps)
    if where < 1 / 3:  # near the shore
        p = np.asarray(outer.exterior.interpolate(rng.uniform(0, outer.exterior.length)).coords[0])
        c = p * (1.0 - (gap + shore) / max(np.hypot(*p), 1e-9))
    elif where < 2 / 3 and holes:  # near an island placed before
        prev = holes[int(rng.integers(0, len(holes)))] if any_before else holes[-1]
        a = rng.uniform(0, 2 * math.pi)
        d = np.array([math.cos(a), math.sin(a)])
        c = np.asarray(prev.centroid.coords[0]) + d * (near[0] * math.sqrt(prev.area) + gap + near[1])
    else:
        c = rng.uniform(-radius, radius, 2)
    isl = affinity.translate(isl, *c)
    return isl if isl.is_valid and body.contains(isl) else None
