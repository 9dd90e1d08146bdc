"""benchmarks/lake_stages.py times the stages of mesh_outline by wrapping its functions: every one
it names must exist where the pipeline looks it up, and the timed run gives the untimed grid."""

from __future__ import annotations

import importlib
import importlib.util
import inspect
import json
import os
import subprocess
import sys

import pytest

from tests.conftest import ROOT


def _bench():
    spec = importlib.util.spec_from_file_location("lake_stages", ROOT / "benchmarks" / "lake_stages.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_every_stage_is_a_function_of_the_pipeline():
    for label, module, name in _bench().STAGES:
        f = getattr(importlib.import_module(module), name, None)
        assert callable(f), (label, module, name)
    # the generator stage is timed step by step: it must still be one
    assert inspect.isgeneratorfunction(importlib.import_module("meshcore.orthogonal").iterate_orthogonalize)


@pytest.mark.slow
def test_a_timed_run_gives_the_grid_and_its_stages():
    bench = _bench()
    r = bench.run_case("testing.y_junction()", 1500)
    assert "error" not in r, r
    cpu = r["cpu"]
    assert set(cpu) == {s[0] for s in bench.STAGES} | {"mesh_outline, all"}
    assert all(v >= 0.0 for v in cpu.values())
    assert cpu["layout, all"] <= cpu["mesh_outline, all"]
    code = (
        "import json; from meshcore import testing; from meshcore.lakegrid import mesh_outline;"
        "mb = mesh_outline(testing.y_junction(), target_cells=1500);"
        "print(json.dumps([len(mb.grids), sum((g.x.shape[0] - 1) * (g.x.shape[1] - 1) for g in mb.grids)]))"
    )
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, env=env, check=True)
    assert json.loads(out.stdout.strip().splitlines()[-1]) == [r["blocks"], r["cells"]]
    assert "| start grid |" in bench.table(["y"], [r])
