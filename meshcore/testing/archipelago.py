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
