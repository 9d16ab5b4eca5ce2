"""What the planner hands to control: dataclasses and the state enums, and the planner
stage's interface (`PlannerStage`).

`Plan.ego` carries the state estimate the plan was made from, so that control needs no
other input: arrows run one way, world frames -> perception -> planner -> control. Every
state in the plan is an enum of its machine (`planner.fsm`), and `speed_source` says which
constraint set the target speed.
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass
from typing import Protocol

import numpy as np
from numpy.typing import NDArray

from perception.messages import EgoState, PlannerInput
from planner.fsm.acc import AccMode
from planner.fsm.control import ControlState
from planner.fsm.hazard import HazardLights
from planner.fsm.lane_source import LaneSource
from planner.fsm.machine import StateChange
from planner.fsm.motion import Motion
from planner.fsm.sensing import Sensing

__all__ = ["MACHINES", "AccMode", "ControlState", "EgoState", "HazardLights", "LaneSource",
           "Lead", "Motion", "Plan", "PlannerStage", "ReferencePath", "SpeedSource",
           "StateChange"]


class SpeedSource(enum.Enum):
    """Which constraint set the plan's target speed (the last of the planner's speed chain
    that lowered it, or the map's plan that it left alone)."""

    SET_SPEED = "set_speed"  # the driver's set speed (capped at the vehicle's maximum)
    SIGHT = "sight"  # the sight cap: the fastest speed whose desired gap and emergency stop
    #   lie within the forward sensing range (`planner.fsm.acc.sight_speed`)
    LIMIT = "limit"  # a posted limit, in force or ahead (braking towards it)
    CURVE = "curve"  # a curve's speed, here or ahead
    FOLLOWING = "following"  # the ACC's trail or brake law behind the vehicle ahead
    EVENT = "event"  # an event's law: a stop, a speed bump, a flat tyre's crawl
    PEDAL = "pedal"  # the driver's accelerator pedal (or the ramp back after it)
    DEGRADED = "degraded"  # the lane lost: the hold speed, then a stop in lane
    EMERGENCY = "emergency"  # the control FSM's emergency stop
    DRIVER = "driver"  # the driver holds the set speed: the function is not engaged


@dataclass(frozen=True, slots=True, eq=False)
class ReferencePath:
    """A path for the lateral controller, sampled ahead of (and a little behind) the car."""

    xy: NDArray[np.float64]  # [m] (N, 2) map frame points, N >= 2, spaced about `spacing`
    heading: NDArray[np.float64]  # [rad] (N,) path tangent, counter-clockwise from +x
    curvature: NDArray[np.float64]  # [1/m] (N,) signed, > 0 turns left


@dataclass(frozen=True, slots=True)
class Lead:
    """The vehicle ahead in the ego's lane, as the tracks show it."""

    track_id: int  # the track's id
    t: float  # [s] time of the track it comes from
    gap: float  # [m] ego front bumper to the lead's rear, along the ego's heading (along the
    #   route or the map lane during a lane change or through a junction)
    speed: float  # [m/s] the lead's speed over ground along that same direction, >= 0: the
    #   ACC's V_l (an oncoming vehicle is taken as standing: an ACC follows none, ISO 15622)
    velocity: float = math.nan  # [m/s] its velocity along that direction, signed (< 0:
    #   oncoming), for the time to collision and the emergency braking; NaN: `speed`
    entered: bool = False  # its track was outside the ego's lane before it became the lead
    #   (a cut-in, a lane change ahead): UN R157 gives the ego time to restore d_min to it

    @property
    def along(self) -> float:
        """[m/s] the lead's velocity along the ego's direction, signed (< 0: coming towards
        the ego): the closing speed is the ego's speed less it."""
        return self.speed if math.isnan(self.velocity) else self.velocity


@dataclass(frozen=True, slots=True, eq=False)
class Plan:
    t: float  # [s] sim time the plan was made at
    ego: EgoState  # the estimate the plan was made from
    path: ReferencePath  # the path to follow (map frame)
    target_speed: float  # [m/s] speed to hold now
    target_accel: float  # [m/s^2] feed-forward acceleration, signed (< 0: braking)
    speed_limit: float  # [m/s] posted limit in force at the front bumper
    station: float  # [m] the ego's station on the route (from the map and its own estimate)
    lateral_error: float  # [m] the ego's offset from the lane kept's map centre line, left +
    lane_source: LaneSource = LaneSource.ACQUIRING  # where the path comes from
    lead: Lead | None = None  # the vehicle ahead in the lane, if a track shows one
    acc_mode: AccMode = AccMode.ACC_OFF  # the ACC / event layer's mode
    motion: Motion = Motion.LANE_KEEP  # the motion FSM's state
    lane: int = 0  # [-] the lane kept, or moved into by a lane change (ego-direction index)
    origin_lane: int = 0  # [-] the lane a lane change in hand leaves (== lane otherwise)
    control: ControlState = ControlState.SPEED_KEEPING  # the control FSM's state
    hazard: HazardLights = HazardLights.OFF  # on from a flat tyre's detection, and during
    #   a minimum-risk stop in lane after a sensor fault
    sensing: Sensing = Sensing.NOMINAL  # the answer to the LiDAR's and GNSS's health
    speed_source: SpeedSource = SpeedSource.SET_SPEED  # what set `target_speed`
    changes: tuple[StateChange, ...] = ()  # state changes made in this tick

    @property
    def states(self) -> dict[str, enum.Enum]:
        """Every state of the plan by its machine's name (`MACHINES`)."""
        return {"lane_source": self.lane_source, "motion": self.motion, "acc": self.acc_mode,
                "control": self.control, "hazard": self.hazard, "sensing": self.sensing,
                "speed_source": self.speed_source}


MACHINES: dict[str, type[enum.Enum]] = {  # the plan's states: machine name -> its states
    "lane_source": LaneSource, "motion": Motion, "acc": AccMode, "control": ControlState,
    "hazard": HazardLights, "sensing": Sensing, "speed_source": SpeedSource}


class PlannerStage(Protocol):
    """The planner stage: `PlannerInput` in, `Plan` out, once per control tick."""

    def update(self, inp: PlannerInput) -> Plan:
        """The plan for the tick of `inp.ego.t`."""
