"""The minimal planner: keep one lane of the map at the target speed.

Each tick: project the ego estimate onto the lane (station, lateral error), sample the lane
centre around it (`planner.route.lane_path`), and plan the target speed
(`planner.speed_planning.SpeedPlanner`). The path and the speed target are computed
separately (`path_for`, `speed_for`) so that the motion / control FSM planners built on this
can swap either one (a lane-change path, an ACC speed) and keep the other.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from perception.messages import EgoState
from planner.messages import Plan, ReferencePath
from planner.route import lane_path
from planner.speed_planning import SpeedPlanner, SpeedPlanningParams, SpeedTarget
from world.hdmap import RoadMap


@dataclass(frozen=True, slots=True)
class LaneKeepingParams:
    set_speed: float  # [m/s] the driver's desired (cruise) speed
    max_speed: float  # [m/s] the vehicle's maximum speed
    lane: int = 0  # ego-direction lane index to keep (0 rightmost)
    path_behind: float = 5.0  # [m] path sampled behind the car's centre
    path_ahead_min: float = 25.0  # [m] shortest path ahead of the car's centre
    path_ahead_time: float = 2.5  # [s] path ahead = max(path_ahead_min, this * speed)
    path_spacing: float = 0.5  # [m] station step of the path samples
    speed: SpeedPlanningParams = field(default_factory=SpeedPlanningParams)


class LaneKeepingPlanner:
    """Follows lane ``params.lane`` of ``road``; stateless between ticks (see `reset`)."""

    def __init__(self, road: RoadMap, params: LaneKeepingParams) -> None:
        if params.lane < 0:
            raise ValueError(f"lane keeping needs an ego-direction lane, got {params.lane}")
        self.road = road
        self.params = params
        self.lane = road.lane(params.lane)
        self.speed_planner = SpeedPlanner(road, self.lane, params.speed)

    def reset(self) -> None:
        """Nothing lives between ticks: the map projection is exact, so no station hint."""

    def localise(self, ego: EgoState) -> tuple[float, float]:
        """(station [m], lateral offset [m], left +) of the ego's centre on the lane."""
        s, r = self.lane.local_coordinates(np.array([ego.x, ego.y]))
        return float(np.asarray(s)), float(np.asarray(r))

    def path_for(self, ego: EgoState, station: float) -> ReferencePath:
        """The lane centre from ``path_behind`` behind to max(25 m, 2.5 s * speed) ahead."""
        p = self.params
        ahead = max(p.path_ahead_min, p.path_ahead_time * max(ego.speed, 0.0))
        return lane_path(
            self.lane, station, p.path_behind, ahead, p.path_spacing, length=self.road.length
        )

    def speed_for(self, station: float) -> SpeedTarget:
        """The speed target for the car's centre at ``station`` [m]."""
        p = self.params
        return self.speed_planner.target(station, set_speed=p.set_speed, max_speed=p.max_speed)

    def update(self, ego: EgoState) -> Plan:
        """The plan for this tick, made from ``ego`` (map frame, car centre)."""
        station, lateral = self.localise(ego)
        target = self.speed_for(station)
        return Plan(
            t=ego.t,
            ego=ego,
            path=self.path_for(ego, station),
            target_speed=target.speed,
            target_accel=target.accel,
            speed_limit=target.limit_at_front,
            station=station,
            lateral_error=lateral,
        )
