"""Reading the entity actions (`entity_actions`): a GlobalAction's EntityAction, the
PrivateActions VisibilityAction and AppearanceAction (LightStateAction; AnimationAction is
refused). Everything is checked when the file is read: names against their schema
enumerations, times within `MAX_TIME`, colours within 0..1."""

from __future__ import annotations

from collections.abc import Callable

from avsim.scenario.openscenario.attributes import unsupported
from avsim.scenario.openscenario.context import Context
from avsim.scenario.openscenario.entity_actions import (
    COLOUR_TYPES,
    VEHICLE_LIGHTS,
    AddEntityAction,
    DeleteEntityAction,
    EntityAction,
    LightState,
    LightStateAction,
    VisibilityAction,
)
from avsim.scenario.openscenario.limits import MAX_TIME
from avsim.scenario.openscenario.parse_positions import parse_position
from avsim.scenario.openscenario.xmlread import Node

MAX_INTENSITY = 1.0e6  # [cd] a light's luminous intensity at most (a headlamp: ~1e5)


def parse_entity_action(node: Node, ctx: Context) -> EntityAction:
    """An EntityAction: AddEntityAction (with its Position) or DeleteEntityAction."""
    entity = ctx.entity_ref(node)
    body = node.only_child()
    if body.tag == "AddEntityAction":
        return AddEntityAction(entity, parse_position(body.need("Position"), ctx))
    if body.tag == "DeleteEntityAction":
        return DeleteEntityAction(entity)
    raise unsupported(body)


def parse_visibility(node: Node, ctx: Context) -> VisibilityAction:
    """A VisibilityAction; 1.2's SensorReferenceSet (which sensors) is refused."""
    for child in node.children:
        raise unsupported(child)
    a = ctx.attrs
    return VisibilityAction(graphics=a.boolean(node, "graphics"),
                            traffic=a.boolean(node, "traffic"),
                            sensors=a.boolean(node, "sensors"))


def _light_type(node: Node, ctx: Context) -> str:
    inner = node.only_child()
    if inner.tag == "VehicleLight":
        return ctx.attrs.choice(inner, "vehicleLightType", VEHICLE_LIGHTS)
    if inner.tag == "UserDefinedLight":
        return "user:" + ctx.attrs.text(inner, "userDefinedLightType")
    raise unsupported(inner)


def _colour(node: Node | None, ctx: Context) -> tuple[str | None,
                                                       tuple[float, float, float] | None]:
    if node is None:
        return None, None
    a = ctx.attrs
    kind = a.choice(node, "colorType", COLOUR_TYPES)
    if not node.children:
        return kind, None
    inner = node.only_child()
    if inner.tag != "ColorRgb":
        raise unsupported(inner)
    rgb = tuple(a.bounded(inner, c, 0.0, 1.0, "(fraction)") for c in ("red", "green", "blue"))
    return kind, (rgb[0], rgb[1], rgb[2])


def _light_state(node: Node, ctx: Context) -> LightState:
    a = ctx.attrs
    colour, rgb = _colour(node.child("Color"), ctx)
    return LightState(
        mode=a.choice(node, "mode", ("on", "off", "flashing")),  # type: ignore[arg-type]
        intensity=a.opt_bounded(node, "luminousIntensity", 0.0, MAX_INTENSITY, "cd"),
        flashing_on=a.opt_bounded(node, "flashingOnDuration", 0.0, MAX_TIME, "s"),
        flashing_off=a.opt_bounded(node, "flashingOffDuration", 0.0, MAX_TIME, "s"),
        colour=colour, rgb=rgb)


def parse_light_state(node: Node, ctx: Context) -> LightStateAction:
    """A LightStateAction: which light, its state, the transition time."""
    return LightStateAction(
        light=_light_type(node.need("LightType"), ctx),
        state=_light_state(node.need("LightState"), ctx),
        transition_time=ctx.attrs.opt_bounded(node, "transitionTime", 0.0, MAX_TIME,
                                              "s") or 0.0)


def _appearance(node: Node, ctx: Context) -> LightStateAction:
    body = node.only_child()
    if body.tag != "LightStateAction":
        raise unsupported(body)
    return parse_light_state(body, ctx)


APPEARANCE_READERS: dict[str, Callable[[Node, Context], VisibilityAction | LightStateAction]] = {
    "VisibilityAction": parse_visibility,
    "AppearanceAction": _appearance,
    "LightStateAction": parse_light_state,
}
