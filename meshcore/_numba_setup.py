"""Where numba caches meshcore's compiled kernels, and keeping that cache consistent.

numba caches compiled kernels on disk: next to the source
(``meshcore/<package>/__pycache__/*.nbi, *.nbc``) or, when ``NUMBA_CACHE_DIR``
is set, in ``$NUMBA_CACHE_DIR/<package>_<hash of its path>/``.  This module
runs before any kernel module is imported and does two things:

* **Read-only installs.**  When the package directory is not writable numba
  falls back to ``$HOME/.cache/numba``; when neither is writable,
  ``@njit(cache=True)`` makes the *import* fail ("no locator available").  We
  therefore check, and if needed point ``NUMBA_CACHE_DIR`` at a writable
  directory (``$XDG_CACHE_HOME/gcmesh-numba``, ``~/.cache/gcmesh-numba`` or the
  system temp directory).  A user-set ``NUMBA_CACHE_DIR`` is always respected.
* **Stale kernels.**  numba keys each cached function on its *own* source
  file only, but meshcore's kernels inline functions from other files (the
  one Winslow stencil, :mod:`meshcore.elliptic._stencil`).  After an edit of
  such a file numba would load kernels compiled with the old code.  The stamp
  (modification time and size) of every kernel module is recorded next to the
  cache (``gcmesh-kernels.stamp``); when it changes, the cached kernels of all
  of them are removed and compile again on first use.

* **Threads on a busy machine.**  numba's OpenMP threads spin while they wait
  at the end of a parallel loop (libgomp's default); when another process
  wants a core, the spinning thread and the one it waits for share it, and a
  solve with two threads took 9–14× as long as with one (measured: 257² with
  two threads under load).  Unless the user set ``OMP_WAIT_POLICY`` or
  ``GOMP_SPINCOUNT``, waiting threads sleep (``OMP_WAIT_POLICY=passive``,
  read when numba first loads its OpenMP layer): under load two threads then
  cost about as much as one, and on an idle machine they still gain.

``scripts/setup.sh`` compiles every kernel once (:func:`compile_all`),
so that the first solve in a new environment loads them instead of compiling.

Runs are reproducible with or without it: a kernel compiled in the running process computes what
the same kernel loaded from the cache computes (tested).  The fold-free repair's sweeps
(:mod:`meshcore.foldfree._sweep`) were compiled with ``fastmath`` ``reassoc`` until session 49,
and then did not: a lake's first run in a process that compiled them came out different from
every later run (a 5 × 6 block's repair differed in the last bits, and the lake's whole grid with
it); they keep the other fast-math flags (:data:`meshcore.foldfree._kernels._FM`).
"""

from __future__ import annotations

import hashlib
import os
import tempfile
from pathlib import Path

__all__ = ["KERNEL_MODULES", "cache_dir", "cache_dirs", "compile_all"]

_ROOT = Path(__file__).parent

#: Every module with numba kernels (relative to the package): they call each other.
KERNEL_MODULES = (
    "elliptic/_stencil.py",
    "elliptic/_compile.py",
    "elliptic/_kernels.py",
    "elliptic/_mg_relax.py",
    "elliptic/_mg_defect.py",
    "elliptic/_mg_transfer.py",
    "elliptic/_mg_fused.py",
    "elliptic/_mg_lines.py",
    "elliptic/_mg_control.py",
    "elliptic/_mg_wake.py",
    "multiblock/_kernels.py",
    "multiblock/_mg_fused.py",
    "multiblock/_hier_kernels.py",
    "multiblock/_start_kernels.py",
    "foldfree/_kernels.py",
    "foldfree/_sweep.py",
    "orthogonal/_kernels.py",
    "orthogonal/_equalize_kernels.py",
    "orthogonal/_bfgs.py",
    "layout/_corner_kernels.py",
)
STAMP_NAME = "gcmesh-kernels.stamp"


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
    """The directory numba uses for the single-block solver's compiled kernels."""
    return str(cache_dirs()[0])


def cache_dirs() -> list[Path]:
    """The cache directory of each package with kernels (numba's own rule, see above)."""
    dirs = _package_dirs(os.environ.get("NUMBA_CACHE_DIR"))
    return [dirs["elliptic"], *(d for pkg, d in dirs.items() if pkg != "elliptic")]


def _stamp() -> str:
    parts = []
    for rel in KERNEL_MODULES:
        try:
            st = (_ROOT / rel).stat()
        except OSError:
            continue
        parts.append(f"{rel}:{st.st_mtime_ns}:{st.st_size}")
    return hashlib.sha1("|".join(parts).encode()).hexdigest()


def _purge_stale() -> None:
    """Remove cached kernels compiled from other versions of the kernel modules."""
    stamp = _stamp()
    stems = {Path(m).stem for m in KERNEL_MODULES}
    for d in cache_dirs():
        marker = d / STAMP_NAME
        try:
            if marker.read_text() == stamp:
                continue
        except OSError:
            pass
        try:
            d.mkdir(parents=True, exist_ok=True)  # numba fills it with kernels of these sources
            for f in d.iterdir():
                if f.suffix in (".nbi", ".nbc") and f.name.split(".", 1)[0] in stems:
                    f.unlink(missing_ok=True)
            marker.write_text(stamp)
        except OSError:  # read-only cache: numba recompiles in memory if needed
            pass


def _configure() -> None:
    if os.environ.get("NUMBA_CACHE_DIR"):
        return
    if _writable(_ROOT / "elliptic" / "__pycache__"):
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


def _wait_policy() -> None:
    if "OMP_WAIT_POLICY" not in os.environ and "GOMP_SPINCOUNT" not in os.environ:
        os.environ["OMP_WAIT_POLICY"] = "passive"


#: The parts of :func:`compile_all`, compiled side by side in processes of their own (numba compiles
#: in one thread): the single-block solver's kernels (``meshcore.elliptic``), and the rest (which
#: call the elliptic kernels too): about equal halves of the work.
PARTS = ("elliptic", "rest")


def compile_all(jobs: int | None = None) -> float:
    """Compile (or load from the cache) every numba kernel once; returns the seconds taken.

    ``scripts/setup.sh`` runs this, so that the first solve in a new environment loads compiled
    kernels instead of compiling them (89 s in one process on a quiet 2-core machine, 50 s in two).
    With more than one core (or ``jobs`` > 1) and a cold cache the two :data:`PARTS` first compile
    side by side: the elliptic part into the cache, the rest into a cache of its own whose kernels of
    the other packages are then copied in (two processes saving overloads of one kernel into one cache
    can leave its index naming the other's data file: numba's cache has no lock).  Then this process
    runs every part, loading what is cached and compiling what is not.  ``jobs=1``: all in this
    process.
    """
    import time

    t0 = time.perf_counter()
    if jobs is None:
        try:
            jobs = len(os.sched_getaffinity(0))
        except AttributeError:  # pragma: no cover - not Linux
            jobs = os.cpu_count() or 1
    if jobs > 1 and not _warm():
        try:
            _compile_side_by_side()
        except OSError:  # (no temporary directory, say): all in this process
            pass
    for part in PARTS:
        _compile_part(part)
    return time.perf_counter() - t0


def _package_dirs(base: str | None) -> dict[str, Path]:
    """Each kernel package's cache directory under ``NUMBA_CACHE_DIR`` = ``base`` (None: the
    packages' ``__pycache__``), numba's rule: ``base/<package>_<sha1 of its path>``."""
    out = {}
    for pkg in sorted({Path(m).parent.name for m in KERNEL_MODULES}):
        src = _ROOT / pkg
        digest = hashlib.sha1(os.path.abspath(src).encode()).hexdigest()
        out[pkg] = Path(base) / f"{src.name}_{digest}" if base else src / "__pycache__"
    return out


def _warm() -> bool:
    """Whether a package other than the elliptic one has kernels cached already."""
    dirs = _package_dirs(os.environ.get("NUMBA_CACHE_DIR"))
    return any(any(d.glob("*.nbi")) for pkg, d in dirs.items() if pkg != "elliptic" and d.is_dir())


def _compile_side_by_side() -> None:
    """:data:`PARTS` compiled in two processes (see :func:`compile_all`); a part that fails leaves
    its kernels to this process."""
    import shutil
    import subprocess
    import sys

    path = os.pathsep.join(filter(None, [str(_ROOT.parent), os.environ.get("PYTHONPATH")]))
    code = "import sys; from meshcore._numba_setup import _compile_part; _compile_part(sys.argv[1])"
    with tempfile.TemporaryDirectory(prefix="gcmesh-kernels-") as own:
        envs = [dict(os.environ, PYTHONPATH=path), dict(os.environ, PYTHONPATH=path, NUMBA_CACHE_DIR=own)]
        procs = []
        try:
            for part, env in zip(PARTS, envs, strict=True):
                quiet = subprocess.DEVNULL
                procs.append(subprocess.Popen([sys.executable, "-c", code, part], env=env, stdout=quiet, stderr=quiet))
            for proc in procs:
                proc.wait()
        except OSError:  # no second process: all in this one
            return
        finally:
            for proc in procs:  # (an interrupt: no compiler left behind)
                if proc.poll() is None:
                    proc.kill()
        ours = _package_dirs(os.environ.get("NUMBA_CACHE_DIR"))
        try:
            for pkg, d in _package_dirs(own).items():
                if pkg == "elliptic" or not d.is_dir():
                    continue
                ours[pkg].mkdir(parents=True, exist_ok=True)
                for f in d.iterdir():
                    if f.suffix in (".nbi", ".nbc"):
                        tmp = ours[pkg] / f".{f.name}.{os.getpid()}"
                        shutil.copyfile(f, tmp)
                        os.replace(tmp, ours[pkg] / f.name)
        except OSError:  # a cache we cannot write: what is missing compiles in this process
            pass


def _compile_part(part: str) -> None:
    """Run the solves of one of :data:`PARTS` once (their kernels compiled or loaded)."""
    import numpy as np

    if part == "elliptic":
        from .elliptic import warmup

        warmup(multigrid=True, parallel=True)
        return
    if part != "rest":
        raise ValueError(f"no such part: {part!r} (one of {PARTS})")
    from .foldfree import repair, smooth
    from .grid import StructuredGrid
    from .multiblock import solve_multiblock
    from .multiblock.topology import Block, Interface, MultiBlockTopology, Side

    s = np.linspace(0.0, 1.0, 9)
    X, Y = np.meshgrid(2.0 * s, s, indexing="ij")
    Y = Y + 0.05 * np.sin(np.pi * X) * np.sin(np.pi * Y)
    folded = X.copy()
    folded[4, 4] = X[6, 4]  # one node pushed past its neighbour: folded cells
    g = StructuredGrid(folded, Y)
    repair(g, strict=False)
    smooth(g, strict=False, max_sweeps=20)
    # a fold whose patch is small enough to be tried: the untangling loop (its own kernel)
    s17 = np.linspace(0.0, 1.0, 17)
    X17, Y17 = np.meshgrid(2.0 * s17, s17, indexing="ij")
    X17[8, 8] = X17[10, 8]
    repair(StructuredGrid(X17, Y17), strict=False)

    def block(name, a, b):
        from .boundary import Borders

        return Block(name, Borders(bottom=np.c_[a[:, 0], b[:, 0]], right=np.c_[a[-1], b[-1]],
                                   top=np.c_[a[:, -1], b[:, -1]], left=np.c_[a[0], b[0]]))  # fmt: skip

    topo = MultiBlockTopology(
        (block("a", X[:5], Y[:5]), block("b", X[4:], Y[4:])), (Interface(Side("a", "right"), Side("b", "left")),)
    )
    for engine in ("multigrid", "blocks", "table"):
        solve_multiblock(topo, engine=engine, max_iterations=3)
    try:  # three blocks meeting at a node (the irregular-node kernels)
        from .case import generate_case, load_case
        from .cli.examples import example_path

        generate_case(load_case(example_path("confluence-multiblock")))
    except Exception:  # pragma: no cover - examples not installed
        pass
    from .lakegrid import mesh_outline  # the orthogonal smoother of `meshcore mesh`

    mesh_outline([(0.0, 0.0), (6.0, 0.0), (6.0, 2.0), (2.0, 2.0), (2.0, 5.0), (0.0, 5.0)], target_cells=200)
    from .orthogonal.equalize import warm_up  # its step runs only where cells across a cut differ 2×

    warm_up()


_configure()
_purge_stale()
_wait_policy()
