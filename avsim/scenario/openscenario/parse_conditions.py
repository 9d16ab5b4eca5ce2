"""Reading StartTrigger/StopTrigger elements: condition groups, conditions, and the
ByValue/ByEntity condition kinds in `conditions`. Others: `not supported yet (<Name>)`."""

from __future__ import annotations

import math
from collections.abc import Callable

from avsim.scenario.openscenario.attributes import unsupported
from avsim.scenario.openscenario.conditions import (
    AccelerationCondition,
    AngleCondition,
    CollisionCondition,
    Condition,
    ConditionGroup,
    ConditionKind,
    DistanceCondition,
    EndOfRoadCondition,
    OffroadCondition,
    ParameterCondition,
    ReachPositionCondition,
    RelativeAngleCondition,
    RelativeClearanceCondition,
    RelativeDistanceCondition,
    RelativeSpeedCondition,
    SimulationTimeCondition,
    SpeedCondition,
    StandStillCondition,
    StoryboardElementStateCondition,
    TimeHeadwayCondition,
    TimeOfDayCondition,
    TimeToCollisionCondition,
    TraveledDistanceCondition,
    Trigger,
    TriggeringEntities,
    VariableCondition,
)
from avsim.scenario.openscenario.context import Context
from avsim.scenario.openscenario.environment import epoch_of
from avsim.scenario.openscenario.limits import MAX_SPEED, MAX_TIME
from avsim.scenario.openscenario.parse_positions import parse_position
from avsim.scenario.openscenario.xmlread import Node

RULES = ("greaterThan", "lessThan", "equalTo", "greaterOrEqual", "lessOrEqual", "notEqualTo")
EDGES = ("none", "rising", "falling", "risingOrFalling")
DISTANCE_TYPES = ("longitudinal", "lateral", "cartesianDistance", "euclidianDistance")
COORDINATE_SYSTEMS = ("entity", "lane", "road", "trajectory")
DIRECTIONS = ("longitudinal", "lateral", "vertical")
ANGLE_TYPES = ("heading", "pitch", "roll")
ANGLE_SYSTEMS = ("entity", "lane", "road", "world")  # trajectory is refused
MAX_ANGLE = 2.0 * math.pi  # [rad] an angle condition's angle and tolerance, in magnitude
MAX_ACCELERATION = 100.0  # [m/s²] an acceleration condition's value, in magnitude
MAX_CLEARANCE = 10_000.0  # [m] a clearance condition's distance forward / backward
MAX_LANES = 100  # [lanes] a relative lane range's bounds, in magnitude
ELEMENT_TYPES = ("story", "act", "maneuver", "event", "action", "maneuverGroup")
STATES = (
    "startTransition",
    "endTransition",
    "stopTransition",
    "skipTransition",
    "completeState",
    "runningState",
    "standbyState",
)


def _rule(node: Node, ctx: Context) -> str:
    return ctx.attrs.choice(node, "rule", RULES)


def _coordinates(node: Node, ctx: Context) -> str:
    """coordinateSystem (1.1+), or 1.0's alongRoute (true: road), default entity."""
    if "coordinateSystem" in node.attrs:
        return ctx.attrs.choice(node, "coordinateSystem", COORDINATE_SYSTEMS)
    return "road" if ctx.attrs.boolean_or(node, "alongRoute", False) else "entity"


def _distance_type(node: Node, ctx: Context, default: str) -> str:
    return ctx.attrs.choice_or(node, "relativeDistanceType", DISTANCE_TYPES, default)


def _duration(node: Node, ctx: Context) -> float:
    """[s] a condition's `duration`, in [0, MAX_TIME]."""
    return ctx.attrs.bounded(node, "duration", 0.0, MAX_TIME, "s")


def _simulation_time(node: Node, ctx: Context) -> ConditionKind:
    value = ctx.attrs.bounded(node, "value", 0.0, MAX_TIME, "s")
    return SimulationTimeCondition(value, _rule(node, ctx))  # type: ignore[arg-type]


def _element_state(node: Node, ctx: Context) -> ConditionKind:
    a = ctx.attrs
    element_type = a.choice(node, "storyboardElementType", ELEMENT_TYPES)
    return StoryboardElementStateCondition(
        element_type=element_type,
        element_ref=ctx.element_ref(node, element_type, "storyboardElementRef"),
        state=a.choice(node, "state", STATES),
    )


def _parameter(node: Node, ctx: Context) -> ConditionKind:
    a = ctx.attrs
    parameter = a.text(node, "parameterRef")
    if a.scope.get(parameter) is None:
        raise node.error(f"parameterRef: no parameter {parameter}")
    return ParameterCondition(parameter, a.text(node, "value"), _rule(node, ctx))  # type: ignore[arg-type]


def _variable(node: Node, ctx: Context) -> ConditionKind:
    a = ctx.attrs
    variable = a.text(node, "variableRef")
    declared = ctx.variables or {}
    if variable not in declared:
        known = ", ".join(sorted(declared)) or "none"
        raise node.error(f"variableRef: no variable {variable} (variables: {known})")
    return VariableCondition(variable, a.text(node, "value"), _rule(node, ctx))  # type: ignore[arg-type]


def _time_of_day(node: Node, ctx: Context) -> ConditionKind:
    text = ctx.attrs.text(node, "dateTime")
    try:
        epoch = epoch_of(text)
    except ValueError:
        raise node.error(f"dateTime: not an ISO 8601 date and time: {text[:40]!r}") from None
    return TimeOfDayCondition(text, epoch, _rule(node, ctx))  # type: ignore[arg-type]


def _acceleration(node: Node, ctx: Context) -> ConditionKind:
    a = ctx.attrs
    direction = a.choice(node, "direction", DIRECTIONS) if "direction" in node.attrs else None
    return AccelerationCondition(
        a.bounded(node, "value", -MAX_ACCELERATION, MAX_ACCELERATION, "m/s²"),
        _rule(node, ctx), direction)  # type: ignore[arg-type]


def _angle_parts(node: Node, ctx: Context, default: str) -> tuple[str, float, float, str]:
    a = ctx.attrs
    if a.opt_text(node, "coordinateSystem") == "trajectory":
        raise node.error("not supported yet (coordinateSystem trajectory)")
    return (a.choice(node, "angleType", ANGLE_TYPES),
            a.bounded(node, "angle", -MAX_ANGLE, MAX_ANGLE, "rad"),
            a.bounded(node, "angleTolerance", 0.0, MAX_ANGLE, "rad"),
            a.choice_or(node, "coordinateSystem", ANGLE_SYSTEMS, default))


def _angle(node: Node, ctx: Context) -> ConditionKind:
    return AngleCondition(*_angle_parts(node, ctx, "world"))  # type: ignore[arg-type]


def _relative_angle(node: Node, ctx: Context) -> ConditionKind:
    return RelativeAngleCondition(ctx.entity_ref(node),
                                  *_angle_parts(node, ctx, "entity"))  # type: ignore[arg-type]


def _lane_range(node: Node, ctx: Context) -> tuple[int | None, int | None]:
    a = ctx.attrs
    ends = [None if k not in node.attrs else a.integer(node, k) for k in ("from", "to")]
    for key, end in zip(("from", "to"), ends, strict=True):
        if end is not None and abs(end) > MAX_LANES:
            raise node.error(f"{key}: must be in [-{MAX_LANES}, {MAX_LANES}] lanes, got {end}")
    low, high = ends
    if low is not None and high is not None and low > high:
        raise node.error(f"from ({low}) is greater than to ({high})")
    return low, high


def _clearance(node: Node, ctx: Context) -> ConditionKind:
    a = ctx.attrs
    for child in node.children:
        if child.tag not in ("RelativeLaneRange", "EntityRef"):
            raise unsupported(child)
    return RelativeClearanceCondition(
        entities=tuple(ctx.entity_ref(e) for e in node.all("EntityRef")),
        distance_forward=a.opt_bounded(node, "distanceForward", 0.0, MAX_CLEARANCE, "m") or 0.0,
        distance_backward=a.opt_bounded(node, "distanceBackward", 0.0, MAX_CLEARANCE, "m")
        or 0.0,
        freespace=a.boolean(node, "freeSpace"),
        opposite_lanes=a.boolean(node, "oppositeLanes"),
        lane_ranges=tuple(_lane_range(r, ctx) for r in node.all("RelativeLaneRange")),
    )


def _relative_distance(node: Node, ctx: Context) -> ConditionKind:
    a = ctx.attrs
    return RelativeDistanceCondition(
        entity=ctx.entity_ref(node),
        distance_type=_distance_type(node, ctx, "euclidianDistance"),  # type: ignore[arg-type]
        value=a.number(node, "value"),
        freespace=a.boolean(node, "freespace"),
        rule=_rule(node, ctx),  # type: ignore[arg-type]
        coordinate_system=_coordinates(node, ctx),  # type: ignore[arg-type]
    )


def _distance(node: Node, ctx: Context) -> ConditionKind:
    a = ctx.attrs
    return DistanceCondition(
        position=parse_position(node.need("Position"), ctx),
        value=a.number(node, "value"),
        freespace=a.boolean(node, "freespace"),
        rule=_rule(node, ctx),  # type: ignore[arg-type]
        distance_type=_distance_type(node, ctx, "euclidianDistance"),  # type: ignore[arg-type]
        coordinate_system=_coordinates(node, ctx),  # type: ignore[arg-type]
    )


def _time_headway(node: Node, ctx: Context) -> ConditionKind:
    a = ctx.attrs
    return TimeHeadwayCondition(
        entity=ctx.entity_ref(node),
        value=a.bounded(node, "value", 0.0, MAX_TIME, "s"),
        freespace=a.boolean(node, "freespace"),
        rule=_rule(node, ctx),  # type: ignore[arg-type]
        coordinate_system=_coordinates(node, ctx),  # type: ignore[arg-type]
        distance_type=_distance_type(node, ctx, "euclidianDistance"),  # type: ignore[arg-type]
    )


def _time_to_collision(node: Node, ctx: Context) -> ConditionKind:
    a = ctx.attrs
    target = node.need("TimeToCollisionConditionTarget").only_child()
    entity = position = None
    if target.tag == "EntityRef":
        entity = ctx.entity_ref(target)
    elif target.tag == "Position":
        position = parse_position(target, ctx)
    else:
        raise unsupported(target)
    return TimeToCollisionCondition(
        entity=entity,
        position=position,
        value=a.bounded(node, "value", 0.0, MAX_TIME, "s"),
        freespace=a.boolean(node, "freespace"),
        rule=_rule(node, ctx),  # type: ignore[arg-type]
        coordinate_system=_coordinates(node, ctx),  # type: ignore[arg-type]
        distance_type=_distance_type(node, ctx, "euclidianDistance"),  # type: ignore[arg-type]
    )


def _reach_position(node: Node, ctx: Context) -> ConditionKind:
    return ReachPositionCondition(
        parse_position(node.need("Position"), ctx), ctx.attrs.number(node, "tolerance")
    )


def _speed(node: Node, ctx: Context) -> ConditionKind:
    if "direction" in node.attrs:  # 1.2: a directional speed
        raise node.error("not supported yet (SpeedCondition direction)")
    value = ctx.attrs.bounded(node, "value", -MAX_SPEED, MAX_SPEED, "m/s")
    return SpeedCondition(value, _rule(node, ctx))  # type: ignore[arg-type]


def _relative_speed(node: Node, ctx: Context) -> ConditionKind:
    if "direction" in node.attrs:
        raise node.error("not supported yet (RelativeSpeedCondition direction)")
    return RelativeSpeedCondition(
        ctx.entity_ref(node),
        ctx.attrs.number(node, "value"),
        _rule(node, ctx),  # type: ignore[arg-type]
    )


def _collision(node: Node, ctx: Context) -> ConditionKind:
    target = node.only_child()
    if target.tag == "EntityRef":
        return CollisionCondition(ctx.entity_ref(target), None)
    if target.tag == "ByType":
        kinds = ("pedestrian", "vehicle", "miscellaneous", "external")
        return CollisionCondition(None, ctx.attrs.choice(target, "type", kinds))
    raise unsupported(target)


_VALUE: dict[str, Callable[[Node, Context], ConditionKind]] = {
    "SimulationTimeCondition": _simulation_time,
    "StoryboardElementStateCondition": _element_state,
    "ParameterCondition": _parameter,
    "VariableCondition": _variable,
    "TimeOfDayCondition": _time_of_day,
}
_ENTITY: dict[str, Callable[[Node, Context], ConditionKind]] = {
    "RelativeDistanceCondition": _relative_distance,
    "DistanceCondition": _distance,
    "TimeHeadwayCondition": _time_headway,
    "TimeToCollisionCondition": _time_to_collision,
    "ReachPositionCondition": _reach_position,
    "TraveledDistanceCondition": lambda n, c: TraveledDistanceCondition(c.attrs.number(n, "value")),
    "SpeedCondition": _speed,
    "RelativeSpeedCondition": _relative_speed,
    "StandStillCondition": lambda n, c: StandStillCondition(_duration(n, c)),
    "EndOfRoadCondition": lambda n, c: EndOfRoadCondition(_duration(n, c)),
    "OffroadCondition": lambda n, c: OffroadCondition(_duration(n, c)),
    "CollisionCondition": _collision,
    "AccelerationCondition": _acceleration,
    "AngleCondition": _angle,
    "RelativeAngleCondition": _relative_angle,
    "RelativeClearanceCondition": _clearance,
}


_Readers = dict[str, Callable[[Node, Context], ConditionKind]]


def _kind(node: Node, ctx: Context, readers: _Readers) -> ConditionKind:
    reader = readers.get(node.tag)
    if reader is None:
        raise unsupported(node)
    return reader(node, ctx)


def parse_condition(node: Node, ctx: Context) -> Condition:
    a = ctx.attrs
    body = node.only_child()
    triggering: TriggeringEntities | None = None
    if body.tag == "ByValueCondition":
        kind = _kind(body.only_child(), ctx, _VALUE)
    elif body.tag == "ByEntityCondition":
        te = body.need("TriggeringEntities")
        triggering = TriggeringEntities(
            rule=a.choice(te, "triggeringEntitiesRule", ("any", "all")),  # type: ignore[arg-type]
            entities=tuple(ctx.entity_ref(e) for e in te.all("EntityRef")),
        )
        if not triggering.entities:
            raise te.error("needs at least one EntityRef")
        kind = _kind(body.need("EntityCondition").only_child(), ctx, _ENTITY)
    else:
        raise unsupported(body)
    return Condition(
        name=a.text(node, "name"),
        delay=a.bounded(node, "delay", 0.0, MAX_TIME, "s"),
        edge=a.choice(node, "conditionEdge", EDGES),  # type: ignore[arg-type]
        triggering_entities=triggering,
        kind=kind,
    )


def parse_trigger(node: Node | None, ctx: Context) -> Trigger | None:
    """A StartTrigger/StopTrigger element as OR of ANDs; None when there is none."""
    if node is None:
        return None
    return Trigger(
        tuple(
            ConditionGroup(tuple(parse_condition(c, ctx) for c in g.all("Condition")))
            for g in node.all("ConditionGroup")
        )
    )


VALUE_CONDITION_READERS = _VALUE  # the ByValueCondition elements read (`coverage`)
ENTITY_CONDITION_READERS = _ENTITY  # the EntityCondition elements read (`coverage`)
