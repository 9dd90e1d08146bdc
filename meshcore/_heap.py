"""Keep freed memory in the process: a setting for the CLI's and the app's entry points.

glibc gives a freed block above its trim threshold back to the kernel, and the next allocation
of that size takes fresh pages, each a page fault.  A multiblock solve allocates the same large
arrays (the multigrid levels, the stencil tables) on every call, so a warm process paid
1 400–3 000 minor faults per solve of the refined Shasta example (session 21).  With blocks up
to :data:`MMAP_THRESHOLD` taken from the heap and :data:`TRIM_THRESHOLD` of free heap kept, it
pays none: `generate_case` of that example 84–86 → 79–80 ms of CPU (min of 7, alternating
processes, session 22); a lake at 15 000 cells (`mesh_outline`) unchanged within the noise.

A process-wide setting, so the library never sets it on import: only :func:`meshcore.cli.main`
and the app's ``main`` call :func:`keep_freed_memory`.  A no-op off glibc.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import sys

__all__ = ["MMAP_THRESHOLD", "TRIM_THRESHOLD", "keep_freed_memory"]

#: Blocks up to this size come from the heap (glibc's largest allowed value on 64-bit).
MMAP_THRESHOLD = 32 << 20
#: Free memory at the heap's top kept up to this size.
TRIM_THRESHOLD = 256 << 20

_M_TRIM_THRESHOLD = -1
_M_MMAP_THRESHOLD = -3


def keep_freed_memory() -> bool:
    """Ask glibc's malloc to keep freed blocks; True when both settings took."""
    if not sys.platform.startswith("linux"):
        return False
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
        mallopt = libc.mallopt
    except (OSError, AttributeError):  # musl and others: no mallopt
        return False
    mallopt.argtypes = [ctypes.c_int, ctypes.c_int]
    mallopt.restype = ctypes.c_int
    return bool(mallopt(_M_MMAP_THRESHOLD, MMAP_THRESHOLD)) and bool(mallopt(_M_TRIM_THRESHOLD, TRIM_THRESHOLD))
