"""benchmarks/robust.py --out reruns some sections of RESULTS.md: their tables change, what each
session wrote there stays (a rerun deleted every session's paragraphs of the sections it ran)."""

from __future__ import annotations

from tests.conftest import benchmark_module


def _robust():
    return benchmark_module("robust")


OLD = """### Busy machine (257²)

| load | ratio |
|---|---|
| idle | 2.23 |

(Run old.)

Session 9 (x): measured this.

Session 12: and that.

### First solve in a new environment

| step | total |
|---|---|
| set-up | 109 |

Session 14: kept as it was.

### Issue 15 targets in this run

| target | wanted | measured |
|---|---|---|
| 257², one busy process | ≤ 1.2 | 0.48 |
| first solve | ≤ 2 s | 1.99 s |"""


def test_a_rerun_replaces_the_tables_and_keeps_the_sessions_notes():
    robust = _robust()
    new = ["### Busy machine (257²)", "", "| load | ratio |", "|---|---|", "| idle | 1.25 |", "", "(Run new.)"]
    out = robust.merge_report(OLD, ["## Issue 15"], {"busy": new}, ["| 257², one busy process | ≤ 1.2 | 0.97 |"])
    busy = out.split("### First solve")[0]
    assert "| idle | 1.25 |" in busy and "2.23" not in busy and "(Run new.)" in busy and "(Run old.)" not in busy
    assert busy.index("(Run new.)") < busy.index("Session 9 (x): measured this.") < busy.index("Session 12: and that.")
    assert "| set-up | 109 |" in out and "Session 14: kept as it was." in out  # a section not rerun: as it was
    assert (
        "| 257², one busy process | ≤ 1.2 | 0.97 |" in out
        and "0.48" not in out
        and "| first solve | ≤ 2 s | 1.99 s |" in out
    )
