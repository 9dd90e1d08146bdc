"""Serial and ``parallel=True`` compilations of one kernel, cached under distinct names.

numba's on-disk cache files a function under its qualified name and line and
does not tell a ``parallel=True`` compilation from a serial one: the two
compilations of one Python function would load each other's machine code
(whichever was compiled first).  :func:`serial` and :func:`parallel` compile a
renamed copy of the function (suffix ``_serial`` / ``_parallel``).  Inside a
serial compilation ``prange`` is a plain ``range``, so both give bit-identical
results wherever the iterations of a ``prange`` are independent.
"""

from __future__ import annotations

import types

from numba import njit

__all__ = ["ROW_CHUNKS", "parallel", "renamed", "serial"]


def renamed(fn, suffix):
    """A copy of ``fn`` with its own name (``fn.__name__ + suffix``)."""
    out = types.FunctionType(fn.__code__, fn.__globals__, fn.__name__ + suffix, fn.__defaults__, fn.__closure__)
    out.__qualname__ = fn.__qualname__ + suffix
    out.__doc__ = fn.__doc__
    return out


def serial(fn):
    """``fn`` compiled serially (``prange`` runs as ``range``)."""
    return njit(cache=True, nogil=True)(renamed(fn, "_serial"))


def parallel(fn):
    """``fn`` compiled with ``parallel=True``."""
    return njit(cache=True, nogil=True, parallel=True)(renamed(fn, "_parallel"))


#: Rows of one colour (or of a defect, a transfer) are split into at most this many
#: chunks: the parallel work units, and the same chunks in the serial compilation.
ROW_CHUNKS = 16
