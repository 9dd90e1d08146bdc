"""T-junctions carried across their blocks while no cell counts exist, and the end of it
(:func:`meshcore.layout.build._make_countable`, :data:`~meshcore.layout.build.PLATEAU_ROUNDS`)."""

from __future__ import annotations

import numpy as np
import pytest

import meshcore.layout.build as build
import meshcore.layout.tjunction as tjunction
from meshcore.errors import TopologyError
from meshcore.layout.blocks import Piece


def _square(x0: float) -> Piece:
    ring = np.array([[x0, 0.0], [x0 + 1.0, 0.0], [x0 + 1.0, 1.0], [x0, 1.0]])
    return Piece(ring, (0, 1, 2, 3))


def _rigged(monkeypatch, t_counts, countable_at=None):
    """``_make_countable``'s steps replaced: after k rounds there are ``t_counts[k]`` T-junctions, a
    new piece each round (a cut carried round a ring of blocks splits one more), and counts exist
    from round ``countable_at``; returns the rounds extended."""
    rounds: list[int] = []

    def countable(pieces, h, closed=False):
        return countable_at is not None and len(rounds) >= countable_at

    def t_junctions(pieces):
        return [(0, 0)] * t_counts[min(len(rounds), len(t_counts) - 1)]

    def extend(pieces, todo=None):
        rounds.append(len(rounds))
        return [*pieces, _square(float(len(pieces)))], [np.zeros((2, 2))]

    monkeypatch.setattr(build, "_countable", countable)
    monkeypatch.setattr(tjunction, "t_junctions", t_junctions)
    monkeypatch.setattr(tjunction, "extend_t_junctions", extend)
    monkeypatch.setattr(build, "conform", lambda rings, eps: rings)
    return rounds


START = [_square(float(k)) for k in range(30)]  # 4 x 30 + 4 rounds allowed


def test_extensions_that_leave_as_many_t_junctions_give_up_after_the_plateau(monkeypatch):
    # lake_with_islands(440302) regular: 17 T-junctions from the 11th round on, 128 rounds of count
    # programs (53 s) before the choice failed; now the same failure after PLATEAU_ROUNDS such rounds
    counts = [30, 25, 20, 17] + [17] * 200
    rounds = _rigged(monkeypatch, counts)
    with pytest.raises(TopologyError, match="no cell counts agree"):
        build._make_countable(START, [], 0.1, 1.0)
    # the count last fell at round 3: the rounds after it up to the plateau are still tried
    assert len(rounds) == 3 + build.PLATEAU_ROUNDS
    assert build.PLATEAU_ROUNDS >= 4


def test_extensions_that_keep_lowering_the_t_junctions_go_on_until_counts_exist(monkeypatch):
    # the count falls every other round: each flat stretch shorter than the plateau, so the rounds
    # go on past PLATEAU_ROUNDS to the one where counts exist
    n = 3 * build.PLATEAU_ROUNDS
    counts = [2 * n - (k // 2) for k in range(n + 5)]
    rounds = _rigged(monkeypatch, counts, countable_at=n)
    pieces, cuts = build._make_countable(START, [], 0.1, 1.0)
    assert len(pieces) == len(START) + n and len(cuts) == n
    assert len(rounds) == n


def test_a_flat_stretch_shorter_than_the_plateau_does_not_stop_them(monkeypatch):
    p = build.PLATEAU_ROUNDS
    counts = [9] * p + [8] + [8] * 5
    rounds = _rigged(monkeypatch, counts, countable_at=p + 2)
    pieces, _ = build._make_countable(START, [], 0.1, 1.0)
    assert len(pieces) == len(START) + p + 2 and len(rounds) == p + 2


def _choices(monkeypatch, countable_ids):
    """``close_frames`` replaced by three closure choices (piece lists told apart by their first
    square's x) of which those in ``countable_ids`` can be counted; T-junction extensions fail
    the test."""
    choices = [[_square(10.0 * k)] for k in range(3)]
    monkeypatch.setattr(build, "close_frames", lambda pieces, sigma, **kw: iter(choices))

    def countable(pieces, h, closed=False):
        return pieces[0].ring[0, 0] / 10.0 in countable_ids

    monkeypatch.setattr(build, "_countable", countable)

    def extend(pieces, todo=None):
        raise AssertionError("a closure choice was extended")

    monkeypatch.setattr(tjunction, "extend_t_junctions", extend)
    return choices


def test_closure_choices_are_counted_as_they_are(monkeypatch):
    choices = _choices(monkeypatch, {1.0, 2.0})
    got = build._first_countable(START, ["cut"], 0.1, 1.0, 0.2, False, True, 0)
    assert got is not None and got[0] is choices[1] and got[1] == ["cut"]


def test_no_countable_closure_choice_gives_none_without_extending_any(monkeypatch):
    # session 45: the extensions cost 10-20 count programs a choice and never made one countable
    _choices(monkeypatch, set())
    assert build._first_countable(START, [], 0.1, 1.0, 0.2, False, True, 0) is None
