"""Chords that graze a land tip (:func:`meshcore.layout.chords.place_chords`, :data:`~.chords.TIP_GAP`).

A chord passing a cell from a sharp land tip leaves the block beyond it wrapped round the tip in a
sliver whose side bends by the tip's whole turn: a non-convex cell from the coarsest level on (Saimaa
at 10 000 cells: the one folded cell of the grid).  With ``AVOID_TIPS`` (off: measured mixed) such
chord positions are not taken."""

from __future__ import annotations

import math

import numpy as np
import pytest

from meshcore import testing
from meshcore.layout.build import skeleton
from meshcore.layout.chords import TIP_GAP, TIP_TURN, place_chords
from meshcore.layout.corners import _arclength_closed, turning
from meshcore.layout.shore import shore_at_scale
from meshcore.segments import feet


def _tips(poly, sigma):
    """Every shore vertex where the water turns right by more than TIP_TURN at scale ``sigma``."""
    out = []
    for ring in [np.asarray(poly.exterior.coords)[:-1], *(np.asarray(h.coords)[:-1] for h in poly.interiors)]:
        t = turning(ring, sigma, _arclength_closed(ring))
        out += list(ring[t < -TIP_TURN])
    return np.asarray(out).reshape(-1, 2)


SHAPES = {
    "lake_with_islands(861507, n_islands=8)": lambda: testing.lake_with_islands(861507, n_islands=8),
    "lake_with_islands(861506, n_islands=7)": lambda: testing.lake_with_islands(861506, n_islands=7),
    "headlands(861506)": lambda: testing.headlands(861506),
    "channel_network(861508, n_branches=5)": lambda: testing.channel_network(861508, n_branches=5),
}


@pytest.mark.parametrize("name", list(SHAPES))
def test_no_chord_passes_close_by_a_land_tip(name, monkeypatch):
    from meshcore.layout import chords as chords_module

    monkeypatch.setattr(chords_module, "AVOID_TIPS", True)
    poly = SHAPES[name]()
    h = math.sqrt(poly.area / 15000)
    water = shore_at_scale(poly, h).layout
    sk = skeleton(water, spacing=h / 2, prune=0.5, min_arm=3 * h)
    chords = place_chords(water, sk, min_length=2 * h)
    tips = _tips(water, 1.5 * h)
    assert len(chords) and len(tips)
    for c in chords:
        a, b = np.asarray(c.points, dtype=float)
        dist, _ = feet(np.repeat(a[None], len(tips), 0), np.repeat(b[None], len(tips), 0), tips)
        off_ends = np.minimum(np.hypot(*(tips - a).T), np.hypot(*(tips - b).T)) > 0.5 * h
        assert not np.any((dist < TIP_GAP * h) & off_ends), (c.kind, c.points)
