"""With :data:`meshcore.multiblock.counts.SHORT_JUMPS` (an option that is off: measured mixed on
lakes of 40–110 blocks, docs/lake-grids-journal.md), a piece of shore shorter than ``multiple``
cells between two cut ends does not take the cells a block side asks for beyond its cut's.

Where two cuts end on the shore a cell or three apart, a block side is the one cut plus the short
piece of shore up to the other's end.  That piece is the one chain of the side no other block
shares, and with short chains exempt from the jump terms it was free: held-out g180713 at 15 000
cells put 36 cells on 3.9 cells of shore beside a 43-cell cut with 12 (the block 80 % of its
nodes beyond 3°).  Measured on the layouts' own counts, whatever rule made the cuts.
"""

from __future__ import annotations

import numpy as np
import pytest

from meshcore import testing
from meshcore.layout import auto_layout
from meshcore.layout.blocks import _chains_of, _counts, _line_work
from meshcore.multiblock import counts

#: Generated shapes whose layouts had such a piece with short chains exempt (the worst 36×).
CASES = {
    "channel network 940007 at 2000": (lambda: testing.channel_network(940007, n_branches=8), 2000),
}


def crowded_tiny_pieces(lay, factor: float = 4.0) -> list[float]:
    """Per shore chain shorter than ``multiple`` cells that has more than ``multiple`` cells at
    ``factor`` or more times the cells per length of another chain of its block side: that ratio
    (the sides' cells counted again, as the layout did, with the counts' settings as they are)."""
    h, m = lay.cell_size, lay.multiple
    pieces = list(lay.pieces)
    work = _line_work(pieces)
    _, n = _counts(work, pieces, h, 3, m, None, True)
    sides, pts, users = _chains_of(pieces, work)
    index = {k: i for i, k in enumerate(pts)}
    out = []
    for keys in sides.values():
        chains = [(float(np.hypot(*np.diff(pts[k], axis=0).T).sum()) / h, int(n[index[k]]), k) for k in keys]
        for length, cells, key in chains:
            if len(users[key]) != 1 or length >= m or cells <= m:
                continue
            others = [c / ln for ln, c, k in chains if k != key and ln > 0]
            if others and cells / length >= factor * min(others):
                out.append(cells / length / min(others))
    return out


@pytest.mark.parametrize("name", list(CASES))
def test_no_crowded_tiny_shore_piece(name, monkeypatch):
    make, cells = CASES[name]
    poly = make()
    monkeypatch.setattr(counts, "SHORT_JUMPS", True)
    after = auto_layout(poly, target_cells=cells, multiple=4)
    assert not crowded_tiny_pieces(after)
    monkeypatch.setattr(counts, "SHORT_JUMPS", False)  # the default
    before = auto_layout(poly, target_cells=cells, multiple=4)
    assert crowded_tiny_pieces(before)  # the case has the pattern with short chains exempt
    # the same blocks, about the same cells
    assert len(after.blocks) == len(before.blocks)
    total = [sum(a * b for a, b in (blk.cells for blk in lay.blocks)) for lay in (before, after)]
    assert abs(total[1] - total[0]) <= 0.1 * total[0]
