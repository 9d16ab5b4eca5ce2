"""Giving freed memory back to the system during a long run.

A run allocates and frees many short-lived buffers every tick (images, point clouds, numpy
temporaries, on several threads). glibc's allocator keeps what is freed inside its arenas
for reuse, and what it cannot reuse stays resident. In a probe of the soak's town loop
(`bench.bench_soak`, `fast` profile, the machine shared) the main process grew about 2.5 MB
per simulated minute with `malloc_trim` never called, about 0.6 with it called once a
minute. `release_memory` asks glibc to return the free pages of every arena
(`malloc_trim(0)`, a few milliseconds); with another C library it does nothing."""

from __future__ import annotations

import ctypes
import ctypes.util
from functools import cache
from typing import Any


@cache
def _libc() -> Any:
    name = ctypes.util.find_library("c")
    if name is None:
        return None
    libc = ctypes.CDLL(name)
    return libc if hasattr(libc, "malloc_trim") else None


def release_memory() -> None:
    """Return the allocator's free memory to the system (glibc), else nothing."""
    libc = _libc()
    if libc is not None:
        libc.malloc_trim(0)
