"""The speed profile of a run as a PNG, like the DECS paper's Fig. 3 (`avsim run --plot`).

Speeds over time in km/h: the ego's (true), the lead vehicle's, the posted limit at the
ego's front bumper and the driver's set speed, with the ACC / event layer's mode
(`planner.fsm.acc.AccMode`) as coloured bands behind them, one colour per mode; under them a
strip of bands says which constraint set the plan's speed at each tick
(`planner.messages.SpeedSource`: set speed, limit, curve, following, event, pedal, degraded
lane, emergency).

The lead vehicle at a tick is the nearest car or truck ahead of the ego in its lane, as the
run's log has it from the truth and the map by the `min_gap` criterion's rule
(`world.truth.vehicles_ahead`: its footprint in the lane the ego's centre is in, ahead along
the ego's route, travelling along the lane; in a town as on a road); a gap in the line where
there is none.

Pure: no PyBullet, no pyplot (a bare `Figure` on the Agg canvas, so no display is needed).
"""

from __future__ import annotations

import enum
import math
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Literal

import numpy as np
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.collections import PolyCollection
from matplotlib.figure import Figure
from numpy.typing import NDArray

from planner.fsm.acc import AccMode
from planner.messages import SpeedSource
from world.frames import MPS_PER_KPH

if TYPE_CHECKING:
    from avsim.run.runner import RunResult

SIZE = (16.0, 7.0)  # [in] at DPI: 1600 x 700 px
DPI = 100  # [px/in]
BAND_ALPHA = 0.3  # [-] opacity of the mode and source bands
VEHICLES = frozenset({"car", "truck"})  # actor types that can be a lead
# one colour per ACC / event mode, by `AccMode` value (legend order: AccMode's)
MODE_COLOURS: dict[str, str] = {
    AccMode.ACC_OFF.value: "#b0bec5",
    AccMode.CRUISE.value: "#4caf50",
    AccMode.TRAIL.value: "#2196f3",
    AccMode.BRAKE.value: "#e53935",
    AccMode.SPEED_LIMIT.value: "#ffc107",
    AccMode.OFF_RAMP.value: "#9c27b0",
    AccMode.PEDESTRIAN.value: "#00bcd4",
    AccMode.SPEED_BUMP.value: "#ff5722",
    AccMode.STOP_SIGN.value: "#880e4f",
    AccMode.FLAT.value: "#795548",
    AccMode.RED_LIGHT.value: "#b71c1c",
    AccMode.YIELD.value: "#ff9800",
}
OTHER_MODE_COLOUR = "#9e9e9e"  # a mode this table does not know yet
# one colour per speed source, by `SpeedSource` value (legend order: SpeedSource's)
SOURCE_COLOURS: dict[str, str] = {
    SpeedSource.SET_SPEED.value: "#66bb6a",
    SpeedSource.LIMIT.value: "#ffca28",
    SpeedSource.CURVE.value: "#8d6e63",
    SpeedSource.FOLLOWING.value: "#42a5f5",
    SpeedSource.EVENT.value: "#ab47bc",
    SpeedSource.PEDAL.value: "#26c6da",
    SpeedSource.DEGRADED.value: "#ff7043",
    SpeedSource.EMERGENCY.value: "#d50000",
}
SOURCE_STRIP = 0.08  # [-] the speed-source strip's height, a fraction of the speed axes'
LINES = {  # series -> (label, colour, style, width)
    "ego": ("ego speed", "#000000", "-", 2.0),
    "lead": ("lead speed", "#1a237e", "-", 1.5),
    "limit": ("posted limit", "#d50000", "--", 1.5),
    "set": ("set speed", "#1b5e20", ":", 1.8),
}

FloatArray = NDArray[np.float64]


def mode_runs(t: Sequence[float],
              modes: Sequence[enum.Enum]) -> list[tuple[str, float, float]]:
    """(mode's value, start [s], end [s]) of each run of equal modes (or sources); a run
    ends where the next one starts, the last one a tick after the last sample."""
    if not len(t):
        return []
    times = np.asarray(t, dtype=np.float64)
    dt = float(times[-1] - times[-2]) if len(times) > 1 else 0.0
    ends = np.append(times[1:], times[-1] + dt)
    runs: list[tuple[str, float, float]] = []
    start = 0
    for i in range(1, len(modes) + 1):
        if i == len(modes) or modes[i] != modes[start]:
            runs.append((modes[start].value, float(times[start]), float(ends[i - 1])))
            start = i
    return runs


def lead_speed(result: RunResult) -> FloatArray:
    """[m/s] per tick: the speed of the vehicle ahead in the ego's lane (the run's log, from
    the truth and the map), NaN where there is none."""
    return result.log.array("lead_speed")


def _title(result: RunResult) -> str:
    """The scenario's name and situation, and its verdict with the failed criteria."""
    failed = [c.name for c in result.criteria if c.failed]
    verdict = "PASS" if not failed else "FAIL (" + ", ".join(failed) + ")"
    return f"{result.scenario.name} ({result.scenario.situation}): {verdict}"


def _draw_bands(fig: Figure, ax: Axes, runs: list[tuple[str, float, float]],
                colours: dict[str, str], title: str,
                loc: Literal["outside right lower", "outside lower center"]) -> None:
    """One collection per mode (or source) over `ax`'s full height, and their legend, in
    the order of `colours`."""
    by_mode: dict[str, list[tuple[float, float]]] = {}
    for mode, start, end in runs:
        by_mode.setdefault(mode, []).append((start, end))
    known = list(colours)
    order = sorted(by_mode, key=lambda m: (known.index(m) if m in known else len(known), m))
    handles = []
    for mode in order:
        verts = [[(a, 0.0), (b, 0.0), (b, 1.0), (a, 1.0)] for a, b in by_mode[mode]]
        band = PolyCollection(verts, transform=ax.get_xaxis_transform(), linewidths=0,
                              facecolors=colours.get(mode, OTHER_MODE_COLOUR),
                              alpha=BAND_ALPHA, zorder=0, label=mode.replace("_", " "))
        ax.add_collection(band, autolim=False)
        handles.append(band)
    if handles:
        fig.legend(handles=handles, loc=loc, title=title, fontsize="small")


def speed_profile_figure(result: RunResult) -> Figure:
    """The figure of `plot_speed_profile`, not yet written."""
    log = result.log
    fig = Figure(figsize=SIZE, dpi=DPI, layout="constrained")
    FigureCanvasAgg(fig)
    ax, strip = fig.subplots(2, 1, sharex=True, height_ratios=(1.0, SOURCE_STRIP))
    t = log.array("t")
    limit = log.array("speed_limit")
    series = {
        "ego": log.array("speed") / MPS_PER_KPH,
        "lead": lead_speed(result) / MPS_PER_KPH,
        "limit": np.where(np.isfinite(limit), limit, math.nan) / MPS_PER_KPH,
        "set": np.full(len(t), result.scenario.driver.set_speed / MPS_PER_KPH),
    }
    for key, values in series.items():
        label, colour, style, width = LINES[key]
        ax.plot(t, values, style, color=colour, linewidth=width, label=label,
                drawstyle="steps-post" if key == "limit" else "default", zorder=2)
    runs = mode_runs(log.t, log.acc_mode)
    _draw_bands(fig, ax, runs, MODE_COLOURS, "ACC / event mode", "outside right lower")
    _draw_bands(fig, strip, mode_runs(log.t, log.speed_source), SOURCE_COLOURS,
                "speed set by", "outside lower center")
    strip.set_yticks([])
    strip.set_ylabel("speed set by", rotation=0, ha="right", va="center")
    top = max([float(np.nanmax(v)) for v in series.values() if np.isfinite(v).any()],
              default=50.0)
    ax.set_ylim(min(0.0, float(np.nanmin(series["ego"]))) if len(t) else 0.0,
                top * 1.08 + 2.0)
    if runs:
        ax.set_xlim(runs[0][1], runs[-1][2])
    strip.set_xlabel("time [s]")
    ax.set_ylabel("speed [km/h]")
    ax.set_title(_title(result))
    ax.grid(True, alpha=0.3, zorder=1)
    fig.legend(handles=ax.get_lines(), loc="outside right upper", fontsize="small")
    return fig


def plot_speed_profile(result: RunResult, path: Path) -> Path:
    """Write the run's speed profile as a PNG of `SIZE` at `DPI` to `path` (its directory is
    made; the file appears whole, through a temporary file beside it). Returns `path`."""
    fig = speed_profile_figure(result)
    path.parent.mkdir(parents=True, exist_ok=True)
    partial = path.with_name(f".{path.name}.partial")
    try:
        fig.savefig(partial, format="png", dpi=DPI)
        partial.replace(path)
    finally:
        partial.unlink(missing_ok=True)
    return path
