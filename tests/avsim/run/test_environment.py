"""An OpenSCENARIO Environment made the world's (`avsim.run.environment`): the file's sun,
the time of day, fog, precipitation and friction; parts left out keep what was in effect."""

from __future__ import annotations

import math
from dataclasses import replace

import pytest

from avsim.run.environment import FULL_INTENSITY, scene_environment
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
from world.environment import CLEAR, NO_FOG, sky_illuminance

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
