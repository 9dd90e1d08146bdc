"""The numba kernels run as plain Python (``NUMBA_DISABLE_JIT=1``) against their NumPy references.

Every test marked ``kernel`` compares a compiled kernel with a NumPy reference
(:mod:`meshcore.elliptic._reference`, dense transfer operators, the multiblock
and fold-free references).  Here the same tests run with the JIT off, in a
separate interpreter (the switch is read when numba is imported): the kernels'
Python source is then what runs, so a coverage tool or a debugger sees it, and
a difference between the compiled and the interpreted kernel (an integer
overflow, a typing surprise) shows up as a failure here and not there.
"""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from tests.conftest import ROOT


@pytest.mark.slow
def test_kernel_tests_pass_with_the_jit_off():
    env = dict(os.environ, NUMBA_DISABLE_JIT="1", PYTHONPATH=str(ROOT))
    cmd = [sys.executable, "-m", "pytest", "-q", "-rA", "-p", "no:cacheprovider", "-m", "kernel", "tests/meshcore"]
    r = subprocess.run(cmd, cwd=ROOT, env=env, capture_output=True, text=True, timeout=1200)
    assert r.returncode == 0, r.stdout[-4000:] + r.stderr[-2000:]
    # the tier covers every package with numba kernels
    for module in ("test_elliptic", "test_multigrid", "test_multiblock", "test_foldfree", "test_corner_kernels"):
        assert f"PASSED tests/meshcore/{module}.py::" in r.stdout, module
