"""The car under test's driver: a storyboard's motion actions on the car avsim's stack
drives, as its driver's inputs (`world.frames.DriverControls`, read by the stack with the
odometry; the stack's front door, never its state).

- SpeedAction: the driver sets the cruise set speed to the target (absolute, or the
  referenced entity's speed at the check the action starts plus a delta / times a factor).
  While the function is on it is the ACC's target, reached by the ACC's own law (the
  file's dynamics shape and rate are not the car's); while it is off the driver drives at
  it, changing his speed at a comfortable rate (`planner.driver_inputs`). Pressing the
  button is the whole input: the action is done at once.
- LaneChangeAction: the driver holds the turn-signal stalk towards the target lane (an
  OpenDRIVE lane id of the route, or lanes to the left of an entity's lane); the stack
  changes lanes when its own rules allow (`planner.fsm.motion`). The action is done, and
  the stalk released, when the car's reference point is in the target lane.
- OverrideControllerValueAction: the driver's throttle (the accelerator pedal,
  `planner.driver_override`) and brake pedal (an override of the system,
  `planner.driver_inputs`) held at their positions, moved there at `maxRate` [1/s] where
  the file gives one (at each trigger check), released by an inactive override. The
  runtime ends the action at once (`runtime.INSTANT`).
- An engaging controller action counts a press of the function's switch
  (`DriverControls.activations`: it turns the function back on after a brake override).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from avsim.run.storyboard.commands import target_route_lane
from avsim.run.storyboard.snapshot import Snapshot
from avsim.scenario.openscenario.model import (
    AbsoluteTargetSpeed,
    LaneChangeAction,
    OverrideControllerValueAction,
    PedalOverride,
    RelativeTargetSpeed,
    SpeedAction,
)
from world.world import World


@dataclass(frozen=True, slots=True)
class _Pedal:
    """A pedal moving to its goal."""

    goal: float  # [-] 0..1
    rate: float | None  # [1/s] None: at once


class Driver:
    """The driver of the car under test `ego` in `world` (module doc); `lane_ids`: the
    route's OpenDRIVE lane ids by route lane."""

    def __init__(self, world: World, ego: str, lane_ids: tuple[int, ...]) -> None:
        self.world = world
        self.ego = ego
        self.lane_ids = lane_ids
        self._lane: tuple[str, int] | None = None  # (tag, route lane) of the stalk held
        self._pedals: dict[str, _Pedal] = {}  # pedal -> its move in hand

    def set_speed(self, action: SpeedAction, snap: Snapshot) -> float:
        """Set the cruise set speed [m/s] to the action's target (module doc)."""
        target = action.target
        if isinstance(target, AbsoluteTargetSpeed):
            v = target.value
        else:
            assert isinstance(target, RelativeTargetSpeed)
            ref = snap.entities[target.entity].speed
            v = ref + target.value if target.value_type == "delta" else ref * target.value
        v = max(v, 0.0)
        self.world.driver = replace(self.world.driver, set_speed=v)
        return v

    def lane_change(self, tag: str, action: LaneChangeAction, snap: Snapshot) -> int:
        """Hold the stalk towards the target route lane (returned); `ValueError` for a lane
        the route does not have there."""
        me = snap.entities[self.ego]
        lane = target_route_lane(action, self.lane_ids, self.world.road.lanes_at(me.s), snap)
        self._lane = (tag, lane)
        self.world.driver = replace(self.world.driver, lane_request=lane)
        return lane

    def release_lane(self, tag: str) -> None:
        """The lane change `tag` is stopped: the stalk is released."""
        if self._lane is not None and self._lane[0] == tag:
            self._lane = None
            self.world.driver = replace(self.world.driver, lane_request=None)

    def override(self, action: OverrideControllerValueAction) -> None:
        """Start moving the pedals the override names."""
        for p in action.pedals:
            self._pedals[p.pedal] = _Pedal(_goal(p), p.max_rate)

    def switched_on(self) -> None:
        """The driver pressed the function's switch."""
        d = self.world.driver
        self.world.driver = replace(d, activations=d.activations + 1)

    def check(self, snap: Snapshot, dt: float) -> str | None:
        """Move the pedals by one check of `dt` [s]; the tag of the lane change that is
        done now (the car in the target lane: the stalk released), if any."""
        for pedal, move in list(self._pedals.items()):
            now = self._position(pedal)
            step = abs(move.goal - now) if move.rate is None else move.rate * dt
            new = now + max(-step, min(step, move.goal - now))
            self._set(pedal, new)
            if new == move.goal:
                del self._pedals[pedal]
        if self._lane is None or snap.entities[self.ego].lane != self._lane[1]:
            return None
        tag = self._lane[0]
        self.release_lane(tag)
        return tag

    def _position(self, pedal: str) -> float:
        return self.world.throttle if pedal == "throttle" else self.world.driver.brake

    def _set(self, pedal: str, value: float) -> None:
        if pedal == "throttle":
            self.world.throttle = value
        else:
            self.world.driver = replace(self.world.driver, brake=value)


def _goal(p: PedalOverride) -> float:
    """[-] the position an override holds its pedal at: released when inactive."""
    return p.value if p.active else 0.0
