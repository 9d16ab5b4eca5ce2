"""`traffic_light`: a light on a plain road, red when the ego comes. It stops before the
line, goes on green and pulls away without overshooting the limit (the stop law's arrival
tolerance keeps the speed loop's integrator empty while it waits)."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from avsim.run.runner import RunResult
from tests.scenarios import golden
from world.hdmap import LightColour
from world.map.signals import light_colour
from world.spec import TrafficLightSpec

pytestmark = pytest.mark.slow
FRONT = 2.4  # [m] the ego's centre -> front bumper


@pytest.fixture(scope="module")
def run(run_scenario: Callable[..., RunResult]) -> RunResult:
    return run_scenario("traffic_light", record=False)


def test_it_stops_at_red_and_goes_on_green(run: RunResult) -> None:
    assert not any(c.failed for c in run.criteria), run.criteria
    light = next(f for f in run.scenario.world.road.features if isinstance(f, TrafficLightSpec))
    t, v, s = run.log.array("t"), run.log.array("speed"), run.log.array("station")
    front = s + FRONT
    red = np.array([light_colour(light, x) is LightColour.RED for x in t])
    waiting = (v < 0.1) & red & (front < light.s) & (front > light.s - 4.0)
    assert waiting.sum() * (t[1] - t[0]) > 5.0  # it stood at the line for the red
    crossing = int(np.argmax(front > light.s))
    assert light_colour(light, float(t[crossing])) is LightColour.GREEN
    assert t[crossing] - light_colour_change(light, t, LightColour.GREEN) < 3.0  # went at once
    acc = [c.target for c in run.state_changes if c.machine == "acc"]
    assert "red_light" in acc


def test_it_pulls_away_to_the_limit_without_overshoot(run: RunResult) -> None:
    c = {r.name: r for r in run.criteria}
    assert c["speed_limit"].value < 0.5  # [km/h] over 50 (1.9 before the stop law's fix)


def light_colour_change(light: TrafficLightSpec, t: np.ndarray, colour: LightColour) -> float:
    """[s] the first time in `t` the light shows `colour` after having shown another."""
    shown = np.array([light_colour(light, x) is colour for x in t])
    k = int(np.argmax(~shown))
    return float(t[k + int(np.argmax(shown[k:]))])


def test_result_matches_golden(run: RunResult) -> None:
    golden.check(run, "traffic_light")
