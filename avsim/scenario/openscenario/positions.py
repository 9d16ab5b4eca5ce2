"""Positions (OpenSCENARIO's Position choice). Angles in radians, lengths in metres."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal

if TYPE_CHECKING:  # a trajectory's vertices are positions
    from avsim.scenario.openscenario.trajectories import Trajectory

ReferenceContext = Literal["relative", "absolute"]


@dataclass(frozen=True, slots=True)
class Orientation:
    """Heading, pitch, roll; `relative` to the road/lane or entity, or `absolute`."""

    h: float  # [rad]
    p: float  # [rad]
    r: float  # [rad]
    type: ReferenceContext | None  # None: not written (the position's default applies)


@dataclass(frozen=True, slots=True)
class WorldPosition:
    x: float  # [m]
    y: float  # [m]
    z: float | None  # [m] None: on the road surface
    h: float | None  # [rad] heading, None when not written
    p: float | None  # [rad]
    r: float | None  # [rad]


@dataclass(frozen=True, slots=True)
class RelativeWorldPosition:
    entity: str
    dx: float  # [m] in world axes
    dy: float  # [m]
    dz: float | None  # [m]
    orientation: Orientation | None


@dataclass(frozen=True, slots=True)
class RelativeObjectPosition:
    entity: str
    dx: float  # [m] in the entity's axes
    dy: float  # [m]
    dz: float | None  # [m]
    orientation: Orientation | None


@dataclass(frozen=True, slots=True)
class RoadPosition:
    road_id: str
    s: float  # [m] along the road's reference line
    t: float  # [m] lateral, left positive
    orientation: Orientation | None


@dataclass(frozen=True, slots=True)
class RelativeRoadPosition:
    entity: str
    ds: float  # [m] along the road
    dt: float  # [m] lateral
    orientation: Orientation | None


@dataclass(frozen=True, slots=True)
class LanePosition:
    road_id: str
    lane_id: str  # OpenDRIVE lane id as written (e.g. "-4")
    s: float  # [m] along the road's reference line
    offset: float  # [m] lateral from the lane's centre, left positive
    orientation: Orientation | None


@dataclass(frozen=True, slots=True)
class RelativeLanePosition:
    """Relative to an entity's lane: `ds` (along the road's reference line) or `ds_lane`
    (along the target lane's centre line, 1.1+) is set, not both."""

    entity: str
    d_lane: int  # lanes to the left (positive) or right
    ds: float | None  # [m]
    ds_lane: float | None  # [m]
    offset: float  # [m] lateral from the target lane's centre
    orientation: Orientation | None


@dataclass(frozen=True, slots=True)
class TrajectoryPosition:
    """A point of a trajectory: `s` along it from its start, `t` to its left."""

    trajectory: Trajectory
    s: float  # [m]
    t: float  # [m] left positive
    orientation: Orientation | None


Position = (
    WorldPosition
    | RelativeWorldPosition
    | RelativeObjectPosition
    | RoadPosition
    | RelativeRoadPosition
    | LanePosition
    | RelativeLanePosition
    | TrajectoryPosition
)
