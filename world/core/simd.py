"""The same numbers on every x86-64 machine: numpy's SIMD dispatch held at x86-64-v3.

numpy picks each loop's kernel at import for the CPU it finds: on a CPU with AVX-512 its
transcendental functions (`sin`, `cos`, `exp`, ...) and some reductions take kernels that
round differently in the last bit from the AVX2 ones. A run's trajectory feeds those results
back into the physics, so the same scenario and seed gave another trajectory (and another
golden result) on an AVX-512 machine than on an AVX2 one. `pin_numpy_dispatch` switches the
AVX-512 kernels off (numpy's ``NPY_DISABLE_CPU_FEATURES``) before numpy is imported, for this
process and every process it starts; a value the user set is kept. It must run before the
first `import numpy`: the packages that simulate (`world`, `avsim`) call it first thing.
"""

from __future__ import annotations

import os
import platform
import sys

NUMPY_ENV = "NPY_DISABLE_CPU_FEATURES"
AVX512_GROUPS = "X86_V4 AVX512_ICL AVX512_SPR"  # numpy 2.x's dispatch groups above x86-64-v3
X86_64 = ("x86_64", "amd64")


def pin_numpy_dispatch() -> bool:
    """Hold numpy's dispatch at x86-64-v3 on x86-64; True when it holds for this process
    (set here or by the user before numpy was imported), False when numpy was imported
    first (its kernels are chosen already) or the machine is not x86-64."""
    if platform.machine().lower() not in X86_64:
        return False
    os.environ.setdefault(NUMPY_ENV, AVX512_GROUPS)
    return "numpy" not in sys.modules
