"""Reading an EnvironmentAction: its Environment inline or a CatalogReference into an
EnvironmentCatalog, into the `environment` model. Every number is bounded (the ranges of
the OpenSCENARIO 1.3 standard, closed at a physical maximum where it is open:
`docs/openscenario.md` "Bounds"); DomeImage (1.2) is refused."""

from __future__ import annotations

import math

from avsim.scenario.openscenario.attributes import unsupported
from avsim.scenario.openscenario.context import Context
from avsim.scenario.openscenario.environment import (
    Environment,
    EnvironmentAction,
    Fog,
    FogBox,
    Precipitation,
    RoadCondition,
    Sun,
    TimeOfDay,
    Weather,
    Wind,
    epoch_of,
)
from avsim.scenario.openscenario.xmlread import Node

CLOUD_STATES = ("cloudy", "free", "overcast", "rainy", "skyOff")
CLOUD_COVERS = ("zeroOktas", "oneOktas", "twoOktas", "threeOktas", "fourOktas", "fiveOktas",
                "sixOktas", "sevenOktas", "eightOktas", "nineOktas")
PRECIPITATION_TYPES = ("dry", "rain", "snow")
WETNESS = ("dry", "moist", "wetWithPuddles", "lowFlooded", "highFlooded")
MAX_ILLUMINANCE = 1.0e6  # [lx] the sun's (direct sunlight is about 1.2e5 lx)
MAX_VISUAL_RANGE = 1.0e6  # [m] fog's visual range
MAX_PRECIPITATION = 1000.0  # [mm/h] (the heaviest rain measured is a few hundred mm/h)
MAX_WIND = 150.0  # [m/s] (the strongest gust measured is about 113 m/s)
MAX_FRICTION_SCALE = 10.0  # [-] a road's friction scale factor
MIN_TEMPERATURE, MAX_TEMPERATURE = 170.0, 340.0  # [K] the standard's range
MIN_PRESSURE, MAX_PRESSURE = 80_000.0, 120_000.0  # [Pa] the standard's range
MAX_FOG_BOX = 1.0e5  # [m] a fog box's centre coordinates and dimensions, in magnitude
_KNOWN = ("ParameterDeclarations", "TimeOfDay", "Weather", "RoadCondition")
_WEATHER = ("Sun", "Fog", "Precipitation", "Wind")


def _time_of_day(node: Node | None, ctx: Context) -> TimeOfDay | None:
    if node is None:
        return None
    text = ctx.attrs.text(node, "dateTime")
    try:
        epoch = epoch_of(text)
    except ValueError:
        raise node.error(f"dateTime: not an ISO 8601 date and time: {text[:40]!r}") from None
    return TimeOfDay(ctx.attrs.boolean(node, "animation"), text, epoch)


def _sun(node: Node | None, ctx: Context) -> Sun | None:
    if node is None:
        return None
    a = ctx.attrs
    lux = a.opt_bounded(node, "illuminance", 0.0, MAX_ILLUMINANCE, "lx")
    if lux is None:
        lux = a.opt_bounded(node, "intensity", 0.0, MAX_ILLUMINANCE, "lx")
    return Sun(azimuth=a.bounded(node, "azimuth", 0.0, 2.0 * math.pi, "rad"),
               elevation=a.bounded(node, "elevation", -math.pi, math.pi, "rad"),
               illuminance=lux)


def _fog(node: Node | None, ctx: Context) -> Fog | None:
    if node is None:
        return None
    a = ctx.attrs
    box = node.child("BoundingBox")
    fog_box = None
    if box is not None:
        c, d = box.need("Center"), box.need("Dimensions")
        fog_box = FogBox(
            tuple(a.bounded(c, k, -MAX_FOG_BOX, MAX_FOG_BOX, "m") for k in "xyz"),  # type: ignore[arg-type]
            tuple(a.bounded(d, k, 0.0, MAX_FOG_BOX, "m")  # type: ignore[arg-type]
                  for k in ("length", "width", "height")))
    return Fog(a.bounded(node, "visualRange", 0.0, MAX_VISUAL_RANGE, "m"), fog_box)


def _precipitation(node: Node | None, ctx: Context) -> Precipitation | None:
    if node is None:
        return None
    a = ctx.attrs
    kind = a.choice(node, "precipitationType", PRECIPITATION_TYPES)
    return Precipitation(
        kind=kind,  # type: ignore[arg-type]
        rate=a.opt_bounded(node, "precipitationIntensity", 0.0, MAX_PRECIPITATION, "mm/h"),
        intensity=a.opt_bounded(node, "intensity", 0.0, 1.0, "[-]"))


def _wind(node: Node | None, ctx: Context) -> Wind | None:
    if node is None:
        return None
    a = ctx.attrs
    return Wind(a.bounded(node, "direction", 0.0, 2.0 * math.pi, "rad"),
                a.bounded(node, "speed", 0.0, MAX_WIND, "m/s"))


def _weather(node: Node | None, ctx: Context) -> Weather | None:
    if node is None:
        return None
    for child in node.children:
        if child.tag not in _WEATHER:
            raise unsupported(child)
    a = ctx.attrs
    state = a.choice(node, "cloudState", CLOUD_STATES) if "cloudState" in node.attrs else None
    cover = (a.choice(node, "fractionalCloudCover", CLOUD_COVERS)
             if "fractionalCloudCover" in node.attrs else None)
    return Weather(
        cloud_state=state,  # type: ignore[arg-type]
        cloud_cover=cover,  # type: ignore[arg-type]
        temperature=a.opt_bounded(node, "temperature", MIN_TEMPERATURE, MAX_TEMPERATURE, "K"),
        pressure=a.opt_bounded(node, "atmosphericPressure", MIN_PRESSURE, MAX_PRESSURE, "Pa"),
        sun=_sun(node.child("Sun"), ctx),
        fog=_fog(node.child("Fog"), ctx),
        precipitation=_precipitation(node.child("Precipitation"), ctx),
        wind=_wind(node.child("Wind"), ctx),
    )


def _road_condition(node: Node | None, ctx: Context) -> RoadCondition | None:
    if node is None:
        return None
    a = ctx.attrs
    wetness = a.choice(node, "wetness", WETNESS) if "wetness" in node.attrs else None
    return RoadCondition(
        a.bounded(node, "frictionScaleFactor", 0.0, MAX_FRICTION_SCALE, "[-]"),
        wetness)  # type: ignore[arg-type]


def parse_environment(node: Node, ctx: Context) -> Environment:
    """An Environment element, or a CatalogReference to one."""
    if node.tag == "CatalogReference":
        entry = ctx.catalogs.resolve(node, ctx.attrs, ("Environment",))
        return parse_environment(entry.node, ctx.in_scope(entry.scope, entry.node))
    if node.tag != "Environment":
        raise unsupported(node)
    ctx = ctx.with_declarations(node)
    for child in node.children:
        if child.tag not in _KNOWN:
            raise unsupported(child)
    return Environment(
        name=ctx.attrs.text(node, "name"),
        time_of_day=_time_of_day(node.child("TimeOfDay"), ctx),
        weather=_weather(node.child("Weather"), ctx),
        road_condition=_road_condition(node.child("RoadCondition"), ctx),
    )


def parse_environment_action(node: Node, ctx: Context) -> EnvironmentAction:
    return EnvironmentAction(parse_environment(node.only_child(), ctx))
