"""Atomic writes: temporary files next to the target, renamed over it when complete.

A failed write leaves nothing behind and the old file as it was; a set of files
that belong together is renamed only once every one of them is written; the
temporaries of a write that was killed (``kill -9``, a crash) are removed by the
next write to the same target.
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

from ..errors import MeshcoreError, WriteError

__all__ = ["STALE_AGE", "atomic_path", "atomic_paths", "clean_stale_temporaries", "one_line", "temp_prefix"]


def one_line(msg: str, limit: int = 400) -> str:
    """Collapse line breaks (a third-party message may hold some) and cap the length."""
    import re

    s = re.sub(r"\s*[\r\n]+\s*", " ", msg).strip()
    return s if len(s) <= limit else s[: limit - 1] + "…"


#: Temporaries older than this (seconds) are stale even when their writer's process id is alive.
STALE_AGE = 24 * 3600.0


def temp_prefix(target: Path) -> str:
    """Name prefix of our temporaries for ``target``: ``.<name>.<pid>.``."""
    return f".{target.name}.{os.getpid()}."


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OSError):
        return True
    return True


def clean_stale_temporaries(target: Path) -> list[Path]:
    """Remove our temporaries for ``target`` left by a killed write; return what was removed.

    A temporary is ``.<name>.<pid>.<random>.tmp`` (a file) or ``….tmpdir`` (a
    ``.vtm`` block folder in the making) next to ``target``.  It is stale when
    its writer process is gone (or it is older than :data:`STALE_AGE`); older
    names without a process id are stale after an hour.  Temporaries of a live
    writer, and every file not named like ours, are left alone.
    """
    import shutil
    import time

    directory = target.parent if str(target.parent) else Path(".")
    head = f".{target.name}."
    removed = []
    try:
        entries = list(os.scandir(directory))
    except OSError:
        return removed
    now = time.time()
    for e in entries:
        name = e.name
        if not name.startswith(head) or not (name.endswith(".tmp") or name.endswith(".tmpdir")):
            continue
        pid_text = name[len(head) :].split(".", 1)[0]
        try:
            age = now - e.stat(follow_symlinks=False).st_mtime
        except OSError:
            continue
        if pid_text.isdigit():
            pid = int(pid_text)
            stale = (pid != os.getpid() and not _pid_alive(pid)) or age > STALE_AGE
        else:
            stale = age > 3600.0
        if not stale:
            continue
        p = Path(e.path)
        try:
            if e.is_dir(follow_symlinks=False):
                shutil.rmtree(p)
            else:
                p.unlink()
            removed.append(p)
        except OSError:
            pass
    return removed


def _write_error(target: Any, exc: BaseException) -> WriteError:
    """One line naming the target and the reason (the system's, when a library buries it in a long
    message: HDF5 reports a full disk as ``… errno = 28, error message = '…' …``)."""
    import re

    errno = re.search(r"\berrno = (\d+)", str(exc))
    if isinstance(exc, OSError) and exc.strerror:
        reason = exc.strerror
    elif errno:
        reason = os.strerror(int(errno.group(1)))
    else:
        reason = str(exc) if isinstance(exc, OSError) else f"{type(exc).__name__}: {exc}"
    return WriteError(one_line(f"{target}: cannot write ({reason})"))


@contextlib.contextmanager
def atomic_paths(paths: Sequence[Any]) -> Iterator[list[Path]]:
    """Yield temporary paths next to ``paths``; rename them over the targets once *all* are written.

    A set of files that belong together (``.grd`` + ``.enc``) is written as a
    set: a failure while writing any of them (disk full …) removes every
    temporary and leaves every old file as it was.  The renames run in the
    order given, after the last byte is written.  Stale temporaries of
    earlier killed writes to the same targets are removed first.
    """
    targets = [Path(p) for p in paths]
    tmps: list[Path] = []
    try:
        for target in targets:
            clean_stale_temporaries(target)
            directory = target.parent if str(target.parent) else Path(".")
            try:
                fd, tmp = tempfile.mkstemp(prefix=temp_prefix(target), suffix=".tmp", dir=directory)
            except OSError as exc:
                raise WriteError(one_line(f"{target}: cannot write here ({exc.strerror or exc})")) from None
            os.close(fd)
            tmps.append(Path(tmp))
        yield list(tmps)
        for tmp in tmps:
            os.chmod(tmp, 0o644)
        for tmp, target in zip(tmps, targets, strict=True):
            os.replace(tmp, target)
    except BaseException as exc:
        for tmp in tmps:
            with contextlib.suppress(OSError):
                tmp.unlink()
        if isinstance(exc, MeshcoreError) or not isinstance(exc, Exception):
            raise
        raise _write_error(" + ".join(str(t) for t in targets), exc) from exc


@contextlib.contextmanager
def atomic_path(path: Any, *, binary: bool = True) -> Iterator[Path]:
    """Yield a temporary path next to ``path``; rename it over ``path`` on success.

    On any error the temporary file is removed and a
    :class:`~meshcore.errors.WriteError` naming ``path`` is raised, so nothing
    partial is ever left at ``path``.
    """
    with atomic_paths([path]) as (tmp,):
        yield tmp
