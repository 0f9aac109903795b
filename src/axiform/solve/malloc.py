"""Keep freed memory in the process for the next allocation (glibc's malloc).

Every Newton iteration allocates and frees the same large temporaries (element tangents,
the material tangent, the pattern data).  By default glibc maps blocks above 128 kB afresh
and gives freed memory back to the system, so the kernel faults in and zeroes those pages
again on every call: up to half the time of an evaluation at 1e3 elements
(benchmarks/README.md § 1).  Raising the mapping and trimming thresholds keeps them.
"""

from __future__ import annotations

import ctypes
import sys

M_TRIM_THRESHOLD = -1
M_MMAP_THRESHOLD = -3


def keep_freed_memory(mmap_threshold: int = 32 * 2**20, trim_threshold: int = 512 * 2**20) -> bool:
    """Blocks below mmap_threshold bytes come from the heap, and up to trim_threshold bytes of
    freed heap stay in the process.  True when set (Linux with glibc), False elsewhere."""
    if not sys.platform.startswith("linux"):
        return False
    try:
        libc = ctypes.CDLL("libc.so.6")
        return bool(libc.mallopt(M_MMAP_THRESHOLD, mmap_threshold) and libc.mallopt(M_TRIM_THRESHOLD, trim_threshold))
    except (OSError, AttributeError):
        return False
