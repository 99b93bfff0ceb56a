"""The C allocator asked to keep freed memory for reuse, so large NumPy temporaries do not fault in fresh pages.

Drop-cutter, the chordal checks and the height-map sweeps create and free
arrays of a few to some tens of megabytes thousands of times.  glibc's
``malloc`` gives such memory back to the system as soon as it is freed (above
its trim threshold), and the next array of the same size faults in fresh,
zeroed pages: the kernel zeroes and maps every page again, thousands of
times over a plan, as system time beside the arithmetic.
:func:`keep_freed_memory` raises glibc's mmap threshold to
:data:`MMAP_THRESHOLD` and its trim threshold to :data:`TRIM_THRESHOLD`: up
to that much freed memory stays with the process for the next array, which
reuses pages already mapped, at the price of a peak memory higher by about
what is kept.  The values computed are the same; only where memory comes
from changes.

The ``lagsym`` command calls it once before a command runs; a program using
the library may call it too (it is the process's setting, so the library
never makes it on its own).  It does nothing where the C library is not
glibc, or where the environment already sets glibc's malloc tuning
(``MALLOC_TRIM_THRESHOLD_``, ``MALLOC_MMAP_THRESHOLD_`` or ``GLIBC_TUNABLES``).
"""

from __future__ import annotations

import os

__all__ = ["MMAP_THRESHOLD", "TRIM_THRESHOLD", "keep_freed_memory"]

MMAP_THRESHOLD = 64 << 20
"""Blocks from this size (bytes) still come straight from the system and go back to it when freed."""

TRIM_THRESHOLD = 256 << 20
"""Freed memory (bytes) the process keeps at most before giving the top of its heap back."""

_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD = -1, -3  # glibc's mallopt parameters (malloc.h)
_USER_TUNING = ("MALLOC_TRIM_THRESHOLD_", "MALLOC_MMAP_THRESHOLD_", "GLIBC_TUNABLES")


def _glibc() -> bool:
    try:
        return bool(os.confstr("CS_GNU_LIBC_VERSION"))
    except (AttributeError, ValueError, OSError):  # not a glibc system
        return False


def keep_freed_memory() -> bool:
    """Set glibc's mmap and trim thresholds for this process; True where the allocator took them.

    Examples
    --------
    >>> keep_freed_memory() in (True, False)
    True
    """
    if any(name in os.environ for name in _USER_TUNING) or not _glibc():
        return False
    import ctypes

    try:
        mallopt = ctypes.CDLL(None).mallopt
    except (OSError, AttributeError):
        return False
    mallopt.argtypes, mallopt.restype = (ctypes.c_int, ctypes.c_int), ctypes.c_int
    return bool(mallopt(_M_MMAP_THRESHOLD, MMAP_THRESHOLD)) & bool(mallopt(_M_TRIM_THRESHOLD, TRIM_THRESHOLD))
