"""The cells per chain of an outline split into blocks: the short cuts give the program's answer."""

from __future__ import annotations

import numpy as np
import pytest

from meshcore import testing
from meshcore.layout import auto_layout
from meshcore.layout.outline import outline_blocks


def _shapes(seed: int):
    return (
        testing.channel_network(seed),
        testing.lake_with_islands(seed),
        testing.round_lake(seed, kind="arms"),
        testing.spiral(),
        testing.y_junction(),
    )


def _borders(topo) -> list[np.ndarray]:
    return [getattr(b.borders, s) for b in topo.blocks for s in ("bottom", "right", "top", "left")]


@pytest.mark.parametrize("seed", range(3))
def test_counts_the_cells_imply_give_the_programs_answer(seed, monkeypatch):
    """The counts the blocks' cells imply are taken as they are (all of them) or fixed in the
    integer program (some): the same topology as the whole program gives (generated lakes)."""
    import meshcore.multiblock.chains as chains

    seen = []
    real = chains._Counts.implied

    def implied(self):
        out = real(self)
        seen.append(out is not None and self.complete(out))
        return out

    monkeypatch.setattr(chains._Counts, "implied", implied)
    for poly in _shapes(seed):
        lay = auto_layout(poly, cell_size=float(np.sqrt(poly.area / 800)), multiple=4)
        got = outline_blocks(lay).topology
        with monkeypatch.context() as m:
            m.setattr(chains._Counts, "implied", lambda self: None)  # the whole program
            want = outline_blocks(lay).topology
        assert all(np.array_equal(a, b) for a, b in zip(_borders(got), _borders(want), strict=True))
        assert got.interfaces == want.interfaces
    assert any(seen) and not all(seen)  # every chain implied (no program), and some left to it


def test_implied_counts_leave_a_sides_cells_to_share():
    from meshcore.multiblock.chains import _Counts, side_chains
    from meshcore.multiblock.outline import BlockOutline

    # one block 4 x 2 whose bottom is two chains (a break in its middle): 4 cells to share
    ring = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [2.0, 1.0], [0.0, 1.0]])
    keys = [tuple(map(float, p)) for p in ring]
    spec = BlockOutline("a", tuple(keys[i] for i in (0, 2, 3, 4)), (4, 2))
    corners = {"a": [keys[i] for i in (0, 2, 3, 4)]}
    sides, pts, users = side_chains([spec], {"a": ring}, corners, set(corners["a"]) | {keys[1]})
    c = _Counts([spec], sides, pts, users, 1)
    got = c.implied()
    assert sorted(got.values()) == [2, 2, 4] and not c.complete(got)  # right, left, top; not the bottom's two
    sides, pts, users = side_chains([spec], {"a": ring}, corners, set(corners["a"]))
    c = _Counts([spec], sides, pts, users, 1)
    got = c.implied()
    assert sorted(got.values()) == [2, 2, 4, 4] and c.complete(got)
    assert _Counts([spec], sides, pts, users, 4).implied() is None  # 2 is not a multiple of 4


def test_least_cells_remembered_are_those_computed():
    from meshcore.multiblock import shorecells

    rng = np.random.default_rng(3)
    for _ in range(20):
        chain = np.cumsum(rng.normal(size=(int(rng.integers(3, 40)), 2)), axis=0)
        h, m = float(rng.uniform(0.3, 2.0)), int(rng.choice([1, 2, 4]))
        want = shorecells._least_cells.__wrapped__(np.ascontiguousarray(chain).tobytes(), chain.shape, h, m, 1.0, 2.0)
        assert shorecells.least_cells(chain, h, m) == want == shorecells.least_cells(chain.copy(), h, m)
