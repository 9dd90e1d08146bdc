"""What one :func:`~meshcore.layout.auto_layout` call remembers between its draws.

The layout choice draws a lake several times (:mod:`.choice`); its tip draw (:mod:`.tipcuts`)
repeats the draw at the chosen scale with the pieces round land tips split, so the skeleton, the
chords, the partition and the region splits of that draw (:mod:`.build`) and the tip splits are made
once and remembered here, and so are the cell counts of pieces counted again (:func:`.blocks._solved`),
within :func:`remembering` only: a module option changed between calls (or by a
test) is read again.  Callers get copies (:func:`copied`) of what is kept.
"""

from __future__ import annotations

import contextlib
import contextvars
import hashlib

import numpy as np

__all__ = ["copied", "digest", "remembered", "remembering", "watching"]

_memo: contextvars.ContextVar[dict | None] = contextvars.ContextVar("layout_memo", default=None)


@contextlib.contextmanager
def remembering():
    """Within this context (one :func:`~meshcore.layout.auto_layout` call) the draws remember
    their skeletons, chords and region splits (:func:`.build._skeleton_and_chords`, :func:`.build._split_region`)
    and :mod:`.tipcuts` its tip splits: the layout choice's tip draw repeats the draw at its scale.
    Kept for the call only, so that a module option changed between calls (or by a test) is read."""
    token = _memo.set({})
    try:
        yield
    finally:
        _memo.reset(token)


def remembered(key: tuple, make):
    """``make()``, remembered under ``key`` within :func:`remembering` (else made each time)."""
    memo = _memo.get()
    if memo is None:
        return make()
    if key not in memo:
        memo[key] = make()
    return memo[key]


def copied(split):
    """``(pieces, cuts)`` (``(ring, forced)`` and arrays) copied: what :func:`remembered` keeps
    stays as it was made."""
    pieces, cuts = split
    return [(np.array(p), tuple(np.array(q) if isinstance(q, np.ndarray) else q for q in f)) for p, f in pieces], [
        np.array(c) for c in cuts
    ]


def digest(*parts) -> bytes:
    """A 128-bit digest of ``parts`` (bytes, or arrays taken as contiguous float64): a key's
    geometry for :func:`remembered`."""
    raw = [p if isinstance(p, bytes) else np.ascontiguousarray(p, dtype=float).tobytes() for p in parts]
    return hashlib.blake2b(b"|".join(raw), digest_size=16).digest()


@contextlib.contextmanager
def watching(var: contextvars.ContextVar):
    """Yields a new list set as ``var`` within this context: what a draw made within it notes
    there (a draw's pieces with a land tip, :func:`.tipcuts.watching_tips`; whether a piece bulges
    or tapers, :func:`.fans.watching_unsplit`), for the layout choice to skip a draw that would
    change nothing."""
    box: list = []
    token = var.set(box)
    try:
        yield box
    finally:
        var.reset(token)
