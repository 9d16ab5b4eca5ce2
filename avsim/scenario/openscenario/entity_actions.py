"""Actions on an entity's presence and looks: the GlobalAction's EntityAction (add an
entity at a position, delete it), and the PrivateActions VisibilityAction and
AppearanceAction's LightStateAction. Times in seconds, luminous intensity in candela."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from avsim.scenario.openscenario.positions import Position

LightMode = Literal["on", "off", "flashing"]

VEHICLE_LIGHTS = ("daytimeRunningLights", "lowBeam", "highBeam", "fogLights",
                  "fogLightsFront", "fogLightsRear", "brakeLights", "warningLights",
                  "indicatorLeft", "indicatorRight", "reversingLights",
                  "licensePlateIllumination", "specialPurposeLights")  # 1.2's VehicleLightType
COLOUR_TYPES = ("other", "red", "yellow", "green", "blue", "violet", "orange", "brown",
                "black", "grey", "white")  # 1.2's ColorType


@dataclass(frozen=True, slots=True)
class AddEntityAction:
    """The entity enters the world at `position` (held out of it until then when no Init
    action places it)."""

    entity: str
    position: Position


@dataclass(frozen=True, slots=True)
class DeleteEntityAction:
    """The entity leaves the world: no body, no contacts, unseen; conditions skip it."""

    entity: str


@dataclass(frozen=True, slots=True)
class VisibilityAction:
    """Who sees the entity: the renderer (`graphics`), other traffic (`traffic`), the
    sensors (`sensors`)."""

    graphics: bool
    traffic: bool
    sensors: bool


@dataclass(frozen=True, slots=True)
class LightState:
    """A light's state: on, off or flashing (the on and off spans [s] when flashing), its
    luminous intensity [cd] and colour (the ColorType, RGB [-] 0..1) when written."""

    mode: LightMode
    intensity: float | None  # [cd]
    flashing_on: float | None  # [s]
    flashing_off: float | None  # [s]
    colour: str | None  # ColorType
    rgb: tuple[float, float, float] | None  # [-] each 0..1


@dataclass(frozen=True, slots=True)
class LightStateAction:
    """One light of the entity (a VehicleLightType, or a user-defined type's name) takes
    `state` over `transition_time` [s]."""

    light: str  # a VEHICLE_LIGHTS name, or "user:<type>" for a UserDefinedLight
    state: LightState
    transition_time: float  # [s] 0 when not written


EntityAction = AddEntityAction | DeleteEntityAction
