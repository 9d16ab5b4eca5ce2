"""The storyboard's state changes in a run's outputs: each variable, parameter and
environment an OpenSCENARIO storyboard set (`avsim.run.storyboard.state.StateChange`), as
the result file's `storyboard_state` entries and as the recording's event lines.

The environment is recorded as the file sets it (SI units: angles [rad], illuminance [lx],
lengths [m], temperature [K], pressure [Pa], precipitation [mm/h], wind [m/s], the time of
day as written and as seconds since 1970-01-01T00:00:00 UTC); what the world renders of it
is `avsim.run.environment`'s."""

from __future__ import annotations

import dataclasses

from avsim.run.storyboard.state import StateChange
from avsim.scenario.openscenario.environment import Environment


def state_change_json(change: StateChange) -> dict[str, object]:
    """A change as a result entry: t [s], kind, name, value (a variable's or parameter's
    new value; for an environment, the environment itself)."""
    value: object = change.value
    if change.environment is not None:
        value = dataclasses.asdict(change.environment)
    return {"t": round(change.t, 4), "kind": change.kind, "name": change.name, "value": value}


def _environment_text(env: Environment) -> str:
    parts = []
    if env.time_of_day is not None:
        animated = ", animated" if env.time_of_day.animation else ""
        parts.append(f"time of day {env.time_of_day.date_time}{animated}")
    weather = env.weather
    if weather is not None and weather.fog is not None:
        parts.append(f"fog {weather.fog.visual_range:g} m")
    if weather is not None and weather.precipitation is not None:
        parts.append(f"precipitation {weather.precipitation.kind}")
    if weather is not None and weather.sun is not None and weather.sun.illuminance is not None:
        parts.append(f"sun {weather.sun.illuminance:g} lx")
    if env.road_condition is not None:
        parts.append(f"friction x{env.road_condition.friction_scale_factor:g} (not applied)")
    return f"environment {env.name}" + (f": {', '.join(parts)}" if parts else "")


def state_change_text(change: StateChange) -> str:
    """A change as one event line of the recording."""
    if change.environment is not None:
        return f"storyboard: {_environment_text(change.environment)}"
    value = change.value
    shown = ("true" if value else "false") if isinstance(value, bool) else value
    return f"storyboard: {change.kind} {change.name} = {shown}"
