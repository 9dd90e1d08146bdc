"""Inputs a new lake modeller sends (session 22's sweep) that failed on main: each now gives a
grid of the water in the file, or exit 2 and one line naming the file and the place."""

from __future__ import annotations

import numpy as np

from tests.meshcore.test_cli_bad_input import _bad


def test_lonlat_points_on_a_line_but_for_their_decimals_are_refused_naming_the_place(tmp_path, capsys):
    # 20 points along a parallel, 6 decimals: a sliver 4 cm wide and 1.6 km long, exit 1 after a
    # minute and a half ("internal error ... All-NaN slice encountered" in the layout's skeleton)
    src, out = tmp_path / "line.csv", tmp_path / "line.vtm"
    lon = 11.9 + 0.001 * np.arange(20)
    src.write_text("lon,lat\n" + "".join(f"{a:.6f},42.600000\n" for a in lon))
    err = _bad(capsys, ["mesh", src, "-o", out, "--cells", "200", "-q"], "line.csv", "on one line", "--cell-size")
    assert "across at its widest (near (7" in err  # the place, in the grid's UTM metres
    assert not out.exists()
