"""Planning: the route, the motion and ACC / event layers, the speed plan."""

from __future__ import annotations

# First: the `world` package holds numpy's SIMD dispatch at x86-64-v3 before numpy is
# imported (the same numbers whichever package a program imports first).
import world.frames  # noqa: F401
