"""The ego's longitudinal acceleration and jerk for the run's plot (`avsim.report.speed_plot`),
with ISO 15622's comfort limits.

Derived from the log's true forward speed v [m/s] at the control ticks t [s]:

- acceleration a [m/s^2] = dv/dt by central differences (`numpy.gradient`, one-sided at the
  ends), then a centred moving mean over `ACCEL_WINDOW` (0.25 s) against the tick-to-tick
  noise of the measured speed; and its centred mean over `ISO_ACCEL_WINDOW` (2 s), the
  average ISO 15622 limits to `ISO_ACCEL` (3.5 m/s^2), drawn with it;
- jerk [m/s^3] = da/dt of the 0.25 s acceleration by central differences, then a centred
  moving mean over `JERK_WINDOW` (1 s, the average ISO 15622 takes for its jerk limit
  `ISO_JERK`, 2.5 m/s^3).

A moving mean near the run's ends takes the samples there are (a shorter window). Pure: no
pyplot, no PyBullet.
"""

from __future__ import annotations

import numpy as np
from matplotlib.axes import Axes

from avsim.report.bands import FloatArray

ACCEL_WINDOW = 0.25  # [s] the acceleration's moving mean
ISO_ACCEL_WINDOW = 2.0  # [s] ISO 15622's averaging of the acceleration limit
JERK_WINDOW = 1.0  # [s] the jerk's moving mean (ISO 15622's averaging of the jerk limit)
ISO_ACCEL = 3.5  # [m/s^2] ISO 15622's comfort limit on deceleration (2 s mean)
ISO_JERK = 2.5  # [m/s^3] ISO 15622's comfort limit on jerk
LINES = {  # series -> (label, colour, style, width); the ego's lines share its colour
    "accel": ("acceleration (true, 0.25 s mean)", "#000000", "-", 0.8),
    "accel_2s": ("acceleration, 2 s mean", "#000000", "-", 2.0),
    "iso_accel": (f"ISO 15622 +-{ISO_ACCEL:g} m/s^2 (2 s mean)", "#6a1b9a", "--", 1.2),
    "jerk": ("jerk (true, 1 s mean)", "#000000", "-", 1.2),
    "iso_jerk": (f"ISO 15622 +-{ISO_JERK:g} m/s^3", "#283593", "--", 1.2),
}
ACCEL_VIEW = (6.0, 12.0)  # [m/s^2] the acceleration axis shows at least +-the first, at
#   most +-the second (a collision's spike leaves the panel, the limits stay readable)
JERK_VIEW = (5.0, 20.0)  # [m/s^3] the same for the jerk axis


def moving_mean(t: FloatArray, x: FloatArray, window: float) -> FloatArray:
    """The centred mean of x over `window` [s] at each of the ticks t [s] (a steady rate;
    fewer samples at the ends)."""
    if len(t) < 2:
        return x.astype(np.float64, copy=True)
    dt = float(t[1] - t[0])
    half = max(round(0.5 * window / dt), 0) if dt > 0.0 else 0
    sums = np.concatenate([[0.0], np.cumsum(x, dtype=np.float64)])
    i = np.arange(len(x))
    lo, hi = np.maximum(i - half, 0), np.minimum(i + half + 1, len(x))
    out: FloatArray = (sums[hi] - sums[lo]) / (hi - lo)
    return out


def _derivative(t: FloatArray, x: FloatArray) -> FloatArray:
    if len(t) < 2:
        return np.zeros(len(t), dtype=np.float64)
    out: FloatArray = np.gradient(x, t)
    return out


def acceleration(t: FloatArray, speed: FloatArray) -> FloatArray:
    """[m/s^2] per tick: the 0.25 s mean of dv/dt (module doc)."""
    return moving_mean(t, _derivative(t, speed), ACCEL_WINDOW)


def jerk(t: FloatArray, speed: FloatArray) -> FloatArray:
    """[m/s^3] per tick: the 1 s mean of the derivative of `acceleration` (module doc)."""
    return moving_mean(t, _derivative(t, acceleration(t, speed)), JERK_WINDOW)


def _line(ax: Axes, t: FloatArray, values: FloatArray, key: str) -> None:
    label, colour, style, width = LINES[key]
    ax.plot(t, values, style, color=colour, linewidth=width, label=label, zorder=2)


def _limits(ax: Axes, limit: float, key: str, view: tuple[float, float],
            values: FloatArray) -> None:
    label, colour, style, width = LINES[key]
    ax.axhline(limit, linestyle=style, color=colour, linewidth=width, label=label, zorder=2)
    ax.axhline(-limit, linestyle=style, color=colour, linewidth=width, zorder=2)
    ax.axhline(0.0, color="#616161", linewidth=0.8, zorder=1)
    finite = values[np.isfinite(values)]
    top = min(max(view[0], 1.1 * float(np.abs(finite).max())), view[1]) if len(finite) \
        else view[0]
    ax.set_ylim(-top, top)
    ax.grid(True, alpha=0.3, zorder=1)
    ax.legend(loc="upper right", fontsize="small", framealpha=0.8)


def draw_accel(ax: Axes, t: FloatArray, speed: FloatArray) -> None:
    """The ego's acceleration and its 2 s mean over time [s], and +-`ISO_ACCEL`."""
    a = acceleration(t, speed)
    _line(ax, t, a, "accel")
    _line(ax, t, moving_mean(t, a, ISO_ACCEL_WINDOW), "accel_2s")
    _limits(ax, ISO_ACCEL, "iso_accel", ACCEL_VIEW, a)
    ax.set_ylabel("accel. [m/s^2]")


def draw_jerk(ax: Axes, t: FloatArray, speed: FloatArray) -> None:
    """The ego's jerk over time [s], and +-`ISO_JERK`."""
    j = jerk(t, speed)
    _line(ax, t, j, "jerk")
    _limits(ax, ISO_JERK, "iso_jerk", JERK_VIEW, j)
    ax.set_ylabel("jerk [m/s^3]")
