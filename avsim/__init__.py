"""The avsim application: scenarios, the closed loop, criteria, recording, batches, reports."""

from world.core.simd import pin_numpy_dispatch

pin_numpy_dispatch()  # before anything imports numpy: the same numbers on every x86-64 CPU
