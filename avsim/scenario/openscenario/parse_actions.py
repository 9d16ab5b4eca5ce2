"""Reading a PrivateAction element into one of the `actions` dataclasses. Any action not
listed in `actions.PrivateAction` is reported as `not supported yet (<Name>)`."""

from __future__ import annotations

from collections.abc import Callable

from avsim.scenario.openscenario.actions import (
    AbsoluteTargetLane,
    AbsoluteTargetLaneOffset,
    AbsoluteTargetSpeed,
    ActivateControllerAction,
    AssignControllerAction,
    FollowTrajectoryAction,
    LaneChangeAction,
    LaneOffsetAction,
    LaneOffsetDynamics,
    LongitudinalDistanceAction,
    OverrideControllerValueAction,
    PedalOverride,
    PrivateAction,
    RelativeTargetLane,
    RelativeTargetLaneOffset,
    RelativeTargetSpeed,
    SpeedAction,
    TeleportAction,
    Timing,
    TransitionDynamics,
)
from avsim.scenario.openscenario.attributes import unsupported
from avsim.scenario.openscenario.context import Context
from avsim.scenario.openscenario.limits import MAX_SPEED, MAX_TIME
from avsim.scenario.openscenario.parse_entities import parse_controller
from avsim.scenario.openscenario.parse_entity_actions import APPEARANCE_READERS
from avsim.scenario.openscenario.parse_motion import MOTION_READERS, parse_constraints
from avsim.scenario.openscenario.parse_positions import parse_position
from avsim.scenario.openscenario.parse_trajectories import parse_trajectory_ref
from avsim.scenario.openscenario.xmlread import Node

SHAPES = ("step", "linear", "sinusoidal", "cubic")
DIMENSIONS = ("rate", "time", "distance")
FOLLOWING_MODES = ("position", "follow")
COORDINATE_SYSTEMS = ("entity", "lane", "road", "trajectory")


def parse_dynamics(node: Node, ctx: Context) -> TransitionDynamics:
    a = ctx.attrs
    mode = None
    if "followingMode" in node.attrs:
        mode = a.choice(node, "followingMode", FOLLOWING_MODES)
    dimension = a.choice(node, "dynamicsDimension", DIMENSIONS)
    value = (a.bounded(node, "value", 0.0, MAX_TIME, "s") if dimension == "time"
             else a.number(node, "value"))
    return TransitionDynamics(
        shape=a.choice(node, "dynamicsShape", SHAPES),  # type: ignore[arg-type]
        dimension=dimension,  # type: ignore[arg-type]
        value=value,
        following_mode=mode,  # type: ignore[arg-type]
    )


def _teleport(node: Node, ctx: Context) -> PrivateAction:
    return TeleportAction(parse_position(node.need("Position"), ctx))


def _speed(node: Node, ctx: Context) -> PrivateAction:
    a = ctx.attrs
    target = node.need("SpeedActionTarget").only_child()
    speed_target: AbsoluteTargetSpeed | RelativeTargetSpeed
    if target.tag == "AbsoluteTargetSpeed":
        speed_target = AbsoluteTargetSpeed(a.bounded(target, "value", -MAX_SPEED, MAX_SPEED,
                                                     "m/s"))
    elif target.tag == "RelativeTargetSpeed":
        value_type = a.choice(target, "speedTargetValueType", ("delta", "factor"))
        speed_target = RelativeTargetSpeed(
            entity=ctx.entity_ref(target),
            value=(a.bounded(target, "value", -MAX_SPEED, MAX_SPEED, "m/s")
                   if value_type == "delta" else a.number(target, "value")),
            value_type=value_type,  # type: ignore[arg-type]
            continuous=a.boolean(target, "continuous"),
        )
    else:
        raise unsupported(target)
    return SpeedAction(parse_dynamics(node.need("SpeedActionDynamics"), ctx), speed_target)


def _longitudinal_distance(node: Node, ctx: Context) -> PrivateAction:
    a = ctx.attrs
    distance = a.opt_number(node, "distance")
    time_gap = a.opt_bounded(node, "timeGap", 0.0, MAX_TIME, "s")
    if (distance is None) == (time_gap is None):
        raise node.error("needs exactly one of distance and timeGap")
    return LongitudinalDistanceAction(
        entity=ctx.entity_ref(node),
        distance=distance,
        time_gap=time_gap,
        freespace=a.boolean(node, "freespace"),
        continuous=a.boolean(node, "continuous"),
        coordinate_system=a.choice_or(node, "coordinateSystem", COORDINATE_SYSTEMS, "entity"),
        displacement=a.choice_or(
            node,
            "displacement",
            ("any", "leadingReferencedEntity", "trailingReferencedEntity"),
            "any",
        ),
        constraints=parse_constraints(node.child("DynamicConstraints"), ctx),
    )


def _lane_change(node: Node, ctx: Context) -> PrivateAction:
    a = ctx.attrs
    target = node.need("LaneChangeTarget").only_child()
    lane_target: AbsoluteTargetLane | RelativeTargetLane
    if target.tag == "RelativeTargetLane":
        lane_target = RelativeTargetLane(ctx.entity_ref(target), a.integer(target, "value"))
    elif target.tag == "AbsoluteTargetLane":
        lane_target = AbsoluteTargetLane(a.text(target, "value"))
    else:
        raise unsupported(target)
    return LaneChangeAction(
        dynamics=parse_dynamics(node.need("LaneChangeActionDynamics"), ctx),
        target=lane_target,
        target_lane_offset=a.opt_number(node, "targetLaneOffset"),
    )


def _lane_offset(node: Node, ctx: Context) -> PrivateAction:
    a = ctx.attrs
    dyn = node.need("LaneOffsetActionDynamics")
    target = node.need("LaneOffsetTarget").only_child()
    offset_target: AbsoluteTargetLaneOffset | RelativeTargetLaneOffset
    if target.tag == "AbsoluteTargetLaneOffset":
        offset_target = AbsoluteTargetLaneOffset(a.number(target, "value"))
    elif target.tag == "RelativeTargetLaneOffset":
        offset_target = RelativeTargetLaneOffset(ctx.entity_ref(target), a.number(target, "value"))
    else:
        raise unsupported(target)
    return LaneOffsetAction(
        continuous=a.boolean(node, "continuous"),
        dynamics=LaneOffsetDynamics(
            max_lateral_acc=a.opt_number(dyn, "maxLateralAcc"),
            shape=a.choice(dyn, "dynamicsShape", SHAPES),  # type: ignore[arg-type]
        ),
        target=offset_target,
    )


def _follow_trajectory(node: Node, ctx: Context) -> PrivateAction:
    a = ctx.attrs
    time_ref = node.need("TimeReference").only_child()
    timing: Timing | None
    if time_ref.tag == "None":
        timing = None
    elif time_ref.tag == "Timing":
        timing = Timing(
            domain=a.choice(time_ref, "domainAbsoluteRelative", ("absolute", "relative")),  # type: ignore[arg-type]
            scale=a.number(time_ref, "scale"),
            offset=a.number(time_ref, "offset"),
        )
    else:
        raise unsupported(time_ref)
    mode = node.need("TrajectoryFollowingMode")
    return FollowTrajectoryAction(
        trajectory=parse_trajectory_ref(node, ctx),
        time_reference=timing,
        following_mode=a.choice(mode, "followingMode", FOLLOWING_MODES),  # type: ignore[arg-type]
        initial_distance_offset=a.opt_number(node, "initialDistanceOffset"),
    )


def _activate_controller(node: Node, ctx: Context) -> PrivateAction:
    a = ctx.attrs
    return ActivateControllerAction(
        lateral=a.opt_boolean(node, "lateral"),
        longitudinal=a.opt_boolean(node, "longitudinal"),
        lighting=a.opt_boolean(node, "lighting"),
        animation=a.opt_boolean(node, "animation"),
    )


def _assign_controller(node: Node, ctx: Context) -> PrivateAction:
    a = ctx.attrs
    inner = [c for c in node.children if c.tag in ("Controller", "CatalogReference")]
    if len(inner) != 1:
        raise node.error("needs exactly one of Controller and CatalogReference")
    return AssignControllerAction(
        controller=parse_controller(inner[0], ctx),
        activate_lateral=a.opt_boolean(node, "activateLateral"),
        activate_longitudinal=a.opt_boolean(node, "activateLongitudinal"),
        activate_lighting=a.opt_boolean(node, "activateLighting"),
        activate_animation=a.opt_boolean(node, "activateAnimation"),
    )


_CONTROLLER_CHILDREN = ("AssignControllerAction", "ActivateControllerAction",
                        "OverrideControllerValueAction")
_OTHER_CONTROLS = ("Clutch", "ParkingBrake", "SteeringWheel", "Gear")  # only inactive
MAX_PEDAL_RATE = 1000.0  # [1/s] a pedal's maxRate at most (above: at once, to rounding)


def _controller(node: Node, ctx: Context) -> PrivateAction:
    for child in node.children:  # 1.0 has a sequence of them: one at a time is read
        if child.tag not in _CONTROLLER_CHILDREN:
            raise unsupported(child)
    return _dispatch(node.only_child(), ctx)


def _pedal(node: Node, ctx: Context, pedal: str) -> PedalOverride:
    """A Throttle or Brake override: `value` and 1.2's `maxRate` on the element, or (1.2's
    Brake) in its BrakePercent child; a BrakeForce is refused (avsim's pedals are
    positions)."""
    a = ctx.attrs
    source = node
    if pedal == "brake" and node.children:
        source = node.only_child()
        if source.tag != "BrakePercent":
            raise node.error(f"{source.tag}: not supported (the brake pedal's position is "
                             "read: BrakePercent)")
    return PedalOverride(
        pedal=pedal,  # type: ignore[arg-type]
        active=a.boolean(node, "active"),
        value=a.bounded(source, "value", 0.0, 1.0, "(pedal position)"),
        max_rate=a.opt_bounded(source, "maxRate", 0.0, MAX_PEDAL_RATE, "1/s"))


def _override(node: Node, ctx: Context) -> PrivateAction:
    """The driver's pedals (throttle, brake); the other controls only inactive. An
    override of nothing is refused."""
    if not node.children:
        raise node.error("overrides no control (Throttle, Brake, Clutch, ParkingBrake, "
                         "SteeringWheel or Gear)")
    pedals = []
    for child in node.children:
        if child.tag in ("Throttle", "Brake"):
            pedals.append(_pedal(child, ctx, child.tag.lower()))
        elif child.tag in _OTHER_CONTROLS:
            if ctx.attrs.boolean(child, "active"):
                raise child.error("not supported (an active override of the "
                                  f"{child.tag}: avsim's driver works the pedals only)")
        else:
            raise unsupported(child)
    return OverrideControllerValueAction(tuple(pedals))


def _wrapper(node: Node, ctx: Context) -> PrivateAction:
    return _dispatch(node.only_child(), ctx)


_READERS: dict[str, Callable[[Node, Context], PrivateAction]] = {
    "LongitudinalAction": _wrapper,
    "LateralAction": _wrapper,
    "RoutingAction": _wrapper,
    "ControllerAction": _controller,
    "TeleportAction": _teleport,
    "SpeedAction": _speed,
    "LongitudinalDistanceAction": _longitudinal_distance,
    "LaneChangeAction": _lane_change,
    "LaneOffsetAction": _lane_offset,
    "FollowTrajectoryAction": _follow_trajectory,
    "ActivateControllerAction": _activate_controller,
    "AssignControllerAction": _assign_controller,
    "OverrideControllerValueAction": _override,
    **MOTION_READERS,
    **APPEARANCE_READERS,
}


def _dispatch(node: Node, ctx: Context) -> PrivateAction:
    reader = _READERS.get(node.tag)
    if reader is None:
        raise unsupported(node)
    return reader(node, ctx)


def parse_private_action(node: Node, ctx: Context) -> PrivateAction:
    """The action a PrivateAction element holds."""
    return _dispatch(node.only_child(), ctx)


PRIVATE_ACTION_READERS = _READERS  # the PrivateAction elements read (`coverage`)
