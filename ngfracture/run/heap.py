"""The process heap during a run: freed memory is kept for the next allocation.

A load step of a 3D fragmentation allocates and frees dense matrices of tens of MB a few
hundred times (Schur complements, the contact QP's Hessian, their factors). glibc serves a
block that large by mmap and returns it to the system when it is freed, so every new one is
fresh memory that the kernel faults in and zeroes page by page. Within a run
(:func:`kept_heap` around ``Simulation.run``) glibc serves no block by mmap (M_MMAP_MAX 0)
and keeps the free memory at the heap's top up to 2 GB (M_TRIM_THRESHOLD): a freed matrix's
memory serves the next one. On leaving, glibc's defaults come back and ``malloc_trim``
returns the free memory. Measured on six late steps of the default sphere (docs/performance.md,
"The heap of a run"): system time 24 -> 6.7 s, wall 129 -> 109 s, the same records to the
last bit, the largest resident set 2.2 -> 3.4 GB. Other C libraries than glibc: nothing changes.
"""
import contextlib
import ctypes
import ctypes.util
import functools
import platform
import threading

__all__ = ["kept_heap"]

#: mallopt's parameters (malloc.h)
M_TRIM_THRESHOLD, M_MMAP_MAX = -1, -4
#: glibc's defaults, restored when the last run leaves
GLIBC_DEFAULTS = {M_MMAP_MAX: 65536, M_TRIM_THRESHOLD: 128 * 1024}
#: free memory at the heap's top that a run keeps (mallopt takes an int)
KEPT_TRIM_THRESHOLD = 2 ** 31 - 1

_runs = 0        # runs inside kept_heap in this process (nested or on threads)
_lock = threading.Lock()


@functools.lru_cache(maxsize=None)
def _glibc():
    """The C library if it is glibc with mallopt, else None (looked up once per process)."""
    if platform.system() != "Linux" or platform.libc_ver()[0] != "glibc":
        return None
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
    except OSError:
        return None
    return libc if hasattr(libc, "mallopt") and hasattr(libc, "malloc_trim") else None


@contextlib.contextmanager
def kept_heap():
    """Keep freed memory in the process while the body runs (glibc only; see the module).

    Usable as a decorator. Nested and concurrent uses keep the heap until the last leaves.

    Yields
    ------
    bool
        Whether the heap is kept (False where the C library is not glibc).
    """
    global _runs
    libc = _glibc()
    if libc is None:
        yield False
        return
    with _lock:
        if _runs == 0:
            libc.mallopt(M_MMAP_MAX, 0)
            libc.mallopt(M_TRIM_THRESHOLD, KEPT_TRIM_THRESHOLD)
        _runs += 1
    try:
        yield True
    finally:
        with _lock:
            _runs -= 1
            if _runs == 0:
                for parameter, value in GLIBC_DEFAULTS.items():
                    libc.mallopt(parameter, value)
                libc.malloc_trim(0)
