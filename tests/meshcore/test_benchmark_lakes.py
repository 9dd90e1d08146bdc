"""The held-out lakes in benchmarks/lakes read the same through every reader, islands included."""

from __future__ import annotations

import json

import numpy as np
import pytest
from shapely.geometry import Polygon

from meshcore.io import read_points
from tests.conftest import ROOT

LAKES = ROOT / "benchmarks" / "lakes"
NAMES = sorted(p.stem for p in LAKES.glob("*.geojson"))


def test_the_set_is_there():
    full = [n for n in NAMES if not n.endswith("_sparse")]
    assert len(full) >= 20 and all(f"{n}_sparse" in NAMES for n in full)
    islands = [n for n in full if json.loads((LAKES / f"{n}.geojson").read_text())["properties"]["islands"]]
    assert len(islands) >= 8
    assert (LAKES / "LICENSE-GSHHG-LGPL-3.0.txt").exists() and (LAKES / "LICENSE-GPL-3.0.txt").exists()


@pytest.mark.parametrize("name", NAMES)
def test_csv_geojson_kml_agree(name):
    rings = [np.array(r[:-1]) for r in json.loads((LAKES / f"{name}.geojson").read_text())["geometry"]["coordinates"]]
    poly = Polygon(rings[0], rings[1:])
    assert poly.is_valid and all(Polygon(rings[0]).contains(Polygon(r)) for r in rings[1:])
    for suffix in (".csv", ".geojson", ".kml"):
        ps = read_points(LAKES / f"{name}{suffix}")
        assert ps.crs == "EPSG:4326"
        assert len(ps) == len(rings), suffix
        for pl, ring in zip(ps, rings, strict=True):
            np.testing.assert_array_equal(pl.points, ring)
    kml = read_points(LAKES / f"{name}.kml")
    assert [pl.orientation for pl in kml] == ["ccw"] + ["cw"] * (len(rings) - 1)
