"""A lake grid whose levels end with folded or non-convex cells is made again with block corners
and cut ends sliding along the shore (``meshcore.lakegrid.FOLD_RETRY``), and the grid with fewer
such cells is the one returned: what ``meshcore mesh``, the app and ``mesh_outline`` get."""

from __future__ import annotations

import re

import numpy as np
import pytest

from meshcore import lakegrid, testing
from meshcore.lakegrid import mesh_layout, mesh_outline
from meshcore.layout import auto_layout
from meshcore.quality import lake_metrics


@pytest.fixture(scope="module")
def layout():
    return auto_layout(testing.y_junction(), target_cells=800, multiple=4)


def _same(a, b) -> bool:
    return all(np.array_equal(p.x, q.x) and np.array_equal(p.y, q.y) for p, q in zip(a.grids, b.grids, strict=True))


def _counted(monkeypatch, counts):
    """``lakegrid._n_folded`` answering ``counts`` in turn (the first pass, then the retry)."""
    said = list(counts)
    calls = []

    def n_folded(grids):
        calls.append(len(grids))
        return said.pop(0)

    monkeypatch.setattr(lakegrid, "_n_folded", n_folded)
    return calls


def test_a_grid_with_fewer_bad_cells_made_again_is_the_one_returned(layout, monkeypatch):
    sliding = mesh_layout(layout, levels=2, slide_ends=True)
    calls = _counted(monkeypatch, [3, 1])
    mb = mesh_layout(layout, levels=2)
    assert len(calls) == 2  # the first pass counted, then the retry
    assert _same(mb, sliding)
    assert "made again with block corners and cut ends sliding along the shore: 3 → 1" in mb.info.message
    assert all("made again" in g.info.message for g in mb.grids)


def test_the_first_grid_stays_when_the_retry_is_no_better_or_not_needed(layout, monkeypatch):
    plain = mesh_layout(layout, levels=2)
    _counted(monkeypatch, [2, 2])
    assert _same(mesh_layout(layout, levels=2), plain)
    calls = _counted(monkeypatch, [0])
    assert _same(mesh_layout(layout, levels=2), plain) and len(calls) == 1  # no fold: no retry
    monkeypatch.setattr(lakegrid, "FOLD_RETRY", False)
    calls = _counted(monkeypatch, [5])
    assert _same(mesh_layout(layout, levels=2), plain) and not calls
    monkeypatch.setattr(lakegrid, "FOLD_RETRY", True)
    calls = _counted(monkeypatch, [])
    assert _same(mesh_layout(layout, levels=2, slide_ends=True), mesh_layout(layout, levels=2, slide_ends=True))
    assert not calls  # asked for sliding ends already: nothing to retry


def test_a_stop_during_the_retry_returns_the_first_grid(layout, monkeypatch):
    import threading

    plain = mesh_layout(layout, levels=2)
    stop = threading.Event()
    said = [1, 0]

    def n_folded(grids):
        stop.set()  # the user stops while the grid is made again
        return said.pop(0)

    monkeypatch.setattr(lakegrid, "_n_folded", n_folded)
    mb = mesh_layout(layout, levels=2, stop_event=stop)
    assert _same(mb, plain) and "made again" not in mb.info.message


@pytest.mark.slow
def test_a_dendritic_reservoirs_corner_on_a_notch_of_the_shore_leaves_no_bad_cell(monkeypatch):
    """``dendritic(370703)`` at 15 000 cells: a tip block's corner where the arm's flank bends away
    from the water left one non-convex cell; made again with sliding corners it has none, and the
    other numbers are no worse than the first grid's by more than half a point."""
    import meshcore.lakegrid as lg

    poly = testing.dendritic(370703)
    mb = mesh_outline(poly, target_cells=15000)
    s = lake_metrics(mb, polygon=poly).summary()
    assert s["folded_cells"] == 0 and mb.info.converged
    assert "made again with block corners and cut ends sliding along the shore: 1 → 0" in mb.info.message
    assert s["max_interface_ratio"] <= 2.0 and s["hausdorff_cells"] <= 0.5
    monkeypatch.setattr(lg, "FOLD_RETRY", False)  # the first grid, its one bad cell left
    first = lake_metrics(mesh_outline(poly, target_cells=15000), polygon=poly).summary()
    assert first["folded_cells"] == 1
    for k in ("pct_nodes_within_3deg", "pct_smoothness_le_1.2"):
        assert s[k] >= first[k] - 0.5, (k, first[k], s[k])


@pytest.mark.parametrize(("counts", "kept"), [([3, 1], True), ([2, 2], False)])
def test_the_callback_hears_the_retry_its_levels_and_which_grid_is_kept(layout, monkeypatch, counts, kept):
    """``meshcore mesh`` printed nothing while the grid was made again (held-out Vänern: its 8 s
    showed as the quality's); the callback now hears the retry, its levels and its equalize step
    (kinds prefixed ``again ``, so the app's level marks do not count them) and the outcome."""
    _counted(monkeypatch, counts)
    heard = []
    mesh_layout(layout, levels=2, callback=lambda kind, value: heard.append((kind, value)))
    kinds = [k for k, _ in heard]
    first = kinds.index("retry")
    assert kinds[:first] == ["level"] * 3 + ["equalize"]
    assert heard[first] == ("retry", counts[0])
    assert kinds[first + 1 :] == ["again level"] * 3 + ["again equalize", "retried"]
    assert heard[-1] == ("retried", (counts[0], counts[1], kept))


def test_the_command_says_the_grid_is_made_again(tmp_path, monkeypatch):
    """The progress lines of ``meshcore mesh`` when the grid is made again: the retry, its levels,
    which grid was kept."""
    from tests.meshcore.test_mesh_cli import mesh

    f = tmp_path / "y.csv"
    ring = np.asarray(testing.y_junction().exterior.coords)[:-1] * 1000.0
    f.write_text("x,y\n" + "\n".join(f"{x:.3f},{y:.3f}" for x, y in ring) + "\n")
    said = [1, 0]

    def n_folded(grids):
        return said.pop(0) if said else 0

    monkeypatch.setattr(lakegrid, "_n_folded", n_folded)
    run = mesh(f, "--cells", 800, "-o", tmp_path / "y.vtm")
    assert run.rc == 0, run.err
    lines = run.err.splitlines()
    at = next(k for k, line in enumerate(lines) if "making it again with block corners" in line)
    assert lines[at].startswith("grid: 1 folded or non-convex cell left — making it again with block corners")
    assert re.fullmatch(r".*sliding along the shore, \d+\.\d s", lines[at])  # (timed, without the "…")
    assert sum(line.startswith("grid level ") for line in lines[:at]) == 3  # the first grid's levels
    again = [line for line in lines[at:] if line.startswith("grid made again: level ")]
    assert [line.split(" (")[0] for line in again] == [f"grid made again: level {k}/3" for k in (1, 2, 3)]
    assert again[-1].startswith("grid made again: level 3/3 (full, ")
    assert re.search(r"cells\) done, \d+ sweeps, [\d.]+ s$", again[-1])
    assert any(line.startswith("grid made again: interfaces, ") for line in lines[at:])
    kept = [line for line in lines[at:] if line.startswith("grid made again: 0 bad cells against 1 — that grid kept, ")]
    assert len(kept) == 1, lines[at:]


@pytest.mark.parametrize(
    ("kind", "value", "stopped", "words"),
    [
        ("retry", 2, False, "grid: 2 folded or non-convex cells left — making it again"),
        ("again equalize", 1, False, "grid made again: interfaces, 1 patch of cells more than 2× apart made alike"),
        ("retried", (3, 1, True), False, "grid made again: 1 bad cell against 3 — that grid kept"),
        ("retried", (2, 2, False), False, "grid made again: 2 bad cells against 2 — the first grid kept"),
        ("retried", (2, 0, False), True, "grid made again: stopped — the first grid kept (2 bad cells)"),
        ("level", (0, None), False, None),
        ("equalize", 0, False, None),
    ],
)
def test_the_words_of_a_grid_made_again(kind, value, stopped, words):
    """``meshcore mesh`` and the app said the grid made again in two wordings ("1 folded or non-convex
    cell(s) left; made again …" against "1 folded or non-convex cell left — making it again …"); both now
    take :func:`meshcore.lakegrid.retry_words` (the app's wording), the CLI adding its seconds."""
    from meshcore.lakegrid import retry_words

    said = retry_words(kind, value, ["cells ÷4", "÷2", "full"], stopped=stopped)
    if kind == "retry":
        assert said.startswith(words) and said.endswith("sliding along the shore…")
    else:
        assert said == words


def test_a_stop_during_a_level_of_the_retry_ends_it_within_every_sweeps(layout, monkeypatch):
    """The grid made again took no snapshots (``every=None``): a Stop during one of its levels waited for
    the level's end (0.7 s of the 0.9 s full level of ``dendritic(370703)`` at 15 000 cells, seconds on a
    large lake, in the app).  Now it runs with the caller's ``every`` and a Stop ends its level within as
    many sweeps."""
    import threading

    from meshcore._generators import drain
    from meshcore.lakegrid import iterate_layout
    from meshcore.orthogonal import levels

    fit_bends = levels.fit_bends

    def run(stop_at: int | None) -> list[int]:
        _counted(monkeypatch, [1, 0])
        stop, sweeps, calls = threading.Event(), [], []

        def fitted(*args, **kw):  # each level's start: the 6th is the retry's full level
            calls.append(1)
            if len(calls) == stop_at:
                stop.set()  # the user stops as its sweeps begin
            return fit_bends(*args, **kw)

        def heard(kind, value):
            if kind == "again level":
                sweeps.append(value[1].sweeps)

        monkeypatch.setattr(levels, "fit_bends", fitted)
        drain(iterate_layout(layout, levels=2, every=2, stop_event=stop, level_callback=heard))
        return sweeps

    free, stopped = run(None), run(6)
    assert len(free) == len(stopped) == 3 and free[2] > 2 and stopped[2] <= 2
