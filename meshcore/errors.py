"""One error hierarchy for meshcore.

Every message names the argument, the border, the file, the line or the point
index it is about, so that the CLI and the app can show it as one readable
line.  All input errors also derive from :class:`ValueError` so callers that
catch ``ValueError`` keep working.

::

    MeshcoreError
     ├── InvalidInputError (ValueError)
     │    ├── BorderMismatchError
     │    ├── BoundaryError            self-intersections, corners, zero-length borders
     │    ├── CaseFileError            TOML case files: unknown keys, bad values
     │    └── TopologyError            multiblock connectivity
     ├── ReadError (ValueError)        a file that cannot be read (names file, line)
     ├── WriteError (OSError)          a file that cannot be written
     ├── FoldedGridError               raised only when a caller asks for strictness
     └── SolverError                   an internal solver failure (not non-convergence)

    Stopped                            the caller's stop ended a long computation (not an error)

Non-convergence is *not* an error: it is reported on the result.  A stop is not one either:
:class:`Stopped` is no :class:`MeshcoreError`, so that code which takes a failed step as a step that
reads nothing and goes on (the layout choice's draws) does not go on after a stop.
"""

from __future__ import annotations

__all__ = [
    "BorderMismatchError",
    "BoundaryError",
    "CaseFileError",
    "FoldedGridError",
    "InvalidInputError",
    "MeshcoreError",
    "MeshcoreWarning",
    "ReadError",
    "SolverError",
    "Stopped",
    "TopologyError",
    "WriteError",
]


class MeshcoreError(Exception):
    """Root of every error raised by meshcore."""


class InvalidInputError(MeshcoreError, ValueError):
    """An argument or input value is invalid; the message names it."""


class BorderMismatchError(InvalidInputError):
    """Opposite borders carry different node counts."""


class BoundaryError(InvalidInputError):
    """The boundary is geometrically unusable (self-intersection, bad corners...)."""


class CaseFileError(InvalidInputError):
    """A case (project) file is malformed; the message names the file and key."""


class TopologyError(InvalidInputError):
    """A multiblock topology is malformed; the message names blocks and borders."""


class ReadError(MeshcoreError, ValueError):
    """A file could not be read; the message names the file and, if known, the line."""


class WriteError(MeshcoreError, OSError):
    """A file could not be written; nothing partial is left behind."""


class FoldedGridError(MeshcoreError):
    """A grid has folded cells and the caller asked for a valid grid."""


class SolverError(MeshcoreError):
    """An internal solver failure (not plain non-convergence)."""


class Stopped(Exception):
    """A computation ended by its caller's stop event (e.g. :func:`meshcore.layout.auto_layout`'s
    ``stop_event``): nothing is returned, and there is nothing to report.  Not a :class:`MeshcoreError`
    (see the module's docstring)."""


class MeshcoreWarning(UserWarning):
    """Something the user should know but that did not stop the run."""
