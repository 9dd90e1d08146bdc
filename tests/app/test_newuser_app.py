"""The app on inputs a new lake modeller sends (session 22's sweep): a clear message, the work kept."""

from __future__ import annotations

import numpy as np
import pytest

pytestmark = pytest.mark.gui

T = np.linspace(0, 2 * np.pi, 24, endpoint=False)


def test_a_lake_of_points_on_one_line_is_refused_by_auto_layout_naming_the_place():
    from app.lake import Lake, compute_layout
    from meshcore.errors import InvalidInputError

    # a sliver 4 cm wide and 1.6 km long (lon/lat on a parallel, 6 decimals, projected): was
    # "internal error: ValueError: All-NaN slice encountered" from the layout (90 s at 10 000 cells)
    x = np.linspace(0.0, 1560.0, 20)
    y = 0.02 * np.sin(np.linspace(0, np.pi, 20))
    lake = Lake(outline=np.r_[np.c_[x, y], np.c_[x[-2:0:-1], -y[-2:0:-1]]], target_cells=200)
    with pytest.raises(InvalidInputError, match=r"on one line.*Lake panel"):
        compute_layout(lake)
    channel = Lake(outline=np.array([[0.0, 0.0], [20000.0, 0.0], [20000.0, 200.0], [0.0, 200.0]]), cell_size=300.0)
    assert compute_layout(channel).n_cells > 0  # narrower than a cell set by the user: laid out


def test_the_lonlat_order_note_of_a_y_x_header_tells_no_command_line_option(win, tmp_path):
    f = tmp_path / "yx.csv"
    f.write_text("Y,X\n" + "".join(f"{47.3 + 0.01 * np.sin(a):.6f},{8.5 + 0.02 * np.cos(a):.6f}\n" for a in T))
    seen = []
    win.doc.reported.connect(lambda level, text: seen.append(text))
    assert win.io.import_points(f, project_lonlat=True)
    notes = [t for t in seen if "the header says" in t]
    assert notes and all("--columns" not in t for t in notes), seen  # the app has no --columns
