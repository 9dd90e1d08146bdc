"""The ``meshcore`` command line.

Subcommands live in one module each with ``add_args(parser)`` and
``run(args) -> int``.  Exit codes: 0 success/converged, 2 bad input (one line
on stderr, no traceback, no partial output), 3 solved but not converged.
"""

from __future__ import annotations

import argparse
import importlib
import platform
import sys
from collections.abc import Sequence

from ..errors import MeshcoreError

__all__ = ["EXIT_BAD_INPUT", "EXIT_NOT_CONVERGED", "EXIT_OK", "main"]

EXIT_OK = 0
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


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="meshcore",
        description="Structured boundary-fitted 2-D grids in generalized coordinates.",
    )
    parser.add_argument("--version", action="version", version=_version())
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name, mod, help_ in SUBCOMMANDS:
        m = importlib.import_module(f"{__name__}.{mod}")
        p = sub.add_parser(name, help=help_, description=help_)
        m.add_args(p)
        p.set_defaults(_run=m.run)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "_run", None):
        parser.print_help(sys.stderr)
        return EXIT_BAD_INPUT
    try:
        return int(args._run(args))
    except MeshcoreError as exc:
        print(f"meshcore {args.command}: error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except KeyboardInterrupt:
        print(f"meshcore {args.command}: interrupted", file=sys.stderr)
        return 130
    except (OSError, ValueError) as exc:  # anything else a user can cause (paths, numbers)
        print(f"meshcore {args.command}: error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
