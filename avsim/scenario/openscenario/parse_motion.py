"""Reading the motion actions beyond speed and lane: SynchronizeAction,
LateralDistanceAction, SpeedProfileAction (1.2), and DynamicConstraints."""

from __future__ import annotations

from collections.abc import Callable

from avsim.scenario.openscenario.actions import (
    DynamicConstraints,
    FinalSpeed,
    LateralDistanceAction,
    PrivateAction,
    SpeedProfileAction,
    SpeedProfileEntry,
    SteadyState,
    SynchronizeAction,
)
from avsim.scenario.openscenario.attributes import unsupported
from avsim.scenario.openscenario.context import Context
from avsim.scenario.openscenario.limits import (
    MAX_DISTANCE,
    MAX_PROFILE_ENTRIES,
    MAX_SPEED,
    MAX_TIME,
)
from avsim.scenario.openscenario.parse_positions import parse_position
from avsim.scenario.openscenario.xmlread import Node

COORDINATE_SYSTEMS = ("entity", "lane", "road", "trajectory")
LATERAL_DISPLACEMENTS = ("any", "leftToReferencedEntity", "rightToReferencedEntity")


def parse_constraints(node: Node | None, ctx: Context) -> DynamicConstraints | None:
    if node is None:
        return None
    a = ctx.attrs
    return DynamicConstraints(
        max_acceleration=a.opt_number(node, "maxAcceleration"),
        max_deceleration=a.opt_number(node, "maxDeceleration"),
        max_speed=a.opt_bounded(node, "maxSpeed", 0.0, MAX_SPEED, "m/s"),
        max_acceleration_rate=a.opt_number(node, "maxAccelerationRate"),
        max_deceleration_rate=a.opt_number(node, "maxDecelerationRate"),
    )


def _steady_state(node: Node, ctx: Context) -> SteadyState | None:
    a = ctx.attrs
    inner = [c for c in node.children
             if c.tag in ("TargetDistanceSteadyState", "TargetTimeSteadyState")]
    if not inner:
        return None
    if len(inner) > 1:
        raise node.error("needs at most one steady state")
    if inner[0].tag == "TargetDistanceSteadyState":
        return SteadyState(a.bounded(inner[0], "distance", 0.0, MAX_DISTANCE, "m"), None)
    return SteadyState(None, a.bounded(inner[0], "time", 0.0, MAX_TIME, "s"))


def _final_speed(node: Node | None, ctx: Context) -> FinalSpeed | None:
    if node is None:
        return None
    a = ctx.attrs
    inner = node.only_child()
    if inner.tag == "AbsoluteSpeed":
        return FinalSpeed(a.bounded(inner, "value", 0.0, MAX_SPEED, "m/s"), "absolute",
                          _steady_state(inner, ctx))
    if inner.tag == "RelativeSpeedToMaster":
        kind = a.choice(inner, "speedTargetValueType", ("delta", "factor"))
        value = (a.bounded(inner, "value", -MAX_SPEED, MAX_SPEED, "m/s") if kind == "delta"
                 else a.bounded(inner, "value", 0.0, 100.0, "-"))
        return FinalSpeed(value, kind, _steady_state(inner, ctx))  # type: ignore[arg-type]
    raise unsupported(inner)


def _tolerance(node: Node, ctx: Context, name: str) -> float:
    value = ctx.attrs.opt_bounded(node, name, 0.0, MAX_DISTANCE, "m")
    return 0.0 if value is None else value


def _synchronize(node: Node, ctx: Context) -> PrivateAction:
    return SynchronizeAction(
        master=ctx.entity_ref(node, "masterEntityRef"),
        master_target=parse_position(node.need("TargetPositionMaster"), ctx),
        target=parse_position(node.need("TargetPosition"), ctx),
        final_speed=_final_speed(node.child("FinalSpeed"), ctx),
        tolerance_master=_tolerance(node, ctx, "targetToleranceMaster"),
        tolerance=_tolerance(node, ctx, "targetTolerance"),
    )


def _lateral_distance(node: Node, ctx: Context) -> PrivateAction:
    a = ctx.attrs
    return LateralDistanceAction(
        entity=ctx.entity_ref(node),
        distance=a.opt_bounded(node, "distance", 0.0, MAX_DISTANCE, "m"),
        freespace=a.boolean(node, "freespace"),
        continuous=a.boolean(node, "continuous"),
        coordinate_system=a.choice_or(node, "coordinateSystem", COORDINATE_SYSTEMS, "entity"),
        displacement=a.choice_or(node, "displacement", LATERAL_DISPLACEMENTS, "any"),
        constraints=parse_constraints(node.child("DynamicConstraints"), ctx),
    )


def _speed_profile(node: Node, ctx: Context) -> PrivateAction:
    a = ctx.attrs
    items = node.all("SpeedProfileEntry")
    if not items:
        raise node.error("needs at least one SpeedProfileEntry")
    if len(items) > MAX_PROFILE_ENTRIES:
        raise node.error(f"must have <= {MAX_PROFILE_ENTRIES} SpeedProfileEntry elements, "
                         f"got {len(items)}")
    entries = tuple(
        SpeedProfileEntry(a.bounded(e, "speed", -MAX_SPEED, MAX_SPEED, "m/s"),
                          a.opt_bounded(e, "time", 0.0, MAX_TIME, "s"))
        for e in items)
    return SpeedProfileAction(
        entity=ctx.entity_ref(node) if "entityRef" in node.attrs else None,
        following_mode=a.choice(node, "followingMode", ("position", "follow")),  # type: ignore[arg-type]
        entries=entries,
        constraints=parse_constraints(node.child("DynamicConstraints"), ctx),
    )


MOTION_READERS: dict[str, Callable[[Node, Context], PrivateAction]] = {
    "SynchronizeAction": _synchronize,
    "LateralDistanceAction": _lateral_distance,
    "SpeedProfileAction": _speed_profile,
}
