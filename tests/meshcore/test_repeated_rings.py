"""A ring an outline file holds twice (a hole copied, a feature exported twice, a CSV ``ring`` written
twice): read once with a note naming both rings (:func:`meshcore.cli.lakefile.without_repeated_rings`).

Before: a repeated island was read as "a pond on an island" (the note said so), an island the same
as the shore was refused as touching the shore, and a CSV ring id written twice over as a ring that
crosses itself."""

from __future__ import annotations

import json

import numpy as np
import pytest

from meshcore.cli.lakefile import lake_parts, lake_rings
from meshcore.io import read_points
from tests.meshcore.test_mesh_cli import mesh

pytest.importorskip("shapely")

T = np.linspace(0, 2 * np.pi, 60, endpoint=False)
SHORE = np.column_stack([1000 * np.cos(T), 600 * np.sin(T)])
ISLE = np.column_stack([200 + 100 * np.cos(T[::3]), 80 * np.sin(T[::3])])
ISLE2 = np.column_stack([-300 + 60 * np.cos(T[::3]), 50 * np.sin(T[::3])])


def closed(r):
    return [*r.tolist(), r[0].tolist()]


def geojson(path, rings):
    lonlat = [[[8 + x / 1e5, 47 + y / 1e5] for x, y in closed(r)] for r in rings]
    geometry = {"type": "Polygon", "coordinates": lonlat}
    feature = {"type": "Feature", "properties": {"name": "lake"}, "geometry": geometry}
    path.write_text(json.dumps({"type": "FeatureCollection", "features": [feature]}))
    return path


def csv(path, rings):
    rows = [f"{k},{x!r},{y!r}" for k, r in rings for x, y in closed(r)]
    path.write_text("ring,x,y\n" + "\n".join(rows) + "\n")
    return path


def rounds(a):
    """A ring's points from its lowest-leftmost point, counter-clockwise (to compare rings)."""
    a = np.asarray(a, float)
    if _area(a) < 0:
        a = a[::-1]
    k = np.lexsort((a[:, 1], a[:, 0]))[0]
    return np.roll(a, -k, axis=0)


def _area(a):
    return 0.5 * float(np.sum(a[:, 0] * np.roll(a[:, 1], -1) - np.roll(a[:, 0], -1) * a[:, 1]))


@pytest.mark.parametrize(
    ("rings", "left_out", "kept"),
    [
        ([(0, SHORE), (1, ISLE), (2, ISLE)], "'2'", "'1'"),  # an island under two ids
        ([(0, SHORE), (1, ISLE), (2, ISLE2), (3, ISLE2[::-1])], "'3'", "'2'"),  # the other way round
        ([(0, SHORE), (1, ISLE), (2, np.roll(SHORE, 7, axis=0))], "'2'", "the shore '0'"),  # the shore again
    ],
)
def test_a_csv_ring_repeated_is_read_once_naming_both(tmp_path, rings, left_out, kept):
    f = csv(tmp_path / "lake.csv", rings)
    once = csv(tmp_path / "once.csv", [r for r in rings if f"'{r[0]}'" != left_out])
    outer, islands, notes = lake_rings(read_points(f))
    outer1, islands1, notes1 = lake_rings(read_points(once))
    assert notes1 == []
    (note,) = notes
    assert f"{left_out} is the same ring as {kept}" in note and "read once" in note
    assert np.array_equal(outer, outer1) and len(islands) == len(islands1)
    for a, b in zip(islands, islands1, strict=True):
        assert np.array_equal(a, b)


def test_a_csv_ring_id_written_twice_over_is_one_round(tmp_path):
    f = csv(tmp_path / "lake.csv", [(0, SHORE), (1, ISLE), (1, ISLE)])
    _, islands, notes = lake_rings(read_points(f))  # was: "island 1 crosses itself"
    (note,) = notes
    assert "'1' goes round its ring 2 times" in note
    (isl,) = islands
    assert len(isl) == len(ISLE) and np.allclose(rounds(isl), rounds(ISLE))


def test_a_geojson_hole_repeated_or_the_same_as_the_shore(tmp_path):
    twice = geojson(tmp_path / "twice.geojson", [SHORE, ISLE[::-1], ISLE[::-1]])
    (part,), notes = lake_parts(read_points(twice))
    assert len(part[2]) == 1  # was: two islands, the second "a pond on an island"
    assert notes == ["'lake hole 2' is the same ring as 'lake hole 1' (20 points): a ring drawn twice, read once — "
                     "'lake hole 2' left out"]  # fmt: skip
    shore = geojson(tmp_path / "shore.geojson", [SHORE, SHORE[::-1]])
    (part,), notes = lake_parts(read_points(shore))
    assert len(part[2]) == 0 and "'lake hole 1' is the same ring as the shore 'lake'" in notes[0]


def test_rings_that_differ_are_not_repeats(tmp_path):
    near = ISLE.copy()
    near[5] += 1.0  # one point a metre away: another ring (the lake's own checks judge it)
    f = csv(tmp_path / "lake.csv", [(0, SHORE), (1, ISLE), (2, ISLE + [0.0, 200.0])])
    assert lake_rings(read_points(f))[2] == []
    g = csv(tmp_path / "near.csv", [(0, SHORE), (1, ISLE), (2, near)])
    assert not any("same ring" in n for n in lake_rings(read_points(g))[2])


def test_meshcore_mesh_of_a_hole_the_same_as_the_shore_meshes_the_lake_with_a_note(tmp_path):
    f = geojson(tmp_path / "lake.geojson", [SHORE, SHORE[::-1]])
    run = mesh(f, "-o", tmp_path / "lake.vtm", "--cell-size", "60")
    assert run.rc == 0, run.err  # was: "'lake hole 1' touches the shore of 'lake'", refused
    assert "note: 'lake hole 1' is the same ring as the shore 'lake' (60 points)" in run.err
    assert f"read {f}" in run.err and "Traceback" not in run.err
    assert (tmp_path / "lake.vtm").exists()
