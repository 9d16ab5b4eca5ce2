"""Numbers in the criteria's messages that say what their values say: a message states the
quantity its criterion's value is, and its text never hides a sign or a crossed threshold
by rounding (0.004 m over a line is not "0.00 m"; 3.504 m/s^2 over 3.5 m/s^2 is not
"3.50").
"""

from __future__ import annotations

import math

MAX_DIGITS = 6  # decimals at most


def signed(x: float, digits: int = 2) -> str:
    """`x` with its sign ("+0.12", "-0.004"), with more decimals than `digits` where fewer
    would show a non-zero `x` as zero."""
    return f"{x:+.{_digits(x, 0.0, digits)}f}"


def beside(x: float, ref: float, digits: int = 1) -> str:
    """`x` with `digits` decimals, or more where fewer would show it equal to `ref` (a
    threshold it is compared with) when it is not."""
    return f"{x:.{_digits(x, ref, digits)}f}"


def _digits(x: float, ref: float, digits: int) -> int:
    """The fewest decimals from `digits` that tell `x` from `ref` (`MAX_DIGITS` at most)."""
    if not math.isfinite(x) or x == ref:
        return digits
    d = digits
    while d < MAX_DIGITS and f"{x:.{d}f}" in {f"{ref:.{d}f}", f"{-ref:.{d}f}"}:
        d += 1
    return d
