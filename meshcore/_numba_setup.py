"""Make numba's on-disk cache work in read-only installs.

numba caches compiled kernels next to the source (``__pycache__``).  When the
package directory is not writable numba falls back to ``$HOME/.cache/numba``;
when neither is writable, ``@njit(cache=True)`` makes the *import* fail
("no locator available").  Before any kernel module is imported we therefore
check, and if needed point ``NUMBA_CACHE_DIR`` at a writable directory
(``$XDG_CACHE_HOME/gcmesh-numba``, ``~/.cache/gcmesh-numba`` or the system temp
directory).  A user-set ``NUMBA_CACHE_DIR`` is always respected.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path


def _writable(d: Path) -> bool:
    try:
        d.mkdir(parents=True, exist_ok=True)
        probe = d / f".gcmesh-probe-{os.getpid()}"
        probe.write_bytes(b"")
        probe.unlink()
        return True
    except OSError:
        return False


def cache_dir() -> str:
    """The directory numba uses for meshcore's compiled kernels."""
    env = os.environ.get("NUMBA_CACHE_DIR")
    if env:
        return env
    return str(Path(__file__).parent / "elliptic" / "__pycache__")


def _configure() -> None:
    if os.environ.get("NUMBA_CACHE_DIR"):
        return
    if _writable(Path(__file__).parent / "elliptic" / "__pycache__"):
        return
    candidates = []
    if os.environ.get("XDG_CACHE_HOME"):
        candidates.append(Path(os.environ["XDG_CACHE_HOME"]) / "gcmesh-numba")
    home = os.environ.get("HOME")
    if home:
        candidates.append(Path(home) / ".cache" / "gcmesh-numba")
    candidates.append(Path(tempfile.gettempdir()) / f"gcmesh-numba-{os.getuid() if hasattr(os, 'getuid') else 0}")
    for c in candidates:
        if _writable(c):
            os.environ["NUMBA_CACHE_DIR"] = str(c)
            try:  # numba may already be imported: update its live config too
                import numba.core.config as cfg

                cfg.CACHE_DIR = str(c)
            except Exception:  # pragma: no cover - numba internals
                pass
            return


_configure()
