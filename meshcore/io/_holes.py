"""A polygon's hole rings must lie in its outer ring: checked where a reader knows which is which.

GeoJSON interior rings and KML ``innerBoundaryIs`` rings are islands of the water.  A hole lying
wholly outside its outer ring (a digitising slip, rings from another polygon pasted in) was read
as one more ring among the file's rings, and a lake reader then took it for a second part of the
water and meshed it as one (``meshcore mesh``: "2 separate parts of water").  The file says it is
a hole: a clear error naming the file, the polygon, the ring and its first point is better.
A hole partly outside is named with its first point outside; one whose points all lie inside but
whose edges cross the outer ring is left to the lake's own check (it names the place).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..errors import ReadError

__all__ = ["check_holes_inside"]


def check_holes_inside(outer: np.ndarray, holes: Sequence[tuple[str, np.ndarray]], where: str, outer_name: str) -> None:
    """Raise :class:`~meshcore.errors.ReadError` for the first hole with a point outside ``outer``.

    ``holes``: ``(what, points)`` per hole ring, ``what`` naming it as the file does (e.g.
    ``"innerBoundaryIs ring 1 ('lake hole 1')"``); ``where`` the file and polygon.
    """
    import shapely
    from shapely.geometry import Polygon

    outer = np.asarray(outer, float).reshape(-1, 2)
    if len(outer) < 3 or not holes:
        return
    try:
        shell = Polygon(outer)
        shell = shell if shell.is_valid else shell.buffer(0)
    except (ValueError, shapely.errors.GEOSException):  # the lake's checks name a broken ring
        return
    if shell.is_empty:
        return
    shapely.prepare(shell)
    tol = 1e-9 * float(np.ptp(outer, axis=0).max())
    for what, pts in holes:
        pts = np.asarray(pts, float).reshape(-1, 2)
        on = shapely.intersects_xy(shell, pts[:, 0], pts[:, 1]) if len(pts) >= 3 else np.ones(len(pts), bool)
        if not on.all():  # a point on the outer ring to rounding (8.552 on the line from 8.55 to 8.56) is on it
            on[~on] = shapely.distance(shell, shapely.points(pts[~on])) <= tol
        if on.all():
            continue
        if on.any():  # partly outside: the first point outside, numbered from 1 as the file has them
            k = int(np.argmin(on))
            raise ReadError(
                f"{where}: {what} crosses its {outer_name}: its point {k + 1} of {len(pts)} at "
                f"({pts[k, 0]:.8g}, {pts[k, 1]:.8g}) lies outside it — a hole (an island) must lie inside the "
                f"outer ring, clear of it (an island that reaches the land is part of the shore)"
            )
        try:
            encloses = Polygon(pts).buffer(0).contains(shell.representative_point())
        except (ValueError, shapely.errors.GEOSException):
            encloses = False
        how = (
            f"encloses its {outer_name} (every point of it outside that ring: are the two swapped?)"
            if encloses
            else f"lies wholly outside its {outer_name}"
        )
        raise ReadError(
            f"{where}: {what}, from its point 1 at ({pts[0, 0]:.8g}, {pts[0, 1]:.8g}), {how} — a hole (an "
            f"island) must lie inside the outer ring; water of its own is a polygon of its own"
        )
