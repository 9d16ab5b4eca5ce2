"""Marks of the run's story on every panel of its plot (`avsim.report.speed_plot`): a
vertical line where each scripted action or event fired (the result's `story`), and a
hatched span over each timed ego event's window (sensor faults such as `camera_blackout`,
`lidar_outage`, `gnss_outage`, and the accelerator override: from when it fired for its
`duration` [s]), each labelled once at the top of the first panel.

Pure: no pyplot, no PyBullet.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

from matplotlib.axes import Axes

if TYPE_CHECKING:
    from avsim.run.runner import RunResult

EVENT_COLOUR = "#3e2723"  # the lines where story entries fired
WINDOW_COLOUR = "#ff6f00"  # the hatched spans of timed events (hatch and edge; no fill)
WINDOW_HATCH = "/"
WINDOW_HATCH_WIDTH = 0.6  # [pt] thin: the lines under it stay readable


@dataclass(frozen=True, slots=True)
class Mark:
    """A story entry that fired: at `t` [s], for `duration` [s] (0: an instant)."""

    t: float  # [s]
    duration: float  # [s]
    label: str


def story_marks(result: RunResult) -> list[Mark]:
    """Each story entry that fired, in time order: an actor's action as `actor: kind`, an
    ego event as its kind with its window when it has a duration, a storyboard element by
    its name."""
    events = result.scenario.world.events
    marks = []
    for e in result.story:
        if e.fired_at is None:
            continue
        duration = 0.0
        if e.element is not None:
            label = e.element
        elif e.actor is not None:
            label = f"{e.actor}: {e.kind}"
        else:
            label = e.kind.replace("_", " ")
            duration = float(getattr(events[e.index].event, "duration", 0.0)) \
                if e.index < len(events) else 0.0
        marks.append(Mark(e.fired_at, duration, label))
    return sorted(marks, key=lambda m: (m.t, m.label))


def draw_marks(axes: Sequence[Axes], marks: Sequence[Mark]) -> None:
    """The marks on every axes; their labels at the top of the first."""
    for ax in axes:
        for m in marks:
            if m.duration > 0.0:
                ax.axvspan(m.t, m.t + m.duration, facecolor="none", edgecolor="none",
                           hatch=WINDOW_HATCH, hatchcolor=WINDOW_COLOUR,
                           hatch_linewidth=WINDOW_HATCH_WIDTH, linewidth=0.0, zorder=1)
            ax.axvline(m.t, color=EVENT_COLOUR, linestyle="-.", linewidth=1.0, zorder=3)
    if not axes:
        return
    top = axes[0]
    for m in marks:
        text = m.label + (f" ({m.duration:g} s)" if m.duration > 0.0 else "")
        top.annotate(text, xy=(m.t, 1.0), xycoords=("data", "axes fraction"),
                     xytext=(2, -2), textcoords="offset points", rotation=90, ha="left",
                     va="top", fontsize="small", color=EVENT_COLOUR, zorder=4,
                     bbox={"boxstyle": "round,pad=0.1", "facecolor": "white", "alpha": 0.7,
                           "linewidth": 0})
