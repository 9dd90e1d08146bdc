"""A large mesh written in a child process (no Qt): the app's window stays responsive.

The writers of :mod:`meshcore.io` format their text and arrays in long calls that hold the GIL
(session 29: a 1.75 million-cell .vtm written in a worker thread still stalled the GUI thread for
1.5 s).  :func:`write_in_process` sends the grids pickled to ``python -m app.write_process`` on its
standard input and waits for it (waiting releases the GIL); the child calls
:func:`app.io_adapter.write_mesh` and answers with ``b"ok"`` or its exception pickled.  The writers
write a temporary file and rename it: the file is complete or absent, whatever happens to the child.

Where no child can be started (a frozen app without a Python to run), the write happens here.
"""

from __future__ import annotations

import os
import pickle
import subprocess
import sys
from pathlib import Path

__all__ = ["write_in_process"]

_OK = b"ok"


def _child_env() -> dict[str, str]:
    """The environment of the child: this process's, with the folder holding ``app`` on its path."""
    env = dict(os.environ)
    root = str(Path(__file__).resolve().parent.parent)
    env["PYTHONPATH"] = os.pathsep.join(p for p in (root, env.get("PYTHONPATH", "")) if p)
    return env


def write_in_process(path, grids, frame=None, format=None) -> None:
    """:func:`app.io_adapter.write_mesh` in a child process; its error raised here.

    >>> import tempfile, numpy as np
    >>> from meshcore import StructuredGrid
    >>> x, y = np.meshgrid(np.arange(3.0), np.arange(2.0), indexing="ij")
    >>> out = Path(tempfile.mkdtemp()) / "g.vts"
    >>> write_in_process(out, [StructuredGrid(x, y)])
    >>> out.exists()
    True
    """
    from . import io_adapter as fio

    if getattr(sys, "frozen", False) or not sys.executable:
        fio.write_mesh(path, grids, frame, format)
        return
    payload = pickle.dumps((str(path), grids, frame, format), protocol=pickle.HIGHEST_PROTOCOL)
    proc = subprocess.run(
        [sys.executable, "-m", "app.write_process"], input=payload, capture_output=True, env=_child_env(), check=False
    )
    if proc.returncode == 0 and proc.stdout == _OK:
        return
    try:
        exc = pickle.loads(proc.stdout) if proc.stdout else None
    except Exception:  # a child that died half way: its stderr says why
        exc = None
    if isinstance(exc, BaseException):
        raise exc
    tail = proc.stderr.decode(errors="replace").strip().splitlines()[-3:]
    raise OSError(f"{Path(path).name}: the writing process ended with code {proc.returncode}: {' '.join(tail)}")


def _main() -> int:
    """The child: read ``(path, grids, frame, format)`` pickled from stdin, write, answer on stdout."""
    from . import io_adapter as fio

    path, grids, frame, format = pickle.loads(sys.stdin.buffer.read())
    try:
        fio.write_mesh(Path(path), grids, frame, format)
    except Exception as exc:  # every error goes back to the app, which shows it
        try:
            answer = pickle.dumps(exc)
        except Exception:  # an exception that does not pickle: its text
            answer = pickle.dumps(OSError(str(exc)))
        sys.stdout.buffer.write(answer)
        return 1
    sys.stdout.buffer.write(_OK)
    return 0


if __name__ == "__main__":
    sys.exit(_main())
