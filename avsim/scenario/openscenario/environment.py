"""The environment of a scenario (OpenSCENARIO's Environment, set by an EnvironmentAction):
time of day, weather, road condition. SI units: angles in radians, illuminance in lux,
lengths in metres, temperatures in kelvin, pressures in pascal, precipitation in mm/h.

avsim records the environment in effect (the run's result and its recording) and hands it to
the world (`avsim.run.environment`): light, fog and precipitation for the cameras and the
LiDAR, the friction scale for the road (`docs/openscenario.md`, "The environment rendered").
"""

from __future__ import annotations

from dataclasses import dataclass
from datetime import UTC, datetime
from typing import Literal

CloudState = Literal["cloudy", "free", "overcast", "rainy", "skyOff"]  # 1.0 / 1.1
CloudCover = Literal[
    "zeroOktas", "oneOktas", "twoOktas", "threeOktas", "fourOktas", "fiveOktas", "sixOktas",
    "sevenOktas", "eightOktas", "nineOktas",
]  # 1.2+
PrecipitationType = Literal["dry", "rain", "snow"]
Wetness = Literal["dry", "moist", "wetWithPuddles", "lowFlooded", "highFlooded"]  # 1.2+


@dataclass(frozen=True, slots=True)
class TimeOfDay:
    """A date and time; `animation`: it advances with the simulation time."""

    animation: bool
    date_time: str  # ISO 8601 as written (a dateTime parameter's text)
    epoch: float  # [s] since 1970-01-01T00:00:00 UTC (a time without a zone is taken as UTC)


@dataclass(frozen=True, slots=True)
class Sun:
    azimuth: float  # [rad] from north, clockwise seen from above
    elevation: float  # [rad] above the horizon
    illuminance: float | None  # [lx] (1.2 illuminance, or 1.0 / 1.1 intensity); None: unset


@dataclass(frozen=True, slots=True)
class FogBox:
    """Fog's BoundingBox: centre (x, y, z) [m] and dimensions (length, width, height) [m]."""

    centre: tuple[float, float, float]  # [m]
    dimensions: tuple[float, float, float]  # [m]


@dataclass(frozen=True, slots=True)
class Fog:
    visual_range: float  # [m]
    box: FogBox | None


@dataclass(frozen=True, slots=True)
class Precipitation:
    kind: PrecipitationType
    rate: float | None  # [mm/h] precipitationIntensity (1.1+)
    intensity: float | None  # [-] 0..1, 1.0's intensity (deprecated in 1.1)


@dataclass(frozen=True, slots=True)
class Wind:
    direction: float  # [rad] where it blows to, from north, clockwise seen from above
    speed: float  # [m/s]


@dataclass(frozen=True, slots=True)
class Weather:
    cloud_state: CloudState | None  # 1.0 / 1.1
    cloud_cover: CloudCover | None  # 1.2+ fractionalCloudCover
    temperature: float | None  # [K] (1.2+)
    pressure: float | None  # [Pa] atmosphericPressure (1.2+)
    sun: Sun | None
    fog: Fog | None
    precipitation: Precipitation | None
    wind: Wind | None  # 1.2+


@dataclass(frozen=True, slots=True)
class RoadCondition:
    friction_scale_factor: float  # [-] on the road's friction
    wetness: Wetness | None  # 1.2+


@dataclass(frozen=True, slots=True)
class Environment:
    """The three parts are required in 1.0 and optional from 1.1 (None: not given)."""

    name: str
    time_of_day: TimeOfDay | None
    weather: Weather | None
    road_condition: RoadCondition | None


@dataclass(frozen=True, slots=True)
class EnvironmentAction:
    """Sets the environment (the one written inline or the EnvironmentCatalog's entry)."""

    environment: Environment


def epoch_of(text: str) -> float:
    """[s] since 1970-01-01T00:00:00 UTC of an ISO 8601 date-time (no zone: UTC);
    ValueError when it is not one."""
    moment = datetime.fromisoformat(text.strip())
    if moment.tzinfo is None:
        moment = moment.replace(tzinfo=UTC)
    return moment.timestamp()


def time_of_day_at(time_of_day: TimeOfDay, set_at: float, t: float) -> float:
    """[s] since the epoch of the environment's time of day at simulation time `t` [s] when
    it was set at `set_at` [s]: advanced with the simulation time when animated."""
    return time_of_day.epoch + (t - set_at if time_of_day.animation else 0.0)
