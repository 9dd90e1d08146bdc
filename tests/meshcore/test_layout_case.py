"""A layout as an ``[outline]`` case: islands in from_outline, round trips, edits, the generator."""

from __future__ import annotations

import math

import numpy as np
import pytest

from meshcore import testing
from meshcore.case import generate_case, layout_case, loads_case
from meshcore.case.write import dumps_case
from meshcore.errors import CaseFileError, TopologyError
from meshcore.layout import auto_layout, layout_from_cuts, layout_from_outline, with_cells
from meshcore.layout.outline import interior_cuts, outline_parts
from meshcore.multiblock import from_outline

pytest.importorskip("shapely")

SIDES = ("bottom", "right", "top", "left")

SQUARE = np.array([[0, 0], [4, 0], [4, 4], [0, 4]], float)
ISLAND = np.array([[1.5, 1.5], [2.5, 1.5], [2.5, 2.5], [1.5, 2.5]], float)
RING_CUTS = [[[0, 0], [1.5, 1.5]], [[4, 0], [2.5, 1.5]], [[4, 4], [2.5, 2.5]], [[0, 4], [1.5, 2.5]]]
RING_BLOCKS = [
    {"name": "s", "corners": [[0, 0], [4, 0], [2.5, 1.5], [1.5, 1.5]], "cells": [8, 4]},
    {"name": "e", "corners": [[4, 0], [4, 4], [2.5, 2.5], [2.5, 1.5]], "cells": [8, 4]},
    {"name": "n", "corners": [[4, 4], [0, 4], [1.5, 2.5], [2.5, 2.5]], "cells": [8, 4]},
    {"name": "w", "corners": [[0, 4], [0, 0], [1.5, 1.5], [1.5, 2.5]], "cells": [8, 4]},
]


def _same_topology(a, b) -> float:
    """Largest distance between the border nodes of two topologies with the same blocks."""
    assert [x.name for x in a.blocks] == [y.name for y in b.blocks]
    assert [x.cells for x in a.blocks] == [y.cells for y in b.blocks]
    return max(
        float(np.abs(x.borders[s] - y.borders[s]).max()) for x, y in zip(a.blocks, b.blocks, strict=True) for s in SIDES
    )


# ------------------------------------------------------------------ from_outline with islands
def test_from_outline_with_an_island_gives_a_ring_of_blocks_that_solves():
    from meshcore.multiblock import solve_multiblock
    from meshcore.quality.lake import block_metrics

    ob = from_outline(SQUARE, cuts=RING_CUTS, blocks=RING_BLOCKS, holes=[ISLAND])
    topo = ob.topology
    assert len(topo.blocks) == 4 and len(topo.interfaces) == 4
    assert len(ob.islands) == 1
    mb = solve_multiblock(topo)
    assert mb.converged
    assert all(not block_metrics(g).folded.any() for g in mb.grids)
    # the grid covers the water and not the island: block areas add up to 16 - 1
    area = sum(
        0.5 * abs(np.sum(np.roll(loop[:, 0], -1) * loop[:, 1] - loop[:, 0] * np.roll(loop[:, 1], -1)))
        for loop in (b.borders.loop() for b in topo.blocks)
    )
    assert area == pytest.approx(15.0, rel=1e-9)


@pytest.mark.parametrize(
    ("cuts", "blocks", "holes", "needle"),
    [
        (RING_CUTS[:1], RING_BLOCKS[:1], [ISLAND], "encloses an island"),
        ([[[0, 0], [4, 4]]], RING_BLOCKS, [ISLAND], "cut 1 leaves the water"),
        (RING_CUTS, RING_BLOCKS, [ISLAND + 10], "island 0"),
        (RING_CUTS, RING_BLOCKS, [ISLAND, ISLAND + 0.2], "islands 0 and 1 overlap"),
    ],
)
def test_from_outline_island_errors_name_the_place(cuts, blocks, holes, needle):
    with pytest.raises(TopologyError, match=needle):
        from_outline(SQUARE, cuts=cuts, blocks=blocks, holes=holes)


# ------------------------------------------------------------------ the layout as outline parts
SHAPES = {
    "y": lambda: testing.y_junction(),
    "islands": lambda: testing.lake_with_islands(2),
    "network": lambda: testing.channel_network(1),
    "hole": lambda: testing.rectangle_with_hole(),
}


@pytest.mark.parametrize("name", sorted(SHAPES))
def test_a_layout_read_back_from_its_outline_parts_is_the_same_layout(name):
    lay = auto_layout(SHAPES[name](), target_cells=1500, multiple=4)
    p = outline_parts(lay)
    back = layout_from_outline(
        p["outline"], holes=p["holes"], cuts=p["cuts"], blocks=p["blocks"], cell_size=lay.cell_size, multiple=4
    )
    assert [b.name for b in back.blocks] == [b.name for b in lay.blocks]
    assert _same_topology(lay.topology(), back.topology()) == 0.0
    # the cuts are exactly the lines between blocks: cutting the water by them gives the blocks again
    again = layout_from_cuts(lay.polygon, lay.cuts, cell_size=lay.cell_size, multiple=4)
    assert len(again.blocks) == len(lay.blocks)
    assert again.polygon.area == pytest.approx(sum(pc_area(pc.ring) for pc in again.pieces), rel=1e-9)


def test_the_shore_of_pieces_is_the_same_whichever_vertex_their_rings_start_at():
    """A layout read back from its case has the same pieces, their rings started at other vertices:
    the shore the grid's nodes slide along started elsewhere too, and the grid moved (Kyoga: 15 m,
    0.03 cells, between ``meshcore mesh`` and ``meshcore generate`` of its ``--case``)."""
    from dataclasses import replace

    from meshcore.layout.outline import shore_of

    lay = auto_layout(testing.lake_with_islands(3), target_cells=1500, multiple=4)
    outer, holes = shore_of(list(lay.pieces))
    assert len(holes) >= 2
    for shift in (1, 2, 3):
        turned = [
            replace(
                pc, ring=np.roll(pc.ring, -shift, axis=0), corners=tuple((c - shift) % len(pc.ring) for c in pc.corners)
            )
            for pc in reversed(lay.pieces)
        ]
        o2, h2 = shore_of(turned)
        np.testing.assert_array_equal(o2, outer)
        assert len(h2) == len(holes)
        for a, b in zip(h2, holes, strict=True):
            np.testing.assert_array_equal(a, b)


def pc_area(r: np.ndarray) -> float:
    return 0.5 * abs(float(np.sum(r[:, 0] * np.roll(r[:, 1], -1) - np.roll(r[:, 0], -1) * r[:, 1])))


def test_interior_cuts_of_a_ring_round_an_island_are_the_four_spokes():
    ob = from_outline(SQUARE, cuts=RING_CUTS, blocks=RING_BLOCKS, holes=[ISLAND])
    from meshcore.layout.blocks import Piece

    pieces = []
    for r, spec in zip(ob.regions, RING_BLOCKS, strict=False):
        del spec
        pieces.append(Piece(np.asarray(r), (0, 1, 2, 3)))
    cuts = interior_cuts(pieces)
    ends = sorted(tuple(sorted((tuple(c[0]), tuple(c[-1])))) for c in cuts)
    want = sorted(tuple(sorted((tuple(map(float, a)), tuple(map(float, b))))) for a, b in RING_CUTS)
    assert ends == want


# ------------------------------------------------------------------ one block's cells, neighbours follow
def test_with_cells_moves_the_neighbours_and_keeps_every_interface_consistent():
    lay = auto_layout(testing.y_junction(), target_cells=1500, multiple=2)
    b = max(lay.blocks, key=lambda b: b.cells[0])
    new = with_cells(lay, b.name, (b.cells[0] + 6, b.cells[1]))
    assert {x.name: x.cells for x in new.blocks}[b.name] == (b.cells[0] + 6, b.cells[1])
    changed = [x.name for x, y in zip(lay.blocks, new.blocks, strict=True) if x.cells != y.cells]
    assert len(changed) >= 2  # a neighbour followed
    new.topology()  # every interface agrees (the topology checks the node counts)
    with pytest.raises(TopologyError, match=f"block {b.name!r}"):
        with_cells(lay, b.name, (b.cells[0] + 1, b.cells[1]))  # not a multiple of 2
    with pytest.raises(TopologyError, match="no block 'nope'"):
        with_cells(lay, "nope", (4, 4))


def test_with_cells_on_a_layout_read_from_outline_parts_sets_that_blocks_sides():
    # the pieces of a layout made from [outline] parts start at each block's sw corner: block
    # cells (ni along bottom/top) go to the sides they name, whatever vertex a region ring starts at
    lay = auto_layout(testing.y_junction(), target_cells=1500, multiple=2)
    p = outline_parts(lay)
    back = layout_from_outline(
        p["outline"], holes=p["holes"], cuts=p["cuts"], blocks=p["blocks"], cell_size=lay.cell_size, multiple=2
    )
    for pc, b in zip(back.pieces, back.blocks, strict=True):
        assert tuple(map(float, pc.ring[pc.corners[0]])) == pytest.approx(b.corners[0])
        assert tuple(map(float, pc.ring[pc.corners[1]])) == pytest.approx(b.corners[1])
    for b in back.blocks:
        new = with_cells(back, b.name, (b.cells[0] + 2, b.cells[1]))
        assert {x.name: x.cells for x in new.blocks}[b.name] == (b.cells[0] + 2, b.cells[1])
        new.topology()  # every interface agrees


# ------------------------------------------------------------------ case file round trip
@pytest.fixture(scope="module")
def y_layout():
    return auto_layout(testing.y_junction(), target_cells=600, multiple=4)


def test_layout_case_text_round_trip_and_the_same_grid(y_layout):
    from meshcore.lakegrid import mesh_layout

    case = layout_case(y_layout)
    text = dumps_case(case)
    back = loads_case(text)
    assert back.outline == case.outline and back.multiblock.mode == "orthogonal"
    mb = generate_case(back)
    ref = mesh_layout(y_layout)
    assert mb.mode == "orthogonal" and mb.converged
    for a, b in zip(mb.grids, ref.grids, strict=True):
        np.testing.assert_allclose(a.x, b.x, rtol=0, atol=1e-9)
        np.testing.assert_allclose(a.y, b.y, rtol=0, atol=1e-9)


def test_the_lake_table_round_trips_and_generate_ignores_it(y_layout):
    """``[lake]``: the water the case was made from as imported (the app's shore and islands) and
    its layout settings, written exactly and read back; the grid is that of the layout alone."""
    from meshcore.case import LakeSection

    shore = np.asarray(testing.y_junction().exterior.coords)[:-1]
    plain = generate_case(loads_case(dumps_case(layout_case(y_layout))))
    lake = LakeSection(shore=shore, islands=(ISLAND,), cell_size=0.25, regular=True)
    case = layout_case(y_layout).replaced(lake=lake)
    back = loads_case(dumps_case(case))
    assert back.lake == lake and back.lake.cell_size == 0.25 and back.lake.regular and not back.lake.single
    np.testing.assert_array_equal(back.lake.shore, shore)
    mb = generate_case(back)
    for a, b in zip(mb.grids, plain.grids, strict=True):
        np.testing.assert_array_equal(a.x, b.x)
        np.testing.assert_array_equal(a.y, b.y)
    text = dumps_case(case)
    with pytest.raises(CaseFileError, match=r"\[lake\].*islands\[0\]"):
        loads_case(text.replace("islands = [", "islands = [[[1, 2]], ", 1))
    with pytest.raises(CaseFileError, match=r"\[lake\].*cell_size"):
        loads_case(text.replace("cell_size = 0.25", "cell_size = -1.0", 1))
    with pytest.raises(CaseFileError, match=r"\[lake\].*colour"):
        loads_case(text.replace("[lake]\n", "[lake]\ncolour = 1\n", 1))


def test_an_edited_case_generates_again(y_layout):
    case = layout_case(y_layout)
    text = dumps_case(case)
    b0 = y_layout.blocks[0]
    new = with_cells(y_layout, b0.name, (b0.cells[0] + 4, b0.cells[1]))
    # edit the text as a user would: the cells of every block that changed
    for old, nb in zip(y_layout.blocks, new.blocks, strict=True):
        if old.cells != nb.cells:
            head = f'name = "{old.name}"'
            i = text.index(head)
            j = text.index("cells = ", i)
            k = text.index("\n", j)
            text = text[:j] + f"cells = [{nb.cells[0]}, {nb.cells[1]}]" + text[k:]
    mb = generate_case(loads_case(text))
    assert [g.cells for g in mb.grids] == [b.cells for b in new.blocks]


def test_case_errors_name_the_section():
    base = dumps_case(layout_case(auto_layout(testing.rectangle_with_hole(), target_cells=300, multiple=2)))
    with pytest.raises(CaseFileError, match=r"holes\[0\]"):
        loads_case(base.replace("holes = [", "holes = [[[1, 2]], ", 1))
    no_outline = (
        '[multiblock]\nmode = "orthogonal"\n[[blocks]]\nname = "b"\ncells = [4, 3]\n[blocks.boundary]\n'
        "bottom = [[0, 0], [2, 0]]\nright = [[2, 0], [2, 1]]\ntop = [[0, 1], [2, 1]]\nleft = [[0, 0], [0, 1]]\n"
    )
    with pytest.raises(CaseFileError, match="needs an \\[outline\\]"):
        loads_case(no_outline)


# ------------------------------------------------------------------ the generator
def test_iterate_layout_yields_grids_and_stops_on_request(y_layout):
    from meshcore.lakegrid import iterate_layout, mesh_layout

    gen = iterate_layout(y_layout, every=10)
    seen = []
    try:
        p = next(gen)
        while True:
            seen.append(p)
            p = next(gen)
    except StopIteration as fin:
        mb = fin.value
    assert len(seen) >= 3 and all(len(p.grids) == len(y_layout.blocks) for p in seen)
    its = [p.iteration for p in seen]
    assert its == sorted(its) and seen[-1].history[-1] == (seen[-1].iteration, seen[-1].residual)
    ref = mesh_layout(y_layout)
    for a, b in zip(mb.grids, ref.grids, strict=True):  # watching does not change the grid
        np.testing.assert_array_equal(a.x, b.x)
    gen = iterate_layout(y_layout, every=10)
    next(gen)
    with pytest.raises(StopIteration) as fin:
        gen.send("stop")
    stopped = fin.value.value
    assert not stopped.converged and stopped.info.message == "stopped"
    assert all(np.isfinite(g.x).all() for g in stopped.grids)


def test_cell_size_default_is_the_mean_cell():
    lay = layout_from_outline(SQUARE, cuts=RING_CUTS, blocks=RING_BLOCKS, holes=[ISLAND])
    assert lay.cell_size == pytest.approx(math.sqrt(15.0 / (4 * 32)))


def test_point_arrays_are_written_exactly_and_a_non_finite_one_refused():
    """A shore of many points is written as a whole array (the app's autosave of a traced lake):
    every float read back to the last bit, and a NaN anywhere in it refused by name."""
    from meshcore.case.write import _clean, _toml_value

    rng = np.random.default_rng(3)
    pts = rng.normal(5e5, 1e4, (2000, 2))
    text = "p = " + _toml_value(_clean(pts))
    import tomllib

    back = np.asarray(tomllib.loads(text)["p"])
    np.testing.assert_array_equal(back, pts)
    assert _clean(np.arange(3)) == [0, 1, 2] and _clean(np.array([True])) == [True]
    pts[1234, 1] = np.nan
    with pytest.raises(CaseFileError, match="non-finite number"):
        _clean(pts)
