"""Work the layout no longer repeats (docs/lake-grids-journal.md, CPU, session 34): the layout
choice's tip draw skipped where the draw at its scale left no piece with a land tip, and the
skeleton, chords and region splits of a draw remembered for the tip draw.  Behaviour, not time:
the same layouts with and without."""

import numpy as np
import pytest
from shapely.geometry import Point, Polygon, box

import meshcore.layout as lay
from meshcore import testing
from meshcore.layout import build
from meshcore.layout.build import _skeleton_and_chords, _split_region, _unfanned
from meshcore.layout.memo import remembering
from meshcore.layout.split import _orient, best_split
from meshcore.layout.tipcuts import _kept_split, noted_tips, splits, tip_split, watching_tips


def _blocks(layout) -> list:
    return [(b.name, b.corners, b.cells) for b in layout.blocks]


def _reading(layout) -> tuple[float, float]:
    """A stand-in for the coarse grid's reading: deterministic, and different layouts differ."""
    area = np.array([Polygon(p.ring).area for p in layout.pieces])
    return float(len(layout.blocks) + area.std() / area.mean()), 1.0


def _tongue() -> Polygon:
    """A basin with a rounded land tongue from its south shore: the water turns round its tip."""
    tongue = box(4.5, 0, 5.5, 3.5).union(Point(5, 3.5).buffer(0.5, 16))
    return box(0, 0, 10, 6).difference(tongue)


def test_watching_tips_notes_the_pieces_with_a_tip():
    u = _orient(np.asarray(_tongue().exterior.coords)[:-1])
    plain = _orient(np.asarray(box(0, 0, 10, 3).exterior.coords)[:-1])
    with watching_tips() as seen:
        noted_tips([(plain, ())], 0.15, 0.3, True, False)
    assert seen == [] and not splits(seen)
    with watching_tips() as seen:
        noted_tips([(plain, ()), (u, ())], 0.15, 0.3, True, False)
    assert len(seen) == 1 and np.array_equal(seen[0][0], u) and splits(seen)
    with watching_tips() as seen:  # forced corners: the tip draw leaves such pieces alone
        noted_tips([(u, (tuple(u[0]),))], 0.15, 0.3, True, False)
    assert seen == []
    noted_tips([(u, ())], 0.15, 0.3, True, False)  # outside the context: nothing to note, no error


def test_a_remembered_tip_split_is_the_fresh_one():
    u = _orient(np.asarray(_tongue().exterior.coords)[:-1])
    fresh = tip_split(u, sigma=0.15, min_width=0.3)
    with remembering():
        first = _kept_split(u, 0.15, 0.3, True, False)
        first[0][0][0][:] = 0.0  # the caller's copy
        again = _kept_split(u, 0.15, 0.3, True, False)
        plain = _orient(np.asarray(box(0, 0, 10, 3).exterior.coords)[:-1])
        assert _kept_split(plain, 0.15, 0.3, True, False) is None
    _same_split(fresh, again)


def _same_split(a, b) -> None:
    assert len(a[0]) == len(b[0]) and len(a[1]) == len(b[1])
    for (ra, fa), (rb, fb) in zip(a[0], b[0], strict=True):
        assert np.array_equal(ra, rb) and len(fa) == len(fb)
    for ca, cb in zip(a[1], b[1], strict=True):
        assert np.array_equal(ca, cb)


@pytest.mark.parametrize(
    "poly",
    [
        box(0, 0, 20, 2),
        _tongue(),
        pytest.param(testing.headlands(4), marks=pytest.mark.slow),
        testing.lake_with_islands(3),
    ],
    ids=["channel", "tongue", "headlands4", "islands3"],
)
def test_the_gated_tip_draw_gives_the_ungated_layout(poly, monkeypatch):
    draws = {}
    got = {}
    real = lay.splitting_tips
    for gate in (False, True):
        n = [0]

        def counting(n=n):
            n[0] += 1
            return real()

        monkeypatch.setattr(lay, "splitting_tips", counting)
        monkeypatch.setattr(lay, "TIP_GATE", gate)
        got[gate] = lay.auto_layout(poly, target_cells=2000, multiple=4, reading=_reading)
        draws[gate] = n[0]
    assert _blocks(got[True]) == _blocks(got[False])
    assert [c.tolist() for c in got[True].cuts] == [c.tolist() for c in got[False].cuts]
    assert draws[True] <= draws[False]
    if poly.equals(box(0, 0, 20, 2)):  # no tip anywhere: the tip draw is not made
        assert draws == {False: 1, True: 0}


def test_a_remembered_region_split_is_the_fresh_one():
    poly = testing.headlands(4)
    h = (poly.area / 800) ** 0.5
    sk, chords = _skeleton_and_chords(poly, h, False)  # outside remembering(): made afresh
    with remembering():
        sk2, chords2 = _skeleton_and_chords(poly, h, False)
        assert _skeleton_and_chords(poly, h, False)[0] is sk2  # remembered
    assert np.array_equal(sk.nodes, sk2.nodes)
    assert [c.points.tolist() for c in chords] == [c.points.tolist() for c in chords2]
    junctions = sk.nodes[sk.degree() >= 3]
    ring = _orient(np.asarray(poly.exterior.coords)[:-1])
    sigma = 1.5 * h
    pieces, cuts, _ = best_split(ring, sigma=sigma, min_width=3 * h, center=build._junction_centre(ring, junctions))
    fresh = _unfanned(pieces, cuts, junctions, sigma, 3 * h, True, False)
    with remembering():
        first = _split_region(ring, junctions, sigma, 3 * h, regular=False, normal=True, thin=False, tees=False)
        first[0][0][0][:] = 0.0  # the caller's copy: changing it leaves the remembered split as it was
        again = _split_region(ring, junctions, sigma, 3 * h, regular=False, normal=True, thin=False, tees=False)
    _same_split(fresh, again)


def test_a_remembered_partition_is_the_fresh_one():
    import shapely

    from meshcore.layout.regions import partition

    poly = testing.lake_with_islands(3)
    h = (poly.area / 800) ** 0.5
    dense = shapely.segmentize(poly, h)
    _, chords = _skeleton_and_chords(poly, h, False)
    lines = [build._densify(c.points, h) for c in chords]
    fresh = partition(dense, lines, 1.5 * h)
    with remembering():
        first = build._partition(dense, lines, 1.5 * h)
        first[0][0][:] = 0.0  # the caller's copy: changing it leaves the remembered partition as it was
        first[1].append(np.zeros((2, 2)))
        again = build._partition(dense, lines, 1.5 * h)
    assert len(fresh[0]) == len(again[0]) and len(fresh[1]) == len(again[1])
    assert all(np.array_equal(a, b) for a, b in zip(fresh[0] + fresh[1], again[0] + again[1], strict=True))


def test_remembered_counts_give_the_layouts_made_without_memo(monkeypatch):
    """The draws' cell counts (and partitions) remembered within one call: the same layouts as with
    nothing remembered, regular (whose frames count the same pieces again) and default."""
    import contextlib

    from meshcore.layout import blocks

    poly = testing.lake_with_islands(3)
    solved = []
    real = blocks.solve_counts
    monkeypatch.setattr(blocks, "solve_counts", lambda *a, **k: solved.append(1) or real(*a, **k))
    got = {}
    for memo in (True, False):
        if not memo:
            monkeypatch.setattr(lay, "remembering", contextlib.nullcontext)
        for regular in (False, True):
            solved.clear()
            out = lay.auto_layout(poly, target_cells=2000, multiple=4, reading=_reading, regular=regular)
            got[memo, regular] = (_blocks(out), [c.tolist() for c in out.cuts], len(solved))
    for regular in (False, True):
        assert got[True, regular][:2] == got[False, regular][:2]
        assert got[True, regular][2] <= got[False, regular][2]
    assert got[True, True][2] < got[False, True][2]  # a regular layout's frames count pieces again
