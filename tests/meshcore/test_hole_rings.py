"""A polygon's hole ring lying outside its outer ring (GeoJSON interior ring, KML innerBoundaryIs):
a read error naming the file, the polygon, the ring and its first point — it was read as one more
ring, and ``meshcore mesh`` meshed it as a second part of the water."""

from __future__ import annotations

import json

import numpy as np
import pytest

from meshcore.errors import ReadError
from meshcore.io import read_points


def _ring(cx, cy, r, n=24):
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    p = np.c_[cx + r * np.cos(t), cy + r * np.sin(t)]
    return np.vstack([p, p[:1]])


SHORE = _ring(9.0, 46.0, 0.05)
INSIDE = _ring(9.01, 46.0, 0.01)[::-1]
OUTSIDE = _ring(9.3, 46.2, 0.01)[::-1]  # a hole wholly outside the shore
ACROSS = _ring(9.05, 46.0, 0.01)[::-1]  # a hole across the shore: the lake's own check names it
AROUND = _ring(9.0, 46.0, 0.2)[::-1]  # a "hole" round the whole shore (rings swapped)


def _geojson(path, holes):
    rings = [SHORE.tolist(), *(h.tolist() for h in holes)]
    feat = {"type": "Feature", "properties": {"name": "lake"}, "geometry": {"type": "Polygon", "coordinates": rings}}
    path.write_text(json.dumps({"type": "FeatureCollection", "features": [feat]}))
    return path


def _kml(path, holes):
    def coords(r):
        return " ".join(f"{x},{y},0" for x, y in r)

    inner = "".join(
        f"<innerBoundaryIs><LinearRing><coordinates>{coords(h)}</coordinates></LinearRing></innerBoundaryIs>"
        for h in holes
    )
    path.write_text(
        '<?xml version="1.0"?><kml xmlns="http://www.opengis.net/kml/2.2"><Document><Placemark><name>lake</name>'
        f"<Polygon><outerBoundaryIs><LinearRing><coordinates>{coords(SHORE)}</coordinates></LinearRing>"
        f"</outerBoundaryIs>{inner}</Polygon></Placemark></Document></kml>"
    )
    return path


@pytest.mark.parametrize(
    ("write", "suffix", "ring"),
    [
        (_geojson, "geojson", "interior ring 2 (ring 3 of the Polygon, 'lake hole 2')"),
        (_kml, "kml", "innerBoundaryIs ring 2 ('lake hole 2')"),
    ],
)
def test_a_hole_outside_its_outer_ring_is_a_read_error_naming_it(tmp_path, write, suffix, ring):
    path = write(tmp_path / f"lake.{suffix}", [INSIDE, OUTSIDE])
    with pytest.raises(ReadError) as err:
        read_points(path)
    msg = str(err.value)
    assert msg.startswith(f"{path}: ") and ring in msg and "lies wholly outside" in msg
    assert f"point 1 at ({OUTSIDE[0, 0]:.8g}, {OUTSIDE[0, 1]:.8g})" in msg
    around = write(tmp_path / f"around.{suffix}", [AROUND])
    with pytest.raises(ReadError, match=r"encloses its .* are the two swapped"):
        read_points(around)


@pytest.mark.parametrize(("write", "suffix"), [(_geojson, "geojson"), (_kml, "kml")])
def test_a_hole_across_its_outer_ring_names_its_first_point_outside(tmp_path, write, suffix):
    path = write(tmp_path / f"lake.{suffix}", [ACROSS])
    k = int(np.argmax(np.hypot(ACROSS[:, 0] - 9.0, ACROSS[:, 1] - 46.0) > 0.05))  # first point beyond the shore
    with pytest.raises(ReadError, match=rf"ring 1 .*crosses its .*: its point {k + 1} of {len(ACROSS)} at \("):
        read_points(path)
    ps = read_points(write(tmp_path / f"ok.{suffix}", [INSIDE]))  # a hole inside: read as before
    assert [pl.name for pl in ps.polylines] == ["lake", "lake hole 1"]
