"""Inputs from the session-19 hostile sweep that failed on main: each gives exit 2 and one
line naming the file and the problem — no traceback, no output file, nothing silently wrong."""

from __future__ import annotations

import pytest

from meshcore.cli import main
from tests.conftest import ROOT

BOTTLE = ROOT / "resources" / "examples" / "bottle-coarse.toml"


def _bad(capsys, argv, *needles):
    rc = main([str(a) for a in argv])
    err = capsys.readouterr().err
    assert rc == 2, err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    for n in needles:
        assert n in err, (n, err)
    return err


@pytest.mark.parametrize(
    "text",
    [
        "a = " + "[" * 5000 + "]" * 5000 + "\n",  # RecursionError in tomllib: exit 1 "internal error"
        "a = " + "{b = " * 3000 + "1" + "}" * 3000 + "\n",
    ],
)
def test_a_case_nested_too_deep_is_a_clear_error(tmp_path, capsys, text):
    case, out = tmp_path / "case.toml", tmp_path / "out.vts"
    case.write_text(text)
    _bad(capsys, ["generate", case, "-o", out, "-q"], "case.toml", "nested too deep")
    assert not out.exists()


@pytest.mark.parametrize("origin", ["[nan, 0.0]", "[0.0, inf]", "[1e300, 0.0]"])
def test_a_case_origin_that_is_not_a_finite_number_is_refused(tmp_path, capsys, origin):
    # nan was accepted: every coordinate written was nan (exit 0)
    case, out = tmp_path / "case.toml", tmp_path / "out.vts"
    case.write_text(BOTTLE.read_text() + f'\n[crs]\norigin = {origin}\ncrs = "EPSG:32632"\n')
    _bad(capsys, ["generate", case, "-o", out, "-q"], "case.toml", "origin")
    assert not out.exists()
