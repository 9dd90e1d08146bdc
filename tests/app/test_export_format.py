"""The export dialog's chosen filter picks the writer when two formats share a suffix (.grd)."""

from __future__ import annotations

from pathlib import Path

from app.io_adapter import mesh_formats
from app.io_export import chosen_format


def _filter(name: str) -> str:
    d, p = next((d, p) for d, p in mesh_formats() if d.endswith(f"[{name}]"))
    return f"{d} ({p})"


def test_a_grd_goes_to_the_format_chosen():
    assert chosen_format(_filter("delft3d-single"), Path("lake.grd")) == "delft3d-single"
    assert chosen_format(_filter("delft3d"), Path("lake.grd")) == "delft3d"


def test_the_suffix_decides_elsewhere():
    assert chosen_format(_filter("vtm"), Path("lake.vtm")) is None  # one format has .vtm
    assert chosen_format(_filter("delft3d-single"), Path("lake.vtm")) is None  # typed another suffix
    assert chosen_format(_filter("efdc"), Path("run/cell.inp")) is None
