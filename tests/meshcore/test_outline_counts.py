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
def test_counts_the_cells_force_are_the_programs(seed, monkeypatch):
    """When every block's cells fix every chain's count (no side's cells to share), the counts are
    taken without the integer program: the same topology as the program gives (generated lakes)."""
    import meshcore.multiblock.chains as chains

    forced = []
    real = chains._Counts.forced
    monkeypatch.setattr(chains._Counts, "forced", lambda self: forced.append(real(self)) or forced[-1])
    for poly in _shapes(seed):
        lay = auto_layout(poly, cell_size=float(np.sqrt(poly.area / 800)), multiple=4)
        got = outline_blocks(lay).topology
        with monkeypatch.context() as m:
            m.setattr(chains._Counts, "forced", lambda self: None)  # always the program
            want = outline_blocks(lay).topology
        assert all(np.array_equal(a, b) for a, b in zip(_borders(got), _borders(want), strict=True))
        assert got.interfaces == want.interfaces
    assert any(f is not None for f in forced)  # the short cut was taken ...
    assert any(f is None for f in forced)  # ... and not where a side's cells are shared


def test_forced_counts_are_none_where_a_side_has_cells_to_share():
    from meshcore.multiblock.chains import _Counts, side_chains
    from meshcore.multiblock.outline import BlockOutline

    # one block 4 x 2 whose bottom is two chains (a break in its middle): 4 cells to share
    ring = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [2.0, 1.0], [0.0, 1.0]])
    keys = [tuple(map(float, p)) for p in ring]
    spec = BlockOutline("a", tuple(keys[i] for i in (0, 2, 3, 4)), (4, 2))
    corners = {"a": [keys[i] for i in (0, 2, 3, 4)]}
    sides, pts, users = side_chains([spec], {"a": ring}, corners, set(corners["a"]) | {keys[1]})
    assert _Counts([spec], sides, pts, users, 1).forced() is None
    sides, pts, users = side_chains([spec], {"a": ring}, corners, set(corners["a"]))
    assert sorted(_Counts([spec], sides, pts, users, 1).forced().values()) == [2, 2, 4, 4]
    assert _Counts([spec], sides, pts, users, 4).forced() is None  # 2 is not a multiple of 4


def test_least_cells_remembered_are_those_computed():
    from meshcore.multiblock import shorecells

    rng = np.random.default_rng(3)
    for _ in range(20):
        chain = np.cumsum(rng.normal(size=(int(rng.integers(3, 40)), 2)), axis=0)
        h, m = float(rng.uniform(0.3, 2.0)), int(rng.choice([1, 2, 4]))
        want = shorecells._least_cells.__wrapped__(np.ascontiguousarray(chain).tobytes(), chain.shape, h, m, 1.0, 2.0)
        assert shorecells.least_cells(chain, h, m) == want == shorecells.least_cells(chain.copy(), h, m)
