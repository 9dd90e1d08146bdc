"""The numba set-up run at import: cache location, stale-kernel purge, OpenMP wait policy."""

from __future__ import annotations

import os
import re
import subprocess
import sys

import pytest

from meshcore import _numba_setup
from tests.conftest import ROOT


def _run(code: str, timeout: float = 300, **env_changes: str | None) -> str:
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    for k, v in env_changes.items():
        if v is None:
            env.pop(k, None)
        else:
            env[k] = v
    r = subprocess.run([sys.executable, "-c", code], env=env, cwd=ROOT, capture_output=True, text=True, timeout=timeout)
    assert r.returncode == 0, r.stderr[-2000:]
    return r.stdout.strip()


def test_waiting_threads_sleep_unless_the_user_chose():
    code = "import os, meshcore; print(os.environ.get('OMP_WAIT_POLICY'))"
    assert _run(code, OMP_WAIT_POLICY=None, GOMP_SPINCOUNT=None) == "passive"
    assert _run(code, OMP_WAIT_POLICY="active", GOMP_SPINCOUNT=None) == "active"
    assert _run(code, OMP_WAIT_POLICY=None, GOMP_SPINCOUNT="1000") == "None"


def test_cached_kernels_are_removed_when_a_kernel_module_changes(tmp_path, monkeypatch):
    stamp = ["v1"]
    monkeypatch.setattr(_numba_setup, "cache_dirs", lambda: [tmp_path])
    monkeypatch.setattr(_numba_setup, "_stamp", lambda: stamp[0])
    kernel = tmp_path / "_mg_relax.smooth-10.py311.nbi"
    data = tmp_path / "_mg_relax.smooth-10.py311.1.nbc"
    other = tmp_path / "somebody_else.f-3.py311.nbi"
    pyc = tmp_path / "_mg_relax.cpython-311.pyc"
    for f in (kernel, data, other, pyc):
        f.write_bytes(b"x")
    _numba_setup._purge_stale()  # no stamp recorded yet: purge
    assert not kernel.exists() and not data.exists()
    empty = tmp_path / "new"  # a cache directory numba has not created yet gets the stamp
    monkeypatch.setattr(_numba_setup, "cache_dirs", lambda: [tmp_path, empty])
    _numba_setup._purge_stale()
    assert (empty / _numba_setup.STAMP_NAME).read_text() == "v1"
    assert other.exists() and pyc.exists()
    kernel.write_bytes(b"x")  # compiled again with the current sources
    _numba_setup._purge_stale()
    assert kernel.exists()
    stamp[0] = "v2"  # a kernel module changed
    _numba_setup._purge_stale()
    assert not kernel.exists() and other.exists()


def test_the_stamp_covers_every_module_with_kernels():
    """Every module that defines numba kernels is listed (an edit of it must purge the cache)."""
    listed = {str(ROOT / "meshcore" / m) for m in _numba_setup.KERNEL_MODULES}
    pattern = re.compile(r"^from numba import .*\bnjit\b", re.M)
    with_kernels = {str(p) for p in (ROOT / "meshcore").rglob("*.py") if pattern.search(p.read_text(encoding="utf-8"))}
    assert with_kernels <= listed, sorted(with_kernels - listed)


def test_the_side_by_side_compile_copies_into_the_directories_numba_reads(tmp_path):
    """:func:`compile_all`'s second process compiles into a cache of its own whose package
    directories are copied into ours (:func:`_package_dirs`): they are where numba itself reads
    and writes each package's kernels, with and without ``NUMBA_CACHE_DIR``."""
    code = (
        "import os\n"
        "from meshcore import _numba_setup as s\n"
        "from meshcore.elliptic import _mg_relax\n"
        "from meshcore.foldfree import _sweep\n"
        "from meshcore.layout import _corner_kernels\n"
        "from meshcore.multiblock import _kernels as mb\n"
        "from meshcore.orthogonal import _kernels as ok\n"
        "kernels = {'elliptic': _mg_relax._relax_range, 'foldfree': _sweep.fast_sweep,\n"
        "           'layout': _corner_kernels.ring_terms, 'multiblock': mb.table_defect, 'orthogonal': ok.sweep}\n"
        "ours = s._package_dirs(os.environ.get('NUMBA_CACHE_DIR'))\n"
        "bad = [p for p, k in kernels.items() if os.path.abspath(k._cache._cache_path) != os.path.abspath(ours[p])]\n"
        "print(sorted(ours) == sorted(kernels), bad)\n"
    )
    assert _run(code, NUMBA_CACHE_DIR=str(tmp_path)) == "True []"
    assert _run(code, NUMBA_CACHE_DIR=None) == "True []"


def test_a_kernel_compiled_in_the_process_gives_what_the_cached_one_gives(tmp_path):
    """The same input gives the same grid whether the kernels were compiled by the running process
    or loaded from numba's cache (an emptied or new cache, a kernel edit, a temp cache wiped at a
    reboot).  The fold-free sweeps with ``fastmath`` ``reassoc`` did not: a repair compiled in the
    process and the same repair loaded came out different in the last bits, and a lake's grid
    amplified that into another grid (session 49)."""
    code = (
        "import hashlib, numpy as np, meshcore\n"
        "from meshcore.foldfree import repair\n"
        "X, Y = np.meshgrid(np.linspace(0, 2, 13), np.linspace(0, 1, 9), indexing='ij')\n"
        "X = X + 0.03 * np.sin(7 * Y) * np.sin(3 * X)\n"
        "Y = Y + 0.02 * np.cos(5 * X)\n"
        "X[5, 4], Y[5, 4] = X[8, 5], Y[8, 5]\n"
        "X[9, 2] = X[7, 2]\n"
        "r = repair(meshcore.StructuredGrid(X, Y), strict=False)\n"
        "assert meshcore.quality(r.grid).n_folded == 0\n"
        "print(hashlib.sha1(r.grid.x.tobytes() + r.grid.y.tobytes()).hexdigest())\n"
    )
    env = {"NUMBA_CACHE_DIR": str(tmp_path)}
    compiled = _run(code, **env)  # an empty cache: compiled here (and written)
    loaded = _run(code, **env)  # loaded
    assert compiled == loaded


@pytest.mark.slow
def test_after_compile_all_a_new_process_compiles_nothing(tmp_path):
    """The set-up step compiles every kernel the solvers use: in a new process (same cache)
    single-block (serial, parallel, periodic, P/Q, SOR), multiblock, fold-free and lake-grid solves
    load every kernel from the cache (numba counts a compilation as a cache miss)."""
    env = {"NUMBA_CACHE_DIR": str(tmp_path)}
    _run("from meshcore._numba_setup import compile_all; compile_all()", timeout=1800, **env)
    code = (
        "import importlib, numpy as np, meshcore\n"
        "from numba.core.registry import CPUDispatcher\n"
        "from meshcore import _numba_setup as s\n"
        "from meshcore.foldfree import repair\n"
        "t = np.linspace(0, 1, 129)\n"
        "b = [np.c_[t, 0.1 * np.sin(2 * np.pi * t)], np.c_[1 + 0 * t, t], np.c_[t, 1 + 0 * t], np.c_[0 * t, t]]\n"
        "for th in (0, 1, 2):\n"
        "    g = meshcore.generate_block(*b, threads=th)\n"
        "    meshcore.generate_block(*b, threads=th, p=0.1 * np.ones(g.x.shape))\n"
        "    meshcore.generate_block(*b, threads=th, method='sor', max_iterations=5)\n"
        "th = np.linspace(0, -2 * np.pi, 65)\n"
        "inner, outer = np.c_[np.cos(th), np.sin(th)], np.c_[3 * np.cos(th), 3 * np.sin(th)]\n"
        "cut = np.c_[np.linspace(1, 3, 17), 0 * np.linspace(1, 3, 17)]\n"
        "meshcore.generate_block(inner, cut, outer, cut, periodic=True)\n"
        "X, Y = np.meshgrid(np.linspace(0, 2, 9), np.linspace(0, 1, 9), indexing='ij')\n"
        "X[4, 4] = X[6, 4]\n"
        "repair(meshcore.StructuredGrid(X, Y), strict=False)\n"
        "from meshcore.case import load_case, generate_case\n"
        "generate_case(load_case(s._ROOT.parent / 'resources/examples/confluence-multiblock.toml'))\n"
        "from meshcore.lakegrid import mesh_outline\n"
        "mesh_outline([(0, 0), (9, 0), (9, 3), (3, 3), (3, 8), (0, 8)], target_cells=300)\n"
        "missed = []\n"
        "for rel in s.KERNEL_MODULES:\n"
        "    name = 'meshcore.' + rel[:-3].replace('/', '.')\n"
        "    try:\n"
        "        mod = importlib.import_module(name)\n"
        "    except ModuleNotFoundError:\n"
        "        continue\n"
        "    for k, f in vars(mod).items():\n"
        "        if isinstance(f, CPUDispatcher) and f.stats.cache_misses:\n"
        "            missed.append(f'{name}.{k}{list(f.stats.cache_misses)}')\n"
        "print(' '.join(sorted(set(missed))) or 'none')\n"
    )
    assert _run(code, timeout=900, **env) == "none"
