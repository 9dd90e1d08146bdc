"""The ``meshcore`` command line.

Subcommands live in one module each with ``add_args(parser)`` and
``run(args) -> int``.  Exit codes: 0 success/converged, 2 bad input (one line
on stderr, no traceback, no partial output), 3 solved but not converged, 1 an
internal error (a bug; one line too, ``MESHCORE_DEBUG=1`` shows the traceback),
130 interrupted (Ctrl-C), 143 terminated (SIGTERM, what ``timeout`` and job
schedulers send: taken as an interruption, so a write in progress removes its
temporaries as on Ctrl-C).
"""

from __future__ import annotations

import argparse
import importlib
import os
import platform
import sys
from collections.abc import Sequence
from typing import Any, NoReturn

from ..errors import MeshcoreError

__all__ = ["EXIT_BAD_INPUT", "EXIT_INTERNAL", "EXIT_NOT_CONVERGED", "EXIT_OK", "console", "main"]

EXIT_OK = 0
EXIT_INTERNAL = 1
EXIT_BAD_INPUT = 2
EXIT_NOT_CONVERGED = 3

#: (subcommand, module, help) — modules are imported lazily.
SUBCOMMANDS: list[tuple[str, str, str]] = [
    ("generate", "generate", "generate a grid from a case file"),
    ("quality", "quality", "print the quality table of a mesh file"),
    ("examples", "examples", "list bundled example cases, or copy one to a folder"),
    ("convert", "convert", "convert a grid file to another format (PLOT3D, VTK, CGNS, ...)"),
    ("import", "import_", "make a case file from a shoreline point file (KML, GeoJSON, CSV, ...)"),
    ("mesh", "mesh", "a lake outline (islands included) in, an orthogonal multiblock grid out"),
]


def register_subcommand(name: str, module: str, help: str) -> None:
    """Add a subcommand implemented by ``meshcore.cli.<module>``."""
    if all(n != name for n, _, _ in SUBCOMMANDS):
        SUBCOMMANDS.append((name, module, help))


def _version() -> str:
    import numba
    import numpy

    from .. import __version__

    return (
        f"meshcore {__version__} (Python {platform.python_version()}, numpy {numpy.__version__}, "
        f"numba {numba.__version__})"
    )


class _Parser(argparse.ArgumentParser):
    """argparse with the promised error format: one line on stderr, exit code 2."""

    def error(self, message: str) -> NoReturn:
        line = " ".join(message.split())
        self.exit(EXIT_BAD_INPUT, f"{self.prog}: error: {line} (see {self.prog} --help)\n")


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="meshcore",
        description="Structured boundary-fitted 2-D grids in generalized coordinates.",
    )
    parser.add_argument("--version", action="version", version=_version())
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    for name, mod, help_ in SUBCOMMANDS:
        m = importlib.import_module(f"{__name__}.{mod}")
        p = sub.add_parser(name, help=help_, description=help_)
        m.add_args(p)
        p.set_defaults(_run=m.run)
    return parser


class _Terminated(KeyboardInterrupt):
    """SIGTERM, raised where the program is, so that what is being written is cleaned up."""


def _terminate(signum: int, frame: Any) -> NoReturn:
    raise _Terminated


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; return the exit code (see the module docstring)."""
    import signal
    import threading

    own = threading.current_thread() is threading.main_thread() and signal.getsignal(signal.SIGTERM) == signal.SIG_DFL
    if own:
        signal.signal(signal.SIGTERM, _terminate)
    try:
        return _main(argv)
    finally:
        if own:
            signal.signal(signal.SIGTERM, signal.SIG_DFL)


def console() -> NoReturn:
    """The ``meshcore`` command itself (its console script and ``python -m meshcore``): :func:`main`,
    then the exit without the interpreter's teardown.

    Every run of the command loads the compiled kernels, and tearing those down took ~1 s of wall
    after the last line was printed (a 2 000-cell lake and a 60 000-cell one alike; 0.2 s with no
    kernel loaded): a script waited for it, and a Ctrl-C in that second killed a run whose files
    were already written (exit -2 instead of 0).  The output streams are flushed and the
    :mod:`atexit` functions run as at a normal exit (logging, temporary folders, numba's own
    shut-down hooks); files the command wrote are closed before :func:`main` returns.  In-process
    callers (tests, scripts) use :func:`main`, which returns."""
    import atexit

    rc = main()
    try:
        for stream in (sys.stdout, sys.stderr):
            try:
                stream.flush()
            except (OSError, ValueError):  # a closed pipe (``meshcore … | head``)
                pass
        atexit._run_exitfuncs()
    except KeyboardInterrupt:  # after the work is done: its exit code stands
        pass
    os._exit(rc)


def _main(argv: Sequence[str] | None) -> int:
    from .._heap import keep_freed_memory

    keep_freed_memory()
    try:
        parser = build_parser()  # imports every subcommand (numba kernels among them): seconds
    except KeyboardInterrupt as exc:
        print(f"meshcore: {'terminated' if isinstance(exc, _Terminated) else 'interrupted'}", file=sys.stderr)
        return 143 if isinstance(exc, _Terminated) else 130
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # --help, --version, or a usage error (already printed as one line)
        return exc.code if isinstance(exc.code, int) else EXIT_BAD_INPUT
    if not getattr(args, "_run", None):
        parser.print_help(sys.stderr)
        return EXIT_BAD_INPUT
    try:
        return int(args._run(args))
    except MeshcoreError as exc:
        print(f"meshcore {args.command}: error: {_one_line(exc)}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except KeyboardInterrupt as exc:
        term = isinstance(exc, _Terminated)
        print(f"meshcore {args.command}: {'terminated' if term else 'interrupted'}", file=sys.stderr)
        return 143 if term else 130
    except (OSError, ValueError) as exc:  # anything else a user can cause (paths, numbers)
        print(f"meshcore {args.command}: error: {_one_line(exc)}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except Exception as exc:  # a bug: still one line, with the way to the traceback
        if os.environ.get("MESHCORE_DEBUG"):
            raise
        print(
            f"meshcore {args.command}: internal error: {type(exc).__name__}: {_one_line(exc)} "
            f"(a bug: please report it; MESHCORE_DEBUG=1 shows the traceback)",
            file=sys.stderr,
        )
        return EXIT_INTERNAL


def _one_line(exc: BaseException) -> str:
    from ..io._atomic import one_line

    return one_line(str(exc)) or type(exc).__name__
