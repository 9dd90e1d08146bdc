"""benchmarks/robust.py keeps a section's session notes, every paragraph of them, when a rerun replaces its tables."""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))

import robust


def test_a_rerun_keeps_every_paragraph_of_the_session_notes():
    old = (
        "## head\n\n### The app against the CLI (same case, same run)\n\nold text\n\n| a |\n|---|\n| 1 |\n\n"
        "(Run old.)\n\nSession 16 (x): found.\n\nChanged: this.\n\n| b |\n|---|\n| 2 |\n\nSession 31: more.\n"
    )
    new = robust.merge_report(old, [], {"app": ["### The app against the CLI (same case, same run)", "", "new"]}, [])
    assert "old text" not in new and "| 1 |" not in new and "new" in new
    for kept in ("Session 16 (x): found.", "Changed: this.", "| 2 |", "Session 31: more."):
        assert kept in new
