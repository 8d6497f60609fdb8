"""Freed heap memory handed back to the operating system between episodes.

An episode allocates and frees hundreds of megabytes in small pieces (PyBullet's world, the planner's worlds, camera
images, numpy temporaries) from several threads. glibc's malloc keeps what was freed in its arenas for reuse, and
fragmentation leaves most of it there: in one process running episode after episode, resident memory held ~60 MB
of free heap after each episode, and the amount crept up from one episode to the next. `release_free_heap` asks
glibc to return it (``malloc_trim``); elsewhere (macOS, musl) it does nothing.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import functools
import time

__all__ = ["release_free_heap"]


@functools.cache
def _malloc_trim() -> object | None:
    """glibc's ``malloc_trim``, or None where the C library has none."""
    name = ctypes.util.find_library("c")
    try:
        libc = ctypes.CDLL(name or "libc.so.6")
        trim = libc.malloc_trim
    except (OSError, AttributeError):
        return None
    trim.argtypes = [ctypes.c_size_t]
    trim.restype = ctypes.c_int
    return trim


def release_free_heap() -> float:
    """Return the C heap's free memory to the operating system; the wall seconds it took (0 where unsupported)."""
    trim = _malloc_trim()
    if trim is None:
        return 0.0
    started = time.perf_counter()
    trim(0)  # type: ignore[operator]
    return time.perf_counter() - started
