"""The speed profile and the margins of a run as a PNG, like the DECS paper's Fig. 3 with more
below it (`avsim run --plot`). Panels, top to bottom, on one time axis [s]:

1. Speeds in km/h: the ego's (true), the lead vehicle's, the posted limit at the ego's front
   bumper and the driver's set speed, with the ACC / event layer's mode (the log's
   `acc_mode`, `planner.fsm.acc.AccMode`'s values) as coloured bands behind them, one colour
   per mode.
2. A strip of the motion FSM's manoeuvres (its recorded states, `avsim.report.states`): lane
   changes left and right, an aborted one, a flat tyre's pull over, turns and U-turns, one
   colour per manoeuvre; lane keeping blank (`avsim.report.margins.motion_runs`).
3. A strip saying which constraint set the plan's speed at each tick (the log's
   `speed_source`, `planner.messages.SpeedSource`'s values: set speed, limit, curve,
   following, event, pedal, degraded lane, emergency, driver, sight).
4. The ego's true longitudinal acceleration [m/s^2] (0.25 s mean of dv/dt, and its 2 s
   mean) with ISO 15622's +-3.5 m/s^2, and
5. its jerk [m/s^3] (1 s mean of da/dt) with ISO 15622's +-2.5 m/s^3
   (`avsim.report.dynamics` says how they are derived and filtered).
6. The bumper gap to the lead [m] with UN R157's d_min at the ego's speed, shaded where the
   gap is under it.
7. The time to collision to the lead [s] (gap / closing speed while the ego closes on it),
   0-10 s, with `ttc_hard` (2.5 s, `avsim.report.margins.TTC_HARD`) dashed.
8. The ego's true lateral offset [m] from the centre of the lane the stack keeps, with
   +-(lane width - car width) / 2, where the body touches the lane's edge.

(`avsim.report.margins` has what panels 2, 6, 7 and 8 show and how.) On every panel, a
dash-dotted line where each scripted action or event fired and a hatched span over each
sensor fault's (or pedal override's) window, labelled at the top (`avsim.report.marks`).

Colours mean one thing across the figure: every ACC mode, speed source and manoeuvre has a
colour of its own (the band tables are keyed by the recorded states' values, so the report
imports no stack code; a state the tables lack is grey), no line shares a band's colour,
and lines share a colour only when they show the same subject (the ego's true motion in
black, the lead in navy).

The lead vehicle at a tick is the nearest car or truck ahead of the ego in its lane, as the
run's log has it from the truth and the map by the `min_gap` criterion's rule
(`world.truth.vehicles_ahead`: its footprint in the lane the ego's centre is in, ahead along
the ego's route, travelling along the lane; in a town as on a road); a gap in the lines
where there is none.

Pure and deterministic: no PyBullet, no pyplot (a bare `Figure` on the Agg canvas, so no
display is needed).
"""

from __future__ import annotations

import io
import math
from functools import cache
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from avsim.files import write_atomic
from avsim.report import dynamics, margins
from avsim.report.bands import BAND_ALPHA, FloatArray, draw_bands, mode_runs
from avsim.report.marks import draw_marks, story_marks
from avsim.run.recorded import recorded_changes, recorded_states
from vehicle_urdf.geometry import read_geometry
from world.frames import MPS_PER_KPH
from world.truth import time_to_collision

if TYPE_CHECKING:
    from avsim.run.runner import RunResult

__all__ = ["BAND_ALPHA", "MODE_COLOURS", "SOURCE_COLOURS", "lead_speed", "mode_runs",
           "plot_speed_profile", "speed_profile_figure"]

SIZE = (16.0, 12.0)  # [in] at DPI: 1600 x 1200 px
DPI = 100  # [px/in]
VEHICLES = frozenset({"car", "truck"})  # actor types that can be a lead
# one colour per ACC / event mode, by the recorded `acc_mode` value (legend order)
MODE_COLOURS: dict[str, str] = {
    "acc_off": "#b2996e",
    "cruise": "#089404",
    "trail": "#0d75f8",
    "brake": "#fe0002",
    "speed_limit": "#ffda03",
    "off_ramp": "#be03fd",
    "pedestrian": "#00fbb0",
    "speed_bump": "#c2ff89",
    "stop_sign": "#680018",
    "red_light": "#ca0147",
    "yield": "#ff9408",
    "flat": "#4e7496",
}
# one colour per speed source, by the recorded `speed_source` value (legend order); "sight"
#   is the speed cap from the forward sensing range
SOURCE_COLOURS: dict[str, str] = {
    "set_speed": "#9dff00",
    "limit": "#758000",
    "curve": "#caa0ff",
    "following": "#02ccfe",
    "event": "#ff63e9",
    "pedal": "#fc86aa",
    "degraded": "#c45508",
    "emergency": "#02066f",
    "driver": "#029386",
    "sight": "#8cffdb",
}
# [-] the panels' heights, relative to the speed panel's
PANELS = {"speed": 1.0, "motion": 0.07, "source": 0.07, "accel": 0.4, "jerk": 0.3,
          "gap": 0.4, "ttc": 0.3, "offset": 0.3}
STRIP_LABELS = {"motion": "manoeuvre", "source": "speed set by"}
LINES = {  # series -> (label, colour, style, width)
    "ego": ("ego speed", "#000000", "-", 2.0),
    "lead": ("lead speed", margins.LEAD_COLOUR, "-", 1.5),
    "limit": ("posted limit", "#b71c1c", "--", 1.5),
    "set": ("set speed", "#1b5e20", ":", 1.8),
}


def lead_speed(result: RunResult) -> FloatArray:
    """[m/s] per tick: the speed of the vehicle ahead in the ego's lane (the run's log, from
    the truth and the map), NaN where there is none."""
    return result.log.array("lead_speed")


@cache
def car_width() -> float:
    """[m] the ego's body width, from its URDF."""
    return read_geometry().body_width


def _title(result: RunResult) -> str:
    """The scenario's name and situation, and its verdict with the failed criteria."""
    failed = [c.name for c in result.criteria if c.failed]
    verdict = "PASS" if not failed else "FAIL (" + ", ".join(failed) + ")"
    return f"{result.scenario.name} ({result.scenario.situation}): {verdict}"


def _draw_speeds(ax: Axes, result: RunResult) -> None:
    """Panel 1's lines, limits, title and grid (its bands are drawn apart)."""
    log = result.log
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
    top = max([float(np.nanmax(v)) for v in series.values() if np.isfinite(v).any()],
              default=50.0)
    ax.set_ylim(min(0.0, float(np.nanmin(series["ego"]))) if len(t) else 0.0,
                top * 1.08 + 2.0)
    ax.set_ylabel("speed [km/h]")
    ax.set_title(_title(result))
    ax.grid(True, alpha=0.3, zorder=1)


def _draw_margins(axes: dict[str, Axes], result: RunResult) -> None:
    """Panels 4-6: the gap and d_min, the time to collision, the lateral offset."""
    log = result.log
    t, speed, gap = log.array("t"), log.array("speed"), log.array("lead_gap")
    margins.draw_gap(axes["gap"], t, gap, margins.min_gap(speed))
    margins.draw_ttc(axes["ttc"], t, time_to_collision(gap, speed, lead_speed(result)))
    bound = margins.lane_margin(result.scenario.world.road, log.array("station"), car_width())
    margins.draw_offset(axes["offset"], t, log.array("cross_track"), bound)


def speed_profile_figure(result: RunResult) -> Figure:
    """The figure of `plot_speed_profile`, not yet written: its axes in the order of
    `PANELS`."""
    log = result.log
    fig = Figure(figsize=SIZE, dpi=DPI, layout="constrained")
    FigureCanvasAgg(fig)
    axes = dict(zip(PANELS, fig.subplots(len(PANELS), 1, sharex=True,
                                         height_ratios=tuple(PANELS.values())), strict=True))
    ax = axes["speed"]
    _draw_speeds(ax, result)
    fig.legend(handles=ax.get_lines(), loc="outside right upper", fontsize="small")
    runs = mode_runs(log.t, log.acc_mode)
    draw_bands(fig, ax, runs, MODE_COLOURS, "ACC / event mode", "outside right lower")
    draw_bands(fig, axes["motion"],
               margins.motion_runs(log.t, recorded_states(log.motion),
                                   recorded_changes(result.state_changes)),
               margins.MOTION_COLOURS, "manoeuvre", "outside right center",
               skip=margins.NEUTRAL)
    draw_bands(fig, axes["source"], mode_runs(log.t, log.speed_source), SOURCE_COLOURS,
               "speed set by", "outside lower center")
    for key, label in STRIP_LABELS.items():
        axes[key].set_yticks([])
        axes[key].set_ylabel(label, rotation=0, ha="right", va="center")
    t, speed = log.array("t"), log.array("speed")
    dynamics.draw_accel(axes["accel"], t, speed)
    dynamics.draw_jerk(axes["jerk"], t, speed)
    _draw_margins(axes, result)
    draw_marks(list(axes.values()), story_marks(result))
    if runs:
        ax.set_xlim(runs[0][1], runs[-1][2])
    axes["offset"].set_xlabel("time [s]")
    return fig


def plot_speed_profile(result: RunResult, path: Path) -> Path:
    """Write the run's speed profile and margins as a PNG of `SIZE` at `DPI` to `path` (its
    directory is made; the file appears whole, through a temporary file beside it). Returns
    `path`."""
    fig = speed_profile_figure(result)
    png = io.BytesIO()
    fig.savefig(png, format="png", dpi=DPI)
    write_atomic(path, png.getvalue())
    return path
