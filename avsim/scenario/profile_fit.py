"""Whether a sensor profile can run a scenario honestly: the stack sees only its sensors,
so a scenario whose story needs a sensor the profile lacks is refused before it runs, with
the one-line error saying why, rather than run to a verdict that means nothing.

Today one such need: traffic lights are read from the front camera's pixels (the HD map has
their heads, not their signal plans), so `--profile none` (GNSS and odometry on the map, no
camera) cannot run a route with a light on it: the car would stand at the first one for
the whole run."""

from __future__ import annotations

from avsim.scenario.errors import ScenarioError
from avsim.scenario.scenario import Scenario
from world.spec import TrafficLightSpec

CAMERALESS = "none"  # the profile without cameras


def check_profile(scenario: Scenario, profile: str, file: str) -> None:
    """`ScenarioError` (`file`, the key that asks for it) when `profile` cannot run
    `scenario` honestly; None when it can."""
    if profile != CAMERALESS:
        return
    if any(isinstance(f, TrafficLightSpec) for f in scenario.world.road.features):
        key = "town.junctions" if scenario.world.town is not None else "road.features"
        raise ScenarioError(file, key, "traffic lights on the route are read by the camera, "
                            "and --profile none has none: use fast, default or paper")
