"""The world's environment (`world.environment.SceneEnvironment`) from an OpenSCENARIO
`Environment` an EnvironmentAction set.

- Light: the file's `Sun` where given: its elevation and azimuth, and its illuminance as the
  scene's (a moon written as a dim sun is night); a `Sun` without illuminance lights the
  scene as a clear sky with the sun at its elevation (`world.environment.sky_illuminance`),
  dimmed by the cloud cover; without a `Sun`, a `TimeOfDay` places the sun
  (`world.environment.solar_elevation`, at the time the action starts: an animated time of
  day does not move it later). Neither: the light in effect is kept.
- Fog: its visual range, everywhere (its `BoundingBox` is not a limit: the fog fills the
  world). A `Weather` without `Fog` clears the fog.
- Precipitation: rain or snow at `precipitationIntensity` [mm/h]; 1.0's `intensity` (0..1)
  is taken as a share of `FULL_INTENSITY` mm/h; `dry`: none.
- `RoadCondition.frictionScaleFactor` scales the road's friction; `wetness` is recorded only.

A part the Environment leaves out (1.1 and later: `TimeOfDay`, `Weather`, `RoadCondition`
are optional) keeps what was in effect.
"""

from __future__ import annotations

from dataclasses import replace

from avsim.scenario.openscenario.environment import Environment, Weather
from world.environment import (
    NO_FOG,
    SceneEnvironment,
    cloud_factor,
    sky_illuminance,
    solar_elevation,
)

FULL_INTENSITY = 50.0  # [mm/h] 1.0's precipitation intensity 1: violent rain (> 50 mm/h, AMS)
OKTAS = {  # fractionalCloudCover -> oktas (nine: sky obscured, taken as eight)
    "zeroOktas": 0.0, "oneOktas": 1.0, "twoOktas": 2.0, "threeOktas": 3.0,
    "fourOktas": 4.0, "fiveOktas": 5.0, "sixOktas": 6.0, "sevenOktas": 7.0,
    "eightOktas": 8.0, "nineOktas": 8.0,
}
CLOUD_STATES = {"free": 0.0, "cloudy": 4.0, "overcast": 8.0, "rainy": 8.0, "skyOff": 0.0}
#   1.0 / 1.1 cloudState -> oktas


def scene_environment(env: Environment, previous: SceneEnvironment,
                      time_of_day: float | None) -> SceneEnvironment:
    """What the world renders for `env` set while `previous` was in effect; `time_of_day`:
    [s] since 1970-01-01 UTC, the environment's time of day now (None: none given)."""
    out = _lit(env.weather, time_of_day, previous)
    if env.weather is not None:
        out = _weathered(env.weather, out)
    if env.road_condition is not None:
        out = replace(out, friction_scale=env.road_condition.friction_scale_factor)
    return out


def _oktas(weather: Weather | None) -> float:
    """[oktas] the weather's cloud cover (0: none given)."""
    if weather is None:
        return 0.0
    if weather.cloud_cover is not None:
        return OKTAS[weather.cloud_cover]
    return CLOUD_STATES.get(weather.cloud_state or "free", 0.0)


def _lit(weather: Weather | None, time_of_day: float | None,
         previous: SceneEnvironment) -> SceneEnvironment:
    """`previous` with the light of the sun or the time of day (module doc)."""
    sun = weather.sun if weather is not None else None
    if sun is not None:
        illuminance = sun.illuminance if sun.illuminance is not None else (
            sky_illuminance(sun.elevation) * cloud_factor(_oktas(weather)))
        return replace(previous, illuminance=illuminance, sun_elevation=sun.elevation,
                       sun_azimuth=sun.azimuth)
    if time_of_day is not None:
        elevation = solar_elevation(time_of_day)
        return replace(previous, sun_elevation=elevation,
                       illuminance=sky_illuminance(elevation) * cloud_factor(_oktas(weather)))
    return previous


def _weathered(weather: Weather, lit: SceneEnvironment) -> SceneEnvironment:
    """`lit` with the weather's fog and precipitation."""
    fog = weather.fog.visual_range if weather.fog is not None else NO_FOG
    rate, snow = 0.0, False
    p = weather.precipitation
    if p is not None and p.kind != "dry":
        snow = p.kind == "snow"
        if p.rate is not None:
            rate = p.rate
        elif p.intensity is not None:
            rate = p.intensity * FULL_INTENSITY
    return replace(lit, fog_visual_range=fog, precipitation=rate, snow=snow)
