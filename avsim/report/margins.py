"""The margins of a run for its plot (`avsim.report.speed_plot`): the gap and the time to
collision to the lead, the lateral offset in the lane, and the motion FSM's manoeuvres.

- Gap [m]: the log's bumper gap to the vehicle ahead in the ego's lane (truth and map), with
  UN R157's minimum following distance d_min at the ego's true speed
  (`avsim.criteria.regulations.r157_min_gap`, the judge's) as the reference; where the gap
  is under d_min the space between them is shaded. The gap axis shows at most `GAP_VIEW`
  times the run's largest d_min (a far lead leaves the top).
- Time to collision [s] (`world.truth.time_to_collision`): gap / closing speed where the
  ego closes on its lead (ego speed - lead speed > 0), nothing where there is no lead or it
  pulls away; shown from 0 to `TTC_VIEW` (longer ones leave the top), with `TTC_HARD` (2.5
  s: a lead closer than this in time seldom leaves a comfortable stop; the stack decides on
  the deceleration it needs, `planner.acc_control.need`) as a dashed line.
- Lateral offset [m]: the ego centre's true offset from the centre of the lane the stack
  keeps (the log's `cross_track`, left +), with +-(lane width - car width) / 2 as the bound
  where the body is still inside that lane (`lane_margin`: the lane width of the route's
  segment at the ego's station, the body width from the car's URDF). During a lane change
  the offset runs out to the bound and beyond until the stack keeps the target lane.
- Manoeuvres (`motion_runs`): the motion FSM's recorded states (`avsim.report.states`), with
  two kinds of lane change told apart by the logged reasons of its changes (`MOTION_REASONS`):
  one that ends by an abort (back to the origin lane), and a flat tyre's pull over to the
  right. Lane keeping gets no band (`NEUTRAL`).

Pure: no pyplot, no PyBullet.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from matplotlib.axes import Axes

from avsim.criteria.regulations import r157_min_gap
from avsim.report.bands import FloatArray, Run, value_runs
from avsim.report.states import (
    LANE_CHANGE_LEFT,
    LANE_CHANGE_RIGHT,
    LANE_CHANGES,
    LANE_KEEP,
    MOTION_MACHINE,
    TURN_LEFT,
    TURN_RIGHT,
    U_TURN,
    RecordedChange,
)
from world.spec import RoadSpec

TTC_VIEW = 10.0  # [s] the time-to-collision axis' top
TTC_HARD = 2.5  # [s] a time to collision marked as short (module doc)
GAP_VIEW = 4.0  # [-] the gap axis' top: at most this many times the run's largest d_min
ABORTED = "lane_change_aborted"  # a lane change that ended by an abort
PULL_OVER = "pull_over"  # a lane change to the right entered for a flat tyre
MOTION_REASONS = {ABORTED: "abort", PULL_OVER: "pull over"}  # what the logged reason holds
NEUTRAL = frozenset({LANE_KEEP})  # states with no band
# one colour per manoeuvre (legend order), none of them an ACC mode's or a speed source's
MOTION_COLOURS: dict[str, str] = {
    LANE_CHANGE_LEFT: "#0203e2",
    LANE_CHANGE_RIGHT: "#0aff02",
    ABORTED: "#fe01b1",
    PULL_OVER: "#7ebd01",
    TURN_RIGHT: "#703be7",
    TURN_LEFT: "#2dfe54",
    U_TURN: "#06470c",
}
LEAD_COLOUR = "#1a237e"  # the lead's lines (its speed, the gap to it)
GAP_LINES = {  # series -> (label, colour, style, width); no band's colour (their pixels
    #   would count as a band's in the tests)
    "gap": ("gap to the lead", LEAD_COLOUR, "-", 1.5),
    "d_min": ("R157 d_min at ego speed", "#c62828", "--", 1.2),
    "ttc": ("time to collision", "#e65100", "-", 1.5),
    "ttc_hard": (f"ttc_hard {TTC_HARD:g} s", "#ad1457", "--", 1.2),
    "offset": ("lateral offset (true)", "#000000", "-", 1.2),
    "bound": ("body at the lane's edge", "#00695c", "--", 1.0),
}
UNDER_D_MIN = "#ef9a9a"  # the shading where the gap is under d_min


def min_gap(speed: FloatArray) -> FloatArray:
    """[m] per tick: UN R157's minimum following distance at the ego's speed [m/s]."""
    return np.fromiter((r157_min_gap(float(v)) for v in speed), dtype=np.float64,
                       count=len(speed))


def lane_margin(road: RoadSpec, station: FloatArray, car_width: float) -> FloatArray:
    """[m] per tick: (lane width - car width [m]) / 2 for the route segment at the station
    [m] (before the route: its first; past its end: its last)."""
    if not road.segments:
        return np.full(np.shape(station), np.nan, dtype=np.float64)
    ends = np.cumsum([seg.length for seg in road.segments])
    widths = np.array([seg.lane_width for seg in road.segments], dtype=np.float64)
    i = np.minimum(np.searchsorted(ends, station, side="right"), len(ends) - 1)
    return (widths[i] - car_width) / 2.0


def _label(run: Run, moves: Sequence[RecordedChange], tol: float) -> str:
    """The manoeuvre a motion run shows: its state, or for a lane change `ABORTED` (left by
    an abort at its end) or `PULL_OVER` (entered for a flat tyre at its start)."""
    state, start, end = run
    if state not in LANE_CHANGES:
        return state
    left = [c.reason for c in moves if c.source == state and abs(c.t - end) <= tol]
    if any(MOTION_REASONS[ABORTED] in reason for reason in left):
        return ABORTED
    entered = [c.reason for c in moves if c.target == state and abs(c.t - start) <= tol]
    if any(MOTION_REASONS[PULL_OVER] in reason for reason in entered):
        return PULL_OVER
    return state


def motion_runs(t: Sequence[float], motion: Sequence[str],
                changes: Sequence[RecordedChange]) -> list[Run]:
    """(manoeuvre, start [s], end [s]) of each run of equal motion states (`value_runs`;
    `motion`: the recorded state per tick), a lane change labelled by the reasons of the
    motion FSM's changes (`changes`, the run's) within half a tick of its start and end
    (`_label`)."""
    runs = value_runs(t, motion)
    tol = 0.5 * (t[1] - t[0]) if len(t) > 1 else 0.0  # [s]
    moves = [c for c in changes if c.machine == MOTION_MACHINE]
    return [(_label(run, moves, tol), run[1], run[2]) for run in runs]


def _line(ax: Axes, t: FloatArray, values: FloatArray, key: str) -> None:
    label, colour, style, width = GAP_LINES[key]
    ax.plot(t, values, style, color=colour, linewidth=width, label=label, zorder=2)


def _finish(ax: Axes, ylabel: str) -> None:
    ax.set_ylabel(ylabel)
    ax.grid(True, alpha=0.3, zorder=1)
    ax.legend(loc="upper right", fontsize="small", framealpha=0.8)


def draw_gap(ax: Axes, t: FloatArray, gap: FloatArray, d_min: FloatArray) -> None:
    """The gap to the lead and d_min over time [s], shaded where the gap is under it."""
    _line(ax, t, gap, "gap")
    _line(ax, t, d_min, "d_min")
    under = np.isfinite(gap) & (gap < d_min)
    if under.any():
        ax.fill_between(t, gap, d_min, where=under, color=UNDER_D_MIN, linewidth=0,
                        zorder=1, label="gap under d_min")
    finite = gap[np.isfinite(gap)]
    d_top = float(d_min.max()) if len(d_min) else 2.0
    shown = min(float(finite.max()), GAP_VIEW * d_top) if len(finite) else d_top
    ax.set_ylim(min(0.0, float(finite.min())) if len(finite) else 0.0,
                1.1 * max(shown, d_top))
    _finish(ax, "gap [m]")


def draw_ttc(ax: Axes, t: FloatArray, ttc: FloatArray) -> None:
    """The time to collision to the lead over time [s], 0 to `TTC_VIEW`, and `TTC_HARD`."""
    _line(ax, t, ttc, "ttc")
    label, colour, style, width = GAP_LINES["ttc_hard"]
    ax.axhline(TTC_HARD, linestyle=style, color=colour, linewidth=width, label=label,
               zorder=2)
    ax.set_ylim(0.0, TTC_VIEW)
    _finish(ax, "TTC [s]")


def draw_offset(ax: Axes, t: FloatArray, offset: FloatArray, bound: FloatArray) -> None:
    """The lateral offset over time [s], a zero line, and +-`bound` where it is known."""
    ax.axhline(0.0, color="#616161", linewidth=0.8, zorder=1)
    _line(ax, t, offset, "offset")
    if np.isfinite(bound).any():
        _line(ax, t, bound, "bound")
        _, colour, style, width = GAP_LINES["bound"]
        ax.plot(t, -bound, style, color=colour, linewidth=width, zorder=2)
    _finish(ax, "lateral offset [m]")
