"""Point files as users send them (session 17's odd inputs): a right outline or one clear error."""

from __future__ import annotations

import numpy as np
import pytest

from meshcore.errors import ReadError
from meshcore.io import read_points

RECT = [(0.0, 0.0), (4000.0, 0.0), (4000.0, 2000.0), (0.0, 2000.0)]


def _csv(rows, header="x,y"):
    return header + "\n" + "\n".join(",".join(f"{v:g}" for v in r) for r in rows) + "\n"


@pytest.mark.parametrize("header", ["id,x,y", "fid,x,y", "name,lon,lat"])
def test_a_column_that_numbers_the_points_is_not_a_ring_name(tmp_path, header):
    lonlat = "lon" in header
    pts = [(8.5 + x / 1e5, 47.3 + y / 1e5) for x, y in RECT] if lonlat else RECT
    f = tmp_path / "ids.csv"
    f.write_text(_csv([(k + 1, *p) for k, p in enumerate(pts)], header))
    ps = read_points(f)
    assert len(ps.polylines) == 1
    np.testing.assert_allclose(ps.polylines[0].points, pts)


def test_a_name_column_still_groups_rings(tmp_path):
    f = tmp_path / "named.csv"
    f.write_text(_csv([(1, *p) for p in RECT] + [(2, 100, 100), (2, 200, 100), (2, 200, 200)], "id,x,y"))
    assert [len(pl) for pl in read_points(f).polylines] == [4, 3]


def test_a_shore_cut_by_a_stray_blank_line_is_one_ring(tmp_path):
    f = tmp_path / "blank.csv"
    f.write_text("x,y\n0,0\n4000,0\n4000,2000\n\n0,2000\n0,0\n")
    (pl,) = read_points(f).polylines
    assert pl.closed
    np.testing.assert_allclose(pl.points, RECT)


def test_rings_apart_stay_apart(tmp_path):
    f = tmp_path / "rings.csv"
    f.write_text("x,y\n0,0\n4000,0\n4000,2000\n0,2000\n0,0\n\n100,100\n200,100\n200,200\n100,100\n")
    assert [len(pl) for pl in read_points(f).polylines] == [4, 3]


def test_a_one_point_piece_says_blank_lines_split(tmp_path):
    f = tmp_path / "b.csv"
    f.write_text("x,y\n0,0\n\n4000,0\n4000,2000\n0,2000\n")
    with pytest.raises(ReadError) as exc:
        read_points(f)
    assert "line 2" in str(exc.value) and "blank line starts a new polyline" in str(exc.value)
