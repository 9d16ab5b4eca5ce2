"""Judging the conditions on the storyboard's state and on an entity's motion and attitude:
variables, time of day, acceleration, angles, clearance. As esmini's `OSCCondition` where
it has the condition (variable, acceleration, angle, clearance); time of day and relative
angle as the OpenSCENARIO 1.3 standard says (esmini has neither).

- Variable: its value now (`state.StoryState`) against the written value read as its type.
- Time of day: the environment's time of day now (advanced with the simulation time since
  it was set when animated) against the condition's; false while no time of day is set.
- Acceleration: along the heading (longitudinal, d speed / dt), across it (lateral,
  speed * yaw rate, left +), vertical 0 (a flat world); no direction: the magnitude of the
  horizontal vector, signed as the longitudinal part.
- Angle: the heading in the world (map frame), against the route (road), against the
  route in the lane's driving direction (lane), or 0 (entity); pitch and roll are 0 (a flat
  world). Holds when the angle's difference from `angle`, wrapped to a half turn, is within
  `tolerance` (+1e-10 rad, as esmini). Relative angle: the triggering entity's angle minus
  the entity's, each in that system (entity and world: the heading difference).
- Relative clearance (`clearance`): lanes counted across the route from the triggering
  entity's lane, left + in its driving direction; an entity counts when it is in a lane of
  a range (any range; none given: every lane), of its direction unless `oppositeLanes`,
  between distanceBackward behind and distanceForward ahead of it (along the route, in its
  driving direction; freeSpace: between the boxes). Holds when no entity counts and a lane
  of a range exists where the triggering entity is (its route lanes, both directions);
  false when it is off the lanes.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import TYPE_CHECKING

from avsim.run.storyboard import geometry as g
from avsim.run.storyboard.rules import compare, value_holds
from avsim.run.storyboard.snapshot import EntityState, Snapshot
from avsim.scenario.openscenario.conditions import (
    AccelerationCondition,
    AngleCondition,
    AngleCoordinates,
    AngleType,
    RelativeAngleCondition,
    RelativeClearanceCondition,
    TimeOfDayCondition,
    VariableCondition,
)

if TYPE_CHECKING:
    from avsim.run.storyboard.conditions import ConditionContext

ANGLE_EPS = 1e-10  # [rad] added to an angle condition's tolerance (esmini's SMALL_NUMBER)
Lanes = Callable[[float], tuple[int, int]]  # station [m] -> (lanes of the route's
#   direction, oncoming lanes) there


def no_lanes(s: float) -> tuple[int, int]:
    raise ValueError("no lane counts given for a clearance condition")


def variable(c: VariableCondition, ctx: ConditionContext) -> bool:
    return value_holds(c.variable, c.rule, c.value, ctx.state.variables)


def time_of_day(c: TimeOfDayCondition, snap: Snapshot, ctx: ConditionContext) -> bool:
    now = ctx.state.time_of_day(snap.time)
    return now is not None and compare(now, c.rule, c.epoch)


def acceleration(c: AccelerationCondition, e: EntityState, _snap: Snapshot,
                 _ctx: ConditionContext) -> bool:
    along, across = e.acceleration, e.speed * e.yaw_rate
    if c.direction == "longitudinal":
        value = along
    elif c.direction == "lateral":
        value = across
    elif c.direction == "vertical":
        value = 0.0
    else:
        value = math.copysign(math.hypot(along, across), along)
    return compare(value, c.rule, c.value)


def _oncoming(e: EntityState) -> bool:
    return e.lane is not None and e.lane < 0


def _angle_of(e: EntityState, angle_type: AngleType, system: AngleCoordinates) -> float:
    """[rad] the entity's angle of this type in the coordinate system (module doc)."""
    if angle_type != "heading" or system == "entity":
        return 0.0
    if system == "world":
        return e.heading
    reverse = math.pi if system == "lane" and _oncoming(e) else 0.0
    return e.heading - (e.route_heading + reverse)


def _within(value: float, angle: float, tolerance: float) -> bool:
    return abs(math.remainder(value - angle, math.tau)) < tolerance + ANGLE_EPS


def angle(c: AngleCondition, e: EntityState, _snap: Snapshot, _ctx: ConditionContext) -> bool:
    return _within(_angle_of(e, c.angle_type, c.coordinate_system), c.angle, c.tolerance)


def relative_angle(c: RelativeAngleCondition, e: EntityState, snap: Snapshot,
                   _ctx: ConditionContext) -> bool:
    other = snap.entities[c.entity]
    system: AngleCoordinates = "world" if c.coordinate_system == "entity" \
        else c.coordinate_system
    mine = _angle_of(e, c.angle_type, system)
    return _within(mine - _angle_of(other, c.angle_type, system), c.angle, c.tolerance)


def _band(lane: int, lanes: int) -> int:
    """The lane's place across the route, right to left: lane i of the route's direction
    is i, oncoming lane -j (j = 1 next to the centre line) is lanes - 1 + j."""
    return lane if lane >= 0 else lanes - 1 - lane


def _in_ranges(k: int, ranges: tuple[tuple[int | None, int | None], ...]) -> bool:
    return not ranges or any((lo is None or k >= lo) and (hi is None or k <= hi)
                             for lo, hi in ranges)


def _counts(c: RelativeClearanceCondition, e: EntityState, o: EntityState,
            ctx: ConditionContext) -> bool:
    """Whether the entity `o` is in the clearance area of `e` (module doc)."""
    assert e.lane is not None
    sign = -1.0 if _oncoming(e) else 1.0
    ds = (g.longitudinal(e, o, True) if c.freespace else o.s - e.s) * sign
    if o.lane is None or not -c.distance_backward <= ds <= c.distance_forward:
        return False
    k = int(sign) * (_band(o.lane, ctx.lanes(o.s)[0]) - _band(e.lane, ctx.lanes(e.s)[0]))
    return _in_ranges(k, c.lane_ranges) and (c.opposite_lanes or _oncoming(o) == _oncoming(e))


def _area_exists(c: RelativeClearanceCondition, e: EntityState, ctx: ConditionContext) -> bool:
    assert e.lane is not None
    lanes, oncoming = ctx.lanes(e.s)
    sign = -1 if _oncoming(e) else 1
    mine = _band(e.lane, lanes)
    for lane in (*range(lanes), *range(-1, -oncoming - 1, -1)):
        same = (lane < 0) == _oncoming(e)
        if _in_ranges(sign * (_band(lane, lanes) - mine), c.lane_ranges) and (
                c.opposite_lanes or same):
            return True
    return False


def clearance(c: RelativeClearanceCondition, e: EntityState, snap: Snapshot,
              ctx: ConditionContext) -> bool:
    if e.lane is None:
        return False
    names = c.entities or tuple(snap.entities)
    others = [snap.entities[n] for n in names if n != e.name and n in snap.entities]
    if any(_counts(c, e, o, ctx) for o in others):
        return False
    return _area_exists(c, e, ctx)
