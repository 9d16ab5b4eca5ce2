"""Coloured bands over time for the run's plot (`avsim.report.speed_plot`): the runs of equal
states of a per-tick series (an FSM's state, the speed's source), and one translucent band
per run over an axes' full height, one colour per state, with their legend.

Pure: no pyplot, no PyBullet.
"""

from __future__ import annotations

import enum
from collections.abc import Sequence
from typing import Literal

import numpy as np
from matplotlib.axes import Axes
from matplotlib.collections import PolyCollection
from matplotlib.figure import Figure
from numpy.typing import NDArray

BAND_ALPHA = 0.3  # [-] opacity of the bands
OTHER_COLOUR = "#9e9e9e"  # a state the colour table does not know yet
Run = tuple[str, float, float]  # (state's value, start [s], end [s])
LegendLoc = Literal["outside right lower", "outside right center", "outside lower center"]

FloatArray = NDArray[np.float64]


def value_runs(t: Sequence[float], values: Sequence[str]) -> list[Run]:
    """(value, start [s], end [s]) of each run of equal values; a run ends where the next one
    starts, the last one a tick after the last sample."""
    if not len(t):
        return []
    times = np.asarray(t, dtype=np.float64)
    dt = float(times[-1] - times[-2]) if len(times) > 1 else 0.0
    ends = np.append(times[1:], times[-1] + dt)
    runs: list[Run] = []
    start = 0
    for i in range(1, len(values) + 1):
        if i == len(values) or values[i] != values[start]:
            runs.append((values[start], float(times[start]), float(ends[i - 1])))
            start = i
    return runs


def mode_runs(t: Sequence[float], modes: Sequence[enum.Enum]) -> list[Run]:
    """`value_runs` of a series of enum members (an FSM's states, the speed's sources), by
    their values."""
    return value_runs(t, [m.value for m in modes])


def draw_bands(fig: Figure, ax: Axes, runs: Sequence[Run], colours: dict[str, str],
               title: str, loc: LegendLoc, skip: frozenset[str] = frozenset()) -> None:
    """One collection per state over `ax`'s full height, and their legend (a figure legend
    at `loc`), in the order of `colours`; the states in `skip` get no band."""
    by_mode: dict[str, list[tuple[float, float]]] = {}
    for mode, start, end in runs:
        if mode not in skip:
            by_mode.setdefault(mode, []).append((start, end))
    known = list(colours)
    order = sorted(by_mode, key=lambda m: (known.index(m) if m in known else len(known), m))
    handles = []
    for mode in order:
        verts = [[(a, 0.0), (b, 0.0), (b, 1.0), (a, 1.0)] for a, b in by_mode[mode]]
        band = PolyCollection(verts, transform=ax.get_xaxis_transform(), linewidths=0,
                              facecolors=colours.get(mode, OTHER_COLOUR),
                              alpha=BAND_ALPHA, zorder=0, label=mode.replace("_", " "))
        ax.add_collection(band, autolim=False)
        handles.append(band)
    if handles:
        fig.legend(handles=handles, loc=loc, title=title, fontsize="small")
