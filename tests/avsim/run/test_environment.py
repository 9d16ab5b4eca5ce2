"""An OpenSCENARIO Environment made the world's (`avsim.run.environment`): the file's sun,
the time of day, fog, precipitation and friction; parts left out keep what was in effect."""

from __future__ import annotations

import math
import shutil
from dataclasses import replace
from pathlib import Path

import pytest

from avsim.run.environment import FULL_INTENSITY, scene_environment
from avsim.run.runner import Runner
from avsim.scenario.load import load_scenario
from avsim.scenario.openscenario.environment import (
    Environment,
    Fog,
    Precipitation,
    RoadCondition,
    Sun,
    TimeOfDay,
    Weather,
    epoch_of,
)
from world.core.client import GROUND_FRICTION
from world.core.rates import PHYSICS_RATE
from world.environment import CLEAR, NO_FOG, sky_illuminance

EXAMPLES = Path(__file__).resolve().parents[3] / "docs" / "examples"

WEATHER = Weather(cloud_state=None, cloud_cover=None, temperature=None, pressure=None,
                  sun=None, fog=None, precipitation=None, wind=None)


def env(weather: Weather | None = None, time_of_day: TimeOfDay | None = None,
        road: RoadCondition | None = None) -> Environment:
    return Environment("e", time_of_day, weather, road)


def test_the_files_sun_lights_the_scene() -> None:
    moon = replace(WEATHER, sun=Sun(azimuth=3.1, elevation=1.15, illuminance=0.1))
    out = scene_environment(env(moon), CLEAR, None)
    assert out.illuminance == 0.1  # NCAP's night: a dim sun high up
    assert (out.sun_elevation, out.sun_azimuth) == (1.15, 3.1)
    low = replace(WEATHER, sun=Sun(azimuth=0.0, elevation=math.radians(-6.0), illuminance=None),
                  cloud_cover="eightOktas")
    assert scene_environment(env(low), CLEAR, None).illuminance == pytest.approx(
        0.25 * sky_illuminance(math.radians(-6.0)))


def test_a_time_of_day_places_the_sun() -> None:
    midnight = TimeOfDay(False, "2020-06-21T00:00:00", epoch_of("2020-06-21T00:00:00"))
    out = scene_environment(env(time_of_day=midnight), CLEAR, midnight.epoch)
    assert out.sun_elevation < 0.0 and out.illuminance < 1.0
    noon = epoch_of("2020-06-21T12:00:00")
    assert scene_environment(env(time_of_day=midnight), CLEAR, noon).illuminance > 1e4


def test_fog_precipitation_and_friction() -> None:
    weather = replace(WEATHER, fog=Fog(30.0, None),
                      precipitation=Precipitation("rain", None, 0.5))
    out = scene_environment(env(weather, road=RoadCondition(0.4, None)), CLEAR, None)
    assert out.fog_visual_range == 30.0
    assert out.precipitation == 0.5 * FULL_INTENSITY and not out.snow
    assert out.friction_scale == 0.4
    snow = replace(WEATHER, precipitation=Precipitation("snow", 2.0, None))
    out = scene_environment(env(snow), out, None)
    assert (out.precipitation, out.snow, out.fog_visual_range) == (2.0, True, NO_FOG)
    assert out.friction_scale == 0.4  # no RoadCondition: the friction in effect is kept
    dry = replace(WEATHER, precipitation=Precipitation("dry", 10.0, None))
    assert scene_environment(env(dry), out, None).precipitation == 0.0


def test_parts_left_out_keep_what_is_in_effect() -> None:
    foggy = replace(CLEAR, fog_visual_range=50.0, illuminance=3.0, friction_scale=0.5)
    assert scene_environment(env(), foggy, None) == foggy


STORY = """<Story name="WeatherStory"><Act name="WeatherAct">
  <ManeuverGroup maximumExecutionCount="1" name="WeatherGroup">
    <Actors selectTriggeringEntities="false"/>
    <Maneuver name="WeatherManeuver"><Event name="Wet" priority="overwrite">
      <Action name="SetWet"><GlobalAction><EnvironmentAction><Environment name="wet">
        <Weather cloudState="free"><Fog visualRange="50"/></Weather>
        <RoadCondition frictionScaleFactor="0.3"/>
      </Environment></EnvironmentAction></GlobalAction></Action>
      <StartTrigger><ConditionGroup><Condition name="late" delay="0" conditionEdge="rising">
        <ByValueCondition><SimulationTimeCondition value="0.5" rule="greaterThan"/>
        </ByValueCondition></Condition></ConditionGroup></StartTrigger>
    </Event></Maneuver>
  </ManeuverGroup>
  <StartTrigger><ConditionGroup><Condition name="now" delay="0" conditionEdge="none">
    <ByValueCondition><SimulationTimeCondition value="0" rule="greaterOrEqual"/>
    </ByValueCondition></Condition></ConditionGroup></StartTrigger>
</Act></Story>
"""


@pytest.mark.parametrize(("duration", "friction"), [(0.4, 1.0), (1.0, 0.3)])
def test_a_story_hands_the_environment_to_the_world_when_it_starts(
        tmp_path: Path, duration: float, friction: float) -> None:
    """An EnvironmentAction at 0.5 s: before it the world is clear, after it the road has
    the file's friction (the physics' own value) and the fog is the world's."""
    shutil.copy(EXAMPLES / "straight.xodr", tmp_path / "straight.xodr")
    text = (EXAMPLES / "minimal.xosc").read_text()
    at = text.rindex("<StopTrigger>")
    (tmp_path / "wet.xosc").write_text(text[:at] + STORY + text[at:])
    runner = Runner(load_scenario(tmp_path / "wet.xosc", {"duration": duration}),
                    profile=None)
    seen: list[float] = []
    world = runner.world
    step = world.step

    def watched() -> None:  # the ground's friction in the physics, every step
        step()
        seen.append(world.client.getDynamicsInfo(world.scene.ground, -1)[1])

    world.step = watched  # type: ignore[method-assign]
    assert runner.run().error is None
    assert seen[-1] == pytest.approx(friction * GROUND_FRICTION)
    assert world.environment.friction_scale == friction
    if friction != 1.0:
        assert world.environment.fog_visual_range == 50.0
        changed = next(i for i, f in enumerate(seen) if f != seen[0])
        assert changed / PHYSICS_RATE == pytest.approx(0.5, abs=0.03)  # its trigger check
