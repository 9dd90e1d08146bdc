"""A stop asked of :func:`meshcore.layout.auto_layout` (``stop_event``) is heard between the stages of a draw
and between draws (:mod:`meshcore.layout.stopping`); before, the app's Stop was heard only at the layout
choice's first coarse reading, ~4 s after the start on Vänern at 10 000 cells (five draws)."""

from __future__ import annotations

import threading

import pytest

from meshcore import testing
from meshcore.errors import MeshcoreError, Stopped
from meshcore.layout import auto_layout


class StopAt:
    """A stop event that is set from its ``n``-th look on (``looks``: how often it was looked at)."""

    def __init__(self, n: int) -> None:
        self.n, self.looks = n, 0

    def is_set(self) -> bool:
        self.looks += 1
        return self.looks >= self.n


@pytest.fixture(scope="module")
def water():
    return testing.lake_with_islands(1)


def _drawn(monkeypatch) -> list:
    """The draws of the layout (:func:`meshcore.layout.build.layout_pieces` calls) as they are made."""
    import meshcore.layout as lay

    drawn, real = [], lay.layout_pieces

    def spy(*a, **kw):
        drawn.append(kw.get("ring"))
        return real(*a, **kw)

    monkeypatch.setattr(lay, "layout_pieces", spy)
    return drawn


@pytest.mark.parametrize("n", [1, 2, 5])
def test_a_stop_set_at_a_check_before_the_first_reading_ends_the_layout_there(water, monkeypatch, n):
    """The stop set at the ``n``-th check (1: the first, before anything is drawn): :class:`Stopped` at that
    check (not looked at again), no coarse reading taken, no layout."""
    drawn, read = _drawn(monkeypatch), []
    stop = StopAt(n)
    with pytest.raises(Stopped):
        auto_layout(
            water, target_cells=3000, multiple=8, reading=lambda lay: read.append(lay) or (1.0, 1.0), stop_event=stop
        )
    assert stop.looks == n and read == []
    assert drawn == [] if n == 1 else len(drawn) <= 1  # (the first draw has more checks than 5)


def test_a_stop_between_the_choice_s_draws_is_not_taken_for_a_draw_that_failed(water, monkeypatch):
    """The layout choice passes over a draw that raises a :class:`~meshcore.errors.MeshcoreError`; a stop
    is none (:class:`Stopped` is not one): set during the first coarse reading, the next draw (another
    scale) ends the layout instead of being passed over."""
    assert not issubclass(Stopped, MeshcoreError)
    drawn, stop, read = _drawn(monkeypatch), threading.Event(), []

    def reading(lay):
        read.append(lay)
        stop.set()  # the user stops while the first layout's coarse grid is read
        return 1.0, 1.0

    with pytest.raises(Stopped):
        auto_layout(water, target_cells=3000, multiple=8, reading=reading, stop_event=stop)
    assert len(read) == 1 and len(drawn) == 1  # the draw at the cell size, read; no other scale drawn


def test_a_stop_event_never_set_changes_nothing(water):
    plain = auto_layout(water, target_cells=3000, multiple=8)
    stop = StopAt(10**9)
    watched = auto_layout(water, target_cells=3000, multiple=8, stop_event=stop)
    assert watched.blocks == plain.blocks and stop.looks > 5
