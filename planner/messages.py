"""What the planner hands to control. A leaf module: dataclasses only.

`Plan.ego` carries the state estimate the plan was made from, so that control needs no
other input: arrows run one way, world frames -> perception -> planner -> control.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from perception.messages import EgoState
from planner.fsm.control import ControlState
from planner.fsm.lane_source import LaneSource

__all__ = ["ControlState", "EgoState", "Lead", "Plan", "ReferencePath", "StateChange"]


@dataclass(frozen=True, slots=True, eq=False)
class ReferencePath:
    """A path for the lateral controller, sampled ahead of (and a little behind) the car."""

    xy: NDArray[np.float64]  # [m] (N, 2) map frame points, N >= 2, spaced about `spacing`
    heading: NDArray[np.float64]  # [rad] (N,) path tangent, counter-clockwise from +x
    curvature: NDArray[np.float64]  # [1/m] (N,) signed, > 0 turns left


@dataclass(frozen=True, slots=True)
class Lead:
    """The vehicle ahead in the ego's lane, as the tracks show it."""

    track_id: int
    t: float  # [s] time of the track it comes from
    gap: float  # [m] ego front bumper to the lead's rear, along the ego's heading
    speed: float  # [m/s] the lead's speed over ground along the ego's heading


@dataclass(frozen=True, slots=True)
class StateChange:
    """One change of a planner state machine, with its reason (for the log and results)."""

    t: float  # [s]
    machine: str  # e.g. "lane_source", "motion", "control", "acc"
    source: str  # the state left
    target: str  # the state entered
    reason: str


@dataclass(frozen=True, slots=True, eq=False)
class Plan:
    t: float  # [s] sim time the plan was made at
    ego: EgoState  # the estimate the plan was made from
    path: ReferencePath  # the path to follow (map frame)
    target_speed: float  # [m/s] speed to hold now
    target_accel: float  # [m/s^2] feed-forward acceleration, signed (< 0 braking ahead of a limit)
    speed_limit: float  # [m/s] posted limit in force at the front bumper
    station: float  # [m] the ego's station on the route (from the map and its own estimate)
    lateral_error: float  # [m] the planner's view of the ego's offset from the path, left +
    lane_source: LaneSource = LaneSource.ACQUIRING  # where the path comes from
    lead: Lead | None = None  # the vehicle ahead in the lane, if a track shows one
    acc_mode: str = "acc_off"  # the ACC / event layer's mode (`planner.fsm.acc.AccMode` value)
    motion: str = "lane_keep"  # the motion FSM's state (`planner.fsm.motion.Motion` value)
    lane: int = 0  # the lane kept, or moved into by a lane change
    origin_lane: int = 0  # the lane a lane change in hand leaves (== lane otherwise)
    control: ControlState = ControlState.SPEED_KEEPING  # the control FSM's state
    hazard: bool = False  # the hazard lights: on from a flat tyre's detection
    changes: tuple[StateChange, ...] = ()  # state changes made in this tick
